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

use crate::equations::saddle::{self, SaddleFailure};
use crate::equations::Workspace;
use crate::error::Error;
use crate::integrate::system::locate;
use crate::model::{Model, Point};

/// Options of the projection onto `f = 0`. Opt-in: see [`Options::project`](super::options::Options::project).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Projection {
    /// Relative residual to keep: `|f_a| ≤ tol · |J_a|·|q̇|` for every constraint `a`. A state
    /// already within it is left alone, so the residual is held at or below `tol`. The default
    /// 1e-12 leaves room for nearly dependent constraints, whose rounding floor is raised by their
    /// conditioning; a well-conditioned constraint can be held at 1e-14. Below `f64::EPSILON`,
    /// the rounding error of `f` itself, it is refused, and so is 1 or more.
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

/// Projects `q̇` (in place, length `n`) onto `f(t, q, ·) = 0` in the metric `W`; see the module
/// docs. Returns the Newton iterations done (each one derivative evaluation and block solve).
pub fn project_velocity<M: Model + ?Sized>(
    model: &M,
    ws: &mut Workspace<f64>,
    t: f64,
    q: &[f64],
    qd: &mut [f64],
    settings: Projection,
) -> Result<usize, Error> {
    let (n, k) = model.sizes();
    if k == 0 {
        return Ok(0);
    }
    let mut blocks = crate::equations::derivatives::ConstraintBlocks::new(n, k);
    newton_projection(
        n,
        k,
        qd,
        settings,
        ws,
        |qd, f, j| {
            model.constraint_blocks(Point::new(t, q, qd), false, &mut blocks);
            f.copy_from_slice(&blocks.f);
            j.copy_from_slice(&blocks.j);
        },
        |qd, w| model.velocity_hessian(Point::new(t, q, qd), w),
        |_, _| false,
    )
    .map(|(iterations, _)| iterations)
    .map_err(|e| e.locate(t, q, qd))
}

/// Projects the positions `q` (in place) onto the holonomic constraints `h(t, ·) = 0`: the
/// smallest change of `q` in the metric `W(t, q, q̇)`, by the same Newton iteration on
/// `[W −Hᵀ; H 0][Δq; λ] = [0; −h]`, `H = ∂h/∂q`. Velocities are not touched; project them after
/// (`ḣ = 0` is among the velocity constraints). Returns the Newton iterations done.
pub fn project_positions<M: Model + ?Sized>(
    model: &M,
    ws: &mut Workspace<f64>,
    t: f64,
    q: &mut [f64],
    qd: &[f64],
    settings: Projection,
) -> Result<usize, Error> {
    let count = model.holonomic_count();
    if count == 0 {
        return Ok(0);
    }
    let n = q.len();
    newton_projection(
        n,
        count,
        q,
        settings,
        ws,
        |q, h, hq| model.holonomic_blocks(t, q, h, Some(hq)),
        |q, w| model.velocity_hessian(Point::new(t, q, qd), w),
        // Next to the coordinates' origin the relative residual's scale `|∂h/∂q|·|q|` vanishes:
        // there a residual within the rounding of `h`'s terms is as close as `q` can come.
        |q, h| {
            crate::problem::holonomic_rounding(model, t, q, qd).is_some_and(|r| {
                h.iter()
                    .zip(r)
                    .all(|(h, r)| h.abs() <= crate::problem::ROUNDING_ULPS * f64::EPSILON * r)
            })
        },
    )
    .map(|(iterations, _)| iterations)
    .map_err(|e| e.locate(t, q, qd))
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
            Self::Saddle(e) => locate(e, t, q, qd),
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
/// place; returns the iterations done and the final relative residual. `settled(q̇, f)` says
/// whether `f` is within the rounding of the constraints' terms: asked only where the iteration
/// would otherwise stop unconverged, it accepts the state then.
// The sizes, the state, the settings, the workspace and the model's three callbacks.
#[allow(clippy::too_many_arguments)]
pub(crate) fn newton_projection(
    n: usize,
    k: usize,
    qd: &mut [f64],
    settings: Projection,
    ws: &mut Workspace<f64>,
    mut constraints: impl FnMut(&[f64], &mut [f64], &mut [f64]),
    mut metric: impl FnMut(&[f64], &mut [f64]),
    mut settled: impl FnMut(&[f64], &[f64]) -> bool,
) -> Result<(usize, f64), ProjectionFailure> {
    let Projection {
        tol,
        max_iterations,
    } = settings;
    let (mut f, mut j, mut w) = (vec![0.0; k], vec![0.0; k * n], vec![0.0; n * n]);
    let norm = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
    // The largest residual relative to its scale; infinite where a value or a scale is not finite
    // (an overflow: a Newton step that left every sensible scale), so that it is never taken
    // for convergence.
    let relative = |f: &[f64], j: &[f64], qd: &[f64]| {
        let qd_norm = norm(qd);
        let mut worst = 0.0f64;
        for a in 0..k {
            let scale = constraint_scale(norm(&j[a * n..(a + 1) * n]), qd_norm);
            let r = f[a].abs() / scale;
            if !(r.is_finite() && scale.is_finite()) {
                return f64::INFINITY;
            }
            worst = worst.max(r);
        }
        worst
    };
    let mut residual = f64::INFINITY;
    let mut previous = f64::INFINITY;
    for iteration in 0..=max_iterations {
        constraints(qd, &mut f, &mut j);
        residual = relative(&f, &j, qd);
        if !residual.is_finite() {
            // At the start, the model itself; after a Newton step, a step that overshot (from
            // near a point where a gradient vanishes) and diverged.
            return Err(if iteration == 0 {
                ProjectionFailure::Saddle(SaddleFailure::NonFinite)
            } else {
                ProjectionFailure::NotConverged {
                    residual,
                    iterations: iteration,
                }
            });
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
            ws.saddle(),
            n,
            k,
            |i, m| w[i * n + m],
            |a, i| j[a * n + i],
            |_| 0.0,
            |a| -f[a],
        )
        .map_err(ProjectionFailure::Saddle)?;
        let step = &ws.saddle().solution()[..n];
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
    if residual.is_finite() && settled(qd, &f) {
        return Ok((max_iterations, residual));
    }
    Err(ProjectionFailure::NotConverged {
        residual,
        iterations: max_iterations,
    })
}
