#!/usr/bin/env python3
"""Converting a large sympy model: the Carvallo–Whipple bicycle, timed through Model.from_sympy.

Model: the benchmark bicycle of Meijaard, Papadopoulos, Ruina and Schwab (2007), "Linearized
dynamics equations for the balance and steer of a bicycle: a benchmark and review", Proc. R. Soc.
A 463, 1955–1982, built with sympy.physics.mechanics in Lagrangian form. Its four rigid bodies are
the rear wheel R, the rear frame B (with rider), the front frame H (fork and handlebar) and the
front wheel F, with the parameters of the paper's Table 1. The coordinates follow Moore's
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
import math
import platform
import statistics
import time
from typing import Any

import numpy as np
import sympy as sp
import sympy.physics.mechanics as me
from scipy.integrate import solve_ivp

import chetaev
from machine import machine

# ---------------------------------------------------------------------------------------------
# The benchmark parameters, Meijaard et al. (2007), Table 1, in this script's axes (z up, y left)
# ---------------------------------------------------------------------------------------------

# Rotating the paper's axes (x forward, y right, z down) half a turn about x turns the products
# of inertia I_xz into −I_xz: the paper's I_Bxz = 2.4 is −2.4 here, its I_Hxz = −0.00756 is
# +0.00756. Heights are positive up: the paper's z_B = −0.9, z_H = −0.7 are 0.9 and 0.7 here.
TABLE_1 = {
    "w": 1.02,  # wheelbase [m]
    "c": 0.08,  # trail [m]
    "lambda": math.pi / 10,  # steer axis tilt from the vertical [rad]
    "g": 9.81,  # gravity [m/s²]
    "r_R": 0.3, "m_R": 2.0, "I_Rxx": 0.0603, "I_Ryy": 0.12,  # rear wheel
    "x_B": 0.3, "z_B": 0.9, "m_B": 85.0,  # rear frame and rider
    "I_Bxx": 9.2, "I_Byy": 11.0, "I_Bzz": 2.8, "I_Bxz": -2.4,
    "x_H": 0.9, "z_H": 0.7, "m_H": 4.0,  # front frame
    "I_Hxx": 0.05892, "I_Hyy": 0.06, "I_Hzz": 0.00708, "I_Hxz": 0.00756,
    "r_F": 0.35, "m_F": 3.0, "I_Fxx": 0.1405, "I_Fyy": 0.28,  # front wheel
}

# The linearised equations in roll and steer, M q̈ + v C1 q̇ + (g K0 + v² K2) q = 0, with the
# matrices published for these parameters (Meijaard et al. 2007, eq. (5.4) and Table 2); their
# steer angle is minus this script's.
BENCH_M = np.array([[80.81722, 2.31941332208709], [2.31941332208709, 0.29784188199686]])
BENCH_C1 = np.array([[0.0, 33.86641391492494], [-0.85035641456978, 1.68540397397560]])
BENCH_K0 = np.array([[-80.95, -2.59951685249872], [-2.59951685249872, -0.80329488458618]])
BENCH_K2 = np.array([[0.0, 76.59734589573222], [0.0, 2.65431523794604]])

ROLL, PITCH, REAR_SPIN, STEER = 3, 4, 5, 6  # indices into q
INDEPENDENT = [3, 5, 6]  # roll rate, rear-wheel spin rate, steer rate
DEPENDENT = [0, 1, 2, 4, 7]  # x', y', yaw rate, pitch rate, front-wheel spin rate




# ---------------------------------------------------------------------------------------------
# The model
# ---------------------------------------------------------------------------------------------


def build_bicycle() -> dict[str, Any]:
    """L, q, the rolling constraints, the holonomic constraint and the parameter values."""
    q = me.dynamicsymbols("x y psi phi theta theta_R delta theta_F")
    x, y, psi, phi, theta, theta_R, delta, theta_F = q
    p = {name: sp.Symbol(name) for name in TABLE_1}
    w, c, lam, g, rR, rF = (p[k] for k in ("w", "c", "lambda", "g", "r_R", "r_F"))

    # Frames. Y: yawed about the vertical; R: rolled about Y.x (the rear wheel's plane stays
    # perpendicular to R.y); B: the rear frame, pitched about R.y; B is aligned with the paper's
    # axes in its reference configuration (theta = 0). S: B tilted back by lambda about B.y, so
    # S.z is the steer axis (pointing up); H: the front frame, steered about S.z; H0: H tilted
    # forward again, aligned with B when delta = 0 (the paper gives H's inertia in those axes).
    # The wheels spin about B.y and H.y.
    N = me.ReferenceFrame("N")
    Y = N.orientnew("Y", "Axis", [psi, N.z])
    R = Y.orientnew("R", "Axis", [phi, Y.x])
    B = R.orientnew("B", "Axis", [theta, R.y])
    S = B.orientnew("S", "Axis", [-lam, B.y])
    H = S.orientnew("H", "Axis", [delta, S.z])
    H0 = H.orientnew("H0", "Axis", [lam, H.y])
    WR = B.orientnew("WR", "Axis", [theta_R, B.y])
    WF = H.orientnew("WF", "Axis", [theta_F, H.y])

    # Points. In the reference configuration (all angles zero) the rear contact is at the
    # origin, the front contact at (w, 0, 0), and the steer axis meets the ground at
    # (w + c, 0, 0): the point A, fixed in B and H alike. From A, the front wheel's centre
    # (w, 0, rF) and the front frame's mass centre (x_H, 0, z_H) are written in H's axes
    # (rotating with the steer): offsets along H.x (perpendicular to the steer axis: the fork
    # offset rF sin(lambda) − c cos(lambda)) and along H.z (the steer axis).
    O = me.Point("O")
    O.set_vel(N, 0)
    contact_R = O.locatenew("contact_R", x * N.x + y * N.y)
    centre_R = contact_R.locatenew("centre_R", rR * R.z)
    mass_B = centre_R.locatenew("mass_B", p["x_B"] * B.x + (p["z_B"] - rR) * B.z)
    A = centre_R.locatenew("A", (w + c) * B.x - rR * B.z)
    dx_H, dz_H = p["x_H"] - w - c, p["z_H"]
    mass_H = A.locatenew(
        "mass_H",
        (dx_H * sp.cos(lam) + dz_H * sp.sin(lam)) * H.x
        + (-dx_H * sp.sin(lam) + dz_H * sp.cos(lam)) * H.z,
    )
    centre_F = A.locatenew(
        "centre_F",
        (rF * sp.sin(lam) - c * sp.cos(lam)) * H.x + (c * sp.sin(lam) + rF * sp.cos(lam)) * H.z,
    )
    # Every mass centre's velocity is its position's time derivative: a function of q and q̇.
    for point in (centre_R, mass_B, mass_H, centre_F):
        point.set_vel(N, point.pos_from(O).dt(N))

    # The front wheel's lowest point: from its centre, rF along the direction in the wheel's
    # plane (perpendicular to the axle H.y) that points most steeply down.
    k = N.z.dot(H.y)
    down_F = (k * H.y - N.z) / sp.sqrt(1 - k**2)

    # Bodies. The wheels are symmetric about their axles, so their inertia is constant in B and H
    # (and the Lagrangian does not depend on the spin angles).
    bodies = [
        me.RigidBody("rear_wheel", centre_R, WR, p["m_R"],
                     (me.inertia(B, p["I_Rxx"], p["I_Ryy"], p["I_Rxx"]), centre_R)),
        me.RigidBody("rear_frame", mass_B, B, p["m_B"],
                     (me.inertia(B, p["I_Bxx"], p["I_Byy"], p["I_Bzz"], 0, 0, p["I_Bxz"]), mass_B)),
        me.RigidBody("front_frame", mass_H, H, p["m_H"],
                     (me.inertia(H0, p["I_Hxx"], p["I_Hyy"], p["I_Hzz"], 0, 0, p["I_Hxz"]), mass_H)),
        me.RigidBody("front_wheel", centre_F, WF, p["m_F"],
                     (me.inertia(H, p["I_Fxx"], p["I_Fyy"], p["I_Fxx"]), centre_F)),
    ]
    for body in bodies:
        body.potential_energy = body.mass * g * body.masscenter.pos_from(O).dot(N.z)
    lagrangian = me.Lagrangian(N, *bodies)

    # Rolling without slip: the wheel's material point at the contact, v_centre + ω × (contact −
    # centre), has no horizontal velocity (its vertical velocity vanishes through the geometry,
    # at the rear, and through h, at the front).
    slip_R = centre_R.vel(N) + WR.ang_vel_in(N).cross(-rR * R.z)
    slip_F = centre_F.vel(N) + WF.ang_vel_in(N).cross(rF * down_F)
    rolling = [slip_R.dot(N.x), slip_R.dot(N.y), slip_F.dot(N.x), slip_F.dot(N.y)]

    # The front contact's height: the centre's height minus rF sqrt(1 − (N.z·H.y)²).
    touching = [centre_F.pos_from(O).dot(N.z) - rF * sp.sqrt(1 - k**2)]

    return {
        "L": lagrangian,
        "q": q,
        "constraints": rolling,
        "holonomic": touching,
        "parameters": {p[name]: value for name, value in TABLE_1.items()},
    }


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
    which are linear in q̇: G(q) q̇ = 0."""
    q, values = bike["q"], bike["parameters"]
    qd = [c.diff() for c in q]
    h = bike["holonomic"][0].xreplace(values)
    h_of = sp.lambdify([q], h)
    dh_of = sp.lambdify([q], h.diff(q[PITCH]))
    G = (sp.Matrix(bike["constraints"]).jacobian(qd)
         .col_join(sp.Matrix(bike["holonomic"]).jacobian(q))).xreplace(values)
    G_of = sp.lambdify([q], G)

    q0 = np.zeros(len(q))
    for _ in range(50):
        step = h_of(q0) / dh_of(q0)
        q0[PITCH] -= step
        if abs(step) < 1e-16:
            break
    qd0 = np.zeros(len(q))
    qd0[INDEPENDENT] = [roll_rate, v / TABLE_1["r_R"], 0.0]
    Gn = np.array(G_of(q0), dtype=float)
    qd0[DEPENDENT] = np.linalg.solve(Gn[:, DEPENDENT], -Gn[:, INDEPENDENT] @ qd0[INDEPENDENT])
    return q0, qd0


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
