"""The energy balance dE/dt = q'.Phi + q'.Q - dL/dt with explicit time: a constraint that depends
on t (its force does work) and a Lagrangian that depends on t; a time symbol of one's own; and
parameters given by name."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp
import sympy.physics.mechanics as me
from scipy.integrate import solve_ivp

import chetaev

t = me.dynamicsymbols._t
TOL = 1e-12  # rtol = atol
GLOBAL = 1000 * TOL  # global error over a few seconds: a modest multiple of the tolerance


def test_a_constraint_that_depends_on_time_drives_the_particle_and_does_work():
    # L = x'^2/2, f = x' - cos t: x = sin t, and in Newton form x'' = mu df/dx' = mu = -sin t;
    # W_Phi = int x' mu dt = -sin^2 t / 2 = E - E0.
    x = me.dynamicsymbols("x")
    model = chetaev.Model.from_sympy(x.diff(t) ** 2 / 2, [x], constraints=[x.diff(t) - sp.cos(t)])
    sol = chetaev.solve(chetaev.Problem(model, [0.0], [1.0]), 2.0, rtol=TOL, atol=TOL)
    np.testing.assert_allclose(sol.q[:, 0], np.sin(sol.t), rtol=0, atol=GLOBAL)
    np.testing.assert_allclose(sol.mu[:, 0], -np.sin(sol.t), rtol=0, atol=GLOBAL)
    np.testing.assert_allclose(sol.work, -np.sin(sol.t) ** 2 / 2, rtol=0, atol=GLOBAL)
    np.testing.assert_allclose(sol.energy - sol.energy[0], sol.work, rtol=0, atol=GLOBAL)
    assert np.abs(sol.energy_balance).max() <= GLOBAL


def test_a_lagrangian_that_depends_on_time_changes_the_energy_by_minus_the_integral_of_dL_dt():
    # L = x'^2/2 - k(t) x^2/2, k = 1 + sin(t)/2: dE/dt = -dL/dt = k'(t) x^2 / 2.
    x = me.dynamicsymbols("x")
    k = 1 + sp.sin(t) / 2
    model = chetaev.Model.from_sympy(x.diff(t) ** 2 / 2 - k * x**2 / 2, [x])
    times = np.linspace(0.0, 3.0, 7)
    sol = chetaev.solve(chetaev.Problem(model, [1.0], [0.0]), 3.0, rtol=TOL, atol=TOL,
                        output=times)

    def rhs(tt, s):  # x, x', and int dL/dt = int -cos(t)/4 x^2 dt
        return [s[1], -(1 + np.sin(tt) / 2) * s[0], -np.cos(tt) / 4 * s[0] ** 2]

    ref = solve_ivp(rhs, (0.0, 3.0), [1.0, 0.0, 0.0], method="DOP853", rtol=TOL, atol=TOL,
                    t_eval=times)
    np.testing.assert_allclose(sol.q[:, 0], ref.y[0], rtol=0, atol=2 * GLOBAL)
    np.testing.assert_allclose(sol.dl_dt_integral, ref.y[2], rtol=0, atol=2 * GLOBAL)
    np.testing.assert_allclose(sol.energy - sol.energy[0], -sol.dl_dt_integral, rtol=0,
                               atol=GLOBAL)
    assert np.abs(sol.energy_balance).max() <= GLOBAL
    assert abs(sol.dl_dt_integral[-1]) > 1e-4  # the energy does change


def test_a_time_symbol_of_ones_own_is_time_in_the_model_and_in_events():
    tau = sp.Symbol("tau")
    X = sp.Function("X")(tau)
    model = chetaev.Model.from_sympy(X.diff(tau) ** 2 / 2 - X**2 / 2, [X], t=tau)
    assert model.coordinates == ["X"]
    events = [chetaev.Event("half-way", "X - 0.9"), chetaev.Event("clock", tau - 0.3)]
    sol = chetaev.solve(chetaev.Problem(model, [1.0], [0.0]), 1.0, rtol=TOL, atol=TOL,
                        events=events)
    # X = cos(tau); the hits come in time order
    assert [e.name for e in sol.events] == ["clock", "half-way"]
    assert sol.events[0].t == pytest.approx(0.3, abs=GLOBAL)
    assert sol.events[1].t == pytest.approx(np.arccos(0.9), abs=GLOBAL)
    assert sol.q[-1, 0] == pytest.approx(np.cos(1.0), abs=GLOBAL)


def test_parameters_may_be_given_by_name():
    x = me.dynamicsymbols("x")
    w = sp.Symbol("w")
    model = chetaev.Model.from_sympy(x.diff(t) ** 2 / 2 - w**2 * x**2 / 2, [x],
                                     parameters={"w": 2.0})
    sol = chetaev.solve(chetaev.Problem(model, [1.0], [0.0]), 1.0, rtol=TOL, atol=TOL,
                        output="final")
    assert sol.q[-1, 0] == pytest.approx(np.cos(2.0), abs=GLOBAL)


def test_parameters_given_by_name_match_symbols_with_assumptions():
    x = me.dynamicsymbols("x")
    w = sp.Symbol("w", positive=True)
    model = chetaev.Model.from_sympy(x.diff(t) ** 2 / 2 - w**2 * x**2 / 2, [x],
                                     parameters={"w": 2.0})
    sol = chetaev.solve(chetaev.Problem(model, [1.0], [0.0]), 1.0, rtol=TOL, atol=TOL,
                        output="final")
    assert sol.q[-1, 0] == pytest.approx(np.cos(2.0), abs=GLOBAL)
