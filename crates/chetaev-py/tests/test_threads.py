"""Solves in threads: the GIL is released while a problem is solved, and a run depends only on
its inputs, so threads give exactly the numbers a sequential loop gives."""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

import chetaev
from models import particle_closed_form, particle_impact_time

GRAVITIES = [2.5, 5.0, 9.81, 10.0, 12.5, 20.0, 24.79, 30.0]
TOL = 1e-10  # rtol = atol


def _run(problem_of, g):
    return chetaev.solve(problem_of(g), 10.0, rtol=TOL, atol=TOL,
                         events=[chetaev.Event("impact", "y", direction="falling", terminal=True)])


@pytest.fixture(scope="module")
def problem_of(particle_model, particle_sympy):
    g = particle_sympy["symbols"]["g"]

    def make(value):
        return chetaev.Problem(particle_model.with_parameters({g: value}), [0.0, 5.0], [10.0, 0.0])

    return make


@pytest.fixture(scope="module")
def sequential(problem_of):
    return [_run(problem_of, g) for g in GRAVITIES]


def test_with_parameters_changes_only_the_value_asked_for(particle_model, particle_sympy):
    moon = particle_model.with_parameters({particle_sympy["symbols"]["g"]: 1.62})
    assert dict(moon.parameters) == {"m": 1.0, "g": 1.62, "v0": 10.0}
    assert dict(particle_model.parameters) == {"m": 1.0, "g": 10.0, "v0": 10.0}  # unchanged
    assert moon.operations == particle_model.operations  # the same graph
    assert dict(particle_model.with_parameters({"g": 3.0}).parameters)["g"] == 3.0


def test_each_parameter_value_gives_its_own_closed_form_impact(sequential):
    for g, sol in zip(GRAVITIES, sequential):
        # global error a modest multiple of TOL over a few seconds: 1000 * TOL
        assert sol.events[0].t == pytest.approx(particle_impact_time(g=g), abs=1000 * TOL)
        _, _, mu = particle_closed_form(sol.t, g=g)
        np.testing.assert_allclose(sol.mu, mu, rtol=0, atol=1000 * TOL)


def test_solves_in_a_thread_pool_give_exactly_the_sequential_results(problem_of, sequential):
    with ThreadPoolExecutor(max_workers=4) as pool:
        threaded = list(pool.map(lambda g: _run(problem_of, g), GRAVITIES * 3))
    for i, sol in enumerate(threaded):
        ref = sequential[i % len(GRAVITIES)]
        # the same inputs, the same arithmetic: bit for bit
        for name in ("t", "q", "qd", "qdd", "mu", "phi", "energy", "work", "energy_balance"):
            np.testing.assert_array_equal(getattr(sol, name), getattr(ref, name), err_msg=name)
        assert sol.events[0].t == ref.events[0].t
        assert sol.stats == ref.stats


def test_one_problem_shared_by_threads_gives_the_same_results(particle_problem, impact):
    def run(_):
        return chetaev.solve(particle_problem, 10.0, rtol=TOL, atol=TOL, events=[impact],
                             sensitivities=["g"])

    ref = run(None)
    with ThreadPoolExecutor(max_workers=4) as pool:
        for sol in pool.map(run, range(8)):
            np.testing.assert_array_equal(sol.q, ref.q)
            np.testing.assert_array_equal(sol.sensitivities["g"]["q"], ref.sensitivities["g"]["q"])
            assert sol.events[0].dt == ref.events[0].dt


def test_a_model_and_a_problem_pickle_with_their_parameters_and_state():
    import pickle

    import sympy as sp
    import sympy.physics.mechanics as me

    x, y = me.dynamicsymbols("x y")
    g, v0 = sp.symbols("g v0")
    L = (x.diff() ** 2 + y.diff() ** 2) / 2 - g * y
    model = chetaev.Model.from_sympy(L, [x, y], constraints=[x.diff() ** 2 + y.diff() ** 2 - v0**2],
                                     parameters={g: 10, v0: 10})
    moon = model.with_parameters({g: 1.62})
    again = pickle.loads(pickle.dumps(moon))
    assert again.parameters == moon.parameters == [("g", 1.62), ("v0", 10.0)]
    assert again.coordinates == ["x", "y"] and again.operations == moon.operations
    problem = chetaev.Problem(again, q0=[0, 5], qd0=[10, 0])
    copy = pickle.loads(pickle.dumps(problem))
    event = chetaev.Event("impact", y, direction="falling", terminal=True)
    a = chetaev.solve(problem, 100, rtol=1e-10, atol=1e-10, events=[event])
    b = chetaev.solve(copy, 100, rtol=1e-10, atol=1e-10, events=[event])
    # The same model, state and options: the same steps, bit for bit.
    assert a.events[0].t == b.events[0].t and np.array_equal(a.q, b.q)


def test_a_process_pool_sweeps_a_pickled_model():
    from concurrent.futures import ProcessPoolExecutor

    import sympy as sp
    import sympy.physics.mechanics as me

    x, y = me.dynamicsymbols("x y")
    g, v0 = sp.symbols("g v0")
    L = (x.diff() ** 2 + y.diff() ** 2) / 2 - g * y
    model = chetaev.Model.from_sympy(L, [x, y], constraints=[x.diff() ** 2 + y.diff() ** 2 - v0**2],
                                     parameters={g: 10, v0: 10})
    speeds = [5.0, 10.0, 20.0]
    with ProcessPoolExecutor(max_workers=2) as pool:
        times = list(pool.map(_impact_time, [model] * 3, speeds))
    # T = (v0/g) arccosh(exp(g h0 / v0²)), h0 = 5: to the tolerance (1e-10) with room.
    closed = [v / 10 * np.arccosh(np.exp(50 / v**2)) for v in speeds]
    np.testing.assert_allclose(times, closed, rtol=1e-8)


def _impact_time(model, speed):
    """The paper's impact time at speed `speed`, in a worker process."""
    p = chetaev.Problem(model.with_parameters({"v0": speed}), q0=[0, 5], qd0=[speed, 0])
    y = model.symbols.q[1]
    event = chetaev.Event("impact", y, direction="falling", terminal=True)
    return chetaev.solve(p, 100, rtol=1e-10, atol=1e-10, events=[event]).events[0].t
