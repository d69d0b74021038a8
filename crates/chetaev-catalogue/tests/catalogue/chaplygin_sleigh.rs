//! The Chaplygin sleigh against the closed form of its body velocities (Bloch §1.7):
//! `u = V tanh(c V t + s0)`, `ω = ω0 cosh s0 / cosh(c V t + s0)`, the heading by the Gudermannian,
//! and the conserved energy `½ m u² + ½ (I + m a²) ω²`.

use crate::common::{assert_energy_balance, assert_within, run, KINDS, TOLERANCES};
use chetaev::equations::{evaluate, Workspace};
use chetaev::prelude::*;
use chetaev_catalogue::chaplygin_sleigh::{body_velocities, entry, ClosedForm, Params};

/// Long enough for `ω` to fall by `e^(−2 c V t)`: about 1e-22 with the default parameters.
const T_END: f64 = 10.0;

#[test]
fn body_velocities_follow_the_closed_form_within_the_tolerance_asked() {
    for p in [
        Params::default(),
        // Centre of mass behind the blade, moving backwards, turning the other way.
        Params {
            a: -0.3,
            u0: -0.4,
            omega0: -2.0,
            theta0: 1.0,
            position: [2.0, -1.0],
            ..Params::default()
        },
    ] {
        let e = entry(&p).expect("valid");
        let v = e.reference.limit_speed();
        for tol in TOLERANCES {
            let (sol, cmp) = run(&e, T_END, tol);
            // The motion relaxes to uniform straight motion, which damps errors: observed ≤ 0.2 tol
            // for u, ω, θ, μ and E against V, V √(m/(I + m a²)), max(1, |θ|), the largest μ and
            // E. The stated bound is 10 tol.
            assert_within(&cmp, &KINDS, 10.0 * tol, &format!("{p:?} tol {tol:e}"));
            // f = −ẋ sin θ + ẏ cos θ is a velocity: drift against V (observed ≤ 0.1 tol).
            assert!(
                sol.max_residual().expect("recorded") <= 10.0 * tol * v,
                "tol {tol:e}"
            );
            assert_energy_balance(&sol, tol);
        }
    }
}

#[test]
fn the_sleigh_ends_moving_straight_at_the_limit_speed() {
    // E = ½ m V²: all the rotational energy ends in forward motion.
    let p = Params::default();
    let e = entry(&p).expect("valid");
    let (sol, _) = run(&e, T_END, 1e-10);
    let (_, q, qd) = sol.last().expect("points");
    let (q, qd) = (
        SVector::<f64, 3>::from_column_slice(q),
        SVector::<f64, 3>::from_column_slice(qd),
    );
    let (u, w) = body_velocities(&q, &qd);
    let v = e.reference.limit_speed();
    let v_expected =
        (p.u0 * p.u0 + (p.inertia + p.m * p.a * p.a) * p.omega0 * p.omega0 / p.m).sqrt();
    assert!((v - v_expected).abs() <= 1e-15 * v);
    // At t = 10, c V t ≈ 25.5: u = V (1 − O(e^(−51))), ω = O(e^(−25.5)) ≈ 1e-11 ω0.
    assert!((u - v).abs() <= 1e-9 * v, "u = {u}, V = {v}");
    assert!(w.abs() <= 1e-9 * p.omega0, "ω = {w}");
    // The total turn is finite: θ(∞) − θ0 = (ω0 cosh s0 / c V)(π/2 − gd s0).
    let turned = e.reference.heading(1e3) - p.theta0;
    assert!((q[2] - p.theta0 - turned).abs() <= 1e-9 * turned.abs());
}

#[test]
fn block_solve_gives_the_reduced_equations_and_the_blade_force() {
    // At states with the closed-form (θ, u, ω) (and any x, y): u̇ = a ω², (I + m a²) ω̇ = −m a u ω
    // and μ = m I u ω / (I + m a²), the sideways force on the blade, to rounding.
    let p = Params {
        m: 1.7,
        inertia: 0.23,
        a: 0.41,
        position: [0.0, 0.0],
        theta0: -0.6,
        u0: 0.35,
        omega0: 2.2,
    };
    let e = entry(&p).expect("valid");
    let cf = ClosedForm::new(&p).expect("valid");
    let model = e.problem.model();
    let mut ws = Workspace::for_model(model);
    let v = cf.limit_speed();
    let w_max = v * (p.m / (p.inertia + p.m * p.a * p.a)).sqrt();
    for t in [0.0, 0.2, 0.9, 2.0] {
        let (theta, u, w) = (cf.heading(t), cf.forward_speed(t), cf.turning_rate(t));
        let q = SVector::from([0.3, -1.2, theta]);
        let qd = SVector::from([u * theta.cos(), u * theta.sin(), w]);
        let d = evaluate(model, &mut ws, t, q.as_slice(), qd.as_slice()).expect("regular");
        let u_dot = d.qdd[0] * theta.cos() + d.qdd[1] * theta.sin();
        let (u_dot_ref, w_dot_ref) = cf.body_accelerations(t);
        let acc = p.a.abs() * w_max * w_max;
        assert!((u_dot - u_dot_ref).abs() <= 1e-14 * acc, "u̇ at {t}");
        assert!(
            (d.qdd[2] - w_dot_ref).abs() <= 1e-14 * acc / p.a.abs(),
            "ω̇ at {t}"
        );
        let force = p.m * p.inertia * v * w_max / (p.inertia + p.m * p.a * p.a);
        assert!(
            (d.mu[0] - cf.multiplier(t)).abs() <= 1e-14 * force,
            "μ at {t}"
        );
    }
}
