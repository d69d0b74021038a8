#!/usr/bin/env python3
"""LSODA (lsoda.py) against chetaev's Rodas4 or Rodas5P (`--method`; rust/, binary `rodas4`) at equal
error.

The two are separate processes, so they are run alternately, A B A B ...: each round runs the
Rodas4 program once (every tolerance) and then lsoda.py once (every tolerance and variant). A
program's time for a tolerance in one round is the median of its own repeated solves; the time
reported is the median of those over the rounds, with the range over the rounds beside it.

Equal error: each code's points (error, time), sorted by error, are interpolated linearly in
(log error, log time); a code has a value at an error only between its smallest and largest
measured error (no extrapolation). The ratios are taken at each decade of error that every code
compared covers, and, per round, from that round's times (the range over the rounds is given).

Usage: nice -n 10 python3 compare.py [--rounds 7] [--method rodas5p] [--out results/run.csv]
Build the Rust side first: cargo build --release --manifest-path rust/Cargo.toml
"""

import argparse
import csv
import io
import math
import os
import statistics
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))


def run_csv(cmd):
    out = subprocess.run(cmd, check=True, capture_output=True, text=True)
    if out.stderr.strip():
        print(out.stderr.strip(), file=sys.stderr)
    return list(csv.DictReader(io.StringIO(out.stdout)))


def interp(points, e):
    """log-time at error e by linear interpolation in (log e, log t); None outside the range."""
    pts = sorted((math.log10(pe), math.log10(pt)) for pe, pt in points)
    le = math.log10(e)
    if not pts or le < pts[0][0] or le > pts[-1][0]:
        return None
    for (e0, t0), (e1, t1) in zip(pts, pts[1:]):
        if e0 <= le <= e1:
            if e1 == e0:
                return 10 ** min(t0, t1)
            return 10 ** (t0 + (t1 - t0) * (le - e0) / (e1 - e0))
    return 10 ** pts[0][1]  # a single point exactly at e


def fmt_t(s):
    if s is None:
        return "–"
    if s < 1e-3:
        return f"{s * 1e6:.0f} µs" if s >= 1e-4 else f"{s * 1e6:.1f} µs"
    return f"{s * 1e3:.2f} ms"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rounds", type=int, default=7)
    ap.add_argument("--t-end", default="999.9")
    ap.add_argument("--lsoda-tols", default="1e-4,1e-5,1e-6,1e-7,1e-8,1e-9,1e-10,1e-11,1e-12,1e-13")
    ap.add_argument("--method", default="rodas4", help="chetaev's methods, comma-separated (rodas4, rodas5p); the first is the reference of the ratios")
    ap.add_argument("--rust-tols", "--rodas4-tols", dest="rust_tols",
                    default="1e-4,1e-5,1e-6,1e-7,1e-8,1e-9,1e-10,1e-11,1e-12")
    ap.add_argument("--variants", default="lsoda,lsoda_jac,odeint")
    ap.add_argument("--python-runs", default="51", help="timed solves per tolerance in lsoda.py")
    ap.add_argument("--rust-runs", default="201", help="timed solves per tolerance in rodas4")
    ap.add_argument("--rust-min-batch-ms", default="0", help="0: each solve timed on its own, as in lsoda.py")
    ap.add_argument("--rodas4", default=os.path.join(HERE, "rust", "target", "release", "rodas4"))
    ap.add_argument("--out", default=None, help="CSV of every round's numbers")
    a = ap.parse_args()

    cmd_a = [a.rodas4, "--method", a.method, "--t-end", a.t_end, "--tols", a.rust_tols, "--runs", a.rust_runs,
             "--min-batch-ms", a.rust_min_batch_ms]
    cmd_b = [sys.executable, os.path.join(HERE, "lsoda.py"), "--t-end", a.t_end, "--tols", a.lsoda_tols,
             "--runs", a.python_runs, "--variants", a.variants]

    rows = []  # every round's rows
    for r in range(a.rounds):
        for name, cmd in (("A", cmd_a), ("B", cmd_b)):
            t0 = time.perf_counter()
            for row in run_csv(cmd):
                row["round"] = r
                rows.append(row)
            print(f"round {r + 1}/{a.rounds} {name} {time.perf_counter() - t0:.1f} s", file=sys.stderr)

    if a.out:
        os.makedirs(os.path.dirname(os.path.abspath(a.out)), exist_ok=True)
        with open(a.out, "w", newline="") as f:
            keys = ["round", "solver", "tol", "error", "abs_error", "median_s", "runs", "batch", "rhs", "jac", "steps",
                    "rejected"]
            w = csv.DictWriter(f, fieldnames=keys)
            w.writeheader()
            w.writerows(rows)

    solvers = []
    for row in rows:
        if row["solver"] not in solvers:
            solvers.append(row["solver"])
    # per solver: tol -> (error, [time per round], counters)
    data = {s: {} for s in solvers}
    for row in rows:
        d = data[row["solver"]].setdefault(float(row["tol"]), {"error": float(row["error"]), "times": {}, "row": row})
        if float(row["error"]) != d["error"]:
            print(f"warning: {row['solver']} tol {row['tol']}: error differs between rounds", file=sys.stderr)
        d["times"][row["round"]] = float(row["median_s"])

    print("## Points (time: median over rounds [min–max of the round medians])\n")
    print("| code | tol | error (scaled) | error (abs) | time | round range | RHS | Jacobians | steps |")
    print("|---|---|---|---|---|---|---|---|---|")
    for s in solvers:
        for tol, d in sorted(data[s].items(), reverse=True):
            ts = list(d["times"].values())
            row = d["row"]
            print(f"| {s} | {tol:.0e} | {d['error']:.2e} | {float(row['abs_error']):.2e} | "
                  f"{fmt_t(statistics.median(ts))} | {fmt_t(min(ts))}–{fmt_t(max(ts))} | {row['rhs']} | {row['jac']} | "
                  f"{row['steps']} |")

    def curve(s, rnd=None):
        return [(d["error"], statistics.median(d["times"].values()) if rnd is None else d["times"][rnd])
                for d in data[s].values() if rnd is None or rnd in d["times"]]

    ref = a.method.split(",")[0].strip()
    others = [s for s in solvers if s != ref]
    levels = []
    for k in range(0, 16):
        e = 10.0 ** -k
        if interp(curve(ref), e) is not None and any(interp(curve(s), e) is not None for s in others):
            levels.append(e)
    rounds = sorted({row["round"] for row in rows})

    print(f"\n## At equal error (time interpolated; ratio = other / {ref}, median-of-rounds curves "
          "[range of the per-round ratios])\n")
    head = "| error | " + " | ".join(f"{s} time" for s in others) + f" | {ref} time | " + \
        " | ".join(f"{s} / {ref}" for s in others) + " |"
    print(head)
    print("|" + "---|" * (2 + 2 * len(others)))
    for e in levels:
        tr = interp(curve(ref), e)
        cells = [fmt_t(interp(curve(s), e)) for s in others]
        ratios = []
        for s in others:
            to = interp(curve(s), e)
            if to is None:
                ratios.append("–")
                continue
            per = [interp(curve(s, r), e) / interp(curve(ref, r), e) for r in rounds
                   if interp(curve(s, r), e) is not None and interp(curve(ref, r), e) is not None]
            ratios.append(f"{to / tr:.1f} [{min(per):.1f}–{max(per):.1f}]")
        print(f"| {e:.0e} | " + " | ".join(cells) + f" | {fmt_t(tr)} | " + " | ".join(ratios) + " |")

    print(f"\n## At each {ref} point (other's time interpolated at {ref}'s error)\n")
    print(f"| {ref} tol | error | {ref} time | " + " | ".join(f"{s} / {ref}" for s in others) + " |")
    print("|" + "---|" * (3 + len(others)))
    for tol, d in sorted(data[ref].items(), reverse=True):
        tr = statistics.median(d["times"].values())
        cells = []
        for s in others:
            to = interp(curve(s), d["error"])
            cells.append("–" if to is None else f"{to / tr:.1f}")
        print(f"| {tol:.0e} | {d['error']:.2e} | {fmt_t(tr)} | " + " | ".join(cells) + " |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
