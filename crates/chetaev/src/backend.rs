//! The integrators of the crate `ode_solvers` (0.6.2) as an alternative backend, and an
//! independent cross-check of the crate's own integrators.
//!
//! `ode_solvers` is wrapped so that none of its known faults can reach a result:
//!
//! - its `Dop853` evaluates two stages at the node `c = 0` instead of `c = 1`, which is wrong
//!   whenever the right-hand side reads the time it is given. The wrapper hands it an autonomous
//!   system: time is an extra state component `s` with `s' = 1`, so every stage reads its time from
//!   the stage state, whose node is the row sum of the Runge–Kutta matrix, never from the argument
//!   `ode_solvers` passes;
//! - its dense output fails when integrating backward or over an interval that starts below zero.
//!   The wrapper always integrates forward in `τ ∈ [0, |t_end − t0|]` with `t = t0 + dir·τ`,
//!   `dir = sign(t_end − t0)`, and asks only for the solution at the accepted steps;
//! - its `Rk4` overshoots the end when the step does not divide the interval; it is not offered;
//! - it has no root finding and its step callback sees the state read-only, so this backend offers
//!   neither events nor projection (use [`solve`](crate::solve) for those).
//!
//! `ode_solvers` controls the error of every component with one scalar `atol`: here that includes
//! the time `s` (integrated exactly, so its error is zero) and the two energy quadratures.

use std::cell::{Cell, RefCell};

use ode_solvers::dop_shared::{IntegrationError, System};
use ode_solvers::{DVector, OutputType};

use crate::error::Error;
use crate::integrate::options::Record;
use crate::integrate::system::{split, ChetaevOde, OdeSystem, Stats};
use crate::model::Model;
use crate::problem::{check_finite, Problem};
use crate::solution::{Solution, Status};

/// The step limit `ode_solvers` applies (its default; accepted plus rejected steps).
pub const ODE_SOLVERS_MAX_STEPS: usize = 100_000;

/// Which ode_solvers method.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OdeSolversMethod {
    /// Dormand–Prince 5(4), `ode_solvers::Dopri5`.
    Dopri5,
    /// Dormand–Prince 8(5,3), `ode_solvers::Dop853`.
    Dop853,
}

impl OdeSolversMethod {
    /// The name recorded in [`Solution::method`].
    pub fn name(self) -> &'static str {
        match self {
            Self::Dopri5 => "Dopri5 (ode_solvers)",
            Self::Dop853 => "Dop853 (ode_solvers)",
        }
    }

    /// The `h·|λ|` above which `ode_solvers` counts a step as stiff. It reports no estimate of its
    /// own, so a stiffness failure carries this bound.
    fn stiffness_threshold(self) -> f64 {
        match self {
            Self::Dopri5 => 3.25,
            Self::Dop853 => 6.1,
        }
    }

    /// Right-hand sides per step attempt, and extra ones per accepted step (without dense output).
    fn evaluations_per_step(self) -> (usize, usize) {
        match self {
            Self::Dopri5 => (6, 0),
            Self::Dop853 => (11, 1),
        }
    }
}

/// Right-hand sides `ode_solvers` evaluates before its first step: two for the initial step size,
/// one at the start.
const STARTUP_EVALUATIONS: usize = 3;

/// Integrates `problem` from its start to `t_end` with the `ode_solvers` method `method` at the
/// scalar tolerances `rtol`, `atol`, and returns the motion as a [`Solution`], recorded at the start
/// and at every step `ode_solvers` accepts (the last one lands on `t_end` exactly).
///
/// A failure reported by `ode_solvers` becomes the [`Status::Failed`] of the solution, with the
/// crate's error: its step limit is [`Error::MaxSteps`], its step size underflow
/// [`Error::StepSizeTooSmall`] (with the bound `10·ε·|t − t0|` below which it gives up, as it does
/// not report the step), its stiffness detection [`Error::Stiff`] (suggesting `"Rodas4"`, with the
/// threshold on `h·|λ|` it exceeded, as it reports no estimate). The statistics count the
/// right-hand sides and output evaluations made by the wrapper, and take the accepted and rejected
/// steps from `ode_solvers`.
///
/// Everything is recorded at the [`Record::Energy`] level: `q̈`, `μ`, `Φ`, `f` and `E` at each
/// point, and the quadratures `W_Φ` and `∫∂L/∂t dt`, carried as state components.
///
/// Bad input (a non-finite `t_end`, tolerances that are not finite and positive, `rtol` below
/// 100 ulps) is an `Err`. A failure of the model during the integration (a singular block system,
/// a non-finite evaluation) ends it: the status is that error and the solution holds the points
/// before it. The step limit is [`ODE_SOLVERS_MAX_STEPS`]. When the integration fails the step
/// counts are those seen by the wrapper: the recorded steps as accepted, the other completed
/// attempts as rejected.
///
/// ```
/// use chetaev::backend::{solve_with_ode_solvers, OdeSolversMethod};
/// use chetaev::prelude::*;
///
/// /// `L = ½ẋ² + x sin t`: `ẍ = sin t`.
/// struct Forced;
/// impl Lagrangian<1> for Forced {
///     fn lagrangian<R: Real>(&self, t: R, q: &SVector<R, 1>, qd: &SVector<R, 1>) -> R {
///         qd[0] * qd[0] * 0.5 + q[0] * t.sin()
///     }
/// }
///
/// let problem = Problem::unconstrained(Forced, 0.0, SVector::from([0.0]), SVector::from([0.0]))?;
/// let sol = solve_with_ode_solvers(&problem, OdeSolversMethod::Dop853, 3.0, 1e-12, 1e-12)?;
/// let (t, q, _) = sol.last().unwrap();
/// assert_eq!(t, 3.0);
/// assert!((q[0] - (3.0 - 3.0f64.sin())).abs() < 1e-9);
/// # Ok::<(), chetaev::Error>(())
/// ```
pub fn solve_with_ode_solvers<M: Model<N, K>, const N: usize, const K: usize>(
    problem: &Problem<M, N, K>,
    method: OdeSolversMethod,
    t_end: f64,
    rtol: f64,
    atol: f64,
) -> Result<Solution<N, K>, Error> {
    validate(t_end, rtol, atol)?;
    let t0 = problem.t0();
    let tau_end = (t_end - t0).abs();
    check_finite("|t_end − t0|", std::slice::from_ref(&tau_end))?;
    let dir = if t_end >= t0 { 1.0 } else { -1.0 };

    let mut adapter = Adapter {
        ode: RefCell::new(ChetaevOde::new(problem.model(), true)),
        failure: RefCell::new(None),
        callbacks: Cell::new(0),
        sol: Solution::new(method.name(), Record::Energy),
        t0,
        t_end,
        dir,
        tau_end,
        recorded_steps: 0,
    };
    let dim = adapter.dim();
    let mut z0 = DVector::<f64>::zeros(dim);
    z0.as_mut_slice()[..N].copy_from_slice(problem.q0().as_slice());
    z0.as_mut_slice()[N..2 * N].copy_from_slice(problem.qd0().as_slice());

    if let Err(e) = adapter.record(t0, z0.as_slice()) {
        return Ok(adapter.finish(Status::Failed(e), None));
    }
    if tau_end == 0.0 {
        return Ok(adapter.finish(Status::Success, None));
    }

    let callback = Callback(&mut adapter);
    let outcome = match method {
        OdeSolversMethod::Dopri5 => {
            let mut stepper =
                ode_solvers::Dopri5::new(callback, 0.0, tau_end, tau_end, z0, rtol, atol);
            stepper.set_output(OutputType::Sparse);
            stepper.integrate()
        }
        OdeSolversMethod::Dop853 => {
            let mut stepper =
                ode_solvers::Dop853::new(callback, 0.0, tau_end, tau_end, z0, rtol, atol);
            stepper.set_output(OutputType::Sparse);
            stepper.integrate()
        }
    };

    let (per_attempt, per_accepted) = method.evaluations_per_step();
    let attempts = |callbacks: usize, accepted: usize| {
        callbacks.saturating_sub(STARTUP_EVALUATIONS + per_accepted * accepted) / per_attempt
    };
    let failure = adapter.failure.get_mut().take();
    let recorded = adapter.recorded_steps;
    Ok(match (failure, outcome) {
        (Some(f), _) => {
            // Every attempt after the failing evaluation sees NaN and is rejected; the steps
            // counted are the ones completed before it.
            let t_fail = t0 + dir * f.tau;
            let keep = adapter
                .sol
                .t
                .iter()
                .take_while(|&&t| dir * (t - t_fail) < 0.0)
                .count();
            truncate(&mut adapter.sol, keep);
            let accepted = keep.saturating_sub(1);
            let rejected = attempts(f.callbacks, accepted).saturating_sub(accepted);
            adapter.finish(Status::Failed(f.error), Some((accepted, rejected)))
        }
        (None, Ok(stats)) => adapter.finish(
            Status::Success,
            Some((stats.accepted_steps as usize, stats.rejected_steps as usize)),
        ),
        (None, Err(e)) => {
            // A stiffness failure is raised after its step was accepted, before it is delivered.
            let undelivered = usize::from(matches!(e, IntegrationError::StiffnessDetected { .. }));
            let total = attempts(adapter.callbacks.get(), recorded + undelivered);
            let rejected = total.saturating_sub(recorded + undelivered);
            let error = map_error(&e, method, t0, dir);
            adapter.finish(Status::Failed(error), Some((recorded, rejected)))
        }
    })
}

/// Checks the inputs as [`solve`](crate::solve) does; `ode_solvers` also needs `atol > 0` because
/// the extra components start at zero.
fn validate(t_end: f64, rtol: f64, atol: f64) -> Result<(), Error> {
    check_finite("t_end", std::slice::from_ref(&t_end))?;
    if !(rtol.is_finite() && rtol > 0.0) {
        return Err(Error::InvalidOption {
            name: "rtol",
            value: rtol,
            hint: "the relative tolerance must be finite and positive; 1e-6 to 1e-13 are typical",
        });
    }
    if rtol < 100.0 * f64::EPSILON {
        return Err(Error::InvalidOption {
            name: "rtol",
            value: rtol,
            hint: "below 100 ulps (2.2e-14) no step size can meet the tolerance in f64; use 1e-13 or more",
        });
    }
    if !(atol.is_finite() && atol > 0.0) {
        return Err(Error::InvalidOption {
            name: "atol",
            value: atol,
            hint: "the absolute tolerance must be finite and positive (ode_solvers applies it to every component)",
        });
    }
    Ok(())
}

/// Translates a failure reported by `ode_solvers` at its time `τ` into the crate's error.
fn map_error(e: &IntegrationError, method: OdeSolversMethod, t0: f64, dir: f64) -> Error {
    let t_of = |tau: f64| t0 + dir * tau;
    match *e {
        IntegrationError::MaxNumStepReached { x, .. } => Error::MaxSteps {
            t: t_of(x),
            max_steps: ODE_SOLVERS_MAX_STEPS,
        },
        // ode_solvers gives up when `0.1·|h| ≤ ε·|τ|`; it does not report `h`, so the bound is given.
        IntegrationError::StepSizeUnderflow { x } => Error::StepSizeTooSmall {
            t: t_of(x),
            h: dir * 10.0 * f64::EPSILON * x.abs(),
        },
        IntegrationError::StiffnessDetected { x } => Error::Stiff {
            t: t_of(x),
            h_lambda: method.stiffness_threshold(),
            suggestion: "Rodas4",
        },
    }
}

/// Shortens every recorded vector to `len` points.
fn truncate<const N: usize, const K: usize>(sol: &mut Solution<N, K>, len: usize) {
    sol.t.truncate(len);
    sol.q.truncate(len);
    sol.qd.truncate(len);
    sol.qdd.truncate(len);
    sol.mu.truncate(len);
    sol.phi.truncate(len);
    sol.residual.truncate(len);
    sol.energy.truncate(len);
    sol.work.truncate(len);
    sol.dl_dt_integral.truncate(len);
}

/// The first model failure inside the right-hand side.
struct Failure {
    /// `τ` of the failing evaluation.
    tau: f64,
    error: Error,
    /// Callbacks made up to and including the failing one.
    callbacks: usize,
}

/// The Chetaev equations in the form `ode_solvers` integrates, and the solution being recorded.
///
/// State `z = [q (N), q̇ (N), W_Φ, ∫∂L/∂t dt, s]` with `t = t0 + dir·s` and derivative
/// `dz/dτ = dir·[q̇, q̈, q̇·Φ, ∂L/∂t], 1`.
struct Adapter<'a, M, const N: usize, const K: usize> {
    ode: RefCell<ChetaevOde<'a, M, N, K>>,
    failure: RefCell<Option<Failure>>,
    callbacks: Cell<usize>,
    sol: Solution<N, K>,
    t0: f64,
    t_end: f64,
    dir: f64,
    tau_end: f64,
    recorded_steps: usize,
}

impl<M: Model<N, K>, const N: usize, const K: usize> Adapter<'_, M, N, K> {
    /// Length of `z`.
    fn dim(&self) -> usize {
        2 * N + 3
    }

    /// Index of `s` in `z`.
    fn time_index(&self) -> usize {
        2 * N + 2
    }

    /// The real time of `ode_solvers`' output time `τ`; the end is hit exactly.
    fn time(&self, tau: f64) -> f64 {
        if (self.tau_end - tau).abs() <= 4.0 * f64::EPSILON * self.tau_end {
            self.t_end
        } else {
            self.t0 + self.dir * tau
        }
    }

    /// `dz/dτ`; after a model failure every component is NaN, which makes `ode_solvers` reject
    /// each further step until it stops.
    fn derivative(&self, z: &[f64], dz: &mut [f64]) {
        self.callbacks.set(self.callbacks.get() + 1);
        if self.failure.borrow().is_some() {
            dz.fill(f64::NAN);
            return;
        }
        let s = z[self.time_index()];
        let t = self.t0 + self.dir * s;
        let m = self.time_index();
        let result = self.ode.borrow_mut().rhs(t, &z[..m], &mut dz[..m]);
        match result {
            Ok(()) => {
                for v in &mut dz[..m] {
                    *v *= self.dir;
                }
                dz[m] = 1.0;
            }
            Err(error) => {
                *self.failure.borrow_mut() = Some(Failure {
                    tau: s,
                    error,
                    callbacks: self.callbacks.get(),
                });
                dz.fill(f64::NAN);
            }
        }
    }

    /// Records `(t, z)` with everything of [`Record::Energy`]; nothing is pushed if the evaluation
    /// fails, so the recorded vectors stay of equal length.
    fn record(&mut self, t: f64, z: &[f64]) -> Result<(), Error> {
        let (q, qd) = split::<N>(z);
        let d = self.ode.get_mut().evaluate(t, &q, &qd)?;
        let sol = &mut self.sol;
        sol.t.push(t);
        sol.q.push(q);
        sol.qd.push(qd);
        sol.qdd.push(d.qdd);
        sol.mu.push(d.mu);
        sol.phi.push(d.phi);
        sol.residual.push(d.f);
        sol.energy.push(d.energy);
        sol.work.push(z[2 * N]);
        sol.dl_dt_integral.push(z[2 * N + 1]);
        Ok(())
    }

    /// The solution with its status and statistics; `steps` are `(accepted, rejected)`.
    fn finish(self, status: Status, steps: Option<(usize, usize)>) -> Solution<N, K> {
        let stats = self.ode.into_inner().stats;
        let (accepted_steps, rejected_steps) = steps.unwrap_or((0, 0));
        let mut sol = self.sol;
        sol.stats = Stats {
            accepted_steps,
            rejected_steps,
            ..stats
        };
        sol.status = status;
        sol
    }
}

/// What `ode_solvers` holds: it keeps the system it is given, so the adapter is lent.
struct Callback<'r, 'a, M, const N: usize, const K: usize>(&'r mut Adapter<'a, M, N, K>);

impl<M: Model<N, K>, const N: usize, const K: usize> System<f64, DVector<f64>>
    for Callback<'_, '_, M, N, K>
{
    /// The time `ode_solvers` passes is not read: it is wrong at two stages of its `Dop853`.
    fn system(&self, _tau: f64, z: &DVector<f64>, dz: &mut DVector<f64>) {
        self.0.derivative(z.as_slice(), dz.as_mut_slice());
    }

    /// Records each accepted step; stops `ode_solvers` when the model fails at it.
    fn solout(&mut self, tau: f64, z: &DVector<f64>, _dz: &DVector<f64>) -> bool {
        let adapter = &mut *self.0;
        if adapter.failure.get_mut().is_some() {
            return true;
        }
        let t = adapter.time(tau);
        match adapter.record(t, z.as_slice()) {
            Ok(()) => {
                adapter.recorded_steps += 1;
                false
            }
            Err(error) => {
                let callbacks = adapter.callbacks.get();
                *adapter.failure.get_mut() = Some(Failure {
                    tau,
                    error,
                    callbacks,
                });
                true
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{Constraints, Lagrangian, Real};
    use nalgebra::SVector;

    /// A particle in gravity held at constant speed `v0`.
    struct Uniform {
        g: f64,
        v0: f64,
    }
    impl Lagrangian<2> for Uniform {
        fn lagrangian<R: Real>(&self, _t: R, q: &SVector<R, 2>, qd: &SVector<R, 2>) -> R {
            qd.dot(qd) * 0.5 - q[1] * self.g
        }
    }
    impl Constraints<2, 1> for Uniform {
        fn constraints<R: Real>(
            &self,
            _t: R,
            _q: &SVector<R, 2>,
            qd: &SVector<R, 2>,
        ) -> SVector<R, 1> {
            SVector::from([qd.dot(qd) - self.v0 * self.v0])
        }
    }

    /// `L = ½ẋ² + x sin t`: `ẍ = sin t`, so `x = t − sin t` from rest at the origin.
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

    const METHODS: [OdeSolversMethod; 2] = [OdeSolversMethod::Dopri5, OdeSolversMethod::Dop853];

    fn forced_problem(t0: f64) -> Problem<crate::model::Unconstrained<Forced>, 1, 0> {
        let q0 = SVector::from([t0 - t0.sin()]);
        let qd0 = SVector::from([1.0 - t0.cos()]);
        Problem::unconstrained(Forced, t0, q0, qd0).expect("consistent")
    }

    /// Largest deviation of `x` and `ẋ` from `t − sin t`, `1 − cos t` over the recorded points.
    fn forced_error(sol: &Solution<1, 0>) -> f64 {
        (0..sol.len())
            .map(|i| {
                let t = sol.t[i];
                let ex = (sol.q[i][0] - (t - t.sin())).abs();
                let ev = (sol.qd[i][0] - (1.0 - t.cos())).abs();
                ex.max(ev)
            })
            .fold(0.0, f64::max)
    }

    fn assert_consistent_lengths<const N: usize, const K: usize>(sol: &Solution<N, K>) {
        let n = sol.len();
        for len in [
            sol.q.len(),
            sol.qd.len(),
            sol.qdd.len(),
            sol.mu.len(),
            sol.phi.len(),
            sol.residual.len(),
            sol.energy.len(),
            sol.work.len(),
            sol.dl_dt_integral.len(),
        ] {
            assert_eq!(len, n);
        }
    }

    #[test]
    fn backend_uniform_projectile_matches_closed_form() {
        let (g, v0, h0) = (10.0, 10.0, 5.0);
        let problem = Problem::new(
            Uniform { g, v0 },
            0.0,
            SVector::from([0.0, h0]),
            SVector::from([v0, 0.0]),
        )
        .expect("consistent");
        for method in METHODS {
            let sol = solve_with_ode_solvers(&problem, method, 1.0, 1e-12, 1e-12).expect("valid");
            assert_eq!(sol.status, Status::Success, "{method:?}");
            assert_consistent_lengths(&sol);
            assert_eq!(sol.t[0], 0.0);
            assert_eq!(*sol.t.last().expect("points"), 1.0);
            let mut err = 0.0f64;
            for i in 0..sol.len() {
                let u = g * sol.t[i] / v0;
                let x = v0 * v0 / g * u.sinh().atan();
                let y = h0 - v0 * v0 / g * u.cosh().ln();
                let xd = v0 / u.cosh();
                let yd = -v0 * u.tanh();
                for e in [
                    sol.q[i][0] - x,
                    sol.q[i][1] - y,
                    sol.qd[i][0] - xd,
                    sol.qd[i][1] - yd,
                ] {
                    err = err.max(e.abs());
                }
            }
            let balance = sol
                .energy_balance()
                .iter()
                .fold(0.0f64, |a, b| a.max(b.abs()));
            println!(
                "uniform projectile {method:?}: max error {err:.3e}, energy balance {balance:.3e}, \
                 residual {:.3e}, {} points, {:?}",
                sol.max_residual(),
                sol.len(),
                sol.stats
            );
            assert!(err < 1e-9, "{method:?}: {err:e}");
            assert!(balance < 1e-9, "{method:?}: {balance:e}");
            assert_eq!(sol.stats.accepted_steps, sol.len() - 1);
            assert!(sol.stats.rhs_evaluations > 0);
            assert_eq!(sol.stats.output_evaluations, sol.len());
        }
    }

    #[test]
    fn backend_dop853_explicit_time_dependence() {
        let problem = forced_problem(0.0);
        for method in METHODS {
            let sol = solve_with_ode_solvers(&problem, method, 3.0, 1e-12, 1e-12).expect("valid");
            assert_eq!(sol.status, Status::Success);
            assert_eq!(*sol.t.last().expect("points"), 3.0);
            let err = forced_error(&sol);
            // ∂L/∂t = x cos t; its integral and E = ½ẋ² − x sin t balance with W_Φ = 0.
            let balance = sol
                .energy_balance()
                .iter()
                .fold(0.0f64, |a, b| a.max(b.abs()));
            println!(
                "forced, forward {method:?}: max error {err:.3e}, energy balance {balance:.3e}, {} points",
                sol.len()
            );
            assert!(err < 1e-9, "{method:?}: {err:e}");
            assert!(balance < 1e-9, "{method:?}: {balance:e}");
        }
    }

    #[test]
    fn backend_backward_integration() {
        let problem = forced_problem(1.0);
        for method in METHODS {
            let sol = solve_with_ode_solvers(&problem, method, -2.0, 1e-12, 1e-12).expect("valid");
            assert_eq!(sol.status, Status::Success);
            assert_consistent_lengths(&sol);
            assert_eq!(sol.t[0], 1.0);
            assert_eq!(*sol.t.last().expect("points"), -2.0);
            assert!(sol.t.windows(2).all(|w| w[1] < w[0]));
            let err = forced_error(&sol);
            println!(
                "forced, backward 1 → −2 {method:?}: max error {err:.3e}, {} points",
                sol.len()
            );
            assert!(err < 1e-9, "{method:?}: {err:e}");
            // ∫_1^{-2} ∂L/∂t dt = ∫ x cos t dt, checked through the energy balance.
            let balance = sol
                .energy_balance()
                .iter()
                .fold(0.0f64, |a, b| a.max(b.abs()));
            assert!(balance < 1e-9, "{method:?}: {balance:e}");
        }
    }

    #[test]
    fn backend_rejects_bad_input() {
        let problem = forced_problem(0.0);
        let m = OdeSolversMethod::Dopri5;
        for (rtol, atol) in [
            (0.0, 1e-9),
            (-1e-6, 1e-9),
            (f64::NAN, 1e-9),
            (1e-16, 1e-9),
            (1e-6, 0.0),
            (1e-6, f64::INFINITY),
        ] {
            let r = solve_with_ode_solvers(&problem, m, 1.0, rtol, atol);
            assert!(
                matches!(r, Err(Error::InvalidOption { .. })),
                "{rtol} {atol}: {r:?}"
            );
        }
        let r = solve_with_ode_solvers(&problem, m, f64::NAN, 1e-6, 1e-9);
        assert!(matches!(r, Err(Error::NonFiniteInput { .. })), "{r:?}");
        let r = solve_with_ode_solvers(&problem, m, f64::INFINITY, 1e-6, 1e-9);
        assert!(matches!(r, Err(Error::NonFiniteInput { .. })), "{r:?}");
    }

    #[test]
    fn backend_zero_interval_records_the_start() {
        let problem = forced_problem(0.5);
        let sol = solve_with_ode_solvers(&problem, OdeSolversMethod::Dop853, 0.5, 1e-8, 1e-8)
            .expect("valid");
        assert_eq!(sol.status, Status::Success);
        assert_eq!(sol.t, vec![0.5]);
        assert_eq!(sol.stats.rhs_evaluations, 0);
    }

    #[test]
    fn backend_model_failure_is_the_status() {
        let problem =
            Problem::unconstrained(Expiring, 0.0, SVector::from([0.0]), SVector::from([0.0]))
                .expect("valid");
        for method in METHODS {
            let sol = solve_with_ode_solvers(&problem, method, 3.0, 1e-10, 1e-10).expect("valid");
            let Status::Failed(Error::NonFiniteEvaluation { t, .. }) = sol.status else {
                panic!("{method:?}: {:?}", sol.status);
            };
            assert!(t > 2.0, "{method:?}: {t}");
            assert_consistent_lengths(&sol);
            assert!(sol.len() > 1);
            assert!(sol.t.iter().all(|&s| s < t && s <= 2.0));
            assert_eq!(sol.stats.accepted_steps, sol.len() - 1);
            // No model evaluation after the failing one: the count is within the attempts counted.
            let (per_attempt, per_accepted) = method.evaluations_per_step();
            let steps = sol.stats.accepted_steps + sol.stats.rejected_steps;
            let bound = STARTUP_EVALUATIONS
                + per_attempt * (steps + 1)
                + per_accepted * sol.stats.accepted_steps;
            assert!(
                sol.stats.rhs_evaluations <= bound,
                "{method:?}: {:?}",
                sol.stats
            );
            println!(
                "expiring {method:?}: failed at t = {t}, last point {:?}, {:?}",
                sol.t.last(),
                sol.stats
            );
        }
    }

    #[test]
    fn backend_maps_ode_solvers_errors() {
        let e = map_error(
            &IntegrationError::MaxNumStepReached {
                x: 2.0,
                n_step: 100_000,
            },
            OdeSolversMethod::Dopri5,
            1.0,
            -1.0,
        );
        assert_eq!(
            e,
            Error::MaxSteps {
                t: -1.0,
                max_steps: ODE_SOLVERS_MAX_STEPS
            }
        );
        let e = map_error(
            &IntegrationError::StepSizeUnderflow { x: 0.5 },
            OdeSolversMethod::Dop853,
            0.0,
            1.0,
        );
        assert!(matches!(e, Error::StepSizeTooSmall { t, h } if t == 0.5 && h > 0.0));
        let e = map_error(
            &IntegrationError::StiffnessDetected { x: 0.25 },
            OdeSolversMethod::Dop853,
            0.0,
            1.0,
        );
        assert_eq!(
            e,
            Error::Stiff {
                t: 0.25,
                h_lambda: 6.1,
                suggestion: "Rodas4"
            }
        );
    }
}
