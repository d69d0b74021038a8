//! The Chetaev equations, reduced to an explicit ODE for `(q, q̇)`.
//!
//! In Newton form (the convention of the whole crate, `docs/conventions.md`):
//!
//! ```text
//! d/dt (∂L/∂q̇) − ∂L/∂q = Jᵀ μ = Φ,      f(t, q, q̇) = 0,      J = ∂f/∂q̇
//! ```
//!
//! The multipliers are eliminated at every evaluation by the block solve of [`saddle`], with
//! every derivative of `L` and `f` from [`derivatives`]. The reduced equations keep only
//! `df/dt = 0`, so `f` itself may drift; see the projection option of the driver.

pub mod derivatives;
pub mod saddle;

use nalgebra::SVector;

use crate::model::{Model, Real};
use derivatives::{constraint_derivatives, lagrangian_derivatives};
use saddle::{SaddleFailure, SaddleWorkspace};

/// Everything known at one point `(t, q, q̇)` after the multipliers are eliminated.
#[derive(Clone, Copy, Debug)]
pub struct Dynamics<T, const N: usize, const K: usize> {
    /// `q̈`, shape `N`.
    pub qdd: SVector<T, N>,
    /// `μ`, shape `K` (Newton form, see the module docs).
    pub mu: SVector<T, K>,
    /// The Chetaev force `Φ = Jᵀμ = Σ_a μ_a ∂f_a/∂q̇`, shape `N`.
    pub phi: SVector<T, N>,
    /// The constraint residual `f`, shape `K`.
    pub f: SVector<T, K>,
    /// `L`.
    pub l: T,
    /// The energy `E = q̇·∂L/∂q̇ − L`.
    pub energy: T,
    /// `∂L/∂t`.
    pub dl_dt: T,
    /// Smallest over largest pivot of the block solve.
    pub pivot_ratio: f64,
}

impl<T: Real, const N: usize, const K: usize> Dynamics<T, N, K> {
    /// The power of the Chetaev force, `q̇·Φ`. With `E` as above, `dE/dt = q̇·Φ − ∂L/∂t`.
    pub fn power(&self, qd: &SVector<T, N>) -> T {
        qd.dot(&self.phi)
    }
}

/// Evaluates the reduced Chetaev equations at `(t, q, q̇)`: builds the block system from the
/// derivatives of `L` and `f` and solves it for `q̈` and `μ`.
///
/// With `K = 0` no constraint derivative is taken and the system is `W q̈ = ∂L/∂q − g`.
#[inline]
pub fn dynamics<M, T, const N: usize, const K: usize>(
    model: &M,
    ws: &mut SaddleWorkspace<T>,
    t: T,
    q: &SVector<T, N>,
    qd: &SVector<T, N>,
) -> Result<Dynamics<T, N, K>, SaddleFailure>
where
    M: Model<N, K> + ?Sized,
    T: Real,
{
    let ld = lagrangian_derivatives(model, t, q, qd);
    let r = ld.dl_dq - ld.g;
    let energy = qd.dot(&ld.p) - ld.l;
    if K == 0 {
        let j = nalgebra::SMatrix::<T, K, N>::zeros();
        let s = SVector::<T, K>::zeros();
        let sol = saddle::solve(ws, &ld.w, &j, &r, &s)?;
        return Ok(Dynamics {
            qdd: sol.qdd,
            mu: sol.mu,
            phi: SVector::zeros(),
            f: s,
            l: ld.l,
            energy,
            dl_dt: ld.dl_dt,
            pivot_ratio: sol.pivot_ratio,
        });
    }
    let cd = constraint_derivatives::<M, T, N, K>(model, t, q, qd);
    let s = -cd.c;
    let sol = saddle::solve(ws, &ld.w, &cd.j, &r, &s)?;
    let phi = cd.j.tr_mul(&sol.mu);
    Ok(Dynamics {
        qdd: sol.qdd,
        mu: sol.mu,
        phi,
        f: cd.f,
        l: ld.l,
        energy,
        dl_dt: ld.dl_dt,
        pivot_ratio: sol.pivot_ratio,
    })
}
