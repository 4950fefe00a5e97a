#!/usr/bin/env python3
"""Instructions of a callgrind profile by the kerf function that executed them, inlining resolved.

The discretizer's walk inlines nearly everything into one function per degree, so
`callgrind_annotate` charges most instructions to `Walker::piece_v3`. This script reads a
profile taken with `--dump-instr=yes`, asks `addr2line -i` for the inline chain of every
instruction address, and charges each instruction's count to the innermost frame that is a kerf
function (`kerf_*`), so `Certifier::eval`, `Step::new` or `Taylor::error` get their own share
even where they were inlined. With `--lines FUNCTION`, also the source lines of the functions
whose name contains FUNCTION.

Self cost only: the line after a `calls=` record (a callee's inclusive cost) is skipped.

Usage (from the repository root):

    cargo build --release --example discretize_time
    valgrind --tool=callgrind --dump-instr=yes --callgrind-out-file=/tmp/cg.out \\
        --toggle-collect='kerf_discretize::discretize' \\
        target/release/examples/discretize_time /tmp/deg3.json 0.01 1
    python3 benches/callgrind_by_function.py /tmp/cg.out \\
        target/release/examples/discretize_time [--lines piece_of]
"""

import argparse
import collections
import subprocess


def self_cost_by_address(path):
    """Instruction counts per address (self cost) from a callgrind file with instr positions."""
    cost = collections.Counter()
    addr = 0
    skip = False
    with open(path) as f:
        for line in f:
            line = line.rstrip("\n")
            if not line:
                continue
            if line.startswith("calls="):
                skip = True
                continue
            if line[0] not in "+-*0123456789":
                continue
            parts = line.split()
            if len(parts) < 2:
                continue
            pos, count = parts[0], parts[-1]
            if pos.startswith("0x"):
                addr = int(pos, 16)
            elif pos.startswith("+"):
                addr += int(pos[1:])
            elif pos.startswith("-"):
                addr -= int(pos[1:])
            if skip:
                skip = False
                continue
            cost[addr] += int(count)
    return cost


def inline_chains(binary, addrs):
    """For each address, its inline chain [(function, file:line), ...], innermost first."""
    out = subprocess.run(
        ["addr2line", "-a", "-i", "-f", "-C", "-e", binary] + [hex(a) for a in addrs],
        capture_output=True,
        text=True,
        check=True,
    ).stdout.split("\n")
    chains = {}
    cur = None
    i = 0
    while i < len(out):
        line = out[i]
        if line.startswith("0x"):
            cur = int(line, 16)
            chains[cur] = []
            i += 1
        elif cur is not None and i + 1 < len(out):
            chains[cur].append((line, out[i + 1].split(" ")[0]))
            i += 2
        else:
            i += 1
    return chains


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("profile")
    ap.add_argument("binary")
    ap.add_argument("--lines", help="also list the source lines of functions containing this")
    ap.add_argument("--top", type=int, default=30)
    args = ap.parse_args()
    cost = self_cost_by_address(args.profile)
    chains = inline_chains(args.binary, sorted(cost))
    total = sum(cost.values())
    by_fn = collections.Counter()
    by_line = collections.Counter()
    for addr, count in cost.items():
        chain = chains.get(addr) or [("?", "?")]
        fn, where = next(((f, w) for f, w in chain if f.startswith("kerf")), chain[0])
        by_fn[fn] += count
        if args.lines and args.lines in fn:
            by_line[where] += count
    print(f"{total:,} instructions")
    for fn, count in by_fn.most_common(args.top):
        print(f"{count:14,d} {100 * count / total:5.1f} %  {fn}")
    if args.lines:
        print(f"-- lines of functions containing {args.lines!r}")
        for where, count in by_line.most_common(args.top):
            print(f"{count:14,d} {100 * count / total:5.1f} %  {where}")


if __name__ == "__main__":
    main()
