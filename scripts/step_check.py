#!/usr/bin/env python3
"""Checks `kerf import` against Open CASCADE's STEP and IGES readers (pip install cadquery-ocp).

    python3 scripts/step_check.py --kerf target/release/kerf fixtures/step/composite_mm.step
    python3 scripts/step_check.py --kerf target/release/kerf --edges fixtures/step/faces.step

For every file: runs `kerf import --all-faces` (plus --edges if asked), reads the same file with
Open CASCADE (STEPControl_Reader, or IGESControl_Reader for .igs/.iges; lengths in mm), and checks
- every imported curve lies within TOL (1e-9 mm) of Open CASCADE's edges at dense samples (400
  per curve plus every knot), and every Open CASCADE edge lies within TOL of the imported curves
  (so nothing is missing), and the curves run the same way (tangents agree); near a gap kerf
  closed, the tolerance is the largest pole move kerf reported;
- every imported surface `face #N` lies within TOL of Open CASCADE's face #N on a 15 x 15 grid,
  covers that face's parameter box (a grid over the box of Open CASCADE's parameter-space
  boundary curves projects within TOL; for IGES within the largest tolerance Open CASCADE gives
  the face's edges, as it builds those curves from the model-space curves by approximation),
  and has the same orientation: `Su x Sv` of kerf's surface agrees with Open CASCADE's normal of
  the face (reversed where the face is REVERSED); a surface kerf approximates (the offset of a
  B-spline surface, listed in `kerf import --json`'s `approximated`) within the bound kerf
  proved for it.

IGES files are read by Open CASCADE with `read.surfacecurve.mode` 3 (each boundary's model-space
curve, as kerf reads it, not a 3D edge rebuilt from the parameter-space curve by approximation,
which lies up to 7e-6 mm off) and compared within IGES_TOL (1e-8 mm): IGES writers print 9-10
significant digits, so a 124 matrix or a revolution's axis is orthonormal only to ~1e-10 and
the two readers' arcs and surfaces differ by up to 5e-9 mm on a 150 mm part.
"""

import argparse
import json
import math
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

from OCP.OCP.BRep import BRep_Tool
from OCP.OCP.BRepTools import BRepTools
from OCP.OCP.collections import Array1_double, Array1_gp_Pnt, Array1_int, Array2_double, Array2_gp_Pnt
from OCP.OCP.Bnd import Bnd_Box
from OCP.OCP.BndLib import BndLib_Add3dCurve
from OCP.OCP.BRepBndLib import BRepBndLib
from OCP.OCP.BRepAdaptor import BRepAdaptor_Curve2d
from OCP.OCP.GeomAdaptor import GeomAdaptor_Curve
from OCP.OCP.Geom import Geom_BSplineCurve, Geom_BSplineSurface
from OCP.OCP.GeomAPI import GeomAPI_ProjectPointOnCurve, GeomAPI_ProjectPointOnSurf
from OCP.OCP.GeomLProp import GeomLProp_SLProps
from OCP.OCP.gp import gp_Pnt, gp_Vec
from OCP.OCP.IFSelect import IFSelect_RetDone
from OCP.OCP.IGESControl import IGESControl_Reader
from OCP.OCP.STEPControl import STEPControl_Reader
from OCP.OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE, TopAbs_REVERSED
from OCP.OCP.TopExp import TopExp_Explorer
from OCP.OCP.TopoDS import TopoDS

TOL = 1e-9
IGES_TOL = 1e-8
# The most an IGES face's parameter box may be missed by where Open CASCADE's own edge
# tolerance allows it, mm (a tenth of kerf's default cutting tolerance).
COVER_TOL_CAP = 1e-3
# Open CASCADE's read.surfacecurve.mode for IGES (3: the model-space curves; --iges-mode 0 shows
# its default, the approximated edges).
SURFACE_CURVE_MODE = 3


def distinct(knots):
    vals, mults = [], []
    for k in knots:
        if vals and k == vals[-1]:
            mults[-1] += 1
        else:
            vals.append(k)
            mults.append(1)
    return vals, mults


def arr1(cls, xs):
    a = cls(1, len(xs))
    for i, x in enumerate(xs):
        a.SetValue(i + 1, x)
    return a


def kerf_curve(c):
    vals, mults = distinct(c["knots"])
    poles = arr1(Array1_gp_Pnt, [gp_Pnt(*p) for p in c["control_points"]])
    w = c.get("weights") or [1.0] * len(c["control_points"])
    return Geom_BSplineCurve(poles, arr1(Array1_double, [float(x) for x in w]), arr1(Array1_double, vals), arr1(Array1_int, mults), c["degree"])


def kerf_surface(s):
    cps = s["control_points"]
    nu, nv = len(cps), len(cps[0])
    net = Array2_gp_Pnt(1, nu, 1, nv)
    w = Array2_double(1, nu, 1, nv)
    ws = s.get("weights") or [[1.0] * nv for _ in range(nu)]
    for a in range(nu):
        for b in range(nv):
            net.SetValue(a + 1, b + 1, gp_Pnt(*cps[a][b]))
            w.SetValue(a + 1, b + 1, float(ws[a][b]))
    ku, mu = distinct(s["knots_u"])
    kv, mv = distinct(s["knots_v"])
    return Geom_BSplineSurface(
        net, w, arr1(Array1_double, ku), arr1(Array1_double, kv), arr1(Array1_int, mu), arr1(Array1_int, mv), s["degree_u"], s["degree_v"]
    )


def occ_by_id(path):
    iges = path.suffix.lower() in (".igs", ".iges")
    if iges:
        # Edges from the file's model-space curves (142's), not rebuilt from parameter curves.
        from OCP.OCP.Interface import Interface_Static
        from OCP.OCP.IGESControl import IGESControl_Controller

        IGESControl_Controller.Init_s()
        Interface_Static.SetIVal_s("read.surfacecurve.mode", SURFACE_CURVE_MODE)
    r = IGESControl_Reader() if iges else STEPControl_Reader()
    if r.ReadFile(str(path)) != IFSelect_RetDone:
        raise SystemExit(f"{path}: Open CASCADE cannot read it")
    r.TransferRoots()
    shape = r.OneShape()
    faces = []
    ex = TopExp_Explorer(shape, TopAbs_FACE)
    while ex.More():
        faces.append(TopoDS.Face(ex.Current()))
        ex.Next()
    free = []
    ex = TopExp_Explorer(shape, TopAbs_EDGE, TopAbs_FACE)
    while ex.More():
        free.append(TopoDS.Edge(ex.Current()))
        ex.Next()
    # (edge, is a seam of its face): Open CASCADE adds seam edges to closed faces that STEP
    # bounds by two circles only (and to a whole sphere), so seams are not required of kerf.
    face_edges = []
    for f in faces:
        fe = TopExp_Explorer(f, TopAbs_EDGE)
        while fe.More():
            e = TopoDS.Edge(fe.Current())
            face_edges.append((e, BRep_Tool.IsClosed_s(e, f)))
            fe.Next()
    return faces, [(e, False) for e in free], face_edges


def edge_curves(edges, with_seams=True):
    out = []
    for e, seam in edges:
        if BRep_Tool.Degenerated_s(e) or (seam and not with_seams):
            continue
        c = BRep_Tool.Curve_s(e, 0.0, 0.0)
        a, b = BRep_Tool.Range_s(e)
        if c is None:
            continue
        sign = -1.0 if e.Orientation() == TopAbs_REVERSED else 1.0
        out.append((c, a, b, sign, box_of(c, a, b)))
    return out


def box_of(c, a, b):
    box = Bnd_Box()
    BndLib_Add3dCurve.Add_s(GeomAdaptor_Curve(c, a, b), 1e-7, box)
    lo, hi = box.CornerMin(), box.CornerMax()
    return (lo.X(), lo.Y(), lo.Z(), hi.X(), hi.Y(), hi.Z())


def box_distance(box, p):
    x0, y0, z0, x1, y1, z1 = box
    dx = max(x0 - p.X(), 0.0, p.X() - x1)
    dy = max(y0 - p.Y(), 0.0, p.Y() - y1)
    dz = max(z0 - p.Z(), 0.0, p.Z() - z1)
    return math.sqrt(dx * dx + dy * dy + dz * dz)


def nearest_on(curves, p, boxes=None):
    """(distance, curve index, parameter) of the nearest point of the curves to p; `boxes` is
    the (n, 6) array of the curves' bounding boxes (made here if not given)."""
    if boxes is None:
        boxes = np.array([cv[4] for cv in curves])
    q = np.array([p.X(), p.Y(), p.Z()])
    gap = np.maximum(np.maximum(boxes[:, :3] - q, q - boxes[:, 3:]), 0.0)
    lower = np.sqrt((gap * gap).sum(axis=1))
    best = (math.inf, -1, 0.0)
    for i in np.argsort(lower, kind="stable"):
        if lower[i] > best[0]:
            break
        i = int(i)
        c, a, b = curves[i][:3]
        pr = GeomAPI_ProjectPointOnCurve(p, c, a, b)
        cands = []
        if pr.NbPoints() > 0:
            cands.append((pr.LowerDistance(), pr.LowerDistanceParameter()))
        for t in (a, b):
            cands.append((p.Distance(c.Value(t)), t))
        d, t = min(cands)
        if d > 1e-9 and d < best[0]:
            # Open CASCADE's projection can miss the foot of the perpendicular near the end of
            # a degree-1 span (it answers with the span's end): scan, then refine by ternary
            # search (the distance is unimodal near the foot).
            n = 64
            ts = [a + (b - a) * k / n for k in range(n + 1)]
            k = min(range(n + 1), key=lambda k: p.Distance(c.Value(ts[k])))
            lo, hi = ts[max(k - 1, 0)], ts[min(k + 1, n)]
            for _ in range(100):
                m1, m2 = lo + (hi - lo) / 3, hi - (hi - lo) / 3
                if p.Distance(c.Value(m1)) < p.Distance(c.Value(m2)):
                    hi = m2
                else:
                    lo = m1
            tm = 0.5 * (lo + hi)
            d, t = min((d, t), (p.Distance(c.Value(tm)), tm))
        if d < best[0]:
            best = (d, i, t)
    return best


def check_file(kerf, step, edges, failures, counts, iges_tol=IGES_TOL):
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "part.curves.json"
        cmd = [kerf, "import", str(step), "-o", str(out), "--all-faces", "--json"]
        if edges:
            cmd += ["--edges", "--every-face-loop"]
        res = subprocess.run(cmd, capture_output=True, text=True)
        if res.returncode != 0:
            failures.append(f"{step}: kerf import failed: {res.stderr.strip()}")
            return
        summary = json.loads(res.stdout)
        doc = json.loads(out.read_text())
    faces, free, face_edges = occ_by_id(step)
    truth = edge_curves(face_edges if edges else free)
    truth_cover = edge_curves(face_edges if edges else free, with_seams=False)
    truth_boxes = np.array([cv[4] for cv in truth])
    iges = step.suffix.lower() in (".igs", ".iges")
    curve_tol = iges_tol if iges else TOL
    surface_tol = iges_tol if iges else TOL
    gap_tol = curve_tol + summary["largest_pole_move_mm"]
    kcurves = []
    for c in doc["curves"]:
        g = kerf_curve(c)
        a, b = g.FirstParameter(), g.LastParameter()
        # One entry per knot span: the projection is reliable where the curve is smooth.
        spans = sorted(set(k for k in c["knots"] if a <= k <= b))
        kcurves.extend((g, s0, s1, 1.0, box_of(g, s0, s1)) for s0, s1 in zip(spans, spans[1:]) if s1 > s0)
        ts = sorted(set([a + (b - a) * k / 400 for k in range(401)] + [k for k in c["knots"] if a <= k <= b]))
        worst, back = 0.0, 0
        for t in ts:
            p = gp_Pnt()
            v = gp_Vec()
            g.D1(t, p, v)
            d, i, u = nearest_on(truth, p, truth_boxes)
            worst = max(worst, d)
            if v.Magnitude() > 1e-12 and a < t < b and d < 1e-6:
                cc, _, _, sign, _ = truth[i]
                q = gp_Pnt()
                w = gp_Vec()
                cc.D1(u, q, w)
                if w.Magnitude() > 1e-12 and sign * v.Dot(w) / (v.Magnitude() * w.Magnitude()) < -0.5:
                    back += 1
        counts["curves"] += 1
        tol = curve_tol if worst <= curve_tol else gap_tol
        if worst > tol:
            failures.append(f"{step}: curve {c['id']!r}: {worst:.3e} mm from Open CASCADE's edges (> {tol:.1e})")
        elif worst > curve_tol:
            print(f"  {step.name}: curve {c['id']!r}: {worst:.3e} mm, within the closed gap's pole move {summary['largest_pole_move_mm']:.3e}")
        if back > 0 and not edges:
            failures.append(f"{step}: curve {c['id']!r}: runs against Open CASCADE's edge at {back} samples")
    # Coverage: every Open CASCADE edge is imported.
    kboxes = np.array([cv[4] for cv in kcurves])
    for k, (c, a, b, _, _) in enumerate(truth_cover):
        worst = 0.0
        for j in range(51):
            p = c.Value(a + (b - a) * j / 50)
            worst = max(worst, nearest_on(kcurves, p, kboxes)[0])
        counts["edges"] += 1
        if worst > gap_tol:
            failures.append(f"{step}: Open CASCADE edge {k}: {worst:.3e} mm from every imported curve")
    # Surfaces: each kerf surface is matched to the Open CASCADE face it fits best (Open CASCADE
    # does not keep the STEP entity numbers on its faces): the face whose surface is nearest
    # the kerf grid and whose parameter box the kerf surface covers.
    face_boxes = []
    for f in faces:
        box = Bnd_Box()
        BRepBndLib.Add_s(f, box)
        lo, hi = box.CornerMin(), box.CornerMax()
        face_boxes.append((lo.X(), lo.Y(), lo.Z(), hi.X(), hi.Y(), hi.Z()))
    for s in doc["surfaces"]:
        counts["surfaces"] += 1
        ks = kerf_surface(s)
        u0, u1, v0, v1 = ks.Bounds()
        grid = []
        for i in range(15):
            for j in range(15):
                u = u0 + (u1 - u0) * (i + 0.5) / 15
                v = v0 + (v1 - v0) * (j + 0.5) / 15
                p = gp_Pnt()
                su, sv = gp_Vec(), gp_Vec()
                ks.D1(u, v, p, su, sv)
                grid.append((p, su.Crossed(sv)))
        best = None
        approx = {a["id"]: a["position_mm"] for a in summary.get("approximated", [])}
        near = max(1e-6, 2.0 * approx.get(s["id"], 0.0))
        for face, fbox in zip(faces, face_boxes):
            if box_distance(fbox, grid[112][0]) > near:
                continue
            os_ = BRep_Tool.Surface_s(face)
            quick = max(project_distance(os_, grid[k][0])[0] for k in (0, 112, 224))
            if quick > near:
                continue
            worst = max(project_distance(os_, p)[0] for p, _ in grid)
            cover = coverage(face, os_, ks)
            score = max(worst, cover)
            if best is None or score < best[0]:
                best = (score, worst, cover, face, os_)
        if best is None:
            failures.append(f"{step}: {s['id']}: no Open CASCADE face within {near:.1e} mm")
            continue
        _, worst, cover, face, os_ = best
        sign = -1.0 if face.Orientation() == TopAbs_REVERSED else 1.0
        flipped = 0
        for p, n in grid:
            d, a, b = project_distance(os_, p)
            props = GeomLProp_SLProps(os_, a, b, 1, 1e-9)
            if props.IsNormalDefined() and n.Magnitude() > 1e-12:
                on = props.Normal()
                if sign * (n.X() * on.X() + n.Y() * on.Y() + n.Z() * on.Z()) / n.Magnitude() < 0.999:
                    flipped += 1
        # A surface kerf approximates (an offset of a B-spline surface) is within the bound it
        # proved of the exact one, which Open CASCADE evaluates.
        own_tol = max(surface_tol, approx.get(s["id"], 0.0))
        if s["id"] in approx:
            print(f"  {step.name}: {s['id']}: {worst:.3e} mm from Open CASCADE's offset surface, within the bound kerf proved ({approx[s['id']]:.3e})")
        if worst > own_tol:
            failures.append(f"{step}: {s['id']}: {worst:.3e} mm from Open CASCADE's surface")
        # An IGES face's parameter-space curves are Open CASCADE's own (read.surfacecurve.mode
        # 3 builds them from the model-space curves by approximation), good to the tolerance it
        # gives the face's edges; its parameter box is no more exact than that.
        # At most COVER_TOL_CAP: a file whose edges Open CASCADE keeps only loosely checks
        # nothing looser than that.
        cover_tol = max(surface_tol, min(edge_tolerance(face), COVER_TOL_CAP)) if iges else surface_tol
        cover_tol = max(cover_tol, approx.get(s["id"], 0.0))
        if cover > cover_tol:
            failures.append(f"{step}: {s['id']}: misses part of Open CASCADE's face box by {cover:.3e} mm")
        elif cover > surface_tol:
            print(f"  {step.name}: {s['id']}: misses Open CASCADE's face box by {cover:.3e} mm, within {cover_tol:.1e} (its edges' tolerance, or the bound kerf proved)")
        if flipped:
            failures.append(f"{step}: {s['id']}: normal disagrees with Open CASCADE's face orientation at {flipped} of {len(grid)} grid points")


def edge_tolerance(face):
    """The largest tolerance Open CASCADE gives an edge of the face (the bound it keeps between
    an edge's 3D curve and its parameter-space curve on the face)."""
    tol = 0.0
    ex = TopExp_Explorer(face, TopAbs_EDGE)
    while ex.More():
        tol = max(tol, BRep_Tool.Tolerance_s(TopoDS.Edge(ex.Current())))
        ex.Next()
    return tol


def project_distance(surface, p):
    pr = GeomAPI_ProjectPointOnSurf(p, surface)
    if pr.NbPoints() == 0:
        return (math.inf, 0.0, 0.0)
    a, b = pr.LowerDistanceParameters()
    return (pr.LowerDistance(), a, b)


def uv_box(face):
    """The face's parameter box: the extremes of its boundary's parameter-space curves, sampled
    (400 intervals per edge). BRepTools.UVBounds is looser: it boxes the curves' poles, up to
    1.7e-3 of the parameter range beyond the boundary on pyiges' impeller."""
    lo, hi = [math.inf, math.inf], [-math.inf, -math.inf]
    ex = TopExp_Explorer(face, TopAbs_EDGE)
    while ex.More():
        c = BRepAdaptor_Curve2d(TopoDS.Edge(ex.Current()), face)
        ex.Next()
        a, b = c.FirstParameter(), c.LastParameter()
        for k in range(401):
            q = c.Value(a + (b - a) * k / 400)
            lo = [min(lo[0], q.X()), min(lo[1], q.Y())]
            hi = [max(hi[0], q.X()), max(hi[1], q.Y())]
    if not all(math.isfinite(x) for x in lo + hi):
        return BRepTools.UVBounds_s(face)
    return lo[0], hi[0], lo[1], hi[1]


def coverage(face, os_, ks):
    """How far the worst point of a 9 x 9 grid over the face's UV box is from kerf's surface."""
    fu0, fu1, fv0, fv1 = uv_box(face)
    cover = 0.0
    for i in range(9):
        for j in range(9):
            p = os_.Value(fu0 + (fu1 - fu0) * i / 8, fv0 + (fv1 - fv0) * j / 8)
            cover = max(cover, project_distance(ks, p)[0])
    return cover


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--kerf", default="target/release/kerf")
    ap.add_argument("--edges", action="store_true", help="import with --edges (face boundary loops)")
    ap.add_argument("--iges-tol", type=float, default=IGES_TOL, help="tolerance for IGES files, mm (default 1e-8)")
    ap.add_argument("--iges-mode", type=int, default=3, help="Open CASCADE's read.surfacecurve.mode for IGES (default 3)")
    ap.add_argument("files", nargs="+", type=Path)
    args = ap.parse_args()
    global SURFACE_CURVE_MODE
    SURFACE_CURVE_MODE = args.iges_mode
    failures = []
    counts = {"curves": 0, "edges": 0, "surfaces": 0}
    for f in args.files:
        before = len(failures)
        check_file(args.kerf, f, args.edges, failures, counts, args.iges_tol)
        print(f"{f}: {'ok' if len(failures) == before else 'FAILED'}")
    for m in failures:
        print("FAIL", m)
    total = counts["curves"] + counts["edges"] + counts["surfaces"]
    print(f"compared {counts['curves']} curves, {counts['edges']} Open CASCADE edges, {counts['surfaces']} surfaces")
    print(f"{total - len(failures)} passed, {len(failures)} failed")
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
