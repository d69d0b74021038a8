//! The driver: step-size control, output, events and projection, the same for every method and
//! every model.

use super::events::{crosses, locate_root, Direction, EventHit};
use super::options::{Options, Output, Record};
use super::projection::{project_positions, project_velocity};
use super::system::{OdeSystem, ReducedOde, Stats};
use super::{time_resolution, Controller, ErrorNorm, Method, MethodInfo, Stepper};
use crate::error::{Error, Singularity};
use crate::model::Model;
use crate::problem::{check_finite, Problem};
use crate::sensitivity::{Sensitivities, Variational};
use crate::solution::{Solution, Status, Warning};

/// Integrates `problem` with `method` as `options` ask.
///
/// Bad options are an `Err`. A failure during the integration (a singular block system, a model
/// evaluating to NaN, a step size too small, the step limit, stiffness detected by an explicit
/// method) is the [`Status::Failed`] of the returned solution, which keeps everything computed up
/// to that point, including the last accepted state.
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
pub fn solve<M, Me>(problem: &Problem<M>, method: Me, options: &Options) -> Result<Solution, Error>
where
    M: Model,
    Me: Method,
{
    let (n, k) = problem.sizes();
    let t0 = problem.t0();
    let mut sys = ReducedOde::for_problem(problem, options.record >= Record::Energy)
        .with_rank_tolerance(options.rank_tolerance)
        .with_horizon(t0, options.horizon());
    if !options.sensitivities.is_empty() {
        if options.projection.is_some() {
            return Err(Error::Sensitivity {
                what: "projection moves the state but not its derivatives; leave projection off \
                       with sensitivities (the variational equations keep S on the linearised \
                       constraints)"
                    .to_string(),
            });
        }
        if options.sensitivity_control {
            if let Some(h) = method.info().fixed_step {
                return Err(Error::Sensitivity {
                    what: format!(
                        "{} takes fixed steps (h = {h}) and has no error control to put the \
                         sensitivities under: leave Options::sensitivity_control off, or use a \
                         method with error control (Dop853, Rodas4)",
                        method.info().name
                    ),
                });
            }
        }
        let variational = Variational::new(
            problem.model(),
            t0,
            problem.q0(),
            problem.qd0(),
            &options.sensitivities,
            &options.events,
            options.sensitivity_control,
        )?;
        sys = sys.with_sensitivities(variational);
    }
    let settings = LoopSettings::new(options, &method, t0, sys.controlled_dim(), 2 * n)?;
    let mut y = vec![0.0; sys.dim()];
    y[..n].copy_from_slice(problem.q0());
    y[n..2 * n].copy_from_slice(problem.qd0());

    let rows = expected_rows(&options.output, sys.dim());
    let mut sol = Solution::with_capacity(settings.info.name, options.record, n, k, rows);
    if let Some(v) = &sys.sens {
        v.initial(&mut y[2 * n..sys.quadratures()]);
        let mut s = Sensitivities::new(v.names(), n, k);
        s.values.reserve(rows);
        sol.sensitivities = Some(s);
    }
    let mut hooks = ChetaevHooks {
        sol: &mut sol,
        options,
        n,
        event_evaluations: 0,
    };
    let mut run = Progress::start(t0, y);
    if let Err(mut e) = step_loop(&mut sys, &mut hooks, &method, &settings, &mut run) {
        // Keep the last accepted state, wherever the output was asked for. Where it cannot be
        // recorded (a quantity of its own is not finite, such as an energy that overflows), a run
        // recording every step would have stopped there with that error: it replaces the step's,
        // so that the error says truly what is kept (the motion before its time).
        if hooks.sol.t.last() != Some(&run.t) {
            if let Err(unrecorded) = hooks.record(&mut sys, run.t, &run.y) {
                e = unrecorded;
            }
        }
        hooks.sol.status = Status::Failed(e);
    }
    let event_evaluations = hooks.event_evaluations;
    sol.stats = run.counts.merged(sys.stats, event_evaluations);
    sol.stats.graph_fallbacks += sys.sens.as_ref().map_or(0, |v| v.rerecords);
    Ok(sol)
}

/// How many points a solve is likely to record, so that the series of a short solve are allocated
/// once: the start and the end for [`Output::Final`], with the listed times for [`Output::Times`],
/// and 64 points for [`Output::Steps`]; never more than about 64 KiB per series (a list of times
/// that the run may not reach, a large model), beyond which the series grow as vectors do.
fn expected_rows(output: &Output, dim: usize) -> usize {
    let most = (8192 / dim.max(1)).max(2);
    match output {
        Output::Final => 2,
        Output::Times(ts) => ts.len().saturating_add(2).min(most),
        Output::Steps => most.min(64),
    }
}

/// The approach to a singular point found inside an accepted step. That step is rejected, and
/// from then on every step stops at most halfway to the point, so that the motion, the events
/// and the output times before it are kept and no step crosses it again (a short step across it
/// can land on the other branch of the motion without the check seeing it: a speed that falls to
/// zero and rises again in the same direction). After 20 steps that the halfway bound held (the
/// point a millionth of the first distance away), or when such a step no longer changes `t`, the
/// run ends with the point's error.
#[derive(Default)]
struct Approach {
    /// The point's error, where it lies, and how many steps the halfway bound held.
    point: Option<(Error, f64, u32)>,
}

impl Approach {
    const HALVINGS: u32 = 20;

    /// An accepted step from `t` failed its check with `e`: `Ok` when the step is to be taken
    /// again towards the point, `e` when the run ends with it (another error, a fixed-step
    /// method, a second point while one is approached).
    fn found(&mut self, e: Error, t: f64, adaptive: bool) -> Result<(), Error> {
        match e {
            // A constraint that ends is met at the start of the step, where the run ends.
            Error::SingularPoint {
                cause: Singularity::Unbounded(_),
                ..
            } => Err(e),
            Error::SingularPoint { t: at, .. } if adaptive && self.point.is_none() && at != t => {
                self.point = Some((e, at, 0));
                Ok(())
            }
            e => Err(e),
        }
    }

    /// The step to take from `t` instead of `h`: at most halfway to the point approached; its
    /// error once the point is reached.
    fn bound(&mut self, t: f64, h: f64) -> Result<f64, Error> {
        let Some((_, at, held)) = &mut self.point else {
            return Ok(h);
        };
        let half = 0.5 * (*at - t);
        if *held >= Self::HALVINGS || half.abs() <= time_resolution(t) {
            let (e, _, _) = self.point.take().expect("approached");
            return Err(e);
        }
        if h.abs() < half.abs() {
            return Ok(h);
        }
        *held += 1;
        Ok(half)
    }
}

/// What the step loop is asked to do, validated once for every driver.
pub(crate) struct LoopSettings<'o> {
    /// The options, validated.
    pub options: &'o Options,
    /// The norm of error control made from `rtol` and `atol`.
    pub norm: ErrorNorm,
    /// The method's facts.
    pub info: MethodInfo,
    /// The step-size controller: the options' or else the method's.
    pub controller: Controller,
}

impl<'o> LoopSettings<'o> {
    /// Validates the options for a system with `controlled` components under error control,
    /// starting at `t0`, with `method`. A per-component `atol` has `block` entries (the state
    /// `(q, q̇)`), repeated over the controlled sensitivities that follow it.
    fn new<Me: Method>(
        o: &'o Options,
        method: &Me,
        t0: f64,
        controlled: usize,
        block: usize,
    ) -> Result<Self, Error> {
        method.validate()?;
        let info = method.info();
        info.validate()?;
        // The method's controller is checked with its facts, the options' with the options.
        o.validate_components(t0, block)?;
        let floor = time_resolution(t0).max(time_resolution(o.t_end));
        if let Some(fixed) = info.fixed_step.filter(|h| *h <= floor) {
            return Err(Error::InvalidOption {
                name: if info.name == "Rk4" {
                    "Rk4::h"
                } else {
                    "fixed step"
                },
                value: fixed,
                hint: "a fixed step this short no longer changes t (it is below 4 ulps of t \
                       over the interval): take a larger step, or count time from a nearer origin",
            });
        }
        let atol = o.atol_of(controlled);
        let controller = o.controller.unwrap_or(info.controller);
        Ok(Self {
            options: o,
            norm: ErrorNorm::new(o.rtol, atol),
            info,
            controller,
        })
    }
}

/// What the step loop needs beyond the right-hand side: recording, event functions, projection.
pub(crate) trait Hooks<S: OdeSystem> {
    /// Records `(t, y)`.
    fn record(&mut self, sys: &mut S, t: f64, y: &[f64]) -> Result<(), Error>;
    /// The time of the last recorded point.
    fn last_recorded(&self) -> Option<f64>;
    /// Number of event functions.
    fn n_events(&self) -> usize;
    /// The value of event function `i` at `(t, y)`.
    fn event_value(&mut self, i: usize, t: f64, y: &[f64]) -> Result<f64, Error>;
    /// Which crossings of event `i` count.
    fn direction(&self, i: usize) -> Direction;
    /// Whether event `i` stops the integration.
    fn is_terminal(&self, i: usize) -> bool;
    /// Event `i` happened at `(t, y)`.
    fn event_hit(&mut self, sys: &mut S, i: usize, t: f64, y: &[f64]) -> Result<(), Error>;
    /// The integration stopped at terminal event `i`.
    fn terminated(&mut self, i: usize);
    /// Projects `y` onto the constraints; returns whether it changed.
    fn project(&mut self, sys: &mut S, t: f64, y: &mut [f64]) -> Result<bool, Error>;
    /// How far from zero event function `i` may be at `(t, y)` by the rounding of the state
    /// alone ([`start_rounding`]); 0 where no state is known to the hooks.
    fn event_rounding(&mut self, i: usize, t: f64, y: &[f64], value: f64) -> f64 {
        let _ = (i, t, y, value);
        0.0
    }
    /// Event `i` is zero at the start, where its function is `value`: it is not armed until it
    /// leaves zero.
    fn unarmed_at_start(&mut self, i: usize, value: f64) {
        let _ = (i, value);
    }
    /// Event `i`, zero at the start, had left zero by `t`: it is armed from then on.
    fn armed(&mut self, i: usize, t: f64) {
        let _ = (i, t);
    }
}

/// How far from zero an event function `g` may be at `(t, q, q̇)` by the rounding of the state
/// alone: `Σ_x |g(x + δx) − g(x)|` over `t` and each component of `q` and of `q̇`, each moved by
/// `δx` of 4 units of roundoff of the largest magnitude of its kind (`|t|`, `max |q_i|`,
/// `max |q̇_i|`). A function that is zero only up to the rounding of a computed initial state
/// (`ẏ0 = v0 sin π`, `1.2e-15 v0`) is within it; a value that the state's rounding cannot
/// reach is not. Evaluations that are not finite add nothing.
fn start_rounding(
    g: &mut impl FnMut(f64, &[f64], &[f64]) -> f64,
    t: f64,
    q: &[f64],
    qd: &[f64],
    value: f64,
) -> f64 {
    let ulps = 4.0 * f64::EPSILON;
    let largest = |v: &[f64]| v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let change = |v: f64| {
        let d = (v - value).abs();
        if d.is_finite() {
            d
        } else {
            0.0
        }
    };
    let mut band = 0.0;
    let dt = ulps * t.abs();
    if dt > 0.0 {
        band += change(g(t + dt, q, qd));
    }
    let n = q.len();
    let (dq, dqd) = (ulps * largest(q), ulps * largest(qd));
    let mut x = [q, qd].concat();
    for i in 0..2 * n {
        let dx = if i < n { dq } else { dqd };
        if dx == 0.0 {
            continue;
        }
        let kept = x[i];
        x[i] = kept + dx;
        band += change(g(t, &x[..n], &x[n..]));
        x[i] = kept;
    }
    band
}

/// The Chetaev driver's hooks: the solution being recorded and the user's options.
struct ChetaevHooks<'s> {
    sol: &'s mut Solution,
    options: &'s Options,
    n: usize,
    event_evaluations: usize,
}

impl ChetaevHooks<'_> {
    /// The error of event `i`'s non-finite value `value` at `t`; out of the way of the event
    /// function's hot path (it clones the event's name).
    #[cold]
    fn non_finite_event(&self, i: usize, t: f64, value: f64) -> Error {
        Error::NonFiniteEvent {
            index: i,
            name: self.options.events[i].name.clone(),
            t,
            value,
        }
    }
}

impl<M: Model + ?Sized> Hooks<ReducedOde<'_, M>> for ChetaevHooks<'_> {
    fn record(&mut self, sys: &mut ReducedOde<'_, M>, t: f64, y: &[f64]) -> Result<(), Error> {
        self.sol.record(sys, t, y)
    }

    fn last_recorded(&self) -> Option<f64> {
        self.sol.t.last().copied()
    }

    fn n_events(&self) -> usize {
        self.options.events.len()
    }

    #[inline]
    fn event_value(&mut self, i: usize, t: f64, y: &[f64]) -> Result<f64, Error> {
        let n = self.n;
        self.event_evaluations += 1;
        let v = (self.options.events[i].g)(t, &y[..n], &y[n..2 * n]);
        if v.is_finite() {
            Ok(v)
        } else {
            Err(self.non_finite_event(i, t, v))
        }
    }

    fn direction(&self, i: usize) -> Direction {
        self.options.events[i].direction
    }

    fn is_terminal(&self, i: usize) -> bool {
        self.options.events[i].terminal
    }

    fn event_hit(
        &mut self,
        sys: &mut ReducedOde<'_, M>,
        i: usize,
        t: f64,
        y: &[f64],
    ) -> Result<(), Error> {
        let n = self.n;
        let (q, qd) = (&y[..n], &y[n..2 * n]);
        // How the event moves, before anything is recorded: a failure leaves the hits and their
        // sensitivities aligned.
        let moved = match &sys.sens {
            Some(_) => {
                let e = sys.quadratures();
                let qdd = sys.evaluate(t, q, qd)?.qdd.clone();
                let event = &self.options.events[i];
                Some(
                    sys.sens
                        .as_ref()
                        .and_then(|v| v.at_event(event, t, (q, qd, &qdd), &y[2 * n..e])),
                )
            }
            None => None,
        };
        self.sol.events.push(EventHit {
            index: i,
            t,
            q: q.to_vec(),
            qd: qd.to_vec(),
        });
        if let (Some(record), Some(moved)) = (&mut self.sol.sensitivities, moved) {
            record.events.push(moved);
        }
        Ok(())
    }

    fn terminated(&mut self, i: usize) {
        self.sol.status = Status::Terminated { event: i };
    }

    fn event_rounding(&mut self, i: usize, t: f64, y: &[f64], value: f64) -> f64 {
        let n = self.n;
        let g = &self.options.events[i].g;
        let mut calls = 0;
        let band = start_rounding(
            &mut |t, q, qd| {
                calls += 1;
                g(t, q, qd)
            },
            t,
            &y[..n],
            &y[n..2 * n],
            value,
        );
        self.event_evaluations += calls;
        band
    }

    fn unarmed_at_start(&mut self, i: usize, value: f64) {
        self.sol.warnings.push(Warning::EventZeroAtStart {
            index: i,
            name: self.options.events[i].name.clone(),
            value,
            armed_by: None,
        });
    }

    fn armed(&mut self, i: usize, t: f64) {
        for w in &mut self.sol.warnings {
            match w {
                Warning::EventZeroAtStart {
                    index, armed_by, ..
                } if *index == i => *armed_by = Some(t),
                _ => {}
            }
        }
    }

    fn project(
        &mut self,
        sys: &mut ReducedOde<'_, M>,
        t: f64,
        y: &mut [f64],
    ) -> Result<bool, Error> {
        let Some(p) = self.options.projection else {
            return Ok(false);
        };
        if sys.model.sizes().1 == 0 {
            return Ok(false);
        }
        let n = self.n;
        let (q, rest) = y.split_at_mut(n);
        let qd = &mut rest[..n];
        // Positions onto h = 0 first (holonomic constraints), then velocities onto f = 0 and ḣ = 0.
        let moved = project_positions(sys.model, &mut sys.ws, t, q, qd, p)?;
        let iterations = moved + project_velocity(sys.model, &mut sys.ws, t, q, qd, p)?;
        sys.stats.projections += 1;
        sys.stats.projection_iterations += iterations;
        Ok(iterations > 0)
    }
}

/// The options of [`solve_ode`]: the same [`Options`] as [`solve`]. A plain system has no
/// constraints to project onto and no `(q, q̇)` to give event functions, so [`solve_ode`] refuses
/// events and projection, and records the state only, whatever [`Options::record`] says.
pub type OdeOptions = Options;

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
    fn last_recorded(&self) -> Option<f64> {
        self.sol.t.last().copied()
    }
    fn n_events(&self) -> usize {
        0
    }
    fn event_value(&mut self, _i: usize, _t: f64, _y: &[f64]) -> Result<f64, Error> {
        Ok(0.0)
    }
    fn direction(&self, _i: usize) -> Direction {
        Direction::Either
    }
    fn is_terminal(&self, _i: usize) -> bool {
        false
    }
    fn event_hit(&mut self, _sys: &mut S, _i: usize, _t: f64, _y: &[f64]) -> Result<(), Error> {
        Ok(())
    }
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
    check_finite("t0", std::slice::from_ref(&t0))?;
    check_finite("y0", y0)?;
    if y0.len() != sys.dim() {
        return Err(Error::InvalidOption {
            name: "y0 (length)",
            value: y0.len() as f64,
            hint: "the initial state must have the system's dimension",
        });
    }
    if !options.events.is_empty() || options.projection.is_some() {
        return Err(Error::InvalidOption {
            name: "events or projection",
            value: options.events.len() as f64,
            hint: "a plain first-order system has no (q, q̇) for events or constraints to project \
                   onto: use solve with a model for these",
        });
    }
    if !options.sensitivities.is_empty() {
        return Err(Error::Sensitivity {
            what: "a plain first-order system has no parameters or equations to differentiate; \
                   use solve with a model, or add the variational equations to the system"
                .to_string(),
        });
    }
    let controlled = sys.controlled_dim();
    let settings = LoopSettings::new(options, &method, t0, controlled, controlled)?;
    let mut sol = OdeSolution {
        t: Vec::new(),
        y: Vec::new(),
        stats: Stats::default(),
        error: None,
    };
    let mut run = Progress::start(t0, y0.to_vec());
    let outcome = step_loop(
        sys,
        &mut PlainHooks { sol: &mut sol },
        &method,
        &settings,
        &mut run,
    );
    if outcome.is_err() && sol.t.last() != Some(&run.t) {
        sol.t.push(run.t);
        sol.y.push(run.y);
    }
    sol.error = outcome.err();
    sol.stats = run.counts;
    Ok(sol)
}

/// Whether `steps` steps that advanced `t` by `advanced` were held at the bound `max_step`: at
/// least half of it each on average.
fn held_at_max_step(max_step: Option<f64>, steps: usize, advanced: f64) -> bool {
    max_step.is_some_and(|h| advanced.abs() >= 0.5 * h * steps as f64)
}

/// Whether a trial step's outcome means "the step left the model's domain or the floating-point
/// range": such a step is retried smaller rather than failing at once.
fn left_domain(trial: &Result<f64, Error>, y_new: &[f64]) -> bool {
    match trial {
        Ok(e) => !e.is_finite() || y_new.iter().any(|v| !v.is_finite()),
        Err(Error::NonFiniteEvaluation { .. }) => true,
        Err(_) => false,
    }
}

/// Per-event state of the step loop: the value at the last step end, whether the function was
/// zero at the start (within the rounding of the state) and has not left zero yet, and that
/// rounding.
struct EventState {
    g: Vec<f64>,
    zero_at_start: Vec<bool>,
    rounding: Vec<f64>,
    /// Scratch for the samples of one step.
    pts: Vec<(f64, f64)>,
}

/// Where a step loop has got to: the last accepted time and state, and the steps counted so far.
/// It starts at the initial point and is what is left when the loop returns, on failure too.
pub(crate) struct Progress {
    /// The time of the last accepted state.
    pub t: f64,
    /// The last accepted state.
    pub y: Vec<f64>,
    /// Accepted and rejected steps.
    pub counts: Stats,
}

impl Progress {
    /// At `(t0, y0)`, no step taken.
    pub(crate) fn start(t0: f64, y0: Vec<f64>) -> Self {
        Self {
            t: t0,
            y: y0,
            counts: Stats::default(),
        }
    }
}

/// The step loop shared by every driver: step-size control, dense output at requested times, event
/// location, projection and recording, from and to `progress`.
pub(crate) fn step_loop<S: OdeSystem, H: Hooks<S>, Me: Method>(
    sys: &mut S,
    hooks: &mut H,
    method: &Me,
    settings: &LoopSettings<'_>,
    progress: &mut Progress,
) -> Result<(), Error> {
    let Progress {
        t: t_last,
        y,
        counts,
    } = progress;
    let (t0, y) = (*t_last, &mut y[..]);
    let options = settings.options;
    let t_end = options.t_end;
    let norm = &settings.norm;
    let info = &settings.info;
    let controller = &settings.controller;
    hooks.record(sys, t0, y)?;
    // The events at the start, also for a run over no time (a check of the start): one zero
    // there, within the rounding of the state, is not armed until it leaves zero.
    let n_events = hooks.n_events();
    let mut events = EventState {
        g: vec![0.0; n_events],
        zero_at_start: vec![false; n_events],
        rounding: vec![0.0; n_events],
        pts: Vec::with_capacity(if n_events > 0 {
            options.event_samples + 2
        } else {
            0
        }),
    };
    for i in 0..n_events {
        let g0 = hooks.event_value(i, t0, y)?;
        let rounding = hooks.event_rounding(i, t0, y, g0);
        events.rounding[i] = rounding;
        if g0.abs() <= rounding {
            events.zero_at_start[i] = true;
            hooks.unarmed_at_start(i, g0);
        } else {
            events.g[i] = g0;
        }
    }
    if t_end == t0 {
        return Ok(());
    }
    let dir = (t_end - t0).signum();
    let dim = y.len();
    let mut stepper = method.stepper(dim);
    stepper.set_dense_output(n_events > 0 || matches!(options.output, Output::Times(_)));
    stepper.reset(sys, t0, y)?;
    let mut pending_times: Vec<f64> = match &options.output {
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
    let h_max = options
        .max_step
        .unwrap_or(f64::INFINITY)
        .min((t_end - t0).abs());

    let mut h = match info.fixed_step {
        Some(h) => h,
        None => match options.initial_step {
            Some(h) => h.abs(),
            None => initial_step(sys, t0, y, t_end, norm, dir, info.order)?,
        },
    }
    .min(h_max)
        * dir;

    let adaptive = info.fixed_step.is_none();
    // A fixed step is set again before each step: the rounding of the one before must not carry.
    let h_fixed = h;
    // The user's bound on the step, where it is below the method's own fixed step.
    let bound = options
        .max_step
        .filter(|&m| info.fixed_step.is_none_or(|f| m < f));
    let q = info.control_order;
    let mut t = t0;
    let mut y_new = vec![0.0; dim];
    let mut buf = vec![0.0; dim];
    let mut steps = 0usize;
    let mut rejected_last = false;
    let mut err_prev = 1e-4f64;
    // Where the second half of the allowed steps began: steps that advance `t` by a thousandth of
    // what the first half did have slowed at a point (a kink, a singular point, a blow-up, or a
    // fast regular phase), not merely been many.
    let mut t_half = t0;
    let mut approach = Approach::default();
    loop {
        if steps >= options.max_steps {
            let stalled = adaptive
                && options.max_steps >= 100
                && (t - t_half).abs() <= 1e-3 * (t_half - t0).abs();
            return Err(Error::MaxSteps {
                stalled,
                t,
                max_steps: options.max_steps,
                hint: if held_at_max_step(bound, steps, t - t0) {
                    "the steps are held at Options::max_step (they took at least half of it on \
                     average): raise it, or Options::max_steps; tolerances do not change them"
                } else if !adaptive {
                    "raise Options::max_steps or take a larger fixed step"
                } else if stalled {
                    "the second half of the steps advanced t by less than a thousandth of what \
                     the first half did: the motion changes ever faster here. At a kink of the \
                     model (an absolute value or a square root at zero), a singular point or a \
                     blow-up the steps shrink to nothing and more steps will not pass it: check \
                     the model near this state (Problem::equations_at). In a fast but regular \
                     phase (a close passage of an orbit) raise Options::max_steps"
                } else {
                    "raise Options::max_steps or loosen the tolerances"
                },
            });
        }
        if steps == options.max_steps / 2 {
            t_half = t;
        }
        steps += 1;
        if !adaptive {
            h = h_fixed;
        }
        h = approach.bound(t, h)?;
        let remaining = t_end - t;
        // Land exactly on t_end; avoid a sliver of a last step by stretching within 1%.
        let last = (h * 1.01).abs() >= remaining.abs();
        if last {
            h = remaining;
        }
        if h.abs() <= time_resolution(t) && !last {
            return Err(Error::StepSizeTooSmall {
                t,
                h,
                advice: info.advice,
            });
        }
        if !last {
            // Step by what `t` can hold: `t + h` is rounded to the spacing of `t`, and a state
            // advanced by the unrounded `h` would part from its time by up to half that spacing
            // at every step (from t0 = 1e9 with h = 1e-3, 2.4e-5 of each step).
            h = (t + h) - t;
        }
        let trial = stepper.try_step(sys, t, h, y, &mut y_new, norm);
        if left_domain(&trial, &y_new) {
            if !adaptive {
                return Err(match trial {
                    Err(e) => e,
                    Ok(_) => Error::NonFiniteState { t, h },
                });
            }
            // A trial stage left the model's domain or the floating-point range: retry smaller.
            sys.left_domain();
            counts.rejected_steps += 1;
            h *= 0.25;
            rejected_last = true;
            if h.abs() <= time_resolution(t.abs().max(f64::MIN_POSITIVE)) {
                return Err(match trial {
                    Err(e) => e,
                    Ok(_) => Error::NonFiniteState { t, h },
                });
            }
            continue;
        }
        let err = trial?;
        if adaptive && err > 1.0 {
            counts.rejected_steps += 1;
            h *= controller.rejected(err, q);
            rejected_last = true;
            continue;
        }

        // Accepted, unless a singular point lies inside the step.
        counts.accepted_steps += 1;
        if let Err(e) = stepper.accept(sys, t, h, y, &y_new) {
            // Approach the point instead (`Approach`): this step is rejected.
            approach.found(e, t, adaptive)?;
            counts.accepted_steps -= 1;
            counts.rejected_steps += 1;
            stepper.reset(sys, t, y)?;
            rejected_last = true;
            continue;
        }
        let t_new = if last { t_end } else { t + h };
        // Stiffness ends the run after this step, once its events and output times are taken.
        let stiff = stepper.stiffness();

        // Events on the dense output of [t, t_new].
        let terminal = if n_events > 0 {
            find_events::<S, H, _>(
                sys,
                hooks,
                &mut stepper,
                &mut events,
                (t, t_new, h, dir),
                &y_new,
                &mut buf,
                options.event_samples,
            )?
        } else {
            None
        };
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
            y.copy_from_slice(&y_new);
            *t_last = ts;
            hooks.event_hit(sys, i, ts, y)?;
            // An event at the start of the step (at t0, say) is at a point already recorded.
            if !(h_event == 0.0 && hooks.last_recorded() == Some(ts)) {
                hooks.record(sys, ts, y)?;
            }
            hooks.terminated(i);
            return Ok(());
        }

        if hooks.project(sys, t_new, &mut y_new)? {
            stepper.reset(sys, t_new, &y_new)?;
        }
        y.copy_from_slice(&y_new);
        t = t_new;
        *t_last = t;
        if last || stiff.is_some() || matches!(options.output, Output::Steps) {
            hooks.record(sys, t, y)?;
        }
        if let Some(h_lambda) = stiff {
            return Err(Error::Stiff {
                t,
                h_lambda,
                suggestion: "Rodas4",
            });
        }
        if last {
            return Ok(());
        }
        if adaptive {
            h *= controller.accepted(err, err_prev, q, rejected_last);
            err_prev = err.max(1e-4);
            if h.abs() > h_max {
                h = h_max * dir;
            }
        }
        rejected_last = false;
    }
}

/// Looks for zeros of the event functions on the dense output of the accepted step `[t, t_new]`.
///
/// Each function is sampled at `samples` equally spaced interior points and at `t_new`. A sign
/// change between neighbouring samples is a crossing, located by regula falsi. Where the samples
/// keep their sign but `|g|` has a local minimum at an interior sample, the function may have
/// crossed zero twice in between (a trajectory grazing a level): the extremum of `g` there is
/// searched by golden section, and if `g` changes sign at it both crossings are located. So a pair
/// of crossings is found whenever the extremum between them is bracketed by samples; a pair is
/// missed only when both zeros and the extremum lie within one sampling interval at a step's end.
/// Non-terminal events are reported in time order; returns the first terminal one.
///
/// An event function zero at the start time (within the rounding of the state) does not fire as
/// it leaves zero, in either direction: it is armed at the first sample beyond that rounding and
/// counts its crossings from the sign it has there.
#[allow(clippy::too_many_arguments)]
fn find_events<S: OdeSystem, H: Hooks<S>, St: Stepper>(
    sys: &mut S,
    hooks: &mut H,
    stepper: &mut St,
    events: &mut EventState,
    (t, t_new, h, dir): (f64, f64, f64, f64),
    y_new: &[f64],
    buf: &mut [f64],
    samples: usize,
) -> Result<Option<(usize, f64)>, Error> {
    let n_events = events.g.len();
    let mut hits: Vec<(usize, f64)> = Vec::new();
    let mut pts = std::mem::take(&mut events.pts);
    for i in 0..n_events {
        let direction = hooks.direction(i);
        let terminal = hooks.is_terminal(i);
        let mut value = |hooks: &mut H, stepper: &mut St, buf: &mut [f64], s: f64| {
            stepper.interpolate((s - t) / h, buf);
            hooks.event_value(i, s, buf)
        };
        pts.clear();
        pts.push((t, events.g[i]));
        for s in 1..=samples {
            let b = t + h * (s as f64 / (samples + 1) as f64);
            pts.push((b, value(hooks, stepper, buf, b)?));
        }
        let g_end = hooks.event_value(i, t_new, y_new)?;
        pts.push((t_new, g_end));
        events.g[i] = g_end;

        let mut start = 0;
        if events.zero_at_start[i] {
            // Leaving zero is not a crossing, in whichever direction: the event is armed at the
            // first sample beyond the rounding of the start, and counts crossings from there.
            let rounding = events.rounding[i];
            let Some(j) = pts.iter().position(|p| p.1.abs() > rounding) else {
                continue;
            };
            events.zero_at_start[i] = false;
            hooks.armed(i, pts[j].0);
            start = j;
        }

        for j in start..pts.len() - 1 {
            let ((a, ga), (b, gb)) = (pts[j], pts[j + 1]);
            // A sample exactly at zero between samples of one sign is a touch, not a crossing.
            let touch = gb == 0.0
                && pts[j + 2..]
                    .iter()
                    .find(|p| p.1 != 0.0)
                    .is_some_and(|p| p.1.signum() == ga.signum());
            if crosses(direction, ga, gb) && !touch {
                hits.push((i, root(hooks, stepper, buf, &mut value, (a, ga), (b, gb))?));
                if terminal {
                    break;
                }
                continue;
            }
            // A grazing approach: |g| smallest at the interior sample b, one sign throughout.
            let Some(&(c, gc)) = pts.get(j + 2) else {
                continue;
            };
            let one_sign = (ga > 0.0 && gb > 0.0 && gc > 0.0) || (ga < 0.0 && gb < 0.0 && gc < 0.0);
            if !(one_sign && gb.abs() < ga.abs() && gb.abs() <= gc.abs()) {
                continue;
            }
            let Some((x, gx)) = dip(hooks, stepper, buf, &mut value, (a, b, c), gb)? else {
                continue;
            };
            if crosses(direction, ga, gx) {
                hits.push((i, root(hooks, stepper, buf, &mut value, (a, ga), (x, gx))?));
                if terminal {
                    break;
                }
            }
            if crosses(direction, gx, gc) {
                hits.push((i, root(hooks, stepper, buf, &mut value, (x, gx), (c, gc))?));
                if terminal {
                    break;
                }
            }
        }
    }
    events.pts = pts;
    hits.sort_by(|a, b| (dir * a.1).total_cmp(&(dir * b.1)));
    for &(i, ts) in &hits {
        if hooks.is_terminal(i) {
            return Ok(Some((i, ts)));
        }
        stepper.interpolate((ts - t) / h, buf);
        // As every recorded point, the state of a crossing is projected where projection is on.
        hooks.project(sys, ts, buf)?;
        hooks.event_hit(sys, i, ts, buf)?;
    }
    Ok(None)
}

/// The crossing of `g` between `(a, g(a))` and `(b, g(b))`, by regula falsi on the dense output.
fn root<H, St>(
    hooks: &mut H,
    stepper: &mut St,
    buf: &mut [f64],
    value: &mut impl FnMut(&mut H, &mut St, &mut [f64], f64) -> Result<f64, Error>,
    (a, ga): (f64, f64),
    (b, gb): (f64, f64),
) -> Result<f64, Error> {
    let mut failure = None;
    let at = |s: f64| match value(hooks, stepper, buf, s) {
        Ok(v) => v,
        Err(e) => {
            failure.get_or_insert(e);
            f64::NAN
        }
    };
    let (r, _) = locate_root(at, a, ga, b, gb);
    match failure {
        Some(e) => Err(e),
        None => Ok(r),
    }
}

/// Golden-section search for a sign change of `g` on `[a, c]`, where `g(b)` (`a < b < c` in the
/// direction of integration) has the sign of `g` at both ends and the smallest magnitude of the
/// three: minimises `|g|` along the dip and stops as soon as `g` changes sign. Returns that point
/// and its value, or `None` when the extremum keeps the sign (or only touches zero).
fn dip<H, St>(
    hooks: &mut H,
    stepper: &mut St,
    buf: &mut [f64],
    value: &mut impl FnMut(&mut H, &mut St, &mut [f64], f64) -> Result<f64, Error>,
    (a, b, c): (f64, f64, f64),
    gb: f64,
) -> Result<Option<(f64, f64)>, Error> {
    const R: f64 = 0.381_966_011_250_105_1; // 2 − φ
    let s = gb.signum();
    let (mut lo, mut hi) = (a, c);
    let (mut x, mut fx) = (b, s * gb);
    for _ in 0..60 {
        if (hi - lo).abs() <= 8.0 * f64::EPSILON * x.abs().max(1.0) {
            break;
        }
        // Probe the larger of the two sub-intervals around the best point.
        let u = if (hi - x).abs() > (x - lo).abs() {
            x + R * (hi - x)
        } else {
            x - R * (x - lo)
        };
        let gu = value(hooks, stepper, buf, u)?;
        // Only a change of sign: a zero with the sign kept on both sides is a touch.
        if s * gu < 0.0 {
            return Ok(Some((u, gu)));
        }
        if s * gu < fx {
            if (u - x) * (hi - lo) > 0.0 {
                lo = x;
            } else {
                hi = x;
            }
            (x, fx) = (u, s * gu);
        } else if (u - x) * (hi - lo) > 0.0 {
            hi = u;
        } else {
            lo = u;
        }
    }
    Ok(None)
}

/// Hairer's starting step (Solving ODEs I, II.4, the routine `HINIT` of DOPRI5 and DOP853): balances
/// `h·|F|` against the tolerance and the second derivative estimated from one Euler step, for a
/// method of order `order`.
fn initial_step<S: OdeSystem>(
    sys: &mut S,
    t0: f64,
    y0: &[f64],
    t_end: f64,
    norm: &ErrorNorm,
    dir: f64,
    order: u32,
) -> Result<f64, Error> {
    let dim = y0.len();
    let p = order as f64;
    // f(t0, y0), the Euler step and f there, in one allocation.
    let mut work = vec![0.0; 3 * dim];
    let (f0, rest) = work.split_at_mut(dim);
    let (y1, f1) = rest.split_at_mut(dim);
    sys.rhs(t0, y0, f0)?;
    // Weighted RMS norms with the scale of y0 alone, as in HINIT.
    let rms = |v: &dyn Fn(usize) -> f64| {
        let n = norm.len() as f64;
        // A component with no scale at y0 (zero, under a purely relative tolerance) gets its
        // scale from where the step takes it: it does not set the first step.
        let ratio = |i: usize| {
            let scale = norm.scale(i, y0[i], 0.0);
            if scale > f64::MIN_POSITIVE {
                v(i) / scale
            } else {
                0.0
            }
        };
        let s: f64 = (0..norm.len()).map(|i| ratio(i).powi(2)).sum();
        if s.is_finite() {
            return (s / n).sqrt();
        }
        // The squares overflow (a state or a rate near 1e150 against its tolerance): the same
        // norm, scaled by its largest ratio first.
        let largest = (0..norm.len()).fold(0.0f64, |m, i| m.max(ratio(i).abs()));
        if !largest.is_finite() {
            // A ratio beyond the floating-point range: the norm is too.
            return f64::INFINITY;
        }
        let s: f64 = (0..norm.len()).map(|i| (ratio(i) / largest).powi(2)).sum();
        largest * (s / n).sqrt()
    };
    // `log2` of the same norm, finite where the norm itself overflows but every `v(i)` is finite
    // (a rate of 1e300 against a tolerance of 1e-11): `v` is scaled by a power of two first.
    let rms_log2 = |v: &dyn Fn(usize) -> f64| {
        let largest = (0..norm.len()).fold(0.0f64, |m, i| m.max(v(i).abs()));
        if !largest.is_finite() || largest == 0.0 {
            return largest.log2();
        }
        let e = largest.log2().floor();
        // 2^−e in two factors, each within the range of f64.
        let (a, b) = ((-0.5 * e).floor().exp2(), (-e - (-0.5 * e).floor()).exp2());
        let scaled = rms(&|i| v(i) * a * b);
        e + scaled.log2()
    };
    let d0 = rms(&|i| y0[i]);
    let d1 = rms(&|i| f0[i]);
    // Where a norm overflows, the quotients below are formed from the norms' logarithms, computed
    // only then.
    let overflow = !(d0.is_finite() && d1.is_finite());
    let mut h0 = if d0 < 1e-5 || d1 < 1e-5 {
        1e-6
    } else if overflow {
        0.01 * (rms_log2(&|i| y0[i]) - rms_log2(&|i| f0[i])).exp2()
    } else {
        0.01 * d0 / d1
    };
    if h0.is_nan() || h0 <= 0.0 {
        // Rates beyond the floating-point range against their scale: start small (a step that
        // still leaves the range is shortened by the step loop).
        h0 = 1e-6 * (t_end - t0).abs();
    }
    h0 = h0.min((t_end - t0).abs());
    // The Euler step may leave the model's domain (slow rates against a large state make a long
    // guess): it is shortened, as a trial step would be, and the guess is never a failure of its
    // own except where the domain ends within rounding of `t0`. A shortened guess also bounds
    // the first step.
    let mut shortened = false;
    loop {
        for i in 0..dim {
            y1[i] = y0[i] + dir * h0 * f0[i];
        }
        // Classified as a trial step's outcome is (`left_domain`), with no error estimate.
        let probe = sys.rhs(t0 + dir * h0, y1, f1).map(|()| 0.0);
        if left_domain(&probe, y1) && h0 > time_resolution(t0.abs().max(f64::MIN_POSITIVE)) {
            h0 *= 0.25;
            shortened = true;
            continue;
        }
        probe?;
        break;
    }
    let d2 = rms(&|i| f1[i] - f0[i]) / h0;
    let h1 = if d1.max(d2) <= 1e-15 {
        (h0 * 1e-3).max(1e-6)
    } else if overflow || !d2.is_finite() {
        let l2 = rms_log2(&|i| f1[i] - f0[i]) - h0.log2();
        ((0.01f64.log2() - rms_log2(&|i| f0[i]).max(l2)) / p).exp2()
    } else {
        (0.01 / d1.max(d2)).powf(1.0 / p)
    };
    let h = (if shortened { h0 } else { 100.0 * h0 }).min(h1);
    // Rates so large that the guess underflows to zero: start small and let the error control
    // grow the step.
    Ok(if h > 0.0 && h.is_finite() {
        h
    } else if shortened {
        h0
    } else {
        1e-6 * (t_end - t0).abs()
    })
}

#[cfg(test)]
mod tests {
    use super::super::events::Event;
    use super::super::testing::Sys;
    use super::super::Dopri5;
    use super::*;

    #[test]
    fn solve_ode_refuses_events_projection_and_sensitivities() {
        let mut sys = Sys::explicit(1, |_t: f64, y: &[f64], dy: &mut [f64]| dy[0] = -y[0]);
        let with_event = Options::until(1.0).event(Event::new("zero", |_t, q, _qd| q[0]));
        let run = solve_ode(&mut sys, Dopri5::default(), 0.0, &[1.0], &with_event);
        assert!(matches!(run, Err(Error::InvalidOption { .. })));
        let projected = Options::until(1.0).project(Default::default());
        let run = solve_ode(&mut sys, Dopri5::default(), 0.0, &[1.0], &projected);
        assert!(matches!(run, Err(Error::InvalidOption { .. })));
        let seeded = Options::until(1.0).sensitivity(crate::Seed::position(0));
        let run = solve_ode(&mut sys, Dopri5::default(), 0.0, &[1.0], &seeded);
        assert!(matches!(run, Err(Error::Sensitivity { .. })));
    }
}
