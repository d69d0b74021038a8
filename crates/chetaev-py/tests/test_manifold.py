"""Dependent coordinates and speeds completed from the independent ones, and the linearisation on
the constraint manifold, against closed forms."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp
import sympy.physics.mechanics as me

import chetaev


@pytest.fixture(scope="module")
def pendulum():
    x, y = me.dynamicsymbols("x y")
    g, l = sp.symbols("g l")
    L = (x.diff() ** 2 + y.diff() ** 2) / 2 - g * y
    model = chetaev.Model.from_sympy(L, [x, y], holonomic=[x**2 + y**2 - l**2],
                                     parameters={g: 9.81, l: 2.0})
    return model, x, y


def test_the_dependent_coordinate_and_speed_of_a_pendulum_are_solved_from_the_independent_ones(pendulum):
    model, x, y = pendulum
    # x = 1.2 on a rod of 2: y = −1.6 (from a guess 10 % off); ẋ = 0.8: ẏ = −x ẋ / y = 0.6.
    q, qd = chetaev.complete(model, [1.2, -1.76], [0.8, 0.0], coordinates=[x], speeds=[x.diff()])
    np.testing.assert_allclose(q, [1.2, -1.6], rtol=0, atol=1e-14)
    np.testing.assert_allclose(qd, [0.8, 0.6], rtol=0, atol=1e-14)


def test_a_problem_completes_its_initial_state_when_independent_ones_are_named(pendulum):
    model, x, _ = pendulum
    problem = chetaev.Problem(model, q0={"x": 1.2, "y": -1.76}, qd0=[0.8, 0.0],
                              independent_coordinates=["x"], independent_speeds=["x_dot"])
    np.testing.assert_allclose(problem.q0, [1.2, -1.6], rtol=0, atol=1e-14)
    np.testing.assert_allclose(problem.qd0, [0.8, 0.6], rtol=0, atol=1e-14)
    # complete=True chooses the dependent ones itself.
    auto = chetaev.Problem(model, q0=[1.2, -1.76], qd0=[0.8, 0.0], complete=True)
    assert abs(np.hypot(*auto.q0) - 2.0) < 1e-14


def test_the_hanging_pendulum_linearised_oscillates_at_sqrt_g_over_l(pendulum):
    model, x, _ = pendulum
    problem = chetaev.Problem(model, q0=[0.0, -2.0], qd0=[0.0, 0.0])
    lin = problem.linearize(coordinates=[x], speeds=[x])
    assert lin.states == ["x", "x_dot"] and lin.a.shape == (2, 2)
    # ±i√(g/l), exact Jacobian: to rounding.
    np.testing.assert_allclose(lin.eigenvalues, [-1j * np.sqrt(9.81 / 2), 1j * np.sqrt(9.81 / 2)],
                               atol=1e-12)
    for value, vector in zip(lin.eigenvalues, lin.eigenvectors.T):
        np.testing.assert_allclose(lin.a @ vector, value * vector, atol=1e-12)


def test_the_particle_at_constant_speed_completes_the_root_nearest_its_guess():
    x, y = me.dynamicsymbols("x y")
    g, v0 = sp.symbols("g v0")
    L = (x.diff() ** 2 + y.diff() ** 2) / 2 - g * y
    model = chetaev.Model.from_sympy(L, [x, y], constraints=[x.diff() ** 2 + y.diff() ** 2 - v0**2],
                                     parameters={g: 10, v0: 10})
    _, down = chetaev.complete(model, [0, 5], [6, -7.2], speeds=["x"])
    _, up = chetaev.complete(model, [0, 5], [6, 8.8], speeds=["x"])
    assert abs(down[1] + 8) < 1e-14 and abs(up[1] - 8) < 1e-14
    with pytest.raises(chetaev.ChetaevError, match="completing the dependent speeds failed at velocity constraint 1"):
        chetaev.complete(model, [0, 5], [12, -1], speeds=["x"])
    with pytest.raises(chetaev.ChetaevError, match="not a coordinate"):
        chetaev.complete(model, [0, 5], [6, -8], speeds=["z"])
    with pytest.raises(chetaev.ChetaevError, match="have 1"):
        chetaev.complete(model, [0, 5], [6, -8], speeds=[0, 1])


def test_completion_reports_its_dependent_indices_and_newton_iterations(pendulum):
    model, x, _ = pendulum
    q, qd, info = chetaev.complete(model, [1.2, -1.76], [0.8, 0.0], coordinates=[x], speeds=[x],
                                   info=True)
    assert info["dependent_coordinates"] == [1] and info["dependent_speeds"] == [1]
    # From a guess 10 % off, Newton's method converges in a handful of iterations.
    assert 1 <= info["coordinate_iterations"] <= 10 and 1 <= info["speed_iterations"] <= 10


def test_a_negative_or_too_large_index_is_a_conversion_error(pendulum):
    model, _, _ = pendulum
    problem = chetaev.Problem(model, q0=[0.0, -2.0], qd0=[0.0, 0.0])
    for bad in (-1, 2):
        with pytest.raises(chetaev.ConversionError, match=f"index {bad} is out of range for 2"):
            problem.linearize(coordinates=[bad])
