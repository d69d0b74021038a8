//! The sign convention, pinned: Newton form `d/dt(∂L/∂q̇) − ∂L/∂q = Σ_a μ_a ∂f_a/∂q̇`, under which
//! the paper's multiplier is (42.40), `μ(t) = −(m g / 2 v0) tanh(g t / v0)`. The printed (42.21)
//! has the opposite sign; with it this test would fail.

use approx::assert_relative_eq;
use chetaev::equations::{evaluate, Workspace};
use chetaev::prelude::*;
use uniform_projectile::closed_form::{uniform, Params};
use uniform_projectile::model::uniform_problem;

#[test]
fn multiplier_is_newton_form_as_in_42_40() {
    let p = Params {
        v0: 3.0,
        g: 9.81,
        h0: 2.0,
        m: 1.7,
    };
    let problem = uniform_problem(&p).expect("valid");
    let mut ws = Workspace::for_model(problem.model());
    for &t in &[0.05, 0.3, 1.0, 2.5] {
        let q = uniform::position(&p, t);
        let qd = uniform::velocity(&p, t);
        let d = evaluate(problem.model(), &mut ws, t, &q, &qd).expect("regular");
        let mu = -(p.m * p.g / (2.0 * p.v0)) * (p.g * t / p.v0).tanh();
        assert!(d.mu[0] < 0.0, "μ < 0 while falling, as (42.40)");
        assert_relative_eq!(d.mu[0], mu, max_relative = 1e-13);
        // (42.39): Φ = 2μ q̇, opposite to the velocity (φ < 0 in (42.41)).
        assert_relative_eq!(d.phi[0], 2.0 * mu * qd[0], max_relative = 1e-13);
        assert_relative_eq!(d.phi[1], 2.0 * mu * qd[1], max_relative = 1e-13);
        // (42.28)/(42.32): ÿ = −(g/v0²)(v0² − ẏ²) = −g/cosh²(gt/v0). From the state (ẋ, ẏ), ÿ carries
        // the cancellation of v0² − ẏ² (and 2μẏ − m g below), condition number 2 sinh²(gt/v0).
        let cond = 1.0 + 2.0 * (p.g * t / p.v0).sinh().powi(2);
        // (42.26): m q̈ = 2μ q̇ + (0, −m g)
        assert_relative_eq!(p.m * d.qdd[0], 2.0 * mu * qd[0], max_relative = 1e-13);
        assert_relative_eq!(
            p.m * d.qdd[1],
            2.0 * mu * qd[1] - p.m * p.g,
            max_relative = 1e-14 * cond
        );
        let ydd = uniform::acceleration(&p, t)[1];
        assert_relative_eq!(d.qdd[1], ydd, max_relative = 1e-14 * cond);
    }
}

#[test]
fn power_of_the_chetaev_force_balances_the_potential() {
    // E = ½ m |q̇|² + m g y is not conserved: dE/dt = q̇·Φ (∂L/∂t = 0), and with |q̇| fixed the
    // work of Φ equals the change of potential energy.
    let p = Params::PAPER;
    let problem = uniform_problem(&p).expect("valid");
    let sol = solve(
        &problem,
        Dopri5::default(),
        &Options::until(0.9).tolerances(1e-11, 1e-12),
    )
    .expect("valid options");
    assert!(sol.is_success());
    let last = sol.len() - 1;
    let dv = p.m * p.g * (sol.q[last][1] - p.h0);
    assert_relative_eq!(sol.work[last], dv, max_relative = 1e-9);
    assert!(sol
        .energy_balance()
        .iter()
        .all(|b| b.abs() < 1e-8 * p.m * p.v0 * p.v0));
}
