#!/usr/bin/python3
"""fixtures/head_wall.json: a drawn box's floor with a vertical wall, two holes of radius 5 in
the floor, one 47 mm from the wall's foot (its nearest point 42 mm from the wall: the default
head's 45 mm body comes within 52 - 50 = 2 mm of the wall) and one far from it. Exact NURBS:
planes of degree 1, circles as rational quadratics (weights 1/sqrt 2 at the corners)."""
import json
import math
from pathlib import Path

W = math.sqrt(0.5)


def circle(cx, cy, r):
    pts = [(1, 0), (1, 1), (0, 1), (-1, 1), (-1, 0), (-1, -1), (0, -1), (1, -1), (1, 0)]
    return {
        "degree": 2,
        "knots": [0, 0, 0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1, 1, 1],
        "control_points": [[cx + r * x, cy + r * y, 0.0] for x, y in pts],
        "weights": [1, W, 1, W, 1, W, 1, W, 1],
    }


def plane(id_, origin, u, v):
    o = origin
    return {
        "type": "nurbs", "id": id_, "degree_u": 1, "degree_v": 1,
        "knots_u": [0, 0, 1, 1], "knots_v": [0, 0, 1, 1],
        "control_points": [[o, [o[k] + v[k] for k in range(3)]],
                           [[o[k] + u[k] for k in range(3)], [o[k] + u[k] + v[k] for k in range(3)]]],
    }


doc = {
    "format": "kerf.curves/1",
    "units": "mm",
    "curves": [
        {"id": "hole-near-wall", **circle(0.0, 0.0, 5.0), "surface": "floor", "scrap": "left"},
        {"id": "hole-far", **circle(-120.0, 0.0, 5.0), "surface": "floor", "scrap": "left"},
    ],
    "surfaces": [
        plane("floor", [-200.0, -200.0, 0.0], [252.0, 0.0, 0.0], [0.0, 400.0, 0.0]),
        plane("wall", [52.0, -200.0, 0.0], [0.0, 400.0, 0.0], [0.0, 0.0, 60.0]),
    ],
}
out = Path(__file__).resolve().parents[1] / "fixtures" / "head_wall.json"
out.write_text(json.dumps(doc, indent=1) + "\n")
print(out)
