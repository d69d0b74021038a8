"""Holonomic constraints: the pendulum in Cartesian coordinates with h = x^2 + y^2 - l^2 against the
same pendulum in its angle (unconstrained)."""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp
import sympy.physics.mechanics as me

import chetaev

t = me.dynamicsymbols._t
MASS, GRAV, LENGTH, THETA0, OMEGA0 = 1.5, 9.81, 2.0, 0.7, 0.4
TIMES = np.linspace(0.0, 3.0, 13)
TOL = 1e-12  # rtol = atol
# global error over 3 s (~2 periods, a hundred steps) is at most ~1000 * TOL on each side.
AGREE = 1e-8


@pytest.fixture(scope="module")
def symbols():
    x, y, th = me.dynamicsymbols("x y theta")
    m, g, l = sp.symbols("m g l")
    return x, y, th, m, g, l


@pytest.fixture(scope="module")
def cartesian(symbols):
    x, y, th, m, g, l = symbols
    L = m / 2 * (x.diff(t) ** 2 + y.diff(t) ** 2) - m * g * y
    model = chetaev.Model.from_sympy(L, [x, y], holonomic=[x**2 + y**2 - l**2],
                                     parameters={m: MASS, g: GRAV, l: LENGTH})
    q0 = [LENGTH * math.sin(THETA0), -LENGTH * math.cos(THETA0)]
    v = LENGTH * OMEGA0  # tangent velocity, so that h' = 2 q.q' = 0
    qd0 = [v * math.cos(THETA0), v * math.sin(THETA0)]
    problem = chetaev.Problem(model, q0, qd0)
    return model, chetaev.solve(problem, 3.0, rtol=TOL, atol=TOL, output=TIMES)


@pytest.fixture(scope="module")
def angular(symbols):
    x, y, th, m, g, l = symbols
    L = m / 2 * l**2 * th.diff(t) ** 2 + m * g * l * sp.cos(th)
    model = chetaev.Model.from_sympy(L, [th], parameters={m: MASS, g: GRAV, l: LENGTH})
    return chetaev.solve(chetaev.Problem(model, [THETA0], [OMEGA0]), 3.0, rtol=TOL, atol=TOL,
                         output=TIMES)


def test_a_holonomic_constraint_counts_as_one_multiplier_and_no_velocity_constraint(cartesian):
    model, sol = cartesian
    assert model.k == 0 and model.holonomic_count == 1
    assert sol.mu.shape == (len(TIMES), 1)
    assert sol.position_residual.shape == (len(TIMES), 1)


def test_the_cartesian_pendulum_moves_as_the_pendulum_in_its_angle(cartesian, angular):
    _, sol = cartesian
    assert sol.success and angular.success
    np.testing.assert_array_equal(sol.t, TIMES)
    np.testing.assert_array_equal(angular.t, TIMES)
    theta = angular.q[:, 0]
    np.testing.assert_allclose(sol.q[:, 0], LENGTH * np.sin(theta), rtol=0, atol=AGREE)
    np.testing.assert_allclose(sol.q[:, 1], -LENGTH * np.cos(theta), rtol=0, atol=AGREE)
    omega = angular.qd[:, 0]
    np.testing.assert_allclose(sol.qd[:, 0], LENGTH * np.cos(theta) * omega, rtol=0, atol=AGREE)
    np.testing.assert_allclose(sol.qd[:, 1], LENGTH * np.sin(theta) * omega, rtol=0, atol=AGREE)
    # the pendulum swings through the bottom: the comparison covers a real motion
    assert theta.min() < 0 < theta.max()


def test_the_position_stays_on_the_circle(cartesian):
    _, sol = cartesian
    # h = |q|^2 - l^2, l^2 = 4: drift at the motion's global error, relative ~1000 * TOL.
    assert np.abs(sol.position_residual).max() <= 1000 * TOL * LENGTH**2
    np.testing.assert_allclose(sol.position_residual[:, 0],
                               (sol.q**2).sum(axis=1) - LENGTH**2, rtol=0, atol=1e-13)


def test_the_holonomic_multiplier_is_minus_the_rod_tension_over_2l(cartesian, angular):
    # Newton form: m q'' = (0, -m g) + mu dh/dq = (0, -m g) + 2 mu q; the rod pulls towards the
    # pivot with the tension S = m l theta'^2 + m g cos(theta), so 2 mu q = -S q / l.
    _, sol = cartesian
    theta, omega = angular.q[:, 0], angular.qd[:, 0]
    tension = MASS * LENGTH * omega**2 + MASS * GRAV * np.cos(theta)
    np.testing.assert_allclose(sol.mu[:, 0], -tension / (2 * LENGTH), rtol=0, atol=AGREE * 10)


def test_the_pendulum_conserves_energy_the_rod_does_no_work(cartesian):
    _, sol = cartesian
    e0 = sol.energy[0]
    np.testing.assert_allclose(sol.energy, e0, rtol=0, atol=1000 * TOL * 30)  # |E| ~ 30 J
    assert np.abs(sol.energy_balance).max() <= 1000 * TOL * 30


def test_projection_holds_the_pendulum_on_the_circle_at_a_loose_tolerance(cartesian):
    model, _ = cartesian
    q0 = [LENGTH * math.sin(THETA0), -LENGTH * math.cos(THETA0)]
    problem = chetaev.Problem(model, q0, [0.0, 0.0])
    loose = chetaev.solve(problem, 3.0, rtol=1e-5, atol=1e-5)
    held = chetaev.solve(problem, 3.0, rtol=1e-5, atol=1e-5, project=True)
    assert held.stats["projections"] > 0
    # projected to the default relative residual 1e-12 of |q|^2 ~ 4 (rounding included)
    assert np.abs(held.position_residual).max() <= 1e-11
    # without projection the drift is at the integration error, far above it
    assert np.abs(loose.position_residual).max() > 1e-9


def test_a_consistent_position_next_to_the_coordinates_origin_is_accepted():
    x, y = me.dynamicsymbols("x y")
    a, b, c = sp.symbols("a b c")
    L = (x.diff() ** 2 + y.diff() ** 2) / 2
    model = chetaev.Model.from_sympy(
        L, [x, y], holonomic=[y + a - b * c * sp.cos(x)], parameters={a: 0.3, b: 0.1, c: 3.0}
    )
    # y = bc cos x − a = 0 to rounding at x = 1e-12: h = −5.6e-17, from the terms 0.3 − 0.3;
    # 1e-10 · |∂h/∂q| · |q0| alone would allow 1e-22.
    problem = chetaev.Problem(model, q0=[1e-12, 0.0], qd0=[0.0, 0.0])
    assert list(problem.q0) == [1e-12, 0.0]
    # 1e-9 off the curve is no rounding of 0.3: still refused.
    with pytest.raises(chetaev.ChetaevError, match="violates holonomic constraint 1"):
        chetaev.Problem(model, q0=[1e-12, 1e-9], qd0=[0.0, 0.0])
