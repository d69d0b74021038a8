//! What happened: the recorded motion, its diagnostics, statistics and why it stopped.

use nalgebra::SVector;

use crate::error::Error;
use crate::integrate::events::EventHit;
use crate::integrate::options::Record;
use crate::integrate::system::Stats;

/// Why the integration stopped.
#[derive(Clone, Debug, PartialEq)]
pub enum Status {
    /// The end time was reached.
    Success,
    /// A terminal event fired; the last recorded point is the event.
    Terminated {
        /// Index of the event in the options.
        event: usize,
    },
    /// The integration failed; everything up to the failure is recorded.
    Failed(Error),
}

/// The motion and everything recorded along it. Vectors of diagnostics are empty when the
/// [`Record`] level did not ask for them.
#[derive(Clone, Debug)]
#[must_use = "a solution carries a status that says whether the integration succeeded"]
pub struct Solution<const N: usize, const K: usize> {
    /// The method that produced it.
    pub method: &'static str,
    /// What was recorded.
    pub record: Record,
    /// Output times.
    pub t: Vec<f64>,
    /// `q` at the output times.
    pub q: Vec<SVector<f64, N>>,
    /// `q̇` at the output times.
    pub qd: Vec<SVector<f64, N>>,
    /// `q̈` ([`Record::Dynamics`] and above).
    pub qdd: Vec<SVector<f64, N>>,
    /// Multipliers `μ`, Newton form ([`Record::Dynamics`] and above).
    pub mu: Vec<SVector<f64, K>>,
    /// The Chetaev force `Φ = Jᵀμ` ([`Record::Dynamics`] and above).
    pub phi: Vec<SVector<f64, N>>,
    /// The constraint residual `f(t, q, q̇)` ([`Record::Dynamics`] and above).
    pub residual: Vec<SVector<f64, K>>,
    /// The energy `E = q̇·∂L/∂q̇ − L` ([`Record::Dynamics`] and above).
    pub energy: Vec<f64>,
    /// The work of the Chetaev force since the start, `W_Φ = ∫ q̇·Φ dt` ([`Record::Energy`]).
    pub work: Vec<f64>,
    /// `∫ ∂L/∂t dt` since the start ([`Record::Energy`]).
    pub dl_dt_integral: Vec<f64>,
    /// Located events, in the order they occurred.
    pub events: Vec<EventHit<N>>,
    /// Work counters.
    pub stats: Stats,
    /// Why it stopped.
    pub status: Status,
}

impl<const N: usize, const K: usize> Solution<N, K> {
    pub(crate) fn new(method: &'static str, record: Record) -> Self {
        Self {
            method,
            record,
            t: Vec::new(),
            q: Vec::new(),
            qd: Vec::new(),
            qdd: Vec::new(),
            mu: Vec::new(),
            phi: Vec::new(),
            residual: Vec::new(),
            energy: Vec::new(),
            work: Vec::new(),
            dl_dt_integral: Vec::new(),
            events: Vec::new(),
            stats: Stats::default(),
            status: Status::Success,
        }
    }

    /// Whether the end time or a terminal event was reached.
    pub fn is_success(&self) -> bool {
        !matches!(self.status, Status::Failed(_))
    }

    /// The error, if the integration failed.
    pub fn error(&self) -> Option<&Error> {
        match &self.status {
            Status::Failed(e) => Some(e),
            _ => None,
        }
    }

    /// Number of recorded points.
    pub fn len(&self) -> usize {
        self.t.len()
    }

    /// Whether nothing was recorded.
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }

    /// The last recorded `(t, q, q̇)`.
    pub fn last(&self) -> Option<(f64, SVector<f64, N>, SVector<f64, N>)> {
        let i = self.t.len().checked_sub(1)?;
        Some((self.t[i], self.q[i], self.qd[i]))
    }

    /// The energy balance `E(t) − E(t0) − W_Φ(t) + ∫∂L/∂t dt`, which vanishes along an exact motion
    /// because `dE/dt = q̇·Φ − ∂L/∂t` ([`Record::Energy`]; empty otherwise).
    pub fn energy_balance(&self) -> Vec<f64> {
        if self.work.is_empty() {
            return Vec::new();
        }
        let e0 = self.energy[0];
        (0..self.work.len())
            .map(|i| self.energy[i] - e0 - self.work[i] + self.dl_dt_integral[i])
            .collect()
    }

    /// `max_i max_a |f_a|` over the recorded points ([`Record::Dynamics`] and above; 0 otherwise).
    pub fn max_residual(&self) -> f64 {
        self.residual
            .iter()
            .flat_map(|f| f.iter())
            .fold(0.0f64, |acc, v| acc.max(v.abs()))
    }
}
