"""The Carvallo–Whipple bicycle (models.whipple_bicycle) against the benchmark of Meijaard,
Papadopoulos, Ruina and Schwab (2007), "Linearized dynamics equations for the balance and steer of
a bicycle: a benchmark and review", Proc. R. Soc. A 463, 1955–1982.

The published numbers (Table 2: the eigenvalues of upright straight running at v = 0, 1, ..., 10
m/s, and the weave and capsize speeds) are in models.py, with where they were transcribed from.
chetaev knows nothing of the linearised benchmark: it linearises the full nonlinear model (eight
coordinates, four rolling constraints, one holonomic constraint) on its constraint manifold, by
automatic differentiation, at the upright state.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg
import sympy as sp
from scipy.optimize import brentq

import chetaev
import models

# All coordinates but the pitch (which the front wheel's touching the ground fixes), and the
# three speeds of the paper: roll rate, rear-wheel rate, steer rate.
COORDINATES = ["x", "y", "psi", "phi", "theta_R", "delta", "theta_F"]
SPEEDS = ["phi_dot", "theta_R_dot", "delta_dot"]
STATES = COORDINATES + SPEEDS
LATERAL = ["phi", "delta", "phi_dot", "delta_dot"]

# Tolerances.
# * Eigenvalues, 1e-8 relative (the acceptance figure for this benchmark). The table prints 14 decimals, so it is exact
#   to 5e-15 absolute, 1.2e-12 relative for its smallest entry (the capsize eigenvalue at 6 m/s,
#   -0.0040669). chetaev's Jacobian is exact (automatic differentiation); the eigen-solver's
#   backward error is ~eps ||A|| ~ 1e-13 absolute here (A has entries up to ~1e2). The worst
#   measured agreement is 3.4e-11 relative (that capsize eigenvalue; 1.4e-13 elsewhere), 300 times
#   inside 1e-8.
EIGEN_RTOL = 1e-8
# * The six other eigenvalues are zero in exact arithmetic; measured at most 1.4e-13 in modulus
#   (the same backward error). 1e-11 is 100 times that, and 4e8 times below the smallest published
#   eigenvalue, so the split into "zero" and "published" cannot be confused.
ZERO_ATOL = 1e-11
# * Weave and capsize speeds to 8 digits (the acceptance figure for this benchmark): found by brentq to xtol 1e-12 on
#   real parts known to ~1e-13 whose slopes are ~1 (weave) and ~0.1 (capsize) per m/s, so the
#   roots are good to ~1e-12 m/s; measured |found - published| = 3.4e-14 m/s (weave) and
#   2.0e-13 m/s (capsize), within the root finder's xtol.
SPEED_RTOL = 1e-8


@pytest.fixture(scope="module")
def bike():
    return models.whipple_bicycle()


def convert(bike):
    return chetaev.Model.from_sympy(bike["L"], bike["q"], constraints=bike["constraints"],
                                    holonomic=bike["holonomic"], parameters=bike["parameters"])


@pytest.fixture(scope="module")
def model(bike):
    return convert(bike)


@pytest.fixture(scope="module")
def linearize(bike, model):
    """The linearisation of upright straight running at forward speed v."""

    def at(v):
        problem = chetaev.Problem(model, *bike["upright"](v))
        return problem.linearize(coordinates=COORDINATES, speeds=SPEEDS)

    return at


def split(eigenvalues):
    """The six eigenvalues of least modulus (zero in exact arithmetic) and the four others."""
    order = np.argsort(np.abs(eigenvalues))
    return eigenvalues[order[:6]], eigenvalues[order[6:]]


def test_the_bicycle_has_eight_coordinates_four_rolling_constraints_and_one_holonomic(model):
    assert model.coordinates == ["x", "y", "psi", "phi", "theta", "theta_R", "delta", "theta_F"]
    assert (model.n, model.k, model.holonomic_count) == (8, 4, 1)


def test_the_linearisation_is_in_the_independent_coordinates_and_speeds_given(linearize):
    lin = linearize(4.6)
    assert lin.states == STATES
    assert lin.a.shape == (10, 10) and lin.eigenvalues.shape == (10,)
    assert lin.full.shape == (16, 16) and lin.basis.shape == (16, 10)
    # The basis is the identity on the independent components: q (pitch omitted), then q̇.
    picked = [0, 1, 2, 3, 5, 6, 7] + [8 + 3, 8 + 5, 8 + 6]
    np.testing.assert_array_equal(lin.basis[picked], np.eye(10))


def test_the_cyclic_coordinates_give_zero_columns_and_the_heading_feeds_only_the_sideways_position(
    linearize,
):
    # x, y and the wheels' angles enter neither L nor the constraints: their columns of A are
    # exactly zero and `cyclic` lists them. The heading psi enters the rolling constraints (the
    # direction of travel), so it is not listed: its column has one entry, in y's row,
    # d(δy)/dt = v δpsi, and nothing else depends on it, so it too gives a zero eigenvalue. The
    # sixth zero eigenvalue is the rear-wheel rate's: straight running is steady at every speed,
    # so a change of speed neither grows nor decays (its row of A is zero to rounding).
    v = 4.6
    lin = linearize(v)
    assert lin.cyclic == ["x", "y", "theta_R", "theta_F"]
    for name in lin.cyclic:
        assert not lin.a[:, STATES.index(name)].any(), name
    psi = lin.a[:, STATES.index("psi")]
    assert psi[STATES.index("y")] == pytest.approx(v, rel=1e-14)
    assert np.count_nonzero(np.abs(psi) > 1e-12) == 1
    assert np.abs(lin.a[STATES.index("theta_R_dot")]).max() < 1e-12
    # The lateral motion (roll, steer and their rates) depends on nothing else: its block
    # decouples, and its eigenvalues are the four non-zero ones.
    rows = [STATES.index(s) for s in LATERAL]
    others = [i for i in range(10) if i not in rows]
    assert np.abs(lin.a[np.ix_(rows, others)]).max() < 1e-12
    _, lateral = split(lin.eigenvalues)
    block = np.linalg.eigvals(lin.a[np.ix_(rows, rows)])
    np.testing.assert_allclose(np.sort_complex(lateral), np.sort_complex(block), rtol=1e-12)


@pytest.mark.parametrize("v", sorted(models.MEIJAARD_TABLE_2))
def test_the_eigenvalues_of_upright_running_are_the_published_ones(linearize, v):
    lin = linearize(v)
    eigenvalues = lin.eigenvalues
    # Sorted by real part, as documented.
    assert np.all(np.diff(eigenvalues.real) >= 0)
    zeros, lateral = split(eigenvalues)
    assert np.abs(zeros).max() < ZERO_ATOL
    published = np.array(models.MEIJAARD_TABLE_2[v])
    for value in published:
        nearest = lateral[np.argmin(np.abs(lateral - value))]
        assert abs(nearest - value) <= EIGEN_RTOL * abs(value), (v, value, nearest)
    # One to one: the four found are the four published (the weave pair is a conjugate pair).
    np.testing.assert_allclose(np.sort_complex(lateral), np.sort_complex(published),
                               rtol=EIGEN_RTOL)


def weave_real_part(linearize, v):
    """The real part of the weave pair (the complex pair of the lateral eigenvalues)."""
    _, lateral = split(linearize(v).eigenvalues)
    pair = lateral[np.abs(lateral.imag) > 0]
    assert len(pair) == 2
    return float(pair.real.max())


def capsize_eigenvalue(linearize, v):
    """The capsize eigenvalue: the larger of the two real lateral eigenvalues (the other is the
    castor mode's, below -14 here). Near its root it is still 1e4 times the zeros' rounding
    (~1e-13) as long as |v - v_c| > 1e-8; closer than ~1e-12 the choice may flip, which moves the
    root by less than that."""
    _, lateral = split(linearize(v).eigenvalues)
    real = lateral[lateral.imag == 0].real
    assert len(real) == 2
    return float(real.max())


def test_the_weave_and_capsize_speeds_are_the_published_ones(linearize):
    weave = brentq(lambda v: weave_real_part(linearize, v), 4.0, 5.0, xtol=1e-12)
    capsize = brentq(lambda v: capsize_eigenvalue(linearize, v), 5.5, 6.5, xtol=1e-12)
    assert weave == pytest.approx(models.MEIJAARD_WEAVE_SPEED, rel=SPEED_RTOL)
    assert capsize == pytest.approx(models.MEIJAARD_CAPSIZE_SPEED, rel=SPEED_RTOL)
    # At the weave speed the weave is a pure oscillation at the published frequency.
    _, lateral = split(linearize(weave).eigenvalues)
    assert lateral.imag.max() == pytest.approx(models.MEIJAARD_WEAVE_FREQUENCY, rel=EIGEN_RTOL)
    # Between them every eigenvalue's real part is negative (the zeros aside): self-stable.
    for v in np.linspace(weave + 1e-3, capsize - 1e-3, 7):
        assert split(linearize(v).eigenvalues)[1].real.max() < 0


def test_a_small_roll_rate_moves_the_nonlinear_bicycle_as_its_linearisation_predicts(
    bike, model, linearize
):
    # Upright at 4.6 m/s, roll rate 1e-3 rad/s: the nonlinear motion against exp(A t) δz0. The
    # neglected terms are third order in the perturbation (the left-right symmetry removes the
    # second): measured 1.6e-10 rad, and 1.3e-9 rad (8 times) for twice the roll rate; tighter
    # integration tolerances (1e-12) leave it unchanged. 1e-8 rad is 60 times that and 4e-5 of
    # the roll's amplitude (2.3e-4 rad): an eigenvalue wrong by 1e-5 /s would exceed it.
    v, rate, times = 4.6, 1e-3, np.linspace(0.0, 3.0, 31)
    sol = chetaev.solve(chetaev.Problem(model, *bike["upright"](v, roll_rate=rate)), times[-1],
                        rtol=1e-11, atol=1e-13, output=times)
    lin = linearize(v)
    dz0 = rate * np.eye(10)[STATES.index("phi_dot")]
    predicted = np.array([scipy.linalg.expm(lin.a * t) @ dz0 for t in times])
    for name, index in (("phi", models.BIKE_ROLL), ("delta", models.BIKE_STEER)):
        np.testing.assert_allclose(sol.q[:, index], predicted[:, STATES.index(name)], rtol=0,
                                   atol=1e-8, err_msg=name)
    assert np.abs(sol.q[:, models.BIKE_ROLL]).max() > 2e-4


@pytest.mark.parametrize(("v", "stable"), [(4.6, True), (3.0, False)])
def test_upright_running_recovers_from_a_roll_rate_inside_the_stable_speeds_and_weaves_below(
    bike, model, v, stable
):
    # 4.6 m/s lies between the weave and capsize speeds: every lateral mode decays (the weave
    # at -0.38/s, so over 10 s by e^-3.8). At 3 m/s the weave grows at +1.7/s (Table 2), e^5 in
    # 3 s. Measured: the largest roll in the last second over that in the first is 0.033 at
    # 4.6 m/s (10 s) and 85 at 3 m/s (3 s).
    t_end = 10.0 if stable else 3.0
    times = np.linspace(0.0, t_end, int(100 * t_end) + 1)
    sol = chetaev.solve(chetaev.Problem(model, *bike["upright"](v, roll_rate=1e-3)), t_end,
                        rtol=1e-10, atol=1e-12, output=times)
    assert sol.success
    roll = np.abs(sol.q[:, models.BIKE_ROLL])
    first, last = roll[times <= 1.0].max(), roll[times >= t_end - 1.0].max()
    if stable:
        assert last < 0.1 * first
    else:
        assert last > 30 * first


@pytest.fixture(scope="module")
def bike_with_rear_height():
    """The bicycle with the rear contact's height z as a ninth coordinate and z = 0 as a second
    holonomic constraint, so that the rear wheel's normal force is a multiplier too."""
    bike = models.whipple_bicycle(rear_contact_height=True)
    return bike, convert(bike)


def test_the_multipliers_of_straight_running_are_the_static_wheel_loads(bike_with_rear_height):
    # mu = [rear friction N.x, N.y, front friction N.x, N.y, front normal force, rear normal force]
    # (models.whipple_bicycle: Newton form, each rolling condition's multiplier is the friction
    # component along its direction, each contact height's the ground's upward force). Running
    # straight at constant speed nothing accelerates: no friction, and the normal forces carry
    # the weight, split by the moments about the rear contact: N_F w = g Σ m_i x_i.
    bike, model = bike_with_rear_height
    sol = chetaev.solve(chetaev.Problem(model, *bike["upright"](4.6)), 1.0, rtol=1e-10,
                        atol=1e-10, record="dynamics")
    p = models.WHIPPLE_PARAMETERS
    front = p["g"] * (p["m_B"] * p["x_B"] + p["m_H"] * p["x_H"] + p["m_F"] * p["w"]) / p["w"]
    for mu in sol.mu:
        np.testing.assert_allclose(mu[:4], 0.0, atol=1e-11)
        assert mu[4] == pytest.approx(front, rel=1e-13)  # 309.30 N
        assert mu[5] == pytest.approx(bike["weight"] - front, rel=1e-13)  # 612.84 N
        assert mu[4] + mu[5] == pytest.approx(bike["weight"], rel=1e-13)  # 94 kg × 9.81
    # The model without z has the same front multiplier.
    plain = models.whipple_bicycle()
    sol = chetaev.solve(chetaev.Problem(convert(plain), *plain["upright"](4.6)), 1.0,
                        rtol=1e-10, atol=1e-10, record="dynamics")
    assert sol.mu[-1, 4] == pytest.approx(front, rel=1e-13)


def test_the_multipliers_are_the_contact_forces_while_the_bicycle_weaves(bike_with_rear_height):
    # Newton's law for the whole bicycle at 3 m/s, weaving from a roll rate of 1e-3 rad/s: the
    # ground's forces (friction and normal, from the multipliers) equal Σ m_i a_i + the weight,
    # with the mass centres' accelerations from sympy (d²/dt² of their positions, at chetaev's
    # q, q̇, q̈). Both sides are computed at the same recorded states, so they agree to the
    # rounding of the block solve (measured 2.3e-13 N on forces up to 922 N).
    bike, model = bike_with_rear_height
    sol = chetaev.solve(chetaev.Problem(model, *bike["upright"](3.0, roll_rate=1e-3)), 3.0,
                        rtol=1e-10, atol=1e-12, output=np.linspace(0.0, 3.0, 7),
                        record="dynamics")
    frame, origin, q, qd = bike["frame"], bike["points"]["O"], bike["q"], bike["qd"]
    centres = [body.masscenter for body in bike["bodies"]]
    accelerations = sp.Matrix([[c.pos_from(origin).dt(frame).dt(frame).dot(e)
                                for e in (frame.x, frame.y, frame.z)] for c in centres])
    qs, vs, ws = sp.symbols("q0:9"), sp.symbols("v0:9"), sp.symbols("w0:9")
    names = {**dict(zip([v.diff() for v in qd], ws)), **dict(zip(qd, vs)), **dict(zip(q, qs))}
    of = sp.lambdify([qs, vs, ws], accelerations.xreplace(bike["parameters"]).xreplace(names),
                     cse=True)
    masses = np.array([float(body.mass.xreplace(bike["parameters"])) for body in bike["bodies"]])
    for i in range(len(sol)):
        a = np.asarray(of(sol.q[i], sol.qd[i], sol.qdd[i]), dtype=float)
        newton = masses @ a + np.array([0.0, 0.0, bike["weight"]])
        mu = sol.mu[i]
        ground = np.array([mu[0] + mu[2], mu[1] + mu[3], mu[4] + mu[5]])
        np.testing.assert_allclose(ground, newton, rtol=0, atol=1e-9)
    # Not vacuous: the bicycle weaves, with sideways forces of tens of newtons by the end.
    assert abs(sol.mu[-1, 1] + sol.mu[-1, 3]) > 10


def test_complete_finds_the_dependent_coordinates_and_speeds_from_a_guess(bike, model):
    # The state of the sympy + numpy helper (independent of chetaev), upright at 4.6 m/s with
    # roll and steer rates; the guess has every dependent value off by 10% (pitch 0.01 rad off).
    q_exact, qd_exact = map(np.array, bike["upright"](4.6, roll_rate=0.1, steer_rate=0.05))
    dependent_speeds = [models.BIKE_X, models.BIKE_Y, models.BIKE_YAW, models.BIKE_PITCH,
                        models.BIKE_FRONT]
    q_guess, qd_guess = q_exact.copy(), qd_exact.copy()
    q_guess[models.BIKE_PITCH] += 0.01
    qd_guess[dependent_speeds] *= 1.1
    q, qd = chetaev.complete(model, q_guess, qd_guess, coordinates=COORDINATES, speeds=SPEEDS)
    # h and the constraints are solved to rounding: 1e-14 on values up to 15 rad/s.
    np.testing.assert_allclose(q, q_exact, rtol=0, atol=1e-15)
    np.testing.assert_allclose(qd, qd_exact, rtol=0, atol=1e-14)
    # Indices, dynamicsymbols and their derivatives name the same components.
    x, y, psi, phi, theta, theta_R, delta, theta_F = bike["q"]
    by_symbol = chetaev.complete(model, q_guess, qd_guess,
                                 coordinates=[x, y, psi, phi, theta_R, delta, theta_F],
                                 speeds=[phi.diff(), theta_R.diff(), delta.diff()])
    by_index = chetaev.complete(model, q_guess, qd_guess, coordinates=[0, 1, 2, 3, 5, 6, 7],
                                speeds=[3, 5, 6])
    for other in (by_symbol, by_index):
        np.testing.assert_array_equal(other[0], q)
        np.testing.assert_array_equal(other[1], qd)
    # A Problem completes the same way when told which are independent.
    problem = chetaev.Problem(model, q_guess, qd_guess, independent_coordinates=COORDINATES,
                              independent_speeds=SPEEDS)
    np.testing.assert_array_equal(problem.q0, q)
    np.testing.assert_array_equal(problem.qd0, qd)


def test_complete_puts_a_leaning_steered_bicycle_on_the_ground(model):
    # Roll 0.2 rad, steer 0.3 rad: the pitch is no longer zero; the completed state is one the
    # Problem accepts, with h, f and ḣ at rounding.
    q_guess = np.zeros(8)
    q_guess[[models.BIKE_ROLL, models.BIKE_STEER]] = [0.2, 0.3]
    qd_guess = np.zeros(8)
    qd_guess[[models.BIKE_ROLL, models.BIKE_REAR, models.BIKE_STEER]] = [0.1, 15.0, -0.2]
    q, qd = chetaev.complete(model, q_guess, qd_guess, coordinates=COORDINATES, speeds=SPEEDS)
    assert abs(q[models.BIKE_PITCH]) > 1e-3
    independent = [0, 1, 2, 3, 5, 6, 7]
    np.testing.assert_array_equal(q[independent], q_guess[independent])
    np.testing.assert_array_equal(qd[[3, 5, 6]], qd_guess[[3, 5, 6]])
    sol = chetaev.solve(chetaev.Problem(model, q, qd), 0.0, output="final", record="dynamics")
    assert np.abs(sol.position_residual[0]).max() < 1e-15
    assert np.abs(sol.residual[0]).max() < 1e-13
