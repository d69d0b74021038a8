//! The vertical rolling disk against its closed form (Bloch §1.4): `θ̇`, `φ̇` constant, the contact
//! point on a circle of radius `R ω / Ω`, `μ` the centripetal force.

use crate::common::{assert_energy_balance, assert_within, run, KINDS, TOLERANCES};
use chetaev::equations::{evaluate, Workspace};
use chetaev_catalogue::rolling_disk::{entry, ClosedForm, Params};

/// A little over three laps of the circle (`Ω t_end = 20`).
const T_END: f64 = 20.0;

#[test]
fn motion_follows_the_closed_form_within_the_tolerance_asked() {
    let p = Params::default();
    let e = entry(&p).expect("valid");
    let speed = p.radius * p.omega;
    for tol in TOLERANCES {
        let (sol, cmp) = run(&e, T_END, tol);
        // Uniform rotation is integrated almost exactly (observed ≤ 0.5 tol of the circle's radius
        // for positions, ≤ 0.1 tol for velocities and E against R ω, and E); 10 tol is the stated
        // bound.
        assert_within(&cmp, &KINDS, 10.0 * tol, &format!("tol {tol:e}"));
        // Both constraints are velocities: drift against R ω (observed ≤ 0.1 tol).
        assert!(
            sol.max_residual().expect("recorded") <= 10.0 * tol * speed,
            "tol {tol:e}"
        );
        assert_energy_balance(&sol, tol);
    }
}

#[test]
fn the_contact_point_stays_on_the_circle() {
    let p = Params {
        position: [1.0, -2.0],
        phi0: 0.8,
        spin: -0.6,
        ..Params::default()
    };
    let e = entry(&p).expect("valid");
    let (centre, rho) = e.reference.circle().expect("Ω ≠ 0");
    assert!((rho - p.radius * p.omega / p.spin.abs()).abs() <= 1e-15 * rho);
    let tol = 1e-10;
    let (sol, _) = run(&e, T_END, tol);
    for q in sol.q.iter() {
        let d = ((q[0] - centre[0]).powi(2) + (q[1] - centre[1]).powi(2)).sqrt();
        // The bound of the closed-form test, 10 tol of the radius.
        assert!((d - rho).abs() <= 10.0 * tol * rho, "distance {d} vs {rho}");
    }
}

#[test]
fn block_solve_gives_the_centripetal_force_and_uniform_rates() {
    // At states of the closed form: θ̈ = φ̈ = 0 (from (I + m R²) θ̈ = 0) and
    // μ = m R ω Ω (−sin φ, cos φ), Newton form.
    let p = Params {
        m: 1.3,
        radius: 0.7,
        i_roll: 0.2,
        i_spin: 0.11,
        position: [0.5, 0.25],
        theta0: 0.3,
        phi0: -0.4,
        omega: 2.5,
        spin: 0.9,
    };
    let e = entry(&p).expect("valid");
    let cf = ClosedForm::new(&p);
    let model = e.problem.model();
    let mut ws = Workspace::for_model(model);
    let force = p.m * p.radius * p.omega * p.spin;
    for t in [0.0, 0.3, 1.1, 4.0] {
        let (q, qd) = (cf.position(t), cf.velocity(t));
        let d = evaluate(model, &mut ws, t, q.as_slice(), qd.as_slice()).expect("regular");
        let (qdd, mu) = (cf.acceleration(t), cf.multiplier(t));
        for i in 0..4 {
            assert!(
                (d.qdd[i] - qdd[i]).abs() <= 1e-14 * force / p.m,
                "q̈[{i}] at {t}"
            );
        }
        for a in 0..2 {
            assert!((d.mu[a] - mu[a]).abs() <= 1e-14 * force, "μ[{a}] at {t}");
        }
    }
}

#[test]
fn without_turning_the_disk_rolls_straight() {
    let p = Params {
        spin: 0.0,
        phi0: 0.5,
        ..Params::default()
    };
    let e = entry(&p).expect("valid");
    assert!(e.reference.circle().is_none());
    let tol = 1e-10;
    let (sol, cmp) = run(&e, 5.0, tol);
    assert!(cmp.max() <= 10.0 * tol, "{cmp:?}");
    let (t, q, _) = sol.last().expect("points");
    let along = p.radius * p.omega * t;
    assert!((q[0] - along * p.phi0.cos()).abs() <= 10.0 * tol * along);
    assert!((q[1] - along * p.phi0.sin()).abs() <= 10.0 * tol * along);
}
