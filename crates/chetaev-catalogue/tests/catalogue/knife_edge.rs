//! The knife edge on an inclined plane against its closed form (Neimark & Fufaev; Bloch §1.6):
//! `φ = ω t`, `x = (g sin α / 2ω²) sin² ω t`, `y = (g sin α / 2ω²)(ω t − ½ sin 2ω t)`,
//! `μ = −2 m g sin α sin ω t`.

use crate::common::{assert_energy_balance, assert_within, run, KINDS, TOLERANCES};
use chetaev::equations::{evaluate, Workspace};
use chetaev::prelude::*;
use chetaev_catalogue::knife_edge::{entry, ClosedForm, Params};
use chetaev_catalogue::Error;

/// Three turns of the blade (`ω t_end ≈ 3.2 · 2π`).
const T_END: f64 = 20.0;

#[test]
fn motion_follows_the_closed_form_within_the_tolerance_asked() {
    let p = Params::default();
    let e = entry(&p).expect("valid");
    let speed = p.g * p.alpha.sin() / p.omega;
    for tol in TOLERANCES {
        let (sol, cmp) = run(&e, T_END, tol);
        // The global error of Dop853 over a few periods of a smooth motion stays within a small
        // multiple of the tolerance (observed, from 1e-8 to 1e-12: at most 10 tol for the
        // positions, 5 tol for the velocities and μ, 12 tol for E); 50 tol leaves a margin of 4.
        // Positions against g sin α / ω², velocities against g sin α / ω, μ against m g sin α,
        // E against ½ I ω² + ½ m (g sin α / ω)².
        assert_within(&cmp, &KINDS, 50.0 * tol, &format!("tol {tol:e}"));
        // f = ẋ sin φ − ẏ cos φ is a velocity: its drift against g sin α / ω (observed ≤ 0.6 tol).
        assert!(
            sol.max_residual().expect("recorded") <= 50.0 * tol * speed,
            "tol {tol:e}"
        );
        assert_energy_balance(&sol, tol);
    }
}

#[test]
fn block_solve_gives_the_sideways_force_and_the_accelerations_of_the_closed_form() {
    // At states of the closed form, the Chetaev equations must return its q̈ and μ, to rounding:
    // this pins the sign of μ (Newton form: Φ = μ (sin φ, −cos φ, 0) is the force on the blade).
    let p = Params {
        m: 2.5,
        inertia: 0.3,
        g: 9.81,
        alpha: 0.4,
        omega: -1.7,
    };
    let e = entry(&p).expect("valid");
    let cf = ClosedForm::new(&p);
    let model = e.problem.model();
    let mut ws = Workspace::for_model(model);
    let a = p.g * p.alpha.sin();
    for t in [0.0, 0.1, 0.7, 1.3, 2.9, 5.0] {
        let (q, qd) = (cf.position(t), cf.velocity(t));
        let d = evaluate(model, &mut ws, t, q.as_slice(), qd.as_slice()).expect("regular");
        let qdd = cf.acceleration(t);
        for i in 0..3 {
            assert!((d.qdd[i] - qdd[i]).abs() <= 1e-14 * a, "q̈[{i}] at t = {t}");
        }
        assert!(
            (d.mu[0] - cf.multiplier(t)).abs() <= 1e-14 * p.m * a,
            "μ at t = {t}: {} vs {}",
            d.mu[0],
            cf.multiplier(t)
        );
        // Φ is perpendicular to the blade and does no work.
        let phi = SVector::<f64, 3>::from_column_slice(&d.phi);
        assert!(phi.dot(&qd).abs() <= 1e-14 * p.m * a * a / p.omega.abs());
    }
}

#[test]
fn the_skate_turns_back_at_half_the_length_scale_down_the_slope() {
    // x = (ℓ/2) sin² ω t with ℓ = g sin α / ω²: the skate never descends below ℓ/2 and reaches it
    // whenever the blade lies across the slope, ω t = π/2 + kπ.
    let p = Params::default();
    let e = entry(&p).expect("valid");
    let half = 0.5 * e.reference.length_scale();
    let across: Vec<f64> = (0..6)
        .map(|k| (0.5 + k as f64) * std::f64::consts::PI / p.omega)
        .collect();
    let tol = 1e-10;
    let sol = solve(
        &e.problem,
        Dop853::default(),
        &Options::until(T_END)
            .tolerances(tol, tol)
            .output_times(across.clone()),
    )
    .expect("valid options");
    assert!(sol.is_success());
    assert_eq!(
        sol.t.iter().filter(|t| across.contains(t)).count(),
        across.len()
    );
    for (t, q) in sol.t.iter().zip(sol.q.iter()) {
        assert!(q[0] <= half * (1.0 + 50.0 * tol), "x({t}) = {}", q[0]);
        if across.contains(t) {
            // The same bound as the closed-form test: 50 tol of the length scale.
            assert!(
                (q[0] - half).abs() <= 50.0 * tol * 2.0 * half,
                "x({t}) = {}",
                q[0]
            );
        }
    }
}

#[test]
fn bad_parameters_are_refused_with_the_reason() {
    let bad = [
        Params {
            omega: 0.0,
            ..Params::default()
        },
        Params {
            alpha: 2.0,
            ..Params::default()
        },
        Params {
            m: f64::NAN,
            ..Params::default()
        },
    ];
    for p in bad {
        assert!(
            matches!(entry(&p), Err(Error::InvalidParameter { .. })),
            "{p:?}"
        );
    }
}
