//! # chetaev-ode-solvers
//!
//! The integrators `Dopri5` and `Dop853` of the crate `ode_solvers` (0.6.2) run on chetaev's
//! reduced Chetaev equations: a second, independent integration of any [`chetaev::Problem`],
//! recorded as a [`chetaev::Solution`] like the one [`chetaev::solve`] returns, to cross-check
//! chetaev's own integrators.
//!
//! ```
//! use chetaev::prelude::*;
//! use chetaev_ode_solvers::{solve_with_ode_solvers, OdeSolversMethod};
//!
//! /// `L = ½ẋ² + x sin t`: `ẍ = sin t`, so `x = t − sin t` from rest at the origin.
//! struct Forced;
//! impl Lagrangian<1> for Forced {
//!     fn lagrangian<R: Real>(&self, t: R, q: &SVector<R, 1>, qd: &SVector<R, 1>) -> R {
//!         qd[0] * qd[0] * 0.5 + q[0] * t.sin()
//!     }
//! }
//!
//! let problem = Problem::unconstrained(Forced, 0.0, SVector::from([0.0]), SVector::from([0.0]))?;
//! let options = Options::until(3.0).tolerances(1e-12, 1e-12);
//! let theirs = solve_with_ode_solvers(&problem, OdeSolversMethod::Dop853, &options)?.ok()?;
//! let ours = solve(&problem, Dop853::default(), &options)?.ok()?;
//! let (t, q, _) = theirs.last().expect("recorded");
//! assert_eq!(t, 3.0);
//! assert!((q[0] - (3.0 - 3.0f64.sin())).abs() < 1e-9);
//! assert!((q[0] - ours.q.last().expect("recorded")[0]).abs() < 1e-9);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! ## A cross-check with its own loop, not a `Method`
//!
//! chetaev's methods implement [`chetaev::integrate::Method`]: a stepper that takes one trial step
//! and estimates its error, while chetaev's driver owns step control, output, events and
//! projection. `ode_solvers` offers no single step: its `integrate` runs its own loop from the start
//! to the end, with its own initial step, step-size control, stiffness test and output. It cannot
//! be a `Method`; it is a second driver around the same equations
//! ([`ReducedOde`]) and the same recording
//! ([`Solution::record`](chetaev::Solution::record), which checks that every recorded quantity is
//! finite and evaluates the diagnostics). Nothing of chetaev's step loop is shared, which is what
//! makes it a cross-check.
//!
//! ## Options
//!
//! [`solve_with_ode_solvers`] takes chetaev's [`Options`]. What `ode_solvers` cannot carry out is
//! refused with a [`BackendError`] that names the option and what to do instead, never ignored.
//! The options are first checked by [`Options::validate`], so that bad numbers get the error
//! [`chetaev::solve`] gives them, before any refusal of the backend's own:
//!
//! | option | here |
//! |---|---|
//! | `t_end` | honoured, backward too |
//! | `rtol`, scalar `atol` | honoured; `atol` must be positive ([`BackendError::ZeroAtol`]) |
//! | `Atol::PerComponent` | refused ([`BackendError::PerComponentAtol`]) |
//! | `initial_step`, `max_step` | honoured (`ode_solvers`' `h` and `h_max`) |
//! | `max_steps` | honoured, up to `u32::MAX` ([`BackendError::MaxSteps`]) |
//! | `Output::Steps`, `Output::Final` | honoured |
//! | `Output::Times` | [`OdeSolversMethod::Dopri5`]: from its continuous output model (order 4); [`OdeSolversMethod::Dop853`]: refused ([`BackendError::OutputTimes`]) |
//! | `record` | every level |
//! | `controller` | honoured where `ode_solvers` runs the same formula: any for Dopri5, `β = 0` for Dop853 ([`BackendError::Controller`]) |
//! | `events` | refused ([`BackendError::Events`]) |
//! | `projection` | refused ([`BackendError::Projection`]) |
//! | `sensitivities` | refused ([`BackendError::Sensitivities`]) |
//! | `rank_tolerance` | honoured: the singular-point check of chetaev's own driver |
//! | `event_samples` | not read (there are no events) |
//!
//! Without a controller each method runs `ode_solvers`' own ([`OdeSolversMethod::controller`]).
//!
//! ## How `ode_solvers` is wrapped
//!
//! None of its known faults can reach a result:
//!
//! - its `Dop853` evaluates two stages at the node `c = 0` instead of `c = 1`, which is wrong
//!   whenever the right-hand side reads the time it is given. The wrapper hands it an autonomous
//!   system: the time is an extra state component `s` with `s' = 1`, so every stage reads its time
//!   from the stage state, whose node is the row sum of the Runge–Kutta matrix, never from the
//!   argument `ode_solvers` passes;
//! - its equally spaced dense output fails when integrating backward or over an interval that
//!   starts below zero. The wrapper always integrates forward in `τ ∈ [0, |t_end − t0|]` with
//!   `t = t0 + dir·τ`, `dir = sign(t_end − t0)`, and never uses that output;
//! - its `Rk4` overshoots the end when the step does not divide the interval; it is not offered.
//!
//! Its error control differs from chetaev's: it measures one root-mean-square norm over its whole
//! state `z = [q, q̇, (W_Φ, ∫∂L/∂t dt), s]`, so the two quadratures of [`Record::Energy`] are
//! under error control (chetaev's driver keeps them outside) and the time `s`, integrated exactly,
//! enters the mean. At equal tolerances its steps therefore differ slightly from chetaev's own
//! `Dopri5` and `Dop853`. Its rejected steps are counted from the right-hand sides it requests,
//! since `ode_solvers` does not count the rejections before its first accepted step. Its state
//! carries the forces' work `W_Q` as chetaev's own `solve` does: for every model with
//! [`Record::Energy`], also one whose forces begin later, except where the compiled equations
//! prove that the model has no forces anywhere (a component that stayed zero would still enter
//! the mean of its norm).
//!
//! [`Options`]: chetaev::prelude::Options
//! [`Record::Energy`]: chetaev::prelude::Record::Energy

mod adapter;
mod error;

pub use error::BackendError;

use chetaev::integrate::system::{OdeSystem, ReducedOde};
use chetaev::integrate::Controller;
use chetaev::model::Model;
use chetaev::prelude::{Atol, Options, Output, Record};
use chetaev::{Error, Problem, Solution, Status};
use ode_solvers::dop_shared::IntegrationError;

use adapter::{Adapter, Callback};

/// Which `ode_solvers` method.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OdeSolversMethod {
    /// Dormand–Prince 5(4), `ode_solvers::Dopri5`.
    Dopri5,
    /// Dormand–Prince 8(5,3), `ode_solvers::Dop853`.
    Dop853,
}

impl OdeSolversMethod {
    /// Both methods.
    pub const ALL: [OdeSolversMethod; 2] = [Self::Dopri5, Self::Dop853];

    /// The name recorded in [`Solution::method`].
    pub fn name(self) -> &'static str {
        match self {
            Self::Dopri5 => "Dopri5 (ode_solvers)",
            Self::Dop853 => "Dop853 (ode_solvers)",
        }
    }

    /// The step-size controller `ode_solvers` runs by default, in chetaev's terms: Hairer's PI
    /// controller (`β = 0.04`, ratios in `[0.2, 10]`) for Dopri5, the I controller with ratios in
    /// `[0.333, 6]` for Dop853; safety 0.9 for both.
    pub fn controller(self) -> Controller {
        match self {
            Self::Dopri5 => Controller::pi(0.2, 10.0, 0.04),
            Self::Dop853 => Controller::i(0.333, 6.0),
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

    /// Right-hand sides per step attempt, and extra ones per accepted step (without
    /// `ode_solvers`' equally spaced dense output, which is never used).
    fn evaluations_per_step(self) -> (usize, usize) {
        match self {
            Self::Dopri5 => (6, 0),
            Self::Dop853 => (11, 1),
        }
    }
}

/// Accepted steps between two stiffness tests of `ode_solvers` (its default).
const STIFFNESS_INTERVAL: u32 = 1000;

/// What to try when `ode_solvers` gives up on the step size.
const STEP_SIZE_ADVICE: &str = "solve it with chetaev's implicit Rodas4 through chetaev::solve";

/// Integrates `problem` from its start to `options.t_end` with the `ode_solvers` method `method`,
/// and returns the motion as a [`Solution`] recorded where `options.output` asks (for
/// [`Output::Steps`], at the start and at every step `ode_solvers` accepts; the last one lands on
/// `t_end` exactly) with what `options.record` asks.
///
/// Options `ode_solvers` cannot honour are refused (see the [crate documentation](crate) and
/// [`BackendError`]); bad input is the [`chetaev::Error`] that [`chetaev::solve`] returns for it,
/// as [`BackendError::Chetaev`].
///
/// A failure during the integration is the [`Status::Failed`] of the solution, with chetaev's error,
/// and the solution keeps the motion up to the last step accepted before it: `ode_solvers`' step
/// limit is [`Error::MaxSteps`], its step size underflow [`Error::StepSizeTooSmall`] (with the
/// bound `10·ε·|t − t0|` below which it gives up, as it does not report the step), its stiffness
/// detection [`Error::Stiff`] (suggesting `"Rodas4"`, with the threshold on `h·|λ|` it exceeded, as
/// it reports no estimate; the step on which it is detected is accepted by `ode_solvers` but not
/// delivered, so it is not recorded). A failure of the model (a singular block system, a
/// non-finite evaluation) ends the integration with that error.
///
/// The statistics count the right-hand sides and output evaluations where the model is called;
/// the accepted steps are those delivered to the wrapper, and the rejected ones the other complete
/// step attempts, counted from the evaluations made.
pub fn solve_with_ode_solvers<M: Model>(
    problem: &Problem<M>,
    method: OdeSolversMethod,
    options: &Options,
) -> Result<Solution, BackendError> {
    let t0 = problem.t0();
    let (n, k) = problem.sizes();
    let settings = Settings::new(options, method, t0, n)?;
    let tau_end = (options.t_end - t0).abs();
    if !tau_end.is_finite() {
        return Err(Error::NonFiniteInput {
            what: "|t_end − t0|".to_string(),
            value: tau_end,
        }
        .into());
    }
    let dir = if options.t_end >= t0 { 1.0 } else { -1.0 };

    // The forces' work is carried unless the compiled equations prove that the model has no
    // forces anywhere (see the crate's docs).
    let ode = ReducedOde::for_problem(problem, options.record >= Record::Energy)
        .with_rank_tolerance(options.rank_tolerance)
        .with_horizon(t0, options.horizon());
    let mut z0 = vec![0.0; ode.dim() + 1];
    z0[..n].copy_from_slice(problem.q0());
    z0[n..2 * n].copy_from_slice(problem.qd0());
    let sol = Solution::empty(method.name(), options.record, n, k);
    let mut adapter = Adapter::new(ode, sol, t0, options.t_end, dir, tau_end, &z0);
    adapter.record_steps = matches!(options.output, Output::Steps);

    if let Err(e) = adapter.record(t0, &z0) {
        return Ok(adapter.finish(Status::Failed(e), 0, 0));
    }
    if tau_end == 0.0 {
        return Ok(adapter.finish(Status::Success, 0, 0));
    }

    let mut continuous = ode_solvers::continuous_output_model::ContinuousOutputModel::default();
    let outcome = run(
        Callback(&mut adapter),
        method,
        &settings,
        ode_solvers::DVector::from_vec(z0),
        tau_end,
        &mut continuous,
    );

    let (per_attempt, per_accepted) = method.evaluations_per_step();
    let startup = if settings.initial_step.is_some() {
        1
    } else {
        3
    };
    let accepted = adapter.accepted_steps;
    // Complete attempts made in `callbacks` evaluations, `delivered` of them accepted steps.
    let attempts = |callbacks: usize, delivered: usize| {
        callbacks.saturating_sub(startup + per_accepted * delivered) / per_attempt
    };
    let (mut status, rejected) = match (adapter.take_failure(), outcome) {
        // Every attempt after the failing evaluation sees NaN and is rejected; the attempts counted
        // are the ones completed up to it.
        (Some(f), _) => (
            Status::Failed(f.error),
            attempts(f.callbacks, accepted).saturating_sub(accepted),
        ),
        (None, Ok(_)) => (
            Status::Success,
            attempts(adapter.callbacks(), accepted).saturating_sub(accepted),
        ),
        (None, Err(e)) => {
            // A stiffness failure is raised after its step was accepted, before it is delivered.
            let undelivered = usize::from(matches!(e, IntegrationError::StiffnessDetected { .. }));
            let total = attempts(adapter.callbacks(), accepted + undelivered);
            (
                Status::Failed(map_error(&e, method, t0, dir, options.max_steps)),
                total.saturating_sub(accepted + undelivered),
            )
        }
    };

    // Output at given times, from the continuous output of the accepted steps.
    let mut output_failed = false;
    if let Output::Times(times) = &options.output {
        let upper = adapter.last_tau();
        let mut taus: Vec<(f64, f64)> = times
            .iter()
            .map(|&s| (dir * (s - t0), s))
            .filter(|&(tau, s)| tau > 0.0 && tau <= upper && dir * (s - options.t_end) < 0.0)
            .collect();
        taus.sort_by(|a, b| a.0.total_cmp(&b.0));
        for (tau, s) in taus {
            // `0 < τ ≤ upper`: within the accepted steps, where the continuous output is defined.
            let Some(z) = continuous.evaluate(tau) else {
                break;
            };
            if let Err(e) = adapter.record(s, z.as_slice()) {
                status = Status::Failed(e);
                output_failed = true;
                break;
            }
        }
    }
    // Unless every step was recorded: the final point from the method's own step, or after a
    // failure the last accepted state (whose own failure to record leaves the error as it is).
    if !adapter.record_steps && !output_failed {
        if let Err(e) = adapter.record_last() {
            if status == Status::Success {
                status = Status::Failed(e);
            }
        }
    }
    Ok(adapter.finish(status, accepted, rejected))
}

/// The options as `ode_solvers` takes them, validated.
struct Settings {
    rtol: f64,
    atol: f64,
    initial_step: Option<f64>,
    max_step: Option<f64>,
    /// `ode_solvers`' `n_max` that allows `Options::max_steps` attempts.
    n_max: u32,
    controller: Controller,
    continuous_output: bool,
}

impl Settings {
    /// Checks the options as [`chetaev::solve`] does ([`Options::validate`], for `n` coordinates
    /// from `t0`), then refuses what `ode_solvers` cannot honour.
    fn new(o: &Options, method: OdeSolversMethod, t0: f64, n: usize) -> Result<Self, BackendError> {
        o.validate(t0, n)?;
        if !o.events.is_empty() {
            return Err(BackendError::Events {
                count: o.events.len(),
            });
        }
        if o.projection.is_some() {
            return Err(BackendError::Projection);
        }
        if !o.sensitivities.is_empty() {
            return Err(BackendError::Sensitivities {
                count: o.sensitivities.len(),
            });
        }
        let atol = match o.atol {
            Atol::Scalar(a) => a,
            Atol::PerComponent(_) => return Err(BackendError::PerComponentAtol),
        };
        if method == OdeSolversMethod::Dop853 && matches!(o.output, Output::Times(_)) {
            return Err(BackendError::OutputTimes);
        }
        let controller = o.controller.unwrap_or(method.controller());
        controller.validate()?;
        if method == OdeSolversMethod::Dop853 && controller.beta != 0.0 {
            return Err(BackendError::Controller {
                beta: controller.beta,
            });
        }
        if o.max_steps > u32::MAX as usize {
            return Err(BackendError::MaxSteps {
                max_steps: o.max_steps,
            });
        }

        if atol == 0.0 {
            return Err(BackendError::ZeroAtol);
        }
        // Dopri5 of ode_solvers stops when more than `n_max` attempts were made, Dop853 when
        // `n_max` were.
        let n_max = match method {
            OdeSolversMethod::Dopri5 => o.max_steps - 1,
            OdeSolversMethod::Dop853 => o.max_steps,
        };
        Ok(Self {
            rtol: o.rtol,
            atol,
            initial_step: o.initial_step.map(f64::abs),
            max_step: o.max_step,
            n_max: u32::try_from(n_max).unwrap_or(u32::MAX),
            controller,
            continuous_output: matches!(o.output, Output::Times(_)),
        })
    }
}

/// Runs `ode_solvers` on `τ ∈ [0, tau_end]` from `z0`; with `continuous_output` (Dopri5 only) it
/// fills `continuous`.
fn run<M: Model>(
    callback: Callback<'_, '_, M>,
    method: OdeSolversMethod,
    s: &Settings,
    z0: ode_solvers::DVector<f64>,
    tau_end: f64,
    continuous: &mut ode_solvers::continuous_output_model::ContinuousOutputModel<
        f64,
        ode_solvers::DVector<f64>,
    >,
) -> Result<ode_solvers::dop_shared::Stats, IntegrationError> {
    let h_max = s.max_step.unwrap_or(f64::INFINITY).min(tau_end);
    // 0 asks ode_solvers for its own initial step.
    let h = s.initial_step.map_or(0.0, |h| h.min(h_max));
    let c = s.controller;
    match method {
        OdeSolversMethod::Dopri5 => {
            let out = if s.continuous_output {
                ode_solvers::OutputType::Continuous
            } else {
                ode_solvers::OutputType::Sparse
            };
            let mut stepper = ode_solvers::Dopri5::from_param(
                callback,
                0.0,
                tau_end,
                tau_end,
                z0,
                s.rtol,
                s.atol,
                c.safety,
                c.beta,
                c.fac_min,
                c.fac_max,
                h_max,
                h,
                s.n_max,
                STIFFNESS_INTERVAL,
                out,
            );
            if s.continuous_output {
                stepper.integrate_with_continuous_output_model(continuous)
            } else {
                stepper.integrate()
            }
        }
        OdeSolversMethod::Dop853 => {
            let mut stepper = ode_solvers::Dop853::from_param(
                callback,
                0.0,
                tau_end,
                tau_end,
                z0,
                s.rtol,
                s.atol,
                c.safety,
                c.beta,
                c.fac_min,
                c.fac_max,
                h_max,
                h,
                s.n_max,
                STIFFNESS_INTERVAL,
                ode_solvers::OutputType::Sparse,
            );
            stepper.integrate()
        }
    }
}

/// Translates a failure reported by `ode_solvers` at its time `τ` into chetaev's error.
fn map_error(
    e: &IntegrationError,
    method: OdeSolversMethod,
    t0: f64,
    dir: f64,
    max_steps: usize,
) -> Error {
    let t_of = |tau: f64| t0 + dir * tau;
    match *e {
        IntegrationError::MaxNumStepReached { x, .. } => Error::MaxSteps {
            t: t_of(x),
            max_steps,
            hint: "raise Options::max_steps or loosen the tolerances",
            // ode_solvers does not say how far its steps went; not judged.
            stalled: false,
        },
        // ode_solvers gives up when `0.1·|h| ≤ ε·|τ|`; it does not report `h`, so the bound is given.
        IntegrationError::StepSizeUnderflow { x } => Error::StepSizeTooSmall {
            t: t_of(x),
            h: dir * 10.0 * f64::EPSILON * x.abs(),
            advice: STEP_SIZE_ADVICE,
        },
        IntegrationError::StiffnessDetected { x } => Error::Stiff {
            t: t_of(x),
            h_lambda: method.stiffness_threshold(),
            suggestion: "Rodas4",
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ode_solvers_errors_map_to_chetaev_errors_in_real_time() {
        let e = map_error(
            &IntegrationError::MaxNumStepReached {
                x: 2.0,
                n_step: 100_000,
            },
            OdeSolversMethod::Dopri5,
            1.0,
            -1.0,
            100_000,
        );
        assert_eq!(
            e,
            Error::MaxSteps {
                t: -1.0,
                max_steps: 100_000,
                hint: "raise Options::max_steps or loosen the tolerances",
                stalled: false,
            }
        );
        let e = map_error(
            &IntegrationError::StepSizeUnderflow { x: 0.5 },
            OdeSolversMethod::Dop853,
            0.0,
            1.0,
            10,
        );
        assert!(
            matches!(e, Error::StepSizeTooSmall { t, h, .. } if t == 0.5 && h > 0.0 && h < 1e-14),
            "{e:?}"
        );
        let e = map_error(
            &IntegrationError::StepSizeUnderflow { x: 0.5 },
            OdeSolversMethod::Dop853,
            3.0,
            -1.0,
            10,
        );
        assert!(
            matches!(e, Error::StepSizeTooSmall { t, h, .. } if t == 2.5 && h < 0.0),
            "{e:?}"
        );
        for (method, h_lambda) in [
            (OdeSolversMethod::Dopri5, 3.25),
            (OdeSolversMethod::Dop853, 6.1),
        ] {
            let e = map_error(
                &IntegrationError::StiffnessDetected { x: 0.25 },
                method,
                0.0,
                1.0,
                10,
            );
            assert_eq!(
                e,
                Error::Stiff {
                    t: 0.25,
                    h_lambda,
                    suggestion: "Rodas4"
                }
            );
        }
    }

    #[test]
    fn default_controllers_are_valid() {
        for method in OdeSolversMethod::ALL {
            assert!(method.controller().validate().is_ok(), "{method:?}");
        }
    }

    /// `y'' = −y` as `ode_solvers` takes it.
    struct Oscillator;
    impl ode_solvers::System<f64, ode_solvers::DVector<f64>> for Oscillator {
        fn system(
            &self,
            _x: f64,
            y: &ode_solvers::DVector<f64>,
            dy: &mut ode_solvers::DVector<f64>,
        ) {
            dy[0] = y[1];
            dy[1] = -y[0];
        }
    }

    #[test]
    fn the_default_controllers_are_those_ode_solvers_runs() {
        let y0 = || ode_solvers::DVector::from_vec(vec![1.0, 0.0]);
        let (rtol, atol, x_end) = (1e-9, 1e-9, 10.0);
        let params = |method: OdeSolversMethod| {
            let c = method.controller();
            (c.safety, c.beta, c.fac_min, c.fac_max)
        };
        let sparse = || ode_solvers::OutputType::Sparse;

        let mut own = ode_solvers::Dopri5::new(Oscillator, 0.0, x_end, x_end, y0(), rtol, atol);
        own.set_output(sparse());
        own.integrate().expect("integrates");
        let (safety, beta, fac_min, fac_max) = params(OdeSolversMethod::Dopri5);
        let mut ours = ode_solvers::Dopri5::from_param(
            Oscillator,
            0.0,
            x_end,
            x_end,
            y0(),
            rtol,
            atol,
            safety,
            beta,
            fac_min,
            fac_max,
            x_end,
            0.0,
            100_000,
            STIFFNESS_INTERVAL,
            sparse(),
        );
        ours.integrate().expect("integrates");
        assert!(own.x_out().len() > 10);
        assert_eq!(own.x_out(), ours.x_out());

        let mut own = ode_solvers::Dop853::new(Oscillator, 0.0, x_end, x_end, y0(), rtol, atol);
        own.set_output(sparse());
        own.integrate().expect("integrates");
        let (safety, beta, fac_min, fac_max) = params(OdeSolversMethod::Dop853);
        let mut ours = ode_solvers::Dop853::from_param(
            Oscillator,
            0.0,
            x_end,
            x_end,
            y0(),
            rtol,
            atol,
            safety,
            beta,
            fac_min,
            fac_max,
            x_end,
            0.0,
            100_000,
            STIFFNESS_INTERVAL,
            sparse(),
        );
        ours.integrate().expect("integrates");
        assert!(own.x_out().len() > 5);
        assert_eq!(own.x_out(), ours.x_out());
    }
}
