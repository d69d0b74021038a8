#!/usr/bin/env python3
"""Two builds of the work-precision program against each other, row by row.

Run the base build and the head build in turn, each into its own directory (base, head, base,
head, ...), then give the directories in pairs:

    python3 bench/tools/two_trees.py BASE1 HEAD1 [BASE2 HEAD2 ...]

For every measured row (scene, method, tolerance or step count) present in both directories of a
pair whose error and number of right-hand sides are the same in both (so that the times are at
equal error and equal work), it prints, per scene and method, the geometric mean of head time /
base time over the rows of all pairs; it counts the rows it leaves out. The ode_solvers rows run code
that neither build changes: their spread is the noise of the machine.
"""

import collections
import csv
import glob
import math
import os
import sys


def rows(directory):
    out = {}
    for path in glob.glob(os.path.join(directory, "*.csv")):
        if os.path.basename(path) == "limit.csv":
            continue
        with open(path, newline="") as f:
            for r in csv.DictReader(f):
                if r.get("outcome") != "measured":
                    continue
                key = (r["scene"], r["method"], r["tolerance"], r["step"])
                out[key] = (float(r["seconds"]), r["error"], r["rhs_evaluations"])
    return out


def main(dirs):
    if len(dirs) < 2 or len(dirs) % 2:
        sys.exit(__doc__)
    logs = collections.defaultdict(list)
    differ, alone = 0, 0
    for base_dir, head_dir in zip(dirs[0::2], dirs[1::2]):
        base, head = rows(base_dir), rows(head_dir)
        alone += len(base.keys() ^ head.keys())
        for key, (t_base, e_base, n_base) in base.items():
            if key not in head:
                continue
            t_head, e_head, n_head = head[key]
            if (e_base, n_base) != (e_head, n_head):
                # Not at equal error or equal work: its time ratio would mean nothing.
                differ += 1
                continue
            logs[key[:2]].append(math.log(t_head / t_base))
    print(f"rows left out, their error or right-hand-side count differing: {differ}")
    print(f"rows left out, measured in one directory of a pair only: {alone}")
    print("| scene | method | head / base (geometric mean) | rows |")
    print("|---|---|---|---|")
    for (scene, method), v in sorted(logs.items()):
        print(f"| {scene} | {method} | {math.exp(sum(v) / len(v)):.3f} | {len(v)} |")
    own = [x for (_, m), v in logs.items() if "ode_solvers" not in m for x in v]
    if own:
        print(f"chetaev's rows together: {math.exp(sum(own) / len(own)):.3f} ({len(own)} rows)")


if __name__ == "__main__":
    main(sys.argv[1:])
