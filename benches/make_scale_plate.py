#!/usr/bin/env python3
"""A synthetic production-size sheet part for the run benchmark: a 2 mm plate 800 x 500 mm
with a grid of NX x NY round holes (radii 4-7 mm), cut by Open CASCADE and written as STEP
(`pip install cadquery-ocp`). With 24 x 20 holes: 486 faces, 1.9 MB, about the size of the
public 493-face production bracket that issue 31 names (not available here).

    python3 benches/make_scale_plate.py 24 20 target/scale/plate480.step

Python is for this benchmark only; nothing in the library or the CLI uses it.
"""

import os
import sys

from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox, BRepPrimAPI_MakeCylinder
from OCP.BRepAlgoAPI import BRepAlgoAPI_Cut
from OCP.BRep import BRep_Builder
from OCP.TopoDS import TopoDS_Compound
from OCP.gp import gp_Ax2, gp_Pnt, gp_Dir
from OCP.STEPControl import STEPControl_Writer, STEPControl_AsIs
from OCP.TopExp import TopExp_Explorer
from OCP.TopAbs import TopAbs_FACE
nx, ny = int(sys.argv[1]), int(sys.argv[2])
t = 2.0
plate = BRepPrimAPI_MakeBox(gp_Pnt(0, 0, 0), 800.0, 500.0, t).Shape()
b = BRep_Builder(); tools = TopoDS_Compound(); b.MakeCompound(tools)
for i in range(nx):
    for j in range(ny):
        x = 40 + i * (720 / max(nx - 1, 1)); y = 40 + j * (420 / max(ny - 1, 1))
        r = 4 + (i + j) % 4
        b.Add(tools, BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(x, y, -1), gp_Dir(0, 0, 1)), r, t + 2).Shape())
shape = BRepAlgoAPI_Cut(plate, tools).Shape()
n = 0
e = TopExp_Explorer(shape, TopAbs_FACE)
while e.More(): n += 1; e.Next()
os.makedirs(os.path.dirname(sys.argv[3]) or ".", exist_ok=True)
w = STEPControl_Writer()
w.Transfer(shape, STEPControl_AsIs)
w.Write(sys.argv[3])
print(n, "faces")
