#!/usr/bin/env python3
"""Linearising the Carvallo–Whipple bicycle from Python: problem.linearize() and chetaev.complete.

Model: models.whipple_bicycle() of crates/chetaev-py/tests/models.py, the benchmark bicycle of
Meijaard et al. (2007): 8 coordinates, 4 rolling constraints, 1 holonomic constraint, converted
once with chetaev.Model.from_sympy before anything is timed.

Timed, each over --rounds rounds after one untimed call (median, min and max):

  1. problem.linearize() at upright straight running at --v m/s, the independent coordinates all
     but the pitch and the independent speeds roll rate, rear-wheel rate, steer rate (given), and
     with both chosen by pivoting (automatic): the exact Jacobian of the reduced equations by
     automatic differentiation, the tangent basis, A_z (10 × 10) and its eigen-decomposition;
  2. chetaev.complete(model, q, qd, coordinates=..., speeds=...) at a leaning, steered state
     (roll 0.2 rad, steer 0.3 rad, roll rate 0.1 rad/s, steer rate -0.2 rad/s, rear wheel at
     v / r_R): from a guess whose dependent values (the pitch; x', y', yaw rate, pitch rate,
     front-wheel rate) are 10% off the completed ones, and, for comparison, from the completed
     state itself (Newton's method then only checks the residual). The number of Newton
     iterations is not exposed to Python (the Rust Completion has it): only times are reported.

The printed eigenvalues are a check that the run linearised what it should: at 4.6 m/s the four
non-zero ones are the benchmark's weave pair, capsize and castor eigenvalues.

No numbers are recorded here: they are whatever a run prints on your machine.

Usage:
  python3 bench/python/linearize.py                 # 101 rounds at 4.6 m/s
  python3 bench/python/linearize.py --rounds 1001 --v 5
"""

from __future__ import annotations

import argparse
import gc
import platform
import statistics
import sys
import time
from pathlib import Path
from typing import Any, Callable

import numpy as np
import sympy as sp

import chetaev
from machine import machine

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "crates" / "chetaev-py" / "tests"))
import models  # noqa: E402

COORDINATES = ["x", "y", "psi", "phi", "theta_R", "delta", "theta_F"]  # all but the pitch
SPEEDS = ["phi_dot", "theta_R_dot", "delta_dot"]


def timed(call: Callable[[], Any], rounds: int) -> tuple[Any, list[float]]:
    """One untimed call, then `rounds` timed ones (seconds each); the last result."""
    result = call()
    times = []
    gc.collect()
    for _ in range(rounds):
        start = time.perf_counter()
        result = call()
        times.append(time.perf_counter() - start)
    return result, times


def row(name: str, times: list[float]) -> str:
    us = [1e6 * s for s in times]
    return f"| {name} | {statistics.median(us):.1f} | {min(us):.1f} | {max(us):.1f} |"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rounds", type=int, default=101, help="timed calls per row")
    ap.add_argument("--v", type=float, default=4.6, help="forward speed [m/s]")
    args = ap.parse_args()

    print(f"machine: {machine()}")
    print(f"python {platform.python_version()}, sympy {sp.__version__}, numpy {np.__version__}, "
          f"chetaev {chetaev.__version__}")

    start = time.perf_counter()
    bike = models.whipple_bicycle()
    model = chetaev.Model.from_sympy(bike["L"], bike["q"], constraints=bike["constraints"],
                                     holonomic=bike["holonomic"], parameters=bike["parameters"])
    q0, qd0 = bike["upright"](args.v)
    problem = chetaev.Problem(model, q0, qd0)
    print(f"model built, converted and its upright state at v = {args.v} m/s made in "
          f"{time.perf_counter() - start:.2f} s (not timed below); model.operations = "
          f"{model.operations}")
    print()

    lin, given = timed(lambda: problem.linearize(coordinates=COORDINATES, speeds=SPEEDS), args.rounds)
    auto_lin, auto = timed(lambda: problem.linearize(), args.rounds)

    # The leaning, steered state, completed once; the guess is 10% off in every dependent value.
    guess_q = np.zeros(8)
    guess_q[[models.BIKE_ROLL, models.BIKE_STEER]] = [0.2, 0.3]
    guess_qd = np.zeros(8)
    guess_qd[[models.BIKE_ROLL, models.BIKE_REAR, models.BIKE_STEER]] = [
        0.1, args.v / models.WHIPPLE_PARAMETERS["r_R"], -0.2]
    exact_q, exact_qd = chetaev.complete(model, guess_q, guess_qd, coordinates=COORDINATES,
                                         speeds=SPEEDS)
    dependent_speeds = [models.BIKE_X, models.BIKE_Y, models.BIKE_YAW, models.BIKE_PITCH,
                        models.BIKE_FRONT]
    off_q, off_qd = exact_q.copy(), exact_qd.copy()
    off_q[models.BIKE_PITCH] *= 1.1
    off_qd[dependent_speeds] *= 1.1

    def complete_from(q: np.ndarray, qd: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return chetaev.complete(model, q, qd, coordinates=COORDINATES, speeds=SPEEDS)

    (done_q, done_qd), from_guess = timed(lambda: complete_from(off_q, off_qd), args.rounds)
    _, from_exact = timed(lambda: complete_from(exact_q, exact_qd), args.rounds)
    _, problem_complete = timed(
        lambda: chetaev.Problem(model, off_q, off_qd, independent_coordinates=COORDINATES,
                                independent_speeds=SPEEDS), args.rounds)
    _, problem_plain = timed(lambda: chetaev.Problem(model, exact_q, exact_qd), args.rounds)

    print(f"{args.rounds} timed calls per row (after one untimed):")
    print("| call | median [µs] | min [µs] | max [µs] |")
    print("|---|---|---|---|")
    print(row("problem.linearize(coordinates=..., speeds=...)", given))
    print(row("problem.linearize() (independent ones by pivoting)", auto))
    print(row("chetaev.complete(...) from the guess 10% off", from_guess))
    print(row("chetaev.complete(...) from the completed state", from_exact))
    print(row("chetaev.Problem(..., independent_coordinates=..., independent_speeds=...) from the guess", problem_complete))
    print(row("chetaev.Problem(...) at the completed state (no completion)", problem_plain))
    print()

    np.set_printoptions(precision=12, linewidth=110)
    order = np.argsort(np.abs(lin.eigenvalues))
    print(f"linearize at v = {args.v} m/s: states {lin.states}; cyclic {lin.cyclic}")
    print(f"  the four non-zero eigenvalues: {lin.eigenvalues[order[6:]]}")
    print(f"  the six others, |λ| at most {np.abs(lin.eigenvalues[order[:6]]).max():.1e}")
    print(f"  automatic choice: states {auto_lin.states}; the same eigenvalues to "
          f"{np.abs(np.sort_complex(auto_lin.eigenvalues) - np.sort_complex(lin.eigenvalues)).max():.1e}")
    print(f"complete: pitch {exact_q[models.BIKE_PITCH]:.15f} rad at roll 0.2, steer 0.3; from the "
          f"guess 10% off, max |Δq| = {np.abs(done_q - exact_q).max():.1e}, "
          f"max |Δq̇| = {np.abs(done_qd - exact_qd).max():.1e} from the first completion")
    *_, info = chetaev.complete(model, off_q, off_qd, coordinates=COORDINATES, speeds=SPEEDS,
                                info=True)
    print(f"  Newton iterations from the guess 10% off (to a relative residual of 1e-14): "
          f"{info['coordinate_iterations']} for the pitch, {info['speed_iterations']} for the five "
          f"dependent speeds")


if __name__ == "__main__":
    main()
