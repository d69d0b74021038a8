"""The rolling disc of sympy's tests (models.py) against sympy's LagrangesMethod + scipy's DOP853.

Two nonholonomic constraints linear and homogeneous in the velocities (rolling without slip);
the multipliers in Newton form are the ground's friction force on the disc (models.py).
"""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp
import sympy.physics.mechanics as me

import chetaev
import models

T_END = 5.0
TOL = 1e-12  # rtol = atol on both sides (chetaev and the scipy reference)
# Each side's global error over 5 s (a few hundred steps) is at most ~1000 * TOL on these O(1..30)
# quantities; the two sides differ by at most the sum: a few 1e-9.
AGREE = 3e-9


@pytest.fixture(scope="module")
def disc_model(disc_sympy):
    d = disc_sympy
    return chetaev.Model.from_sympy(d["L"], d["q"], constraints=d["constraints"],
                                    parameters=d["parameters"])


@pytest.fixture(scope="module")
def disc_run(disc_model, disc_sympy):
    problem = chetaev.Problem(disc_model, disc_sympy["q0"], disc_sympy["qd0"])
    return chetaev.solve(problem, T_END, rtol=TOL, atol=TOL)


@pytest.fixture(scope="module")
def reference():
    return models.rolling_disc_reference(T_END, rtol=TOL, atol=TOL)


def test_the_disc_model_has_five_coordinates_and_two_rolling_constraints(disc_model):
    assert disc_model.n == 5 and disc_model.k == 2 and disc_model.holonomic_count == 0
    assert disc_model.coordinates == ["q1", "q2", "q3", "x", "y"]
    assert dict(disc_model.parameters) == models.DISC_PARAMETERS


def test_the_disc_reaches_the_end_time(disc_run):
    assert disc_run.status == "success" and disc_run.success and disc_run.message is None
    assert disc_run.t[0] == 0.0 and disc_run.t[-1] == T_END


def test_the_end_state_and_multipliers_agree_with_sympy_lagranges_method_and_scipy(
    disc_run, reference
):
    t_final, q, qd, mu = reference
    assert t_final == T_END
    np.testing.assert_allclose(disc_run.q[-1], q, rtol=0, atol=AGREE)
    np.testing.assert_allclose(disc_run.qd[-1], qd, rtol=0, atol=AGREE)
    # mu in Newton form on both sides (models.py: sympy's lam are -mu, the reference returns +mu)
    np.testing.assert_allclose(disc_run.mu[-1], mu, rtol=0, atol=AGREE)
    # the comparison is not vacuous: the disc has moved and the friction is not small
    assert np.abs(q[3:]).max() > 1.0 and np.abs(mu).max() > 0.5


def test_the_accelerations_and_multipliers_at_each_recorded_state_are_the_references(disc_run):
    # the equations alone, at chetaev's own states: rounding of the two linear solves only.
    for i in range(0, len(disc_run), max(1, len(disc_run) // 10)):
        qdd, mu = models.rolling_disc_accelerations(disc_run.q[i], disc_run.qd[i])
        np.testing.assert_allclose(disc_run.qdd[i], qdd, rtol=0, atol=1e-10)
        np.testing.assert_allclose(disc_run.mu[i], mu, rtol=0, atol=1e-10)


def test_the_multipliers_are_the_friction_force_m_times_the_centres_horizontal_acceleration(
    disc_run, disc_sympy
):
    # Newton form: friction is the only horizontal force on the disc, mu = m a_D (N.x, N.y).
    d = disc_sympy
    t = me.dynamicsymbols._t
    D, N = d["points"]["D"], d["frame"]
    acc = D.pos_from(d["points"]["O"]).dt(N).dt(N)
    qs, vs, ws = (sp.symbols(f"{k}0:5") for k in "qvw")
    sub = {**{c.diff(t, 2): w for c, w in zip(d["q"], ws)},
           **{c.diff(t): v for c, v in zip(d["q"], vs)},
           **dict(zip(d["q"], qs)), **d["parameters"]}
    f = sp.lambdify((qs, vs, ws), [acc.dot(N.x).subs(sub), acc.dot(N.y).subs(sub)])
    m = models.DISC_PARAMETERS["m"]
    for i in range(0, len(disc_run), max(1, len(disc_run) // 10)):
        a = np.array(f(disc_run.q[i], disc_run.qd[i], disc_run.qdd[i]), dtype=float)
        # evaluation of the recorded (q, q', q''): rounding only
        np.testing.assert_allclose(disc_run.mu[i], m * a, rtol=0, atol=1e-10)


def test_the_disc_keeps_rolling_without_slip(disc_run):
    assert disc_run.residual.shape == (len(disc_run), 2)
    # velocities of order 3 m/s held at the local tolerance, drifting by ~1000 * TOL at most.
    assert np.abs(disc_run.residual).max() <= 1000 * TOL * 3
    for i in (0, len(disc_run) // 2, -1):
        f = models.rolling_disc_constraints(disc_run.q[i], disc_run.qd[i])
        np.testing.assert_allclose(disc_run.residual[i], f, rtol=0, atol=1e-13)


def test_the_energy_is_conserved_because_rolling_constraints_do_no_work(disc_run):
    e0 = models.rolling_disc_energy(disc_run.q[0], disc_run.qd[0])
    assert disc_run.energy[0] == pytest.approx(e0, rel=1e-14)
    # E ~ 7 J; the motion's error ~1000 * TOL relative over 5 s.
    np.testing.assert_allclose(disc_run.energy, e0, rtol=1000 * TOL, atol=0)
    # q'.Phi = mu . (J q') = mu . f = 0 for constraints linear and homogeneous in q'
    assert np.abs(disc_run.work).max() <= 1000 * TOL * abs(e0)
    assert np.abs(disc_run.energy_balance).max() <= 1000 * TOL * abs(e0)
    energies = [models.rolling_disc_energy(q, qd) for q, qd in zip(disc_run.q, disc_run.qd)]
    np.testing.assert_allclose(disc_run.energy, energies, rtol=1e-13, atol=0)


def test_the_disc_made_from_its_frame_and_bodies_has_sympys_lagrangian(disc_sympy):
    d = disc_sympy
    from_bodies = chetaev.Model.from_sympy(q=d["q"], frame=d["frame"], bodies=d["bodies"],
                                           constraints=d["constraints"],
                                           parameters=d["parameters"])
    problem = chetaev.Problem(from_bodies, d["q0"], d["qd0"])
    t = me.dynamicsymbols._t
    qs, vs = sp.symbols("q0:5"), sp.symbols("v0:5")
    sub = {**{c.diff(t): v for c, v in zip(d["q"], vs)}, **dict(zip(d["q"], qs)),
           **d["parameters"]}
    lagrangian = sp.lambdify((qs, vs), me.Lagrangian(d["frame"], *d["bodies"]).subs(sub))
    rng = np.random.default_rng(7)
    for _ in range(5):
        q = rng.uniform(-1, 1, 5)
        qd = models.disc_dependent_velocities(q, rng.uniform(-3, 3, 3), 0.5)
        eq = problem.equations_at(0.0, list(q), qd)
        # L ~ 10 J, evaluated two ways: rounding only
        assert eq["lagrangian"] == pytest.approx(float(lagrangian(q, qd)), rel=1e-13, abs=1e-13)
        assert eq["energy"] == pytest.approx(models.rolling_disc_energy(q, qd), rel=1e-13)


def test_the_machine_code_choices_agree_and_auto_repeats_itself_to_the_bit(disc_model, disc_sympy):
    # The disc to t = 5 at 1e-12 takes a few thousand right-hand sides: "auto" compiles within the
    # first solve. Two fresh problems switch at the same evaluation, so they agree to the bit;
    # "never" and "at_once" take the other routes, equal to rounding.
    def run(machine_code):
        problem = chetaev.Problem(disc_model, disc_sympy["q0"], disc_sympy["qd0"], machine_code=machine_code)
        return chetaev.solve(problem, T_END, rtol=TOL, atol=TOL)

    first, again = run("auto"), run("auto")
    assert np.array_equal(first.t, again.t) and np.array_equal(first.q, again.q)
    for other in ("never", "at_once"):
        sol = run(other)
        assert abs(sol.t[-1] - first.t[-1]) == 0
        assert np.abs(sol.q[-1] - first.q[-1]).max() < 1e-9, other


def test_the_machine_code_choice_survives_pickling_and_a_wrong_one_is_refused(disc_model, disc_sympy):
    import pickle

    problem = chetaev.Problem(disc_model, disc_sympy["q0"], disc_sympy["qd0"], machine_code="never")
    back = pickle.loads(pickle.dumps(problem))
    # Long enough that "auto" would switch to machine code, whose rounding differs.
    a = chetaev.solve(problem, T_END, rtol=TOL, atol=TOL)
    b = chetaev.solve(back, T_END, rtol=TOL, atol=TOL)
    assert np.array_equal(a.q, b.q)
    with pytest.raises(chetaev.ChetaevError, match="'auto'.*'never'.*'at_once'"):
        chetaev.Problem(disc_model, disc_sympy["q0"], disc_sympy["qd0"], machine_code="fast")
