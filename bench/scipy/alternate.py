#!/usr/bin/env python3
"""Two builds of the chetaev side (`rust/`, binary `rodas4`) against each other: run alternately,
A B A B ..., each on the same core when `taskset` is available, with the same arguments.

For each method and tolerance prints the median over the rounds of each build's time, the ratio
new / old and the ratio in each round, and whether the two builds gave the same error and counters
(the binary prints the error to 7 digits).

Usage (build the old revision in a worktree first):
    git worktree add ../chetaev-old <rev>
    cargo build --release --manifest-path ../chetaev-old/bench/scipy/rust/Cargo.toml
    cargo build --release --manifest-path bench/scipy/rust/Cargo.toml
    python3 bench/scipy/alternate.py ../chetaev-old/bench/scipy/rust/target/release/rodas4 \\
        bench/scipy/rust/target/release/rodas4 --rounds 6 -- --runs 101 --tols 1e-4,1e-7,1e-10,1e-13
"""

import argparse
import csv
import io
import shutil
import statistics
import subprocess
import sys


def run(binary, args, core):
    cmd = (["taskset", "-c", core] if core is not None else []) + [binary] + args
    try:
        done = subprocess.run(cmd, capture_output=True, text=True)
    except OSError as e:
        sys.exit(f"alternate.py: cannot run {binary}: {e}; build it first (see the usage above)")
    if done.returncode != 0:
        sys.exit(f"alternate.py: {binary} failed ({done.returncode}): {done.stderr.strip()}")
    return list(csv.DictReader(io.StringIO(done.stdout)))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("old")
    ap.add_argument("new")
    ap.add_argument("--rounds", type=int, default=6)
    ap.add_argument("--core", default="1", help="the core for taskset (ignored without taskset)")
    argv = sys.argv[1:]
    split = argv.index("--") if "--" in argv else len(argv)
    a = ap.parse_args(argv[:split])
    a.args = argv[split + 1:]
    core = a.core if shutil.which("taskset") else None
    times, results = {}, {}
    for _ in range(a.rounds):
        for build, binary in (("old", a.old), ("new", a.new)):
            for row in run(binary, a.args, core):
                key = (row["solver"], row["tol"])
                times.setdefault(key, {}).setdefault(build, []).append(float(row["median_s"]))
                results.setdefault(key, set()).add((row["error"], row["rhs"], row["jac"], row["steps"]))
    print("| method | tol | old | new | new / old | per round | same results |")
    print("|---|---|---|---|---|---|---|")
    for (solver, tol), t in times.items():
        old, new = statistics.median(t["old"]), statistics.median(t["new"])
        rounds = " ".join(f"{n / o:.2f}" for o, n in zip(t["old"], t["new"]))
        same = len(results[(solver, tol)]) == 1
        print(f"| {solver} | {tol} | {old * 1e6:.1f} µs | {new * 1e6:.1f} µs | {new / old:.3f} | {rounds} | {same} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
