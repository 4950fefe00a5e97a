#!/usr/bin/env python3
"""Picks the inputs a fuzz run found worth keeping, within a byte budget.

    target/x86_64-unknown-linux-gnu/release/<target> -merge=1 -use_counters=0 \
        -merge_control_file=/tmp/mcf -max_len=65536 <seeds dir> <minimized run corpus>
    python3 pick_corpus.py /tmp/mcf 150000 > chosen     # then copy the files listed

The control file libFuzzer's merge writes lists, per input, the coverage edges it reaches
(`-use_counters=0`: edges, not hit-count buckets). The seeds (the first directory) are kept;
of the other inputs, the one reaching most edges not yet covered per byte is taken, until
nothing new is left or the budget (bytes) is spent. Statistics go to stderr.
"""
import os
import sys


def main():
    control, budget = sys.argv[1], int(sys.argv[2])
    lines = open(control).read().split("\n")
    n, n_first = int(lines[0]), int(lines[1])
    files = lines[2 : 2 + n]
    cov = {}
    for line in lines[2 + n :]:
        p = line.split()
        if p and p[0] == "COV":
            cov[int(p[1])] = set(p[2:])
    have = set().union(*(cov.get(i, set()) for i in range(n_first)))
    every = set().union(*cov.values())
    seeds = len(have)
    cand = {i: cov.get(i, set()) for i in range(n_first, n)}
    size = {i: max(1, os.path.getsize(files[i])) for i in cand}
    chosen, spent = [], 0
    while True:
        gain = {i: len(c - have) / size[i] for i, c in cand.items() if c - have}
        if not gain:
            break
        best = max(gain, key=lambda i: (gain[i], -i))
        if spent + size[best] > budget:
            del cand[best]
            continue
        spent += size[best]
        have |= cand.pop(best)
        chosen.append(best)
    print(
        f"seeds reach {seeds} edges, all inputs {len(every)}; kept {len(chosen)} inputs "
        f"({spent} bytes) reaching {len(have)}",
        file=sys.stderr,
    )
    for i in chosen:
        print(files[i])


if __name__ == "__main__":
    main()
