//! The paper's two motions against their closed forms: (42.4)–(42.16) and (42.29)–(42.42).

use chetaev::prelude::*;
use chetaev_suite::{norm, rel_err};
use uniform_projectile::closed_form::{classical, table, uniform, Params};
use uniform_projectile::model::{classical_problem, impact, uniform_problem};

/// Largest error of (q, q̇) over the recorded points, positions relative to max(h0, R) and
/// velocities to v0.
fn max_state_error(
    sol: &Solution,
    exact_q: impl Fn(f64) -> [f64; 2],
    exact_v: impl Fn(f64) -> [f64; 2],
    q_scale: f64,
    v_scale: f64,
) -> f64 {
    (0..sol.len()).fold(0.0f64, |acc, i| {
        let (x, v) = (exact_q(sol.t[i]), exact_v(sol.t[i]));
        let eq = (sol.q[i][0] - x[0]).abs().max((sol.q[i][1] - x[1]).abs()) / q_scale;
        let ev = (sol.qd[i][0] - v[0]).abs().max((sol.qd[i][1] - v[1]).abs()) / v_scale;
        acc.max(eq).max(ev)
    })
}

#[test]
fn uniform_motion_follows_42_29_and_42_30_within_the_tolerance_asked() {
    let p = Params::PAPER;
    let problem = uniform_problem(&p).expect("valid");
    for tol in [1e-6, 1e-8, 1e-10, 1e-12] {
        let sol = solve(
            &problem,
            Dopri5::default(),
            &Options::until(2.0).tolerances(tol, tol).event(impact()),
        )
        .expect("valid");
        assert_eq!(sol.status, Status::Terminated { event: 0 });
        let err = max_state_error(
            &sol,
            |t| uniform::position(&p, t),
            |t| uniform::velocity(&p, t),
            p.h0.max(10.0),
            p.v0,
        );
        // The global error of this short, smooth motion stays below the local tolerance (about 5%
        // of it is observed); a factor 1 leaves a margin of 20.
        assert!(err <= tol, "tol {tol:e}: error {err:e}");
        // μ and |Φ| along the motion, (42.40) and (42.42).
        for i in 0..sol.len() {
            let mu = uniform::multiplier(&p, sol.t[i]);
            assert!(
                (sol.mu[i][0] - mu).abs() <= 10.0 * tol * p.m * p.g / p.v0,
                "μ at t = {}",
                sol.t[i]
            );
            let phi = uniform::chetaev_force_magnitude(&p, sol.t[i]);
            assert!((norm(&sol.phi[i]) - phi).abs() <= 10.0 * tol * p.m * p.g);
        }
    }
}

#[test]
fn impact_is_located_to_1e_12_relative() {
    let p = Params::PAPER;
    let k = table(&p);
    let sol = solve(
        &uniform_problem(&p).expect("valid"),
        Dop853::default(),
        &Options::until(10.0)
            .tolerances(1e-13, 1e-13)
            .event(impact()),
    )
    .expect("valid");
    let hit = &sol.events[0];
    assert!(
        rel_err(hit.t, k.uniform.t_impact) <= 1e-12,
        "T: {:e}",
        rel_err(hit.t, k.uniform.t_impact)
    );
    assert!(
        rel_err(hit.q[0], k.uniform.range) <= 1e-12,
        "R: {:e}",
        rel_err(hit.q[0], k.uniform.range)
    );
    assert!(hit.q[1].abs() <= 1e-12 * p.h0);
    assert_eq!(
        sol.last().expect("points").0,
        hit.t,
        "the last point is the impact"
    );

    let sol = solve(
        &classical_problem(&p).expect("valid"),
        Dopri5::default(),
        &Options::until(10.0)
            .tolerances(1e-13, 1e-13)
            .event(impact()),
    )
    .expect("valid");
    let hit = &sol.events[0];
    assert!(rel_err(hit.t, k.classical.t_impact) <= 1e-12);
    assert!(rel_err(hit.q[0], k.classical.range) <= 1e-12);
}

#[test]
fn classical_motion_is_newtons() {
    // K = 0: the Euler–Lagrange equations are Newton's, ẍ = 0, ÿ = −g (42.3).
    let p = Params {
        v0: 3.0,
        g: 9.81,
        h0: 7.0,
        m: 2.5,
    };
    let sol = solve(
        &classical_problem(&p).expect("valid"),
        Dopri5::default(),
        &Options::until(1.0).tolerances(1e-12, 1e-12),
    )
    .expect("valid");
    for i in 0..sol.len() {
        assert!(sol.qdd[i][0].abs() <= 1e-12 && (sol.qdd[i][1] + p.g).abs() <= 1e-12 * p.g);
    }
    let err = max_state_error(
        &sol,
        |t| classical::position(&p, t),
        |t| classical::velocity(&p, t),
        7.0,
        3.0,
    );
    assert!(err <= 1e-12, "{err:e}");
    assert!(sol.mu.iter().all(|m| m.is_empty()));
}

#[test]
fn energy_balance_work_of_phi_equals_change_of_potential() {
    let p = Params::PAPER;
    let sol = solve(
        &uniform_problem(&p).expect("valid"),
        Dopri5::default(),
        &Options::until(5.0).tolerances(1e-11, 1e-11).event(impact()),
    )
    .expect("valid");
    for i in 0..sol.len() {
        // Kinetic energy is constant, so W_Φ = m g (y − h0).
        let dv = p.m * p.g * (sol.q[i][1] - p.h0);
        assert!(
            (sol.work[i] - dv).abs() <= 1e-9 * p.m * p.g * p.h0,
            "t = {}",
            sol.t[i]
        );
    }
    let last = sol.len() - 1;
    assert!(
        (sol.work[last] + p.m * p.g * p.h0).abs() <= 1e-9 * p.m * p.g * p.h0,
        "W_Φ = −m g h0 at the impact"
    );
}
