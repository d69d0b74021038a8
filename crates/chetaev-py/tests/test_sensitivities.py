"""Seeds: derivatives of the motion and of the impact time with respect to initial values and
parameters, against the closed form differentiated (docs/sensitivities.md)."""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp

import chetaev
from models import PARTICLE_H0, particle_closed_form

G, V0, H0 = 10.0, 10.0, PARTICLE_H0
TOL = 1e-12  # rtol = atol, sensitivities under the same control
GLOBAL = 1000 * TOL  # global error over ~1 s: a modest multiple of the local tolerance


def _closed_form_derivative(wrt: str) -> float:
    """d/d(wrt) of T = (v0/g) arccosh(exp(g h0 / v0^2))."""
    g, v0, h0 = sp.symbols("g v0 h0", positive=True)
    T = v0 / g * sp.acosh(sp.exp(g * h0 / v0**2))
    return float(sp.diff(T, {"g": g, "v0": v0, "h0": h0}[wrt]).subs({g: G, v0: V0, h0: H0}))


def test_the_closed_form_derivative_in_h0_is_e_to_the_a_over_v0_sqrt_e_to_the_2a_minus_1():
    # a cross-check of the reference itself, by hand: a = g h0 / v0^2
    a = G * H0 / V0**2
    assert _closed_form_derivative("h0") == pytest.approx(
        math.exp(a) / (V0 * math.sqrt(math.exp(2 * a) - 1)), rel=1e-14)


@pytest.mark.parametrize("make,name", [
    (lambda: chetaev.Seed.position(1), "q2(t0)"),
    (lambda: chetaev.Seed("dh", positions=[(1, 1.0)]), "dh"),
], ids=["Seed.position(1)", "Seed('dh', positions=[(1, 1.0)])"])
def test_the_impact_time_moves_with_the_initial_height_as_the_closed_form_says(
    particle_problem, impact, make, name
):
    seed = make()
    assert seed.name == name
    sol = chetaev.solve(particle_problem, 10.0, rtol=TOL, atol=TOL, events=[impact],
                        sensitivities=[seed], sensitivity_control=True)
    assert list(sol.sensitivities) == [name]
    assert sol.events[0].dt[name] == pytest.approx(_closed_form_derivative("h0"), abs=GLOBAL)
    # y = h0 - (v0^2/g) ln cosh(g t/v0), x independent of h0: dq/dh0 = (0, 1), dq'/dh0 = 0
    dq, dqd = sol.sensitivities[name]["q"], sol.sensitivities[name]["qd"]
    assert dq.shape == dqd.shape == (len(sol), 2)
    np.testing.assert_allclose(dq, np.tile([0.0, 1.0], (len(sol), 1)), rtol=0, atol=GLOBAL)
    np.testing.assert_allclose(dqd, 0.0, rtol=0, atol=GLOBAL)


def test_a_seed_of_the_speed_moving_v0_and_the_initial_velocity_together_gives_dT_dv0(
    particle_problem, impact
):
    # f = |q'|^2 - v0^2 keeps holding if x'(0) = v0 moves with v0: rate 1 on q'_1(0).
    seed = chetaev.Seed("dv0", parameters={"v0": 1.0}, velocities=[(0, 1.0)])
    sol = chetaev.solve(particle_problem, 10.0, rtol=TOL, atol=TOL, events=[impact],
                        sensitivities=[seed], sensitivity_control=True)
    assert sol.events[0].dt["dv0"] == pytest.approx(_closed_form_derivative("v0"), abs=GLOBAL)


def test_a_seed_that_leaves_the_constraint_is_refused(particle_problem):
    # moving x'(0) alone breaks |q'(0)| = v0
    with pytest.raises(chetaev.ChetaevError, match="velocity constraint 1"):
        chetaev.solve(particle_problem, 1.0, sensitivities=[chetaev.Seed.velocity(0)])


def test_a_seed_of_a_coordinate_the_model_does_not_have_is_refused(particle_problem):
    with pytest.raises(chetaev.ChetaevError, match="2 coordinates"):
        chetaev.solve(particle_problem, 1.0, sensitivities=[chetaev.Seed.position(7)])


def test_several_seeds_are_carried_together_each_as_alone(particle_problem, impact):
    seeds = [chetaev.Seed.parameter("g"), chetaev.Seed("dh", positions=[(1, 1.0)])]
    both = chetaev.solve(particle_problem, 10.0, rtol=TOL, atol=TOL, events=[impact],
                         sensitivities=seeds, sensitivity_control=True)
    assert list(both.sensitivities) == ["g", "dh"]
    assert both.events[0].dt["g"] == pytest.approx(_closed_form_derivative("g"), abs=GLOBAL)
    assert both.events[0].dt["dh"] == pytest.approx(_closed_form_derivative("h0"), abs=GLOBAL)


def test_without_seeds_there_are_no_sensitivities(particle_problem, impact):
    sol = chetaev.solve(particle_problem, 10.0, rtol=TOL, atol=TOL, events=[impact])
    assert sol.sensitivities is None
    assert sol.events[0].dt == {}


def test_the_motion_is_the_same_with_uncontrolled_sensitivities(particle_problem):
    # sensitivity_control=False: "the step size is then the motion's"
    plain = chetaev.solve(particle_problem, 1.0, rtol=TOL, atol=TOL)
    seeded = chetaev.solve(particle_problem, 1.0, rtol=TOL, atol=TOL, sensitivities=["g"])
    np.testing.assert_array_equal(seeded.t, plain.t)
    np.testing.assert_array_equal(seeded.q, plain.q)
    q, _, _ = particle_closed_form(plain.t)
    np.testing.assert_allclose(plain.q, q, rtol=0, atol=10 * GLOBAL)


def test_the_repr_of_a_velocity_seed_shows_its_name_as_python_would():
    seed = chetaev.Seed.velocity(0)
    assert seed.name == "q\u0307" + "1(t0)"  # q̇1(t0)
    assert seed.name in repr(seed), repr(seed)


@pytest.mark.parametrize("wrt", ["g", "v0"])
def test_the_multiplier_and_the_chetaev_force_move_as_the_closed_form_says(
    particle_problem, impact, wrt
):
    # mu = -(m g / (2 v0)) tanh(g t / v0) (42.40), Phi = 2 mu q', differentiated by sympy
    m, g, v0, t = sp.symbols("m g v0 t", positive=True)
    u = g * t / v0
    mu = -(m * g / (2 * v0)) * sp.tanh(u)
    phi = [2 * mu * v0 / sp.cosh(u), -2 * mu * v0 * sp.tanh(u)]
    symbol = {"g": g, "v0": v0}[wrt]
    values = {m: 1.0, g: G, v0: V0}
    exact = [sp.lambdify(t, sp.diff(e, symbol).subs(values), "numpy") for e in [mu, *phi]]
    seed = (chetaev.Seed.parameter("g") if wrt == "g"
            else chetaev.Seed("v0", parameters={"v0": 1.0}, velocities=[(0, 1.0)]))
    sol = chetaev.solve(particle_problem, 10.0, rtol=TOL, atol=TOL, events=[impact],
                        sensitivities=[seed], sensitivity_control=True, record="dynamics")
    s = sol.sensitivities[seed.name]
    assert s["mu"].shape == (len(sol), 1) and s["phi"].shape == (len(sol), 2)
    times = np.asarray(sol.t)
    size = max(np.max(np.abs(np.broadcast_to(f(times), times.shape))) for f in exact)
    np.testing.assert_allclose(s["mu"][:, 0], exact[0](times), rtol=0, atol=1e-10 * size)
    for i in range(2):
        np.testing.assert_allclose(s["phi"][:, i], exact[i + 1](times), rtol=0, atol=1e-10 * size)


def test_without_the_multipliers_recorded_their_sensitivities_are_absent(particle_problem, impact):
    sol = chetaev.solve(particle_problem, 10.0, events=[impact], record="state",
                        sensitivities=[chetaev.Seed.parameter("g")])
    assert set(sol.sensitivities["g"]) == {"q", "qd"}
