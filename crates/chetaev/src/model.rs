//! The traits a user implements: a Lagrangian and, optionally, velocity constraints.
//!
//! Both are written once, generically over the scalar type `R: Real`, so that the same code is
//! evaluated with `f64` for values and with num-dual's dual numbers for every derivative the
//! Chetaev equations need. Nothing else is asked of the user: no mass matrix, no Jacobian, no
//! multiplier algebra.

use nalgebra::SVector;
use num_dual::DualNum;

/// A scalar the library can differentiate: `f64`, or any (nested) num-dual number over `f64`.
///
/// It offers the arithmetic operators (also with `f64` on the right: `x * 2.0`), comparisons with
/// `f64`, and the elementary functions of [`num_dual::DualNum`] (`sqrt`, `sin`, `cosh`, `ln`,
/// `powi`, `atan2`, ...), called as methods: `x.sqrt()`.
pub trait Real: DualNum<f64> + Copy {}
impl<T: DualNum<f64> + Copy> Real for T {}

/// A Lagrangian `L(t, q, q̇)` on `N` generalised coordinates.
///
/// `L` may depend on time and position in any smooth way and may contain terms linear in `q̇`
/// (gyroscopic or magnetic ones). The Hessian `W = ∂²L/∂q̇²` must be regular on the tangent space
/// of the constraints; for an unconstrained system it must be regular.
///
/// ```
/// use chetaev::prelude::*;
///
/// /// A particle of mass `m` in homogeneous gravity `g`, coordinates `(x, y)`.
/// struct Particle { m: f64, g: f64 }
///
/// impl Lagrangian<2> for Particle {
///     fn lagrangian<R: Real>(&self, _t: R, q: &SVector<R, 2>, qd: &SVector<R, 2>) -> R {
///         qd.dot(qd) * (0.5 * self.m) - q[1] * (self.m * self.g)
///     }
/// }
/// ```
pub trait Lagrangian<const N: usize> {
    /// `L(t, q, q̇)`.
    fn lagrangian<R: Real>(&self, t: R, q: &SVector<R, N>, qd: &SVector<R, N>) -> R;
}

/// `K` velocity constraints `f_a(t, q, q̇) = 0`, `a = 1..K`, possibly nonlinear in `q̇` and
/// dependent on `q` and `t`.
///
/// The constraint force is Chetaev's, `Φ = Σ_a μ_a ∂f_a/∂q̇` (see `docs/conventions.md`). The
/// Jacobian `J = ∂f/∂q̇` (shape `K × N`) must have full row rank along the motion.
///
/// The unconstrained motion of any Lagrangian needs no extra code: wrap it in [`Unconstrained`]
/// (`K = 0`), which pays for no multiplier work.
///
/// ```
/// use chetaev::prelude::*;
///
/// /// A particle held at constant speed `v0` (isotachytonic constraint).
/// struct ConstantSpeed { v0: f64 }
///
/// impl Constraints<2, 1> for ConstantSpeed {
///     fn constraints<R: Real>(&self, _t: R, _q: &SVector<R, 2>, qd: &SVector<R, 2>) -> SVector<R, 1> {
///         SVector::from([qd.dot(qd) - self.v0 * self.v0])
///     }
/// }
/// ```
pub trait Constraints<const N: usize, const K: usize> {
    /// `f(t, q, q̇)`, shape `K`.
    fn constraints<R: Real>(&self, t: R, q: &SVector<R, N>, qd: &SVector<R, N>) -> SVector<R, K>;
}

/// A Lagrangian system with no constraints (`K = 0`): plain Euler–Lagrange equations, with no
/// multiplier work. [`Problem::unconstrained`](crate::Problem::unconstrained) wraps a model in it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Unconstrained<M>(pub M);

impl<M: Lagrangian<N>, const N: usize> Lagrangian<N> for Unconstrained<M> {
    #[inline(always)]
    fn lagrangian<R: Real>(&self, t: R, q: &SVector<R, N>, qd: &SVector<R, N>) -> R {
        self.0.lagrangian(t, q, qd)
    }
}

impl<M, const N: usize> Constraints<N, 0> for Unconstrained<M> {
    #[inline(always)]
    fn constraints<R: Real>(
        &self,
        _t: R,
        _q: &SVector<R, N>,
        _qd: &SVector<R, N>,
    ) -> SVector<R, 0> {
        SVector::zeros()
    }
}

/// A model: a Lagrangian on `N` coordinates with `K` constraints (`K = 0` for none).
///
/// Implemented automatically for every type that implements [`Lagrangian`] and [`Constraints`].
pub trait Model<const N: usize, const K: usize>: Lagrangian<N> + Constraints<N, K> {}
impl<T: Lagrangian<N> + Constraints<N, K>, const N: usize, const K: usize> Model<N, K> for T {}
