//! Sizes known only at run time: the same equations and motion as the static path.

use chetaev::dynamic::{
    dynamics as dyn_dynamics, solve_dyn, DynEvent, DynModel, DynOptions, DynProblem,
};
use chetaev::equations::{dynamics, saddle::SaddleWorkspace};
use chetaev::prelude::*;
use uniform_projectile::closed_form::{table, Params};
use uniform_projectile::model::{impact, uniform_problem, UniformProjectile};

/// The paper's model, sizes at run time.
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

/// Every block non-zero (as in tests/derivatives.rs), N = 2, K = 1, written once for both paths.
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
    let s = dynamics::<_, f64, 2, 1>(
        &Everything,
        &mut SaddleWorkspace::default(),
        t,
        &SVector::from(q),
        &SVector::from(qd),
    )
    .expect("regular");
    let d =
        dyn_dynamics(&Everything, &mut SaddleWorkspace::default(), t, &q, &qd).expect("regular");
    for i in 0..2 {
        assert!((s.qdd[i] - d.qdd[i]).abs() <= 1e-14 * s.qdd[i].abs().max(1.0));
        assert!((s.phi[i] - d.phi[i]).abs() <= 1e-14 * s.phi[i].abs().max(1.0));
    }
    assert!((s.mu[0] - d.mu[0]).abs() <= 1e-14 * s.mu[0].abs().max(1.0));
    assert!((s.energy - d.energy).abs() <= 1e-14 * s.energy.abs().max(1.0));
    assert!((s.dl_dt - d.dl_dt).abs() <= 1e-13 * s.dl_dt.abs().max(1.0));
}

#[test]
fn run_time_sizes_solve_the_paper_like_the_static_path() {
    let p = Params::PAPER;
    let stat = uniform_problem(&p).expect("valid");
    let dynp = DynProblem::new(
        DynUniform(*stat.model()),
        0.0,
        vec![0.0, p.h0],
        vec![p.v0, 0.0],
    )
    .expect("valid");
    let tol = 1e-12;
    for (a, b) in [
        (
            solve(
                &stat,
                Dop853::default(),
                &Options::until(5.0).tolerances(tol, tol).event(impact()),
            )
            .expect("valid"),
            solve_dyn(
                &dynp,
                Dop853::default(),
                &DynOptions::until(5.0)
                    .tolerances(tol, tol)
                    .event(DynEvent::new("impact", |_, q, _| q[1]).falling().terminal()),
            )
            .expect("valid"),
        ),
        (
            solve(
                &stat,
                Rodas4,
                &Options::until(5.0)
                    .tolerances(tol, tol)
                    .event(impact())
                    .project(Projection::default()),
            )
            .expect("valid"),
            solve_dyn(
                &dynp,
                Rodas4,
                &DynOptions::until(5.0)
                    .tolerances(tol, tol)
                    .project(Projection::default())
                    .event(DynEvent::new("impact", |_, q, _| q[1]).falling().terminal()),
            )
            .expect("valid"),
        ),
    ] {
        assert_eq!(a.status, b.status);
        // The same methods and controller on equations equal to rounding: the same motion.
        assert_eq!(a.len(), b.len(), "{}", a.method);
        let (ha, hb) = (&a.events[0], &b.events[0]);
        assert!(
            (ha.t - hb.t).abs() <= 1e-13 * ha.t,
            "{}: {} vs {}",
            a.method,
            ha.t,
            hb.t
        );
        let k = table(&p).uniform;
        assert!(((hb.t - k.t_impact) / k.t_impact).abs() <= 1e-10);
        assert!(((hb.q[0] - k.range) / k.range).abs() <= 1e-10);
        let ba = a.energy_balance();
        let bb = b.energy_balance();
        assert_eq!(ba.len(), bb.len());
        assert!(bb.iter().all(|v| v.abs() <= 1e-9));
        assert!((a.max_residual() - b.max_residual()).abs() <= 1e-10);
        assert_eq!(a.stats.accepted_steps, b.stats.accepted_steps);
        assert_eq!(a.stats.projections, b.stats.projections);
    }
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
        let p = DynProblem::new(Chain { n, v0: 2.0 }, 0.0, q0, qd0).expect("valid");
        let sol = solve_dyn(
            &p,
            Dop853::default(),
            &DynOptions::until(3.0)
                .tolerances(1e-10, 1e-10)
                .project(Projection::default()),
        )
        .expect("valid");
        assert!(sol.is_success(), "n = {n}: {:?}", sol.status);
        assert!(
            sol.max_residual() <= 1e-12 * 2.0 * 4.0,
            "n = {n}: {:e}",
            sol.max_residual()
        );
        assert!(
            sol.energy_balance().iter().all(|b| b.abs() <= 1e-8),
            "n = {n}"
        );
    }
}

#[test]
fn run_time_sizes_are_validated() {
    let e = DynProblem::new(
        Chain { n: 3, v0: 1.0 },
        0.0,
        vec![0.0; 2],
        vec![1.0, 0.0, 0.0],
    )
    .unwrap_err();
    assert!(
        matches!(
            e,
            Error::InvalidOption {
                name: "q0 (length)",
                ..
            }
        ),
        "{e}"
    );
    let e = DynProblem::new(Chain { n: 0, v0: 1.0 }, 0.0, vec![], vec![]).unwrap_err();
    assert!(matches!(e, Error::InvalidOption { .. }), "{e}");
    let e =
        DynProblem::new(Chain { n: 2, v0: 1.0 }, 0.0, vec![0.0; 2], vec![2.0, 0.0]).unwrap_err();
    assert!(matches!(e, Error::InconsistentInitialState { .. }), "{e}");
    let p =
        DynProblem::new(Chain { n: 2, v0: 1.0 }, 0.0, vec![0.0; 2], vec![1.0, 0.0]).expect("valid");
    let e = solve_dyn(
        &p,
        Dopri5::default(),
        &DynOptions::until(1.0).atol_per_component(vec![1e-9; 3]),
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
}
