"""A fresh problem's first solve, by each choice of `machine_code`.

Sympy's rolling disc (crates/chetaev-py/tests/models.py) to t = 5, converted once. Each round makes
a fresh `chetaev.Problem` with `machine_code="never"`, `"auto"` and `"at_once"` in turn and solves
it once (recording its equations and any compiling included), timed in Python; prints the median
of each over the rounds and the right-hand sides of a solve. `"never"` is what a first solve
shorter than 10^4 right-hand sides did before machine code was made when it pays.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import chetaev
from machine import machine

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "crates" / "chetaev-py" / "tests"))
import models  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rounds", type=int, default=15)
    ap.add_argument("--tols", default="1e-10,1e-12")
    args = ap.parse_args()
    print(machine())
    d = models.rolling_disc()
    model = chetaev.Model.from_sympy(d["L"], d["q"], constraints=d["constraints"], parameters=d["parameters"])
    for tol in (float(t) for t in args.tols.split(",")):
        times: dict[str, list[float]] = {"never": [], "auto": [], "at_once": []}
        for _ in range(args.rounds):
            for choice, samples in times.items():
                start = time.perf_counter()
                problem = chetaev.Problem(model, d["q0"], d["qd0"], machine_code=choice)
                sol = chetaev.solve(problem, 5.0, rtol=tol, atol=tol)
                samples.append(time.perf_counter() - start)
        medians = ", ".join(f"{k} {statistics.median(v) * 1e3:.2f} ms" for k, v in times.items())
        print(f"rtol = atol = {tol:g}, {sol.stats['rhs_evaluations']} right-hand sides: {medians}")


if __name__ == "__main__":
    main()
