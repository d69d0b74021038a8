"""Where and what a solve records (Output and Record of crates/chetaev/src/integrate/options.rs),
projection, and per-component absolute tolerances."""

from __future__ import annotations

import numpy as np
import pytest

import chetaev
from models import particle_closed_form

TOL = 1e-10  # rtol = atol
GLOBAL = 100 * TOL  # global error over ~1 s: a modest multiple of the local tolerance


def test_output_times_are_recorded_exactly_with_the_start_and_the_final_point(particle_problem):
    times = np.linspace(0.1, 0.9, 9)
    sol = chetaev.solve(particle_problem, 1.0, rtol=TOL, atol=TOL, output=times)
    # Output::Times: "at these times only, by dense output (plus the start and the final point)"
    np.testing.assert_array_equal(sol.t, np.concatenate([[0.0], times, [1.0]]))
    q, qd, mu = particle_closed_form(sol.t)
    np.testing.assert_allclose(sol.q, q, rtol=0, atol=10 * GLOBAL)
    np.testing.assert_allclose(sol.mu, mu, rtol=0, atol=GLOBAL)


def test_output_times_including_the_ends_record_each_end_once(particle_problem):
    times = np.linspace(0.0, 1.0, 11)
    sol = chetaev.solve(particle_problem, 1.0, rtol=TOL, atol=TOL, output=times)
    np.testing.assert_array_equal(sol.t, times)


def test_output_times_are_recorded_in_order_and_a_repeated_interior_time_twice(particle_problem):
    sol = chetaev.solve(particle_problem, 1.0, rtol=TOL, atol=TOL,
                        output=[0.5, 0.2, 0.5, 0.0, 1.0, 0.0])
    # sorted in the direction of integration; 0.5 twice, the start and the end once each
    np.testing.assert_array_equal(sol.t, [0.0, 0.2, 0.5, 0.5, 1.0])
    np.testing.assert_array_equal(sol.q[2], sol.q[3])


def test_output_times_backward_in_time_are_recorded_in_the_direction_of_integration(
    particle_problem,
):
    sol = chetaev.solve(particle_problem, -1.0, rtol=TOL, atol=TOL, output=[-0.2, -0.8, -0.5])
    np.testing.assert_array_equal(sol.t, [0.0, -0.2, -0.5, -0.8, -1.0])
    q, _, mu = particle_closed_form(sol.t)  # the closed form holds for t < 0 too
    np.testing.assert_allclose(sol.q, q, rtol=0, atol=10 * GLOBAL)
    np.testing.assert_allclose(sol.mu, mu, rtol=0, atol=GLOBAL)


def test_output_times_beyond_a_terminal_event_are_cut_at_the_event(particle_problem, impact):
    sol = chetaev.solve(particle_problem, 10.0, rtol=TOL, atol=TOL,
                        output=np.linspace(0.0, 10.0, 11), events=[impact])
    assert sol.status == "terminated"
    np.testing.assert_array_equal(sol.t[:-1], [0.0, 1.0])
    assert sol.t[-1] == sol.events[0].t


def test_output_final_records_the_start_and_the_end_only(particle_problem):
    sol = chetaev.solve(particle_problem, 1.0, rtol=TOL, atol=TOL, output="final")
    np.testing.assert_array_equal(sol.t, [0.0, 1.0])
    assert sol.q.shape == (2, 2) and sol.mu.shape == (2, 1)
    q, _, _ = particle_closed_form(1.0)
    np.testing.assert_allclose(sol.q[-1], q, rtol=0, atol=10 * GLOBAL)


def test_output_steps_records_every_accepted_step_and_the_start(particle_problem):
    sol = chetaev.solve(particle_problem, 1.0, rtol=TOL, atol=TOL, output="steps")
    assert len(sol) == sol.stats["accepted_steps"] + 1
    assert np.all(np.diff(sol.t) > 0) and sol.t[-1] == 1.0


def test_record_state_keeps_t_q_qd_and_leaves_the_dynamics_and_energy_empty(particle_problem):
    sol = chetaev.solve(particle_problem, 1.0, rtol=TOL, atol=TOL, record="state")
    m = len(sol)
    assert m > 2 and sol.q.shape == (m, 2) and sol.qd.shape == (m, 2)
    # "empty rows below record='dynamics'": zero rows, the width kept
    assert sol.qdd.shape == (0, 2) and sol.phi.shape == (0, 2)
    assert sol.mu.shape == (0, 1) and sol.residual.shape == (0, 1)
    assert sol.energy.shape == (0,) and sol.work.shape == (0,)
    assert sol.energy_balance.shape == (0,)


def test_record_dynamics_adds_the_multipliers_but_not_the_work(particle_problem):
    sol = chetaev.solve(particle_problem, 1.0, rtol=TOL, atol=TOL, record="dynamics")
    m = len(sol)
    assert sol.mu.shape == (m, 1) and sol.qdd.shape == (m, 2) and sol.residual.shape == (m, 1)
    # the quadratures of the work are carried only with record='energy'
    assert sol.work.shape == (0,) and sol.energy_balance.shape == (0,)
    full = chetaev.solve(particle_problem, 1.0, rtol=TOL, atol=TOL, record="energy")
    # recording more changes no step: the same motion
    np.testing.assert_array_equal(sol.t, full.t)
    np.testing.assert_array_equal(sol.mu, full.mu)
    assert full.energy.shape == (m,)


def test_the_position_residual_has_one_row_per_point_without_holonomic_constraints(
    particle_problem,
):
    sol = chetaev.solve(particle_problem, 1.0, rtol=TOL, atol=TOL)
    assert sol.position_residual.shape == (len(sol), 0)


def test_projection_holds_the_relative_residual_at_its_tolerance(particle_problem):
    loose = 1e-6
    free = chetaev.solve(particle_problem, 1.0, rtol=loose, atol=loose)
    held = chetaev.solve(particle_problem, 1.0, rtol=loose, atol=loose, project=True)
    assert held.stats["projections"] > 0 and free.stats["projections"] == 0
    # the default projection tolerance 1e-12 of |f| against its velocity terms
    assert held.relative_residual.max() <= 1e-12
    assert np.abs(held.residual).max() <= 1e-12 * 2 * 10.0**2  # the terms of f are ~2 v0^2
    # without it the residual is at the integration error, far above
    assert free.relative_residual.max() > 1e-10
    tight = chetaev.solve(particle_problem, 1.0, rtol=loose, atol=loose, project=1e-14)
    assert tight.relative_residual.max() <= 1e-14


def test_a_per_component_atol_equal_to_the_scalar_gives_the_same_run(particle_problem):
    scalar = chetaev.solve(particle_problem, 1.0, rtol=TOL, atol=TOL)
    listed = chetaev.solve(particle_problem, 1.0, rtol=TOL, atol=[TOL] * 4)
    as_array = chetaev.solve(particle_problem, 1.0, rtol=TOL, atol=np.full(4, TOL))
    for sol in (listed, as_array):
        np.testing.assert_array_equal(sol.t, scalar.t)
        np.testing.assert_array_equal(sol.q, scalar.q)


@pytest.mark.parametrize("component", range(4))
def test_a_per_component_atol_controls_its_own_component(particle_problem, component):
    # rtol = 0: the absolute tolerances alone set the steps. One tight component (1e-12) among
    # loose ones (1) makes the run accurate; all loose, it is not.
    loose = chetaev.solve(particle_problem, 1.0, rtol=0.0, atol=[1.0] * 4, output="final")
    atol = [1.0] * 4
    atol[component] = 1e-12
    tight = chetaev.solve(particle_problem, 1.0, rtol=0.0, atol=atol, output="final")
    q, qd, _ = particle_closed_form(1.0)
    exact = np.concatenate([q, qd])
    error = np.abs(np.concatenate([tight.q[-1], tight.qd[-1]]) - exact)
    # the tight component's global error: a modest multiple of its 1e-12
    assert error[component] <= 1e-9
    assert np.abs(np.concatenate([loose.q[-1], loose.qd[-1]]) - exact).max() > 1e-9
    assert tight.stats["accepted_steps"] > loose.stats["accepted_steps"]
