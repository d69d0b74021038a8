//! The ode_solvers backend against closed forms, chetaev's own integrators, and the options it
//! must refuse.

use chetaev::model::Fixed;
use chetaev::prelude::*;
use chetaev_ode_solvers::{solve_with_ode_solvers, BackendError, OdeSolversMethod};
use uniform_projectile::closed_form::{uniform, Params};
use uniform_projectile::model::uniform_problem;

const METHODS: [OdeSolversMethod; 2] = OdeSolversMethod::ALL;

/// `L = ½ẋ² + x sin t`: `ẍ = sin t`, so `x = t − sin t`, `ẋ = 1 − cos t` through the origin at rest.
struct Forced;
impl Lagrangian<1> for Forced {
    fn lagrangian<R: Real>(&self, t: R, q: &SVector<R, 1>, qd: &SVector<R, 1>) -> R {
        qd[0] * qd[0] * 0.5 + q[0] * t.sin()
    }
}

/// `L = ½ẋ² + x √(2 − t)`: `ẍ = √(2 − t)`, not finite after `t = 2`.
struct Expiring;
impl Lagrangian<1> for Expiring {
    fn lagrangian<R: Real>(&self, t: R, q: &SVector<R, 1>, qd: &SVector<R, 1>) -> R {
        qd[0] * qd[0] * 0.5 + q[0] * (t * (-1.0) + 2.0).sqrt()
    }
}

/// The uniform projectile with its sizes known at run time: `L = ½(ẋ² + ẏ²) − g y`,
/// `f = ẋ² + ẏ² − v0²` (unit mass).
struct DynUniform {
    g: f64,
    v0: f64,
}
impl DynModel for DynUniform {
    fn sizes(&self) -> (usize, usize) {
        (2, 1)
    }
    fn lagrangian<R: Real>(&self, _t: R, q: &[R], qd: &[R]) -> R {
        (qd[0] * qd[0] + qd[1] * qd[1]) * 0.5 - q[1] * self.g
    }
    fn constraints<R: Real>(&self, _t: R, _q: &[R], qd: &[R], f: &mut [R]) {
        f[0] = qd[0] * qd[0] + qd[1] * qd[1] - self.v0 * self.v0;
    }
}

type ForcedProblem = Problem<Fixed<Unconstrained<Forced>, 1, 0>>;

/// The forced motion from its exact state at `t0`.
fn forced_problem(t0: f64) -> ForcedProblem {
    let q0 = SVector::from([t0 - t0.sin()]);
    let qd0 = SVector::from([1.0 - t0.cos()]);
    Problem::unconstrained(Forced, t0, q0, qd0).expect("consistent")
}

/// Largest deviation of `x` and `ẋ` from `t − sin t`, `1 − cos t` over the recorded points.
fn forced_error(sol: &Solution) -> f64 {
    (0..sol.len())
        .map(|i| {
            let t = sol.t[i];
            let ex = (sol.q[i][0] - (t - t.sin())).abs();
            let ev = (sol.qd[i][0] - (1.0 - t.cos())).abs();
            ex.max(ev)
        })
        .fold(0.0, f64::max)
}

/// Largest deviation of `q`, `q̇` from the paper's closed form (42.29), (42.30).
fn uniform_error(p: &Params, sol: &Solution) -> f64 {
    let mut err = 0.0f64;
    for i in 0..sol.len() {
        let (x, v) = (
            uniform::position(p, sol.t[i]),
            uniform::velocity(p, sol.t[i]),
        );
        for j in 0..2 {
            err = err.max((sol.q[i][j] - x[j]).abs());
            err = err.max((sol.qd[i][j] - v[j]).abs());
        }
    }
    err
}

fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |a, b| a.max(b.abs()))
}

fn assert_consistent_lengths(sol: &Solution) {
    let n = sol.len();
    assert_eq!(sol.q.len(), n);
    assert_eq!(sol.qd.len(), n);
    let dynamics = if sol.record >= Record::Dynamics { n } else { 0 };
    for len in [
        sol.qdd.len(),
        sol.mu.len(),
        sol.phi.len(),
        sol.residual.len(),
        sol.energy.len(),
    ] {
        assert_eq!(len, dynamics);
    }
    let energy = if sol.record >= Record::Energy { n } else { 0 };
    assert_eq!(sol.work.len(), energy);
    assert_eq!(sol.dl_dt_integral.len(), energy);
}

/// Right-hand sides per attempt and extra per accepted step, as `ode_solvers` 0.6.2 makes them.
fn evaluations_per_step(method: OdeSolversMethod) -> (usize, usize) {
    match method {
        OdeSolversMethod::Dopri5 => (6, 0),
        OdeSolversMethod::Dop853 => (11, 1),
    }
}

#[test]
fn uniform_projectile_matches_the_closed_form() {
    let p = Params::PAPER;
    let problem = uniform_problem(&p).expect("consistent");
    let options = Options::until(1.0).tolerances(1e-12, 1e-12);
    for method in METHODS {
        let sol = solve_with_ode_solvers(&problem, method, &options).expect("valid");
        assert_eq!(sol.status, Status::Success, "{method:?}");
        assert_eq!(sol.method, method.name());
        assert_consistent_lengths(&sol);
        assert_eq!(sol.t[0], 0.0);
        assert_eq!(*sol.t.last().expect("points"), 1.0);
        let err = uniform_error(&p, &sol);
        let balance = max_abs(&sol.energy_balance());
        // μ (42.40), in the Newton form of the paper.
        let mu_err = (0..sol.len())
            .map(|i| (sol.mu[i][0] - uniform::multiplier(&p, sol.t[i])).abs())
            .fold(0.0, f64::max);
        assert!(err < 1e-9, "{method:?}: {err:e}");
        assert!(balance < 1e-9, "{method:?}: {balance:e}");
        assert!(mu_err < 1e-9, "{method:?}: {mu_err:e}");
        assert!(sol.max_residual().expect("recorded") < 1e-9, "{method:?}");
        assert_eq!(sol.stats.accepted_steps, sol.len() - 1);
        assert!(sol.stats.rhs_evaluations > 0);
        assert_eq!(sol.stats.output_evaluations, sol.len());
    }
}

#[test]
fn run_time_models_are_integrated_alike() {
    let p = Params::PAPER;
    let problem = Problem::dynamic(
        DynUniform { g: p.g, v0: p.v0 },
        0.0,
        vec![0.0, p.h0],
        vec![p.v0, 0.0],
    )
    .expect("consistent");
    let fixed = uniform_problem(&p).expect("consistent");
    let options = Options::until(1.0).tolerances(1e-12, 1e-12);
    for method in METHODS {
        let sol = solve_with_ode_solvers(&problem, method, &options).expect("valid");
        assert_eq!(sol.status, Status::Success, "{method:?}");
        let err = uniform_error(&p, &sol);
        assert!(err < 1e-9, "{method:?}: {err:e}");
        // The same equations by another differentiation: the same steps up to rounding.
        let reference = solve_with_ode_solvers(&fixed, method, &options).expect("valid");
        assert_eq!(sol.len(), reference.len(), "{method:?}");
    }
}

#[test]
fn agrees_with_chetaev_own_integrators() {
    let p = Params::PAPER;
    let problem = uniform_problem(&p).expect("consistent");
    let options = Options::until(1.0).tolerances(1e-12, 1e-12).output_final();
    let ours = [
        solve(&problem, Dopri5::default(), &options).expect("valid"),
        solve(&problem, Dop853::default(), &options).expect("valid"),
    ];
    for (method, ours) in METHODS.into_iter().zip(ours) {
        let theirs = solve_with_ode_solvers(&problem, method, &options).expect("valid");
        assert_eq!(theirs.status, Status::Success);
        let (t, q, qd) = theirs.last().expect("points");
        let (s, r, rd) = ours.last().expect("points");
        assert_eq!(t, s);
        for j in 0..2 {
            assert!((q[j] - r[j]).abs() < 1e-9, "{method:?}: {q:?} {r:?}");
            assert!((qd[j] - rd[j]).abs() < 1e-9, "{method:?}: {qd:?} {rd:?}");
        }
    }
}

#[test]
fn explicit_time_dependence_matches_the_exact_solution() {
    let problem = forced_problem(0.0);
    let options = Options::until(3.0).tolerances(1e-12, 1e-12);
    for method in METHODS {
        let sol = solve_with_ode_solvers(&problem, method, &options).expect("valid");
        assert_eq!(sol.status, Status::Success);
        assert_eq!(*sol.t.last().expect("points"), 3.0);
        let err = forced_error(&sol);
        // ∂L/∂t = x cos t; its integral and E = ½ẋ² − x sin t balance with W_Φ = 0.
        let balance = max_abs(&sol.energy_balance());
        assert!(err < 1e-9, "{method:?}: {err:e}");
        assert!(balance < 1e-9, "{method:?}: {balance:e}");
    }
}

#[test]
fn integrates_backward() {
    let problem = forced_problem(1.0);
    let options = Options::until(-2.0).tolerances(1e-12, 1e-12);
    for method in METHODS {
        let sol = solve_with_ode_solvers(&problem, method, &options).expect("valid");
        assert_eq!(sol.status, Status::Success);
        assert_consistent_lengths(&sol);
        assert_eq!(sol.t[0], 1.0);
        assert_eq!(*sol.t.last().expect("points"), -2.0);
        assert!(sol.t.windows(2).all(|w| w[1] < w[0]));
        let err = forced_error(&sol);
        assert!(err < 1e-9, "{method:?}: {err:e}");
        // ∫_1^{-2} ∂L/∂t dt = ∫ x cos t dt, checked through the energy balance.
        let balance = max_abs(&sol.energy_balance());
        assert!(balance < 1e-9, "{method:?}: {balance:e}");
    }
}

#[test]
fn bad_input_is_chetaev_error() {
    let problem = forced_problem(0.0);
    let m = OdeSolversMethod::Dopri5;
    for (rtol, atol) in [
        (-1e-6, 1e-9),
        (f64::NAN, 1e-9),
        (1e-16, 1e-9),
        (1e-6, -1e-9),
        (1e-6, f64::INFINITY),
        (1e-6, f64::NAN),
        (0.0, 1e-301),
        (0.0, 0.0),
    ] {
        let r = solve_with_ode_solvers(&problem, m, &Options::until(1.0).tolerances(rtol, atol));
        assert!(
            matches!(r, Err(BackendError::Chetaev(Error::InvalidOption { .. }))),
            "{rtol} {atol}: {r:?}"
        );
    }
    for t_end in [f64::NAN, f64::INFINITY] {
        let r = solve_with_ode_solvers(&problem, m, &Options::until(t_end));
        assert!(
            matches!(r, Err(BackendError::Chetaev(Error::NonFiniteInput { .. }))),
            "{r:?}"
        );
    }
    // Finite ends whose distance is not.
    let far = Problem::unconstrained(Forced, -1e308, SVector::from([0.0]), SVector::from([0.0]))
        .expect("valid");
    let r = solve_with_ode_solvers(&far, m, &Options::until(1e308));
    assert!(
        matches!(r, Err(BackendError::Chetaev(Error::NonFiniteInput { .. }))),
        "{r:?}"
    );
    for options in [
        Options::until(1.0).max_steps(0),
        Options::until(1.0).initial_step(0.0),
        Options::until(1.0).initial_step(f64::NAN),
        Options::until(1.0).max_step(0.0),
        Options::until(1.0).max_step(-1.0),
        Options::until(1.0).controller(Controller::pi(0.2, 10.0, 0.5)),
    ] {
        let r = solve_with_ode_solvers(&problem, m, &options);
        assert!(
            matches!(r, Err(BackendError::Chetaev(Error::InvalidOption { .. }))),
            "{options:?}: {r:?}"
        );
    }
    let r = solve_with_ode_solvers(&problem, m, &Options::until(1.0).output_times(vec![2.0]));
    assert!(
        matches!(
            r,
            Err(BackendError::Chetaev(Error::OutputTimeOutOfRange { time, .. })) if time == 2.0
        ),
        "{r:?}"
    );
    let r = solve_with_ode_solvers(
        &problem,
        m,
        &Options::until(1.0).output_times(vec![f64::NAN]),
    );
    assert!(
        matches!(r, Err(BackendError::Chetaev(Error::NonFiniteInput { .. }))),
        "{r:?}"
    );
}

/// Options both integrators take are checked alike: the backend refuses bad numbers with the very
/// error `chetaev::solve` returns for them (per-component `atol` and `atol = 0` aside, which only
/// the backend refuses).
#[test]
fn bad_numbers_get_the_answer_chetaev_gives() {
    let problem = forced_problem(0.0);
    for options in [
        Options::until(1.0).tolerances(-1e-6, 1e-9),
        Options::until(1.0).tolerances(1e-16, 1e-9),
        Options::until(1.0).tolerances(1e-6, f64::NAN),
        Options::until(1.0).tolerances(0.0, 1e-301),
        Options::until(f64::NAN),
        Options::until(1.0).max_steps(0),
        Options::until(1.0).initial_step(f64::NAN),
        Options::until(1.0).max_step(-1.0),
        Options::until(1.0).output_times(vec![0.5, 2.0]),
        Options::until(1.0).output_times(vec![0.5, f64::NAN]),
        Options::until(1.0).controller(Controller::pi(0.2, 10.0, 0.5)),
        Options {
            rank_tolerance: 1.5,
            ..Options::until(1.0)
        },
        // Two bad options at once: the same one is named.
        Options::until(1.0)
            .tolerances(-1.0, 1e-9)
            .controller(Controller::pi(0.2, 10.0, 0.5)),
        Options::until(1.0).tolerances(0.0, 0.0).max_step(-1.0),
    ] {
        let theirs = solve(&problem, Dopri5::default(), &options).map(|_| ());
        let Err(expected) = theirs else {
            panic!("{options:?}: chetaev accepts it")
        };
        let ours = solve_with_ode_solvers(&problem, OdeSolversMethod::Dopri5, &options);
        match ours {
            // By their messages, which name the option, its value and the hint (a NaN value is
            // not equal to itself).
            Err(BackendError::Chetaev(e)) => {
                assert_eq!(e.to_string(), expected.to_string(), "{options:?}")
            }
            other => panic!("{options:?}: {other:?}, expected {expected:?}"),
        }
    }
}

/// A particle whose prescribed speed falls to zero at `t = 1`, `f = |q̇|² − (1 − t)²`: the gradient
/// `J = 2 q̇` vanishes there.
struct Braking;

impl Lagrangian<2> for Braking {
    fn lagrangian<R: Real>(&self, _t: R, _q: &SVector<R, 2>, qd: &SVector<R, 2>) -> R {
        qd.dot(qd) * 0.5
    }
}

impl Constraints<2, 1> for Braking {
    fn constraints<R: Real>(&self, t: R, _q: &SVector<R, 2>, qd: &SVector<R, 2>) -> SVector<R, 1> {
        let v = -t + 1.0;
        SVector::from([qd.dot(qd) - v * v])
    }
}

/// The singular-point check (`rank_tolerance`) is honoured: both integrators stop where `J`
/// passes through zero, at `t = 1`.
#[test]
fn the_singular_point_check_is_honoured() {
    let problem =
        Problem::new(Braking, 0.0, SVector::zeros(), SVector::from([1.0, 0.0])).expect("valid");
    let options = Options::until(2.0).tolerances(1e-10, 1e-10);
    let stop = |status: &Status| match status {
        Status::Failed(Error::SingularPoint {
            t,
            cause: chetaev::Singularity::Gradient(1),
            ..
        }) => *t,
        other => panic!("{other:?}"),
    };
    let sol = solve(&problem, Dopri5::default(), &options).expect("valid");
    let ours = solve_with_ode_solvers(&problem, OdeSolversMethod::Dopri5, &options).expect("valid");
    let theirs = stop(&sol.status);
    let t = stop(&ours.status);
    assert!(
        (t - 1.0).abs() < 1e-3 && (theirs - 1.0).abs() < 1e-3,
        "{t}, {theirs}"
    );
    // The motion before it is kept: the start, and the steps accepted before the one across it.
    assert!(
        ours.len() >= 2 && ours.t.iter().all(|&s| s < 1.0),
        "{:?}",
        ours.t
    );
    assert_eq!(ours.n(), 2);
}

#[test]
fn zero_interval_records_the_start() {
    let problem = forced_problem(0.5);
    for method in METHODS {
        for options in [
            Options::until(0.5).tolerances(1e-8, 1e-8),
            Options::until(0.5).tolerances(1e-8, 1e-8).output_final(),
        ] {
            let sol = solve_with_ode_solvers(&problem, method, &options).expect("valid");
            assert_eq!(sol.status, Status::Success);
            assert_eq!(sol.t, vec![0.5]);
            assert_eq!(sol.stats.rhs_evaluations, 0);
            assert_eq!(sol.stats.accepted_steps, 0);
        }
    }
}

#[test]
fn model_failure_is_the_status() {
    let problem = Problem::unconstrained(Expiring, 0.0, SVector::from([0.0]), SVector::from([0.0]))
        .expect("valid");
    for method in METHODS {
        for output in [Output::Steps, Output::Final] {
            let mut options = Options::until(3.0).tolerances(1e-10, 1e-10);
            options.output = output.clone();
            let sol = solve_with_ode_solvers(&problem, method, &options).expect("valid");
            let Status::Failed(Error::NonFiniteEvaluation { t, .. }) = sol.status else {
                panic!("{method:?} {output:?}: {:?}", sol.status);
            };
            assert!(t > 2.0, "{method:?}: {t}");
            assert_consistent_lengths(&sol);
            assert!(sol.len() > 1);
            // The motion up to the last accepted step, which ends before the failure.
            assert!(sol.t.iter().all(|&s| s < t && s <= 2.0), "{:?}", sol.t);
            if output == Output::Steps {
                assert_eq!(sol.stats.accepted_steps, sol.len() - 1);
            } else {
                assert_eq!(sol.len(), 2);
            }
            // No model evaluation after the failing one: the count is within the attempts counted.
            let (per_attempt, per_accepted) = evaluations_per_step(method);
            let steps = sol.stats.accepted_steps + sol.stats.rejected_steps;
            let bound = 3 + per_attempt * (steps + 1) + per_accepted * sol.stats.accepted_steps;
            assert!(
                sol.stats.rhs_evaluations <= bound,
                "{method:?}: {:?}",
                sol.stats
            );
        }
    }
}

#[test]
fn model_failure_keeps_the_output_times_before_it() {
    let problem = Problem::unconstrained(Expiring, 0.0, SVector::from([0.0]), SVector::from([0.0]))
        .expect("valid");
    let options = Options::until(3.0)
        .tolerances(1e-10, 1e-10)
        .output_times(vec![2.5, 0.5, 1.0]);
    let sol = solve_with_ode_solvers(&problem, OdeSolversMethod::Dopri5, &options).expect("valid");
    let Status::Failed(Error::NonFiniteEvaluation { t, .. }) = sol.status else {
        panic!("{:?}", sol.status);
    };
    assert!(t > 2.0, "{t}");
    assert_consistent_lengths(&sol);
    // The start, the times before the failure, and the last accepted state.
    assert_eq!(sol.len(), 4, "{:?}", sol.t);
    assert_eq!(sol.t[..3], [0.0, 0.5, 1.0]);
    assert!(sol.t[3] > 1.0 && sol.t[3] <= 2.0, "{:?}", sol.t);
    // ẋ = (2/3)(2^{3/2} − (2 − t)^{3/2}) from rest.
    for i in 0..sol.len() {
        let t = sol.t[i];
        let exact = 2.0 / 3.0 * (2f64.powf(1.5) - (2.0 - t).powf(1.5));
        // rtol = 1e-10 along a motion whose ẍ has a square-root singularity at t = 2.
        assert!(
            (sol.qd[i][0] - exact).abs() < 1e-8,
            "t = {t}: {}",
            sol.qd[i][0]
        );
    }
}

#[test]
fn statistics_count_every_evaluation() {
    let problem = forced_problem(0.0);
    for method in METHODS {
        let (per_attempt, per_accepted) = evaluations_per_step(method);
        for (options, startup) in [
            (Options::until(3.0).tolerances(1e-10, 1e-10), 3),
            (
                Options::until(3.0)
                    .tolerances(1e-10, 1e-10)
                    .initial_step(1e-3),
                1,
            ),
        ] {
            let sol = solve_with_ode_solvers(&problem, method, &options).expect("valid");
            assert_eq!(sol.status, Status::Success);
            let s = sol.stats;
            assert_eq!(
                s.rhs_evaluations,
                startup
                    + per_attempt * (s.accepted_steps + s.rejected_steps)
                    + per_accepted * s.accepted_steps,
                "{method:?}: {s:?}"
            );
            assert_eq!(s.accepted_steps, sol.len() - 1);
            assert_eq!(s.output_evaluations, sol.len());
            assert_eq!(s.jacobian_evaluations, 0);
        }
    }
}

#[test]
fn step_options_are_honoured() {
    let problem = forced_problem(0.0);
    for method in METHODS {
        // The first step is the one asked for.
        let options = Options::until(3.0)
            .tolerances(1e-8, 1e-8)
            .initial_step(-1e-3);
        let sol = solve_with_ode_solvers(&problem, method, &options).expect("valid");
        assert_eq!(sol.t[1], 1e-3, "{method:?}");

        // No step longer than the bound (up to rounding of t = t0 + τ).
        let options = Options::until(3.0).tolerances(1e-8, 1e-8).max_step(0.05);
        let sol = solve_with_ode_solvers(&problem, method, &options).expect("valid");
        assert!(sol.len() > 60, "{method:?}: {}", sol.len());
        assert!(
            sol.t
                .windows(2)
                .all(|w| w[1] - w[0] <= 0.05 * (1.0 + 1e-12)),
            "{method:?}"
        );

        // The step limit counts accepted and rejected attempts, as chetaev::solve does.
        let options = Options::until(3.0).tolerances(1e-12, 1e-12).max_steps(10);
        let sol = solve_with_ode_solvers(&problem, method, &options).expect("valid");
        let Status::Failed(Error::MaxSteps { t, max_steps, .. }) = sol.status else {
            panic!("{method:?}: {:?}", sol.status);
        };
        assert_eq!(max_steps, 10);
        assert_eq!(
            sol.stats.accepted_steps + sol.stats.rejected_steps,
            10,
            "{method:?}: {:?}",
            sol.stats
        );
        assert_eq!(*sol.t.last().expect("points"), t, "{method:?}");
    }
}

#[test]
fn a_user_controller_changes_the_steps() {
    let problem = forced_problem(0.0);
    let base = Options::until(3.0).tolerances(1e-10, 1e-10);
    for method in METHODS {
        let own = solve_with_ode_solvers(&problem, method, &base).expect("valid");
        let same = solve_with_ode_solvers(
            &problem,
            method,
            &base.clone().controller(method.controller()),
        )
        .expect("valid");
        assert_eq!(own.t, same.t, "{method:?}");
        // Steps that may grow only by 1.5 at a time.
        let slow = solve_with_ode_solvers(
            &problem,
            method,
            &base.clone().controller(Controller::i(0.2, 1.5)),
        )
        .expect("valid");
        assert_eq!(slow.status, Status::Success);
        assert_ne!(own.t, slow.t, "{method:?}");
        assert!(
            slow.t
                .windows(3)
                .all(|w| w[2] - w[1] <= 1.5 * (w[1] - w[0]) * (1.0 + 1e-9) || w[2] == 3.0),
            "{method:?}"
        );
        assert!(forced_error(&slow) < 1e-8);
    }
}

#[test]
fn final_output_records_the_start_and_the_end() {
    let problem = forced_problem(0.0);
    let options = Options::until(3.0).tolerances(1e-12, 1e-12).output_final();
    for method in METHODS {
        let sol = solve_with_ode_solvers(&problem, method, &options).expect("valid");
        assert_eq!(sol.status, Status::Success);
        assert_eq!(sol.t, vec![0.0, 3.0]);
        assert_consistent_lengths(&sol);
        assert!(forced_error(&sol) < 1e-9);
        assert!(max_abs(&sol.energy_balance()) < 1e-9);
        assert!(sol.stats.accepted_steps > 1);
        assert_eq!(sol.stats.output_evaluations, 2);
    }
}

#[test]
fn dopri5_records_at_given_times() {
    // Forward and backward; times unordered, repeated, at the ends.
    for (t0, t_end, times) in [
        (0.0, 3.0, vec![2.5, 0.0, 1.0, 1.0, 0.1, 3.0]),
        (1.0, -2.0, vec![-1.5, 0.5, 1.0, -2.0]),
    ] {
        let problem = forced_problem(t0);
        let options = Options::until(t_end)
            .tolerances(1e-12, 1e-12)
            .output_times(times.clone());
        let sol =
            solve_with_ode_solvers(&problem, OdeSolversMethod::Dopri5, &options).expect("valid");
        assert_eq!(sol.status, Status::Success);
        assert_consistent_lengths(&sol);
        // The start, the interior times in order, the end.
        let dir = (t_end - t0).signum();
        let mut inner: Vec<f64> = times
            .iter()
            .copied()
            .filter(|&s| dir * (s - t0) > 0.0 && dir * (s - t_end) < 0.0)
            .collect();
        inner.sort_by(|a, b| (dir * a).total_cmp(&(dir * b)));
        let mut expected = vec![t0];
        expected.extend(inner);
        expected.push(t_end);
        assert_eq!(sol.t, expected);
        // Dense output of order 4 between steps of a 5th-order method at rtol = 1e-12.
        let err = forced_error(&sol);
        assert!(err < 1e-9, "{t0} → {t_end}: {err:e}");
        assert!(max_abs(&sol.energy_balance()) < 1e-9);
    }
}

#[test]
fn every_record_level_is_honoured() {
    let p = Params::PAPER;
    let problem = uniform_problem(&p).expect("consistent");
    for method in METHODS {
        for record in [Record::State, Record::Dynamics, Record::Energy] {
            let options = Options::until(1.0).tolerances(1e-12, 1e-12).record(record);
            let sol = solve_with_ode_solvers(&problem, method, &options).expect("valid");
            assert_eq!(sol.status, Status::Success);
            assert_eq!(sol.record, record);
            assert_consistent_lengths(&sol);
            assert!(uniform_error(&p, &sol) < 1e-9, "{method:?} {record:?}");
            let evaluations = if record >= Record::Dynamics {
                sol.len()
            } else {
                0
            };
            assert_eq!(sol.stats.output_evaluations, evaluations);
        }
    }
}

/// Asserts that the error names the option and sends to chetaev's own driver.
fn assert_refused(r: Result<Solution, BackendError>, expected: fn(&BackendError) -> bool) {
    let e = r.expect_err("refused");
    assert!(expected(&e), "{e:?}");
    assert!(e.to_string().contains("chetaev::solve"), "{e}");
}

#[test]
fn events_are_refused() {
    let problem = forced_problem(0.0);
    let options = Options::until(3.0).event(Event::new("x = 1", |_t, q, _qd| q[0] - 1.0));
    for method in METHODS {
        assert_refused(solve_with_ode_solvers(&problem, method, &options), |e| {
            matches!(e, BackendError::Events { count: 1 })
        });
    }
}

#[test]
fn projection_is_refused() {
    let problem = uniform_problem(&Params::PAPER).expect("consistent");
    let options = Options::until(1.0).project(Projection::default());
    for method in METHODS {
        assert_refused(solve_with_ode_solvers(&problem, method, &options), |e| {
            matches!(e, BackendError::Projection)
        });
    }
}

#[test]
fn sensitivities_are_refused() {
    let problem = uniform_problem(&Params::PAPER).expect("consistent");
    let options = Options::until(1.0).sensitivity(Seed::new("h0").with_position(1, 1.0));
    for method in METHODS {
        assert_refused(solve_with_ode_solvers(&problem, method, &options), |e| {
            matches!(e, BackendError::Sensitivities { count: 1 })
        });
    }
}

#[test]
fn per_component_tolerances_are_refused() {
    let problem = forced_problem(0.0);
    let options = Options::until(1.0).atol_per_component(&[1e-9], &[1e-9]);
    for method in METHODS {
        assert_refused(solve_with_ode_solvers(&problem, method, &options), |e| {
            matches!(e, BackendError::PerComponentAtol)
        });
    }
}

#[test]
fn zero_absolute_tolerance_is_refused() {
    let problem = forced_problem(0.0);
    let options = Options::until(1.0).tolerances(1e-8, 0.0);
    for method in METHODS {
        assert_refused(solve_with_ode_solvers(&problem, method, &options), |e| {
            matches!(e, BackendError::ZeroAtol)
        });
    }
}

#[test]
fn output_times_are_refused_by_dop853() {
    let problem = forced_problem(0.0);
    let options = Options::until(1.0).output_grid(0.0, 11);
    assert_refused(
        solve_with_ode_solvers(&problem, OdeSolversMethod::Dop853, &options),
        |e| matches!(e, BackendError::OutputTimes),
    );
}

#[test]
fn a_pi_controller_is_refused_by_dop853() {
    let problem = forced_problem(0.0);
    let options = Options::until(1.0).controller(Controller::pi(0.2, 10.0, 0.04));
    assert_refused(
        solve_with_ode_solvers(&problem, OdeSolversMethod::Dop853, &options),
        |e| matches!(e, BackendError::Controller { beta } if *beta == 0.04),
    );
    // Dopri5 runs the same PI formula.
    let sol = solve_with_ode_solvers(&problem, OdeSolversMethod::Dopri5, &options).expect("valid");
    assert_eq!(sol.status, Status::Success);
}

#[test]
fn a_step_limit_beyond_u32_is_refused() {
    let Some(max_steps) = (u32::MAX as usize).checked_add(1) else {
        return;
    };
    let problem = forced_problem(0.0);
    let options = Options::until(1.0).max_steps(max_steps);
    for method in METHODS {
        assert_refused(solve_with_ode_solvers(&problem, method, &options), |e| {
            matches!(e, BackendError::MaxSteps { .. })
        });
    }
}

/// `ẍ = −ẋ` from `t = 1` on (a drag that begins later: no force at the start), `ẋ0 = 1`.
struct LateDrag;
impl Lagrangian<1> for LateDrag {
    fn lagrangian<R: Real>(&self, _t: R, _q: &SVector<R, 1>, qd: &SVector<R, 1>) -> R {
        qd[0] * qd[0] * 0.5
    }
    fn forces<R: Real>(
        &self,
        t: R,
        _q: &SVector<R, 1>,
        qd: &SVector<R, 1>,
    ) -> Option<SVector<R, 1>> {
        (t.re() >= 1.0).then(|| SVector::from([-qd[0]]))
    }
}

#[test]
fn the_work_of_forces_that_begin_later_is_in_the_balance() {
    let problem =
        Problem::unconstrained(LateDrag, 0.0, [0.0].into(), [1.0].into()).expect("consistent");
    for method in METHODS {
        let options = Options::until(3.0).tolerances(1e-12, 1e-12).max_step(0.25);
        let sol = solve_with_ode_solvers(&problem, method, &options).expect("valid");
        assert_eq!(sol.status, Status::Success);
        // ẋ(3) = e^(−2); W_Q = E(3) − E(0) = ½(e^(−4) − 1).
        let (_, _, qd) = sol.last().expect("points");
        assert!(
            (qd[0] - (-2f64).exp()).abs() < 1e-8,
            "{method:?}: {}",
            qd[0]
        );
        let w = *sol.work_forces.last().expect("recorded");
        assert!(
            (w - 0.5 * ((-4f64).exp() - 1.0)).abs() < 1e-8,
            "{method:?}: W_Q = {w}"
        );
        assert!(max_abs(&sol.energy_balance()) < 1e-8, "{method:?}");
    }
}
