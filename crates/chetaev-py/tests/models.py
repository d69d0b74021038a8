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
