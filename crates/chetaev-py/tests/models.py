"""Models built with ``sympy.physics.mechanics`` for the tests of the Python bindings.

Not a test module: the tests import it (``from models import rolling_disc, particle``).

Sign convention (the one of ``chetaev``, see ``docs/conventions.md``): the equations are in
*Newton form*,

    d/dt (dL/dq') - dL/dq = sum_a mu_a df_a/dq' = Phi,

the constraint force ``Phi`` standing on the force side.

Contents
--------
``rolling_disc()``
    The rolling disc of sympy's own tests (``sympy/physics/mechanics/tests/test_kane.py`` and
    ``test_lagrange.py``, ``test_rolling_disc``): yaw ``q1``, lean ``q2``, spin ``q3`` (3-1-2
    rotations Z, X, Y), here with the contact point's ground position ``x, y`` as two more
    coordinates so that the rolling (no-slip) conditions are two nonholonomic constraints linear
    in the velocities. Coordinates ``q = [q1, q2, q3, x, y]``.
``rolling_disc_reference(t_end, rtol, atol)``
    The same disc solved independently: ``LagrangesMethod`` with ``nonhol_coneqs``, lambdified,
    integrated by ``scipy.integrate.solve_ivp(method="DOP853")``.
``rolling_disc_energy(q, qd)``
    The energy ``E = q'.dL/dq' - L`` of the disc (conserved: the rolling constraints do no work).
``particle()`` and ``particle_closed_form(t)``
    The uniform horizontal projectile (a particle in gravity at constant speed,
    ``x'^2 + y'^2 - v0^2 = 0``, a constraint nonlinear in the velocities) and its closed form.

Two differences from sympy's tests, both deliberate:

* sympy's ``test_lagrange.py::test_rolling_disc`` builds the Lagrangian with the contact point
  fixed (``C.set_vel(N, 0)``), i.e. with the rolling constraints already substituted into the
  kinetic energy, which is not admissible for nonholonomic constraints; here the centre's
  velocity is the unconstrained one, ``d/dt (x N.x + y N.y + r L.z)``, and rolling enters only
  through the constraints.
* the same test sets ``potential_energy = -m g r cos(q2)``, which makes the upright disc stable
  when not rolling (its ``q2''`` has ``-4 g sin(q2) / (5 r)``, where ``test_kane.py``'s force
  ``-m g Y.z`` gives ``+4 g sin(q2) / (5 r)``). The centre is at height ``r cos(q2)``, so here
  ``V = +m g r cos(q2)``, consistent with ``test_kane.py``.
"""

from __future__ import annotations

import functools
import math
from typing import Any, Callable, Sequence

import numpy as np
import sympy as sp
import sympy.physics.mechanics as me

t = me.dynamicsymbols._t

# Rolling disc: numerical values of the parameters and the initial state.
DISC_PARAMETERS = {"m": 1.0, "r": 0.5, "g": 9.81}
# q0 = [q1, q2, q3, x, y]: yaw 0.3 rad, lean 0.1 rad (from upright), at the origin.
DISC_Q0 = (0.3, 0.1, 0.0, 0.0, 0.0)
# Independent velocities q1', q2', q3'; x', y' follow from the constraints. Spin 6 rad/s
# (rolling speed r * 6 = 3 m/s) is above the critical spin sqrt(g / (3 r)) ~ 2.56 rad/s of the
# upright disc, so the disc stays up (|q2| <= 0.246 rad over t in [0, 5]).
DISC_QD0_INDEPENDENT = (0.5, -0.2, 6.0)

DISC_CONTACT_FORCE_NOTE = (
    "f = [v_P . N.x, v_P . N.y] with v_P the velocity of the disc's material point at the "
    "contact: f1 = x' - r cos(q1) q3', f2 = y' - r sin(q1) q3'. Since df_a/dq' = "
    "(dv_P/dq') . e_a, the Chetaev force Phi = mu_1 df_1/dq' + mu_2 df_2/dq' is the generalised "
    "force of the force mu_1 N.x + mu_2 N.y applied at P: in Newton form, mu_1 and mu_2 are the "
    "N.x and N.y components (in newtons) of the horizontal friction force of the ground on the "
    "disc (friction being the only horizontal force, mu = m times the centre's horizontal "
    "acceleration). The normal force is no multiplier (the holonomic contact with the ground is "
    "built into the geometry, the centre at height r cos(q2)); it is m (z_c'' + g), z_c = r cos(q2)."
)


def _disc_symbols() -> tuple[list[sp.Function], tuple[sp.Symbol, sp.Symbol, sp.Symbol]]:
    q1, q2, q3, x, y = me.dynamicsymbols("q1 q2 q3 x y")
    m, r, g = sp.symbols("m r g")
    return [q1, q2, q3, x, y], (m, r, g)


def rolling_disc() -> dict[str, Any]:
    """The rolling disc of sympy's tests, with coordinates ``q = [q1, q2, q3, x, y]``.

    ``q1`` yaw (about ``N.z``), ``q2`` lean (about ``Y.x``), ``q3`` spin (about ``L.y``, the
    disc's axis), ``x, y`` the contact point's position on the ground plane ``N.x, N.y``
    (``N.z`` up). The disc: mass ``m``, radius ``r``, thin (central inertia ``m r^2/4``,
    ``m r^2/2``, ``m r^2/4`` about ``L.x, L.y, L.z``), in gravity ``g``.

    Returns a fresh dict (safe to mutate) with keys

    * ``L``: ``me.Lagrangian(N, disc)`` with ``disc.potential_energy = m g r cos(q2)``;
    * ``T``, ``V``: kinetic and potential energy (``L = T - V``);
    * ``q``: ``[q1, q2, q3, x, y]`` (dynamicsymbols, functions of ``t``);
    * ``qd``: their time derivatives;
    * ``constraints``: ``[x' - r cos(q1) q3', y' - r sin(q1) q3']`` (no slip at the contact);
    * ``parameters``: ``{m: 1.0, r: 0.5, g: 9.81}`` (sympy symbols as keys);
    * ``symbols``: ``{"m": m, "r": r, "g": g}``;
    * ``frame``: ``N``; ``frames``: ``{"N", "Y", "L", "R"}``;
    * ``points``: ``{"O": origin, "C": contact point on the ground, "D": centre}``;
    * ``bodies``: ``[disc]``; ``disc``: the ``RigidBody``;
    * ``gravity_loads``: ``[(D, -m g N.z)]``, to use with ``T`` in place of ``V``;
    * ``q0``, ``qd0``: the initial state (floats), ``qd0`` satisfying the constraints;
    * ``contact_force_note``: what the multipliers are physically.
    """
    q, (m, r, g) = _disc_symbols()
    q1, q2, q3, x, y = q

    # 3-1-2 (Z, X, Y) rotations, as in sympy's test: yaw frame Y, lean frame L, disc frame R.
    N = me.ReferenceFrame("N")
    Y = N.orientnew("Y", "Axis", [q1, N.z])
    L = Y.orientnew("L", "Axis", [q2, Y.x])
    R = L.orientnew("R", "Axis", [q3, L.y])

    # Origin O, contact point C on the ground, centre D = C + r L.z. The centre's velocity is
    # the time derivative of its position (no rolling assumed here).
    O = me.Point("O")
    O.set_vel(N, 0)
    C = O.locatenew("C", x * N.x + y * N.y)
    C.set_vel(N, C.pos_from(O).dt(N))
    D = C.locatenew("D", r * L.z)
    D.set_vel(N, D.pos_from(O).dt(N))

    inertia = me.inertia(L, m / 4 * r**2, m / 2 * r**2, m / 4 * r**2)
    disc = me.RigidBody("disc", D, R, m, (inertia, D))
    height = D.pos_from(O).dot(N.z)  # r cos(q2)
    disc.potential_energy = m * g * height

    lagrangian = me.Lagrangian(N, disc)
    kinetic = disc.kinetic_energy(N)
    potential = disc.potential_energy

    # Velocity of the disc's material point at the contact; rolling without slip: its two
    # horizontal components vanish (the vertical one vanishes identically).
    v_contact = D.vel(N) + R.ang_vel_in(N).cross(-r * L.z)
    constraints = [sp.trigsimp(v_contact.dot(N.x)), sp.trigsimp(v_contact.dot(N.y))]

    parameters = {m: DISC_PARAMETERS["m"], r: DISC_PARAMETERS["r"], g: DISC_PARAMETERS["g"]}
    qd0 = disc_dependent_velocities(DISC_Q0, DISC_QD0_INDEPENDENT, DISC_PARAMETERS["r"])

    return {
        "L": lagrangian,
        "T": kinetic,
        "V": potential,
        "q": list(q),
        "qd": [qi.diff(t) for qi in q],
        "constraints": constraints,
        "parameters": parameters,
        "symbols": {"m": m, "r": r, "g": g},
        "frame": N,
        "frames": {"N": N, "Y": Y, "L": L, "R": R},
        "points": {"O": O, "C": C, "D": D},
        "bodies": [disc],
        "disc": disc,
        "gravity_loads": [(D, -m * g * N.z)],
        "q0": list(DISC_Q0),
        "qd0": qd0,
        "contact_force_note": DISC_CONTACT_FORCE_NOTE,
    }


def disc_dependent_velocities(
    q0: Sequence[float], qd_independent: Sequence[float], r: float
) -> list[float]:
    """Full ``[q1', q2', q3', x', y']`` from ``q1', q2', q3'``: ``x' = r cos(q1) q3'``,
    ``y' = r sin(q1) q3'`` (the constraints solved for the dependent velocities)."""
    q1 = float(q0[0])
    q1d, q2d, q3d = (float(v) for v in qd_independent)
    return [q1d, q2d, q3d, r * math.cos(q1) * q3d, r * math.sin(q1) * q3d]


# ---------------------------------------------------------------------------------------------
# Independent reference: sympy's LagrangesMethod + scipy's solve_ivp (DOP853)
# ---------------------------------------------------------------------------------------------


@functools.lru_cache(maxsize=None)
def _disc_equations() -> dict[str, Any]:
    """Derive the disc's equations with ``LagrangesMethod`` (slow, a few seconds; cached).

    ``mass_matrix_full @ [q', q'', lam] = forcing_full``; only the lower-right block
    (``n + k`` rows: the dynamic equations and the differentiated constraints) is kept, the upper
    rows being ``q' = q'``.
    """
    model = rolling_disc()
    q = model["q"]
    n, k = len(q), len(model["constraints"])
    lm = me.LagrangesMethod(model["L"], q, nonhol_coneqs=model["constraints"], frame=model["frame"])
    lm.form_lagranges_equations()
    return {
        "model": model,
        "n": n,
        "k": k,
        "M": lm.mass_matrix_full[n:, n:],  # [[Md, -C^T], [C, 0]]
        "F": lm.forcing_full[n:, :],
        "Md": lm.mass_matrix[:, :n],
        "Fd": lm.forcing,
        "C": sp.Matrix(model["constraints"]).jacobian(model["qd"]),
    }


def _numeric_symbols(q: list, qd: list) -> tuple[list[sp.Symbol], list[sp.Symbol], dict]:
    """Plain symbols for q and q' (lambdify needs symbols, not functions of t)."""
    qs = [sp.Symbol(f"_q{i}") for i in range(len(q))]
    vs = [sp.Symbol(f"_v{i}") for i in range(len(q))]
    sub = {**dict(zip(qd, vs)), **dict(zip(q, qs))}  # derivatives first
    return qs, vs, sub


@functools.lru_cache(maxsize=None)
def _disc_functions() -> dict[str, Callable]:
    """Lambdified ``M(q, q', p)``, ``F(q, q', p)``, ``E(q, q', p)`` and the Newton-form check
    pieces, ``p = (m, r, g)`` (cached)."""
    eq = _disc_equations()
    model = eq["model"]
    syms = model["symbols"]
    params = [syms["m"], syms["r"], syms["g"]]
    qs, vs, sub = _numeric_symbols(model["q"], model["qd"])
    lag = model["L"]
    energy = sum(v * lag.diff(v) for v in model["qd"]) - lag

    def lam(expr: Any) -> Callable:
        return sp.lambdify((qs, vs, params), sp.sympify(expr).subs(sub), modules="numpy", cse=True)

    return {
        "M": lam(eq["M"]),
        "F": lam(eq["F"]),
        "Md": lam(eq["Md"]),
        "Fd": lam(eq["Fd"]),
        "C": lam(eq["C"]),
        "E": lam(energy),
        "f": lam(sp.Matrix(model["constraints"])),
    }


def _params_tuple(parameters: dict | None) -> tuple[float, float, float]:
    """``(m, r, g)`` from a ``{symbol or name: value}`` dict (defaults: ``DISC_PARAMETERS``)."""
    values = dict(DISC_PARAMETERS)
    for key, value in (parameters or {}).items():
        values[str(key)] = float(value)
    return (values["m"], values["r"], values["g"])


def rolling_disc_accelerations(
    q: Sequence[float], qd: Sequence[float], parameters: dict | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """``(q'', mu)`` at one state, ``mu`` in Newton form (``chetaev``'s convention).

    Solves ``[[Md, -C^T], [C, 0]] [q''; lam] = [Fd; Fc]`` (sympy's ``mass_matrix_full``):
    ``Md q'' = Fd + C^T lam``, i.e. ``d/dt dL/dq' - dL/dq = C^T lam``, so ``mu = lam``.
    (sympy's symbolic ``LagrangesMethod.eom`` carries the opposite sign, ``... + C^T lam1 = 0``:
    its ``lam1, lam2`` symbols are ``-mu``; the returned values here are ``+mu``.)
    """
    fns = _disc_functions()
    p = _params_tuple(parameters)
    n = 5
    sol = np.linalg.solve(np.asarray(fns["M"](list(q), list(qd), p), dtype=float),
                          np.asarray(fns["F"](list(q), list(qd), p), dtype=float).ravel())
    return sol[:n], sol[n:]


def rolling_disc_energy(q: Sequence[float], qd: Sequence[float], parameters: dict | None = None) -> float:
    """``E = q'.dL/dq' - L`` (= T + V) of the disc at one state."""
    return float(_disc_functions()["E"](list(q), list(qd), _params_tuple(parameters)))


def rolling_disc_constraints(q: Sequence[float], qd: Sequence[float], parameters: dict | None = None) -> np.ndarray:
    """The constraint values ``f(q, q')`` (both zero on an admissible state)."""
    return np.asarray(_disc_functions()["f"](list(q), list(qd), _params_tuple(parameters)), dtype=float).ravel()


@functools.lru_cache(maxsize=32)
def _reference_cached(
    t_end: float, rtol: float, atol: float, q0: tuple, qd0: tuple, p: tuple
) -> tuple[float, tuple, tuple, tuple, int]:
    from scipy.integrate import solve_ivp

    fns = _disc_functions()
    M, F = fns["M"], fns["F"]
    n = len(q0)

    def rhs(_t: float, state: np.ndarray) -> np.ndarray:
        q, qd = state[:n], state[n:]
        sol = np.linalg.solve(np.asarray(M(q, qd, p), dtype=float), np.asarray(F(q, qd, p), dtype=float).ravel())
        return np.concatenate((qd, sol[:n]))

    res = solve_ivp(rhs, (0.0, t_end), np.array(q0 + qd0, dtype=float), method="DOP853",
                    rtol=rtol, atol=atol)
    if not res.success:
        raise RuntimeError(f"solve_ivp failed: {res.message}")
    y = res.y[:, -1]
    _, mu = rolling_disc_accelerations(y[:n], y[n:], {"m": p[0], "r": p[1], "g": p[2]})
    return float(res.t[-1]), tuple(y[:n]), tuple(y[n:]), tuple(mu), int(res.nfev)


def rolling_disc_reference(
    t_end: float = 5.0,
    rtol: float = 1e-12,
    atol: float = 1e-12,
    *,
    q0: Sequence[float] | None = None,
    qd0: Sequence[float] | None = None,
    parameters: dict | None = None,
) -> tuple[float, np.ndarray, np.ndarray, np.ndarray]:
    """The disc solved by sympy + scipy, independently of ``chetaev``.

    Equations: ``LagrangesMethod(L, q, nonhol_coneqs=constraints)`` (derived once per process,
    cached), lambdified (``cse=True``); state ``(q, q')``, the accelerations and multipliers from
    the linear solve of ``mass_matrix_full``'s lower block at each right-hand side; integrated by
    ``solve_ivp(method="DOP853", rtol=rtol, atol=atol)`` from ``t = 0``. The constraints are
    enforced at the acceleration level only, so they drift by the integration error.

    Returns ``(t_final, q(t_end), q'(t_end), mu(t_end))`` (numpy arrays, ``q`` ordered
    ``[q1, q2, q3, x, y]``). ``mu`` is in **Newton form**, the sign ``chetaev`` uses:
    ``d/dt dL/dq' - dL/dq = mu_1 df_1/dq' + mu_2 df_2/dq'``; ``mu_1, mu_2`` are the ``N.x, N.y``
    components of the ground's friction force on the disc (see ``DISC_CONTACT_FORCE_NOTE``).
    sympy's own ``lam1, lam2`` in ``LagrangesMethod.eom`` are ``-mu``.

    Defaults: the model's ``q0``, ``qd0`` and parameters (``parameters`` may override any of
    ``m, r, g``, keyed by symbol or name). Results are cached per arguments.
    """
    q0_ = tuple(float(v) for v in (DISC_Q0 if q0 is None else q0))
    if qd0 is None:
        qd0 = disc_dependent_velocities(q0_, DISC_QD0_INDEPENDENT, _params_tuple(parameters)[1])
    qd0_ = tuple(float(v) for v in qd0)
    t_final, q, qd, mu, _ = _reference_cached(float(t_end), float(rtol), float(atol), q0_, qd0_,
                                              _params_tuple(parameters))
    return t_final, np.array(q), np.array(qd), np.array(mu)


# ---------------------------------------------------------------------------------------------
# Uniform horizontal projectile (Swaczyna and Volny): a constraint nonlinear in the velocities
# ---------------------------------------------------------------------------------------------

PARTICLE_PARAMETERS = {"m": 1.0, "g": 10.0, "v0": 10.0}
PARTICLE_H0 = 5.0


def particle() -> dict[str, Any]:
    """Planar particle in gravity at constant speed.

    ``L = m/2 (x'^2 + y'^2) - m g y``, constraint ``x'^2 + y'^2 - v0^2 = 0``; ``q = [x, y]``
    (dynamicsymbols named ``x``, ``y``), parameters ``m, g, v0`` = 1, 10, 10, from
    ``q0 = [0, 5]``, ``qd0 = [10, 0]``.

    Newton form ``m x'' = 2 mu x'``, ``m y'' = 2 mu y' - m g``; closed form
    (``particle_closed_form``): impact ``T = (v0/g) arccosh(exp(g h0 / v0^2))`` with ``h0 = 5``
    (``= arccosh(e^0.5)`` here), ``mu(t) = -(m g / (2 v0)) tanh(g t / v0)``.
    """
    x, y = me.dynamicsymbols("x y")
    m, g, v0 = sp.symbols("m g v0")
    xd, yd = x.diff(t), y.diff(t)
    lagrangian = m / 2 * (xd**2 + yd**2) - m * g * y
    p = PARTICLE_PARAMETERS
    return {
        "L": lagrangian,
        "q": [x, y],
        "qd": [xd, yd],
        "constraints": [xd**2 + yd**2 - v0**2],
        "parameters": {m: p["m"], g: p["g"], v0: p["v0"]},
        "symbols": {"m": m, "g": g, "v0": v0},
        "q0": [0.0, PARTICLE_H0],
        "qd0": [p["v0"], 0.0],
        "h0": PARTICLE_H0,
        "impact_time": particle_impact_time(),
    }


def particle_impact_time(m: float = 1.0, g: float = 10.0, v0: float = 10.0, h0: float = PARTICLE_H0) -> float:
    """``T = (v0/g) arccosh(exp(g h0 / v0^2))`` (``m`` does not enter)."""
    del m
    return v0 / g * math.acosh(math.exp(g * h0 / v0**2))


def particle_closed_form(
    t_: float | np.ndarray, m: float = 1.0, g: float = 10.0, v0: float = 10.0, h0: float = PARTICLE_H0
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(q, q', mu)`` at time(s) ``t_`` from ``q0 = [0, h0]``, ``qd0 = [v0, 0]``.

    With ``u = g t / v0``: ``x = (v0^2/g) arctan(sinh u)``, ``y = h0 - (v0^2/g) ln cosh u``,
    ``x' = v0 / cosh u``, ``y' = -v0 tanh u``, ``mu = -(m g / (2 v0)) tanh u`` (Newton form).
    Shapes: ``q``, ``q'`` have a last axis of 2; ``mu`` a last axis of 1.
    """
    u = g * np.asarray(t_, dtype=float) / v0
    q = np.stack([v0**2 / g * np.arctan(np.sinh(u)), h0 - v0**2 / g * np.log(np.cosh(u))], axis=-1)
    qd = np.stack([v0 / np.cosh(u), -v0 * np.tanh(u)], axis=-1)
    mu = (-(m * g) / (2 * v0) * np.tanh(u))[..., None]
    return q, qd, mu


# ---------------------------------------------------------------------------------------------
# The Carvallo–Whipple bicycle: the benchmark of Meijaard, Papadopoulos, Ruina and Schwab (2007)
# ---------------------------------------------------------------------------------------------

# The benchmark parameters, Meijaard et al. (2007), Table 1, in this model's axes (z up, y left).
# Rotating the paper's axes (x forward, y right, z down) half a turn about x turns the products
# of inertia I_xz into −I_xz: the paper's I_Bxz = 2.4 is −2.4 here, its I_Hxz = −0.00756 is
# +0.00756. Heights are positive up: the paper's z_B = −0.9, z_H = −0.7 are 0.9 and 0.7 here.
WHIPPLE_PARAMETERS = {
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

# Indices into the bicycle's q = [x, y, psi, phi, theta, theta_R, delta, theta_F] (and z, 8, in
# the variant with the rear contact's height).
BIKE_X, BIKE_Y, BIKE_YAW, BIKE_ROLL, BIKE_PITCH, BIKE_REAR, BIKE_STEER, BIKE_FRONT = range(8)
BIKE_HEIGHT = 8

# Meijaard et al. (2007), Table 2 (b) and (c): the eigenvalues of the linearised benchmark bicycle
# in upright straight running at forward speed v [m/s], as published, 14 decimals. The paper
# tabulates v = 0, 1, ..., 10 m/s; transcribed from the gtest that checks a model against every
# eigenvalue of that table, github.com/hazelnusse/OBD, whipple/tests/whipple-eigs-unittest.cpp
# (Dale L. Peterson), whose numbers agree with the rows for v = 0, 4, 5, 10 quoted in other
# repositories to the last printed digit or two. Per row: the weave pair (λ, its conjugate), the
# capsize mode, the castor mode; at v = 0 the four real roots ±3.13164324790656 (the inverted
# pendulum of the rear frame) and ±5.53094371765393 (of the front frame), in the same slots.
MEIJAARD_TABLE_2 = {
    0.0: (3.13164324790656 + 0j, 5.53094371765393 + 0j, -3.13164324790656 + 0j, -5.53094371765393 + 0j),
    1.0: (3.52696170990070 + 0.80774027519930j, 3.52696170990070 - 0.80774027519930j,
          -3.13423125066578 + 0j, -7.11008014637442 + 0j),
    2.0: (2.68234517512745 + 1.68066296590675j, 2.68234517512745 - 1.68066296590675j,
          -3.07158645641514 + 0j, -8.67387984831735 + 0j),
    3.0: (1.70675605663975 + 2.31582447384325j, 1.70675605663975 - 2.31582447384325j,
          -2.63366137253667 + 0j, -10.35101467245920 + 0j),
    4.0: (0.41325331521125 + 3.07910818603206j, 0.41325331521125 - 3.07910818603206j,
          -1.42944427361326 + 0j, -12.15861426576447 + 0j),
    5.0: (-0.77534188219585 + 4.46486771378823j, -0.77534188219585 - 4.46486771378823j,
          -0.32286642900409 + 0j, -14.07838969279822 + 0j),
    6.0: (-1.52644486584142 + 5.87673060598709j, -1.52644486584142 - 5.87673060598709j,
          -0.00406690076970 + 0j, -16.08537123098030 + 0j),
    7.0: (-2.13875644258362 + 7.19525913329805j, -2.13875644258362 - 7.19525913329805j,
          0.10268170574766 + 0j, -18.15788466125262 + 0j),
    8.0: (-2.69348683581097 + 8.46037971396931j, -2.69348683581097 - 8.46037971396931j,
          0.14327879765713 + 0j, -20.27940894394569 + 0j),
    9.0: (-3.21675402252485 + 9.69377351531791j, -3.21675402252485 - 9.69377351531791j,
          0.15790184030917 + 0j, -22.43788559040858 + 0j),
    10.0: (-3.72016840437287 + 10.90681139476287j, -3.72016840437287 - 10.90681139476287j,
           0.16105338653172 + 0j, -24.62459635017404 + 0j),
}

# Meijaard et al. (2007), Table 2 (a): the weave speed (the weave pair's real part crosses zero,
# at λ = ±3.43503384866144 i), the capsize speed (the capsize eigenvalue crosses zero) and the
# speed where the two real roots meet to form the weave pair (λ = 3.78290405129320, double);
# the same source.
MEIJAARD_WEAVE_SPEED = 4.29238253634111
MEIJAARD_WEAVE_FREQUENCY = 3.43503384866144
MEIJAARD_CAPSIZE_SPEED = 6.02426201538837
MEIJAARD_BIFURCATION_SPEED = 0.68428307889246
MEIJAARD_BIFURCATION_EIGENVALUE = 3.78290405129320


def whipple_bicycle(rear_contact_height: bool = False) -> dict[str, Any]:
    """The benchmark bicycle of Meijaard et al. (2007) in Lagrangian form.

    Its four rigid bodies are the rear wheel R, the rear frame B (with rider), the front frame H
    (fork and handlebar) and the front wheel F, with the parameters of the paper's Table 1
    (``WHIPPLE_PARAMETERS``). The coordinates follow Moore's formulation (Moore, Hubbard,
    Kooijman, Schwab 2010), eight of them::

        q = [x, y, psi, phi, theta, theta_R, delta, theta_F]
             rear contact point on the ground, yaw, roll, pitch (of the rear frame),
             rear-wheel spin, steer, front-wheel spin

    with the ground frame N having N.z up (Meijaard and Moore put z down; so here y points left,
    the steer angle and the yaw rate have the opposite sign, and a wheel rolling forward spins at
    +v/r). The Lagrangian is ``me.Lagrangian(N, *bodies)`` with the gravity potentials m g z.
    Rolling without slip is four velocity constraints, linear in q̇: the horizontal velocity of
    each wheel's material point at its contact is zero,
    ``[slip_R . N.x, slip_R . N.y, slip_F . N.x, slip_F . N.y]``. The front wheel touching the
    ground is one holonomic constraint h(q) = 0, the height of the front wheel's lowest point (it
    fixes the pitch given roll and steer); the rear contact is on the ground by construction.
    8 coordinates − 1 − 4 constraints: 3 degrees of freedom (roll, steer, rear-wheel spin).

    With ``rear_contact_height=True`` the rear contact point gets a height ``z`` as a ninth
    coordinate (``q[8]``) and the rear wheel's touching the ground becomes a second holonomic
    constraint ``z = 0`` (``holonomic = [front, z]``), so that its multiplier is there to read.

    What the multipliers are, in chetaev's Newton form
    ``d/dt ∂L/∂q̇ − ∂L/∂q = Σ_a μ_a ∂f_a/∂q̇ + Σ_b λ_b ∂h_b/∂q`` (``sol.mu`` holds ``μ`` then
    ``λ``): ``∂f_a/∂q̇`` is the partial velocity of the wheel's material contact point along
    N.x or N.y, so ``μ_1, μ_2`` (rear) and ``μ_3, μ_4`` (front) are the N.x, N.y components of
    the ground's friction force on each wheel, in newtons. ``h`` is the height of the front
    wheel's lowest point; that point is the lowest of the rim, so a virtual displacement moves
    the material point at the contact vertically by ``δh`` (to first order): ``∂h/∂q`` is its
    vertical partial velocity and ``λ_1`` the upward (normal) force of the ground on the front
    wheel. Likewise, in the variant, ``λ_2`` (of ``z = 0``) is the normal force on the rear
    wheel.

    Returns a fresh dict: ``L``, ``q``, ``qd``, ``constraints`` (the four rolling conditions),
    ``holonomic``, ``parameters`` ({symbol: value}, Table 1), ``symbols`` ({name: symbol}),
    ``frame`` (N), ``frames``, ``points``, ``bodies``, ``weight`` (the total weight, N), and
    ``upright(v, roll_rate=0.0, steer_rate=0.0)``: the upright state (roll = steer = 0, heading
    along N.x) at forward speed ``v`` [m/s], ``(q0, qd0)`` as lists, the pitch solved from h = 0
    by Newton and the dependent speeds from the constraints with sympy + numpy (independently of
    chetaev); ``v / r_R`` is the rear wheel's spin rate.
    """
    names = "x y psi phi theta theta_R delta theta_F" + (" z" if rear_contact_height else "")
    q = list(me.dynamicsymbols(names))
    x, y, psi, phi, theta, theta_R, delta, theta_F = q[:8]
    height = q[8] if rear_contact_height else sp.S.Zero
    p = {name: sp.Symbol(name) for name in WHIPPLE_PARAMETERS}
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
    contact_R = O.locatenew("contact_R", x * N.x + y * N.y + height * N.z)
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
    if rear_contact_height:
        touching.append(height)

    parameters = {p[name]: value for name, value in WHIPPLE_PARAMETERS.items()}
    bike = {
        "L": lagrangian,
        "q": q,
        "qd": [qi.diff(t) for qi in q],
        "constraints": rolling,
        "holonomic": touching,
        "parameters": parameters,
        "symbols": p,
        "frame": N,
        "frames": {"N": N, "Y": Y, "R": R, "B": B, "S": S, "H": H, "WR": WR, "WF": WF},
        "points": {"O": O, "contact_R": contact_R, "centre_R": centre_R, "mass_B": mass_B,
                   "A": A, "mass_H": mass_H, "centre_F": centre_F},
        "bodies": bodies,
        "weight": WHIPPLE_PARAMETERS["g"] * sum(
            WHIPPLE_PARAMETERS[m] for m in ("m_R", "m_B", "m_H", "m_F")),
    }
    bike["upright"] = _bicycle_upright(bike)
    return bike


def _bicycle_upright(bike: dict[str, Any]) -> Callable[..., tuple[list[float], list[float]]]:
    """The ``upright(v, roll_rate=0.0, steer_rate=0.0)`` of ``whipple_bicycle``: lambdified on
    first use."""
    cache: dict[str, Any] = {}

    def functions() -> dict[str, Any]:
        if not cache:
            q, qd, values = bike["q"], bike["qd"], bike["parameters"]
            qs, vs, sub = _numeric_symbols(q, qd)
            h = sp.Matrix(bike["holonomic"]).xreplace(values).xreplace(sub)
            # G(q) q̇ = 0: the rolling constraints and ḣ, all linear and homogeneous in q̇.
            G = (sp.Matrix(bike["constraints"]).jacobian(qd)
                 .col_join(sp.Matrix(bike["holonomic"]).jacobian(q))).xreplace(values).xreplace(sub)
            cache["h"] = sp.lambdify([qs], h, modules="numpy", cse=True)
            cache["hq"] = sp.lambdify([qs], h.jacobian(qs), modules="numpy", cse=True)
            cache["G"] = sp.lambdify([qs], G, modules="numpy", cse=True)
        return cache

    def upright(v: float, roll_rate: float = 0.0, steer_rate: float = 0.0) -> tuple[list[float], list[float]]:
        fns = functions()
        n = len(bike["q"])
        # Coordinates: everything zero but the pitch (and, in the variant, the height z, which
        # h = 0 fixes at 0 too), by Newton on h = 0; the benchmark's reference configuration is
        # upright with both wheels on the ground, so the pitch is 0 up to rounding.
        dependent_q = [BIKE_PITCH] + ([BIKE_HEIGHT] if n > 8 else [])
        q0 = np.zeros(n)
        for _ in range(50):
            step = np.linalg.solve(np.asarray(fns["hq"](q0), dtype=float)[:, dependent_q],
                                   -np.asarray(fns["h"](q0), dtype=float).ravel())
            q0[dependent_q] += step
            if np.abs(step).max() < 1e-16:
                break
        # Speeds: roll rate, rear-wheel spin v / r_R and steer rate given; the others from
        # G(q0) q̇ = 0.
        independent = [BIKE_ROLL, BIKE_REAR, BIKE_STEER]
        dependent = [i for i in range(n) if i not in independent]
        qd0 = np.zeros(n)
        qd0[independent] = [roll_rate, v / WHIPPLE_PARAMETERS["r_R"], steer_rate]
        G = np.asarray(fns["G"](q0), dtype=float)
        qd0[dependent] = np.linalg.solve(G[:, dependent], -G[:, independent] @ qd0[independent])
        return [float(a) for a in q0], [float(a) for a in qd0]

    return upright
