//! The classical fourth-order Runge–Kutta method with a fixed step, and cubic Hermite dense output.
//!
//! Tableau: W. Kutta, "Beitrag zur näherungsweisen Integration totaler Differentialgleichungen",
//! Z. Math. Phys. 46 (1901) 435–453; Hairer, Nørsett, Wanner, *Solving ODEs I*, Table II.1.2.

use super::system::OdeSystem;
use super::{combine, Method, MethodInfo, Step, Stepper, Trial};
use crate::error::Error;

/// Classical Runge–Kutta, fourth order, fixed step `h` (the last step is shortened to end exactly
/// at the end time). No error control: the accuracy is whatever `h` gives.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Rk4 {
    /// The step size (positive; the driver applies the direction of integration).
    pub h: f64,
}

impl Rk4 {
    /// Classical Runge–Kutta with step `h`.
    pub fn new(h: f64) -> Self {
        Self { h }
    }
}

impl Method for Rk4 {
    type Stepper = Rk4Stepper;
    fn info(&self) -> MethodInfo {
        MethodInfo::fixed_step("Rk4", 4, 3, 2.78, self.h).with_advice(
            "Rk4 has no error control: halve the step to check the error, or use Dopri5 or Dop853 \
             with a tolerance",
        )
    }
    fn stepper(&self, dim: usize) -> Rk4Stepper {
        Rk4Stepper {
            k: std::array::from_fn(|_| vec![0.0; dim]),
            ytmp: vec![0.0; dim],
            y0: vec![0.0; dim],
            y1: vec![0.0; dim],
            f0: vec![0.0; dim],
            h_last: 0.0,
        }
    }
    fn validate(&self) -> Result<(), Error> {
        if self.h.is_finite() && self.h > 0.0 {
            Ok(())
        } else {
            Err(Error::InvalidOption {
                name: "Rk4::h",
                value: self.h,
                hint: "the step must be a finite positive number",
            })
        }
    }
}

/// The working state of [`Rk4`].
#[derive(Clone, Debug)]
pub struct Rk4Stepper {
    k: [Vec<f64>; 4],
    ytmp: Vec<f64>,
    y0: Vec<f64>,
    y1: Vec<f64>,
    f0: Vec<f64>,
    h_last: f64,
}

impl Stepper for Rk4Stepper {
    fn reset<S: OdeSystem>(&mut self, sys: &mut S, t: f64, y: &[f64]) -> Result<(), Error> {
        sys.rhs(t, y, &mut self.k[0])
    }

    fn attempt<S: OdeSystem>(&mut self, sys: &mut S, trial: Trial<'_>) -> Result<f64, Error> {
        let (t, h, y, y_new, _) = trial.parts();
        let [k1, k2, k3, k4] = &mut self.k;
        let yt = &mut self.ytmp;
        combine(yt, y, 0.5 * h, &[1.0], [k1]);
        sys.rhs(t + 0.5 * h, yt, k2)?;
        combine(yt, y, 0.5 * h, &[1.0], [k2]);
        sys.rhs(t + 0.5 * h, yt, k3)?;
        combine(yt, y, h, &[1.0], [k3]);
        sys.rhs(t + h, yt, k4)?;
        combine(y_new, y, h / 6.0, &[1.0, 2.0, 2.0, 1.0], [k1, k2, k3, k4]);
        Ok(0.0)
    }

    fn commit<S: OdeSystem>(&mut self, sys: &mut S, step: Step<'_>) -> Result<(), Error> {
        let Step { t, h, y, y_new } = step;
        self.y0.copy_from_slice(y);
        self.y1.copy_from_slice(y_new);
        self.f0.copy_from_slice(&self.k[0]);
        self.h_last = h;
        // The derivative at the new point serves the Hermite interpolant and the next step.
        sys.rhs(t + h, y_new, &mut self.k[0])
    }

    fn interpolate(&self, theta: f64, out: &mut [f64]) {
        // Cubic Hermite on (y0, f0) and (y1, f1), third order.
        let h = self.h_last;
        let f1 = &self.k[0];
        let (t2, t3) = (theta * theta, theta * theta * theta);
        let h00 = 2.0 * t3 - 3.0 * t2 + 1.0;
        let h10 = t3 - 2.0 * t2 + theta;
        let h01 = -2.0 * t3 + 3.0 * t2;
        let h11 = t3 - t2;
        for i in 0..out.len() {
            out[i] = h00 * self.y0[i] + h10 * h * self.f0[i] + h01 * self.y1[i] + h11 * h * f1[i];
        }
    }
}
