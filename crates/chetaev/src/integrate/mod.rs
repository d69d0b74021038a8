//! Integration: the methods, and the driver that owns step control, output, events and projection.
//!
//! A method ([`Dopri5`], [`Dop853`], [`Rk4`], ...) is a small value holding only its own options.
//! It produces a [`Stepper`] that knows how to take one trial step on an [`OdeSystem`], estimate its
//! error, and interpolate inside the last accepted step. It never sees the physics; the driver
//! ([`solve`](crate::solve)) never sees a tableau.

pub mod dop853;
pub mod dopri5;
pub mod driver;
pub mod events;
pub mod options;
pub mod projection;
pub mod rk4;
pub mod rodas4;
pub mod system;

pub use dop853::Dop853;
pub use dopri5::Dopri5;
pub use rk4::Rk4;
pub use rodas4::Rodas4;

use crate::error::Error;
use system::OdeSystem;

/// A named integration method from the literature, with its options.
pub trait Method {
    /// The stepper it runs.
    type Stepper: Stepper;
    /// The method's name, as in the literature.
    fn name(&self) -> &'static str;
    /// A stepper for a system of dimension `dim`, with its work vectors allocated once.
    fn stepper(&self, dim: usize) -> Self::Stepper;
    /// Checks the method's own options.
    fn validate(&self) -> Result<(), Error> {
        Ok(())
    }
}

/// One integration method's step, error estimate and dense output.
pub trait Stepper {
    /// The order `p` of the step-size exponent `1/p` (the lower order of an embedded pair plus one);
    /// `None` for a fixed-step method.
    fn control_order(&self) -> Option<u32>;
    /// The step size of a fixed-step method.
    fn fixed_step(&self) -> Option<f64> {
        None
    }
    /// Prepares stepping from `(t, y)` (evaluates `F(t, y)` where the method reuses it). Called
    /// before the first step and whenever the state was changed from outside (projection).
    fn reset<S: OdeSystem>(&mut self, sys: &mut S, t: f64, y: &[f64]) -> Result<(), Error>;
    /// Attempts a step of size `h` from `(t, y)`, writes the result to `y_new` and returns the
    /// error estimate measured with `norm` (`≤ 1` means acceptable; `0` for fixed-step methods).
    fn try_step<S: OdeSystem>(
        &mut self,
        sys: &mut S,
        t: f64,
        h: f64,
        y: &[f64],
        y_new: &mut [f64],
        norm: &ErrorNorm,
    ) -> Result<f64, Error>;
    /// The trial step was accepted: prepare dense output on `[t, t + h]` and the next step.
    fn accept<S: OdeSystem>(
        &mut self,
        sys: &mut S,
        t: f64,
        h: f64,
        y: &[f64],
        y_new: &[f64],
    ) -> Result<(), Error>;
    /// The dense output `y(t + θh)`, `θ ∈ [0, 1]`, of the last accepted step.
    fn interpolate(&self, theta: f64, out: &mut [f64]);
    /// Whether anything will call [`Stepper::interpolate`] (output at requested times, events).
    /// A method whose dense output costs extra work may skip it when not; the default ignores it.
    fn set_dense_output(&mut self, needed: bool) {
        let _ = needed;
    }
    /// `Some(h·|λ|)` when the method has detected stiffness on the last steps.
    fn stiffness(&self) -> Option<f64> {
        None
    }
    /// The implicit method to suggest when this one detects stiffness.
    fn stiff_alternative(&self) -> &'static str {
        "Rodas4"
    }
}

/// The weighted RMS norm of error control: `sqrt(mean_i (e_i / (atol_i + rtol·max(|y_i|, |ŷ_i|)))²)`
/// over the controlled components.
#[derive(Clone, Debug)]
pub struct ErrorNorm {
    rtol: f64,
    atol: Vec<f64>,
}

impl ErrorNorm {
    /// A norm with one relative tolerance and one absolute tolerance per controlled component.
    pub fn new(rtol: f64, atol: Vec<f64>) -> Self {
        Self { rtol, atol }
    }

    /// `Σ_i (e_i / sc_i)²` over the controlled components.
    #[inline]
    pub fn sum_sq(&self, e: &[f64], y: &[f64], y_new: &[f64]) -> f64 {
        let mut s = 0.0;
        for (i, atol) in self.atol.iter().enumerate() {
            let sc = atol + self.rtol * y[i].abs().max(y_new[i].abs());
            let r = e[i] / sc;
            s += r * r;
        }
        s
    }

    /// The weighted RMS norm of `e`.
    #[inline]
    pub fn norm(&self, e: &[f64], y: &[f64], y_new: &[f64]) -> f64 {
        (self.sum_sq(e, y, y_new) / self.atol.len() as f64).sqrt()
    }

    /// Number of controlled components.
    pub fn len(&self) -> usize {
        self.atol.len()
    }

    /// Whether no component is controlled.
    pub fn is_empty(&self) -> bool {
        self.atol.is_empty()
    }
}

/// Hairer's stiffness test for explicit Runge–Kutta methods (Hairer & Wanner II, Section IV.2, and
/// the codes DOPRI5 and DOP853): on each accepted step `h·|λ|` is estimated from two stages `k_a`,
/// `k_b` evaluated at the same node from states `y_a`, `y_b`, as `|h|·|k_a − k_b| / |y_a − y_b|`;
/// the problem is stiff after 15 steps above the boundary of the method's stability region, and the
/// count restarts after 6 steps below it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct StiffnessTest {
    enabled: bool,
    boundary: f64,
    stiff_steps: u32,
    nonstiff_steps: u32,
    h_lambda: f64,
}

impl StiffnessTest {
    /// A test against the stability boundary `boundary` (3.25 for DOPRI5, 6.1 for DOP853).
    pub(crate) fn new(enabled: bool, boundary: f64) -> Self {
        Self {
            enabled,
            boundary,
            stiff_steps: 0,
            nonstiff_steps: 0,
            h_lambda: 0.0,
        }
    }

    /// Updates the test after an accepted step of size `h`.
    pub(crate) fn observe(&mut self, h: f64, k_a: &[f64], k_b: &[f64], y_a: &[f64], y_b: &[f64]) {
        if !self.enabled {
            return;
        }
        let (mut num, mut den) = (0.0, 0.0);
        for i in 0..k_a.len() {
            num += (k_a[i] - k_b[i]).powi(2);
            den += (y_a[i] - y_b[i]).powi(2);
        }
        if den > 0.0 {
            self.h_lambda = h.abs() * (num / den).sqrt();
        }
        if self.h_lambda > self.boundary {
            self.nonstiff_steps = 0;
            self.stiff_steps += 1;
        } else {
            self.nonstiff_steps += 1;
            if self.nonstiff_steps == 6 {
                self.stiff_steps = 0;
            }
        }
    }

    /// `Some(h·|λ|)` once the problem has been found stiff.
    pub(crate) fn detected(&self) -> Option<f64> {
        (self.stiff_steps >= 15).then_some(self.h_lambda)
    }
}

/// `out = y + h Σ_s a_s k_s` over the stages with non-zero coefficients.
#[inline(always)]
pub(crate) fn combine(out: &mut [f64], y: &[f64], h: f64, terms: &[(f64, &[f64])]) {
    for i in 0..out.len() {
        let mut acc = 0.0;
        for (a, k) in terms {
            acc += a * k[i];
        }
        out[i] = y[i] + h * acc;
    }
}
