#!/usr/bin/env python3
"""Makes the STEP fixtures of fixtures/step/ with Open CASCADE (pip install cadquery-ocp).

    python3 scripts/make_step_fixtures.py [fixtures/step]

Open CASCADE builds every solid, face and edge and writes the files (STEPControl_Writer).
Open CASCADE writes a wire as loose TRIMMED_CURVEs in a GEOMETRIC_CURVE_SET, never as a
COMPOSITE_CURVE, so this script then rewrites each such set into COMPOSITE_CURVEs of those same
trimmed curves (with the senses and gaps the cases below ask for), and removes the reference
direction of one circle's placement. Open CASCADE's own reader is the truth every fixture is
checked against (scripts/step_check.py), so a fixture only has to be valid STEP, not "right".

Files:
- composite_mm.step: a block 120 x 80 x 20 mm; on its top face a closed composite of a line, a
  circular arc, a rational B-spline and a line, one segment written reversed (same_sense .F.)
  and a 0.04 mm gap (closed by kerf); an open composite with a 0.3 mm gap (opened by kerf); a
  full circle on the side face x = 120 whose placement has no reference direction and an axis
  parallel to X; a composite that runs over the top face and down the side face (two faces).
- composite_inch.step: the same written in inches.
- faces.step: one solid or face of every kind: box (planes), cylinder, cone, sphere, torus,
  extrusion of a B-spline, revolution of a B-spline, rational B-spline surface; read with
  --edges (every face's boundary loops).
- offsets.step: one face on each exact kind of OFFSET_SURFACE, as Open CASCADE writes
  Geom_OffsetSurface: a cylinder of radius 20 offset by +3, a cone (semi-angle 15 degrees,
  radius 0.3 at its placement) by -2, a sphere of radius 25 by +5, a plane by +4, a torus (30,
  8) by -3; and a face on a RECTANGULAR_TRIMMED_SURFACE of a cylinder of radius 15 with its u
  sense reversed (.F.), which this script writes in place of the face's CYLINDRICAL_SURFACE
  (Open CASCADE writes the basis alone): the face's normal turns inward.
- offset_freeform.step: offsets of free-form bases, which kerf approximates with a proven
  bound: a bicubic B-spline sheet of two spans by +2.5, a rational biquadratic cap by -1.5, the
  extrusion of a rational cubic by +1.5 and the revolution of a rational cubic (2 rad) by -1.
- assembly.step: an assembly as Open CASCADE writes one (`write.step.assembly` 1: NEXT_
  ASSEMBLY_USAGE_OCCURRENCE, representation relationships with ITEM_DEFINED_TRANSFORMATIONs): a
  box 40 x 30 x 5 placed twice, where it is and turned 0.5 rad about z then moved by
  (100, 20, 3); and a sub-assembly moved by (0, -60, 0) holding a cylinder (radius 5, height 8)
  moved by (-50, 0, 0) (nested placements).
- trim_composite.step: the folded panel and trim line of fixtures/trim_creases.json (written by
  examples/make_fixtures.rs; run that first): the panel's profile (four lines meeting at
  creases of 10, 25 and 40 degrees, a bend arc of radius 10 up to the vertical, the flange's
  line) extruded along y into a shell of planes and a cylinder, and the trim line as one closed
  COMPOSITE_CURVE of its 20 pieces (lines and circular arcs through the same points, joined C0
  at the creases). Its header's time stamp is fixed, so that it is the same bytes on every run.

With names after OUTDIR (`python3 scripts/make_step_fixtures.py fixtures/step
trim_composite.step`) only those files are written: the other files' headers carry the time
they were written.
"""

import re
import sys
from pathlib import Path

from OCP.BRep import BRep_Builder
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge, BRepBuilderAPI_MakeFace, BRepBuilderAPI_MakeWire
from OCP.BRepPrimAPI import (
    BRepPrimAPI_MakeBox,
    BRepPrimAPI_MakeCone,
    BRepPrimAPI_MakeCylinder,
    BRepPrimAPI_MakePrism,
    BRepPrimAPI_MakeRevol,
    BRepPrimAPI_MakeSphere,
    BRepPrimAPI_MakeTorus,
)
import json

from OCP.GC import GC_MakeArcOfCircle
from OCP.Geom import Geom_BSplineCurve, Geom_BSplineSurface, Geom_Circle, Geom_TrimmedCurve
from OCP.gp import gp_Ax1, gp_Ax2, gp_Dir, gp_Pnt, gp_Vec
from OCP.Interface import Interface_Static
from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer
from OCP.OCP.collections import Array1_double as TColStd_Array1OfReal
from OCP.OCP.collections import Array1_gp_Pnt as TColgp_Array1OfPnt
from OCP.OCP.collections import Array1_int as TColStd_Array1OfInteger
from OCP.OCP.collections import Array2_double as TColStd_Array2OfReal
from OCP.OCP.collections import Array2_gp_Pnt as TColgp_Array2OfPnt
from OCP.OCP.TopoDS import TopoDS_Compound, TopoDS_Wire


def arr_pnt(pts):
    a = TColgp_Array1OfPnt(1, len(pts))
    for i, p in enumerate(pts):
        a.SetValue(i + 1, gp_Pnt(*p))
    return a


def arr_real(xs):
    a = TColStd_Array1OfReal(1, len(xs))
    for i, x in enumerate(xs):
        a.SetValue(i + 1, float(x))
    return a


def arr_int(xs):
    a = TColStd_Array1OfInteger(1, len(xs))
    for i, x in enumerate(xs):
        a.SetValue(i + 1, int(x))
    return a


def bspline(pts, weights, knots, mults, degree):
    return Geom_BSplineCurve(arr_pnt(pts), arr_real(weights), arr_real(knots), arr_int(mults), degree)


def line(a, b):
    return BRepBuilderAPI_MakeEdge(gp_Pnt(*a), gp_Pnt(*b)).Edge()


def arc(center, normal, xdir, r, a0, a1):
    c = Geom_Circle(gp_Ax2(gp_Pnt(*center), gp_Dir(*normal), gp_Dir(*xdir)), r)
    return BRepBuilderAPI_MakeEdge(Geom_TrimmedCurve(c, a0, a1, True)).Edge()


def compound(shapes):
    b = BRep_Builder()
    c = TopoDS_Compound()
    b.MakeCompound(c)
    for s in shapes:
        b.Add(c, s)
    return c


def wire(edges):
    """A wire of these edges in this order, connected or not (no check)."""
    b = BRep_Builder()
    w = TopoDS_Wire()
    b.MakeWire(w)
    for e in edges:
        b.Add(w, e)
    return w


def write(shape, path, unit="MM"):
    Interface_Static.SetCVal_s("write.step.schema", "AP214IS")
    Interface_Static.SetCVal_s("write.step.unit", unit)
    w = STEPControl_Writer()
    w.Transfer(shape, STEPControl_AsIs)
    if w.Write(str(path)) != 1:
        raise SystemExit(f"cannot write {path}")


# --- composite contours -----------------------------------------------------------------
# Each contour is a list of (edge, same_sense). An edge with same_sense False is built
# reversed (from the contour's later point to its earlier one) and marked .F. in the
# composite, so the contour is connected only if the reader applies the sense.

Z = 20.0


def contours():
    top = []
    # 1. Closed: line, arc (CCW, centre (50, 30), r 20, -90..90 deg), rational B-spline back
    # to (10, 50), line down to (10, 10.04): a 0.04 mm gap to the start (closed by kerf).
    top.append(
        [
            (line((10, 10, Z), (50, 10, Z)), True),
            (arc((50, 30, Z), (0, 0, 1), (1, 0, 0), 20.0, -1.5707963267948966, 1.5707963267948966), True),
            # written from (10, 50) to (50, 50): reversed, same_sense .F.
            (
                BRepBuilderAPI_MakeEdge(
                    bspline(
                        [(10, 50, Z), (20, 62, Z), (35, 58, Z), (50, 50, Z)],
                        [1.0, 0.7, 1.6, 1.0],
                        [0.0, 1.0],
                        [4, 4],
                        3,
                    )
                ).Edge(),
                False,
            ),
            (line((10, 50, Z), (10, 10.04, Z)), True),
        ]
    )
    # 2. Open with a 0.3 mm gap: opened into two contours.
    top.append(
        [
            (line((20, 70, Z), (60, 70, Z)), True),
            (line((60.3, 70, Z), (80, 60, Z)), True),
            (arc((90, 60, Z), (0, 0, 1), (1, 0, 0), 10.0, 3.141592653589793, 6.0), True),
        ]
    )
    # 3. Over two faces: along the top to the edge x = 120, then down the side face.
    top.append(
        [
            (line((100, 20, Z), (120, 20, Z)), True),
            (line((120, 20, Z), (120, 20, 5)), True),
            (line((120, 20, 5), (120, 5, 5)), True),
        ]
    )
    # 4. A full circle on the side face x = 120 (axis parallel to X; its reference direction
    # is removed below).
    side = BRepBuilderAPI_MakeEdge(
        Geom_Circle(gp_Ax2(gp_Pnt(120, 50, 10), gp_Dir(1, 0, 0)), 5.0)
    ).Edge()
    return top, side


def composite_text(text, groups):
    """Rewrites the file's GEOMETRIC_CURVE_SETs (one per wire, in file order, matching
    `groups`): each set's trimmed curves become one COMPOSITE_CURVE with the given senses, or
    stay loose."""
    sets = list(re.finditer(r"#(\d+) = GEOMETRIC_CURVE_SET\('',\(([^;]*?)\)\);", text, re.S))
    if len(sets) != len(groups):
        raise SystemExit(f"{len(sets)} curve sets written for {len(groups)} contours")
    next_id = max(int(x) for x in re.findall(r"#(\d+)\s*=", text)) + 1
    new_entities = []
    pieces = []
    last = 0
    for n, (m, (senses, keep_loose)) in enumerate(zip(sets, groups)):
        items = [x.strip() for x in m.group(2).replace("\n", "").split(",")]
        assert len(items) == len(senses), (items, senses)
        if keep_loose:
            continue
        segs = []
        for item, sense in zip(items, senses):
            sid = next_id
            next_id += 1
            new_entities.append(
                f"#{sid} = COMPOSITE_CURVE_SEGMENT(.CONTINUOUS.,{'.T.' if sense else '.F.'},{item});"
            )
            segs.append(f"#{sid}")
        cid = next_id
        next_id += 1
        new_entities.append(f"#{cid} = COMPOSITE_CURVE('contour {n + 1}',({','.join(segs)}),.F.);")
        pieces.append(text[last : m.start()])
        pieces.append(f"#{m.group(1)} = GEOMETRIC_CURVE_SET('',(#{cid}));")
        last = m.end()
    pieces.append(text[last:])
    text = "".join(pieces)
    return text.replace("ENDSEC;\nEND-ISO-10303-21;", "\n".join(new_entities) + "\nENDSEC;\nEND-ISO-10303-21;")


def drop_ref_direction(text, circle_radius_text):
    """Removes the reference direction of the placement of the circle written with this radius."""
    m = re.search(r"#\d+ = CIRCLE\('',#(\d+),%s\);" % re.escape(circle_radius_text), text)
    if not m:
        raise SystemExit("circle not found")
    pid = m.group(1)
    return re.sub(
        r"(#%s = AXIS2_PLACEMENT_3D\('',#\d+,#\d+),#\d+\);" % pid,
        r"\1,$);",
        text,
    )


def make_composites(out: Path, unit: str, name: str):
    top, side = contours()
    block = BRepPrimAPI_MakeBox(120.0, 80.0, 20.0).Shape()
    wires = [wire([e for e, _ in c]) for c in top] + [wire([side])]
    path = out / name
    write(compound([block] + wires), path, unit)
    text = path.read_text()
    groups = [([s for _, s in c], False) for c in top] + [([True], True)]
    text = composite_text(text, groups)
    radius = "5." if unit == "MM" else None
    if radius is None:
        m = re.findall(r"CIRCLE\('',#\d+,([0-9.E+-]+)\);", text)
        radius = m[-1]
    text = drop_ref_direction(text, radius)
    path.write_text(text)


def make_faces(out: Path):
    shapes = []
    shapes.append(BRepPrimAPI_MakeBox(gp_Pnt(-200, 0, 0), 30, 20, 10).Shape())
    shapes.append(BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(-150, 0, 0), gp_Dir(0, 0, 1)), 10, 25).Shape())
    shapes.append(BRepPrimAPI_MakeCone(gp_Ax2(gp_Pnt(-100, 0, 0), gp_Dir(0, 1, 1)), 12, 4, 20).Shape())
    shapes.append(BRepPrimAPI_MakeSphere(gp_Pnt(-50, 0, 0), 9).Shape())
    shapes.append(BRepPrimAPI_MakeTorus(gp_Ax2(gp_Pnt(0, 0, 0), gp_Dir(1, 0, 1)), 15, 4).Shape())
    prof = bspline([(40, 0, 0), (45, 10, 0), (55, -5, 0), (60, 5, 0)], [1, 2, 0.5, 1], [0, 1], [4, 4], 3)
    shapes.append(
        BRepPrimAPI_MakePrism(BRepBuilderAPI_MakeEdge(prof).Edge(), gp_Vec(0, 3, 12)).Shape()
    )
    prof2 = bspline([(100, 0, 0), (106, 0, 5), (103, 0, 12), (108, 0, 20)], [1, 1.5, 0.8, 1], [0, 1], [4, 4], 3)
    shapes.append(
        BRepPrimAPI_MakeRevol(BRepBuilderAPI_MakeEdge(prof2).Edge(), gp_Ax1(gp_Pnt(90, 0, 0), gp_Dir(0, 0, 1)), 4.0).Shape()
    )
    net = TColgp_Array2OfPnt(1, 4, 1, 3)
    w = TColStd_Array2OfReal(1, 4, 1, 3)
    for i in range(4):
        for j in range(3):
            net.SetValue(i + 1, j + 1, gp_Pnt(150 + 10 * i, 10 * j, 3 * ((i * j) % 3) - 2))
            w.SetValue(i + 1, j + 1, 1.0 + 0.3 * ((i + 2 * j) % 3))
    surf = Geom_BSplineSurface(net, w, arr_real([0, 1]), arr_real([0, 1]), arr_int([4, 4]), arr_int([3, 3]), 3, 2)
    shapes.append(BRepBuilderAPI_MakeFace(surf, 0.1, 0.9, 0.05, 0.8, 1e-7).Face())
    write(compound(shapes), out / "faces.step")


def make_trim_composite(out: Path):
    """The folded panel of fixtures/trim_creases.json as a shell, its trim line as one closed
    composite curve of lines and arcs."""
    src = json.loads((Path(__file__).resolve().parent.parent / "fixtures" / "trim_creases.json").read_text())
    y0 = src["surfaces"][0]["control_points"][0][0][1]
    y1 = src["surfaces"][0]["control_points"][0][1][1]

    def arc3(a, b, c):
        return BRepBuilderAPI_MakeEdge(GC_MakeArcOfCircle(gp_Pnt(*a), gp_Pnt(*b), gp_Pnt(*c)).Value()).Edge()

    def on_arc(p0, p1, p2, w):
        """The middle (t = 1/2) of the rational quadratic Bezier p0, p1 (weight w), p2."""
        return [(a + 2 * w * b + c) / (2 + 2 * w) for a, b, c in zip(p0, p1, p2)]

    # The profile at y = y0: each face's first column (u across the folds).
    profile = BRepBuilderAPI_MakeWire()
    for f in src["surfaces"]:
        col = [row[0] for row in f["control_points"]]
        if f["degree_u"] == 1:
            profile.Add(line(col[0], col[1]))
        else:
            w = f["weights"][1][0]
            profile.Add(arc3(col[0], on_arc(col[0], col[1], col[2], w), col[2]))
    shell = BRepPrimAPI_MakePrism(profile.Wire(), gp_Vec(0, y1 - y0, 0)).Shape()
    # The trim line: one rational quadratic Bezier per span (every joint is a double knot).
    c = src["curves"][0]
    cps, ws = c["control_points"], c["weights"]
    edges = []
    for k in range(0, len(cps) - 1, 2):
        p0, p1, p2, w = cps[k], cps[k + 1], cps[k + 2], ws[k + 1]
        edges.append(line(p0, p2) if w == 1.0 else arc3(p0, on_arc(p0, p1, p2, w), p2))
    path = out / "trim_composite.step"
    write(compound([shell, wire(edges)]), path)
    text = composite_text(path.read_text(), [([True] * len(edges), False)])
    text = re.sub(r"(FILE_NAME\('[^']*',)'[^']*'", r"\1'2026-12-03T00:00:00'", text, count=1)
    path.write_text(text)


def make_offsets(out: Path):
    from OCP.Geom import (
        Geom_ConicalSurface,
        Geom_CylindricalSurface,
        Geom_OffsetSurface,
        Geom_Plane,
        Geom_SphericalSurface,
        Geom_ToroidalSurface,
    )
    from OCP.gp import gp_Ax3

    def face(surface, u0, u1, v0, v1):
        return BRepBuilderAPI_MakeFace(surface, u0, u1, v0, v1, 1e-7).Face()

    ax = lambda x, y, z, d=(0, 0, 1): gp_Ax3(gp_Pnt(x, y, z), gp_Dir(*d))
    faces = [
        face(Geom_OffsetSurface(Geom_CylindricalSurface(ax(0, 0, 0), 20.0), 3.0), 0.0, 2.0, 0.0, 30.0),
        face(Geom_OffsetSurface(Geom_ConicalSurface(ax(100, 0, 0), 0.2617993877991494, 15.0), -2.0), 0.5, 3.0, 0.0, 20.0),
        face(Geom_OffsetSurface(Geom_SphericalSurface(ax(0, 100, 0), 25.0), 5.0), 0.0, 2.5, -0.5, 0.8),
        face(Geom_OffsetSurface(Geom_Plane(ax(0, -100, 0, (0, 1, 1))), 4.0), -10.0, 10.0, -5.0, 5.0),
        face(Geom_OffsetSurface(Geom_ToroidalSurface(ax(100, 100, 0), 30.0, 8.0), -3.0), 0.0, 2.0, 0.0, 1.5),
        face(Geom_CylindricalSurface(ax(-100, 0, 0, (1, 0, 0)), 15.0), 0.5, 2.5, -10.0, 10.0),
    ]
    path = out / "offsets.step"
    write(compound(faces), path)
    text = path.read_text()
    # The last face's CYLINDRICAL_SURFACE (radius 15), wrapped in a RECTANGULAR_TRIMMED_SURFACE
    # that reverses u: the face now refers to the trimmed surface.
    cyl = re.search(r"#(\d+) ?= ?CYLINDRICAL_SURFACE\('[^']*',#\d+,15\.", text).group(1)
    face_ref = re.compile(r"(ADVANCED_FACE\('[^']*',\([^)]*\),)#" + cyl + r",")
    if len(face_ref.findall(text)) != 1:
        raise SystemExit("offsets.step: the radius-15 cylinder's face not found once")
    new_id = 1 + max(int(i) for i in re.findall(r"^#(\d+)", text, re.M))
    text = face_ref.sub(lambda m: f"{m.group(1)}#{new_id},", text)
    text = text.replace(
        "ENDSEC;\nEND-ISO-10303-21;",
        f"#{new_id} = RECTANGULAR_TRIMMED_SURFACE('',#{cyl},0.5,2.5,-10.,10.,.F.,.T.);\nENDSEC;\nEND-ISO-10303-21;",
    )
    text = re.sub(r"(FILE_NAME\('[^']*',)'[^']*'", r"\1'2026-12-05T00:00:00'", text, count=1)
    path.write_text(text)


def make_offset_freeform(out: Path):
    from OCP.Geom import Geom_OffsetSurface, Geom_SurfaceOfLinearExtrusion, Geom_SurfaceOfRevolution

    def face(surface, u0, u1, v0, v1):
        return BRepBuilderAPI_MakeFace(surface, u0, u1, v0, v1, 1e-7).Face()

    faces = []
    # Free-form bases (approximated by kerf, with the bound it proves): a bicubic B-spline of
    # two spans in u, a wavy sheet over [200, 300] x [0, 80], offset by +2.5; and a rational
    # biquadratic dome cap over [200, 260] x [100, 160], offset by -1.5.
    net = TColgp_Array2OfPnt(1, 5, 1, 4)
    zs = [[0, 6, -3, 2], [4, -2, 8, 0], [-3, 5, 1, 4], [2, -4, 3, -1], [0, 3, -2, 1]]
    for i in range(5):
        for j in range(4):
            net.SetValue(i + 1, j + 1, gp_Pnt(200 + 25 * i, 80 * j / 3, zs[i][j]))
    wavy = Geom_BSplineSurface(net, arr_real([0, 0.5, 1]), arr_real([0, 1]), arr_int([4, 1, 4]), arr_int([4, 4]), 3, 3)
    faces.append(face(Geom_OffsetSurface(wavy, 2.5), 0.0, 1.0, 0.0, 1.0))
    net = TColgp_Array2OfPnt(1, 3, 1, 3)
    w = TColStd_Array2OfReal(1, 3, 1, 3)
    for i in range(3):
        for j in range(3):
            net.SetValue(i + 1, j + 1, gp_Pnt(200 + 30 * i, 100 + 30 * j, 12 if (i, j) == (1, 1) else 4 * ((i + j) % 2)))
            w.SetValue(i + 1, j + 1, 0.7 if (i + j) % 2 else 1.0)
    dome = Geom_BSplineSurface(net, w, arr_real([0, 1]), arr_real([0, 1]), arr_int([3, 3]), arr_int([3, 3]), 2, 2)
    faces.append(face(Geom_OffsetSurface(dome, -1.5), 0.0, 1.0, 0.0, 1.0))
    # An extrusion of a rational cubic along (0, 0.3, 1) offset by +1.5, and a revolution of a
    # rational cubic profile (about the z axis through (300, 300, 0), 2 rad) offset by -1.
    prof = bspline([(200, 200, 0), (215, 215, 0), (235, 195, 0), (250, 210, 0)], [1, 1.4, 0.8, 1], [0, 1], [4, 4], 3)
    faces.append(face(Geom_OffsetSurface(Geom_SurfaceOfLinearExtrusion(prof, gp_Dir(0, 0.3, 1)), 1.5), 0.0, 1.0, 0.0, 20.0))
    prof2 = bspline([(320, 300, 0), (330, 300, 8), (326, 300, 16), (335, 300, 25)], [1, 1.2, 0.9, 1], [0, 1], [4, 4], 3)
    rev = Geom_SurfaceOfRevolution(prof2, gp_Ax1(gp_Pnt(300, 300, 0), gp_Dir(0, 0, 1)))
    faces.append(face(Geom_OffsetSurface(rev, -1.0), 0.0, 2.0, 0.0, 1.0))
    path = out / "offset_freeform.step"
    write(compound(faces), path)
    text = re.sub(r"(FILE_NAME\('[^']*',)'[^']*'", r"\1'2026-12-05T00:00:00'", path.read_text(), count=1)
    path.write_text(text)


def make_assembly(out: Path):
    from OCP.gp import gp_Trsf
    from OCP.TopLoc import TopLoc_Location

    box = BRepPrimAPI_MakeBox(40, 30, 5).Shape()
    turn = gp_Trsf()
    turn.SetRotation(gp_Ax1(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), 0.5)
    move = gp_Trsf()
    move.SetTranslation(gp_Vec(100, 20, 3))
    cyl = BRepPrimAPI_MakeCylinder(5, 8).Shape()
    t3 = gp_Trsf()
    t3.SetTranslation(gp_Vec(-50, 0, 0))
    t4 = gp_Trsf()
    t4.SetTranslation(gp_Vec(0, -60, 0))
    sub = compound([cyl.Located(TopLoc_Location(t3))])
    shape = compound([box, box.Located(TopLoc_Location(move.Multiplied(turn))), sub.Located(TopLoc_Location(t4))])
    Interface_Static.SetIVal_s("write.step.assembly", 1)
    try:
        write(shape, out / "assembly.step")
    finally:
        Interface_Static.SetIVal_s("write.step.assembly", 0)
    path = out / "assembly.step"
    text = re.sub(r"(FILE_NAME\('[^']*',)'[^']*'", r"\1'2026-12-05T00:00:00'", path.read_text(), count=1)
    path.write_text(text)


MAKERS = {
    "assembly.step": make_assembly,
    "offsets.step": make_offsets,
    "offset_freeform.step": make_offset_freeform,
    "composite_mm.step": lambda out: make_composites(out, "MM", "composite_mm.step"),
    "composite_inch.step": lambda out: make_composites(out, "INCH", "composite_inch.step"),
    "faces.step": make_faces,
    "trim_composite.step": make_trim_composite,
}


if __name__ == "__main__":
    out = Path(sys.argv[1] if len(sys.argv) > 1 else "fixtures/step")
    out.mkdir(parents=True, exist_ok=True)
    names = sys.argv[2:] or list(MAKERS)
    for name in names:
        if name not in MAKERS:
            raise SystemExit(f"unknown file {name} (known: {', '.join(MAKERS)})")
        MAKERS[name](out)
    print("wrote", ", ".join(sorted(names)))
