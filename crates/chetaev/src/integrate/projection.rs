//! Projection of the velocity onto the constraint manifold `f(t, q, ·) = 0`.
//!
//! The reduced equations keep only `df/dt = 0`, so `f` drifts with the integration error. The
//! projection finds the smallest correction of `q̇` in the kinetic metric `W = ∂²L/∂q̇²`, by Newton
//! iteration on
//!
//! ```text
//! [ W   −Jᵀ ] [ Δq̇ ]   [  0 ]
//! [ J    0  ] [ λ  ] = [ −f ],      q̇ ← q̇ + Δq̇,
//! ```
//!
//! the same block system as the equations of motion, so it needs no new assumption. Positions are
//! not touched: velocity constraints do not restrict them.

use nalgebra::SVector;

use crate::equations::derivatives::{constraint_derivatives, velocity_hessian};
use crate::equations::saddle::{self, SaddleWorkspace};
use crate::error::Error;
use crate::integrate::system::locate;
use crate::model::Model;

/// Options of the projection onto `f = 0`. Opt-in: see [`Options::project`](super::options::Options::project).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Projection {
    /// Relative residual to keep: `|f_a| ≤ tol · |J_a|·|q̇|` for every constraint `a`. A state
    /// already within it is left alone, so the residual is held at or below `tol`. The default
    /// 1e-12 leaves room for nearly dependent constraints, whose rounding floor is raised by their
    /// conditioning; a well-conditioned constraint can be held at 1e-14.
    pub tol: f64,
    /// Newton iterations before giving up with [`Error::ProjectionFailed`].
    pub max_iterations: usize,
}

impl Default for Projection {
    fn default() -> Self {
        Self {
            tol: 1e-12,
            max_iterations: 10,
        }
    }
}

/// The result of a projection.
#[derive(Clone, Copy, Debug)]
pub struct Projected<const N: usize> {
    /// The projected velocity.
    pub qd: SVector<f64, N>,
    /// Newton iterations done (each one derivative evaluation and block solve).
    pub iterations: usize,
    /// `max_a |f_a|` relative to `|J_a|·|q̇|` at the projected velocity.
    pub residual: f64,
}

/// The natural scale `|J_a|·|q̇|` of constraint `a` (1 where it vanishes), against which residuals
/// are measured.
pub(crate) fn constraint_scale(j_row_norm: f64, qd_norm: f64) -> f64 {
    let s = j_row_norm * qd_norm;
    if s > 0.0 {
        s
    } else {
        1.0
    }
}

/// Projects `q̇` onto `f(t, q, ·) = 0` in the metric `W`; see the module docs.
pub fn project_velocity<M: Model<N, K>, const N: usize, const K: usize>(
    model: &M,
    ws: &mut SaddleWorkspace<f64>,
    t: f64,
    q: &SVector<f64, N>,
    qd: &SVector<f64, N>,
    tol: f64,
    max_iterations: usize,
) -> Result<Projected<N>, Error> {
    let mut qd = *qd;
    let mut residual = f64::INFINITY;
    let mut previous = f64::INFINITY;
    for iteration in 0..=max_iterations {
        let cd = constraint_derivatives::<M, f64, N, K>(model, t, q, &qd);
        let qd_norm = qd.norm();
        residual = (0..K).fold(0.0f64, |acc, a| {
            acc.max(cd.f[a].abs() / constraint_scale(cd.j.row(a).norm(), qd_norm))
        });
        if !residual.is_finite() {
            return Err(locate(saddle::SaddleFailure::NonFinite, t, q, &qd));
        }
        // Stagnation close to the tolerance is the rounding floor of f, not a failure to converge.
        let stagnated = iteration > 0 && residual > 0.5 * previous && residual <= 1e3 * tol;
        if stagnated {
            return Ok(Projected {
                qd,
                iterations: iteration,
                residual,
            });
        }
        previous = residual;
        if residual <= tol || iteration == max_iterations {
            if residual <= tol {
                return Ok(Projected {
                    qd,
                    iterations: iteration,
                    residual,
                });
            }
            break;
        }
        let (_, _, w) = velocity_hessian(model, t, q, &qd);
        let sol = saddle::solve(ws, &w, &cd.j, &SVector::zeros(), &(-cd.f))
            .map_err(|e| locate(e, t, q, &qd))?;
        let step = sol.qdd;
        qd += step;
        // Stop at the rounding floor: a correction below a few ulps of q̇ cannot reduce f further.
        if step.norm() <= 4.0 * f64::EPSILON * qd.norm() {
            let cd = constraint_derivatives::<M, f64, N, K>(model, t, q, &qd);
            let qd_norm = qd.norm();
            let r = (0..K).fold(0.0f64, |acc, a| {
                acc.max(cd.f[a].abs() / constraint_scale(cd.j.row(a).norm(), qd_norm))
            });
            if r <= 1e3 * tol.max(f64::EPSILON) {
                return Ok(Projected {
                    qd,
                    iterations: iteration + 1,
                    residual: r,
                });
            }
        }
    }
    Err(Error::ProjectionFailed {
        t,
        residual,
        iterations: max_iterations,
    })
}
