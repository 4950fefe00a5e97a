#!/usr/bin/env python3
"""kerf's feed plan against the time-optimal reference TOPP-RA, fixture by fixture.

For every fixture path (`kerf discretize -t 0.01 --normals`, `kerf post`) and feed:
  * kerf: `kerf interpolate <one path>.axes.json --feed F --cycle 0.001 --csv --json`, with the
    machine's jerk limits removed (acceleration-limited; once with the chord cap between
    set-points lifted, `--chord-tolerance 1`, the reference's formulation, once with kerf's
    default 0.001 mm) and with them (the shipped file);
  * reference: TOPP-RA (`pip install toppra`) on the axis positions of `kerf post` splined
    (scipy CubicSpline) against the tip's arc length, split at true corners (one-sided tangents,
    from the circles through the two neighbouring points on each side, turning by more than
    5 degrees), per-axis velocity and acceleration limits of the same machine file, the tip
    speed ds/dt <= F as one more constrained coordinate, rest to rest on every piece; a run of
    tip steps under 1e-6 mm (the tool axis turning in place at a crease) is a piece of its own,
    parametrized by the axes' distance, under the axis limits alone;
  * the CSV of every kerf run is checked independently: every cycle's velocity, acceleration and
    (with jerk limits) jerk by finite differences, at rest before and after, against the limits;
    and every set-point's tool tip (the A/C head's forward kinematics) against the polyline of
    the certified cutting points (largest distance, and where along the path), with and without
    the jerk-limited blend, and its tool axis against the poses' axes there (largest angle: the
    arc between the axes of the segment's two poses; the poses themselves are within the tilt
    tolerance of the normals).

Usage: python3 benches/plan_vs_toppra.py [--kerf target/release/kerf] [--feeds 6000,20000,40000]
       [--only sheet_metal_holes[,dome,...]] [--out bench-out]
Run it from the repository root (the fixture paths are relative). A fixture on two machines
(trim_panel) has its files named fixture.machine.* in the output directory.
Python is for this benchmark only; nothing in the library or the CLI uses it.
"""

import argparse
import copy
import json
import math
import os
import subprocess
import sys

import numpy as np

FIXTURES = [
    ("door_trim", "ac_head"),
    ("tube_saddle", "ac_head"),
    ("turbine_blade_edge", "gantry_ac"),
    ("sheet_metal_holes", "gantry_ac"),
    ("dome", "ac_head"),
    # Issue 26: a 1 m trim line over a domed panel near the pole, and a line over creases of
    # 10 to 40 degrees and up a vertical wall. Both fit the travel as modelled (no --place).
    ("trim_panel", "ac_head"),
    ("trim_panel", "gantry_ac"),
    ("trim_creases", "ac_head"),
]
CORNER_DEG = 5.0
STILL_MM = 1e-6  # a tip step this short is the tool axis turning in place


def run(cmd):
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed:\n{p.stderr}")
    return p.stdout


def circle_tangent(p, q, r, at_end):
    """Unit tangent at r (at_end) or at p of the circle through p, q, r; chord if collinear."""
    a, b = q - p, r - q
    n = np.cross(a, b)
    if np.linalg.norm(n) <= 1e-12 * np.linalg.norm(a) * np.linalg.norm(b):
        d = r - p
        return d / np.linalg.norm(d)
    # circumcentre
    u, v = q - p, r - p
    w = np.cross(u, v)
    c = p + (np.cross(v, w) * u.dot(u) + np.cross(w, u) * v.dot(v)) / (2 * w.dot(w))
    e3 = n / np.linalg.norm(n)
    point = r if at_end else p
    t = np.cross(e3, point - c)
    return t / np.linalg.norm(t)


def corners(tips):
    """Indices of the true corners (rest points) of a polyline of cutting points."""
    out = []
    n = len(tips)
    for i in range(1, n - 1):
        left = (
            circle_tangent(tips[i - 2], tips[i - 1], tips[i], True)
            if i >= 2 and 0.5 <= np.linalg.norm(tips[i - 1] - tips[i - 2]) / max(np.linalg.norm(tips[i] - tips[i - 1]), 1e-300) <= 2
            else (tips[i] - tips[i - 1]) / np.linalg.norm(tips[i] - tips[i - 1])
        )
        right = (
            circle_tangent(tips[i], tips[i + 1], tips[i + 2], False)
            if i + 2 < n and 0.5 <= np.linalg.norm(tips[i + 2] - tips[i + 1]) / max(np.linalg.norm(tips[i + 1] - tips[i]), 1e-300) <= 2
            else (tips[i + 1] - tips[i]) / np.linalg.norm(tips[i + 1] - tips[i])
        )
        if left.dot(right) < math.cos(math.radians(CORNER_DEG)):
            out.append(i)
    return out


def toppra_piece(q, ss, vl, al):
    """TOPP-RA duration of one piece, rest to rest: coordinates q against the parameter ss."""
    import toppra as ta
    import toppra.algorithm as algo
    import toppra.constraint as constraint

    if len(ss) == 2:
        q = np.vstack([q[0], 0.5 * (q[0] + q[1]), q[1]])
        ss = np.array([0.0, 0.5 * ss[-1], ss[-1]])
    path = ta.SplineInterpolator(ss, q, bc_type="not-a-knot")
    pc_v = constraint.JointVelocityConstraint(np.column_stack([-vl, vl]))
    pc_a = constraint.JointAccelerationConstraint(np.column_stack([-al, al]))
    n = int(max(100, min(20000, ss[-1] / 0.1)))
    grid = np.linspace(0, ss[-1], n + 1)
    inst = algo.TOPPRA([pc_v, pc_a], path, gridpoints=grid, parametrizer="ParametrizeConstAccel")
    traj = inst.compute_trajectory(0, 0)
    if traj is None:
        raise RuntimeError("TOPP-RA failed")
    return traj.duration


def toppra_time(pos, tips, vmax, amax, feed):
    """TOPP-RA duration of one path, at rest at its ends, at every true corner and around every
    turn of the tool axis in place."""
    import toppra as ta

    ta.setup_logging("WARNING")
    vl = np.array(list(vmax) + [feed])
    al = np.array(list(amax) + [1e12])
    seg = np.linalg.norm(np.diff(tips, axis=0), axis=1)
    # The tool axis turning in place (at a crease: the tip still, the axes moving; kerf post
    # writes these steps as 1e-8 mm or 0): the tip's arc length cannot parametrize them, so each
    # run of still steps is a piece of its own, rest to rest, parametrized by the axes' own
    # distance (mm and degrees), under the axes' limits only.
    still = seg <= STILL_MM
    total = 0.0
    i, n = 0, len(seg)
    while i < n:
        j = i
        while j < n and still[j] == still[i]:
            j += 1
        if still[i]:
            d = np.linalg.norm(np.diff(pos[i : j + 1], axis=0), axis=1)
            k = np.concatenate([[True], d > 1e-9])
            sq = np.concatenate([[0.0], np.cumsum(d[d > 1e-9])])
            if sq[-1] > 0:
                total += toppra_piece(pos[i : j + 1][k], sq, vl[:-1], al[:-1])
        else:
            p, t = pos[i : j + 1], tips[i : j + 1]
            s = np.concatenate([[0.0], np.cumsum(seg[i:j])])
            cuts = [0] + corners(t) + [len(t) - 1]
            for a, b in zip(cuts[:-1], cuts[1:]):
                ss = s[a : b + 1] - s[a]
                if ss[-1] <= 0:
                    continue
                # the tip's arc length is a 6th coordinate
                total += toppra_piece(np.column_stack([p[a : b + 1], ss]), ss, vl, al)
        i = j
    return total


def check_csv(path, vmax, amax, jmax, cycle):
    """Cycles over any limit (> 1 + 1e-9), from the set-points CSV alone."""
    q = np.loadtxt(path, delimiter=",", skiprows=1)[:, 1:]
    q = np.vstack([q[:1], q[:1], q, q[-1:], q[-1:]])
    v = np.diff(q, axis=0) / cycle
    a = np.diff(q, 2, axis=0) / cycle**2
    j = np.diff(q, 3, axis=0) / cycle**3
    over = int((np.abs(v) > np.array(vmax) * (1 + 1e-9)).any(axis=1).sum())
    over += int((np.abs(a) > np.array(amax) * (1 + 1e-9)).any(axis=1).sum())
    worst = [float((np.abs(v) / vmax).max()), float((np.abs(a) / amax).max()), 0.0]
    if jmax is not None:
        over += int((np.abs(j) > np.array(jmax) * (1 + 1e-9)).any(axis=1).sum())
        worst[2] = float((np.abs(j) / jmax).max())
    return over, worst


def tips_of(q, kin):
    """Tool tips of set-points [X, Y, Z, A, C] of an A/C head (paper 000 eq 16 inverted:
    x = X - r_a sin A sin C + r_c cos C, y = Y + r_a sin A cos C + r_c sin C, z = Z - r_a cos A)."""
    ra, rc = kin["r_a"], kin["r_c"]
    a, c = np.radians(q[:, 3]), np.radians(q[:, 4])
    return np.column_stack([
        q[:, 0] - ra * np.sin(a) * np.sin(c) + rc * np.cos(c),
        q[:, 1] + ra * np.sin(a) * np.cos(c) + rc * np.sin(c),
        q[:, 2] - ra * np.cos(a),
    ])


def axes_of(q):
    """Tool axes (unit, from the tip towards the head) of set-points of an A/C head."""
    a, c = np.radians(q[:, 3]), np.radians(q[:, 4])
    return np.column_stack([np.sin(a) * np.sin(c), -np.sin(a) * np.cos(c), np.cos(a)])


def arc_angle(v, u0, u1):
    """Angle (rad) of unit vectors v [m, 3] from the great-circle arcs u0 -> u1 [n, 3]: [m, n]."""
    n = np.cross(u0, u1)
    nn = np.linalg.norm(n, axis=1)
    ends = np.minimum(np.arccos(np.clip(v @ u0.T, -1, 1)), np.arccos(np.clip(v @ u1.T, -1, 1)))
    nh = n / np.maximum(nn, 1e-300)[:, None]
    vn = v @ nh.T  # [m, n]
    w = v[:, None, :] - vn[:, :, None] * nh[None, :, :]
    inside = ((np.cross(u0[None], w) * nh[None]).sum(2) >= 0) & ((np.cross(w, u1[None]) * nh[None]).sum(2) >= 0)
    onarc = np.arctan2(np.abs(vn), np.linalg.norm(w, axis=2))
    return np.where(inside & (nn[None, :] > 1e-12), np.minimum(onarc, ends), ends)


def polyline_distance(points, poly, axes=None, pose_axes=None):
    """Largest distance of `points` from the polyline `poly` (brute force over its segments), and
    the arc length along `poly` of the point nearest the farthest one. With `axes` (the
    set-points' tool axes) and `pose_axes` (the poses'), also the largest angle (degrees) of a
    set-point's axis from the poses' axes where it is (the arc between the two ends' axes of the
    segments within 1 um of the nearest, so that a turn in place counts as one place), and the
    arc length there."""
    a, b = poly[:-1], poly[1:]
    d = b - a
    dd = np.maximum((d * d).sum(axis=1), 1e-300)
    s0 = np.concatenate([[0.0], np.cumsum(np.sqrt(dd))])[:-1]
    worst, at, worst_ang, ang_at = 0.0, 0.0, 0.0, 0.0
    idx = np.arange(len(points))
    for chunk in np.array_split(idx, max(1, len(points) // 2000)):
        w = points[chunk][:, None, :] - a[None, :, :]
        t = np.clip((w * d[None, :, :]).sum(axis=2) / dd[None, :], 0.0, 1.0)
        r = w - t[:, :, None] * d[None, :, :]
        n2 = (r * r).sum(axis=2)
        k = n2.argmin(axis=1)
        dist = np.sqrt(n2[np.arange(len(k)), k])
        i = int(dist.argmax())
        if dist[i] > worst:
            worst, at = float(dist[i]), float(s0[k[i]] + t[i, k[i]] * np.sqrt(dd[k[i]]))
        if axes is not None:
            near = np.sqrt(n2) <= dist[:, None] + 1e-3
            ang = np.where(near, arc_angle(axes[chunk], pose_axes[:-1], pose_axes[1:]), np.inf).min(axis=1)
            i = int(ang.argmax())
            if ang[i] > worst_ang:
                worst_ang, ang_at = float(ang[i]), float(s0[k[i]] + t[i, k[i]] * np.sqrt(dd[k[i]]))
    if axes is None:
        return worst, at
    return worst, at, math.degrees(worst_ang), ang_at


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--kerf", default="target/release/kerf")
    ap.add_argument("--feeds", default="6000,20000,40000")
    ap.add_argument("--only", default="", help="comma-separated fixture names")
    ap.add_argument("--out", default="bench-out")
    ap.add_argument("--cycle", type=float, default=0.001)
    args = ap.parse_args()
    feeds = [float(f) for f in args.feeds.split(",")]
    os.makedirs(args.out, exist_ok=True)
    rows = []
    only = set(filter(None, args.only.split(",")))
    for fixture, mname in FIXTURES:
        if only and fixture not in only:
            continue
        # The first machine of a fixture keeps the old file names; a second one adds its name.
        tag = fixture if [m for f, m in FIXTURES if f == fixture][0] == mname else f"{fixture}.{mname}"
        mfile = f"fixtures/machines/{mname}.json"
        machine = json.load(open(mfile))
        names = list(machine["max_velocity"].keys())
        vmax = np.array([machine["max_velocity"][k] / 60.0 for k in names])
        amax = np.array([machine["max_acceleration"][k] for k in names])
        jmax = np.array([machine["max_jerk"][k] for k in names]) if "max_jerk" in machine else None
        nojerk = copy.deepcopy(machine)
        nojerk.pop("max_jerk", None)
        nojerk_file = os.path.join(args.out, f"{mname}-nojerk.json")
        json.dump(nojerk, open(nojerk_file, "w"))
        tp = os.path.join(args.out, f"{fixture}.toolpath.json")
        axes = os.path.join(args.out, f"{tag}.axes.json")
        run([args.kerf, "discretize", f"fixtures/{fixture}.json", "-t", "0.01", "--normals", "-o", tp])
        # Issue 26's trim lines with the 1-degree tilt cone they were made for (the default
        # is the exact normal).
        tilt = ["--tilt-tolerance", "1"] if fixture.startswith("trim_") else []
        run([args.kerf, "post", tp, "--machine", mfile, "-o", axes, *tilt])
        doc = json.load(open(axes))
        for p in doc["paths"]:
            one = dict(doc)
            one["paths"] = [p]
            pfile = os.path.join(args.out, f"{tag}.{p['id']}.axes.json")
            json.dump(one, open(pfile, "w"))
            pos = np.array(p["positions"], dtype=float)
            tips = np.array(p["poses"], dtype=float)[:, :3]
            pose_axes = np.array(p["poses"], dtype=float)[:, 3:]
            pose_axes /= np.linalg.norm(pose_axes, axis=1)[:, None]
            length = float(np.linalg.norm(np.diff(tips, axis=0), axis=1).sum())
            for feed in feeds:
                ref = toppra_time(pos, tips, vmax, amax, feed / 60.0)
                res = {}
                # "free": the chord cap between set-points lifted, as in the reference's
                # formulation; "acc" and "jerk": kerf's defaults (chord 0.001 mm).
                for label, mf, jl, chord in [("free", nojerk_file, None, "1.0"),
                                             ("acc", nojerk_file, None, "0.001"),
                                             ("jerk", mfile, jmax, "0.001")]:
                    if label == "jerk" and jmax is None:
                        continue
                    csv = os.path.join(args.out, f"{tag}.{p['id']}.{int(feed)}.{label}.csv")
                    out = run([args.kerf, "interpolate", pfile, "-m", mf, "--feed", str(feed),
                               "--cycle", str(args.cycle), "--chord-tolerance", chord,
                               "--csv", csv, "--json"])
                    summary = json.loads(out)
                    over, worst = check_csv(csv, vmax, amax, jl, args.cycle)
                    st = summary["paths"][0] if summary.get("paths") else {}
                    # The set-points' tips against the certified polyline of cutting points.
                    rows_q = np.loadtxt(csv, delimiter=",", skiprows=1)[:, 1:]
                    dev, dev_at, ang, ang_at = polyline_distance(
                        tips_of(rows_q, machine["kinematics"]), tips, axes_of(rows_q), pose_axes)
                    res[label] = (summary["duration_s"], over, worst, st.get("length_share_at_feed", 0.0),
                                  dev, summary.get("blend_deviation_mm", 0.0), dev_at, ang, ang_at)
                a, fr = res["acc"], res["free"]
                line = (f"{fixture:18s} {mname:9s} {p['id']:18s} {length:7.1f} mm {feed:6.0f}  ref {ref:7.3f} s  "
                        f"kerf {fr[0]:7.3f} s = {fr[0] / ref:5.3f} x  over {fr[1]}  | chord 1 um {a[0]:7.3f} s = {a[0] / ref:5.3f} x"
                        f"  at feed {100 * a[3]:5.1f} %  over {a[1]}")
                if "jerk" in res:
                    j = res["jerk"]
                    line += (f"  | jerk {j[0]:7.3f} s = {j[0] / a[0]:5.3f} x  at feed {100 * j[3]:5.1f} %  over {j[1]} (j {j[2][2]:.3f})"
                             f"  | from polyline {1000 * a[4]:.1f} / {1000 * j[4]:.1f} um (at {a[6]:.1f} / {j[6]:.1f} mm), blend {1000 * j[5]:.1f} um"
                             f"  | axis from poses {fr[7]:.2f} / {a[7]:.2f} / {j[7]:.2f} deg (at {fr[8]:.1f} / {a[8]:.1f} / {j[8]:.1f} mm)")
                print(line, flush=True)
                rows.append(dict(fixture=fixture, machine=mname, path=p["id"], length=length, feed=feed, ref=ref,
                                 free=fr[0], free_over=fr[1], acc=a[0], acc_over=a[1], acc_worst=a[2], acc_share=a[3],
                                 jerk=res.get("jerk", (None,))[0],
                                 jerk_over=res.get("jerk", (0, 0))[1],
                                 jerk_share=res.get("jerk", (0, 0, 0, 0))[3],
                                 acc_dev=a[4], acc_dev_at=a[6], jerk_dev=res.get("jerk", (0,) * 7)[4],
                                 jerk_dev_at=res.get("jerk", (0,) * 7)[6],
                                 free_axis_deg=fr[7], free_axis_at=fr[8], acc_axis_deg=a[7], acc_axis_at=a[8],
                                 jerk_axis_deg=res.get("jerk", (0,) * 9)[7], jerk_axis_at=res.get("jerk", (0,) * 9)[8],
                                 jerk_blend=res.get("jerk", (0,) * 7)[5]))
    json.dump(rows, open(os.path.join(args.out, "plan_vs_toppra.json"), "w"), indent=1)
    worst_ratio = max(r["free"] / r["ref"] for r in rows)
    best_ratio = min(r["free"] / r["ref"] for r in rows)
    worst_chord = max(r["acc"] / r["ref"] for r in rows)
    long_jerk = [r["jerk"] / r["acc"] for r in rows if r["jerk"] and r["length"] > 100]
    print(f"kerf / TOPP-RA (acceleration-limited, no chord cap): {best_ratio:.3f} .. {worst_ratio:.3f}")
    print(f"kerf with its 1 um chord cap / TOPP-RA: up to {worst_chord:.3f}")
    if long_jerk:
        print(f"jerk-limited / acceleration-limited on paths > 100 mm: up to {max(long_jerk):.3f}")
    print(f"cycles over a limit: {sum(r['free_over'] + r['acc_over'] + r['jerk_over'] for r in rows)}")
    print(f"set-points from the polyline of cutting points: acceleration-limited up to "
          f"{1000 * max(r['acc_dev'] for r in rows):.1f} um, jerk-limited (blended) up to "
          f"{1000 * max(r['jerk_dev'] for r in rows):.1f} um; blend up to "
          f"{1000 * max(r['jerk_blend'] for r in rows):.1f} um")
    print(f"set-points' tool axis from the poses': up to "
          f"{max(max(r['free_axis_deg'], r['acc_axis_deg'], r['jerk_axis_deg']) for r in rows):.2f} deg")


if __name__ == "__main__":
    main()
