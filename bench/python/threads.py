"""Solves in threads: the GIL is released while chetaev solves, so two threads run two solves at once.

Times a batch of solves of sympy's rolling disc (crates/chetaev-py/tests/models.py) to t = 5 at
rtol = atol = 1e-10, each with its own parameter value (the model converted once,
``with_parameters``), run alternately one after another in the main thread (A) and by a
``ThreadPoolExecutor`` with ``--threads`` workers (B); prints the machine, the median times and the
speed-up A / B. On a machine with at least that many idle cores, a speed-up near the thread count
says the solves ran in parallel; with the GIL held it would stay at 1.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np

import chetaev
from machine import machine

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "crates" / "chetaev-py" / "tests"))
import models  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rounds", type=int, default=7)
    ap.add_argument("--solves", type=int, default=16, help="solves per batch")
    ap.add_argument("--threads", type=int, default=2)
    args = ap.parse_args()

    d = models.rolling_disc()
    base = chetaev.Model.from_sympy(d["L"], d["q"], constraints=d["constraints"], parameters=d["parameters"])
    g = next(s for s in d["parameters"] if str(s) == "g")
    problems = [
        chetaev.Problem(base.with_parameters({g: value}), q0=d["q0"], qd0=d["qd0"])
        for value in np.linspace(9.0, 10.0, args.solves)
    ]

    def run(problem: chetaev.Problem) -> float:
        return chetaev.solve(problem, 5.0, rtol=1e-10, atol=1e-10, output="final").q[-1, 1]

    # Warm: a problem records its equations on its first solve and switches to machine code after
    # 10⁴ right-hand sides (about seven solves here); time only the final tier.
    for _ in range(12):
        sequential = [run(p) for p in problems]
    print(f"machine: {machine()}")
    a_times, b_times = [], []
    with ThreadPoolExecutor(max_workers=args.threads) as pool:
        for _ in range(args.rounds):
            start = time.perf_counter()
            a = [run(p) for p in problems]
            a_times.append(time.perf_counter() - start)
            start = time.perf_counter()
            b = list(pool.map(run, problems))
            b_times.append(time.perf_counter() - start)
            assert a == b == sequential  # the same numbers, whichever thread solved
    a, b = statistics.median(a_times), statistics.median(b_times)
    print(f"{args.solves} solves of the rolling disc: one thread {a * 1e3:.1f} ms, "
          f"{args.threads} threads {b * 1e3:.1f} ms (medians of {args.rounds}); speed-up {a / b:.2f}")
    print(f"after: {machine()}")


if __name__ == "__main__":
    main()
