#!/usr/bin/python3
"""The head-check fixtures (docs/process.md, "The head along the cuts"), exact NURBS: planes of
degree 1, circles and the bend as rational quadratics (weights 1/sqrt 2 at the corners).

- fixtures/head_wall.json: a drawn box's floor with a vertical wall, two holes of radius 5 in
  the floor, one 47 mm from the wall's foot (its nearest point 42 mm from the wall: the default
  head's 45 mm body comes within 52 - 50 = 2 mm of the wall) and one far from it.
- fixtures/head_channel.json: a trim line along the floor of a U-channel 100 mm wide with walls
  40 mm high, 6 mm off the channel's middle: the 45 mm body passes 44 - 45 = -1 mm from the
  nearer wall (it cuts into it) with the beam upright; tilted away by 5 degrees or so it clears.
- fixtures/head_bend.json: a trim line along a 90-degree bend of inner radius 20 (15 degrees up
  it) between a floor and a vertical flange whose top is 33 mm above the floor: the beam along
  the bend's normal leans 15 degrees away from the flange, and the flange's top edge lies 27.4
  mm along the axis from the cutting point, above the body's bottom face (26 mm) and 22.7 mm
  from the axis (inside its 45 mm radius); leaning 7.5-10 degrees more brings the edge below
  the bottom face by the clearance (24.2 mm along at 22.5 degrees), while the other side of the
  body's bottom rim stays 5 mm above the floor.
- fixtures/head_slot.json: a hole of radius 3 at the bottom of a slot 10 mm wide with walls 30 mm
  high: the nozzle cone (14 mm across at its top, 25 mm above its tip) is wider than the slot,
  so no tilt clears it: refused by name."""
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


def write(name, doc):
    out = Path(__file__).resolve().parents[1] / "fixtures" / name
    out.write_text(json.dumps(doc, indent=1) + "\n")
    print(out)


def line(a, b):
    return {"degree": 1, "knots": [0, 0, 1, 1], "control_points": [a, b]}


write("head_wall.json", {
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
})

write("head_channel.json", {
    "format": "kerf.curves/1",
    "units": "mm",
    "curves": [
        {"id": "channel-trim", **line([6.0, -100.0, 0.0], [6.0, 100.0, 0.0]), "surface": "channel-floor"},
    ],
    "surfaces": [
        plane("channel-floor", [-50.0, -200.0, 0.0], [100.0, 0.0, 0.0], [0.0, 400.0, 0.0]),
        plane("channel-left", [-50.0, -200.0, 0.0], [0.0, 0.0, 40.0], [0.0, 400.0, 0.0]),
        plane("channel-right", [50.0, -200.0, 0.0], [0.0, 400.0, 0.0], [0.0, 0.0, 40.0]),
    ],
})

R = 20.0
H = 13.0
T = math.radians(15.0)
bend = {
    "type": "nurbs", "id": "bend", "degree_u": 2, "degree_v": 1,
    "knots_u": [0, 0, 0, 1, 1, 1], "knots_v": [0, 0, 1, 1],
    "control_points": [[[0.0, -200.0, 0.0], [0.0, 200.0, 0.0]],
                       [[R, -200.0, 0.0], [R, 200.0, 0.0]],
                       [[R, -200.0, R], [R, 200.0, R]]],
    "weights": [[1, 1], [W, W], [1, 1]],
}
write("head_bend.json", {
    "format": "kerf.curves/1",
    "units": "mm",
    "curves": [
        {"id": "bend-trim", **line([R * math.sin(T), -60.0, R - R * math.cos(T)], [R * math.sin(T), 60.0, R - R * math.cos(T)]), "surface": "bend"},
    ],
    "surfaces": [
        plane("bend-floor", [-150.0, -200.0, 0.0], [150.0, 0.0, 0.0], [0.0, 400.0, 0.0]),
        bend,
        plane("bend-flange", [R, -200.0, R], [0.0, 0.0, H], [0.0, 400.0, 0.0]),
    ],
})

write("head_slot.json", {
    "format": "kerf.curves/1",
    "units": "mm",
    "curves": [
        {"id": "hole-in-slot", **circle(0.0, 0.0, 3.0), "surface": "slot-floor", "scrap": "left"},
    ],
    "surfaces": [
        plane("slot-floor", [-5.0, -100.0, 0.0], [10.0, 0.0, 0.0], [0.0, 200.0, 0.0]),
        plane("slot-left", [-5.0, -100.0, 0.0], [0.0, 0.0, 30.0], [0.0, 200.0, 0.0]),
        plane("slot-right", [5.0, -100.0, 0.0], [0.0, 200.0, 0.0], [0.0, 0.0, 30.0]),
    ],
})
