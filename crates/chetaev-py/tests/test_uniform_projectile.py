"""The paper's particle (Swaczyna and Volny, "Uniform horizontal projectile motion") against its
closed form, and the classical projectile against its own.

L = m/2 (x'^2 + y'^2) - m g y, f = x'^2 + y'^2 - v0^2, m = 1, g = 10, v0 = 10, q0 = (0, 5),
q'0 = (10, 0). With u = g t / v0: x = (v0^2/g) atan(sinh u), y = h0 - (v0^2/g) ln cosh u,
mu = -(m g / 2 v0) tanh u in Newton form (d/dt dL/dq' - dL/dq = mu df/dq'),
T = (v0/g) arccosh(exp(g h0 / v0^2)).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp
import sympy.physics.mechanics as me

import chetaev
from models import PARTICLE_H0, particle_closed_form, particle_impact_time

M, G, V0, H0 = 1.0, 10.0, 10.0, PARTICLE_H0
T_IMPACT = particle_impact_time()
R_IMPACT = V0**2 / G * math.atan(math.sinh(G * T_IMPACT / V0))

TOL = 1e-12  # rtol = atol of the runs below
# An adaptive method's global error over this short run (about 1 s, a few dozen steps at most) is a
# modest multiple of its local tolerance: 1000 * TOL leaves room for that factor on every method.
GLOBAL = 1000 * TOL


@pytest.fixture(scope="module")
def paper_run(particle_problem, impact):
    return chetaev.solve(particle_problem, 10.0, rtol=TOL, atol=TOL, events=[impact])


def test_the_closed_form_impact_time_is_the_one_printed_in_the_paper():
    # Table 42.1 (README, closed-form row): T = 1.085038501948 s, R = 9.191066572936 m, printed
    # with 12 decimals: equal to half a unit of the last one.
    assert T_IMPACT == pytest.approx(1.085038501948, abs=5e-13)
    assert R_IMPACT == pytest.approx(9.191066572936, abs=5e-13)


@pytest.mark.parametrize("expression", ["sympy", "string"])
def test_the_impact_is_found_at_t_equal_v0_over_g_arccosh_exp_g_h0_over_v0_squared(
    particle_problem, particle_sympy, expression
):
    y = particle_sympy["q"][1] if expression == "sympy" else "y"
    event = chetaev.Event("impact", y, direction="falling", terminal=True)
    sol = chetaev.solve(particle_problem, 10.0, rtol=TOL, atol=TOL, events=[event])
    assert sol.status == "terminated" and sol.success
    assert sol.terminated_by == 0
    assert len(sol.events) == 1
    hit = sol.events[0]
    assert hit.name == "impact" and hit.index == 0
    assert hit.t == pytest.approx(T_IMPACT, abs=GLOBAL)
    assert sol.t[-1] == hit.t  # the run ends at the terminal event
    # y(T) = 0 up to the event location's accuracy (|y'| = 8 m/s there, so 8 * GLOBAL).
    assert abs(hit.q[1]) <= 8 * GLOBAL


def test_an_event_zero_at_the_start_does_not_end_the_run_and_is_named_in_the_warnings(
    particle_problem, particle_sympy
):
    # The horizontal launch has y_dot = 0 at the start and y_dot < 0 at once: no apex is
    # reported there, the run goes on to its end, and the solution says why.
    apex = chetaev.Event("apex", particle_sympy["qd"][1], direction="falling", terminal=True)
    sol = chetaev.solve(particle_problem, 0.5, events=[apex])
    assert sol.status == "success"
    assert sol.t[-1] == 0.5 and len(sol.t) > 2
    assert len(sol.events) == 0
    assert len(sol.warnings) == 1
    assert '"apex" (index 0) is zero at the start' in sol.warnings[0]
    # An ordinary run warns of nothing.
    impact = chetaev.Event("impact", "y", direction="falling", terminal=True)
    assert chetaev.solve(particle_problem, 10.0, events=[impact]).warnings == []


def test_the_range_is_x_at_the_impact_v0_squared_over_g_atan_sinh_g_t_over_v0(paper_run):
    hit = paper_run.events[0]
    # x' = 6 m/s at impact: the error in T moves x by 6 * GLOBAL at most, plus x's own error.
    assert hit.q[0] == pytest.approx(R_IMPACT, abs=10 * GLOBAL)
    assert paper_run.q[-1, 0] == pytest.approx(R_IMPACT, abs=10 * GLOBAL)


def test_the_recorded_motion_follows_the_closed_form(paper_run):
    q, qd, _ = particle_closed_form(paper_run.t)
    # positions of order 10 m, velocities of order 10 m/s: relative GLOBAL each.
    np.testing.assert_allclose(paper_run.q, q, rtol=0, atol=10 * GLOBAL)
    np.testing.assert_allclose(paper_run.qd, qd, rtol=0, atol=10 * GLOBAL)


def test_the_multiplier_is_minus_mg_over_2v0_tanh_gt_over_v0_in_newton_form(paper_run):
    _, _, mu = particle_closed_form(paper_run.t)
    assert paper_run.mu.shape == (len(paper_run), 1)
    # mu is an algebraic function of the state (|mu| <= m g / 2 v0 = 0.5): its error follows the
    # state's relative error, GLOBAL.
    np.testing.assert_allclose(paper_run.mu, mu, rtol=0, atol=GLOBAL)
    # The paper's printed (42.21) has the opposite sign: here mu < 0 once the particle falls.
    assert (paper_run.mu[1:, 0] < 0).all()


def test_the_chetaev_force_is_mu_times_df_dqd_equal_2_mu_qd(paper_run):
    # Phi is computed from mu and J = 2 q' at each point: equal to rounding of these O(10) numbers.
    np.testing.assert_allclose(paper_run.phi, 2 * paper_run.mu * paper_run.qd, rtol=0, atol=1e-12)
    _, qd, mu = particle_closed_form(paper_run.t)
    np.testing.assert_allclose(paper_run.phi, 2 * mu * qd, rtol=0, atol=10 * GLOBAL)


def test_the_chetaev_force_satisfies_newtons_equations_with_the_recorded_acceleration(paper_run):
    # m q'' = Phi + (0, -m g): the identity of Newton form, rounding only.
    np.testing.assert_allclose(M * paper_run.qdd, paper_run.phi + np.array([0.0, -M * G]),
                               rtol=0, atol=1e-11)


def test_the_speed_is_held_at_v0_along_the_motion(paper_run):
    assert paper_run.residual.shape == (len(paper_run), 1)
    # f = |q'|^2 - v0^2 = 2 v0 d|q'| to first order: relative error GLOBAL of v0^2 = 100.
    assert np.abs(paper_run.residual).max() <= GLOBAL * V0**2
    assert paper_run.relative_residual.max() <= GLOBAL
    speed = np.hypot(paper_run.qd[:, 0], paper_run.qd[:, 1])
    np.testing.assert_allclose(speed, V0, rtol=GLOBAL, atol=0)


def test_the_energy_is_not_conserved_it_drops_by_m_g_h0_the_work_of_the_chetaev_force(paper_run):
    e = paper_run.energy
    # E = 1/2 m v0^2 + m g y: 100 J at the start, 50 J at the impact, whatever the method.
    assert e[0] == pytest.approx(0.5 * M * V0**2 + M * G * H0, abs=1e-12)
    assert e[-1] - e[0] == pytest.approx(-M * G * H0, abs=GLOBAL * 100)  # y(T) to GLOBAL * 10 m
    # W_Phi = int q'.Phi dt = 2 v0^2 int mu dt = -m v0^2 ln cosh(g T / v0) = -m g h0.
    assert paper_run.work[0] == 0.0
    assert paper_run.work[-1] == pytest.approx(-M * G * H0, abs=GLOBAL * 100)
    # the balance E - E0 - W_Phi carried along with the motion (quadratures of 50 J at GLOBAL).
    assert np.abs(paper_run.energy_balance).max() <= GLOBAL * 100
    # and it is the right balance: E changes, but E - W_Phi does not.
    assert abs(e[-1] - e[0]) > 1e6 * np.abs(paper_run.energy_balance).max()


def test_the_partial_motion_of_a_run_that_hits_its_step_limit_is_still_the_motion(particle_problem):
    sol = chetaev.solve(particle_problem, 10.0, rtol=TOL, atol=TOL, max_steps=3)
    assert sol.status == "failed" and sol.success is False
    assert sol.message and "3" in sol.message
    assert sol.terminated_by is None
    assert len(sol) >= 1 and sol.t[0] == 0.0
    q, _, _ = particle_closed_form(sol.t)
    np.testing.assert_allclose(sol.q, q, rtol=0, atol=10 * GLOBAL)


# --------------------------------------------------------------------------------------------
# Several methods
# --------------------------------------------------------------------------------------------

METHOD_TOL = 1e-10


def test_the_methods_are_the_documented_six():
    assert set(chetaev.methods()) == {"dopri5", "dop853", "tsit5", "rk4", "rodas4", "rodas5p"}


@pytest.mark.parametrize("method", [m for m in chetaev.methods() if m != "rk4"])
def test_every_adaptive_method_finds_the_impact_time_to_its_tolerance(
    particle_problem, impact, method
):
    sol = chetaev.solve(particle_problem, 10.0, method=method, rtol=METHOD_TOL, atol=METHOD_TOL,
                        events=[impact])
    assert sol.status == "terminated"
    assert sol.method.lower() == method
    # global error a modest multiple of the local tolerance over ~1 s: 100 * METHOD_TOL.
    assert sol.events[0].t == pytest.approx(T_IMPACT, abs=100 * METHOD_TOL)
    _, _, mu = particle_closed_form(sol.t)
    np.testing.assert_allclose(sol.mu, mu, rtol=0, atol=100 * METHOD_TOL)


def test_rk4_needs_its_step(particle_problem):
    with pytest.raises(chetaev.ChetaevError, match="step"):
        chetaev.solve(particle_problem, 1.0, method="rk4")


def test_rk4_with_a_fixed_step_finds_the_impact_to_order_h4(particle_problem, impact):
    h = 1e-3
    sol = chetaev.solve(particle_problem, 10.0, method="rk4", step=h, events=[impact])
    assert sol.status == "terminated"
    # fourth order: error ~ C h^4 with C of order (g/v0)^4 T ~ 1; 1e-3^4 = 1e-12, allow 100x.
    assert sol.events[0].t == pytest.approx(T_IMPACT, abs=100 * h**4)
    # fixed steps: about T/h accepted steps
    assert sol.stats["accepted_steps"] == pytest.approx(T_IMPACT / h, abs=2)


# --------------------------------------------------------------------------------------------
# The classical projectile: the same Lagrangian, no constraint
# --------------------------------------------------------------------------------------------


def test_the_classical_projectile_lands_at_sqrt_2h0_over_g_and_range_v0_t(particle_sympy):
    p = particle_sympy
    model = chetaev.Model.from_sympy(p["L"], p["q"], parameters=p["parameters"])
    assert model.k == 0
    problem = chetaev.Problem(model, p["q0"], p["qd0"])
    assert problem.sizes == (2, 0)
    sol = chetaev.solve(problem, 10.0, rtol=TOL, atol=TOL,
                        events=[chetaev.Event("impact", "y", direction="falling", terminal=True)])
    t_c = math.sqrt(2 * H0 / G)
    assert sol.events[0].t == pytest.approx(t_c, abs=GLOBAL)
    assert sol.events[0].q[0] == pytest.approx(V0 * t_c, abs=10 * GLOBAL)
    assert sol.mu.shape == (len(sol), 0)
    # no constraint: the energy is conserved (quadrature at GLOBAL of 100 J).
    np.testing.assert_allclose(sol.energy, sol.energy[0], rtol=0, atol=100 * GLOBAL)
    assert np.all(sol.work == 0.0)
    # the constrained particle lands later and shorter (T = 1.085 s > 1 s, R = 9.19 m < 10 m).
    assert t_c < T_IMPACT and R_IMPACT < V0 * t_c


# --------------------------------------------------------------------------------------------
# Sensitivity of T with respect to g
# --------------------------------------------------------------------------------------------


def _dT_dg() -> float:
    g, v0, h0 = sp.symbols("g v0 h0", positive=True)
    T = v0 / g * sp.acosh(sp.exp(g * h0 / v0**2))
    return float(sp.diff(T, g).subs({g: G, v0: V0, h0: H0}))


@pytest.mark.parametrize("seed", ["symbol", "name", "Seed.parameter"])
def test_the_sensitivity_of_the_impact_time_to_g_is_the_derivative_of_the_closed_form(
    particle_problem, particle_sympy, impact, seed
):
    g = particle_sympy["symbols"]["g"]
    s = {"symbol": g, "name": "g", "Seed.parameter": chetaev.Seed.parameter(g)}[seed]
    sol = chetaev.solve(particle_problem, 10.0, rtol=TOL, atol=TOL, events=[impact],
                        sensitivities=[s], sensitivity_control=True)
    assert list(sol.sensitivities) == ["g"]
    # dT/dg ~ -0.046 s^3/m; the sensitivities are integrated under the same control: GLOBAL.
    assert sol.events[0].dt["g"] == pytest.approx(_dT_dg(), abs=GLOBAL)


def test_the_sensitivity_of_the_motion_to_g_is_the_derivative_of_the_closed_form(
    particle_problem, particle_sympy
):
    sol = chetaev.solve(particle_problem, 1.0, rtol=TOL, atol=TOL, sensitivities=["g"],
                        sensitivity_control=True, output=np.linspace(0.0, 1.0, 6))
    tt, g, v0, h0 = sp.symbols("t g v0 h0", positive=True)
    u = g * tt / v0
    x = v0**2 / g * sp.atan(sp.sinh(u))
    y = h0 - v0**2 / g * sp.log(sp.cosh(u))
    dq = sp.lambdify(tt, [sp.diff(x, g).subs({g: G, v0: V0, h0: H0}),
                          sp.diff(y, g).subs({g: G, v0: V0, h0: H0})])
    expected = np.array([dq(ti) for ti in sol.t], dtype=float)
    # dq/dg of order 0.5 m/(m/s^2): GLOBAL relative
    np.testing.assert_allclose(sol.sensitivities["g"]["q"], expected, rtol=0, atol=10 * GLOBAL)


# --------------------------------------------------------------------------------------------
# The equations at a state
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("t", [0.0, 0.4, 1.0])
def test_the_equations_at_a_state_of_the_closed_form_give_its_multiplier_and_acceleration(
    particle_problem, t
):
    q, qd, mu = particle_closed_form(t)
    eq = particle_problem.equations_at(t, list(q), list(qd))
    # pure evaluation, no integration: rounding of O(10) numbers only.
    np.testing.assert_allclose(eq["mu"], mu, rtol=0, atol=1e-13)
    u = G * t / V0  # q'' of the closed form: x'' = -g sinh u / cosh^2 u, y'' = -g / cosh^2 u
    np.testing.assert_allclose(eq["qdd"], [-G * math.sinh(u) / math.cosh(u) ** 2,
                                           -G / math.cosh(u) ** 2], rtol=0, atol=1e-12)
    np.testing.assert_allclose(eq["phi"], 2 * mu * qd, rtol=0, atol=1e-12)
    np.testing.assert_allclose(eq["j"], [2 * qd], rtol=0, atol=1e-12)
    assert eq["j"].shape == (1, 2)
    assert abs(eq["f"][0]) <= 1e-12  # the closed-form state is on f = 0 to rounding of v0^2
    assert eq["energy"] == pytest.approx(0.5 * V0**2 + G * q[1], abs=1e-12)
    assert eq["lagrangian"] == pytest.approx(0.5 * V0**2 - G * q[1], abs=1e-12)


def test_the_readme_example_runs_with_integer_inputs_and_gives_the_paper_numbers():
    x, y = me.dynamicsymbols("x y")
    m, g, v0 = sp.symbols("m g v0")
    L = m * (x.diff() ** 2 + y.diff() ** 2) / 2 - m * g * y
    f = x.diff() ** 2 + y.diff() ** 2 - v0**2
    model = chetaev.Model.from_sympy(L, [x, y], constraints=[f], parameters={m: 1, g: 10, v0: 10})
    problem = chetaev.Problem(model, q0=[0, 5], qd0=[10, 0])
    sol = chetaev.solve(problem, 10, rtol=1e-12, atol=1e-12,
                        events=[chetaev.Event("impact", y, direction="falling", terminal=True)])
    assert sol.events[0].t == pytest.approx(T_IMPACT, abs=GLOBAL)
    mu_T = -(M * G) / (2 * V0) * math.tanh(G * sol.events[0].t / V0)
    assert sol.mu[-1, 0] == pytest.approx(mu_T, abs=GLOBAL)
