#!/usr/bin/python3
"""Program forms tried on the tilted-head fixture in LinuxCNC's simulator (docs/linuxcnc.md).

    /usr/bin/python3 tests/linuxcnc/experiments.py [--out DIR]

Each variant is one simulator run of tube_saddle on ac_head (and the flat part for contrast);
the figures (time LinuxCNC / kerf, tip deviation, accelerations) go to DIR/experiments.json.
Not part of CI (about two minutes); the assertions of check.py are reported, not enforced.
"""
import json
import re
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import check  # noqa: E402

VARIANTS = [
    # (tag, fixture, machine, kerf args, [TRAJ] lines, program edit)
    ("-default", "tube_saddle", "ac_head", (), (), None),
    ("-blend0.02", "tube_saddle", "ac_head", ("--blend-tolerance", "0.02"), (), None),
    ("-g61", "tube_saddle", "ac_head", (), (), lambda t: re.sub(r"G64 P\S+ Q0", "G61", t)),
    ("-lin0.02", "tube_saddle", "ac_head", ("--linearization-tolerance", "0.02"), (), None),
    ("-depth200", "tube_saddle", "ac_head", (), ("ARC_BLEND_OPTIMIZATION_DEPTH = 200",), None),
    ("-noarcblend", "tube_saddle", "ac_head", (), ("ARC_BLEND_ENABLE = 0",), None),
    ("-t0.05", "tube_saddle", "ac_head", ("-t", "0.05"), (), None),
    ("-t0.002", "tube_saddle", "ac_head", ("-t", "0.002"), (), None),
    ("-normalstep4", "tube_saddle", "ac_head", ("--max-normal-step", "4"), (), None),
    ("-normalstep4-t0.05", "tube_saddle", "ac_head", ("--max-normal-step", "4", "-t", "0.05"), (), None),
    # Negative control: the motion-synchronized codes. M62 acts at the start of the next move, so
    # the dwell runs with the beam off; the last M63 has no move after it and never fires.
    ("-m62m63", "tube_saddle", "ac_head", (), (),
     lambda t: t.replace("M64 P0", "M62 P0").replace("M65 P0", "M63 P0")),
    ("-door", "door_trim", "ac_head", (), (), None),
    ("-door-blend0.001", "door_trim", "ac_head", ("--blend-tolerance", "0.001"), (), None),
    ("-door-g61", "door_trim", "ac_head", (), (), lambda t: re.sub(r"G64 P\S+ Q0", "G61", t)),
    ("-flat-default", "sheet_metal_holes", "gantry_ac", (), (), None),
]


def main():
    args = sys.argv[1:]
    out = Path(args[args.index("--out") + 1]) if "--out" in args else Path(tempfile.mkdtemp(prefix="kerf-lcnc-exp-"))
    out.mkdir(parents=True, exist_ok=True)
    root = check.ROOT
    b = check.run(["cargo", "build", "--release", "-p", "kerf-cli", "--bin", "kerf", "--example", "lcnc_measure"], cwd=root)
    if b.returncode != 0:
        print(b.stderr)
        return 1
    kerf = root / "target" / "release" / "kerf"
    measure = root / "target" / "release" / "examples" / "lcnc_measure"
    rows = []
    only = args[args.index("--only") + 1:] if "--only" in args else None
    for tag, fixture, machine, extra, traj, edit in VARIANTS:
        if only and tag not in only:
            continue
        fig = check.simulate(kerf, measure, fixture, machine, False, out, tag, extra, traj, edit)
        if fig:
            fig.pop("per_cut", None)
            rows.append(fig)
    (out / "experiments.json").write_text(json.dumps(rows, indent=2))
    print(f"{'variant':<16} {'time_s':>8} {'kerf_s':>8} {'ratio':>6} {'dev_mm':>8} {'budget':>7} {'acc_rapid':>9} {'acc_cut':>8}")
    for r in rows:
        print(f"{r['fixture'][:5] + r['variant']:<16} {r['linuxcnc_time_s']:8.3f} {r['kerf_predicted_s']:8.3f} "
              f"{r['time_ratio']:6.3f} {r['max_deviation_beam_on_mm']:8.5f} {r['tolerance_budget_mm']:7.3f} "
              f"{max(r['max_acceleration_ratio_rapids'].values()):9.3f} {max(r['max_acceleration_ratio_cuts'].values()):8.3f} tip max {r['max_tip_speed_beam_on_mm_per_min']:.0f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
