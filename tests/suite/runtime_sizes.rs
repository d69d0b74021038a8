//! Sizes known only at run time: a model written on slices ([`DynModel`], built with
//! `Problem::dynamic`) has the same equations, the same motion and every option of a static one.

use chetaev::equations::{evaluate, Workspace};
use chetaev::integrate::AnyMethod;
use chetaev::model::Fixed;
use chetaev::prelude::*;
use chetaev_suite::{distance, norm};
use uniform_projectile::closed_form::{table, Params};
use uniform_projectile::model::{impact, scaled_atol, uniform_problem, UniformProjectile};

/// The paper's model, sizes at run time.
#[derive(Debug)]
struct DynUniform(UniformProjectile);

impl DynModel for DynUniform {
    fn sizes(&self) -> (usize, usize) {
        (2, 1)
    }
    fn lagrangian<R: Real>(&self, t: R, q: &[R], qd: &[R]) -> R {
        self.0.lagrangian(
            t,
            &SVector::from_column_slice(q),
            &SVector::from_column_slice(qd),
        )
    }
    fn constraints<R: Real>(&self, t: R, q: &[R], qd: &[R], f: &mut [R]) {
        f[0] = self.0.constraints(
            t,
            &SVector::from_column_slice(q),
            &SVector::from_column_slice(qd),
        )[0];
    }
}

/// Every block non-zero (as in tests/suite/derivatives.rs), N = 2, K = 1, written once for both flavours.
#[derive(Clone, Copy)]
struct Everything;
impl Everything {
    fn l<R: Real>(t: R, x: R, y: R, xd: R, yd: R) -> R {
        let (a, b, c) = (x * x + 1.0, y.sin() + 2.0, x * y * 0.3);
        a * xd * xd * 0.5 + b * yd * yd * 0.5 + c * xd * yd + t.cos() * (x * yd - y * xd)
            - (t * 0.1 + 1.0) * (x * x + y.powi(4)) * 0.5
    }
    fn f<R: Real>(t: R, x: R, y: R, xd: R, yd: R) -> R {
        xd * xd + t.exp() * x * yd - t * y.sin()
    }
}
impl Lagrangian<2> for Everything {
    fn lagrangian<R: Real>(&self, t: R, q: &SVector<R, 2>, qd: &SVector<R, 2>) -> R {
        Self::l(t, q[0], q[1], qd[0], qd[1])
    }
}
impl Constraints<2, 1> for Everything {
    fn constraints<R: Real>(&self, t: R, q: &SVector<R, 2>, qd: &SVector<R, 2>) -> SVector<R, 1> {
        SVector::from([Self::f(t, q[0], q[1], qd[0], qd[1])])
    }
}
impl DynModel for Everything {
    fn sizes(&self) -> (usize, usize) {
        (2, 1)
    }
    fn lagrangian<R: Real>(&self, t: R, q: &[R], qd: &[R]) -> R {
        Self::l(t, q[0], q[1], qd[0], qd[1])
    }
    fn constraints<R: Real>(&self, t: R, q: &[R], qd: &[R], f: &mut [R]) {
        f[0] = Self::f(t, q[0], q[1], qd[0], qd[1]);
    }
}

#[test]
fn run_time_equations_equal_the_static_ones() {
    let (t, q, qd) = (0.7, [0.4, -1.1], [1.3, 0.6]);
    let fixed = Fixed::<_, 2, 1>(Everything);
    let mut ws_static = Workspace::for_model(&fixed);
    let s = evaluate(&fixed, &mut ws_static, t, &q, &qd).expect("regular");
    let mut ws_dynamic = Workspace::for_model(&Everything);
    let d = evaluate(&Everything, &mut ws_dynamic, t, &q, &qd).expect("regular");
    for i in 0..2 {
        assert!((s.qdd[i] - d.qdd[i]).abs() <= 1e-14 * s.qdd[i].abs().max(1.0));
        assert!((s.phi[i] - d.phi[i]).abs() <= 1e-14 * s.phi[i].abs().max(1.0));
    }
    assert!((s.mu[0] - d.mu[0]).abs() <= 1e-14 * s.mu[0].abs().max(1.0));
    assert!((s.energy - d.energy).abs() <= 1e-14 * s.energy.abs().max(1.0));
    assert!((s.dl_dt - d.dl_dt).abs() <= 1e-13 * s.dl_dt.abs().max(1.0));
}

/// The same method and options on the static and the run-time model of the paper's motion give
/// the same motion: the equations agree to rounding, so the step sequence is the same.
#[test]
fn run_time_sizes_solve_the_paper_like_the_static_path() {
    let p = Params::PAPER;
    let stat = uniform_problem(&p).expect("valid");
    let dynp = Problem::dynamic(
        DynUniform(**stat.model()),
        0.0,
        vec![0.0, p.h0],
        vec![p.v0, 0.0],
    )
    .expect("valid");
    let tol = 1e-12;
    let (aq, av) = scaled_atol(&p, tol);
    let base = Options::until(5.0).tolerances(tol, tol);
    let cases: Vec<(AnyMethod, Options)> = vec![
        // Events.
        (
            AnyMethod::Dop853(Dop853::default()),
            base.clone().event(impact()),
        ),
        // The implicit method (exact Jacobian by nested dual numbers), with projection.
        (
            AnyMethod::Rodas4(Rodas4),
            base.clone().event(impact()).project(Projection::default()),
        ),
        // Output times by dense output, up to a terminal event.
        (
            AnyMethod::Dopri5(Dopri5::default()),
            base.clone()
                .event(impact())
                .output_times(vec![0.25, 0.5, 0.75, 1.0]),
        ),
        // Per-component absolute tolerances, the state only, the final point only.
        (
            AnyMethod::Tsit5(Tsit5::default()),
            Options::until(1.0)
                .tolerances(tol, 0.0)
                .atol_per_component(&aq, &av)
                .record(Record::State)
                .output_final(),
        ),
        // A fixed step with projection, on an output grid.
        (
            AnyMethod::Rk4(Rk4::new(1e-3)),
            Options::until(1.0)
                .project(Projection::default())
                .output_grid(0.0, 11),
        ),
    ];
    let k = table(&p).uniform;
    for (method, options) in cases {
        let a = solve(&stat, method, &options).expect("valid");
        let b = solve(&dynp, method, &options).expect("valid");
        let name = a.method;
        assert!(a.is_success(), "{name}: {:?}", a.status);
        assert_eq!(a.status, b.status, "{name}");
        assert_eq!((a.n(), a.k()), (b.n(), b.k()), "{name}");
        // The same methods and controller on equations equal to rounding: the same motion.
        assert_eq!(a.len(), b.len(), "{name}");
        assert_eq!(a.stats.accepted_steps, b.stats.accepted_steps, "{name}");
        assert_eq!(a.stats.rejected_steps, b.stats.rejected_steps, "{name}");
        assert_eq!(a.stats.projections, b.stats.projections, "{name}");
        for i in 0..a.len() {
            assert!(
                (a.t[i] - b.t[i]).abs() <= 1e-13 * a.t[i].abs().max(1.0),
                "{name}: t {} vs {}",
                a.t[i],
                b.t[i]
            );
            assert!(
                distance(&a.q[i], &b.q[i]) <= 1e-12 * p.h0,
                "{name}: q {:?} vs {:?}",
                &a.q[i],
                &b.q[i]
            );
            assert!(
                distance(&a.qd[i], &b.qd[i]) <= 1e-12 * p.v0,
                "{name}: q̇ {:?} vs {:?}",
                &a.qd[i],
                &b.qd[i]
            );
        }
        if let Output::Times(times) = &options.output {
            // The start (once, also when it is an output time), the output times, and a terminal
            // event if one fired.
            let mut expected = vec![0.0];
            expected.extend(times.iter().filter(|&&s| s != 0.0));
            assert_eq!(
                a.len(),
                expected.len() + a.events.len(),
                "{name}: {:?}",
                a.t
            );
            assert_eq!(&a.t[..expected.len()], &expected[..], "{name}");
            assert_eq!(a.t, b.t, "{name}");
        }
        assert_eq!(a.events.len(), b.events.len(), "{name}");
        if let (Some(ha), Some(hb)) = (a.events.first(), b.events.first()) {
            assert!(
                (ha.t - hb.t).abs() <= 1e-13 * ha.t,
                "{name}: {} vs {}",
                ha.t,
                hb.t
            );
            assert!(((hb.t - k.t_impact) / k.t_impact).abs() <= 1e-10, "{name}");
            assert!(((hb.q[0] - k.range) / k.range).abs() <= 1e-10, "{name}");
        }
        let ba = a.energy_balance();
        let bb = b.energy_balance();
        assert_eq!(ba.len(), bb.len(), "{name}");
        assert!(bb.iter().all(|v| v.abs() <= 1e-9), "{name}");
        match (a.max_residual(), b.max_residual()) {
            (Some(ra), Some(rb)) => assert!((ra - rb).abs() <= 1e-10, "{name}"),
            (None, None) => assert_eq!(a.record, Record::State, "{name}"),
            other => panic!("{name}: {other:?}"),
        }
    }
}

#[test]
fn run_time_initial_velocity_is_projected_like_the_static_one() {
    let p = Params::PAPER;
    let model = **uniform_problem(&p).expect("valid").model();
    let (q0, qd0) = ([0.0, p.h0], [1.05 * p.v0, 0.0]);
    let e = Problem::dynamic(DynUniform(model), 0.0, q0.to_vec(), qd0.to_vec()).unwrap_err();
    assert!(
        matches!(e, Error::InconsistentInitialState { index: 1, .. }),
        "{e}"
    );
    let stat = Problem::with_projected_velocity(model, 0.0, SVector::from(q0), SVector::from(qd0))
        .expect("projectable");
    let dynp =
        Problem::dynamic_with_projected_velocity(DynUniform(model), 0.0, q0.to_vec(), qd0.to_vec())
            .expect("projectable");
    assert!(distance(stat.qd0(), dynp.qd0()) <= 1e-14 * p.v0);
    assert!((norm(dynp.qd0()) - p.v0).abs() <= 1e-14 * p.v0);
    assert_eq!(dynp.q0(), &q0[..], "only the velocity is changed");
}

/// N unit masses on springs (N chosen at run time) held at constant total speed.
#[derive(Debug)]
struct Chain {
    n: usize,
    v0: f64,
}
impl DynModel for Chain {
    fn sizes(&self) -> (usize, usize) {
        (self.n, 1)
    }
    fn lagrangian<R: Real>(&self, _t: R, q: &[R], qd: &[R]) -> R {
        let mut l = R::zero();
        for i in 0..self.n {
            l += qd[i] * qd[i] * 0.5 - q[i] * q[i] * 0.5;
            if i + 1 < self.n {
                l -= (q[i + 1] - q[i]).powi(2) * 0.5;
            }
        }
        l
    }
    fn constraints<R: Real>(&self, _t: R, _q: &[R], qd: &[R], f: &mut [R]) {
        f[0] = qd.iter().fold(R::zero(), |a, v| a + *v * *v) - self.v0 * self.v0;
    }
}

#[test]
fn sizes_chosen_at_run_time_work_end_to_end() {
    for n in [1usize, 5, 12] {
        let mut qd0 = vec![0.0; n];
        qd0[0] = 2.0;
        let q0: Vec<f64> = (0..n).map(|i| 0.1 * i as f64).collect();
        let p = Problem::dynamic(Chain { n, v0: 2.0 }, 0.0, q0, qd0).expect("valid");
        let sol = solve(
            &p,
            Dop853::default(),
            &Options::until(3.0)
                .tolerances(1e-10, 1e-10)
                .project(Projection::default()),
        )
        .expect("valid");
        assert!(sol.is_success(), "n = {n}: {:?}", sol.status);
        assert_eq!((sol.n(), sol.k()), (n, 1));
        assert!(
            sol.max_residual().expect("recorded") <= 1e-12 * 2.0 * 4.0,
            "n = {n}: {:e}",
            sol.max_residual().expect("recorded")
        );
        assert!(
            sol.max_energy_balance().is_some_and(|b| b <= 1e-8),
            "n = {n}"
        );
    }
}

#[test]
fn run_time_sizes_are_validated() {
    let e = Problem::dynamic(
        Chain { n: 3, v0: 1.0 },
        0.0,
        vec![0.0; 2],
        vec![1.0, 0.0, 0.0],
    )
    .unwrap_err();
    assert!(matches!(e, Error::InvalidModel { .. }), "{e}");
    assert!(e.to_string().contains("q0 has 2 entries"), "{e}");
    let e = Problem::dynamic(Chain { n: 0, v0: 1.0 }, 0.0, vec![], vec![]).unwrap_err();
    assert!(matches!(e, Error::InvalidModel { .. }), "{e}");
    let e =
        Problem::dynamic(Chain { n: 2, v0: 1.0 }, 0.0, vec![0.0; 2], vec![2.0, 0.0]).unwrap_err();
    assert!(
        matches!(e, Error::InconsistentInitialState { index: 1, .. }),
        "{e}"
    );
    let p = Problem::dynamic(Chain { n: 2, v0: 1.0 }, 0.0, vec![0.0; 2], vec![1.0, 0.0])
        .expect("valid");
    let e = solve(
        &p,
        Dopri5::default(),
        &Options::until(1.0).atol_per_component(&[1e-9; 2], &[1e-9; 1]),
    )
    .unwrap_err();
    assert!(
        matches!(
            e,
            Error::InvalidOption {
                name: "atol (length)",
                ..
            }
        ),
        "{e}"
    );
    let sol = solve(
        &p,
        Dopri5::default(),
        &Options::until(1.0).atol_per_component(&[1e-9; 2], &[1e-9; 2]),
    )
    .expect("one tolerance per component is valid");
    assert!(sol.is_success(), "{:?}", sol.status);
}
