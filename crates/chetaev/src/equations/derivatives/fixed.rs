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

use crate::model::{Constraints, Lagrangian, Point, Real};

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
pub fn lagrangian_derivatives<M: Lagrangian<N> + ?Sized, T: Real, const N: usize>(
    model: &M,
    t: T,
    q: &SVector<T, N>,
    qd: &SVector<T, N>,
) -> LagrangianDerivatives<T, N> {
    At::new(model, t, *q, *qd).lagrangian()
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
pub fn velocity_hessian<M: Lagrangian<N> + ?Sized, T: Real, const N: usize>(
    model: &M,
    t: T,
    q: &SVector<T, N>,
    qd: &SVector<T, N>,
) -> (T, SVector<T, N>, SMatrix<T, N, N>) {
    At::new(model, t, *q, *qd).velocity_hessian()
}

/// Evaluates `f`, `J = ∂f/∂q̇` and `(∂f/∂q) q̇ + ∂f/∂t` at `(t, q, q̇)`.
#[inline(always)]
pub fn constraint_derivatives<
    M: Constraints<N, K> + ?Sized,
    T: Real,
    const N: usize,
    const K: usize,
>(
    model: &M,
    t: T,
    q: &SVector<T, N>,
    qd: &SVector<T, N>,
) -> ConstraintDerivatives<T, N, K> {
    At::new(model, t, *q, *qd).constraints()
}

/// The forces not derivable from `L`, `Q(t, q, q̇) − ∂D/∂q̇` (shape `N`), `−∂D/∂q̇` by one gradient
/// pass over `q̇`; `None` when the model has neither.
#[inline(always)]
pub fn forces<M: Lagrangian<N> + ?Sized, T: Real, const N: usize>(
    model: &M,
    t: T,
    q: &SVector<T, N>,
    qd: &SVector<T, N>,
) -> Option<SVector<T, N>> {
    At::new(model, t, *q, *qd).forces()
}

/// A static model at one point `(t, q, q̇)`: the dual-number passes over its `L` and `f` are its
/// methods, each with the smallest dual type that carries its result (see the module docs).
pub(crate) struct At<'a, M: ?Sized, T, const N: usize> {
    model: &'a M,
    /// `t`.
    pub t: T,
    /// `q`.
    pub q: SVector<T, N>,
    /// `q̇`.
    pub qd: SVector<T, N>,
}

impl<'a, M: ?Sized, T: Real, const N: usize> At<'a, M, T, N> {
    /// `model` at `(t, q, q̇)`.
    #[inline(always)]
    pub fn new(model: &'a M, t: T, q: SVector<T, N>, qd: SVector<T, N>) -> Self {
        Self { model, t, q, qd }
    }

    /// `model` at a point given on slices of length `N`.
    #[inline(always)]
    pub fn from_point(model: &'a M, x: Point<'_, T>) -> Self {
        // Element by element rather than `from_column_slice`, which calls `memcpy` for a few words.
        let (q, qd) = (x.q, x.qd);
        let q = SVector::<T, N>::from_fn(|i, _| q[i]);
        let qd = SVector::<T, N>::from_fn(|i, _| qd[i]);
        Self::new(model, x.t, q, qd)
    }
}

impl<M: Lagrangian<N> + ?Sized, T: Real, const N: usize> At<'_, M, T, N> {
    /// Every derivative of `L` the equations need: passes A, B and C.
    #[inline(always)]
    pub fn lagrangian(&self) -> LagrangianDerivatives<T, N> {
        let (l, p, w) = self.velocity_hessian();
        let dl_dq = self.position_gradient();
        let (g, dl_dir) = self.along_motion();
        let dl_dt = dl_dir - dl_dq.dot(&self.qd);
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
    pub fn along_motion(&self) -> (SVector<T, N>, T) {
        let along = |x: T, dx: T| {
            Hyper::<T, N>::new(
                x,
                Derivative::none(),
                Derivative::some(SMatrix::<T, 1, 1>::new(dx)),
                Derivative::none(),
            )
        };
        let (q, qd) = (&self.q, &self.qd);
        let qb: SVector<Hyper<T, N>, N> = SVector::from_fn(|i, _| along(q[i], qd[i]));
        let lb = self
            .model
            .lagrangian(along(self.t, T::one()), &qb, &seeded_hyper(qd));
        (
            lb.eps1eps2.unwrap_generic(Const::<N>, U1),
            lb.eps2.unwrap_generic(U1, U1)[0],
        )
    }

    /// Pass C: `∂L/∂q` (shape `N`).
    #[inline(always)]
    pub fn position_gradient(&self) -> SVector<T, N> {
        let qd = self.qd.map(Grad::from_re);
        let l = self
            .model
            .lagrangian(Grad::from_re(self.t), &seeded(&self.q), &qd);
        l.eps.unwrap_generic(Const::<N>, U1)
    }

    /// `L` alone.
    #[inline(always)]
    pub fn value(&self) -> T {
        self.model.lagrangian(self.t, &self.q, &self.qd)
    }

    /// `L` and `p = ∂L/∂q̇` (shape `N`) from one gradient pass over `q̇`.
    #[inline(always)]
    pub fn momentum(&self) -> (T, SVector<T, N>) {
        let q = self.q.map(Grad::from_re);
        let l = self
            .model
            .lagrangian(Grad::from_re(self.t), &q, &seeded(&self.qd));
        (l.re, l.eps.unwrap_generic(Const::<N>, U1))
    }

    /// Pass A: `L`, `p` and `W`, in one pass or column by column (see [`velocity_hessian`]).
    #[inline]
    pub fn velocity_hessian(&self) -> (T, SVector<T, N>, SMatrix<T, N, N>) {
        if N <= DENSE_HESSIAN_MAX_N {
            self.hessian_dense()
        } else {
            self.hessian_by_columns()
        }
    }

    #[inline]
    fn hessian_dense(&self) -> (T, SVector<T, N>, SMatrix<T, N, N>) {
        let n = Const::<N>;
        type A<T, const N: usize> = Dual2Vec<T, f64, Const<N>>;
        let qa: SVector<A<T, N>, N> = self.q.map(A::from_re);
        let mut qda: SVector<A<T, N>, N> = self.qd.map(A::from_re);
        for (i, x) in qda.iter_mut().enumerate() {
            x.v1 = Derivative::derivative_generic(U1, n, i);
        }
        let la = self.model.lagrangian(A::<T, N>::from_re(self.t), &qa, &qda);
        (
            la.re,
            la.v1.unwrap_generic(U1, n).transpose(),
            la.v2.unwrap_generic(n, n),
        )
    }

    #[inline]
    fn hessian_by_columns(&self) -> (T, SVector<T, N>, SMatrix<T, N, N>) {
        let n = Const::<N>;
        let tb = Hyper::<T, N>::from_re(self.t);
        let qb: SVector<Hyper<T, N>, N> = self.q.map(Hyper::from_re);
        let mut qdb = seeded_hyper(&self.qd);
        let mut w = SMatrix::<T, N, N>::zeros();
        let (mut l, mut p) = (T::zero(), SVector::<T, N>::zeros());
        for j in 0..N {
            qdb[j].eps2 = Derivative::some(SMatrix::<T, 1, 1>::new(T::one()));
            let v = self.model.lagrangian(tb, &qb, &qdb);
            qdb[j].eps2 = Derivative::none();
            w.set_column(j, &v.eps1eps2.unwrap_generic(n, U1));
            if j == 0 {
                l = v.re;
                p = v.eps1.unwrap_generic(n, U1);
            }
        }
        (l, p, w)
    }

    /// The forces not derivable from `L`: `Q(t, q, q̇) − ∂D/∂q̇` (shape `N`), `−∂D/∂q̇` by one
    /// gradient pass of `DualVec<N>` over `q̇`; `None` when the model has neither.
    #[inline(always)]
    pub fn forces(&self) -> Option<SVector<T, N>> {
        let (m, t, q, qd) = (self.model, self.t, &self.q, &self.qd);
        let q_direct = m.forces(t, q, qd);
        // Whether there is a dissipation function at all, asked on values: for the default `None`
        // this folds away, and no dual pass is made.
        let no_dissipation = m
            .dissipation(t.re(), &q.map(|x| x.re()), &qd.map(|x| x.re()))
            .is_none();
        if no_dissipation {
            return q_direct;
        }
        let q_dissipative = m
            .dissipation(Grad::<T, N>::from_re(t), &q.map(Grad::from_re), &seeded(qd))
            .map(|d| -d.eps.unwrap_generic(Const::<N>, U1));
        match (q_direct, q_dissipative) {
            (None, None) => None,
            (Some(a), None) => Some(a),
            (None, Some(b)) => Some(b),
            (Some(a), Some(b)) => Some(a + b),
        }
    }

    /// [`At::lagrangian`] into `out`, whose vectors have length `N`.
    #[inline(always)]
    pub fn lagrangian_blocks(&self, out: &mut LagrangianBlocks<T>) {
        let d = self.lagrangian();
        out.l = d.l;
        out.p.copy_from_slice(d.p.as_slice());
        // W is symmetric: its column-major storage is its row-major layout.
        out.w.copy_from_slice(d.w.as_slice());
        out.dl_dq.copy_from_slice(d.dl_dq.as_slice());
        out.g.copy_from_slice(d.g.as_slice());
        out.dl_dt = d.dl_dt;
    }

    /// `W = ∂²L/∂q̇²` into `w` (row-major `N × N`).
    pub fn velocity_hessian_into(&self, w: &mut [T]) {
        let (_, _, wm) = self.velocity_hessian();
        w.copy_from_slice(wm.as_slice());
    }
}

impl<M: ?Sized, T: Real, const N: usize> At<'_, M, T, N> {
    /// `f`, `J = ∂f/∂q̇` and `c = (∂f/∂q) q̇ + ∂f/∂t`.
    #[inline(always)]
    pub fn constraints<const K: usize>(&self) -> ConstraintDerivatives<T, N, K>
    where
        M: Constraints<N, K>,
    {
        let (f, j) = self.constraint_jacobian();
        let c = self.constraint_direction();
        ConstraintDerivatives { f, j, c }
    }

    /// `f` and `J = ∂f/∂q̇` (shape `K × N`) from one gradient pass over `q̇`.
    #[inline(always)]
    pub fn constraint_jacobian<const K: usize>(&self) -> (SVector<T, K>, SMatrix<T, K, N>)
    where
        M: Constraints<N, K>,
    {
        let n = Const::<N>;
        let q = self.q.map(Grad::from_re);
        let fd = self
            .model
            .constraints(Grad::from_re(self.t), &q, &seeded(&self.qd));
        let f = fd.map(|fa| fa.re);
        let j = SMatrix::<T, K, N>::from_fn(|a, i| fd[a].eps.unwrap_generic(n, U1)[i]);
        (f, j)
    }

    /// `c = (∂f/∂q) q̇ + ∂f/∂t` from one directional derivative along `(δq, δt) = (q̇, 1)`.
    #[inline(always)]
    pub fn constraint_direction<const K: usize>(&self) -> SVector<T, K>
    where
        M: Constraints<N, K>,
    {
        let (q, qd) = (&self.q, &self.qd);
        let te = Dual::<T, f64>::new(self.t, T::one());
        let qe: SVector<Dual<T, f64>, N> = SVector::from_fn(|i, _| Dual::new(q[i], qd[i]));
        let qde: SVector<Dual<T, f64>, N> = qd.map(Dual::from_re);
        self.model.constraints(te, &qe, &qde).map(|fa| fa.eps)
    }

    /// The first `K` rows of the constraint blocks (`J` row-major `K × N`); `c` only `with_c`.
    /// Holonomic rows, if any, follow them.
    #[inline(always)]
    pub fn constraint_blocks<const K: usize>(&self, with_c: bool, out: &mut ConstraintBlocks<T>)
    where
        M: Constraints<N, K>,
    {
        let (f, j) = self.constraint_jacobian::<K>();
        out.f[..K].copy_from_slice(f.as_slice());
        for a in 0..K {
            for i in 0..N {
                out.j[a * N + i] = j[(a, i)];
            }
        }
        if with_c {
            out.c[..K].copy_from_slice(self.constraint_direction::<K>().as_slice());
        }
    }
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
