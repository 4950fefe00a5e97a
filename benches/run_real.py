#!/usr/bin/env python3
"""`kerf run --place auto` on every real part, with the CPU time of each stage.

    python3 benches/run_real.py [--kerf target/release/kerf] [--machine fixtures/machines/gantry_ac.json]
                                [--runs 3] [--threads N] [FILE ...]

Without FILE: every real part shipped in the repository (`fixtures/realdata/*.json`,
`fixtures/realdata/step/*.stp`), the STEP files of `../shared/realdata/step/` that are not
shipped, and the IGES copies in `target/iges-real/` when they exist
(`python3 scripts/make_iges_fixtures.py target/iges-real fixtures/realdata/step/*.stp`).
STEP and IGES parts run with `--edges` (sheet recognition: each feature cut once).

For each file, the fastest of `--runs` whole `kerf run` processes by wall time: its wall time,
its user + system CPU from the operating system (`wait4`), and the per-stage CPU times of that
run's `report.json` (`timings`, docs/formats.md; its wall times are there too). Prints the load average before and
after, since the machine is shared: read the figures with it. `--threads N` sets
`RAYON_NUM_THREADS` (default: rayon's, one thread per core).

Python is for this benchmark only; nothing in the library or the CLI uses it.
"""

import argparse
import glob
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

# The stages shown as columns (the rest are summed into "other").
STAGES = ["read", "discretize", "normals", "sides", "place", "cuts", "kinematics", "traverses", "plan", "gcode", "view", "report", "write"]


def default_files():
    files = sorted(glob.glob("fixtures/realdata/*.json")) + sorted(glob.glob("fixtures/realdata/step/*.stp"))
    shipped = {Path(f).name for f in files}
    files += [f for f in sorted(glob.glob("../shared/realdata/step/*.stp")) if Path(f).name not in shipped]
    files += sorted(glob.glob("target/iges-real/*.igs"))
    return files


def run_once(kerf, path, machine, out, env):
    cmd = [kerf, "run", path, "-m", machine, "--place", "auto", "--out", out, "-q"]
    if not path.endswith(".json"):
        cmd.append("--edges")
    t0 = time.perf_counter()
    # Standard error to a file, not a pipe: wait4 must not wait on a child blocked writing.
    with tempfile.TemporaryFile() as errf:
        proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=errf, env=env)
        _, status, usage = os.wait4(proc.pid, 0)
        wall = time.perf_counter() - t0
        errf.seek(0)
        err = errf.read().decode(errors="replace")
    code = os.waitstatus_to_exitcode(status)
    if code != 0:
        raise SystemExit(f"{path}: kerf run exited {code}: {err.strip()}")
    with open(os.path.join(out, "report.json")) as f:
        report = json.load(f)
    return wall, usage.ru_utime + usage.ru_stime, report


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--kerf", default="target/release/kerf")
    ap.add_argument("--machine", default="fixtures/machines/gantry_ac.json")
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--threads", type=int)
    ap.add_argument("files", nargs="*")
    args = ap.parse_args()
    files = args.files or default_files()
    if not files:
        raise SystemExit("no real part found (run from the repository root)")
    env = dict(os.environ)
    if args.threads:
        env["RAYON_NUM_THREADS"] = str(args.threads)
    load0 = os.getloadavg()
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for k, path in enumerate(files):
            best = None
            for r in range(args.runs):
                out = os.path.join(tmp, f"{k}-{r}")
                res = run_once(args.kerf, path, args.machine, out, env)
                if best is None or res[0] < best[0]:
                    best = res
            rows.append((path, *best))
    load1 = os.getloadavg()
    print(f"load average before {load0[0]:.2f}, after {load1[0]:.2f}; {os.cpu_count()} cores; "
          f"RAYON_NUM_THREADS={env.get('RAYON_NUM_THREADS', 'default')}; fastest of {args.runs} by wall time; "
          f"machine {args.machine}")
    print()
    print("| file | contours | motion s | wall s | CPU s | " + " | ".join(STAGES) + " | other |")
    print("|---|---:|---:|---:|---:|" + "---:|" * (len(STAGES) + 1))
    for path, wall, cpu, report in rows:
        stages = {s["stage"]: s for s in report["timings"]["stages"]}
        shown = [stages.get(s, {}).get("cpu_s", 0.0) for s in STAGES]
        other = sum(s["cpu_s"] for name, s in stages.items() if name not in STAGES)
        contours = report["discretize"]["curves"]
        motion = report["interpolation"]["duration_s"]
        print(f"| `{path}` | {contours} | {motion:.1f} | {wall:.3f} | {cpu:.3f} | "
              + " | ".join(f"{v:.3f}" for v in shown) + f" | {other:.3f} |")
    slow = max(rows, key=lambda r: r[1])
    print()
    print(f"slowest: {slow[0]} {slow[1]:.3f} s wall")
    return 0


if __name__ == "__main__":
    sys.exit(main())
