"""Forces not derivable from L, three ways (generalised forces, sympy loads, a Rayleigh function),
against the closed form of a projectile with linear drag; and models made from bodies."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp
import sympy.physics.mechanics as me
from scipy.integrate import quad

import chetaev
from models import particle_closed_form

t = me.dynamicsymbols._t
MASS, GRAV, DRAG = 2.0, 9.81, 0.7
Q0, QD0 = [0.0, 1.0], [3.0, 4.0]
TIMES = np.linspace(0.0, 2.0, 9)
TOL = 1e-12  # rtol = atol
# global error over 2 s, a few dozen steps: a modest multiple of TOL; 1000 * TOL covers it.
GLOBAL = 1000 * TOL


@pytest.fixture(scope="module")
def drag():
    x, y = me.dynamicsymbols("x y")
    m, g, c = sp.symbols("m g c")
    xd, yd = x.diff(t), y.diff(t)
    L = m / 2 * (xd**2 + yd**2) - m * g * y
    N = me.ReferenceFrame("N")
    O = me.Point("O")
    O.set_vel(N, 0)
    P = O.locatenew("P", x * N.x + y * N.y)
    P.set_vel(N, P.pos_from(O).dt(N))
    return dict(x=x, y=y, m=m, g=g, c=c, L=L, N=N, O=O, P=P,
                parameters={m: MASS, g: GRAV, c: DRAG})


def _models(d):
    x, y, c, L, P, N = d["x"], d["y"], d["c"], d["L"], d["P"], d["N"]
    xd, yd = x.diff(t), y.diff(t)
    return {
        "forces": chetaev.Model.from_sympy(L, [x, y], forces=[-c * xd, -c * yd],
                                           parameters=d["parameters"]),
        "loads": chetaev.Model.from_sympy(L, [x, y], loads=[(P, -c * P.vel(N))], frame=N,
                                          parameters=d["parameters"]),
        "rayleigh": chetaev.Model.from_sympy(L, [x, y], rayleigh=c / 2 * (xd**2 + yd**2),
                                             parameters=d["parameters"]),
    }


@pytest.fixture(scope="module")
def runs(drag):
    return {name: chetaev.solve(chetaev.Problem(model, Q0, QD0), 2.0, rtol=TOL, atol=TOL,
                                output=TIMES)
            for name, model in _models(drag).items()}


def _closed_form(tt):
    """m q'' = -c q' + (0, -m g): exponential relaxation with tau = m / c."""
    tau = MASS / DRAG
    decay = 1 - np.exp(-tt / tau)
    x = Q0[0] + QD0[0] * tau * decay
    y = Q0[1] + (QD0[1] + GRAV * tau) * tau * decay - GRAV * tau * tt
    xd = QD0[0] * np.exp(-tt / tau)
    yd = (QD0[1] + GRAV * tau) * np.exp(-tt / tau) - GRAV * tau
    return np.stack([x, y], axis=-1), np.stack([xd, yd], axis=-1)


def test_drag_as_forces_as_loads_and_as_a_rayleigh_function_gives_the_same_motion(runs):
    ref = runs["forces"]
    for name in ("loads", "rayleigh"):
        sol = runs[name]
        np.testing.assert_array_equal(sol.t, ref.t)
        # the same equations from three inputs: equal up to the rounding of Q, amplified by the
        # integration (10 steps): 1e-10 is far below any difference in the equations.
        np.testing.assert_allclose(sol.q, ref.q, rtol=0, atol=1e-10, err_msg=name)
        np.testing.assert_allclose(sol.qd, ref.qd, rtol=0, atol=1e-10, err_msg=name)
        np.testing.assert_allclose(sol.work_forces, ref.work_forces, rtol=0, atol=1e-10)


@pytest.mark.parametrize("name", ["forces", "loads", "rayleigh"])
def test_the_damped_projectile_follows_its_closed_form(runs, name):
    sol = runs[name]
    q, qd = _closed_form(sol.t)
    np.testing.assert_allclose(sol.q, q, rtol=0, atol=GLOBAL * 10)
    np.testing.assert_allclose(sol.qd, qd, rtol=0, atol=GLOBAL * 10)


@pytest.mark.parametrize("name", ["forces", "loads", "rayleigh"])
def test_the_energy_drops_by_the_work_of_the_drag_minus_c_integral_of_speed_squared(runs, name):
    sol = runs[name]
    speed2 = lambda s: float((_closed_form(np.array(s))[1] ** 2).sum())  # noqa: E731
    w = np.array([quad(speed2, 0.0, ti, epsabs=1e-13, epsrel=1e-13)[0] for ti in sol.t])
    # W_Q ~ 70 J, carried by a quadrature along the motion: relative GLOBAL.
    np.testing.assert_allclose(sol.work_forces, -DRAG * w, rtol=0, atol=100 * GLOBAL)
    np.testing.assert_allclose(sol.energy - sol.energy[0], sol.work_forces, rtol=0,
                               atol=100 * GLOBAL)
    assert np.abs(sol.energy_balance).max() <= 100 * GLOBAL
    assert np.all(sol.work == 0.0)  # no constraint, no Chetaev force


def test_a_constraint_on_the_speed_absorbs_linear_drag_raising_mu_by_c_over_2(drag):
    # the paper's particle with drag: m q'' = 2 mu q' - c q' - m g e_y, and |q'| = v0 fixes the
    # motion, so it is the paper's motion with mu = mu_paper + c / 2 (docs/scenes.md).
    x, y, g, c = drag["x"], drag["y"], drag["g"], drag["c"]
    m, v0 = sp.symbols("m v0")
    xd, yd = x.diff(t), y.diff(t)
    model = chetaev.Model.from_sympy(m / 2 * (xd**2 + yd**2) - m * g * y, [x, y],
                                     constraints=[xd**2 + yd**2 - v0**2],
                                     forces=[-c * xd, -c * yd],
                                     parameters={m: 1.0, g: 10.0, v0: 10.0, c: DRAG})
    sol = chetaev.solve(chetaev.Problem(model, [0.0, 5.0], [10.0, 0.0]), 1.0, rtol=TOL, atol=TOL)
    q, _, mu = particle_closed_form(sol.t)
    np.testing.assert_allclose(sol.q, q, rtol=0, atol=10 * GLOBAL)
    np.testing.assert_allclose(sol.mu, mu + DRAG / 2, rtol=0, atol=GLOBAL)
    # E - E0 = W_Phi + W_Q, both nonzero
    assert abs(sol.work_forces[-1]) > 1 and abs(sol.work[-1]) > 1
    assert np.abs(sol.energy_balance).max() <= 100 * GLOBAL


def test_a_model_from_frame_and_a_particle_with_potential_energy_has_sympys_lagrangian(drag):
    x, y, m, g = drag["x"], drag["y"], drag["m"], drag["g"]
    N, P = drag["N"], drag["P"]
    body = me.Particle("body", P, m)
    body.potential_energy = m * g * y
    from_bodies = chetaev.Model.from_sympy(q=[x, y], frame=N, bodies=[body],
                                           parameters=drag["parameters"])
    by_hand = chetaev.Model.from_sympy(drag["L"], [x, y], parameters=drag["parameters"])
    lagrangian = me.Lagrangian(N, body)
    assert sp.simplify(lagrangian - drag["L"]) == 0  # the premise: sympy's L is m/2|v|^2 - m g y
    a, b = chetaev.Problem(from_bodies, Q0, QD0), chetaev.Problem(by_hand, Q0, QD0)
    X, Y, U, V = sp.symbols("X Y U V")
    value = sp.lambdify((X, Y, U, V), lagrangian.subs(
        {x.diff(t): U, y.diff(t): V, x: X, y: Y, **drag["parameters"]}))
    rng = np.random.default_rng(3)
    for _ in range(5):
        q, qd = rng.uniform(-5, 5, 2), rng.uniform(-5, 5, 2)
        ea, eb = a.equations_at(0.0, list(q), list(qd)), b.equations_at(0.0, list(q), list(qd))
        # evaluations of the same polynomial of O(100): rounding only
        assert ea["lagrangian"] == pytest.approx(value(*q, *qd), rel=1e-14, abs=1e-13)
        assert ea["lagrangian"] == pytest.approx(eb["lagrangian"], rel=1e-14, abs=1e-13)
        np.testing.assert_allclose(ea["qdd"], [0.0, -GRAV], rtol=0, atol=1e-14)
    sol = chetaev.solve(a, 1.0, rtol=TOL, atol=TOL, output="final")
    assert sol.q[-1, 1] == pytest.approx(Q0[1] + QD0[1] - GRAV / 2, abs=GLOBAL)


def test_a_model_from_bodies_without_lagrangian_needs_the_frame(drag):
    body = me.Particle("body", drag["P"], drag["m"])
    with pytest.raises(chetaev.ConversionError, match="frame"):
        chetaev.Model.from_sympy(q=[drag["x"], drag["y"]], bodies=[body],
                                 parameters=drag["parameters"])
