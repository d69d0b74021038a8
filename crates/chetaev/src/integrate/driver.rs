//! The driver: step-size control, output, events and projection, the same for every method.

use super::events::{locate_root, EventHit};
use super::options::{Atol, Options, Output, Record};
use super::projection::project_velocity;
use super::system::{split, ChetaevOde, OdeSystem, Stats};
use super::{ErrorNorm, Method, Stepper};
use crate::error::Error;
use crate::model::Model;
use crate::problem::{check_finite, Problem};
use crate::solution::{Solution, Status};

/// Step-size controller: safety factor and bounds on the change of `h` per step.
const SAFETY: f64 = 0.9;
const FAC_MIN: f64 = 0.2;
const FAC_MAX: f64 = 10.0;

/// Integrates `problem` with `method` as `options` ask.
///
/// Bad options are an `Err`. A failure during the integration (a singular block system, a model
/// evaluating to NaN, a step size too small, the step limit, stiffness detected by an explicit
/// method) is the [`Status::Failed`] of the returned solution, which keeps everything computed
/// up to that point.
///
/// ```
/// use chetaev::prelude::*;
///
/// struct Uniform { g: f64, v0: f64 }
/// impl Lagrangian<2> for Uniform {
///     fn lagrangian<R: Real>(&self, _t: R, q: &SVector<R, 2>, qd: &SVector<R, 2>) -> R {
///         qd.dot(qd) * 0.5 - q[1] * self.g
///     }
/// }
/// impl Constraints<2, 1> for Uniform {
///     fn constraints<R: Real>(&self, _t: R, _q: &SVector<R, 2>, qd: &SVector<R, 2>) -> SVector<R, 1> {
///         SVector::from([qd.dot(qd) - self.v0 * self.v0])
///     }
/// }
///
/// let model = Uniform { g: 10.0, v0: 10.0 };
/// let problem = Problem::new(model, 0.0, SVector::from([0.0, 5.0]), SVector::from([10.0, 0.0]))?;
/// let ground = Event::new("ground", |_t, q, _qd| q[1]).falling().terminal();
/// let sol = solve(&problem, Dopri5::default(), &Options::until(10.0).tolerances(1e-10, 1e-12).event(ground))?;
/// let t_impact = sol.events[0].t;
/// // (42.38): T = (v0/g) arccosh(exp(g h0 / v0²))
/// assert!((t_impact - (0.5f64.exp()).acosh()).abs() < 1e-8);
/// # Ok::<(), chetaev::Error>(())
/// ```
pub fn solve<M, Me, const N: usize, const K: usize>(
    problem: &Problem<M, N, K>,
    method: Me,
    options: &Options<N>,
) -> Result<Solution<N, K>, Error>
where
    M: Model<N, K>,
    Me: Method,
{
    validate(options)?;
    method.validate()?;
    let t0 = problem.t0();
    let mut sys = ChetaevOde::new(problem.model(), options.record >= Record::Energy);
    let mut y = vec![0.0; sys.dim()];
    y[..N].copy_from_slice(problem.q0().as_slice());
    y[N..2 * N].copy_from_slice(problem.qd0().as_slice());
    let norm = error_norm(options, N);

    let mut sol = Solution::new(method.name(), options.record);
    let mut hooks = ChetaevHooks {
        sol: &mut sol,
        options,
        event_evaluations: 0,
    };
    let (outcome, counts) = drive(&mut sys, &mut hooks, method, t0, &mut y, &norm, options);
    let event_evaluations = hooks.event_evaluations;
    if let Err(e) = outcome {
        sol.status = Status::Failed(e);
    }
    sol.stats = counts.merged(sys.stats, event_evaluations);
    Ok(sol)
}

pub(crate) fn validate<const N: usize>(o: &Options<N>) -> Result<(), Error> {
    check_finite("t_end", std::slice::from_ref(&o.t_end))?;
    let positive = |name: &'static str, v: f64, hint: &'static str| {
        if v.is_finite() && v > 0.0 {
            Ok(())
        } else {
            Err(Error::InvalidOption {
                name,
                value: v,
                hint,
            })
        }
    };
    if !(o.rtol.is_finite() && o.rtol >= 0.0) {
        return Err(Error::InvalidOption {
            name: "rtol",
            value: o.rtol,
            hint:
                "the relative tolerance must be finite and non-negative; 1e-6 to 1e-13 are typical",
        });
    }
    let atols: Vec<f64> = match &o.atol {
        Atol::Scalar(a) => vec![*a],
        Atol::PerComponent(v) => {
            if v.len() != 2 * N {
                return Err(Error::InvalidOption {
                    name: "atol (length)",
                    value: v.len() as f64,
                    hint: "give one absolute tolerance per component of (q, q̇), 2N in all",
                });
            }
            v.clone()
        }
    };
    for a in atols {
        if !(a.is_finite() && a >= 0.0) || (a == 0.0 && o.rtol == 0.0) {
            return Err(Error::InvalidOption {
                name: "atol",
                value: a,
                hint: "absolute tolerances must be finite and non-negative, and not zero together with rtol",
            });
        }
    }
    if o.rtol < 100.0 * f64::EPSILON && o.rtol != 0.0 {
        return Err(Error::InvalidOption {
            name: "rtol",
            value: o.rtol,
            hint: "below 100 ulps (2.2e-14) no step size can meet the tolerance in f64; use 1e-13 or more",
        });
    }
    if let Some(h) = o.initial_step {
        positive("initial_step", h.abs(), "a finite non-zero first step")?;
    }
    if let Some(h) = o.max_step {
        positive("max_step", h, "a finite positive bound")?;
    }
    if o.max_steps == 0 {
        return Err(Error::InvalidOption {
            name: "max_steps",
            value: 0.0,
            hint: "allow at least one step",
        });
    }
    if let Output::Times(ts) = &o.output {
        check_finite("output time", ts)?;
    }
    if let Some(p) = &o.projection {
        positive(
            "projection tol",
            p.tol,
            "a small positive relative residual such as 1e-14",
        )?;
    }
    Ok(())
}

fn error_norm<const N: usize>(o: &Options<N>, n: usize) -> ErrorNorm {
    let atol = match &o.atol {
        Atol::Scalar(a) => vec![*a; 2 * n],
        Atol::PerComponent(v) => v.clone(),
    };
    ErrorNorm::new(o.rtol, atol)
}

/// Runs the step loop with the settings of `options`; returns the outcome and the loop's counts
/// (accepted and rejected steps).
pub(crate) fn drive<S: OdeSystem, H: Hooks<S>, Me: Method, const N: usize>(
    sys: &mut S,
    hooks: &mut H,
    method: Me,
    t0: f64,
    y: &mut [f64],
    norm: &ErrorNorm,
    options: &Options<N>,
) -> (Result<(), Error>, Stats) {
    let settings = LoopSettings {
        output: &options.output,
        max_steps: options.max_steps,
        initial_step: options.initial_step,
        max_step: options.max_step,
    };
    let mut counts = Stats::default();
    let outcome = step_loop(
        sys,
        hooks,
        method,
        t0,
        options.t_end,
        y,
        norm,
        &settings,
        &mut counts,
    );
    (outcome, counts)
}

/// What the step loop needs beyond the right-hand side: recording, event functions, projection.
pub(crate) trait Hooks<S: OdeSystem> {
    /// Records `(t, y)`.
    fn record(&mut self, sys: &mut S, t: f64, y: &[f64]) -> Result<(), Error>;
    /// Number of event functions.
    fn n_events(&self) -> usize;
    /// The value of event function `i` at `(t, y)`.
    fn event_value(&mut self, i: usize, t: f64, y: &[f64]) -> Result<f64, Error>;
    /// Whether going from `g0` to `g1` is a crossing of event `i` that counts.
    fn crosses(&self, i: usize, g0: f64, g1: f64) -> bool;
    /// Whether event `i` stops the integration.
    fn is_terminal(&self, i: usize) -> bool;
    /// Event `i` happened at `(t, y)`.
    fn event_hit(&mut self, i: usize, t: f64, y: &[f64]);
    /// The integration stopped at terminal event `i`.
    fn terminated(&mut self, i: usize);
    /// Projects `y` onto the constraints; returns whether it changed.
    fn project(&mut self, sys: &mut S, t: f64, y: &mut [f64]) -> Result<bool, Error>;
}

/// The driver's settings that do not depend on the model.
pub(crate) struct LoopSettings<'o> {
    pub output: &'o Output,
    pub max_steps: usize,
    pub initial_step: Option<f64>,
    pub max_step: Option<f64>,
}

/// The Chetaev driver's hooks: the solution being recorded and the user's options.
struct ChetaevHooks<'s, const N: usize, const K: usize> {
    sol: &'s mut Solution<N, K>,
    options: &'s Options<N>,
    event_evaluations: usize,
}

impl<M: Model<N, K>, const N: usize, const K: usize> Hooks<ChetaevOde<'_, M, N, K>>
    for ChetaevHooks<'_, N, K>
{
    fn record(
        &mut self,
        sys: &mut ChetaevOde<'_, M, N, K>,
        t: f64,
        y: &[f64],
    ) -> Result<(), Error> {
        let (q, qd) = split::<N>(y);
        // Evaluate before pushing anything, so a failure leaves every recorded vector the same length.
        let d = if self.options.record >= Record::Dynamics {
            Some(sys.evaluate(t, &q, &qd)?)
        } else {
            None
        };
        let sol = &mut *self.sol;
        sol.t.push(t);
        sol.q.push(q);
        sol.qd.push(qd);
        if let Some(d) = d {
            sol.qdd.push(d.qdd);
            sol.mu.push(d.mu);
            sol.phi.push(d.phi);
            sol.residual.push(d.f);
            sol.energy.push(d.energy);
        }
        if self.options.record >= Record::Energy {
            sol.work.push(y[2 * N]);
            sol.dl_dt_integral.push(y[2 * N + 1]);
        }
        Ok(())
    }

    fn n_events(&self) -> usize {
        self.options.events.len()
    }

    fn event_value(&mut self, i: usize, t: f64, y: &[f64]) -> Result<f64, Error> {
        let (q, qd) = split::<N>(y);
        self.event_evaluations += 1;
        let v = (self.options.events[i].g)(t, &q, &qd);
        if v.is_finite() {
            Ok(v)
        } else {
            Err(Error::NonFiniteEvent {
                index: i,
                t,
                value: v,
            })
        }
    }

    fn crosses(&self, i: usize, g0: f64, g1: f64) -> bool {
        self.options.events[i].crosses(g0, g1)
    }

    fn is_terminal(&self, i: usize) -> bool {
        self.options.events[i].terminal
    }

    fn event_hit(&mut self, i: usize, t: f64, y: &[f64]) {
        let (q, qd) = split::<N>(y);
        self.sol.events.push(EventHit { index: i, t, q, qd });
    }

    fn terminated(&mut self, i: usize) {
        self.sol.status = Status::Terminated { event: i };
    }

    fn project(
        &mut self,
        sys: &mut ChetaevOde<'_, M, N, K>,
        t: f64,
        y: &mut [f64],
    ) -> Result<bool, Error> {
        let Some(p) = self.options.projection else {
            return Ok(false);
        };
        if K == 0 {
            return Ok(false);
        }
        let (q, qd) = split::<N>(y);
        let r = project_velocity(sys.model, &mut sys.ws, t, &q, &qd, p.tol, p.max_iterations)?;
        sys.stats.projections += 1;
        sys.stats.projection_iterations += r.iterations;
        y[N..2 * N].copy_from_slice(r.qd.as_slice());
        Ok(r.iterations > 0)
    }
}

/// Options of [`solve_ode`]: a plain first-order system with no events, projection or diagnostics.
#[derive(Clone, Debug, PartialEq)]
pub struct OdeOptions {
    /// The end time (earlier than the start integrates backward).
    pub t_end: f64,
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance, one per controlled component (or one for all).
    pub atol: Atol,
    /// First step size; chosen automatically when `None`.
    pub initial_step: Option<f64>,
    /// Largest step size.
    pub max_step: Option<f64>,
    /// Step limit.
    pub max_steps: usize,
    /// Where to record.
    pub output: Output,
}

impl OdeOptions {
    /// Integrate to `t_end` with `rtol = 1e-6`, `atol = 1e-9`, recording every step.
    pub fn until(t_end: f64) -> Self {
        Self {
            t_end,
            rtol: 1e-6,
            atol: Atol::Scalar(1e-9),
            initial_step: None,
            max_step: None,
            max_steps: 1_000_000,
            output: Output::Steps,
        }
    }

    /// Sets the relative and absolute tolerance.
    pub fn tolerances(mut self, rtol: f64, atol: f64) -> Self {
        self.rtol = rtol;
        self.atol = Atol::Scalar(atol);
        self
    }
}

/// The result of [`solve_ode`].
#[derive(Clone, Debug)]
#[must_use = "a solution carries a status that says whether the integration succeeded"]
pub struct OdeSolution {
    /// Output times.
    pub t: Vec<f64>,
    /// States at the output times.
    pub y: Vec<Vec<f64>>,
    /// Accepted and rejected steps (the system counts its own evaluations).
    pub stats: Stats,
    /// `None` on success, or why the integration failed.
    pub error: Option<Error>,
}

struct PlainHooks<'s> {
    sol: &'s mut OdeSolution,
}

impl<S: OdeSystem> Hooks<S> for PlainHooks<'_> {
    fn record(&mut self, _sys: &mut S, t: f64, y: &[f64]) -> Result<(), Error> {
        self.sol.t.push(t);
        self.sol.y.push(y.to_vec());
        Ok(())
    }
    fn n_events(&self) -> usize {
        0
    }
    fn event_value(&mut self, _i: usize, _t: f64, _y: &[f64]) -> Result<f64, Error> {
        Ok(0.0)
    }
    fn crosses(&self, _i: usize, _g0: f64, _g1: f64) -> bool {
        false
    }
    fn is_terminal(&self, _i: usize) -> bool {
        false
    }
    fn event_hit(&mut self, _i: usize, _t: f64, _y: &[f64]) {}
    fn terminated(&mut self, _i: usize) {}
    fn project(&mut self, _sys: &mut S, _t: f64, _y: &mut [f64]) -> Result<bool, Error> {
        Ok(false)
    }
}

/// Integrates any first-order system `y' = F(t, y)` with the same methods and step control as
/// [`solve`]. For hand-written right-hand sides, comparisons and tests; constrained mechanics goes
/// through [`solve`].
pub fn solve_ode<S: OdeSystem, Me: Method>(
    sys: &mut S,
    method: Me,
    t0: f64,
    y0: &[f64],
    options: &OdeOptions,
) -> Result<OdeSolution, Error> {
    method.validate()?;
    check_finite("t0", std::slice::from_ref(&t0))?;
    check_finite("y0", y0)?;
    if y0.len() != sys.dim() {
        return Err(Error::InvalidOption {
            name: "y0 (length)",
            value: y0.len() as f64,
            hint: "the initial state must have the system's dimension",
        });
    }
    let n = sys.controlled_dim();
    let atol = match &options.atol {
        Atol::Scalar(a) => vec![*a; n],
        Atol::PerComponent(v) => v.clone(),
    };
    let mut check = Options::<0>::until(options.t_end).tolerances(options.rtol, 1.0);
    check.initial_step = options.initial_step;
    check.max_step = options.max_step;
    check.max_steps = options.max_steps;
    check.output = options.output.clone();
    validate(&check)?;
    if atol.len() != n || atol.iter().any(|a| !(a.is_finite() && *a >= 0.0)) {
        return Err(Error::InvalidOption {
            name: "atol",
            value: atol.len() as f64,
            hint: "absolute tolerances must be finite, non-negative, one per controlled component",
        });
    }
    let norm = ErrorNorm::new(options.rtol, atol);
    let mut sol = OdeSolution {
        t: Vec::new(),
        y: Vec::new(),
        stats: Stats::default(),
        error: None,
    };
    let settings = LoopSettings {
        output: &options.output,
        max_steps: options.max_steps,
        initial_step: options.initial_step,
        max_step: options.max_step,
    };
    let mut y = y0.to_vec();
    let mut counts = Stats::default();
    let outcome = step_loop(
        sys,
        &mut PlainHooks { sol: &mut sol },
        method,
        t0,
        options.t_end,
        &mut y,
        &norm,
        &settings,
        &mut counts,
    );
    sol.error = outcome.err();
    sol.stats = counts;
    Ok(sol)
}

/// The step loop shared by every driver: step-size control, dense output at requested times, event
/// location, projection and recording.
#[allow(clippy::too_many_arguments)]
pub(crate) fn step_loop<S: OdeSystem, H: Hooks<S>, Me: Method>(
    sys: &mut S,
    hooks: &mut H,
    method: Me,
    t0: f64,
    t_end: f64,
    y: &mut [f64],
    norm: &ErrorNorm,
    settings: &LoopSettings<'_>,
    counts: &mut Stats,
) -> Result<(), Error> {
    hooks.record(sys, t0, y)?;
    if t_end == t0 {
        return Ok(());
    }
    let dir = (t_end - t0).signum();
    let dim = y.len();
    let mut stepper = method.stepper(dim);
    stepper.set_dense_output(hooks.n_events() > 0 || matches!(settings.output, Output::Times(_)));
    stepper.reset(sys, t0, y)?;

    let n_events = hooks.n_events();
    let mut g_old = vec![0.0; n_events];
    let mut g_new = vec![0.0; n_events];
    for (i, g) in g_old.iter_mut().enumerate() {
        *g = hooks.event_value(i, t0, y)?;
    }
    let mut pending_times: Vec<f64> = match settings.output {
        Output::Times(ts) => {
            let mut v: Vec<f64> = ts
                .iter()
                .copied()
                .filter(|&s| dir * (s - t0) > 0.0 && dir * (s - t_end) <= 0.0)
                .collect();
            v.sort_by(|a, b| (dir * b).total_cmp(&(dir * a)));
            v // latest first: pop from the back in time order
        }
        _ => Vec::new(),
    };
    let h_max = settings
        .max_step
        .unwrap_or(f64::INFINITY)
        .min((t_end - t0).abs());

    let mut h = match stepper.fixed_step() {
        Some(h) => h,
        None => match settings.initial_step {
            Some(h) => h.abs(),
            None => initial_step(sys, t0, y, t_end, norm, dir)?,
        },
    }
    .min(h_max)
        * dir;

    let mut t = t0;
    let mut y_new = vec![0.0; dim];
    let mut buf = vec![0.0; dim];
    let mut steps = 0usize;
    let mut rejected_last = false;
    let order = stepper.control_order();
    loop {
        if steps >= settings.max_steps {
            return Err(Error::MaxSteps {
                t,
                max_steps: settings.max_steps,
            });
        }
        steps += 1;
        let remaining = t_end - t;
        // Land exactly on t_end; avoid a sliver of a last step by stretching within 1%.
        let last = (h * 1.01).abs() >= remaining.abs();
        if last {
            h = remaining;
        }
        if h.abs() <= 4.0 * f64::EPSILON * t.abs() && !last {
            return Err(Error::StepSizeTooSmall { t, h });
        }
        let trial = stepper.try_step(sys, t, h, y, &mut y_new, norm);
        let err = match trial {
            Ok(e) if e.is_finite() => e,
            Ok(_) | Err(Error::NonFiniteEvaluation { .. }) if order.is_some() => {
                // A trial stage left the model's domain: retry with a smaller step.
                counts.rejected_steps += 1;
                h *= 0.25;
                rejected_last = true;
                if h.abs() <= 4.0 * f64::EPSILON * t.abs().max(f64::MIN_POSITIVE) {
                    return Err(trial.err().unwrap_or(Error::StepSizeTooSmall { t, h }));
                }
                continue;
            }
            Ok(_) => {
                return Err(Error::NonFiniteEvaluation {
                    t: t + h,
                    q: y_new.clone(),
                    qd: Vec::new(),
                })
            }
            Err(e) => return Err(e),
        };
        if err > 1.0 && order.is_some() {
            counts.rejected_steps += 1;
            let p = order.unwrap_or(1) as f64;
            h *= (SAFETY * err.powf(-1.0 / p)).clamp(FAC_MIN, 1.0);
            rejected_last = true;
            continue;
        }

        // Accepted.
        counts.accepted_steps += 1;
        stepper.accept(sys, t, h, y, &y_new)?;
        let t_new = if last { t_end } else { t + h };
        if let Some(h_lambda) = stepper.stiffness() {
            hooks.record(sys, t_new, &y_new)?;
            return Err(Error::Stiff {
                t: t_new,
                h_lambda,
                suggestion: stepper.stiff_alternative(),
            });
        }

        // Events on the dense output of [t, t_new].
        let mut terminal: Option<(usize, f64)> = None;
        if n_events > 0 {
            for (i, g) in g_new.iter_mut().enumerate() {
                *g = hooks.event_value(i, t_new, &y_new)?;
            }
            let mut hits: Vec<(usize, f64)> = Vec::new();
            for i in 0..n_events {
                if !hooks.crosses(i, g_old[i], g_new[i]) {
                    continue;
                }
                let mut failure = None;
                let mut at = |s: f64| {
                    stepper.interpolate((s - t) / h, &mut buf);
                    match hooks.event_value(i, s, &buf) {
                        Ok(v) => v,
                        Err(e) => {
                            failure.get_or_insert(e);
                            f64::NAN
                        }
                    }
                };
                let (ts, _) = locate_root(&mut at, t, g_old[i], t_new, g_new[i]);
                if let Some(e) = failure {
                    return Err(e);
                }
                hits.push((i, ts));
            }
            hits.sort_by(|a, b| (dir * a.1).total_cmp(&(dir * b.1)));
            for &(i, ts) in &hits {
                if hooks.is_terminal(i) {
                    terminal = Some((i, ts));
                    break;
                }
                stepper.interpolate((ts - t) / h, &mut buf);
                hooks.event_hit(i, ts, &buf);
            }
        }
        let t_stop = terminal.map_or(t_new, |(_, ts)| ts);

        // Dense output at requested times up to the stop (an event point and the final point are
        // recorded from the method's own step below).
        while let Some(&s) = pending_times.last() {
            if dir * (s - t_stop) > 0.0 || (terminal.is_some() && s == t_stop) {
                break;
            }
            pending_times.pop();
            if last && s == t_end {
                break;
            }
            stepper.interpolate((s - t) / h, &mut buf);
            // The interpolant is not on the constraint manifold; with projection on, every recorded
            // point is.
            hooks.project(sys, s, &mut buf)?;
            hooks.record(sys, s, &buf)?;
        }

        if let Some((i, ts)) = terminal {
            // Land on the event with one step of the method itself, more accurate than the
            // interpolant, then stop.
            stepper.reset(sys, t, y)?;
            let h_event = ts - t;
            if h_event != 0.0 {
                stepper.try_step(sys, t, h_event, y, &mut y_new, norm)?;
            } else {
                y_new.copy_from_slice(y);
            }
            hooks.project(sys, ts, &mut y_new)?;
            hooks.event_hit(i, ts, &y_new);
            hooks.record(sys, ts, &y_new)?;
            hooks.terminated(i);
            return Ok(());
        }

        if hooks.project(sys, t_new, &mut y_new)? {
            stepper.reset(sys, t_new, &y_new)?;
        }
        if last || matches!(settings.output, Output::Steps) {
            hooks.record(sys, t_new, &y_new)?;
        }
        std::mem::swap(&mut g_old, &mut g_new);
        y.copy_from_slice(&y_new);
        t = t_new;
        if last {
            return Ok(());
        }
        if let Some(p) = order {
            let fac_max = if rejected_last { 1.0 } else { FAC_MAX };
            let fac = if err > 0.0 {
                SAFETY * err.powf(-1.0 / p as f64)
            } else {
                FAC_MAX
            };
            h *= fac.clamp(FAC_MIN, fac_max);
            if h.abs() > h_max {
                h = h_max * dir;
            }
        }
        rejected_last = false;
    }
}

/// Hairer's starting step (Solving ODEs I, II.4): balances `h·|F|` against the tolerance and the
/// second derivative estimated from one Euler step.
fn initial_step<S: OdeSystem>(
    sys: &mut S,
    t0: f64,
    y0: &[f64],
    t_end: f64,
    norm: &ErrorNorm,
    dir: f64,
) -> Result<f64, Error> {
    let dim = y0.len();
    let p = 5.0f64;
    let mut f0 = vec![0.0; dim];
    sys.rhs(t0, y0, &mut f0)?;
    let zeros = vec![0.0; dim];
    let d0 = norm.norm(y0, y0, &zeros);
    let d1 = norm.norm(&f0, y0, &zeros);
    let mut h0 = if d0 < 1e-5 || d1 < 1e-5 {
        1e-6
    } else {
        0.01 * d0 / d1
    };
    h0 = h0.min((t_end - t0).abs());
    let y1: Vec<f64> = (0..dim).map(|i| y0[i] + dir * h0 * f0[i]).collect();
    let mut f1 = vec![0.0; dim];
    sys.rhs(t0 + dir * h0, &y1, &mut f1)?;
    let diff: Vec<f64> = (0..dim).map(|i| f1[i] - f0[i]).collect();
    let d2 = norm.norm(&diff, y0, &zeros) / h0;
    let h1 = if d1.max(d2) <= 1e-15 {
        (h0 * 1e-3).max(1e-6)
    } else {
        (0.01 / d1.max(d2)).powf(1.0 / p)
    };
    Ok((100.0 * h0).min(h1))
}
