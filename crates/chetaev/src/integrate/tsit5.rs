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

use super::{combine, system::OdeSystem, Controller, ErrorNorm, Method, MethodInfo, Stepper};
use crate::error::Error;

const C2: f64 = 0.161;
const C3: f64 = 0.327;
const C4: f64 = 0.9;
const C5: f64 = 0.9800255409045096857298102862870245954942;

const A21: f64 = 0.161;
const A31: f64 = -0.8480655492356988544426874250230774675121e-2;
const A32: f64 = 0.3354806554923569885444268742502307746751;
const A41: f64 = 2.897153057105493432130432594192938764924;
const A42: f64 = -6.359448489975074843148159912383825625952;
const A43: f64 = 4.362295432869581411017727318190886861027;
const A51: f64 = 5.325864828439256604428877920840511317836;
const A52: f64 = -11.74888356406282787774717033978577296188;
const A53: f64 = 7.495539342889836208304604784564358155658;
const A54: f64 = -0.9249506636175524925650207933207191611349e-1;
const A61: f64 = 5.861455442946420028659251486982647890394;
const A62: f64 = -12.92096931784710929170611868178335939541;
const A63: f64 = 8.159367898576158643180400794539253485181;
const A64: f64 = -0.7158497328140099722453054252582973869127e-1;
const A65: f64 = -0.2826905039406838290900305721271224146717e-1;
// The weights of the step (row 7 of the tableau: stage 7 is the derivative at the new point).
const B1: f64 = 0.9646076681806522951816731316512876333711e-1;
const B2: f64 = 0.01;
const B3: f64 = 0.4798896504144995747752495322905965199130;
const B4: f64 = 1.379008574103741893192274821856872770756;
const B5: f64 = -3.290069515436080679901047585711363850115;
const B6: f64 = 2.324710524099773982415355918398765796109;

// E_i = b_i − b̂_i.
const E1: f64 = -1.780011052225771443378550607539534775944e-3;
const E2: f64 = -8.164344596567469032236360633546862401862e-4;
const E3: f64 = 7.880878010261996010314727672526304238628e-3;
const E4: f64 = -1.44711007173262907537165147972635116720e-1;
const E5: f64 = 5.823571654525552250199376106520421794260e-1;
const E6: f64 = -4.580821059291869466616365188325542974428e-1;
const E7: f64 = 1.0 / 66.0;

// The interpolant's polynomial coefficients.
const R11: f64 = 0.999999999999999974283372471559910888475;
const R12: f64 = -2.763706197274825911336735930481400260916;
const R13: f64 = 2.91325546182191274375068099306808;
const R14: f64 = -1.0530884977290216;
const R22: f64 = 0.13169999999999999727;
const R23: f64 = -0.22339999999999999818;
const R24: f64 = 0.1017;
const R32: f64 = 3.93029623689475152850687446709813398;
const R33: f64 = -5.94103387213150473470249202589458001;
const R34: f64 = 2.490627285651252793;
const R42: f64 = -12.411077166933676983734381540685453484102;
const R43: f64 = 30.3381886302823215981729903691836576;
const R44: f64 = -16.54810288924490272;
const R52: f64 = 37.50931341651103919496903965334519631242;
const R53: f64 = -88.1789048947664011014276693541209817;
const R54: f64 = 47.37952196281928122;
const R62: f64 = -27.896526289197287805948263144598643896;
const R63: f64 = 65.09189467479367152629021928716553658;
const R64: f64 = -34.87065786149660974;
const R72: f64 = 1.5;
const R73: f64 = -4.0;
const R74: f64 = 2.5;

/// Tsitouras 5(4): explicit, adaptive, fifth order, with fourth-order dense output.
///
/// Often a little cheaper than [`Dopri5`](super::Dopri5) at equal error, at moderate tolerances.
/// It has no stiffness test; its step-size control is the PI controller of
/// [`Dopri5`](super::Dopri5).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Tsit5;

impl Method for Tsit5 {
    type Stepper = Tsit5Stepper;
    fn info(&self) -> MethodInfo {
        MethodInfo {
            name: "Tsit5",
            order: 5,
            embedded_order: Some(4),
            control_order: 5,
            dense_order: 4,
            stability_size: 3.5069,
            needs_jacobian: false,
            fixed_step: None,
            controller: Controller::pi(0.2, 10.0, 0.04),
            advice:
                "for tolerances below about 1e-10 Dop853 is cheaper; for a stiff problem use Rodas4",
        }
    }
    fn stepper(&self, dim: usize) -> Tsit5Stepper {
        Tsit5Stepper {
            k: std::array::from_fn(|_| vec![0.0; dim]),
            ytmp: vec![0.0; dim],
            y0: vec![0.0; dim],
            h: 0.0,
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
    /// The start of the last accepted step, for the dense output.
    y0: Vec<f64>,
    h: f64,
}

impl Stepper for Tsit5Stepper {
    fn reset<S: OdeSystem>(&mut self, sys: &mut S, t: f64, y: &[f64]) -> Result<(), Error> {
        sys.rhs(t, y, &mut self.k[0])
    }

    fn try_step<S: OdeSystem>(
        &mut self,
        sys: &mut S,
        t: f64,
        h: f64,
        y: &[f64],
        y_new: &mut [f64],
        norm: &ErrorNorm,
    ) -> Result<f64, Error> {
        let [k1, k2, k3, k4, k5, k6, k7] = &mut self.k;
        let yt = &mut self.ytmp;
        combine(yt, y, h, &[(A21, k1)]);
        sys.rhs(t + C2 * h, yt, k2)?;
        combine(yt, y, h, &[(A31, k1), (A32, k2)]);
        sys.rhs(t + C3 * h, yt, k3)?;
        combine(yt, y, h, &[(A41, k1), (A42, k2), (A43, k3)]);
        sys.rhs(t + C4 * h, yt, k4)?;
        combine(yt, y, h, &[(A51, k1), (A52, k2), (A53, k3), (A54, k4)]);
        sys.rhs(t + C5 * h, yt, k5)?;
        combine(
            yt,
            y,
            h,
            &[(A61, k1), (A62, k2), (A63, k3), (A64, k4), (A65, k5)],
        );
        sys.rhs(t + h, yt, k6)?;
        combine(
            y_new,
            y,
            h,
            &[(B1, k1), (B2, k2), (B3, k3), (B4, k4), (B5, k5), (B6, k6)],
        );
        sys.rhs(t + h, y_new, k7)?;
        let mut sum = 0.0;
        for i in 0..norm.len() {
            let e = h
                * (E1 * k1[i]
                    + E2 * k2[i]
                    + E3 * k3[i]
                    + E4 * k4[i]
                    + E5 * k5[i]
                    + E6 * k6[i]
                    + E7 * k7[i]);
            let r = e / norm.scale(i, y[i], y_new[i]);
            sum += r * r;
        }
        Ok((sum / norm.len() as f64).sqrt())
    }

    fn accept<S: OdeSystem>(
        &mut self,
        _sys: &mut S,
        _t: f64,
        h: f64,
        y: &[f64],
        _y_new: &[f64],
    ) -> Result<(), Error> {
        // The stages stay for the dense output; the derivative at the new point (k7) becomes the
        // first stage of the next step when it starts, so both live side by side until then.
        self.y0.copy_from_slice(y);
        self.h = h;
        self.k.rotate_right(1);
        // Now k[0] is the old k7 (the next step's k1) and k[1..7] the old k1..k6.
        Ok(())
    }

    fn interpolate(&self, theta: f64, out: &mut [f64]) {
        let [k7, k1, k2, k3, k4, k5, k6] = &self.k;
        let t2 = theta * theta;
        let b1 = theta * (R11 + theta * (R12 + theta * (R13 + theta * R14)));
        let b2 = t2 * (R22 + theta * (R23 + theta * R24));
        let b3 = t2 * (R32 + theta * (R33 + theta * R34));
        let b4 = t2 * (R42 + theta * (R43 + theta * R44));
        let b5 = t2 * (R52 + theta * (R53 + theta * R54));
        let b6 = t2 * (R62 + theta * (R63 + theta * R64));
        let b7 = t2 * (R72 + theta * (R73 + theta * R74));
        let h = self.h;
        for i in 0..out.len() {
            out[i] = self.y0[i]
                + h * (b1 * k1[i]
                    + b2 * k2[i]
                    + b3 * k3[i]
                    + b4 * k4[i]
                    + b5 * k5[i]
                    + b6 * k6[i]
                    + b7 * k7[i]);
        }
    }
}
