//! Hairer's stiffness test for explicit methods: its settings, which the methods that have it
//! ([`Dopri5`](super::Dopri5), [`Dop853`](super::Dop853), [`Tsit5`](super::Tsit5)) share, and the
//! test itself.

/// The settings of the stiffness test of an explicit method (Hairer's, as in the codes DOPRI5 and
/// DOP853): whether it runs, and how often it looks. When it fires the solve stops with
/// [`Error::Stiff`](crate::Error::Stiff), whose advice names an implicit method.
///
/// With the `serde` feature it reads and writes as the two keys `stiffness_detection` and
/// `stiffness_interval` beside the method's name (see [`AnyMethod`](super::AnyMethod)).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default))]
pub struct StiffnessDetection {
    /// Stop with [`Error::Stiff`](crate::Error::Stiff) when the test fires on 15 accepted steps
    /// (default on).
    #[cfg_attr(feature = "serde", serde(rename = "stiffness_detection"))]
    pub enabled: bool,
    /// Test every this many accepted steps until stiffness is suspected, then every step (1000, as
    /// the codes' `NSTIFF`; 0 counts as 1).
    #[cfg_attr(feature = "serde", serde(rename = "stiffness_interval"))]
    pub interval: u32,
}

impl StiffnessDetection {
    /// The test switched off: the method goes on however small stability makes its steps.
    pub const OFF: Self = Self {
        enabled: false,
        interval: 1000,
    };
}

impl Default for StiffnessDetection {
    fn default() -> Self {
        Self {
            enabled: true,
            interval: 1000,
        }
    }
}

/// Hairer's stiffness test for explicit Runge–Kutta methods (Hairer & Wanner II, Section IV.2, and
/// the codes DOPRI5 and DOP853): `h·|λ|` is estimated from two stages `k_a`, `k_b` evaluated at the
/// same node from states `y_a`, `y_b`, as `|h|·|k_a − k_b| / |y_a − y_b|`; the problem is stiff
/// after 15 tested steps above the boundary of the method's stability region, and the count
/// restarts after 6 steps below it. As in the codes, only every `interval`-th accepted step is
/// tested until one is found above the boundary; from then on every step is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct StiffnessTest {
    enabled: bool,
    boundary: f64,
    interval: u32,
    accepted: u32,
    stiff_steps: u32,
    nonstiff_steps: u32,
    h_lambda: f64,
    /// The leading components the test compares: those under error control. What rides along
    /// outside it (the energy balance's quadratures) must not change where stiffness is found.
    controlled: usize,
}

impl StiffnessTest {
    /// A test with the settings `detection` against the stability boundary `boundary` (3.25 for
    /// DOPRI5, 6.1 for DOP853, 3.45 for Tsit5).
    pub(crate) fn new(detection: StiffnessDetection, boundary: f64) -> Self {
        Self {
            enabled: detection.enabled,
            boundary,
            interval: detection.interval.max(1),
            accepted: 0,
            stiff_steps: 0,
            nonstiff_steps: 0,
            h_lambda: 0.0,
            controlled: usize::MAX,
        }
    }

    /// Compares only the first `m` components, those the error norm controls (call with each
    /// trial step's [`ErrorNorm::len`](super::ErrorNorm::len)).
    #[inline(always)]
    pub(crate) fn controls(&mut self, m: usize) {
        self.controlled = m;
    }

    /// Whether the step about to be accepted is tested (so the stepper computes the estimate).
    #[inline]
    pub(crate) fn wants_test(&mut self) -> bool {
        if !self.enabled {
            return false;
        }
        self.accepted += 1;
        self.stiff_steps > 0 || self.accepted % self.interval == 0
    }

    /// Updates the test after an accepted step of size `h`; call only when [`Self::wants_test`].
    pub(crate) fn observe(&mut self, h: f64, k_a: &[f64], k_b: &[f64], y_a: &[f64], y_b: &[f64]) {
        let (mut num, mut den) = (0.0, 0.0);
        for i in 0..k_a.len().min(self.controlled) {
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
