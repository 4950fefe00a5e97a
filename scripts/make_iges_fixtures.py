#!/usr/bin/env python3
"""Makes the IGES fixtures of fixtures/iges/ with Open CASCADE (pip install cadquery-ocp).

    python3 scripts/make_iges_fixtures.py [OUTDIR]              # the fixtures
    python3 scripts/make_iges_fixtures.py OUTDIR PART.stp ...   # IGES copies of STEP parts

Open CASCADE builds or reads the shapes and writes the files (IGESControl_Writer, trimmed
surfaces: 144 on 108/120/122/128, boundaries 142 with model-space 102/110/100/126 curves, 124
matrices). Open CASCADE's own IGES reader is the truth kerf's reader is checked against
(scripts/step_check.py), so a fixture only has to be valid IGES, not "right".

Files:
- faces.igs: fixtures/step/faces.step (a solid or face of every kind) written as IGES;
  read with --edges.
- curves.igs: a plate face 120 x 80 mm on z = 0 and a cylinder face (radius 20, axis along y
  at x = 160, z = 0, y from 0 to 80), with free curves: a circle of radius 5 about (20, 20, 0),
  an ellipse arc (semi-axes 12 and 6 about (60, 20, 0), from 0 to 270 degrees), a planar cubic
  B-spline on the plate, a closed wire of three lines and a quarter circle of radius 10 (a
  rounded rectangle corner) on the plate, a circle of radius 20 round the cylinder at y = 40
  (a vertical circle in the plane y = 40), and a 3D B-spline on no face.
- curves_inch.igs: the same, written in inches.
- sheet.igs: a sheet-metal plate 100 x 60 x 2 mm (z from 0 to 2) with a round hole of radius 8
  about (25, 30) and a rectangular cut-out 30 x 20 from (55, 20) to (85, 40), made by Boolean
  cuts of a box; read with --edges, a sheet of three through-features.

Their start and global sections carry the time they were written; regenerate them all at once.
"""

import sys
from pathlib import Path

from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge, BRepBuilderAPI_MakeFace, BRepBuilderAPI_MakeWire
from OCP.BRep import BRep_Builder
from OCP.BRepAlgoAPI import BRepAlgoAPI_Cut
from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox, BRepPrimAPI_MakeCylinder
from OCP.GC import GC_MakeArcOfCircle, GC_MakeArcOfEllipse
from OCP.Geom import Geom_BSplineCurve, Geom_CylindricalSurface
from OCP.gp import gp_Ax2, gp_Ax3, gp_Dir, gp_Elips, gp_Pln, gp_Pnt, gp_Circ
from OCP.IGESControl import IGESControl_Controller, IGESControl_Writer
from OCP.Interface import Interface_Static
from OCP.STEPControl import STEPControl_Reader
from OCP.OCP.collections import Array1_double, Array1_gp_Pnt, Array1_int
from OCP.OCP.TopoDS import TopoDS_Compound


def arr(cls, xs):
    a = cls(1, len(xs))
    for i, x in enumerate(xs):
        a.SetValue(i + 1, x)
    return a


def bspline(pts, knots, mults, degree):
    return Geom_BSplineCurve(arr(Array1_gp_Pnt, [gp_Pnt(*p) for p in pts]), arr(Array1_double, knots), arr(Array1_int, mults), degree)


def compound(shapes):
    b = BRep_Builder()
    c = TopoDS_Compound()
    b.MakeCompound(c)
    for s in shapes:
        b.Add(c, s)
    return c


def write(shape, path, unit="MM"):
    IGESControl_Controller.Init_s()
    Interface_Static.SetIVal_s("write.iges.brep.mode", 0)
    w = IGESControl_Writer(unit, 0)
    w.AddShape(shape)
    w.ComputeModel()
    if not w.Write(str(path)):
        raise SystemExit(f"{path}: Open CASCADE could not write it")
    print(f"wrote {path}")


def step_shape(path):
    r = STEPControl_Reader()
    r.ReadFile(str(path))
    r.TransferRoots()
    return r.OneShape()


def curves_part():
    plate = BRepBuilderAPI_MakeFace(gp_Pln(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), 0.0, 120.0, 0.0, 80.0).Face()
    cyl = Geom_CylindricalSurface(gp_Ax3(gp_Pnt(160, 0, 0), gp_Dir(0, 1, 0), gp_Dir(1, 0, 0)), 20.0)
    tube = BRepBuilderAPI_MakeFace(cyl, 0.0, 6.283185307179586, 0.0, 80.0, 1e-7).Face()
    edge = lambda c: BRepBuilderAPI_MakeEdge(c).Edge()
    circle = edge(gp_Circ(gp_Ax2(gp_Pnt(20, 20, 0), gp_Dir(0, 0, 1)), 5.0))
    ell = GC_MakeArcOfEllipse(gp_Elips(gp_Ax2(gp_Pnt(60, 20, 0), gp_Dir(0, 0, 1), gp_Dir(1, 0, 0)), 12.0, 6.0), 0.0, 4.71238898038469, True).Value()
    ellipse = edge(ell)
    spline = edge(bspline([(90, 10, 0), (100, 30, 0), (110, 10, 0), (115, 40, 0), (100, 60, 0)], [0, 0.5, 1], [4, 1, 4], 3))
    # A rounded rectangle: three lines and a quarter circle of radius 10 at (40, 60).
    w = BRepBuilderAPI_MakeWire()
    w.Add(edge_seg((10, 40), (40, 40)))
    w.Add(BRepBuilderAPI_MakeEdge(GC_MakeArcOfCircle(gp_Circ(gp_Ax2(gp_Pnt(40, 50, 0), gp_Dir(0, 0, 1)), 10.0), gp_Pnt(40, 40, 0), gp_Pnt(50, 50, 0), True).Value()).Edge())
    w.Add(edge_seg((50, 50), (50, 70)))
    w.Add(edge_seg((50, 70), (10, 70)))
    w.Add(edge_seg((10, 70), (10, 40)))
    ring = edge(gp_Circ(gp_Ax2(gp_Pnt(160, 40, 0), gp_Dir(0, 1, 0)), 20.0))
    free3d = edge(bspline([(0, 100, 0), (30, 110, 20), (60, 95, 40), (90, 120, 10)], [0, 1], [4, 4], 3))
    return compound([plate, tube, circle, ellipse, spline, w.Wire(), ring, free3d])


def sheet_part():
    plate = BRepPrimAPI_MakeBox(gp_Pnt(0, 0, 0), gp_Pnt(100, 60, 2)).Shape()
    hole = BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(25, 30, -1), gp_Dir(0, 0, 1)), 8.0, 4.0).Shape()
    cut = BRepPrimAPI_MakeBox(gp_Pnt(55, 20, -1), gp_Pnt(85, 40, 3)).Shape()
    return BRepAlgoAPI_Cut(BRepAlgoAPI_Cut(plate, hole).Shape(), cut).Shape()


def edge_seg(a, b):
    return BRepBuilderAPI_MakeEdge(gp_Pnt(a[0], a[1], 0), gp_Pnt(b[0], b[1], 0)).Edge()


def main():
    out = Path(sys.argv[1]) if len(sys.argv) > 1 else Path("fixtures/iges")
    out.mkdir(parents=True, exist_ok=True)
    if len(sys.argv) > 2:
        for p in map(Path, sys.argv[2:]):
            write(step_shape(p), out / (p.stem + ".igs"))
        return
    here = Path(__file__).resolve().parent.parent
    write(step_shape(here / "fixtures/step/faces.step"), out / "faces.igs")
    part = curves_part()
    write(part, out / "curves.igs")
    write(part, out / "curves_inch.igs", "IN")
    write(sheet_part(), out / "sheet.igs")


if __name__ == "__main__":
    main()
