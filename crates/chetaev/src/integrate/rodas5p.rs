//! Rodas5P: Steinebach's L-stable, stiffly accurate Rosenbrock method of order 5(4) with eight
//! stages, an embedded fourth-order error estimate and a fourth-order dense output.
//!
//! Method: G. Steinebach, *Construction of Rosenbrock–Wanner method Rodas5P and numerical
//! benchmarks within the Julia Differential Equations package*, BIT Numerical Mathematics 63, 27
//! (2023). It keeps the structure of Di Marzo's Rodas5 and improves its convergence on stiff
//! problems and its dense output. The coefficients are those of `OrdinaryDiffEq.jl`'s
//! `Rodas5PTableau`, in the same variables as RODAS, reproduced here digit for digit. The stages,
//! the error estimate and the dense output are those of the family, in
//! [`rosenbrock`](super::rosenbrock): `γ ≈ 0.2119`, the first six stages from their rows of `a`
//! (`c_6 = 1`), the seventh and eighth at `Y_7 = Y_6 + u_6` and `Y_8 = Y_7 + u_7`, and
//! `y_1 = Y_8 + u_8`; the step size is controlled with the exponent `1/5`.

#![allow(clippy::excessive_precision)]

use super::rosenbrock::{lower, RosenbrockStepper, Tableau};
use super::{Method, MethodInfo};

/// `γ`, which is also `d_1`.
const GAMMA: f64 = 0.21193756319429014;

/// The tableau of `OrdinaryDiffEq.jl`'s `Rodas5PTableau`: its `a_ij`, `C_ij`, nodes `c_i`, `d_i`,
/// and dense-output rows `h_2j`, `h_3j`, `h_4j`.
static TABLEAU: Tableau<8, 3> = Tableau {
    gamma: GAMMA,
    m: 6,
    c: [
        0.0,
        0.6358126895828704,
        0.4095798393397535,
        0.9769306725060716,
        0.4288403609558664,
        1.0,
        1.0,
        1.0,
    ],
    d: [
        GAMMA,
        -0.42387512638858027,
        -0.3384627126235924,
        1.8046452872882734,
        2.325825639765069,
        0.0,
        0.0,
        0.0,
    ],
    a: [
        [0.0; 8],
        lower(&[3.0]),
        lower(&[2.849394379747939, 0.45842242204463923]),
        lower(&[-6.954028509809101, 2.489845061869568, -10.358996098473584]),
        lower(&[
            2.8029986275628964,
            0.5072464736228206,
            -0.3988312541770524,
            -0.04721187230404641,
        ]),
        lower(&[
            -7.502846399306121,
            2.561846144803919,
            -11.627539656261098,
            -0.18268767659942256,
            0.030198172008377946,
        ]),
        [0.0; 8],
        [0.0; 8],
    ],
    coupling: [
        [0.0; 8],
        lower(&[-14.155112264123755]),
        lower(&[-17.97296035885952, -2.859693295451294]),
        lower(&[147.12150275711716, -1.41221402718213, 71.68940251302358]),
        lower(&[
            165.43517024871676,
            -0.4592823456491126,
            42.90938336958603,
            -5.961986721573306,
        ]),
        lower(&[
            24.854864614690072,
            -3.0009227002832186,
            47.4931110020768,
            5.5814197821558125,
            -0.6610691825249471,
        ]),
        lower(&[
            30.91273214028599,
            -3.1208243349937974,
            77.79954646070892,
            34.28646028294783,
            -19.097331116725623,
            -28.087943162872662,
        ]),
        lower(&[
            37.80277123390563,
            -3.2571969029072276,
            112.26918849496327,
            66.9347231244047,
            -40.06618937091002,
            -54.66780262877968,
            -9.48861652309627,
        ]),
    ],
    dense: [
        [
            25.948786856663858,
            -2.5579724845846235,
            10.433815404888879,
            -2.3679251022685204,
            0.524948541321073,
            1.1241088310450404,
            0.4272876194431874,
            -0.17202221070155493,
        ],
        [
            -9.91568850695171,
            -0.9689944594115154,
            3.0438037242978453,
            -24.495224566215796,
            20.176138334709044,
            15.98066361424651,
            -6.789040303419874,
            -6.710236069923372,
        ],
        [
            11.419903575922262,
            2.8879645146136994,
            72.92137995996029,
            80.12511834622643,
            -52.072871366152654,
            -59.78993625266729,
            -0.15582684282751913,
            4.883087185713722,
        ],
    ],
};

/// Rodas5P of Steinebach: linearly implicit (Rosenbrock), L-stable, stiffly accurate, order 5(4),
/// with fourth-order dense output.
///
/// Like [`Rodas4`](super::Rodas4) a method for stiff problems, with the exact Jacobian of the
/// reduced equations and their exact time derivative at every step. Its eight stages cost a third
/// more than Rodas4's six, and its fifth order repays them at tight tolerances. It has no options:
/// the step-size control is the driver's.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Rodas5P;

/// The working state of [`Rodas5P`].
pub type Rodas5PStepper = RosenbrockStepper<8, 3>;

impl Method for Rodas5P {
    type Stepper = Rodas5PStepper;
    fn info(&self) -> MethodInfo {
        MethodInfo::rosenbrock("Rodas5P", (5, 4), 4).with_advice(
            "on a non-stiff problem Dopri5 or Dop853 is cheaper; a failing Rodas5P run often means \
             a singularity of the model near the failure",
        )
    }
    fn stepper(&self, dim: usize) -> Rodas5PStepper {
        RosenbrockStepper::new(&TABLEAU, dim)
    }
}

#[cfg(test)]
mod tests {
    use super::super::rosenbrock::tests::check_consistency;
    use super::super::testing::{fixed_steps, Sys};
    use super::*;
    use crate::error::Error;

    #[test]
    fn rodas5p_tableau_is_consistent() {
        check_consistency(&TABLEAU);
    }

    #[test]
    fn rodas5p_step_costs_one_jacobian_one_lu_and_eight_evaluations() -> Result<(), Error> {
        for n in [1, 3] {
            let mut sys = Sys::new(
                1,
                |t: f64, y: &[f64], dy: &mut [f64]| dy[0] = -y[0] + t,
                |_t: f64, _y: &[f64], jac: &mut [f64], dfdt: &mut [f64]| {
                    jac[0] = -1.0;
                    dfdt[0] = 1.0;
                },
            );
            fixed_steps(&Rodas5P, &mut sys, (0.0, &[1.0]), 1.0, n)?;
            assert_eq!(sys.jacobian_evaluations, n);
            assert_eq!(sys.lu_decompositions, n);
            assert_eq!(sys.rhs_evaluations, 8 * n);
        }
        Ok(())
    }
}
