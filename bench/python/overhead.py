"""The cost of the Python door: a solve called from Python against the same solve timed in Rust.

Two scenes, each converted once from sympy: the paper's particle (m = 1, g = 10, v0 = 10, from
(0, 5) with velocity (10, 0)) to its impact, a solve of some ten microseconds where the call's own
cost shows most; and sympy's rolling disc (crates/chetaev-py/tests/models.py) to t = 5. Then,
alternately in one process (A, B, A, B, ...):

  A  ``chetaev.solve(problem, ...)`` called from Python and the impact time read from the solution,
     timed in Python (``time.perf_counter``) around each batch of calls;
  B  the same problem, method and options solved by ``chetaev::solve`` inside Rust, timed there
     (``chetaev._chetaev._solve_seconds``): no Python call, no conversion of arguments or results.

Both run the same steps, so they are at equal error by construction (the printed step counts and
impact times are the same). Prints the machine, its load, and per tolerance the median time per
solve of each and the ratio A / B over the rounds.
"""

from __future__ import annotations

import argparse
import statistics
import time

import sympy as sp
from sympy.physics.mechanics import dynamicsymbols

import chetaev
from machine import machine
from chetaev import _chetaev

import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "crates", "chetaev-py", "tests"))




def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rounds", type=int, default=11)
    ap.add_argument("--batch", type=int, default=200, help="solves per timed batch")
    ap.add_argument("--tols", default="1e-10,1e-11,1e-12")
    ap.add_argument("--method", default="dop853")
    args = ap.parse_args()

    x, y = dynamicsymbols("x y")
    m, g, v0 = sp.symbols("m g v0")
    L = m * (x.diff() ** 2 + y.diff() ** 2) / 2 - m * g * y
    f = x.diff() ** 2 + y.diff() ** 2 - v0**2
    model = chetaev.Model.from_sympy(L, [x, y], constraints=[f], parameters={m: 1, g: 10, v0: 10})
    particle = chetaev.Problem(model, q0=[0, 5], qd0=[10, 0])
    impact = chetaev.Event("impact", y, direction="falling", terminal=True)

    import models  # the rolling disc of sympy's tests

    d = models.rolling_disc()
    disc_model = chetaev.Model.from_sympy(d["L"], d["q"], constraints=d["constraints"], parameters=d["parameters"])
    disc = chetaev.Problem(disc_model, q0=d["q0"], qd0=d["qd0"])

    print(f"machine: {machine()}")
    print(f"chetaev {chetaev.__version__}, method {args.method}, {args.rounds} rounds")
    print("| scene | tol | steps | Python [µs/solve] | Rust [µs/solve] | Python / Rust (median, min–max over rounds) |")
    print("|---|---|---|---|---|---|")
    scenes = [("particle to impact", particle, 10.0, [impact], args.batch), ("rolling disc to t = 5", disc, 5.0, [], max(1, args.batch // 50))]
    for name, problem, t_end, events, batch in scenes:
        for tol in (float(t) for t in args.tols.split(",")):
            kw = dict(method=args.method, rtol=tol, atol=tol, events=events)
            # Warm: the first solve records the equations, and after 10⁴ right-hand sides a problem
            # switches to machine code; both sides are timed in that final tier.
            for _ in range(12):
                warm = chetaev.solve(problem, t_end, **kw)
            _chetaev._solve_seconds(problem, t_end, 3, **kw)
            a_times, b_times, ratios = [], [], []
            for _ in range(args.rounds):
                start = time.perf_counter()
                for _ in range(batch):
                    sol = chetaev.solve(problem, t_end, **kw)
                    last = sol.events[0].t if events else sol.t[-1]
                a = (time.perf_counter() - start) / batch
                b = sum(_chetaev._solve_seconds(problem, t_end, batch, **kw)) / batch
                a_times.append(a)
                b_times.append(b)
                ratios.append(a / b)
            assert last == (warm.events[0].t if events else warm.t[-1])
            print(
                f"| {name} | {tol:g} | {warm.stats['accepted_steps']} | {statistics.median(a_times) * 1e6:.1f} "
                f"| {statistics.median(b_times) * 1e6:.1f} | {statistics.median(ratios):.3f} ({min(ratios):.3f}–{max(ratios):.3f}) |"
            )
    print(f"load after: {machine().split('; ')[1]}")


if __name__ == "__main__":
    main()
