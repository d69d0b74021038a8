#!/usr/bin/env python3
"""Time ratio of two methods at equal error, from a CSV of the work-precision program
(`cargo run --release -p chetaev-bench --bin work-precision -- --out DIR`, files `DIR/<scene>.csv`).

Each method's measured points (error, seconds) are sorted by error and interpolated linearly in
(log error, log time); a ratio is printed at each decade of error that both cover.

Usage: python3 bench/tools/equal_error.py docs/performance/stiff.csv Rodas4 Rodas5P
"""

import csv
import math
import sys


def curve(rows, method):
    points = []
    for r in rows:
        if r["method"] == method and r["error"] and r["seconds"]:
            e, t = float(r["error"]), float(r["seconds"])
            if e > 0 and t > 0:
                points.append((e, t))
    return sorted(points)


def at(points, e):
    for (e0, t0), (e1, t1) in zip(points, points[1:]):
        if e0 <= e <= e1 and e0 < e1:
            f = (math.log(e) - math.log(e0)) / (math.log(e1) - math.log(e0))
            return math.exp(math.log(t0) + f * (math.log(t1) - math.log(t0)))
    return None


def main():
    if len(sys.argv) != 4:
        print(__doc__, file=sys.stderr)
        return 2
    path, a, b = sys.argv[1:]
    try:
        with open(path, newline="") as f:
            rows = list(csv.DictReader(f))
    except OSError as e:
        print(f"cannot read {path}: {e}; write it with the work-precision program (see above)",
              file=sys.stderr)
        return 1
    if rows and not {"method", "error", "seconds"} <= rows[0].keys():
        print(f"{path} is not a CSV of the work-precision program (columns method, error, seconds)",
              file=sys.stderr)
        return 1
    ca, cb = curve(rows, a), curve(rows, b)
    if not ca or not cb:
        print(f"no measured points of {a!r} or {b!r} in {path}", file=sys.stderr)
        return 1
    print(f"| error | {a} | {b} | {a} / {b} |")
    print("|---|---|---|---|")
    for k in range(1, 16):
        e = 10.0 ** -k
        ta, tb = at(ca, e), at(cb, e)
        if ta is not None and tb is not None:
            print(f"| 1e-{k} | {ta * 1e6:.1f} µs | {tb * 1e6:.1f} µs | {ta / tb:.2f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
