#!/usr/bin/env python3
"""Draws docs/architecture.svg from the code as it is.

Upper half: the data flow of `kerf run` (the stages of crates/kerf-pipeline/src/stages.rs, the
crate that does each, the files between them and the commands that run a stage alone). Lower
half: the crate dependency graph read from `cargo metadata` (each crate's [dependencies] on
other workspace crates, an arrow from the user to the crate used), crates layered by their
longest chain of dependencies so that every arrow points down.

    python3 scripts/architecture_svg.py > docs/architecture.svg

tests/doc_links.rs checks that the picture names every crate of the workspace.
"""

import json
import subprocess
import sys
from html import escape

# The stages of a run, in order: (crate, what it does, the function of stages.rs or the
# command that runs it alone).
STAGES = [
    ("kerf-step / kerf-iges", ["STEP or IGES in: contours and", "their faces as exact NURBS"], "kerf import; Job::from_cad"),
    ("kerf-format", ["read and check every value", "(kerf-io: bounded, atomic I/O)"], "kerf validate"),
    ("kerf-discretize", ["cutting points, chord error", "proven per segment"], "stages::discretize"),
    ("kerf-normals", ["surface normal per point,", "normal-step insertion"], "stages::orient"),
    ("kerf-process", ["scrap side, kerf offset, start,", "leads, order, head, traverses"], "plan_cuts, solve, programs"),
    ("kerf-kinematics", ["placement, inverse kinematics,", "limits, pole, non-linearity"], "stages::place, solve; kerf post"),
    ("kerf-interp", ["fit, feed plan within every", "axis limit, G-code (8 dialects)"], "stages::programs; kerf gcode"),
    ("kerf-view / kerf-plot", ["3D view, picture,", "typed report"], "stages::output; kerf view"),
]

FILES_IN = ["curves.json (kerf.curves/1)", "part.step / part.igs", "machine.json (kerf.machine/1)", "technology.json (optional)"]
FILES_OUT = ["toolpath.json (kerf.toolpath/1)", "axes.json (kerf.axes/1)", "program.nc, setpoints.csv", "report.json, plot.svg, view.html"]


def metadata():
    out = subprocess.run(
        ["cargo", "metadata", "--format-version", "1", "--no-deps"],
        check=True, capture_output=True, text=True,
    ).stdout
    m = json.loads(out)
    names = {p["name"] for p in m["packages"]}
    deps = {}
    for p in m["packages"]:
        deps[p["name"]] = sorted({d["name"] for d in p["dependencies"] if d["name"] in names and d["kind"] is None})
    return deps


def reduced(deps):
    """The edges no longer chain implies (a -> c left out where a -> ... -> b -> c)."""

    def reach(n, seen):
        for d in deps[n]:
            if d not in seen:
                seen.add(d)
                reach(d, seen)
        return seen

    out = {}
    for n, ds in deps.items():
        implied = set()
        for d in ds:
            implied |= reach(d, set())
        out[n] = [d for d in ds if d not in implied]
    return out


def layers(deps):
    depth = {}

    def d(n):
        if n not in depth:
            depth[n] = 0 if not deps[n] else 1 + max(d(x) for x in deps[n])
        return depth[n]

    for n in deps:
        d(n)
    top = max(depth.values())
    rows = [[] for _ in range(top + 1)]
    for n, k in depth.items():
        rows[top - k].append(n)
    return [sorted(r) for r in rows]


def text(x, y, s, size=12, weight="normal", anchor="middle", fill="#222"):
    return f'<text x="{x:.1f}" y="{y:.1f}" font-size="{size}" font-weight="{weight}" text-anchor="{anchor}" fill="{fill}">{escape(s)}</text>'


def main():
    deps = metadata()
    width = 1280
    out = []
    # Upper half: the data flow.
    box_w, box_h, gap = 142, 96, 12
    x0, y0 = 20, 120
    out.append(text(width / 2, 30, "kerf: the stages of a run, the files between them, and the crates", 18, "bold"))
    out.append(text(x0, 62, "in: " + "  |  ".join(FILES_IN), 12, anchor="start"))
    out.append(text(x0, 82, "kerf run (kerf_pipeline::Job::run): the crates that do the work, in data-flow order, with the functions of stages.rs (and the commands) that call them:", 12, anchor="start", fill="#555"))
    for i, (crate, lines, cmd) in enumerate(STAGES):
        x = x0 + i * (box_w + gap)
        out.append(f'<rect x="{x}" y="{y0}" width="{box_w}" height="{box_h}" rx="6" fill="#eef4fb" stroke="#4a77a8"/>')
        out.append(text(x + box_w / 2, y0 + 20, crate, 12, "bold"))
        for j, l in enumerate(lines):
            out.append(text(x + box_w / 2, y0 + 40 + 15 * j, l, 10))
        out.append(text(x + box_w / 2, y0 + box_h - 10, cmd, 9, fill="#7a4a00"))
        if i + 1 < len(STAGES):
            ax = x + box_w
            out.append(f'<line x1="{ax}" y1="{y0 + box_h / 2}" x2="{ax + gap}" y2="{y0 + box_h / 2}" stroke="#4a77a8" stroke-width="2" marker-end="url(#arrow)"/>')
    out.append(text(x0, y0 + box_h + 26, "out (all or nothing, one directory): " + "  |  ".join(FILES_OUT), 12, anchor="start"))
    out.append(text(x0, y0 + box_h + 46, "kerf check and kerf plot read any toolpath independently (kerf-check never uses the discretizer).", 12, anchor="start", fill="#555"))
    # Lower half: the crate dependencies.
    top = y0 + box_h + 90
    out.append(text(width / 2, top, "Crate dependencies (cargo metadata; an arrow points to the crate used; an arrow a longer chain implies is left out)", 14, "bold"))
    rows = layers(deps)
    row_h, cw, ch = 86, 132, 30
    pos = {}
    for r, row in enumerate(rows):
        y = top + 30 + r * row_h
        span = len(row) * cw + (len(row) - 1) * 16
        x = (width - span) / 2
        for n in row:
            pos[n] = (x, y)
            x += cw + 16
    for n, ds in sorted(reduced(deps).items()):
        x, y = pos[n]
        for dname in ds:
            dx, dy = pos[dname]
            out.append(f'<line x1="{x + cw / 2:.1f}" y1="{y + ch:.1f}" x2="{dx + cw / 2:.1f}" y2="{dy:.1f}" stroke="#9aa" stroke-width="1" marker-end="url(#arrow-grey)"/>')
    for n, (x, y) in sorted(pos.items()):
        out.append(f'<rect x="{x:.1f}" y="{y:.1f}" width="{cw}" height="{ch}" rx="5" fill="#fff" stroke="#333"/>')
        out.append(text(x + cw / 2, y + 19, n, 12, "bold"))
    height = int(top + 30 + len(rows) * row_h + 10)
    head = (
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" viewBox="0 0 {width} {height}" font-family="sans-serif">\n'
        '<defs><marker id="arrow" viewBox="0 0 10 10" refX="9" refY="5" markerWidth="7" markerHeight="7" orient="auto"><path d="M0,0 L10,5 L0,10 z" fill="#4a77a8"/></marker>'
        '<marker id="arrow-grey" viewBox="0 0 10 10" refX="9" refY="5" markerWidth="6" markerHeight="6" orient="auto"><path d="M0,0 L10,5 L0,10 z" fill="#9aa"/></marker></defs>\n'
        f'<rect width="{width}" height="{height}" fill="#fff"/>\n'
    )
    sys.stdout.write(head + "\n".join(out) + "\n</svg>\n")


if __name__ == "__main__":
    main()
