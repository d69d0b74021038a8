//! What the driver is asked to do: the end time, tolerances, output, events, projection.

use std::sync::Arc;

use nalgebra::SVector;

use super::events::Event;
use super::projection::Projection;

/// Absolute tolerance: one number for every component, or one per component of `(q, q̇)`
/// (length `2N`: the `N` positions, then the `N` velocities).
#[derive(Clone, Debug, PartialEq)]
pub enum Atol {
    /// The same absolute tolerance for every component.
    Scalar(f64),
    /// One absolute tolerance per component of `(q, q̇)`, length `2N`.
    PerComponent(Vec<f64>),
}

/// Where the solution is recorded.
#[derive(Clone, Debug, PartialEq)]
pub enum Output {
    /// At every accepted step (and at the start, the end and terminal events).
    Steps,
    /// At these times only, by dense output (plus the start and the final point).
    Times(Vec<f64>),
    /// At the start and the final point only.
    Final,
}

/// How much is recorded at each output point. Each level includes the ones before it; a problem
/// pays only for what it records.
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

/// Options of one solve. Build with [`Options::until`] and the builder methods.
#[derive(Clone)]
pub struct Options<const N: usize> {
    /// The end time; earlier than the start time integrates backward.
    pub t_end: f64,
    /// Relative tolerance.
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
    pub events: Vec<Event<N>>,
    /// Projection onto `f = 0` after each accepted step and at every recorded point (off by default).
    pub projection: Option<Projection>,
}

impl<const N: usize> std::fmt::Debug for Options<N> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Options")
            .field("t_end", &self.t_end)
            .field("rtol", &self.rtol)
            .field("atol", &self.atol)
            .field("initial_step", &self.initial_step)
            .field("max_step", &self.max_step)
            .field("max_steps", &self.max_steps)
            .field("output", &self.output)
            .field("record", &self.record)
            .field("events", &self.events.len())
            .field("projection", &self.projection)
            .finish()
    }
}

impl<const N: usize> Options<N> {
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
        }
    }

    /// Sets the relative and (scalar) absolute tolerance.
    pub fn tolerances(mut self, rtol: f64, atol: f64) -> Self {
        self.rtol = rtol;
        self.atol = Atol::Scalar(atol);
        self
    }

    /// Sets one absolute tolerance per component: `q` first, then `q̇`.
    pub fn atol_per_component(mut self, atol_q: SVector<f64, N>, atol_qd: SVector<f64, N>) -> Self {
        let mut v = atol_q.as_slice().to_vec();
        v.extend_from_slice(atol_qd.as_slice());
        self.atol = Atol::PerComponent(v);
        self
    }

    /// Records at these times only.
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
    pub fn event(mut self, event: Event<N>) -> Self {
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
}

/// An event function `g(t, q, q̇)`, shared so options can be cloned across a parameter sweep.
pub type EventFn<const N: usize> =
    Arc<dyn Fn(f64, &SVector<f64, N>, &SVector<f64, N>) -> f64 + Send + Sync>;
