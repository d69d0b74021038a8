//! The reduced Chetaev equations as a first-order ODE on flat `f64` slices, which is all an
//! integrator sees.
//!
//! State layout: `y = [q (N), q̇ (N)]`, followed, when the energy balance is recorded, by two
//! quadratures `[W_Φ, ∫∂L/∂t dt]` with `dW_Φ/dt = q̇·Φ`. The quadratures are outside error
//! control, so recording them never changes the motion.

use nalgebra::SVector;
use num_dual::Dual64;

use crate::equations::{dynamics, saddle::SaddleFailure, saddle::SaddleWorkspace, Dynamics};
use crate::error::Error;
use crate::model::Model;

/// A first-order system `y' = F(t, y)` on flat slices.
pub trait OdeSystem {
    /// Length of `y`.
    fn dim(&self) -> usize;
    /// The first `controlled_dim()` components are under error control.
    fn controlled_dim(&self) -> usize;
    /// `dy = F(t, y)`.
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), Error>;
    /// The Jacobian `∂F/∂y` (row-major, `dim × dim`) and `∂F/∂t` (length `dim`). Only implicit
    /// methods call it.
    fn jacobian(
        &mut self,
        t: f64,
        y: &[f64],
        jac: &mut [f64],
        dfdt: &mut [f64],
    ) -> Result<(), Error>;
    /// Records one LU decomposition of an implicit method's iteration matrix.
    fn count_lu(&mut self) {}
}

/// Counts of the work done, kept where user code is called so that no method can forget one.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Stats {
    /// Evaluations of the reduced right-hand side by the integrator.
    pub rhs_evaluations: usize,
    /// Evaluations of the exact Jacobian (each costs `2·dim + 1` dual right-hand sides).
    pub jacobian_evaluations: usize,
    /// LU decompositions of the implicit methods' iteration matrix.
    pub lu_decompositions: usize,
    /// Evaluations for the recorded diagnostics (`q̈`, `μ`, `Φ`, `f`, `E`) at output points.
    pub output_evaluations: usize,
    /// Accepted steps.
    pub accepted_steps: usize,
    /// Rejected steps.
    pub rejected_steps: usize,
    /// Projections onto the constraints.
    pub projections: usize,
    /// Newton iterations spent in projections (each one derivative evaluation and block solve).
    pub projection_iterations: usize,
    /// Evaluations of event functions.
    pub event_evaluations: usize,
}

impl Stats {
    /// The step loop's counts (steps) combined with the system's (evaluations, projections) and
    /// the hooks' event evaluations.
    pub(crate) fn merged(self, system: Stats, event_evaluations: usize) -> Stats {
        Stats {
            accepted_steps: self.accepted_steps,
            rejected_steps: self.rejected_steps,
            event_evaluations,
            ..system
        }
    }
}

/// Adds `t` and the state to a failure of the block solve.
pub(crate) fn locate<const N: usize>(
    e: SaddleFailure,
    t: f64,
    q: &SVector<f64, N>,
    qd: &SVector<f64, N>,
) -> Error {
    locate_slices(e, t, q.as_slice(), qd.as_slice())
}

/// [`locate`] for states held as slices.
pub(crate) fn locate_slices(e: SaddleFailure, t: f64, q: &[f64], qd: &[f64]) -> Error {
    let (q, qd) = (q.to_vec(), qd.to_vec());
    match e {
        SaddleFailure::NonFinite => Error::NonFiniteEvaluation { t, q, qd },
        SaddleFailure::ZeroConstraintRow { row } => Error::DegenerateConstraint {
            t,
            index: row,
            q,
            qd,
        },
        SaddleFailure::Singular { pivot_ratio } => Error::Singular {
            t,
            pivot_ratio,
            q,
            qd,
        },
    }
}

/// The reduced equations of one model, with scratch space and counters.
pub(crate) struct ChetaevOde<'a, M, const N: usize, const K: usize> {
    pub model: &'a M,
    pub ws: SaddleWorkspace<f64>,
    pub energy: bool,
    pub stats: Stats,
}

impl<'a, M: Model<N, K>, const N: usize, const K: usize> ChetaevOde<'a, M, N, K> {
    pub fn new(model: &'a M, energy: bool) -> Self {
        Self {
            model,
            ws: SaddleWorkspace::default(),
            energy,
            stats: Stats::default(),
        }
    }

    /// The full dynamics at a state, for output (counted as an output evaluation).
    pub fn evaluate(
        &mut self,
        t: f64,
        q: &SVector<f64, N>,
        qd: &SVector<f64, N>,
    ) -> Result<Dynamics<f64, N, K>, Error> {
        self.stats.output_evaluations += 1;
        dynamics(self.model, &mut self.ws, t, q, qd).map_err(|e| locate(e, t, q, qd))
    }
}

/// Splits a flat state into `q` and `q̇`.
#[inline(always)]
pub(crate) fn split<const N: usize>(y: &[f64]) -> (SVector<f64, N>, SVector<f64, N>) {
    (
        SVector::<f64, N>::from_column_slice(&y[..N]),
        SVector::<f64, N>::from_column_slice(&y[N..2 * N]),
    )
}

impl<M: Model<N, K>, const N: usize, const K: usize> OdeSystem for ChetaevOde<'_, M, N, K> {
    fn dim(&self) -> usize {
        if self.energy {
            2 * N + 2
        } else {
            2 * N
        }
    }

    fn controlled_dim(&self) -> usize {
        2 * N
    }

    #[inline]
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), Error> {
        self.stats.rhs_evaluations += 1;
        let (q, qd) = split::<N>(y);
        let d =
            dynamics(self.model, &mut self.ws, t, &q, &qd).map_err(|e| locate(e, t, &q, &qd))?;
        dy[..N].copy_from_slice(qd.as_slice());
        dy[N..2 * N].copy_from_slice(d.qdd.as_slice());
        if self.energy {
            dy[2 * N] = d.power(&qd);
            dy[2 * N + 1] = d.dl_dt;
        }
        Ok(())
    }

    fn count_lu(&mut self) {
        self.stats.lu_decompositions += 1;
    }

    fn jacobian(
        &mut self,
        t: f64,
        y: &[f64],
        jac: &mut [f64],
        dfdt: &mut [f64],
    ) -> Result<(), Error> {
        self.stats.jacobian_evaluations += 1;
        let dim = self.dim();
        let mut ws = SaddleWorkspace::<Dual64>::default();
        // One forward pass per direction: y_j for j < 2N, then t. The quadratures do not feed back.
        for dir in 0..=2 * N {
            let seed = |i: usize| if i == dir { 1.0 } else { 0.0 };
            let q = SVector::<Dual64, N>::from_fn(|i, _| Dual64::new(y[i], seed(i)));
            let qd = SVector::<Dual64, N>::from_fn(|i, _| Dual64::new(y[N + i], seed(N + i)));
            let td = Dual64::new(t, seed(2 * N));
            let (qr, qdr) = split::<N>(y);
            let d =
                dynamics(self.model, &mut ws, td, &q, &qd).map_err(|e| locate(e, t, &qr, &qdr))?;
            let mut col = |row: usize, v: f64| {
                if dir < 2 * N {
                    jac[row * dim + dir] = v;
                } else {
                    dfdt[row] = v;
                }
            };
            for i in 0..N {
                col(i, qd[i].eps);
                col(N + i, d.qdd[i].eps);
            }
            if self.energy {
                col(2 * N, d.power(&qd).eps);
                col(2 * N + 1, d.dl_dt.eps);
            }
        }
        if self.energy {
            for row in 0..dim {
                jac[row * dim + 2 * N] = 0.0;
                jac[row * dim + 2 * N + 1] = 0.0;
            }
        }
        if jac.iter().chain(dfdt.iter()).any(|v| !v.is_finite()) {
            let (q, qd) = split::<N>(y);
            return Err(locate(SaddleFailure::NonFinite, t, &q, &qd));
        }
        Ok(())
    }
}
