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
use crate::equations::saddle::{self, SaddleFailure, SaddleWorkspace};
use crate::error::Error;
use crate::integrate::system::locate_slices;
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
    let mut v = *qd;
    let outcome = newton_projection(
        N,
        K,
        v.as_mut_slice(),
        Projection {
            tol,
            max_iterations,
        },
        ws,
        |qd, f, j| {
            let cd = constraint_derivatives::<M, f64, N, K>(
                model,
                t,
                q,
                &SVector::from_column_slice(qd),
            );
            f.copy_from_slice(cd.f.as_slice());
            for a in 0..K {
                for i in 0..N {
                    j[a * N + i] = cd.j[(a, i)];
                }
            }
        },
        |qd, w| {
            let (_, _, wm) = velocity_hessian(model, t, q, &SVector::from_column_slice(qd));
            for i in 0..N {
                for m in 0..N {
                    w[i * N + m] = wm[(i, m)];
                }
            }
        },
    );
    match outcome {
        Ok((iterations, residual)) => Ok(Projected {
            qd: v,
            iterations,
            residual,
        }),
        Err(e) => Err(e.locate(t, q.as_slice(), v.as_slice())),
    }
}

/// Why a Newton projection stopped without converging.
#[derive(Clone, Copy, Debug)]
pub(crate) enum ProjectionFailure {
    /// The block system failed (non-finite values, a degenerate or dependent constraint).
    Saddle(SaddleFailure),
    /// The residual did not reach the tolerance.
    NotConverged {
        /// Relative residual after the last iteration.
        residual: f64,
        /// Iterations done.
        iterations: usize,
    },
}

impl ProjectionFailure {
    /// The error, with the time and state where it happened.
    pub(crate) fn locate(self, t: f64, q: &[f64], qd: &[f64]) -> Error {
        match self {
            Self::Saddle(e) => locate_slices(e, t, q, qd),
            Self::NotConverged {
                residual,
                iterations,
            } => Error::ProjectionFailed {
                t,
                residual,
                iterations,
            },
        }
    }
}

/// The Newton iteration of the projection for any sizes: `constraints(q̇, f, J)` writes `f` (`k`)
/// and `J` (`k × n`, row-major), `metric(q̇, W)` writes `W` (`n × n`, row-major). Corrects `qd` in
/// place; returns the iterations done and the final relative residual.
pub(crate) fn newton_projection(
    n: usize,
    k: usize,
    qd: &mut [f64],
    settings: Projection,
    ws: &mut SaddleWorkspace<f64>,
    mut constraints: impl FnMut(&[f64], &mut [f64], &mut [f64]),
    mut metric: impl FnMut(&[f64], &mut [f64]),
) -> Result<(usize, f64), ProjectionFailure> {
    let Projection {
        tol,
        max_iterations,
    } = settings;
    let (mut f, mut j, mut w) = (vec![0.0; k], vec![0.0; k * n], vec![0.0; n * n]);
    let norm = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
    let relative = |f: &[f64], j: &[f64], qd: &[f64]| {
        let qd_norm = norm(qd);
        (0..k).fold(0.0f64, |acc, a| {
            acc.max(f[a].abs() / constraint_scale(norm(&j[a * n..(a + 1) * n]), qd_norm))
        })
    };
    let mut residual = f64::INFINITY;
    let mut previous = f64::INFINITY;
    for iteration in 0..=max_iterations {
        constraints(qd, &mut f, &mut j);
        residual = relative(&f, &j, qd);
        if !residual.is_finite() {
            return Err(ProjectionFailure::Saddle(SaddleFailure::NonFinite));
        }
        // Stagnation close to the tolerance is the rounding floor of f, not a failure to converge.
        let stagnated = iteration > 0 && residual > 0.5 * previous && residual <= 1e3 * tol;
        if residual <= tol || stagnated {
            return Ok((iteration, residual));
        }
        if iteration == max_iterations {
            break;
        }
        previous = residual;
        metric(qd, &mut w);
        saddle::solve_blocks(
            ws,
            n,
            k,
            |i, m| w[i * n + m],
            |a, i| j[a * n + i],
            |_| 0.0,
            |a| -f[a],
        )
        .map_err(ProjectionFailure::Saddle)?;
        let step = &ws.solution()[..n];
        let step_norm = norm(step);
        for (v, dv) in qd.iter_mut().zip(step) {
            *v += dv;
        }
        // Stop at the rounding floor: a correction below a few ulps of q̇ cannot reduce f further.
        if step_norm <= 4.0 * f64::EPSILON * norm(qd) {
            constraints(qd, &mut f, &mut j);
            let r = relative(&f, &j, qd);
            if r <= 1e3 * tol.max(f64::EPSILON) {
                return Ok((iteration + 1, r));
            }
        }
    }
    Err(ProjectionFailure::NotConverged {
        residual,
        iterations: max_iterations,
    })
}
