#!/usr/bin/env python3
"""CPU time of `kerf import` beside Open CASCADE's read-and-transfer of the same STEP or IGES
file, in one run (pip install cadquery-ocp).

    python3 benches/import_vs_occt.py --kerf target/release/kerf [--edges] FILE...

kerf: the whole `kerf import FILE -o OUT --json` process (read, faces, contours, the document
written), its user + system CPU from the operating system (`RUSAGE_CHILDREN`). Open CASCADE:
`STEPControl_Reader` / `IGESControl_Reader` `ReadFile` + `TransferRoots` in this process
(`time.process_time`), which builds its shapes but writes nothing. Each the fastest of
`--runs` (default 5). Prints one row per file and the ratio kerf / Open CASCADE.
"""

import argparse
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from OCP.OCP.IFSelect import IFSelect_RetDone
from OCP.OCP.IGESControl import IGESControl_Reader
from OCP.OCP.STEPControl import STEPControl_Reader


def kerf_cpu(kerf, path, edges, out):
    cmd = [kerf, "import", str(path), "-o", str(out), "--json"]
    if edges:
        cmd.append("--edges")
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    res = subprocess.run(cmd, capture_output=True, text=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if res.returncode != 0:
        raise SystemExit(f"{path}: kerf import failed: {res.stderr.strip()}")
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def occt_cpu(path):
    t0 = time.process_time()
    r = IGESControl_Reader() if path.suffix.lower() in (".igs", ".iges") else STEPControl_Reader()
    if r.ReadFile(str(path)) != IFSelect_RetDone:
        raise SystemExit(f"{path}: Open CASCADE cannot read it")
    r.TransferRoots()
    r.OneShape()
    return time.process_time() - t0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--kerf", default="target/release/kerf")
    ap.add_argument("--edges", action="store_true", help="import with --edges")
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("files", nargs="+", type=Path)
    args = ap.parse_args()
    print(f"| file | size | kerf import{' --edges' if args.edges else ''} CPU s | Open CASCADE read + transfer CPU s | kerf / OCCT |")
    print("|---|---:|---:|---:|---:|")
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "x.curves.json"
        for f in args.files:
            k = min(kerf_cpu(args.kerf, f, args.edges, out) for _ in range(args.runs))
            o = min(occt_cpu(f) for _ in range(args.runs))
            print(f"| `{f}` | {f.stat().st_size / 1024:.0f} KB | {k:.3f} | {o:.3f} | {k / o:.2f} |", flush=True)


if __name__ == "__main__":
    sys.exit(main())
