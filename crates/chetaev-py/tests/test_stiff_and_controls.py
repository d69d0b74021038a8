"""Stiff problems and the solver's controls: the paper's stiff scene (v0 = 1e-3, h0 = 1), the
stiffness test of the explicit methods, the step-size controller and the rank tolerance."""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp
from sympy.physics.mechanics import dynamicsymbols

import chetaev

V0, G, H0 = 1e-3, 9.81, 1.0


@pytest.fixture(scope="module")
def stiff():
    x, y = dynamicsymbols("x y")
    g, v0 = sp.symbols("g v0")
    L = (x.diff() ** 2 + y.diff() ** 2) / 2 - g * y
    f = x.diff() ** 2 + y.diff() ** 2 - v0**2
    model = chetaev.Model.from_sympy(L, [x, y], constraints=[f], parameters={g: G, v0: V0})
    problem = chetaev.Problem(model, q0=[0.0, H0], qd0=[V0, 0.0])
    impact = chetaev.Event("impact", y, direction="falling", terminal=True)
    return problem, impact


def impact_time() -> float:
    # T = (v0/g) arccosh(e^z), z = g h0/v0² ≈ 9.8e6: arccosh(e^z) = z + ln 2 − e^(−2z)/4 − ...,
    # and e^(−2z) underflows, so T = h0/v0 + (v0/g) ln 2 to rounding.
    return H0 / V0 + V0 / G * math.log(2.0)


@pytest.mark.parametrize("method", ["rodas4", "rodas5p"])
def test_the_implicit_methods_reach_the_stiff_impact(stiff, method):
    problem, impact = stiff
    # Absolute tolerances scaled to the motion: positions of 1 m, velocities of v0 = 1 mm/s.
    rtol = 1e-10
    atol = [rtol * H0] * 2 + [rtol * V0] * 2
    sol = chetaev.solve(problem, 2000.0, method=method, rtol=rtol, atol=atol, events=[impact])
    assert sol.status == "terminated"
    # T ≈ 1000 s to 1e-8 relative: 100 × rtol, for the error grown over the 1000 s fall.
    assert sol.events[0].t == pytest.approx(impact_time(), rel=1e-8)
    assert sol.stats["jacobian_evaluations"] > 0 and sol.stats["lu_decompositions"] > 0


def test_an_explicit_method_stops_on_the_stiff_scene_and_names_an_implicit_one(stiff):
    problem, impact = stiff
    sol = chetaev.solve(problem, 2000.0, method="dopri5", rtol=1e-8, atol=1e-8, events=[impact])
    assert sol.status == "failed" and not sol.success
    assert "stiff" in sol.message.lower() and "Rodas4" in sol.message
    assert len(sol) > 1 and sol.t[-1] < 1000.0           # the motion so far is kept
    assert sol.stats["jacobian_evaluations"] == 0         # an explicit method needs none


def test_switching_the_stiffness_test_off_lets_the_method_go_on_to_its_step_limit(stiff):
    problem, impact = stiff
    sol = chetaev.solve(problem, 2000.0, method="dopri5", rtol=1e-8, atol=1e-8, events=[impact],
                        stiffness_detection=False, max_steps=3000)
    assert sol.status == "failed"
    assert "step limit" in sol.message and "stiff" not in sol.message.split(";")[0].lower()
    assert sol.stats["accepted_steps"] + sol.stats["rejected_steps"] >= 3000 - 1


def test_stiffness_detection_is_refused_for_a_method_without_it(stiff):
    problem, _ = stiff
    with pytest.raises(chetaev.ChetaevError, match="explicit methods with error control"):
        chetaev.solve(problem, 1.0, method="rodas4", stiffness_detection=True)


def test_another_controller_changes_the_steps_not_the_answer(particle_problem, impact):
    kw = dict(method="dopri5", rtol=1e-10, atol=1e-10, events=[impact])
    plain = chetaev.solve(particle_problem, 10.0, **kw)
    pi = chetaev.solve(particle_problem, 10.0, controller={"safety": 0.7, "beta": 0.0},
                       **kw)
    assert plain.stats["accepted_steps"] != pi.stats["accepted_steps"] or not np.array_equal(plain.t, pi.t)
    # Both at rtol = 1e-10 on T ≈ 1.085: agree to the tolerance's order.
    assert pi.events[0].t == pytest.approx(plain.events[0].t, rel=1e-9)


def test_an_unknown_controller_key_is_refused(particle_problem):
    with pytest.raises(chetaev.ChetaevError, match="unknown controller key 'gain'"):
        chetaev.solve(particle_problem, 1.0, controller={"gain": 1.0})


def test_the_rank_tolerance_is_passed_to_the_library_and_checked(particle_problem):
    with pytest.raises(chetaev.ChetaevError, match="rank"):
        chetaev.solve(particle_problem, 1.0, rank_tolerance=-1.0)
    sol = chetaev.solve(particle_problem, 1.0, rank_tolerance=1e-6)
    assert sol.success
