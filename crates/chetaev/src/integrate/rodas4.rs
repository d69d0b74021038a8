//! RODAS: Hairer and Wanner's L-stable, stiffly accurate Rosenbrock method of order 4(3) with six
//! stages, an embedded third-order error estimate and a third-order dense output.
//!
//! Method: E. Hairer, G. Wanner, *Solving Ordinary Differential Equations II*, 2nd ed., Springer
//! 1996, Sections IV.7, VI.3 and VI.4 (the code RODAS). The coefficients are those of the published
//! code `rodas.f`, subroutine `ROCOE` with `METH = 1`, reproduced here digit for digit;
//! `OrdinaryDiffEq.jl`'s `Rodas4` tableau has the same values. The stages, the error estimate and
//! the dense output are those of the family, in [`rosenbrock`](super::rosenbrock): `γ = 1/4`, the
//! first five stages from their rows of `a` (`c_5 = 1`), the sixth at the embedded solution
//! `Y_6 = Y_5 + u_5`, and `y_1 = Y_6 + u_6`; the step size is controlled with the exponent `1/4`.

#![allow(clippy::excessive_precision)]

use super::rosenbrock::{lower, RosenbrockStepper, Tableau};
use super::{Method, MethodInfo};

/// The tableau of `rodas.f` (`METH = 1`): its `A_ij`, `C_ij`, nodes `C_i`, `D_i`, and dense-output
/// rows `D_2j`, `D_3j`.
static TABLEAU: Tableau<6, 2> = Tableau {
    gamma: 0.25,
    m: 5,
    c: [0.0, 0.386, 0.21, 0.63, 1.0, 1.0],
    d: [
        0.2500000000000000e+00,
        -0.1043000000000000e+00,
        0.1035000000000000e+00,
        -0.3620000000000023e-01,
        0.0,
        0.0,
    ],
    a: [
        [0.0; 6],
        lower(&[0.1544000000000000e+01]),
        lower(&[0.9466785280815826e+00, 0.2557011698983284e+00]),
        lower(&[
            0.3314825187068521e+01,
            0.2896124015972201e+01,
            0.9986419139977817e+00,
        ]),
        lower(&[
            0.1221224509226641e+01,
            0.6019134481288629e+01,
            0.1253708332932087e+02,
            -0.6878860361058950e+00,
        ]),
        [0.0; 6],
    ],
    coupling: [
        [0.0; 6],
        lower(&[-0.5668800000000000e+01]),
        lower(&[-0.2430093356833875e+01, -0.2063599157091915e+00]),
        lower(&[
            -0.1073529058151375e+00,
            -0.9594562251023355e+01,
            -0.2047028614809616e+02,
        ]),
        lower(&[
            0.7496443313967647e+01,
            -0.1024680431464352e+02,
            -0.3399990352819905e+02,
            0.1170890893206160e+02,
        ]),
        lower(&[
            0.8083246795921522e+01,
            -0.7981132988064893e+01,
            -0.3152159432874371e+02,
            0.1631930543123136e+02,
            -0.6058818238834054e+01,
        ]),
    ],
    dense: [
        [
            0.1012623508344586e+02,
            -0.7487995877610167e+01,
            -0.3480091861555747e+02,
            -0.7992771707568823e+01,
            0.1025137723295662e+01,
            0.0,
        ],
        [
            -0.6762803392801253e+00,
            0.6087714651680015e+01,
            0.1643084320892478e+02,
            0.2476722511418386e+02,
            -0.6594389125716872e+01,
            0.0,
        ],
    ],
};

/// RODAS of Hairer and Wanner: linearly implicit (Rosenbrock), L-stable, stiffly accurate, order
/// 4(3), with third-order dense output.
///
/// The method for stiff problems, which an explicit method such as [`Dopri5`](super::Dopri5)
/// reports with [`Error::Stiff`](crate::Error::Stiff). Every step uses the exact Jacobian of the
/// reduced equations and their exact time derivative (nested dual numbers), so the order is
/// attained on non-autonomous problems as well. It has no options: the step-size control is the
/// driver's. For tolerances of about `1e-8` and below, [`Rodas5P`](super::Rodas5P) is usually
/// cheaper.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Rodas4;

/// The working state of [`Rodas4`].
pub type Rodas4Stepper = RosenbrockStepper<6, 2>;

impl Method for Rodas4 {
    type Stepper = Rodas4Stepper;
    fn info(&self) -> MethodInfo {
        MethodInfo::rosenbrock("Rodas4", (4, 3), 3).with_advice(
            "on a non-stiff problem Dopri5 or Dop853 is cheaper; a failing Rodas4 run often means a \
             singularity of the model near the failure",
        )
    }
    fn stepper(&self, dim: usize) -> Rodas4Stepper {
        RosenbrockStepper::new(&TABLEAU, dim)
    }
}

#[cfg(test)]
mod tests {
    use super::super::rosenbrock::tests::check_consistency;
    use super::super::system::OdeSystem;
    use super::super::testing::{fixed_steps, loose, Jac, Rhs, Sys};
    use super::super::{ErrorNorm, Stepper};
    use super::*;
    use crate::error::Error;

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
        check_consistency(&TABLEAU);
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
