//! Derivatives of a static model (`Lagrangian<N> + Constraints<N, K>`) by vector dual numbers,
//! which carry every direction at once and live on the stack.
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
//! dual along the direction `(q̇, 1)` (`(∂f/∂q) q̇ + ∂f/∂t`).

use nalgebra::{Const, SMatrix, SVector, U1};
use num_dual::{Derivative, Dual, Dual2Vec, DualVec, HyperDualVec};

use crate::model::{Constraints, Lagrangian, Real};

use super::{ConstraintBlocks, LagrangianBlocks};

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
    let (l, p, w) = velocity_hessian(model, t, q, qd);
    let dl_dq = position_gradient(model, t, q, qd);
    let (g, dl_dir) = along_motion(model, t, q, qd);
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

/// Pass B: `g = (∂²L/∂q̇∂q) q̇ + ∂²L/∂q̇∂t` (shape `N`) and the derivative of `L` along
/// `(δq, δt) = (q̇, 1)`, `∂L/∂q·q̇ + ∂L/∂t`.
#[inline(always)]
pub(crate) fn along_motion<M, T, const N: usize>(
    model: &M,
    t: T,
    q: &SVector<T, N>,
    qd: &SVector<T, N>,
) -> (SVector<T, N>, T)
where
    M: Lagrangian<N> + ?Sized,
    T: Real,
{
    let along = |x: T, dx: T| {
        Hyper::<T, N>::new(
            x,
            Derivative::none(),
            Derivative::some(SMatrix::<T, 1, 1>::new(dx)),
            Derivative::none(),
        )
    };
    let qb: SVector<Hyper<T, N>, N> = SVector::from_fn(|i, _| along(q[i], qd[i]));
    let lb = model.lagrangian(along(t, T::one()), &qb, &seeded_hyper(qd));
    (
        lb.eps1eps2.unwrap_generic(Const::<N>, U1),
        lb.eps2.unwrap_generic(U1, U1)[0],
    )
}

/// Pass C: `∂L/∂q` (shape `N`).
#[inline(always)]
pub(crate) fn position_gradient<M, T, const N: usize>(
    model: &M,
    t: T,
    q: &SVector<T, N>,
    qd: &SVector<T, N>,
) -> SVector<T, N>
where
    M: Lagrangian<N> + ?Sized,
    T: Real,
{
    let l = model.lagrangian(Grad::<T, N>::from_re(t), &seeded(q), &qd.map(Grad::from_re));
    l.eps.unwrap_generic(Const::<N>, U1)
}

/// A first-order dual number over `N` directions (one gradient pass).
type Grad<T, const N: usize> = DualVec<T, f64, Const<N>>;

/// A hyper-dual number over `N` directions and one more: second derivatives across the two.
type Hyper<T, const N: usize> = HyperDualVec<T, f64, Const<N>, U1>;

/// `x` as [`Hyper`] numbers seeded with the unit directions in their first part.
#[inline(always)]
fn seeded_hyper<T: Real, const N: usize>(x: &SVector<T, N>) -> SVector<Hyper<T, N>, N> {
    SVector::from_fn(|i, _| {
        Hyper::new(
            x[i],
            Derivative::derivative_generic(Const::<N>, U1, i),
            Derivative::none(),
            Derivative::none(),
        )
    })
}

/// `x` as [`Grad`] numbers seeded with the unit directions: the variables of a gradient pass.
#[inline(always)]
fn seeded<T: Real, const N: usize>(x: &SVector<T, N>) -> SVector<Grad<T, N>, N> {
    let mut v: SVector<Grad<T, N>, N> = x.map(Grad::from_re);
    for (i, e) in v.iter_mut().enumerate() {
        e.eps = Derivative::derivative_generic(Const::<N>, U1, i);
    }
    v
}

/// `L` and `p = ∂L/∂q̇` (shape `N`) from one gradient pass over `q̇`.
#[inline(always)]
pub(crate) fn momentum<M, T, const N: usize>(
    model: &M,
    t: T,
    q: &SVector<T, N>,
    qd: &SVector<T, N>,
) -> (T, SVector<T, N>)
where
    M: Lagrangian<N> + ?Sized,
    T: Real,
{
    let l = model.lagrangian(Grad::<T, N>::from_re(t), &q.map(Grad::from_re), &seeded(qd));
    (l.re, l.eps.unwrap_generic(Const::<N>, U1))
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
    let tb = Hyper::<T, N>::from_re(t);
    let qb: SVector<Hyper<T, N>, N> = q.map(Hyper::from_re);
    let mut qdb = seeded_hyper(qd);
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
    let (f, j) = constraint_jacobian::<M, T, N, K>(model, t, q, qd);
    let c = constraint_direction::<M, T, N, K>(model, t, q, qd);
    ConstraintDerivatives { f, j, c }
}

/// `f` and `J = ∂f/∂q̇` (shape `K × N`) from one gradient pass over `q̇`.
#[inline(always)]
pub(crate) fn constraint_jacobian<M, T, const N: usize, const K: usize>(
    model: &M,
    t: T,
    q: &SVector<T, N>,
    qd: &SVector<T, N>,
) -> (SVector<T, K>, SMatrix<T, K, N>)
where
    M: Constraints<N, K> + ?Sized,
    T: Real,
{
    let n = Const::<N>;
    let fd = model.constraints(Grad::<T, N>::from_re(t), &q.map(Grad::from_re), &seeded(qd));
    let f = fd.map(|fa| fa.re);
    let j = SMatrix::<T, K, N>::from_fn(|a, i| fd[a].eps.unwrap_generic(n, U1)[i]);
    (f, j)
}

/// `c = (∂f/∂q) q̇ + ∂f/∂t` from one directional derivative along `(δq, δt) = (q̇, 1)`.
#[inline(always)]
pub(crate) fn constraint_direction<M, T, const N: usize, const K: usize>(
    model: &M,
    t: T,
    q: &SVector<T, N>,
    qd: &SVector<T, N>,
) -> SVector<T, K>
where
    M: Constraints<N, K> + ?Sized,
    T: Real,
{
    let te = Dual::<T, f64>::new(t, T::one());
    let qe: SVector<Dual<T, f64>, N> = SVector::from_fn(|i, _| Dual::new(q[i], qd[i]));
    let qde: SVector<Dual<T, f64>, N> = qd.map(Dual::from_re);
    model.constraints(te, &qe, &qde).map(|fa| fa.eps)
}

/// [`lagrangian_derivatives`] on slices of length `N`, into `out`.
#[inline(always)]
pub(crate) fn lagrangian_blocks<M, T, const N: usize>(
    model: &M,
    t: T,
    q: &[T],
    qd: &[T],
    out: &mut LagrangianBlocks<T>,
) where
    M: Lagrangian<N> + ?Sized,
    T: Real,
{
    let q = SVector::<T, N>::from_column_slice(q);
    let qd = SVector::<T, N>::from_column_slice(qd);
    let d = lagrangian_derivatives(model, t, &q, &qd);
    out.l = d.l;
    out.p.copy_from_slice(d.p.as_slice());
    // W is symmetric: its column-major storage is its row-major layout.
    out.w.copy_from_slice(d.w.as_slice());
    out.dl_dq.copy_from_slice(d.dl_dq.as_slice());
    out.g.copy_from_slice(d.g.as_slice());
    out.dl_dt = d.dl_dt;
}

/// `W = ∂²L/∂q̇²` on slices, into `w` (row-major `N × N`).
pub(crate) fn velocity_hessian_into<M, T, const N: usize>(
    model: &M,
    t: T,
    q: &[T],
    qd: &[T],
    w: &mut [T],
) where
    M: Lagrangian<N> + ?Sized,
    T: Real,
{
    let q = SVector::<T, N>::from_column_slice(q);
    let qd = SVector::<T, N>::from_column_slice(qd);
    let (_, _, wm) = velocity_hessian(model, t, &q, &qd);
    w.copy_from_slice(wm.as_slice());
}

/// [`constraint_derivatives`] on slices, into `out` (`J` row-major `K × N`).
#[inline(always)]
pub(crate) fn constraint_blocks<M, T, const N: usize, const K: usize>(
    model: &M,
    t: T,
    q: &[T],
    qd: &[T],
    with_c: bool,
    out: &mut ConstraintBlocks<T>,
) where
    M: Constraints<N, K> + ?Sized,
    T: Real,
{
    let q = SVector::<T, N>::from_column_slice(q);
    let qd = SVector::<T, N>::from_column_slice(qd);
    // The first K rows: the velocity constraints (holonomic rows, if any, follow).
    let (f, j) = constraint_jacobian::<M, T, N, K>(model, t, &q, &qd);
    out.f[..K].copy_from_slice(f.as_slice());
    for a in 0..K {
        for i in 0..N {
            out.j[a * N + i] = j[(a, i)];
        }
    }
    if with_c {
        let c = constraint_direction::<M, T, N, K>(model, t, &q, &qd);
        out.c[..K].copy_from_slice(c.as_slice());
    }
}

/// The forces not derivable from `L`: `Q(t, q, q̇) − ∂D/∂q̇` (shape `N`), `−∂D/∂q̇` by one gradient
/// pass of `DualVec<N>` over `q̇`; `None` when the model has neither.
#[inline(always)]
pub fn forces<M, T, const N: usize>(
    model: &M,
    t: T,
    q: &SVector<T, N>,
    qd: &SVector<T, N>,
) -> Option<SVector<T, N>>
where
    M: Lagrangian<N> + ?Sized,
    T: Real,
{
    let q_direct = model.forces(t, q, qd);
    // Whether there is a dissipation function at all, asked on values: for the default `None`
    // this folds away, and no dual pass is made.
    let no_dissipation = model
        .dissipation(t.re(), &q.map(|x| x.re()), &qd.map(|x| x.re()))
        .is_none();
    if no_dissipation {
        return q_direct;
    }
    let q_dissipative = model
        .dissipation(Grad::<T, N>::from_re(t), &q.map(Grad::from_re), &seeded(qd))
        .map(|d| -d.eps.unwrap_generic(Const::<N>, U1));
    match (q_direct, q_dissipative) {
        (None, None) => None,
        (Some(a), None) => Some(a),
        (None, Some(b)) => Some(b),
        (Some(a), Some(b)) => Some(a + b),
    }
}
