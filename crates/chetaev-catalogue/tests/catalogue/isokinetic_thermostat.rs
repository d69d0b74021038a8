//! The Gaussian isokinetic thermostat against its closed form for constant forces (Zhang 1997;
//! Minary, Martyna & Tuckerman 2003; Tuckerman §4.12), its multiplier against the friction
//! coefficient of the isokinetic equations (Evans & Morriss), and its one-particle case against the
//! uniform horizontal projectile of Swaczyna and Volný.

use crate::common::{assert_energy_balance, assert_within, run, KINDS, TOLERANCES};
use chetaev::equations::{evaluate, Workspace};
use chetaev::prelude::*;
use chetaev_catalogue::isokinetic_thermostat::{entry, friction_coefficient, ClosedForm, Params};
use uniform_projectile::closed_form::{uniform, Params as Paper};

/// Eight particles in 3D (`N = 24`) with masses 1…8 and alternating charges in a tilted field.
fn eight_particles() -> Params<24> {
    let masses: Vec<f64> = (1..=8).map(f64::from).collect();
    let charges: Vec<f64> = (0..8)
        .map(|i| if i % 2 == 0 { 1.0 } else { -0.7 })
        .collect();
    let positions: Vec<f64> = (0..24).map(|k| (k as f64 * 0.37).sin()).collect();
    let velocities: Vec<f64> = (0..24).map(|k| (k as f64 * 1.3 + 0.2).cos()).collect();
    Params::particles_in_field(
        3,
        &masses,
        &charges,
        &[0.3, -0.5, 1.1],
        &positions,
        &velocities,
    )
    .expect("consistent lengths")
}

fn check_against_closed_form<const N: usize>(p: &Params<N>, t_end: f64, tolerances: &[f64]) {
    let e = entry(p).expect("valid");
    let k0 = p.kinetic_energy();
    for &tol in tolerances {
        let (sol, cmp) = run(&e, t_end, tol);
        // Observed ≤ 1.1 tol for positions (against √(2K0/m_k) · max(t, 1/√b)), velocities
        // (against √(2K0/m_k)), μ (against √b) and K (against K0), from 1e-6 to 1e-12. The stated
        // bound is 10 tol.
        assert_within(&cmp, &KINDS, 10.0 * tol, &format!("N = {N}, tol {tol:e}"));
        // f = K − K0 against K0 (observed ≤ 1.1 tol).
        assert!(
            sol.max_residual().expect("recorded") <= 10.0 * tol * k0,
            "tol {tol:e}"
        );
        assert_energy_balance(&sol, tol);
    }
}

#[test]
fn four_particles_in_3d_follow_the_closed_form_within_the_tolerance_asked() {
    // N = 12 coordinates, one constraint; ten field time scales 1/√b.
    let p = Params::four_particles();
    let (_, b) = ClosedForm::new(&p).expect("valid").coefficients();
    check_against_closed_form(&p, 10.0 / b.sqrt(), &TOLERANCES);
}

#[test]
fn eight_particles_in_3d_follow_the_closed_form_within_the_tolerance_asked() {
    // N = 24 coordinates, one constraint; one tolerance (each right-hand side differentiates a
    // 24 × 24 Hessian, which is slow in unoptimised test builds).
    let p = eight_particles();
    let (_, b) = ClosedForm::new(&p).expect("valid").coefficients();
    check_against_closed_form(&p, 5.0 / b.sqrt(), &[1e-10]);
}

#[test]
fn multiplier_is_minus_the_gaussian_friction_coefficient() {
    // m_k q̈_k = F_k + μ m_k q̇_k with μ = −α, α = Σ F·v / Σ m v² (Evans & Morriss), at arbitrary
    // states on the constraint (any q, any q̇ with Σ ½ m q̇² = K0).
    let p = eight_particles();
    let e = entry(&p).expect("valid");
    let k0 = p.kinetic_energy();
    let model = e.problem.model();
    let mut ws = Workspace::for_model(model);
    for s in 0..5 {
        let q = SVector::<f64, 24>::from_fn(|k, _| ((k * 7 + s * 3) as f64).sin() * 4.0);
        let v = SVector::<f64, 24>::from_fn(|k, _| ((k * 5 + s * 11) as f64 * 0.7).cos());
        let v = v * (k0 / (0.5 * p.mass.component_mul(&v).dot(&v))).sqrt();
        let d = evaluate(model, &mut ws, 0.0, q.as_slice(), v.as_slice()).expect("regular");
        let alpha = friction_coefficient(&p.mass, &p.force, &v);
        let (_, b) = ClosedForm::new(&p).expect("valid").coefficients();
        // |α| ≤ √b: compare against √b, to rounding.
        assert!(
            (d.mu[0] + alpha).abs() <= 1e-14 * b.sqrt(),
            "μ = {}, α = {alpha}",
            d.mu[0]
        );
        for k in 0..24 {
            let phi = -alpha * p.mass[k] * v[k];
            let scale = b.sqrt() * p.mass[k] * (2.0 * k0 / p.mass[k]).sqrt();
            assert!((d.phi[k] - phi).abs() <= 1e-14 * scale, "Φ[{k}]");
            let qdd = p.force[k] / p.mass[k] - alpha * v[k];
            assert!(
                (d.qdd[k] - qdd).abs() <= 1e-14 * scale / p.mass[k],
                "q̈[{k}]"
            );
        }
        // The Chetaev force removes exactly the power of the field: q̇·Φ = 2 K0 μ = −F·q̇.
        let phi = SVector::<f64, 24>::from_column_slice(&d.phi);
        assert!((phi.dot(&v) + p.force.dot(&v)).abs() <= 1e-13 * b.sqrt() * k0);
    }
}

#[test]
fn one_particle_in_gravity_is_the_uniform_projectile() {
    // f = ½ m |q̇|² − ½ m v0² is the paper's f = |q̇|² − v0² times m/2, so Φ = μ m q̇ = 2 μ_paper q̇:
    // μ = 2 μ_paper / m = −(g/v0) tanh(g t/v0), and the motion is (42.29), (42.30).
    let paper = Paper::PAPER;
    let p = Params::projectile(paper.m, paper.g, paper.v0, paper.h0);
    let e = entry(&p).expect("valid");
    let (a, b) = e.reference.coefficients();
    assert_eq!(a, 0.0);
    assert!((b.sqrt() - paper.g / paper.v0).abs() <= 1e-15 * paper.g / paper.v0);
    // Until the impact, T = 1.085 s (Table 42.1).
    let t_end = uniform::kinematics(&paper).t_impact;
    let q_scale = paper.h0.max(uniform::kinematics(&paper).range);
    for tol in TOLERANCES {
        let (sol, cmp) = run(&e, t_end, tol);
        for i in 0..sol.len() {
            let t = sol.t[i];
            let (x, v) = (uniform::position(&paper, t), uniform::velocity(&paper, t));
            for c in 0..2 {
                // As tests/suite/paper.rs: positions against max(h0, R), velocities against v0; observed
                // ≤ 0.15 tol, stated bound 10 tol.
                assert!(
                    (sol.q[i][c] - x[c]).abs() <= 10.0 * tol * q_scale,
                    "x[{c}]({t})"
                );
                assert!(
                    (sol.qd[i][c] - v[c]).abs() <= 10.0 * tol * paper.v0,
                    "v[{c}]({t})"
                );
            }
            let mu = 2.0 * uniform::multiplier(&paper, t) / paper.m;
            assert!(
                (sol.mu[i][0] - mu).abs() <= 10.0 * tol * paper.g / paper.v0,
                "μ({t})"
            );
            // |Φ| = m g tanh(g t/v0), (42.42).
            let phi = uniform::chetaev_force_magnitude(&paper, t);
            let phi_norm = sol.phi[i].iter().map(|x| x * x).sum::<f64>().sqrt();
            assert!((phi_norm - phi).abs() <= 10.0 * tol * paper.m * paper.g);
        }
        // The catalogue's own closed form agrees with the paper's along the same motion.
        assert!(cmp.max() <= 10.0 * tol, "{:?}", cmp.worst());
        assert_energy_balance(&sol, tol);
    }
    // And pointwise, without integration: the closed forms coincide to rounding.
    for t in [0.0, 0.1, 0.5, 1.0, 3.0, -0.7] {
        let (q, v) = (e.reference.position(t), e.reference.velocity(t));
        let (x, w) = (uniform::position(&paper, t), uniform::velocity(&paper, t));
        let length = paper.v0 * paper.v0 / paper.g;
        for c in 0..2 {
            assert!(
                (q[c] - x[c]).abs() <= 1e-14 * length.max(paper.v0 * t.abs()),
                "q[{c}]({t})"
            );
            assert!((v[c] - w[c]).abs() <= 1e-15 * paper.v0, "v[{c}]({t})");
        }
        let mu = 2.0 * uniform::multiplier(&paper, t) / paper.m;
        assert!((e.reference.multiplier(t) - mu).abs() <= 1e-15 * paper.g / paper.v0);
    }
}

#[test]
fn closed_form_is_exact_where_it_degenerates() {
    // Velocity along (β = 1) or against (β = −1) the acceleration M⁻¹F of the field: the speed
    // cannot change and the velocity cannot turn, so the motion is uniform, q = q0 + q̇0 t, with
    // μ = −β √b. Here γ = 0 and 1 + β w → 0, where the textbook forms cancel (against the field
    // (q̇0 + M⁻¹F s)/ṡ does, to rounding amplified by e^(√b t)): the closed form is exact to
    // rounding either way, long after e^(√b t) overflows.
    for beta in [1.0, -1.0] {
        let p = Params::<3> {
            mass: SVector::from([1.0, 2.0, 1.0]),
            force: SVector::from([0.0, 0.0, -2.0]),
            q0: SVector::from([0.5, 0.0, 0.0]),
            qd0: SVector::from([0.0, 0.0, -beta]),
        };
        let cf = ClosedForm::new(&p).expect("valid");
        let r = cf.coefficients().1.sqrt();
        assert_eq!(r, 2.0);
        for t in [0.0, 0.1, 1.0, 5.0, 15.0, 40.0, 1e3] {
            let bound = 4.0 * f64::EPSILON;
            let (q, v) = (cf.position(t), cf.velocity(t));
            let q_exact = p.q0 + p.qd0 * t;
            assert!(
                (q - q_exact).norm() <= bound * (1.0 + t),
                "β = {beta}, t = {t}: {q}"
            );
            assert!((v - p.qd0).norm() <= bound, "β = {beta}, t = {t}: {v}");
            assert!(
                (cf.multiplier(t) + beta * r).abs() <= bound * r,
                "β = {beta}, t = {t}"
            );
        }
    }
    // Along the field the uniform motion is stable (the friction takes the work of the field);
    // against it, exactly, no rounding of the solve moves the velocity off its line, so the
    // solve stays uniform too (one particle launched straight up in gravity at 2 m/s, μ = g/2);
    // a weak field (b = 1e-18) is nearly free motion: all integrate to the closed form.
    let cases = [
        Params::<3> {
            mass: SVector::from([1.0, 1.0, 1.0]),
            force: SVector::from([0.0, 0.0, -9.81]),
            q0: SVector::from([0.0, 0.0, 1.0]),
            qd0: SVector::from([0.0, 0.0, 2.0]),
        },
        Params::<3> {
            mass: SVector::from([1.0, 1.0, 1.0]),
            force: SVector::from([0.0, 0.0, -2.0]),
            q0: SVector::zeros(),
            qd0: SVector::from([0.0, 0.0, -1.0]),
        },
        Params::<3> {
            mass: SVector::from([1.0, 2.0, 3.0]),
            force: SVector::from([1e-9, 0.0, -1e-9]),
            q0: SVector::from([1.0, 2.0, 3.0]),
            qd0: SVector::from([0.5, -0.5, 0.2]),
        },
    ];
    for p in cases {
        let e = entry(&p).expect("valid");
        let tol = 1e-12;
        let (sol, cmp) = run(&e, 5.0, tol);
        assert!(cmp.max() <= 10.0 * tol, "{p:?}: {:?}", cmp.worst());
        assert_energy_balance(&sol, tol);
    }
}
