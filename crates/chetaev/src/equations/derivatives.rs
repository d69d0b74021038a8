//! Every derivative of `L` and `f` the Chetaev equations need, by forward-mode automatic
//! differentiation. This is the one place where num-dual's types appear.
//!
//! All functions are generic over the outer scalar `T`: `f64` for values, and a dual number when
//! the caller differentiates the reduced equations once more (the Jacobian of the implicit methods).
//!
//! The Lagrangian takes three passes, each with the smallest dual type that carries its result:
//!
//! | pass | dual type | seeds | yields |
//! |---|---|---|---|
//! | A | `Dual2Vec<N>` (or `N` × `HyperDualVec<N, 1>` above 8 coordinates) | `q̇` | `L`, `p = ∂L/∂q̇`, `W = ∂²L/∂q̇²` |
//! | B | `HyperDualVec<N, 1>` | `q̇`, and the direction `(δq, δt) = (q̇, 1)` | `g = (∂²L/∂q̇∂q) q̇ + ∂²L/∂q̇∂t`, `∂L/∂q·q̇ + ∂L/∂t` |
//! | C | `DualVec<N>` | `q` | `∂L/∂q` |
//!
//! Pass B never forms the `N × N` matrix `∂²L/∂q̇∂q`: the equations need it only applied to `q̇`,
//! so a directional derivative suffices. The work is `O(N²)` for A and `O(N)` for B and C.
//!
//! The constraints take two passes: `DualVec<N>` over `q̇` (`f` and `J = ∂f/∂q̇`), and a scalar
//! dual along the direction `(q̇, 1)` (`(∂f/∂q) q̇ + ∂f/∂t`). With `K = 0` neither runs.

use nalgebra::{Const, SMatrix, SVector, U1};
use num_dual::{Derivative, Dual, Dual2Vec, DualVec, HyperDualVec};

use crate::model::{Constraints, Lagrangian, Real};

/// The Lagrangian and its derivatives at one point `(t, q, q̇)`.
#[derive(Clone, Copy, Debug)]
pub struct LagrangianDerivatives<T, const N: usize> {
    /// `L`.
    pub l: T,
    /// `p = ∂L/∂q̇`, shape `N`.
    pub p: SVector<T, N>,
    /// `W = ∂²L/∂q̇²`, shape `N × N`.
    pub w: SMatrix<T, N, N>,
    /// `∂L/∂q`, shape `N`.
    pub dl_dq: SVector<T, N>,
    /// `g = (∂²L/∂q̇∂q) q̇ + ∂²L/∂q̇∂t`, shape `N`: the part of `d/dt ∂L/∂q̇` that does not involve `q̈`.
    pub g: SVector<T, N>,
    /// `∂L/∂t`.
    pub dl_dt: T,
}

/// The constraints and their derivatives at one point `(t, q, q̇)`.
#[derive(Clone, Copy, Debug)]
pub struct ConstraintDerivatives<T, const N: usize, const K: usize> {
    /// `f`, shape `K`.
    pub f: SVector<T, K>,
    /// `J = ∂f/∂q̇`, shape `K × N`.
    pub j: SMatrix<T, K, N>,
    /// `c = (∂f/∂q) q̇ + ∂f/∂t`, shape `K`: the part of `df/dt` that does not involve `q̈`.
    pub c: SVector<T, K>,
}

/// Evaluates `L`, `∂L/∂q̇`, `W`, `∂L/∂q`, `(∂²L/∂q̇∂q) q̇ + ∂²L/∂q̇∂t` and `∂L/∂t` at `(t, q, q̇)`.
#[inline(always)]
pub fn lagrangian_derivatives<M, T, const N: usize>(
    model: &M,
    t: T,
    q: &SVector<T, N>,
    qd: &SVector<T, N>,
) -> LagrangianDerivatives<T, N>
where
    M: Lagrangian<N> + ?Sized,
    T: Real,
{
    let n = Const::<N>;

    let (l, p, w) = velocity_hessian(model, t, q, qd);

    // Pass B: ∂/∂q̇ of the derivative along (δq, δt) = (q̇, 1).
    type B<T, const N: usize> = HyperDualVec<T, f64, Const<N>, U1>;
    let tb = B::<T, N>::new(
        t,
        Derivative::none(),
        Derivative::some(SMatrix::<T, 1, 1>::new(T::one())),
        Derivative::none(),
    );
    let qb: SVector<B<T, N>, N> = SVector::from_fn(|i, _| {
        B::new(
            q[i],
            Derivative::none(),
            Derivative::some(SMatrix::<T, 1, 1>::new(qd[i])),
            Derivative::none(),
        )
    });
    let qdb: SVector<B<T, N>, N> = SVector::from_fn(|i, _| {
        B::new(
            qd[i],
            Derivative::derivative_generic(n, U1, i),
            Derivative::none(),
            Derivative::none(),
        )
    });
    let lb = model.lagrangian(tb, &qb, &qdb);
    let dl_dir = lb.eps2.unwrap_generic(U1, U1)[0];
    let g = lb.eps1eps2.unwrap_generic(n, U1);

    // Pass C: gradient over q.
    type C<T, const N: usize> = DualVec<T, f64, Const<N>>;
    let tc = C::<T, N>::from_re(t);
    let mut qc: SVector<C<T, N>, N> = q.map(C::from_re);
    for (i, x) in qc.iter_mut().enumerate() {
        x.eps = Derivative::derivative_generic(n, U1, i);
    }
    let qdc: SVector<C<T, N>, N> = qd.map(C::from_re);
    let lc = model.lagrangian(tc, &qc, &qdc);
    let dl_dq = lc.eps.unwrap_generic(n, U1);

    let dl_dt = dl_dir - dl_dq.dot(qd);
    LagrangianDerivatives {
        l,
        p,
        w,
        dl_dq,
        g,
        dl_dt,
    }
}

/// Above this many coordinates `W` is taken column by column (see [`velocity_hessian`]).
pub const DENSE_HESSIAN_MAX_N: usize = 8;

/// Pass A alone: `L`, `p = ∂L/∂q̇` (shape `N`) and `W = ∂²L/∂q̇²` (shape `N × N`) at `(t, q, q̇)`.
///
/// Up to [`DENSE_HESSIAN_MAX_N`] coordinates in one pass with `Dual2Vec<N>`, whose numbers carry
/// the whole `N × N` Hessian: `O(N³)` bytes for a vector of them, on the stack. Beyond that, `N`
/// passes with `HyperDualVec<N, 1>`, one column of `W` each: the same `O(N²)` work per operation
/// of `L` in all, with `O(N²)` memory, so large models do not overflow the stack.
#[inline]
pub fn velocity_hessian<M, T, const N: usize>(
    model: &M,
    t: T,
    q: &SVector<T, N>,
    qd: &SVector<T, N>,
) -> (T, SVector<T, N>, SMatrix<T, N, N>)
where
    M: Lagrangian<N> + ?Sized,
    T: Real,
{
    if N <= DENSE_HESSIAN_MAX_N {
        hessian_dense(model, t, q, qd)
    } else {
        hessian_by_columns(model, t, q, qd)
    }
}

#[inline]
fn hessian_dense<M, T, const N: usize>(
    model: &M,
    t: T,
    q: &SVector<T, N>,
    qd: &SVector<T, N>,
) -> (T, SVector<T, N>, SMatrix<T, N, N>)
where
    M: Lagrangian<N> + ?Sized,
    T: Real,
{
    let n = Const::<N>;
    type A<T, const N: usize> = Dual2Vec<T, f64, Const<N>>;
    let ta = A::<T, N>::from_re(t);
    let qa: SVector<A<T, N>, N> = q.map(A::from_re);
    let mut qda: SVector<A<T, N>, N> = qd.map(A::from_re);
    for (i, x) in qda.iter_mut().enumerate() {
        x.v1 = Derivative::derivative_generic(U1, n, i);
    }
    let la = model.lagrangian(ta, &qa, &qda);
    (
        la.re,
        la.v1.unwrap_generic(U1, n).transpose(),
        la.v2.unwrap_generic(n, n),
    )
}

#[inline]
fn hessian_by_columns<M, T, const N: usize>(
    model: &M,
    t: T,
    q: &SVector<T, N>,
    qd: &SVector<T, N>,
) -> (T, SVector<T, N>, SMatrix<T, N, N>)
where
    M: Lagrangian<N> + ?Sized,
    T: Real,
{
    let n = Const::<N>;
    type B<T, const N: usize> = HyperDualVec<T, f64, Const<N>, U1>;
    let tb = B::<T, N>::from_re(t);
    let qb: SVector<B<T, N>, N> = q.map(B::from_re);
    let mut qdb: SVector<B<T, N>, N> = SVector::from_fn(|i, _| {
        B::new(
            qd[i],
            Derivative::derivative_generic(n, U1, i),
            Derivative::none(),
            Derivative::none(),
        )
    });
    let mut w = SMatrix::<T, N, N>::zeros();
    let (mut l, mut p) = (T::zero(), SVector::<T, N>::zeros());
    for j in 0..N {
        qdb[j].eps2 = Derivative::some(SMatrix::<T, 1, 1>::new(T::one()));
        let v = model.lagrangian(tb, &qb, &qdb);
        qdb[j].eps2 = Derivative::none();
        w.set_column(j, &v.eps1eps2.unwrap_generic(n, U1));
        if j == 0 {
            l = v.re;
            p = v.eps1.unwrap_generic(n, U1);
        }
    }
    (l, p, w)
}

/// Evaluates `f`, `J = ∂f/∂q̇` and `(∂f/∂q) q̇ + ∂f/∂t` at `(t, q, q̇)`.
#[inline(always)]
pub fn constraint_derivatives<M, T, const N: usize, const K: usize>(
    model: &M,
    t: T,
    q: &SVector<T, N>,
    qd: &SVector<T, N>,
) -> ConstraintDerivatives<T, N, K>
where
    M: Constraints<N, K> + ?Sized,
    T: Real,
{
    let n = Const::<N>;

    // J from a gradient over q̇.
    type D<T, const N: usize> = DualVec<T, f64, Const<N>>;
    let td = D::<T, N>::from_re(t);
    let qdual: SVector<D<T, N>, N> = q.map(D::from_re);
    let mut qdd: SVector<D<T, N>, N> = qd.map(D::from_re);
    for (i, x) in qdd.iter_mut().enumerate() {
        x.eps = Derivative::derivative_generic(n, U1, i);
    }
    let fd = model.constraints(td, &qdual, &qdd);
    let f = fd.map(|fa| fa.re);
    let j = SMatrix::<T, K, N>::from_fn(|a, i| fd[a].eps.unwrap_generic(n, U1)[i]);

    // (∂f/∂q) q̇ + ∂f/∂t from one directional derivative along (δq, δt) = (q̇, 1).
    let te = Dual::<T, f64>::new(t, T::one());
    let qe: SVector<Dual<T, f64>, N> = SVector::from_fn(|i, _| Dual::new(q[i], qd[i]));
    let qde: SVector<Dual<T, f64>, N> = qd.map(Dual::from_re);
    let c = model.constraints(te, &qe, &qde).map(|fa| fa.eps);

    ConstraintDerivatives { f, j, c }
}

/// Evaluates `f` alone (no derivatives), for residuals.
#[inline]
pub fn constraint_values<M, const N: usize, const K: usize>(
    model: &M,
    t: f64,
    q: &SVector<f64, N>,
    qd: &SVector<f64, N>,
) -> SVector<f64, K>
where
    M: Constraints<N, K> + ?Sized,
{
    model.constraints(t, q, qd)
}
