//! Tsitouras 5(4): seven stages (first same as last), fifth-order step, embedded fourth-order error
//! estimate, and a free fourth-order dense output.
//!
//! Tableau, error weights and interpolant: Ch. Tsitouras, "Runge–Kutta pairs of order 5(4)
//! satisfying only the first column simplifying assumption", Comput. Math. Appl. 62 (2011)
//! 770–775; the values below are those of the paper to double precision, as also tabulated by
//! OrdinaryDiffEq.jl (`Tsit5`). The error weights `E_i = b_i − b̂_i` are written with the sign of
//! `b̂_7 = −1/66`, the correction to the printed paper.
//!
//! The continuous extension is `y(t + θh) = y + h Σ_i b_i(θ) k_i` with
//! `b_1(θ) = θ (R11 + R12 θ + R13 θ² + R14 θ³)` and `b_i(θ) = θ² (Ri2 + Ri3 θ + Ri4 θ²)` for
//! `i = 2..7`; `b_i(1) = b_i`.

#![allow(clippy::excessive_precision)]

use super::stiffness::{StiffnessDetection, StiffnessTest};
use super::system::OdeSystem;
use super::Trial;
use super::{combine, weighted, Controller, Method, MethodInfo, Stage, Stages54, Step, Stepper};
use crate::error::Error;

// The stages 2 to 6 (stage 7 is the derivative at the new point, from the weights of the step).
const STAGES: Stages54 = Stages54 {
    s2: Stage {
        c: 0.161,
        a: [0.161],
    },
    s3: Stage {
        c: 0.327,
        a: [
            -0.8480655492356988544426874250230774675121e-2,
            0.3354806554923569885444268742502307746751,
        ],
    },
    s4: Stage {
        c: 0.9,
        a: [
            2.897153057105493432130432594192938764924,
            -6.359448489975074843148159912383825625952,
            4.362295432869581411017727318190886861027,
        ],
    },
    s5: Stage {
        c: 0.9800255409045096857298102862870245954942,
        a: [
            5.325864828439256604428877920840511317836,
            -11.74888356406282787774717033978577296188,
            7.495539342889836208304604784564358155658,
            -0.9249506636175524925650207933207191611349e-1,
        ],
    },
    s6: Stage {
        c: 1.0,
        a: [
            5.861455442946420028659251486982647890394,
            -12.92096931784710929170611868178335939541,
            8.159367898576158643180400794539253485181,
            -0.7158497328140099722453054252582973869127e-1,
            -0.2826905039406838290900305721271224146717e-1,
        ],
    },
};
// The weights b_1 to b_6 of the step (row 7 of the tableau: stage 7 is the derivative at the new
// point).
const B: [f64; 6] = [
    0.9646076681806522951816731316512876333711e-1,
    0.01,
    0.4798896504144995747752495322905965199130,
    1.379008574103741893192274821856872770756,
    -3.290069515436080679901047585711363850115,
    2.324710524099773982415355918398765796109,
];

// E_i = b_i − b̂_i.
const E: [f64; 7] = [
    -1.780011052225771443378550607539534775944e-3,
    -8.164344596567469032236360633546862401862e-4,
    7.880878010261996010314727672526304238628e-3,
    -1.44711007173262907537165147972635116720e-1,
    5.823571654525552250199376106520421794260e-1,
    -4.580821059291869466616365188325542974428e-1,
    1.0 / 66.0,
];

// The interpolant's polynomial coefficients: `R1 = [R11, R12, R13, R14]` of `b_1(θ)`, and
// `R[i − 2] = [Ri2, Ri3, Ri4]` of `b_i(θ)`, `i = 2..7`.
const R1: [f64; 4] = [
    0.999999999999999974283372471559910888475,
    -2.763706197274825911336735930481400260916,
    2.91325546182191274375068099306808,
    -1.0530884977290216,
];
const R: [[f64; 3]; 6] = [
    [0.13169999999999999727, -0.22339999999999999818, 0.1017],
    [
        3.93029623689475152850687446709813398,
        -5.94103387213150473470249202589458001,
        2.490627285651252793,
    ],
    [
        -12.411077166933676983734381540685453484102,
        30.3381886302823215981729903691836576,
        -16.54810288924490272,
    ],
    [
        37.50931341651103919496903965334519631242,
        -88.1789048947664011014276693541209817,
        47.37952196281928122,
    ],
    [
        -27.896526289197287805948263144598643896,
        65.09189467479367152629021928716553658,
        -34.87065786149660974,
    ],
    [1.5, -4.0, 2.5],
];

/// Where the stability region of Tsit5 meets the negative real axis (about 3.51); the stiffness
/// test compares against 3.45, as DOPRI5's 3.25 stands to its 3.31.
const STIFF_H_LAMBDA: f64 = 3.45;

/// Tsitouras 5(4): explicit, adaptive, fifth order, with fourth-order dense output.
///
/// Often a little cheaper than [`Dopri5`](super::Dopri5) at equal error, at moderate tolerances.
/// Its step-size control is the PI controller of [`Dopri5`](super::Dopri5), and it has the same
/// stiffness test, from its last two stages, which share the node `t + h`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default))]
pub struct Tsit5 {
    /// The stiffness test, which stops the solve with [`Error::Stiff`] (on by default).
    #[cfg_attr(feature = "serde", serde(flatten))]
    pub stiffness: StiffnessDetection,
}

impl Method for Tsit5 {
    type Stepper = Tsit5Stepper;
    fn info(&self) -> MethodInfo {
        MethodInfo::explicit("Tsit5", (5, 4), 4, 3.5069)
            .with_controller(Controller::pi(0.2, 10.0, 0.04))
            .with_advice(
                "below tolerances of about 1e-10 Dop853 is cheaper; for a stiff problem use Rodas4",
            )
    }
    fn stiffness_detection_mut(&mut self) -> Option<&mut StiffnessDetection> {
        Some(&mut self.stiffness)
    }
    fn stepper(&self, dim: usize) -> Tsit5Stepper {
        Tsit5Stepper {
            k: std::array::from_fn(|_| vec![0.0; dim]),
            ytmp: vec![0.0; dim],
            ysti: vec![0.0; dim],
            y0: vec![0.0; dim],
            h: 0.0,
            stiffness: StiffnessTest::new(self.stiffness, STIFF_H_LAMBDA),
        }
    }
}

/// The working state of [`Tsit5`].
#[derive(Clone, Debug)]
pub struct Tsit5Stepper {
    /// Stages 1–7; after an accepted step they also serve the dense output until `k_1` is
    /// replaced by `k_7` at the start of the next step.
    k: [Vec<f64>; 7],
    ytmp: Vec<f64>,
    /// The argument of stage 6, for the stiffness test.
    ysti: Vec<f64>,
    /// The start of the last accepted step, for the dense output.
    y0: Vec<f64>,
    h: f64,
    stiffness: StiffnessTest,
}

impl Stepper for Tsit5Stepper {
    fn reset<S: OdeSystem>(&mut self, sys: &mut S, t: f64, y: &[f64]) -> Result<(), Error> {
        sys.rhs(t, y, &mut self.k[0])
    }

    fn attempt<S: OdeSystem>(&mut self, sys: &mut S, trial: Trial<'_>) -> Result<f64, Error> {
        let (t, h, y, y_new, norm) = trial.parts();
        self.stiffness.controls(norm.len());
        let [k1, k2, k3, k4, k5, k6, k7] = &mut self.k;
        // The argument of stage 6 stays in `ysti` for the stiffness test.
        STAGES.eval(
            sys,
            (t, h, y),
            [k1, k2, k3, k4, k5, k6],
            &mut self.ytmp,
            &mut self.ysti,
        )?;
        combine(y_new, y, h, &B, [k1, k2, k3, k4, k5, k6]);
        sys.rhs(t + h, y_new, k7)?;
        Ok(norm.of_combination(h, &E, &[&**k1, k2, k3, k4, k5, k6, k7], y, y_new))
    }

    fn commit<S: OdeSystem>(&mut self, _sys: &mut S, step: Step<'_>) -> Result<(), Error> {
        // h·|λ| from the last two stages, which share the node t + h.
        if self.stiffness.wants_test() {
            self.stiffness
                .observe(step.h, &self.k[6], &self.k[5], step.y_new, &self.ysti);
        }
        // The stages stay for the dense output; the derivative at the new point (k7) becomes the
        // first stage of the next step when it starts, so both live side by side until then.
        self.y0.copy_from_slice(step.y);
        self.h = step.h;
        self.k.rotate_right(1);
        // Now k[0] is the old k7 (the next step's k1) and k[1..7] the old k1..k6.
        Ok(())
    }

    fn interpolate(&self, theta: f64, out: &mut [f64]) {
        let [k7, k1, k2, k3, k4, k5, k6] = &self.k;
        let t2 = theta * theta;
        let mut b = [theta * (R1[0] + theta * (R1[1] + theta * (R1[2] + theta * R1[3]))); 7];
        for (b, r) in b[1..].iter_mut().zip(&R) {
            *b = t2 * (r[0] + theta * (r[1] + theta * r[2]));
        }
        let k = [&**k1, k2, k3, k4, k5, k6, k7];
        let h = self.h;
        for (i, out) in out.iter_mut().enumerate() {
            *out = self.y0[i] + h * weighted(&b, &k, i);
        }
    }

    fn stiffness(&self) -> Option<f64> {
        self.stiffness.detected()
    }
}
