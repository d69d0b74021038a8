//! Dormand–Prince 8(5,3) with its seventh-order continuous extension and Hairer's stiffness test.
//!
//! Tableau: P. J. Prince, J. R. Dormand, "High order embedded Runge-Kutta formulae",
//! J. Comput. Appl. Math. 7 (1981) 67–75. Error estimate, dense output and stiffness detection:
//! E. Hairer, S. P. Nørsett, G. Wanner, *Solving Ordinary Differential Equations I*, 2nd ed.,
//! Springer 1993, Sections II.5, II.6, II.10 and IV.2 (the code DOP853, version of April 25, 1996
//! with the corrections of March 4, 2002, whose coefficients are reproduced here digit for digit).
//!
//! Twelve stages give the eighth-order step; the twelfth stage and the first-same-as-last
//! thirteenth sit at the node `t + h`. The error estimate combines an embedded fifth-order and an
//! embedded third-order formula: with `err5²` and `err3²` their weighted sums of squares over the
//! `n` controlled components (each difference over the step), `err = err5² / sqrt(n·(err5² +
//! 0.01·err3²))`, which behaves like an eighth-order estimate, so the step size is controlled with
//! the exponent `1/8`. Three further stages (nodes `0.1`, `0.2`, `7/9`) are evaluated after each
//! accepted step for the dense output.
//!
//! The stiffness test is DOP853's: `h·|λ|` is estimated from stages 12 and 13, which share the
//! node `t + h`, and stiffness is reported after 15 steps above `6.1` (just inside the stability
//! interval `(-6.39, 0)`), six steps below clearing the count. As for [`Dopri5`](super::Dopri5),
//! every accepted step is tested.

#![allow(clippy::excessive_precision)]

use super::stiffness::{StiffnessDetection, StiffnessTest};
use super::system::OdeSystem;
use super::Trial;
use super::{combine, weighted, Method, MethodInfo, Stage, Step, Stepper};
use crate::error::Error;

// The stages: the node c_i and the non-zero a_ij of each row, over the stages named where the row
// is used. Stages 1, 12 and 13 sit at c = 0, 1, 1 and take t and t + h directly.
const S2: Stage<1> = Stage {
    c: 0.526001519587677318785587544488e-01,
    a: [5.26001519587677318785587544488e-2],
};
const S3: Stage<2> = Stage {
    c: 0.789002279381515978178381316732e-01,
    a: [
        1.97250569845378994544595329183e-2,
        5.91751709536136983633785987549e-2,
    ],
};
const S4: Stage<2> = Stage {
    c: 0.118350341907227396726757197510e+00,
    a: [
        2.95875854768068491816892993775e-2,
        8.87627564304205475450678981324e-2,
    ],
};
const S5: Stage<3> = Stage {
    c: 0.281649658092772603273242802490e+00,
    a: [
        2.41365134159266685502369798665e-1,
        -8.84549479328286085344864962717e-1,
        9.24834003261792003115737966543e-1,
    ],
};
const S6: Stage<3> = Stage {
    c: 0.333333333333333333333333333333e+00,
    a: [
        3.7037037037037037037037037037e-2,
        1.70828608729473871279604482173e-1,
        1.25467687566822425016691814123e-1,
    ],
};
const S7: Stage<4> = Stage {
    c: 0.25e+00,
    a: [
        3.7109375e-2,
        1.70252211019544039314978060272e-1,
        6.02165389804559606850219397283e-2,
        -1.7578125e-2,
    ],
};
const S8: Stage<5> = Stage {
    c: 0.307692307692307692307692307692e+00,
    a: [
        3.70920001185047927108779319836e-2,
        1.70383925712239993810214054705e-1,
        1.07262030446373284651809199168e-1,
        -1.53194377486244017527936158236e-2,
        8.27378916381402288758473766002e-3,
    ],
};
const S9: Stage<6> = Stage {
    c: 0.651282051282051282051282051282e+00,
    a: [
        6.24110958716075717114429577812e-1,
        -3.36089262944694129406857109825e0,
        -8.68219346841726006818189891453e-1,
        2.75920996994467083049415600797e1,
        2.01540675504778934086186788979e1,
        -4.34898841810699588477366255144e1,
    ],
};
const S10: Stage<7> = Stage {
    c: 0.6e+00,
    a: [
        4.77662536438264365890433908527e-1,
        -2.48811461997166764192642586468e0,
        -5.90290826836842996371446475743e-1,
        2.12300514481811942347288949897e1,
        1.52792336328824235832596922938e1,
        -3.32882109689848629194453265587e1,
        -2.03312017085086261358222928593e-2,
    ],
};
const S11: Stage<8> = Stage {
    c: 0.857142857142857142857142857142e+00,
    a: [
        -9.3714243008598732571704021658e-1,
        5.18637242884406370830023853209e0,
        1.09143734899672957818500254654e0,
        -8.14978701074692612513997267357e0,
        -1.85200656599969598641566180701e1,
        2.27394870993505042818970056734e1,
        2.49360555267965238987089396762e0,
        -3.0467644718982195003823669022e0,
    ],
};
const S12: Stage<9> = Stage {
    c: 1.0,
    a: [
        2.27331014751653820792359768449e0,
        -1.05344954667372501984066689879e1,
        -2.00087205822486249909675718444e0,
        -1.79589318631187989172765950534e1,
        2.79488845294199600508499808837e1,
        -2.85899827713502369474065508674e0,
        -8.87285693353062954433549289258e0,
        1.23605671757943030647266201528e1,
        6.43392746015763530355970484046e-1,
    ],
};

// Stages 14 to 16 of the continuous extension (stage 13 is the derivative at t + h).
const S14: Stage<8> = Stage {
    c: 0.1e+00,
    a: [
        5.61675022830479523392909219681e-2,
        2.53500210216624811088794765333e-1,
        -2.46239037470802489917441475441e-1,
        -1.24191423263816360469010140626e-1,
        1.5329179827876569731206322685e-1,
        8.20105229563468988491666602057e-3,
        7.56789766054569976138603589584e-3,
        -8.298e-3,
    ],
};
const S15: Stage<8> = Stage {
    c: 0.2e+00,
    a: [
        3.18346481635021405060768473261e-2,
        2.83009096723667755288322961402e-2,
        5.35419883074385676223797384372e-2,
        -5.49237485713909884646569340306e-2,
        -1.08347328697249322858509316994e-4,
        3.82571090835658412954920192323e-4,
        -3.40465008687404560802977114492e-4,
        1.41312443674632500278074618366e-1,
    ],
};
const S16: Stage<8> = Stage {
    c: 0.777777777777777777777777777778e+00,
    a: [
        -4.28896301583791923408573538692e-1,
        -4.69762141536116384314449447206e0,
        7.68342119606259904184240953878e0,
        4.06898981839711007970213554331e0,
        3.56727187455281109270669543021e-1,
        -1.39902416515901462129418009734e-3,
        2.9475147891527723389556272149e0,
        -9.15095847217987001081870187138e0,
    ],
};

// Weights b_1 and b_6 to b_12 of the eighth-order step.
const B: [f64; 8] = [
    5.42937341165687622380535766363e-2,
    4.45031289275240888144113950566e0,
    1.89151789931450038304281599044e0,
    -5.8012039600105847814672114227e0,
    3.1116436695781989440891606237e-1,
    -1.52160949662516078556178806805e-1,
    2.01365400804030348374776537501e-1,
    4.47106157277725905176885569043e-2,
];

// The embedded third-order formula, for err3: the weights of stages 1, 9 and 12.
const BHH: [f64; 3] = [
    0.244094488188976377952755905512e+00,
    0.733846688281611857341361741547e+00,
    0.220588235294117647058823529412e-01,
];

// The difference of the eighth-order step and the embedded fifth-order formula, for err5, over
// stages 1 and 6 to 12.
const ER: [f64; 8] = [
    0.1312004499419488073250102996e-01,
    -0.1225156446376204440720569753e+01,
    -0.4957589496572501915214079952e+00,
    0.1664377182454986536961530415e+01,
    -0.3503288487499736816886487290e+00,
    0.3341791187130174790297318841e+00,
    0.8192320648511571246570742613e-01,
    -0.2235530786388629525884427845e-01,
];

// Coefficients of the continuous extension: rows 4 to 7 of Hairer's d_ij, over stages 1 and 6 to
// 16.
const D: [[f64; 12]; 4] = [
    [
        -0.84289382761090128651353491142e+01,
        0.56671495351937776962531783590e+00,
        -0.30689499459498916912797304727e+01,
        0.23846676565120698287728149680e+01,
        0.21170345824450282767155149946e+01,
        -0.87139158377797299206789907490e+00,
        0.22404374302607882758541771650e+01,
        0.63157877876946881815570249290e+00,
        -0.88990336451333310820698117400e-01,
        0.18148505520854727256656404962e+02,
        -0.91946323924783554000451984436e+01,
        -0.44360363875948939664310572000e+01,
    ],
    [
        0.10427508642579134603413151009e+02,
        0.24228349177525818288430175319e+03,
        0.16520045171727028198505394887e+03,
        -0.37454675472269020279518312152e+03,
        -0.22113666853125306036270938578e+02,
        0.77334326684722638389603898808e+01,
        -0.30674084731089398182061213626e+02,
        -0.93321305264302278729567221706e+01,
        0.15697238121770843886131091075e+02,
        -0.31139403219565177677282850411e+02,
        -0.93529243588444783865713862664e+01,
        0.35816841486394083752465898540e+02,
    ],
    [
        0.19985053242002433820987653617e+02,
        -0.38703730874935176555105901742e+03,
        -0.18917813819516756882830838328e+03,
        0.52780815920542364900561016686e+03,
        -0.11573902539959630126141871134e+02,
        0.68812326946963000169666922661e+01,
        -0.10006050966910838403183860980e+01,
        0.77771377980534432092869265740e+00,
        -0.27782057523535084065932004339e+01,
        -0.60196695231264120758267380846e+02,
        0.84320405506677161018159903784e+02,
        0.11992291136182789328035130030e+02,
    ],
    [
        -0.25693933462703749003312586129e+02,
        -0.15418974869023643374053993627e+03,
        -0.23152937917604549567536039109e+03,
        0.35763911791061412378285349910e+03,
        0.93405324183624310003907691704e+02,
        -0.37458323136451633156875139351e+02,
        0.10409964950896230045147246184e+03,
        0.29840293426660503123344363579e+02,
        -0.43533456590011143754432175058e+02,
        0.96324553959188282948394950600e+02,
        -0.39177261675615439165231486172e+02,
        -0.14972683625798562581422125276e+03,
    ],
];

/// `h·|λ|` above which a step counts as limited by stability rather than by accuracy.
const STIFF_H_LAMBDA: f64 = 6.1;

/// Dormand–Prince 8(5,3): explicit, adaptive, eighth order, with seventh-order dense output.
///
/// The choice for non-stiff problems at stringent tolerances (about `1e-7` to `1e-13`). A step costs
/// eleven new evaluations of the right-hand side (the twelfth is the previous step's last); each
/// accepted step costs one more for the next step and three for the dense output.
///
/// Step-size control is the I controller with step ratios in `[0.2, 10]` (its step counts match
/// those of Hairer's DOP853 within 1 %).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default))]
pub struct Dop853 {
    /// The stiffness test, which stops the solve with [`Error::Stiff`] (on by default).
    #[cfg_attr(feature = "serde", serde(flatten))]
    pub stiffness: StiffnessDetection,
}

impl Method for Dop853 {
    type Stepper = Dop853Stepper;
    fn info(&self) -> MethodInfo {
        // DOP853's error estimate combines its 5th- and 3rd-order embedded solutions into one of
        // order 8 (Hairer, Nørsett, Wanner I, II.10), so step control uses the order itself.
        MethodInfo::explicit("Dop853", (8, 5), 7, 6.39)
            .with_control_order(8)
            .with_advice(
                "above tolerances of about 1e-7 Dopri5 is cheaper; for a stiff problem use Rodas4",
            )
    }
    fn stiffness_detection_mut(&mut self) -> Option<&mut StiffnessDetection> {
        Some(&mut self.stiffness)
    }
    fn stepper(&self, dim: usize) -> Dop853Stepper {
        Dop853Stepper {
            work: vec![0.0; VECTORS * dim],
            dim,
            stiffness: StiffnessTest::new(self.stiffness, STIFF_H_LAMBDA),
            err_sums: (0.0, 0.0),
            dense: true,
        }
    }
}

/// The stepper's vectors, in this order: the stages `k1..k16` (1–12 of the step, 13 the derivative
/// at the new point, 14–16 of the dense output), the stage argument, the argument of stage 12 (kept
/// for the stiffness test, as stage 12 shares the node `t + h` with stage 13), and the eight
/// dense-output coefficients.
const VECTORS: usize = 16 + 2 + 8;
/// Where the dense-output coefficients start.
const RCONT: usize = 18;

/// `split!(data, n => a, b, _, c)` binds `a`, `b`, `c` to the first, second and fourth of the
/// vectors of length `n` laid end to end in `data`, as disjoint mutable slices.
///
/// A chain of `split_at_mut(n)`, written out, so every slice has the length `n` itself as far as
/// the compiler can see: the stage loops over `0..n` drop their bounds checks (all but one per
/// component in the scalar loop that handles fewer than five components, see
/// `docs/performance/step-loop.md`), and the slices stay in registers across the right-hand-side
/// calls. Cutting them with `chunks_exact_mut` and an empty fallback for a missing chunk, or with
/// `std::array::from_fn` (not inlined for twenty-odd elements), loses the lengths, and with them
/// the checks come back into every stage loop.
macro_rules! split {
    ($data:expr, $n:expr => $($name:tt),+) => {
        let (rest, n): (&mut [f64], usize) = ($data, $n);
        $(let ($name, rest) = rest.split_at_mut(n);)+
        let _ = rest;
    };
}

/// The working state of [`Dop853`].
#[derive(Clone, Debug)]
pub struct Dop853Stepper {
    /// The [`VECTORS`] work vectors of length `dim`, in one allocation (a solve of a few
    /// microseconds would otherwise spend a noticeable part of it allocating and freeing them).
    work: Vec<f64>,
    dim: usize,
    stiffness: StiffnessTest,
    /// The weighted sums of squares `(err5², err3²)` of the last trial step.
    err_sums: (f64, f64),
    /// Whether `accept` prepares the dense output (three more stages per step).
    dense: bool,
}

impl Stepper for Dop853Stepper {
    fn reset<S: OdeSystem>(&mut self, sys: &mut S, t: f64, y: &[f64]) -> Result<(), Error> {
        split!(&mut self.work, self.dim => k1);
        sys.rhs(t, y, k1)
    }

    fn attempt<S: OdeSystem>(&mut self, sys: &mut S, trial: Trial<'_>) -> Result<f64, Error> {
        let (t, h, y, y_new, norm) = trial.parts();
        self.stiffness.controls(norm.len());
        let n = self.dim;
        let (y, y_new) = (&y[..n], &mut y_new[..n]);
        split!(&mut self.work, n =>
               k1, k2, k3, k4, k5, k6, k7, k8, k9, k10, k11, k12, _, _, _, _, yt, ysti);
        combine(yt, y, h, &S2.a, [k1]);
        sys.rhs(t + S2.c * h, yt, k2)?;
        combine(yt, y, h, &S3.a, [k1, k2]);
        sys.rhs(t + S3.c * h, yt, k3)?;
        combine(yt, y, h, &S4.a, [k1, k3]);
        sys.rhs(t + S4.c * h, yt, k4)?;
        combine(yt, y, h, &S5.a, [k1, k3, k4]);
        sys.rhs(t + S5.c * h, yt, k5)?;
        combine(yt, y, h, &S6.a, [k1, k4, k5]);
        sys.rhs(t + S6.c * h, yt, k6)?;
        combine(yt, y, h, &S7.a, [k1, k4, k5, k6]);
        sys.rhs(t + S7.c * h, yt, k7)?;
        combine(yt, y, h, &S8.a, [k1, k4, k5, k6, k7]);
        sys.rhs(t + S8.c * h, yt, k8)?;
        combine(yt, y, h, &S9.a, [k1, k4, k5, k6, k7, k8]);
        sys.rhs(t + S9.c * h, yt, k9)?;
        combine(yt, y, h, &S10.a, [k1, k4, k5, k6, k7, k8, k9]);
        sys.rhs(t + S10.c * h, yt, k10)?;
        combine(yt, y, h, &S11.a, [k1, k4, k5, k6, k7, k8, k9, k10]);
        sys.rhs(t + S11.c * h, yt, k11)?;
        combine(ysti, y, h, &S12.a, [k1, k4, k5, k6, k7, k8, k9, k10, k11]);
        sys.rhs(t + h, ysti, k12)?;
        // The step and both error estimates in one pass, weighted and summed as they are formed
        // (Hairer's DOP853 does the same in its final loop); components beyond the norm's are
        // outside error control and only stepped.
        let kb = [&*k1, k6, k7, k8, k9, k10, k11, k12];
        let controlled = norm.len().min(n);
        let (mut err5, mut err3) = (0.0, 0.0);
        for i in 0..controlled {
            let incr = weighted(&B, &kb, i);
            y_new[i] = y[i] + h * incr;
            // Weighted by h/sc rather than 1/sc then h: a tiny first step under a tiny absolute
            // tolerance (1e-291 against 1e-300) would otherwise square the rounding of the
            // stages' combination, 1e-15/1e-300, to infinity.
            let w = h / norm.scale(i, y[i], y_new[i]);
            let e3 = (incr - BHH[0] * k1[i] - BHH[1] * k9[i] - BHH[2] * k12[i]) * w;
            let e5 = weighted(&ER, &kb, i) * w;
            err3 += e3 * e3;
            err5 += e5 * e5;
        }
        for i in controlled..n {
            y_new[i] = y[i] + h * weighted(&B, &kb, i);
        }
        self.err_sums = (err5, err3);
        let err = err5;
        let mut deno = err5 + 0.01 * err3;
        if deno <= 0.0 {
            deno = 1.0;
        }
        let nd = norm.len() as f64 * deno;
        // Hairer's form, except where the sums are so small (below about 1e-308, on a step of
        // 1e-150) that `1/nd` overflows: there the quotient, which stays finite.
        let inverse = 1.0 / nd;
        Ok(if inverse.is_finite() {
            err * inverse.sqrt()
        } else {
            err / nd.sqrt()
        })
    }

    fn commit<S: OdeSystem>(&mut self, sys: &mut S, step: Step<'_>) -> Result<(), Error> {
        let Step { t, h, y_new, .. } = step;
        let n = self.dim;
        let y_new = &y_new[..n];
        split!(&mut self.work, n =>
               k1, _, _, _, _, _, _, _, _, _, _, k12, k13, _, _, _, _, ysti);
        sys.rhs(t + h, y_new, k13)?;
        // h·|λ| from stages 12 and 13, which share the node t + h.
        if self.stiffness.wants_test() {
            self.stiffness.observe(h, k13, k12, y_new, ysti);
        }
        if !self.dense {
            // Nothing will interpolate: no extra stages, and `k_13` starts the next step.
            k1.copy_from_slice(k13);
        }
        Ok(())
    }

    fn extend<S: OdeSystem>(&mut self, sys: &mut S, step: Step<'_>) -> Result<(), Error> {
        if !self.dense {
            return Ok(());
        }
        let Step { t, h, y, y_new } = step;
        let n = self.dim;
        let (y, y_new) = (&y[..n], &y_new[..n]);
        split!(&mut self.work, n =>
               k1, _, _, _, _, k6, k7, k8, k9, k10, k11, k12, k13, k14, k15, k16,
               yt, _, r1, r2, r3, r4, r5, r6, r7, r8);
        // The three stages of the continuous extension, after the end of the step was checked
        // (their nodes lie inside the step).
        combine(yt, y, h, &S14.a, [k1, k7, k8, k9, k10, k11, k12, k13]);
        sys.rhs(t + S14.c * h, yt, k14)?;
        combine(yt, y, h, &S15.a, [k1, k6, k7, k8, k11, k12, k13, k14]);
        sys.rhs(t + S15.c * h, yt, k15)?;
        combine(yt, y, h, &S16.a, [k1, k6, k7, k8, k9, k13, k14, k15]);
        sys.rhs(t + S16.c * h, yt, k16)?;
        let kd = [&*k1, k6, k7, k8, k9, k10, k11, k12, k13, k14, k15, k16];
        for i in 0..n {
            let ydiff = y_new[i] - y[i];
            let bspl = h * k1[i] - ydiff;
            r1[i] = y[i];
            r2[i] = ydiff;
            r3[i] = bspl;
            r4[i] = ydiff - h * k13[i] - bspl;
            r5[i] = h * weighted(&D[0], &kd, i);
            r6[i] = h * weighted(&D[1], &kd, i);
            r7[i] = h * weighted(&D[2], &kd, i);
            r8[i] = h * weighted(&D[3], &kd, i);
        }
        // First same as last: the derivative at the new point starts the next step.
        k1.copy_from_slice(k13);
        Ok(())
    }

    fn interpolate(&self, theta: f64, out: &mut [f64]) {
        let (n, dim) = (out.len(), self.dim);
        let [r1, r2, r3, r4, r5, r6, r7, r8]: [&[f64]; 8] =
            std::array::from_fn(|j| &self.work[(RCONT + j) * dim..(RCONT + j + 1) * dim][..n]);
        let th1 = 1.0 - theta;
        for i in 0..n {
            let par = r5[i] + theta * (r6[i] + th1 * (r7[i] + theta * r8[i]));
            out[i] = r1[i] + theta * (r2[i] + th1 * (r3[i] + theta * (r4[i] + th1 * par)));
        }
    }

    fn stiffness(&self) -> Option<f64> {
        self.stiffness.detected()
    }

    fn set_dense_output(&mut self, needed: bool) {
        self.dense = needed;
    }
}

#[cfg(test)]
mod tests {
    use super::super::testing::{loose, slopes, Sys};
    use super::super::ErrorNorm;
    use super::*;

    #[test]
    fn tableau_is_consistent() {
        // Row sums of the stage coefficients are the nodes.
        let rows: [(f64, &[f64]); 14] = [
            (S2.c, &S2.a),
            (S3.c, &S3.a),
            (S4.c, &S4.a),
            (S5.c, &S5.a),
            (S6.c, &S6.a),
            (S7.c, &S7.a),
            (S8.c, &S8.a),
            (S9.c, &S9.a),
            (S10.c, &S10.a),
            (S11.c, &S11.a),
            (S12.c, &S12.a),
            (S14.c, &S14.a),
            (S15.c, &S15.a),
            (S16.c, &S16.a),
        ];
        for (c, a) in rows {
            assert!((a.iter().sum::<f64>() - c).abs() < 1e-14, "row of c = {c}");
        }
        // The weights integrate t^(q-1) exactly for q ≤ 8, the fifth-order formula (b - er) for
        // q ≤ 5, the third-order one for q ≤ 3.
        let c = [0.0, S6.c, S7.c, S8.c, S9.c, S10.c, S11.c, 1.0];
        let (b, er) = (B, ER);
        for q in 1..=8 {
            let s: f64 = (0..8).map(|j| b[j] * c[j].powi(q - 1)).sum();
            assert!((s - 1.0 / q as f64).abs() < 1e-14, "b, q = {q}");
            if q <= 5 {
                let s: f64 = (0..8).map(|j| (b[j] - er[j]) * c[j].powi(q - 1)).sum();
                assert!((s - 1.0 / q as f64).abs() < 1e-14, "b - er, q = {q}");
            }
            if q <= 3 {
                let s = BHH[0] * 0.0f64.powi(q - 1) + BHH[1] * S9.c.powi(q - 1) + BHH[2];
                assert!((s - 1.0 / q as f64).abs() < 1e-14, "bhh, q = {q}");
            }
        }
    }

    #[test]
    fn error_estimate_behaves_like_order_8() -> Result<(), Error> {
        // Over one step the fifth-order difference is O(h^6), the third-order one O(h^4), and
        // their combination err5²/sqrt(err5² + 0.01·err3²) is O(h^8).
        let norm = ErrorNorm::new(0.0, vec![1e-12]);
        let (mut est, mut e5, mut e3) = (Vec::new(), Vec::new(), Vec::new());
        for h in [0.05, 0.025, 0.0125] {
            let mut sys = Sys::explicit(1, |t: f64, y: &[f64], dy: &mut [f64]| {
                dy[0] = t.cos() * y[0]
            });
            let mut st = Dop853::default().stepper(1);
            let y = [1.0];
            let mut y_new = [0.0];
            st.reset(&mut sys, 0.0, &y)?;
            est.push(st.try_step(&mut sys, 0.0, h, &y, &mut y_new, &norm)?);
            e5.push(st.err_sums.0.sqrt());
            e3.push(st.err_sums.1.sqrt());
        }
        let (p, p5, p3) = (slopes(&est), slopes(&e5), slopes(&e3));
        eprintln!("error estimates {est:?}, observed orders {p:?}, err5 {p5:?}, err3 {p3:?}");
        assert!(p.iter().all(|p| (p - 8.0).abs() < 0.3), "{p:?}");
        assert!(p5.iter().all(|p| (p - 6.0).abs() < 0.1), "{p5:?}");
        assert!(p3.iter().all(|p| (p - 4.0).abs() < 0.1), "{p3:?}");
        Ok(())
    }

    #[test]
    fn polynomials_in_t_are_exact() -> Result<(), Error> {
        // y' = q·t^(q-1), y = t^q, q ≤ 8, in one step over [0, 1] and over [0.5, 1.5]; the dense
        // output is exact for q ≤ 7.
        for q in 1..=8 {
            let qf = q as f64;
            for (t0, h) in [(0.0f64, 1.0), (0.5, 1.0)] {
                let mut sys = Sys::explicit(1, move |t: f64, _y: &[f64], dy: &mut [f64]| {
                    dy[0] = qf * t.powi(q - 1)
                });
                let mut st = Dop853::default().stepper(1);
                let y = [t0.powi(q)];
                let mut y_new = [0.0];
                st.reset(&mut sys, t0, &y)?;
                st.try_step(&mut sys, t0, h, &y, &mut y_new, &loose(1))?;
                let exact = (t0 + h).powi(q);
                assert!(
                    (y_new[0] - exact).abs() < 1e-13 * exact,
                    "q = {q}, t0 = {t0}: {}",
                    y_new[0]
                );
                st.accept(&mut sys, t0, h, &y, &y_new)?;
                if q <= 7 {
                    let mut out = [0.0];
                    for theta in [0.1, 0.3, 0.5, 0.77, 0.9] {
                        st.interpolate(theta, &mut out);
                        let exact = (t0 + theta * h).powi(q);
                        assert!(
                            (out[0] - exact).abs() < 1e-13,
                            "q = {q}, θ = {theta}: {}",
                            out[0]
                        );
                    }
                }
            }
        }
        Ok(())
    }

    #[test]
    fn step_costs_twelve_evaluations_and_accept_four() -> Result<(), Error> {
        let mut sys = Sys::explicit(1, |t: f64, y: &[f64], dy: &mut [f64]| {
            dy[0] = t.cos() * y[0]
        });
        let mut st = Dop853::default().stepper(1);
        let mut y_new = [0.0];
        st.reset(&mut sys, 0.0, &[1.0])?;
        assert_eq!(sys.rhs_evaluations, 1);
        st.try_step(&mut sys, 0.0, 0.1, &[1.0], &mut y_new, &loose(1))?;
        assert_eq!(sys.rhs_evaluations, 12);
        st.accept(&mut sys, 0.0, 0.1, &[1.0], &y_new)?;
        assert_eq!(sys.rhs_evaluations, 16);
        Ok(())
    }

    /// Runs the driver's step-size control (safety 0.9, exponent 1/8, factor in [0.2, 10]) for at
    /// most `max_steps` accepted steps; returns the step at which stiffness was reported.
    fn controlled<S: OdeSystem>(
        sys: &mut S,
        method: Dop853,
        t0: f64,
        y0: &[f64],
        t_end: f64,
        tol: f64,
        max_steps: usize,
    ) -> Result<Option<(usize, f64)>, Error> {
        let dim = y0.len();
        let norm = ErrorNorm::new(tol, vec![tol; dim]);
        let mut st = method.stepper(dim);
        let mut y = y0.to_vec();
        let mut y_new = vec![0.0; dim];
        let (mut t, mut h) = (t0, 1e-3f64);
        st.reset(sys, t, &y)?;
        let mut accepted = 0;
        while accepted < max_steps && t < t_end {
            h = h.min(t_end - t);
            let err = st.try_step(sys, t, h, &y, &mut y_new, &norm)?;
            let fac = if err > 0.0 {
                0.9 * err.powf(-1.0 / 8.0)
            } else {
                10.0
            };
            if err > 1.0 {
                h *= fac.clamp(0.2, 1.0);
                continue;
            }
            st.accept(sys, t, h, &y, &y_new)?;
            accepted += 1;
            if let Some(h_lambda) = st.stiffness() {
                return Ok(Some((accepted, h_lambda)));
            }
            t += h;
            y.copy_from_slice(&y_new);
            h *= fac.clamp(0.2, 10.0);
        }
        Ok(None)
    }

    #[test]
    fn stiffness_is_detected() -> Result<(), Error> {
        let lambda = 1e6;
        let f = move |t: f64, y: &[f64], dy: &mut [f64]| dy[0] = -lambda * (y[0] - t.cos());

        // Fixed steps with h·λ = 6.3, inside the stability interval (-6.39, 0) and above 6.1.
        let mut sys = Sys::explicit(1, f);
        let every_step = Dop853 {
            stiffness: StiffnessDetection {
                interval: 1,
                ..StiffnessDetection::default()
            },
        };
        let mut st = every_step.stepper(1);
        let norm = loose(1);
        let (mut t, h) = (0.0, 6.3 / lambda);
        let (mut y, mut y_new) = ([1.0], [0.0]);
        st.reset(&mut sys, t, &y)?;
        for step in 1..=15 {
            st.try_step(&mut sys, t, h, &y, &mut y_new, &norm)?;
            st.accept(&mut sys, t, h, &y, &y_new)?;
            t += h;
            y = y_new;
            match st.stiffness() {
                None => assert!(step < 15),
                Some(h_lambda) => {
                    assert_eq!(step, 15);
                    assert!((h_lambda - 6.3).abs() < 1e-6, "{h_lambda}");
                }
            }
        }

        // Under step-size control the steps settle at the stability limit.
        let mut sys = Sys::explicit(1, f);
        let hit = controlled(&mut sys, Dop853::default(), 0.0, &[1.0], 1.0, 1e-6, 2000)?;
        eprintln!("controlled stiff run: reported at accepted step, h·λ = {hit:?}");
        assert!(matches!(hit, Some((_, h_lambda)) if h_lambda > STIFF_H_LAMBDA));

        // Switched off, never.
        let mut sys = Sys::explicit(1, f);
        let method = Dop853 {
            stiffness: StiffnessDetection::OFF,
        };
        assert_eq!(
            controlled(&mut sys, method, 0.0, &[1.0], 1.0, 1e-6, 2000)?,
            None
        );
        Ok(())
    }

    #[test]
    fn stiffness_is_not_reported_on_a_nonstiff_problem() -> Result<(), Error> {
        for tol in [1e-4, 1e-8, 1e-12] {
            let mut sys = Sys::explicit(2, |_t: f64, y: &[f64], dy: &mut [f64]| {
                dy[0] = y[1];
                dy[1] = -y[0];
            });
            assert_eq!(
                controlled(
                    &mut sys,
                    Dop853::default(),
                    0.0,
                    &[1.0, 0.0],
                    50.0,
                    tol,
                    100_000
                )?,
                None
            );
            let mut sys = Sys::explicit(1, |t: f64, y: &[f64], dy: &mut [f64]| {
                dy[0] = -2.0 * y[0] + t.cos()
            });
            assert_eq!(
                controlled(&mut sys, Dop853::default(), 0.0, &[1.0], 50.0, tol, 100_000)?,
                None
            );
        }
        Ok(())
    }
}
