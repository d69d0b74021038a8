#!/usr/bin/env python3
"""Converting a large sympy model: the Carvallo–Whipple bicycle, timed through Model.from_sympy.

Model: models.whipple_bicycle() of crates/chetaev-py/tests/models.py (imported from there, so
that the model exists once), the benchmark bicycle of Meijaard, Papadopoulos, Ruina and Schwab
(2007), "Linearized dynamics equations for the balance and steer of a bicycle: a benchmark and
review", Proc. R. Soc. A 463, 1955–1982, built with sympy.physics.mechanics in Lagrangian form.
Its four rigid bodies are the rear wheel R, the rear frame B (with rider), the front frame H (fork
and handlebar) and the front wheel F, with the parameters of the paper's Table 1. The coordinates follow Moore's
formulation (Moore, Hubbard, Kooijman, Schwab 2010), eight of them:

    q = [x, y, psi, phi, theta, theta_R, delta, theta_F]
         rear contact point on the ground, yaw, roll, pitch (of the rear frame),
         rear-wheel spin, steer, front-wheel spin

with the ground frame N having N.z up (Meijaard and Moore put z down; so here y points left, the
steer angle and the yaw rate have the opposite sign, and a wheel rolling forward spins at +v/r).
The Lagrangian is me.Lagrangian(N, *bodies) with the gravity potentials m g z. Rolling without
slip is four velocity constraints, linear in q̇: the horizontal velocity of each wheel's material
point at its contact is zero. The front wheel touching the ground is one holonomic constraint
h(q) = 0 (it fixes the pitch given roll and steer); the rear contact is on the ground by
construction. 8 coordinates − 1 − 4 constraints: 3 degrees of freedom (roll, steer, rear-wheel
spin), as in the paper.

The script
  1. builds the model in sympy (timed, not part of the conversion time), and an expanded copy
     (sympy.expand of L, the constraints and h: a much larger tree, several thousand distinct
     operations);
  2. times chetaev.Model.from_sympy on each over --rounds rounds (first, min, median, max) and
     prints model.operations beside the size of the sympy expressions: count_ops(L), the nodes of
     L's, the constraints' and h's trees (preorder_traversal, repeats counted) and the distinct
     subtrees among them;
  3. builds the upright initial state (roll = steer = 0, the pitch solved from h = 0 by Newton,
     rear-wheel spin rate v/rR, the dependent speeds solved from the constraints), constructs
     chetaev.Problem (a ChetaevError is printed as it is) and solves 1 s of upright, straight
     running at v = 4.6 m/s with rtol = atol = 1e-8, printing the final roll and the status;
  4. as a check of the model, starts it again with a small roll rate (--roll-rate, 0.01 rad/s)
     and compares roll and steer over the second with the paper's linearised equations
     M q̈ + v C1 q̇ + (g K0 + v² K2) q = 0 (the published M, C1, K0, K2); the difference is second
     order in the perturbation.

No numbers are recorded here: they are whatever a run prints on your machine.

Usage:
  python3 bench/python/convert.py                  # 7 rounds
  python3 bench/python/convert.py --rounds 21 --v 4.6 --roll-rate 0.01
"""

from __future__ import annotations

import argparse
import gc
import platform
import statistics
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np
import sympy as sp
from scipy.integrate import solve_ivp

import chetaev
from machine import machine

# ---------------------------------------------------------------------------------------------
# The model: the bicycle of the package's tests (crates/chetaev-py/tests/models.py)
# ---------------------------------------------------------------------------------------------

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "crates" / "chetaev-py" / "tests"))
import models  # noqa: E402

TABLE_1 = models.WHIPPLE_PARAMETERS  # Meijaard et al. (2007), Table 1, in the model's axes

# The linearised equations in roll and steer, M q̈ + v C1 q̇ + (g K0 + v² K2) q = 0, with the
# matrices published for these parameters (Meijaard et al. 2007, eq. (5.4) and Table 2); their
# steer angle is minus this script's.
BENCH_M = np.array([[80.81722, 2.31941332208709], [2.31941332208709, 0.29784188199686]])
BENCH_C1 = np.array([[0.0, 33.86641391492494], [-0.85035641456978, 1.68540397397560]])
BENCH_K0 = np.array([[-80.95, -2.59951685249872], [-2.59951685249872, -0.80329488458618]])
BENCH_K2 = np.array([[0.0, 76.59734589573222], [0.0, 2.65431523794604]])

ROLL, PITCH, STEER = models.BIKE_ROLL, models.BIKE_PITCH, models.BIKE_STEER  # indices into q




def build_bicycle() -> dict[str, Any]:
    """L, q, the rolling constraints, the holonomic constraint, the parameter values and the
    upright state's helper: models.whipple_bicycle()."""
    return models.whipple_bicycle()


def expression_size(exprs: list[Any]) -> tuple[int, int]:
    """Tree nodes summed over the expressions (repeats counted) and the distinct subtrees."""
    nodes, distinct = 0, set()
    for e in exprs:
        for node in sp.preorder_traversal(e):
            nodes += 1
            distinct.add(node)
    return nodes, len(distinct)


def convert(bike: dict[str, Any]) -> chetaev.Model:
    return chetaev.Model.from_sympy(
        bike["L"], bike["q"], constraints=bike["constraints"], holonomic=bike["holonomic"],
        parameters=bike["parameters"],
    )


def time_conversion(bike: dict[str, Any], rounds: int) -> tuple[chetaev.Model, list[float]]:
    times, model = [], None
    for _ in range(rounds):
        gc.collect()
        start = time.perf_counter()
        model = convert(bike)
        times.append(time.perf_counter() - start)
    return model, times


# ---------------------------------------------------------------------------------------------
# The initial state and the solves
# ---------------------------------------------------------------------------------------------


def initial_state(bike: dict[str, Any], v: float, roll_rate: float) -> tuple[np.ndarray, np.ndarray]:
    """Upright (roll = steer = 0) at the origin, heading along N.x; the pitch from h = 0 by
    Newton; rear-wheel spin rate v/rR and the given roll rate, steer rate 0; the dependent speeds
    (x', y', yaw rate, pitch rate, front-wheel spin) from the four rolling constraints and ḣ = 0,
    which are linear in q̇: G(q) q̇ = 0 (models.whipple_bicycle()["upright"])."""
    q0, qd0 = bike["upright"](v, roll_rate=roll_rate)
    return np.array(q0), np.array(qd0)


def make_problem(model: chetaev.Model, q0: np.ndarray, qd0: np.ndarray) -> chetaev.Problem | None:
    """chetaev.Problem at (q0, q̇0); a ChetaevError is printed in full, and then the remedy its
    message names (project_velocity=True: the position projected onto h = 0, then the velocity)
    is tried and said so."""
    try:
        return chetaev.Problem(model, q0, qd0)
    except chetaev.ChetaevError as e:
        print(f"  chetaev.Problem(model, q0, qd0) raised {type(e).__name__}: {e}")
    try:
        problem = chetaev.Problem(model, q0, qd0, project_velocity=True)
    except chetaev.ChetaevError as e:
        print(f"  chetaev.Problem(..., project_velocity=True) raised {type(e).__name__}: {e}")
        return None
    moved = np.abs(problem.q0 - q0).max(), np.abs(problem.qd0 - qd0).max()
    print(f"  retried with project_velocity=True: accepted; q0 moved by {moved[0]:.3g} at most, "
          f"q̇0 by {moved[1]:.3g}")
    return problem


def linearised(v: float, roll_rate: float, times: np.ndarray) -> np.ndarray:
    """Roll and (the paper's) steer of the linearised benchmark from roll rate `roll_rate`."""
    g = TABLE_1["g"]
    stiffness = g * BENCH_K0 + v**2 * BENCH_K2

    def rhs(_t: float, s: np.ndarray) -> np.ndarray:
        angles, rates = s[:2], s[2:]
        return np.concatenate([rates, np.linalg.solve(BENCH_M, -(v * BENCH_C1 @ rates + stiffness @ angles))])

    sol = solve_ivp(rhs, (times[0], times[-1]), [0.0, 0.0, roll_rate, 0.0], method="DOP853",
                    rtol=1e-12, atol=1e-14, t_eval=times)
    return sol.y[:2].T


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rounds", type=int, default=7, help="conversions timed per form")
    ap.add_argument("--v", type=float, default=4.6, help="forward speed [m/s]")
    ap.add_argument("--t-end", type=float, default=1.0)
    ap.add_argument("--tol", type=float, default=1e-8, help="rtol = atol of the solves")
    ap.add_argument("--roll-rate", type=float, default=0.01,
                    help="initial roll rate [rad/s] of the check against the linearised benchmark")
    args = ap.parse_args()

    print(f"machine: {machine()}")
    print(f"python {platform.python_version()}, sympy {sp.__version__}, chetaev {chetaev.__version__}")

    start = time.perf_counter()
    bike = build_bicycle()
    built = time.perf_counter() - start
    start = time.perf_counter()
    expanded = dict(bike, L=sp.expand(bike["L"]),
                    constraints=[sp.expand(f) for f in bike["constraints"]],
                    holonomic=[sp.expand(h) for h in bike["holonomic"]])
    expanding = time.perf_counter() - start
    print(f"sympy: model built in {built:.3f} s (frames, bodies, Lagrangian, constraints); "
          f"sympy.expand of it in {expanding:.3f} s (not part of any conversion time)")
    print(f"q = {bike['q']}: {len(bike['constraints'])} velocity constraints, "
          f"{len(bike['holonomic'])} holonomic, {len(bike['parameters'])} parameters")
    print()

    print(f"chetaev.Model.from_sympy(L, q, constraints=..., holonomic=..., parameters=...), "
          f"{args.rounds} rounds:")
    print("| form | count_ops(L) | tree nodes (L, f, h) | distinct subtrees | model.operations "
          "| first [ms] | min [ms] | median [ms] | max [ms] |")
    print("|---|---|---|---|---|---|---|---|---|")
    models = {}
    for name, form in (("as built", bike), ("expanded", expanded)):
        # Timed first, so that the sizes' traversals do not warm anything for the first round.
        model, times = time_conversion(form, args.rounds)
        nodes, distinct = expression_size([form["L"], *form["constraints"], *form["holonomic"]])
        ops = sp.count_ops(form["L"], visual=False)
        models[name] = model
        ms = [1e3 * s for s in times]
        print(f"| {name} | {ops} | {nodes} | {distinct} | {model.operations} | {ms[0]:.2f} "
              f"| {min(ms):.2f} | {statistics.median(ms):.2f} | {max(ms):.2f} |")
    print()

    # Upright, straight running: roll and steer stay zero; the bicycle moves along N.x at v.
    q0, qd0 = initial_state(bike, args.v, 0.0)
    print(f"upright at v = {args.v} m/s: pitch from h = 0: {q0[PITCH]:.3g} rad; "
          f"q̇0 = {np.array2string(qd0, precision=6)}")
    finals = {}
    for name, model in models.items():
        print(f"{name}:")
        start = time.perf_counter()
        problem = make_problem(model, q0, qd0)
        if problem is None:
            continue
        made = time.perf_counter() - start
        start = time.perf_counter()
        sol = chetaev.solve(problem, args.t_end, method="dop853", rtol=args.tol, atol=args.tol)
        solved = time.perf_counter() - start
        finals[name] = sol.q[-1]
        print(f"  Problem in {made:.3f} s, solve in {solved:.3f} s: status {sol.status}"
              f"{'' if sol.success else f' ({sol.message})'}, {sol.stats['accepted_steps']} steps; "
              f"at t = {sol.t[-1]:g}: roll {sol.q[-1, ROLL]:.3g} rad, steer {sol.q[-1, STEER]:.3g} rad, "
              f"x {sol.q[-1, 0]:.12g} m (v t = {args.v * sol.t[-1]:.12g}); "
              f"max |h| {np.abs(sol.position_residual).max():.2g}, "
              f"max |f| {np.abs(sol.residual).max():.2g}, "
              f"max |energy balance| {np.abs(sol.energy_balance).max():.2g}")
    if len(finals) == 2:
        print(f"as built vs expanded at t_end: max |Δq| = "
              f"{np.abs(finals['as built'] - finals['expanded']).max():.3g}")
    print()

    # The check: a small roll rate, against the paper's linearised equations.
    if args.roll_rate:
        q0, qd0 = initial_state(bike, args.v, args.roll_rate)
        print(f"check: initial roll rate {args.roll_rate} rad/s at v = {args.v} m/s, as built, "
              f"against the linearised benchmark (M, C1, K0, K2 of Meijaard et al. 2007):")
        problem = make_problem(models["as built"], q0, qd0)
        if problem is not None:
            times = np.linspace(0.0, args.t_end, 101)
            sol = chetaev.solve(problem, args.t_end, method="dop853", rtol=args.tol, atol=args.tol,
                                output=times)
            reference = linearised(args.v, args.roll_rate, times)
            ours = np.column_stack([sol.q[:, ROLL], -sol.q[:, STEER]])  # the paper's steer sign
            print(f"  status {sol.status}; max |roll| {np.abs(ours[:, 0]).max():.3g} rad, "
                  f"max |steer| {np.abs(ours[:, 1]).max():.3g} rad; max difference from the "
                  f"linearised solution: roll {np.abs(ours[:, 0] - reference[:, 0]).max():.2g} rad, "
                  f"steer {np.abs(ours[:, 1] - reference[:, 1]).max():.2g} rad")


if __name__ == "__main__":
    main()
