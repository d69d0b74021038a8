//! What the driver is asked to do: the end time, tolerances, output, events, projection.

use std::sync::Arc;

use super::events::Event;
use super::projection::Projection;
use super::Controller;
use crate::error::Error;
use crate::problem::check_finite;
use crate::sensitivity::Seed;

/// Absolute tolerance: one number for every component, or one per component of `(q, q̇)`
/// (length `2n`: the `n` positions, then the `n` velocities).
#[derive(Clone, Debug, PartialEq)]
pub enum Atol {
    /// The same absolute tolerance for every component.
    Scalar(f64),
    /// One absolute tolerance per component of `(q, q̇)`, length `2n`.
    PerComponent(Vec<f64>),
}

/// Where the solution is recorded.
#[derive(Clone, Debug, PartialEq)]
pub enum Output {
    /// At every accepted step (and at the start, the end and terminal events).
    Steps,
    /// At these times only, by dense output (plus the start and the final point), recorded in
    /// the direction of integration whatever their order here; a time given twice is recorded
    /// twice, but for the start and the final point, each recorded once however often it is
    /// listed.
    Times(Vec<f64>),
    /// At the start and the final point only.
    Final,
}

/// How much is recorded at each output point. Each level includes the ones before it; a problem
/// pays only for what it records.
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Record {
    /// `t`, `q`, `q̇` only.
    State,
    /// Also `q̈`, `μ`, `Φ` and the residual `f` (one evaluation of the equations per output point).
    Dynamics,
    /// Also `E`, the work `W_Φ` of the Chetaev force and `∫∂L/∂t dt` (two quadratures carried along
    /// with the motion, outside error control).
    Energy,
}

/// The largest [`Options::event_samples`]: beyond it, bounding the step with
/// [`Options::max_step`] resolves close crossings for less.
pub const MAX_EVENT_SAMPLES: usize = 10_000;

/// Options of one solve. Build with [`Options::until`] and the builder methods.
#[derive(Clone, Debug)]
pub struct Options {
    /// The end time; earlier than the start time integrates backward.
    pub t_end: f64,
    /// Relative tolerance: 0 (with a positive `atol`), or 100 ulps (`2.2e-14`) or more. A tolerance
    /// far above 1 never rejects a step: with [`Options::initial_step`] and [`Options::max_step`]
    /// both `h`, it holds an adaptive method to fixed steps `h`, for studying its order in `h`.
    pub rtol: f64,
    /// Absolute tolerance.
    pub atol: Atol,
    /// First step size (its sign is ignored); chosen automatically when `None`.
    pub initial_step: Option<f64>,
    /// Largest step size; unbounded when `None`.
    pub max_step: Option<f64>,
    /// Step limit (accepted plus rejected).
    pub max_steps: usize,
    /// Where to record.
    pub output: Output,
    /// What to record.
    pub record: Record,
    /// Event functions.
    pub events: Vec<Event>,
    /// Projection onto `f = 0` after each accepted step, at every recorded point and at the state
    /// of every crossing of an event (off by default).
    pub projection: Option<Projection>,
    /// Interior points of each step at which event functions are sampled on the dense output
    /// (besides the step's end), so that a function crossing zero twice within one step is seen
    /// when its zeros are more than `h/(event_samples + 1)` apart. Default 4, at most
    /// [`MAX_EVENT_SAMPLES`].
    pub event_samples: usize,
    /// Singular points: the run stops with [`Error::SingularPoint`] where a constraint's gradient
    /// `∂f_a/∂q̇` passes through zero between two accepted steps (taken as varying linearly between
    /// them, its smallest size falls below this fraction of its larger size at the step's ends,
    /// and below half its smaller one), where
    /// the gradients of two or more constraints become linearly dependent between two accepted
    /// steps (the orientation of the frame they span reverses, with less than this fraction of
    /// them leaving the span they had; for as many constraints as coordinates, `det ∂f/∂q̇`
    /// changing sign), or where the size of `W = ∂²L/∂q̇²` changes by more than its inverse within
    /// one step. A gradient or a metric that grows or shrinks steadily is not singular, however
    /// far it goes, nor are gradients that turn fast. Also, once a trial step has left the
    /// model's domain, where a constraint's gradient has grown more than a thousandfold since the
    /// start and the velocity misses it by a quarter of its terms or more (away from a turning
    /// point, where those terms are below a thousandth of their largest size): the constraint ends
    /// there ([`Singularity::Unbounded`](crate::Singularity::Unbounded), the curve
    /// `y = −√(1 − x²)` at `x = ±1`). Default `1e-8`; `0` turns the check off.
    pub rank_tolerance: f64,
    /// Step-size controller; the method's own (its [`MethodInfo::controller`]) when `None`.
    ///
    /// [`MethodInfo::controller`]: super::MethodInfo::controller
    pub controller: Option<Controller>,
    /// Directions in which the derivatives of the motion are carried along with it (none by
    /// default); see [`Seed`] and [`Sensitivities`](crate::Sensitivities).
    pub sensitivities: Vec<Seed>,
    /// Whether the sensitivities are under error control, with the same tolerances as the
    /// state (off by default: the step size is then the motion's, and the sensitivities are as
    /// accurate as the method is along it).
    pub sensitivity_control: bool,
}

impl Options {
    /// Where a solve with these options is known to end: `t_end`, or `None` where a terminal
    /// event may end it before (the tiering then counts on the right-hand sides so far only).
    pub fn horizon(&self) -> Option<f64> {
        (!self.events.iter().any(|e| e.terminal)).then_some(self.t_end)
    }

    /// Integrate to `t_end` with `rtol = 1e-6`, `atol = 1e-9`, output at every step, everything
    /// recorded, no events, no projection.
    pub fn until(t_end: f64) -> Self {
        Self {
            t_end,
            rtol: 1e-6,
            atol: Atol::Scalar(1e-9),
            initial_step: None,
            max_step: None,
            max_steps: 1_000_000,
            output: Output::Steps,
            record: Record::Energy,
            events: Vec::new(),
            projection: None,
            event_samples: 4,
            rank_tolerance: 1e-8,
            controller: None,
            sensitivities: Vec::new(),
            sensitivity_control: false,
        }
    }

    /// Checks every option that does not depend on the method, for a model with `n` coordinates
    /// whose motion starts at `t0`: finite `t_end`, tolerances (a per-component `atol` of length
    /// `2n`), step bounds, the step limit, output times between `t0` and `t_end`, the rank
    /// tolerance, the projection's tolerance and the controller. The error names the option and
    /// what to try.
    ///
    /// [`solve`](crate::solve) calls it before it takes a step (with the method's own checks); an
    /// integrator outside the crate calls it so that its users get the same answers for the same
    /// options, then refuses what it cannot honour itself.
    pub fn validate(&self, t0: f64, n: usize) -> Result<(), Error> {
        self.validate_components(t0, n.saturating_mul(2))
    }

    /// [`Options::validate`] for a system whose per-component `atol` has `block` entries.
    pub(crate) fn validate_components(&self, t0: f64, block: usize) -> Result<(), Error> {
        let invalid = |name: &'static str, value: f64, hint: &'static str| {
            Err(Error::InvalidOption { name, value, hint })
        };
        let positive = |name: &'static str, v: f64, hint: &'static str| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                invalid(name, v, hint)
            }
        };
        check_finite("t_end", std::slice::from_ref(&self.t_end))?;
        if !(self.rtol.is_finite() && self.rtol >= 0.0) {
            return invalid(
                "rtol",
                self.rtol,
                "the relative tolerance must be finite and non-negative; 1e-6 to 1e-13 are typical",
            );
        }
        if self.rtol < 100.0 * f64::EPSILON && self.rtol != 0.0 {
            return invalid(
                "rtol",
                self.rtol,
                "below 100 ulps (2.2e-14) no step size can meet the tolerance in f64; use 1e-13 or more",
            );
        }
        let atol = match &self.atol {
            Atol::Scalar(a) => std::slice::from_ref(a),
            Atol::PerComponent(v) if v.len() != block => {
                return invalid(
                    "atol (length)",
                    v.len() as f64,
                    "give one absolute tolerance per controlled component: for a model, the n \
                     positions then the n velocities, 2n in all",
                );
            }
            Atol::PerComponent(v) => v.as_slice(),
        };
        for &a in atol {
            if !(a.is_finite() && a >= 0.0) {
                return invalid(
                    "atol",
                    a,
                    "absolute tolerances must be finite and non-negative",
                );
            }
            if self.rtol == 0.0 && a < 1e-300 {
                return invalid(
                    "atol",
                    a,
                    "with rtol = 0 the absolute tolerance alone sets the accuracy, and it must be \
                     positive and representable; give rtol > 0, or an atol such as 1e-12",
                );
            }
        }
        if let Some(h) = self.initial_step {
            positive("initial_step", h.abs(), "a finite non-zero first step")?;
        }
        if let Some(h) = self.max_step {
            positive("max_step", h, "a finite positive bound")?;
            if h <= super::time_resolution(t0).max(super::time_resolution(self.t_end)) {
                return invalid(
                    "max_step",
                    h,
                    "steps this short no longer change t (they are below 4 ulps of t over the \
                     interval): give a larger bound, or count time from a nearer origin",
                );
            }
        }
        if self.max_steps == 0 {
            return invalid("max_steps", 0.0, "allow at least one step");
        }
        if let Output::Times(ts) = &self.output {
            check_finite("output time", ts)?;
            let (lo, hi) = (t0.min(self.t_end), t0.max(self.t_end));
            if let Some(&time) = ts.iter().find(|&&s| s < lo || s > hi) {
                return Err(Error::OutputTimeOutOfRange {
                    time,
                    t0,
                    t_end: self.t_end,
                });
            }
        }
        if !(self.rank_tolerance.is_finite() && (0.0..1.0).contains(&self.rank_tolerance)) {
            return invalid(
                "rank_tolerance",
                self.rank_tolerance,
                "a fraction in [0, 1), such as the default 1e-8 (0 turns the singular-point check off)",
            );
        }
        if self.event_samples > MAX_EVENT_SAMPLES {
            return invalid(
                "event_samples",
                self.event_samples as f64,
                "at most 10000 samples per step; to see crossings closer together, bound the step \
                 with max_step, which also samples more densely",
            );
        }
        if let Some(p) = &self.projection {
            positive(
                "projection tol",
                p.tol,
                "a small positive relative residual such as 1e-14",
            )?;
            if p.tol < f64::EPSILON {
                return invalid(
                    "projection tol",
                    p.tol,
                    "below the rounding error of f in f64 (2.2e-16 of its terms) no projection can \
                     reach it; use 1e-14 or more (the default is 1e-12)",
                );
            }
            if p.tol >= 1.0 {
                return invalid(
                    "projection tol",
                    p.tol,
                    "a relative residual of 1 or more leaves a velocity as far off as its own size \
                     alone; use less than 1 (the default is 1e-12)",
                );
            }
            if p.max_iterations == 0 {
                return invalid(
                    "projection max_iterations",
                    0.0,
                    "allow at least one Newton iteration (Projection::default() allows 10)",
                );
            }
        }
        if let Some(c) = &self.controller {
            c.validate()?;
        }
        Ok(())
    }

    /// The absolute tolerance of each of `controlled` components: the scalar, or the
    /// per-component tolerances repeated (for the sensitivities that follow the state).
    pub(crate) fn atol_of(&self, controlled: usize) -> Vec<f64> {
        match &self.atol {
            Atol::Scalar(a) => vec![*a; controlled],
            Atol::PerComponent(v) => v.iter().copied().cycle().take(controlled).collect(),
        }
    }

    /// Sets the relative and (scalar) absolute tolerance.
    pub fn tolerances(mut self, rtol: f64, atol: f64) -> Self {
        self.rtol = rtol;
        self.atol = Atol::Scalar(atol);
        self
    }

    /// Sets one absolute tolerance per component: the `n` positions `q` first, then the `n`
    /// velocities `q̇` (checked against the model's sizes by [`solve`](crate::solve)).
    pub fn atol_per_component(mut self, atol_q: &[f64], atol_qd: &[f64]) -> Self {
        let mut v = atol_q.to_vec();
        v.extend_from_slice(atol_qd);
        self.atol = Atol::PerComponent(v);
        self
    }

    /// Records on `count` equally spaced times from the start time `t0` to the end time,
    /// both included. A grid needs both ends: a `count` below 2 records the start and the end
    /// only, as [`Options::output_final`].
    pub fn output_grid(self, t0: f64, count: usize) -> Self {
        let t_end = self.t_end;
        let times = match count {
            0 | 1 => return self.output_final(),
            _ => (0..count)
                .map(|i| {
                    if i + 1 == count {
                        t_end
                    } else {
                        t0 + (t_end - t0) * (i as f64 / (count - 1) as f64)
                    }
                })
                .collect(),
        };
        self.output_times(times)
    }

    /// Records at these times only ([`Output::Times`]: in the direction of integration, whatever
    /// their order here).
    pub fn output_times(mut self, times: Vec<f64>) -> Self {
        self.output = Output::Times(times);
        self
    }

    /// Records at the start and the end only.
    pub fn output_final(mut self) -> Self {
        self.output = Output::Final;
        self
    }

    /// Chooses what is recorded.
    pub fn record(mut self, record: Record) -> Self {
        self.record = record;
        self
    }

    /// Adds an event function.
    pub fn event(mut self, event: Event) -> Self {
        self.events.push(event);
        self
    }

    /// Projects onto `f = 0` after each accepted step.
    pub fn project(mut self, projection: Projection) -> Self {
        self.projection = Some(projection);
        self
    }

    /// Sets the first step size.
    pub fn initial_step(mut self, h: f64) -> Self {
        self.initial_step = Some(h);
        self
    }

    /// Bounds the step size.
    pub fn max_step(mut self, h: f64) -> Self {
        self.max_step = Some(h);
        self
    }

    /// Sets the step limit.
    pub fn max_steps(mut self, n: usize) -> Self {
        self.max_steps = n;
        self
    }

    /// Sets the number of interior points of each step at which event functions are sampled.
    pub fn event_samples(mut self, samples: usize) -> Self {
        self.event_samples = samples;
        self
    }

    /// Sets the threshold of the singular-point check (`0` turns it off).
    pub fn rank_tolerance(mut self, tolerance: f64) -> Self {
        self.rank_tolerance = tolerance;
        self
    }

    /// Carries the derivatives of the motion in the direction `seed` along with it (a parameter,
    /// an initial value, or both together); repeat for several.
    pub fn sensitivity(mut self, seed: Seed) -> Self {
        self.sensitivities.push(seed);
        self
    }

    /// Puts the sensitivities under error control (with the state's tolerances; a per-component
    /// `atol` of length `2n` applies to each seed's `∂q`, `∂q̇` as to `q`, `q̇`). A fixed-step
    /// method ([`Rk4`](crate::integrate::Rk4)) has none: with seeds, `solve` refuses it there.
    pub fn sensitivity_control(mut self, on: bool) -> Self {
        self.sensitivity_control = on;
        self
    }

    /// Replaces the method's step-size controller.
    pub fn controller(mut self, controller: Controller) -> Self {
        self.controller = Some(controller);
        self
    }
}

/// An event function `g(t, q, q̇)` on slices of length `n`, shared so options can be cloned across
/// a parameter sweep.
pub type EventFn = Arc<dyn Fn(f64, &[f64], &[f64]) -> f64 + Send + Sync>;
