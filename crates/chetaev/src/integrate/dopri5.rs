//! Dormand–Prince 5(4) with its fourth-order continuous extension and Hairer's stiffness test.
//!
//! Tableau: J. R. Dormand, P. J. Prince, "A family of embedded Runge-Kutta formulae",
//! J. Comput. Appl. Math. 6 (1980) 19–26. Dense output and stiffness detection: E. Hairer,
//! S. P. Nørsett, G. Wanner, *Solving Ordinary Differential Equations I*, 2nd ed., Springer 1993,
//! Sections II.5, II.6 and IV.2 (the code DOPRI5).

use super::stiffness::{StiffnessDetection, StiffnessTest};
use super::system::OdeSystem;
use super::{combine, weighted, Controller, Method, MethodInfo, Stage, Stages54, Step, Stepper};
use super::{Pool, Trial};
use crate::error::Error;

// The stages 2 to 6 (stage 7 is the derivative at the new point, from the weights of the step).
const STAGES: Stages54 = Stages54 {
    s2: Stage {
        c: 1.0 / 5.0,
        a: [1.0 / 5.0],
    },
    s3: Stage {
        c: 3.0 / 10.0,
        a: [3.0 / 40.0, 9.0 / 40.0],
    },
    s4: Stage {
        c: 4.0 / 5.0,
        a: [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0],
    },
    s5: Stage {
        c: 8.0 / 9.0,
        a: [
            19372.0 / 6561.0,
            -25360.0 / 2187.0,
            64448.0 / 6561.0,
            -212.0 / 729.0,
        ],
    },
    s6: Stage {
        c: 1.0,
        a: [
            9017.0 / 3168.0,
            -355.0 / 33.0,
            46732.0 / 5247.0,
            49.0 / 176.0,
            -5103.0 / 18656.0,
        ],
    },
};
// The weights of the step, b_1 and b_3 to b_6 (b_2 = b_7 = 0).
const B: [f64; 5] = [
    35.0 / 384.0,
    500.0 / 1113.0,
    125.0 / 192.0,
    -2187.0 / 6784.0,
    11.0 / 84.0,
];
// The error weights E_i = b_i − b̂_i over stages 1 and 3 to 7 (E_2 = 0).
const E: [f64; 6] = [
    71.0 / 57600.0,
    -71.0 / 16695.0,
    71.0 / 1920.0,
    -17253.0 / 339200.0,
    22.0 / 525.0,
    -1.0 / 40.0,
];
// The dense output's coefficients d_i over stages 1 and 3 to 7 (d_2 = 0).
const D: [f64; 6] = [
    -12715105075.0 / 11282082432.0,
    87487479700.0 / 32700410799.0,
    -10690763975.0 / 1880347072.0,
    701980252875.0 / 199316789632.0,
    -1453857185.0 / 822651844.0,
    69997945.0 / 29380423.0,
];

/// `h·|λ|` where the stability region of DOPRI5 meets the negative real axis (about 3.3); the
/// stiffness test of the code DOPRI5 compares against 3.25.
const STIFF_H_LAMBDA: f64 = 3.25;

/// Dormand–Prince 5(4): explicit, adaptive, fifth order, with fourth-order dense output.
///
/// The default choice for non-stiff problems at moderate tolerances (down to about `1e-10`).
/// Step-size control is Hairer's DOPRI5's: a PI controller with `β = 0.04`, step ratios in
/// `[0.2, 10]`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default))]
pub struct Dopri5 {
    /// The stiffness test, which stops the solve with [`Error::Stiff`] (on by default).
    #[cfg_attr(feature = "serde", serde(flatten))]
    pub stiffness: StiffnessDetection,
}

impl Method for Dopri5 {
    type Stepper = Dopri5Stepper;
    fn info(&self) -> MethodInfo {
        MethodInfo::explicit("Dopri5", (5, 4), 4, 3.3)
            .with_controller(Controller::pi(0.2, 10.0, 0.04))
            .with_advice(
                "for tolerances below about 1e-10 Dop853 is cheaper; for a stiff problem use \
                 Rodas4",
            )
    }
    fn stiffness_detection_mut(&mut self) -> Option<&mut StiffnessDetection> {
        Some(&mut self.stiffness)
    }
    fn stepper(&self, dim: usize) -> Dopri5Stepper {
        Dopri5Stepper {
            pool: Pool::new(VECTORS, dim),
            stiffness: StiffnessTest::new(self.stiffness, STIFF_H_LAMBDA),
            dense: true,
        }
    }
}

/// The stepper's vectors: the stages `k1..k7`, the stage argument, the argument of stage 6 (kept
/// for the stiffness test), and the five dense-output coefficients.
const VECTORS: usize = 7 + 2 + 5;

/// The working state of [`Dopri5`].
#[derive(Clone, Debug)]
pub struct Dopri5Stepper {
    /// See [`VECTORS`].
    pool: Pool,
    stiffness: StiffnessTest,
    /// Whether `accept` builds the dense-output coefficients.
    dense: bool,
}

impl Stepper for Dopri5Stepper {
    fn reset<S: OdeSystem>(&mut self, sys: &mut S, t: f64, y: &[f64]) -> Result<(), Error> {
        sys.rhs(t, y, self.pool.get_mut(0))
    }

    fn attempt<S: OdeSystem>(&mut self, sys: &mut S, trial: Trial<'_>) -> Result<f64, Error> {
        let (t, h, y, y_new, norm) = trial.parts();
        self.stiffness.controls(norm.len());
        let [k1, k2, k3, k4, k5, k6, k7, yt, ysti, ..] = self.pool.all::<VECTORS>();
        // The argument of stage 6 stays in `ysti` for the stiffness test.
        STAGES.eval(sys, (t, h, y), [k1, k2, k3, k4, k5, k6], yt, ysti)?;
        combine(y_new, y, h, &B, [k1, k3, k4, k5, k6]);
        sys.rhs(t + h, y_new, k7)?;
        Ok(norm.of_combination(h, &E, &[&*k1, k3, k4, k5, k6, k7], y, y_new))
    }

    fn commit<S: OdeSystem>(&mut self, _sys: &mut S, step: Step<'_>) -> Result<(), Error> {
        let Step { h, y, y_new, .. } = step;
        let [k1, _, k3, k4, k5, k6, k7, _, ysti, r1, r2, r3, r4, r5] = self.pool.all::<VECTORS>();
        // h·|λ| from the last two stages, which share the node t + h.
        if self.stiffness.wants_test() {
            self.stiffness.observe(h, k7, k6, y_new, ysti);
        }
        if !self.dense {
            k1.copy_from_slice(k7);
            return Ok(());
        }
        let kd = [&*k1, k3, k4, k5, k6, k7];
        for i in 0..y.len() {
            let dy = y_new[i] - y[i];
            let bspl = h * k1[i] - dy;
            r1[i] = y[i];
            r2[i] = dy;
            r3[i] = bspl;
            r4[i] = dy - h * k7[i] - bspl;
            r5[i] = h * weighted(&D, &kd, i);
        }
        // First same as last: the derivative at the new point starts the next step.
        k1.copy_from_slice(k7);
        Ok(())
    }

    fn interpolate(&self, theta: f64, out: &mut [f64]) {
        let [r1, r2, r3, r4, r5] = [9, 10, 11, 12, 13].map(|i| self.pool.get(i));
        let th1 = 1.0 - theta;
        for i in 0..out.len() {
            out[i] = r1[i] + theta * (r2[i] + th1 * (r3[i] + theta * (r4[i] + th1 * r5[i])));
        }
    }

    fn stiffness(&self) -> Option<f64> {
        self.stiffness.detected()
    }

    fn set_dense_output(&mut self, needed: bool) {
        self.dense = needed;
    }
}
