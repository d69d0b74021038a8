//! RODAS: Hairer and Wanner's L-stable, stiffly accurate Rosenbrock method of order 4(3) with six
//! stages, an embedded third-order error estimate and a third-order dense output.
//!
//! Method: E. Hairer, G. Wanner, *Solving Ordinary Differential Equations II*, 2nd ed., Springer
//! 1996, Sections IV.7 (the implementation of Rosenbrock methods in the variables `u_i`, which
//! avoids a matrix-vector product per stage), VI.3 and VI.4 (the code RODAS). The coefficients are
//! those of the published code `rodas.f`, subroutine `ROCOE` with `METH = 1`, reproduced here digit
//! for digit; `OrdinaryDiffEq.jl`'s `Rodas4` tableau has the same values.
//!
//! With `E = I/(hγ) − J`, `J = ∂F/∂y (t, y)` and `F_t = ∂F/∂t (t, y)`, both evaluated once at the
//! start of the step, the stages are
//!
//! ```text
//! E u_i = F(t + c_i h, y + Σ_{j<i} a_ij u_j) + h d_i F_t + Σ_{j<i} (c_ij / h) u_j,   i = 1..6,
//! ```
//!
//! with `c_1 = 0`, `c_5 = c_6 = 1` and `d_5 = d_6 = 0`. The embedded third-order solution is
//! `ŷ = y + Σ_{j≤4} a_5j u_j + u_5` (the argument of the sixth stage), the fourth-order solution is
//! `y_1 = ŷ + u_6`, and `u_6` is the error estimate; the step size is controlled with the exponent
//! `1/4`. The dense output is
//!
//! ```text
//! y(t + θh) = (1 − θ) y + θ (y_1 + (1 − θ)(Σ_{j≤5} d_2j u_j + θ Σ_{j≤5} d_3j u_j)).
//! ```
//!
//! One step costs one Jacobian (reused when a rejected step is retried from the same point, as in
//! RODAS), one LU decomposition of `E` with partial pivoting, six right-hand sides (five when the
//! Jacobian is reused) and six triangular solves.

#![allow(clippy::excessive_precision)]

use nalgebra::{DMatrix, DVectorViewMut, Dyn, LU};

use super::system::OdeSystem;
use super::{combine, weighted, Controller, Method, MethodInfo, Step, Stepper, Trial};
use crate::error::Error;

const GAMMA: f64 = 0.25;

/// Stage `i` of 2 to 5: the node `c_i`, the coefficient `d_i` of `h F_t` (`γ_i = Σ_j γ_ij`), and
/// over `j < i` the stage arguments `a_ij` and the couplings `c_ij` of the stage increments.
struct Stage<const S: usize> {
    c: f64,
    d: f64,
    a: [f64; S],
    coupling: [f64; S],
}

impl<const S: usize> Stage<S> {
    /// The couplings divided by the step size, `c_ij / h`, from `hinv = 1/h`.
    #[inline(always)]
    fn couplings(&self, hinv: f64) -> [f64; S] {
        self.coupling.map(|c| c * hinv)
    }
}

// Stage 1: d_1 = γ (c_1 = 0).
const D1: f64 = 0.2500000000000000e+00;

// Stages 2 to 5 (stage 5 sits at c_5 = 1 with d_5 = 0, and takes t + h and 0 directly).
const S2: Stage<1> = Stage {
    c: 0.386,
    d: -0.1043000000000000e+00,
    a: [0.1544000000000000e+01],
    coupling: [-0.5668800000000000e+01],
};
const S3: Stage<2> = Stage {
    c: 0.21,
    d: 0.1035000000000000e+00,
    a: [0.9466785280815826e+00, 0.2557011698983284e+00],
    coupling: [-0.2430093356833875e+01, -0.2063599157091915e+00],
};
const S4: Stage<3> = Stage {
    c: 0.63,
    d: -0.3620000000000023e-01,
    a: [
        0.3314825187068521e+01,
        0.2896124015972201e+01,
        0.9986419139977817e+00,
    ],
    coupling: [
        -0.1073529058151375e+00,
        -0.9594562251023355e+01,
        -0.2047028614809616e+02,
    ],
};
const S5: Stage<4> = Stage {
    c: 1.0,
    d: 0.0,
    a: [
        0.1221224509226641e+01,
        0.6019134481288629e+01,
        0.1253708332932087e+02,
        -0.6878860361058950e+00,
    ],
    coupling: [
        0.7496443313967647e+01,
        -0.1024680431464352e+02,
        -0.3399990352819905e+02,
        0.1170890893206160e+02,
    ],
};

// Stage 6: the couplings c_6j (c_6 = 1, d_6 = 0; its argument is the embedded solution).
const C6: [f64; 5] = [
    0.8083246795921522e+01,
    -0.7981132988064893e+01,
    -0.3152159432874371e+02,
    0.1631930543123136e+02,
    -0.6058818238834054e+01,
];

// Dense output: the rows d_2j and d_3j.
const DENSE: [[f64; 5]; 2] = [
    [
        0.1012623508344586e+02,
        -0.7487995877610167e+01,
        -0.3480091861555747e+02,
        -0.7992771707568823e+01,
        0.1025137723295662e+01,
    ],
    [
        -0.6762803392801253e+00,
        0.6087714651680015e+01,
        0.1643084320892478e+02,
        0.2476722511418386e+02,
        -0.6594389125716872e+01,
    ],
];

/// RODAS of Hairer and Wanner: linearly implicit (Rosenbrock), L-stable, stiffly accurate, order
/// 4(3), with third-order dense output.
///
/// The method for stiff problems, which an explicit method such as [`Dopri5`](super::Dopri5)
/// reports with [`Error::Stiff`]. Every step uses the exact Jacobian of the reduced equations and
/// their exact time derivative (nested dual numbers), so the order is attained on non-autonomous
/// problems as well. It has no options: the step-size control is the driver's.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Rodas4;

impl Method for Rodas4 {
    type Stepper = Rodas4Stepper;
    fn info(&self) -> MethodInfo {
        MethodInfo {
            name: "Rodas4",
            order: 4,
            embedded_order: Some(3),
            control_order: 4,
            dense_order: 3,
            stability_size: f64::INFINITY,
            needs_jacobian: true,
            fixed_step: None,
            controller: Controller::i(0.2, 10.0),
            advice:
                "on a non-stiff problem Dopri5 or Dop853 is cheaper; a failing Rodas4 run often \
                     means a singularity of the model near the failure",
        }
    }
    fn stepper(&self, dim: usize) -> Rodas4Stepper {
        Rodas4Stepper {
            jac: vec![0.0; dim * dim],
            dfdt: vec![0.0; dim],
            f0: vec![0.0; dim],
            jac_t: f64::NAN,
            jac_y: vec![0.0; dim],
            jac_valid: false,
            lu: Some(LU::new(DMatrix::zeros(dim, dim))),
            k: std::array::from_fn(|_| vec![0.0; dim]),
            ytmp: vec![0.0; dim],
            dy: vec![0.0; dim],
            rcont: std::array::from_fn(|_| vec![0.0; dim]),
        }
    }
}

/// The working state of [`Rodas4`].
#[derive(Clone, Debug)]
pub struct Rodas4Stepper {
    /// `∂F/∂y`, row-major.
    jac: Vec<f64>,
    /// `∂F/∂t`.
    dfdt: Vec<f64>,
    /// `F(t, y)` at the point of the Jacobian.
    f0: Vec<f64>,
    /// The point `(t, y)` of `jac`, `dfdt` and `f0`, valid when `jac_valid`.
    jac_t: f64,
    jac_y: Vec<f64>,
    jac_valid: bool,
    /// The LU factors of `I/(hγ) − J` (`None` only while they are being recomputed).
    lu: Option<LU<f64, Dyn, Dyn>>,
    /// The stage increments `u_1..u_6`.
    k: [Vec<f64>; 6],
    ytmp: Vec<f64>,
    dy: Vec<f64>,
    /// Dense output: `y`, `y_1`, `Σ d_2j u_j`, `Σ d_3j u_j` of the last accepted step.
    rcont: [Vec<f64>; 4],
}

/// `out = dy + hd·dfdt + Σ_s c_s k_s`: the right-hand side of a stage.
#[inline(always)]
fn stage_rhs<const S: usize>(
    out: &mut [f64],
    dy: &[f64],
    hd: f64,
    dfdt: &[f64],
    c: [f64; S],
    k: [&[f64]; S],
) {
    for i in 0..out.len() {
        let mut acc = dy[i] + hd * dfdt[i];
        for (c, k) in c.iter().zip(&k) {
            acc += c * k[i];
        }
        out[i] = acc;
    }
}

impl Rodas4Stepper {
    /// Factors `I/(hγ) − J` into `self.lu`, reusing the storage of the previous factors. Returns
    /// whether the matrix is invertible.
    fn decompose<S: OdeSystem>(&mut self, sys: &mut S, h: f64) -> bool {
        let n = self.dfdt.len();
        let mut m = self
            .lu
            .take()
            .map_or_else(|| DMatrix::zeros(n, n), LU::l_unpack);
        let fac = 1.0 / (h * GAMMA);
        for r in 0..n {
            for c in 0..n {
                m[(r, c)] = -self.jac[r * n + c];
            }
            m[(r, r)] += fac;
        }
        let lu = LU::new(m);
        sys.count_lu();
        let ok = lu.is_invertible();
        self.lu = Some(lu);
        ok
    }
}

impl Stepper for Rodas4Stepper {
    fn reset<S: OdeSystem>(&mut self, _sys: &mut S, _t: f64, _y: &[f64]) -> Result<(), Error> {
        // F, J and ∂F/∂t are evaluated by the step at its starting point, and reused only while
        // that point stays the same.
        Ok(())
    }

    fn attempt<S: OdeSystem>(&mut self, sys: &mut S, trial: Trial<'_>) -> Result<f64, Error> {
        let (t, h, y, y_new, norm) = trial.parts();
        let n = y.len();
        if !(self.jac_valid && self.jac_t == t && self.jac_y[..] == *y) {
            self.jac_valid = false;
            sys.rhs(t, y, &mut self.f0)?;
            sys.jacobian(t, y, &mut self.jac, &mut self.dfdt)?;
            self.jac_t = t;
            self.jac_y.copy_from_slice(y);
            self.jac_valid = true;
        }
        if !(1.0 / (h * GAMMA)).is_finite() {
            // A step so short (subnormal) that 1/(hγ) overflows: the change of y is h·F(t, y) to
            // far below rounding, so one explicit Euler step is exact in floating point.
            for i in 0..n {
                y_new[i] = y[i] + h * self.f0[i];
            }
            return Ok(0.0);
        }
        if !self.decompose(sys, h) {
            // A singular iteration matrix: reject, so that the driver retries with a smaller h.
            return Ok(f64::INFINITY);
        }
        let Self {
            dfdt,
            f0,
            lu,
            k,
            ytmp,
            dy,
            ..
        } = self;
        let Some(lu) = lu.as_ref() else {
            return Ok(f64::INFINITY);
        };
        let solve = |u: &mut [f64]| lu.solve_mut(&mut DVectorViewMut::from_slice(u, n));
        let [k1, k2, k3, k4, k5, k6] = k;
        let hinv = 1.0 / h;

        stage_rhs(k1, f0, h * D1, dfdt, [], []);
        solve(k1);

        combine(ytmp, y, 1.0, &S2.a, [k1]);
        sys.rhs(t + S2.c * h, ytmp, dy)?;
        stage_rhs(k2, dy, h * S2.d, dfdt, S2.couplings(hinv), [k1]);
        solve(k2);

        combine(ytmp, y, 1.0, &S3.a, [k1, k2]);
        sys.rhs(t + S3.c * h, ytmp, dy)?;
        stage_rhs(k3, dy, h * S3.d, dfdt, S3.couplings(hinv), [k1, k2]);
        solve(k3);

        combine(ytmp, y, 1.0, &S4.a, [k1, k2, k3]);
        sys.rhs(t + S4.c * h, ytmp, dy)?;
        stage_rhs(k4, dy, h * S4.d, dfdt, S4.couplings(hinv), [k1, k2, k3]);
        solve(k4);

        combine(ytmp, y, 1.0, &S5.a, [k1, k2, k3, k4]);
        sys.rhs(t + h, ytmp, dy)?;
        stage_rhs(k5, dy, 0.0, dfdt, S5.couplings(hinv), [k1, k2, k3, k4]);
        solve(k5);

        // The embedded third-order solution.
        for i in 0..n {
            y_new[i] = ytmp[i] + k5[i];
        }
        sys.rhs(t + h, y_new, dy)?;
        stage_rhs(
            k6,
            dy,
            0.0,
            dfdt,
            C6.map(|c| c * hinv),
            [k1, k2, k3, k4, k5],
        );
        solve(k6);

        // The fourth-order solution; u_6 is its difference from the embedded one.
        for i in 0..n {
            y_new[i] += k6[i];
        }
        Ok(norm.norm(k6, y, y_new))
    }

    fn commit<S: OdeSystem>(&mut self, _sys: &mut S, step: Step<'_>) -> Result<(), Error> {
        let Step { y, y_new, .. } = step;
        let [k1, k2, k3, k4, k5, _] = &self.k;
        let ku = [&**k1, k2, k3, k4, k5];
        let [r0, r1, r2, r3] = &mut self.rcont;
        for i in 0..y.len() {
            r0[i] = y[i];
            r1[i] = y_new[i];
            r2[i] = weighted(&DENSE[0], &ku, i);
            r3[i] = weighted(&DENSE[1], &ku, i);
        }
        Ok(())
    }

    fn interpolate(&self, theta: f64, out: &mut [f64]) {
        let [r0, r1, r2, r3] = &self.rcont;
        let th1 = 1.0 - theta;
        for i in 0..out.len() {
            out[i] = th1 * r0[i] + theta * (r1[i] + th1 * (r2[i] + theta * r3[i]));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::testing::{fixed_steps, loose, Jac, Rhs, Sys};
    use super::super::ErrorNorm;
    use super::*;

    /// Accepted and rejected steps of an adaptive run.
    #[derive(Debug)]
    struct Run {
        y: Vec<f64>,
        accepted: usize,
        rejected: usize,
    }

    /// Adaptive integration from `(t0, y0)` to `t1`: a step is accepted when `err ≤ 1`, and
    /// `h ← h·clamp(0.9·err^(−1/4), 0.2, 5)`.
    fn adaptive<S: OdeSystem>(
        sys: &mut S,
        t0: f64,
        y0: &[f64],
        t1: f64,
        h0: f64,
        norm: &ErrorNorm,
    ) -> Result<Run, Error> {
        let dim = y0.len();
        let mut st = Rodas4.stepper(dim);
        let mut y = y0.to_vec();
        let mut y_new = vec![0.0; dim];
        let (mut t, mut h) = (t0, h0);
        let (mut accepted, mut rejected) = (0, 0);
        st.reset(sys, t, &y)?;
        while t < t1 {
            assert!(accepted + rejected < 100_000, "too many steps at t = {t}");
            let last = t + h >= t1;
            if last {
                h = t1 - t;
            }
            let err = st.try_step(sys, t, h, &y, &mut y_new, norm)?;
            if err <= 1.0 {
                st.accept(sys, t, h, &y, &y_new)?;
                y.copy_from_slice(&y_new);
                t = if last { t1 } else { t + h };
                accepted += 1;
            } else {
                rejected += 1;
            }
            h *= (0.9 * err.powf(-0.25)).clamp(0.2, 5.0);
        }
        Ok(Run {
            y,
            accepted,
            rejected,
        })
    }

    /// `y1' = −(y1 − cos t) − sin t`, `y2' = cos(t)·y2 + y1 − cos t`: the solution
    /// `(cos t, exp(sin t))` from `(1, 1)`, with an explicit time dependence and a coupling that
    /// vanishes on the solution.
    fn non_autonomous() -> Sys<Rhs, Jac> {
        Sys::new(
            2,
            |t: f64, y: &[f64], dy: &mut [f64]| {
                dy[0] = -(y[0] - t.cos()) - t.sin();
                dy[1] = t.cos() * y[1] + y[0] - t.cos();
            },
            |t: f64, y: &[f64], jac: &mut [f64], dfdt: &mut [f64]| {
                jac.copy_from_slice(&[-1.0, 0.0, 1.0, t.cos()]);
                dfdt[0] = -t.sin() - t.cos();
                dfdt[1] = -t.sin() * y[1] + t.sin();
            },
        )
    }

    #[test]
    fn rodas4_tableau_is_consistent() {
        // On y' = 1 (h = 1, J = 0, F_t = 0): u_i = γ (1 + Σ_j c_ij u_j); every stage argument is
        // then y + c_i, the step is exact, the error estimate and the dense-output corrections
        // vanish.
        let c: [&[f64]; 6] = [
            &[],
            &S2.coupling,
            &S3.coupling,
            &S4.coupling,
            &S5.coupling,
            &C6,
        ];
        let mut u = [0.0f64; 6];
        for i in 0..6 {
            let s: f64 = c[i].iter().zip(&u).map(|(c, u)| c * u).sum();
            u[i] = GAMMA * (1.0 + s);
        }
        let a: [(f64, &[f64]); 4] = [(S2.c, &S2.a), (S3.c, &S3.a), (S4.c, &S4.a), (S5.c, &S5.a)];
        for (ci, row) in a {
            let s: f64 = row.iter().zip(&u).map(|(a, u)| a * u).sum();
            assert!((s - ci).abs() < 1e-13, "node {ci}: {s}");
        }
        assert!(u[4].abs() < 1e-13 && u[5].abs() < 1e-13, "{u:?}");
        let [d2, d3] = DENSE.map(|d| d.iter().zip(&u).map(|(d, u)| d * u).sum::<f64>());
        assert!(d2.abs() < 1e-13 && d3.abs() < 1e-13, "{d2} {d3}");
    }

    #[test]
    fn rodas4_integrates_polynomials_in_t_exactly() -> Result<(), Error> {
        // y' = 2t and y' = 4t³: only the ∂F/∂t terms carry the time dependence into the stages.
        let mut sys = Sys::new(
            2,
            |t: f64, _y: &[f64], dy: &mut [f64]| {
                dy[0] = 2.0 * t;
                dy[1] = 4.0 * t.powi(3);
            },
            |t: f64, _y: &[f64], jac: &mut [f64], dfdt: &mut [f64]| {
                jac.fill(0.0);
                dfdt[0] = 2.0;
                dfdt[1] = 12.0 * t * t;
            },
        );
        let y = fixed_steps(&Rodas4, &mut sys, (0.0, &[0.0, 0.0]), 3.0, 3)?;
        eprintln!("t², t⁴ at t = 3: {y:?}");
        assert!((y[0] - 9.0).abs() < 1e-13, "{}", y[0]);
        assert!((y[1] - 81.0).abs() < 1e-11, "{}", y[1]);
        Ok(())
    }

    #[test]
    fn rodas4_step_costs_one_jacobian_one_lu_and_six_evaluations() -> Result<(), Error> {
        for n in [1, 2, 7] {
            let mut sys = non_autonomous();
            fixed_steps(&Rodas4, &mut sys, (0.0, &[1.0, 1.0]), 2.0, n)?;
            assert_eq!(sys.jacobian_evaluations, n);
            assert_eq!(sys.lu_decompositions, n);
            assert_eq!(sys.rhs_evaluations, 6 * n);
        }
        Ok(())
    }

    #[test]
    fn rodas4_reuses_the_jacobian_after_a_rejection() -> Result<(), Error> {
        let mut sys = non_autonomous();
        let mut st = Rodas4.stepper(2);
        let y0 = [1.0, 1.0];
        let mut y1 = [0.0; 2];
        let tight = ErrorNorm::new(1e-12, vec![1e-12; 2]);
        st.reset(&mut sys, 0.0, &y0)?;
        assert!(st.try_step(&mut sys, 0.0, 1.0, &y0, &mut y1, &tight)? > 1.0);
        st.try_step(&mut sys, 0.0, 0.5, &y0, &mut y1, &tight)?;
        assert_eq!(sys.jacobian_evaluations, 1);
        assert_eq!(sys.lu_decompositions, 2);
        assert_eq!(sys.rhs_evaluations, 1 + 5 + 5);
        // A new starting point gets a new Jacobian.
        let y_mid = y1;
        st.accept(&mut sys, 0.0, 0.5, &y0, &y_mid)?;
        st.try_step(&mut sys, 0.5, 0.5, &y_mid, &mut y1, &tight)?;
        assert_eq!(sys.jacobian_evaluations, 2);
        Ok(())
    }

    #[test]
    fn rodas4_singular_iteration_matrix_is_a_rejection() -> Result<(), Error> {
        // J = 4 = 1/(hγ) at h = 1: I/(hγ) − J vanishes.
        let mut sys = Sys::new(
            1,
            |_t: f64, y: &[f64], dy: &mut [f64]| dy[0] = 4.0 * y[0],
            |_t: f64, _y: &[f64], jac: &mut [f64], dfdt: &mut [f64]| {
                jac[0] = 4.0;
                dfdt[0] = 0.0;
            },
        );
        let mut st = Rodas4.stepper(1);
        let mut y1 = [0.0];
        st.reset(&mut sys, 0.0, &[1.0])?;
        let err = st.try_step(&mut sys, 0.0, 1.0, &[1.0], &mut y1, &loose(1))?;
        assert_eq!(err, f64::INFINITY);
        let err = st.try_step(&mut sys, 0.0, 0.01, &[1.0], &mut y1, &loose(1))?;
        assert!(err.is_finite() && (y1[0] - 0.04f64.exp()).abs() < 1e-10);
        Ok(())
    }

    #[test]
    fn rodas4_stiff_linear_problem() -> Result<(), Error> {
        // y' = −1e6 (y − cos t) − sin t, y = cos t over [0, 10]; an explicit method is limited to
        // h ≈ 3e-6 by stability, some 3 million steps.
        let mut sys = Sys::new(
            1,
            |t: f64, y: &[f64], dy: &mut [f64]| dy[0] = -1e6 * (y[0] - t.cos()) - t.sin(),
            |t: f64, _y: &[f64], jac: &mut [f64], dfdt: &mut [f64]| {
                jac[0] = -1e6;
                dfdt[0] = -1e6 * t.sin() - t.cos();
            },
        );
        let norm = ErrorNorm::new(1e-8, vec![1e-10]);
        let run = adaptive(&mut sys, 0.0, &[1.0], 10.0, 1e-4, &norm)?;
        let err = (run.y[0] - 10.0f64.cos()).abs();
        eprintln!(
            "stiff linear: error {err:e}, {run:?}, rhs {}, jacobians {}, LU {}",
            sys.rhs_evaluations, sys.jacobian_evaluations, sys.lu_decompositions
        );
        assert!(err < 1e-7, "{err:e}");
        assert!(run.accepted + run.rejected < 500, "{run:?}");
        Ok(())
    }

    #[test]
    fn rodas4_robertson_kinetics() -> Result<(), Error> {
        // Robertson's chemical kinetics over [0, 1e11], reference values of the IVP test set
        // (Mazzia, Magherini, Bari). Once y3 is of order 1 the fast reaction gives an eigenvalue
        // between about −3e3 and −1e4, so an explicit method would need on the order of 1e14
        // steps.
        let mut sys = Sys::new(
            3,
            |_t: f64, y: &[f64], dy: &mut [f64]| {
                dy[0] = -0.04 * y[0] + 1e4 * y[1] * y[2];
                dy[2] = 3e7 * y[1] * y[1];
                dy[1] = -dy[0] - dy[2];
            },
            |_t: f64, y: &[f64], jac: &mut [f64], dfdt: &mut [f64]| {
                let a = [-0.04, 1e4 * y[2], 1e4 * y[1]];
                let b = [0.0, 6e7 * y[1], 0.0];
                jac[..3].copy_from_slice(&a);
                jac[6..].copy_from_slice(&b);
                for j in 0..3 {
                    jac[3 + j] = -a[j] - b[j];
                }
                dfdt.fill(0.0);
            },
        );
        let norm = ErrorNorm::new(1e-6, vec![1e-12, 1e-16, 1e-12]);
        let run = adaptive(&mut sys, 0.0, &[1.0, 0.0, 0.0], 1e11, 1e-6, &norm)?;
        let reference = [
            0.2083340149701255e-7,
            0.8333360770334713e-13,
            0.9999999791665050,
        ];
        let rel: Vec<f64> = (0..3)
            .map(|i| (run.y[i] - reference[i]).abs() / reference[i])
            .collect();
        let mass = run.y.iter().sum::<f64>() - 1.0;
        eprintln!(
            "Robertson: relative errors {rel:?}, mass defect {mass:e}, {run:?}, rhs {}, \
             jacobians {}, LU {}",
            sys.rhs_evaluations, sys.jacobian_evaluations, sys.lu_decompositions
        );
        assert!(rel.iter().all(|&e| e < 1e-3), "{rel:?}");
        assert!(mass.abs() < 1e-13, "{mass:e}");
        assert!(run.accepted + run.rejected < 1000, "{run:?}");
        Ok(())
    }
}
