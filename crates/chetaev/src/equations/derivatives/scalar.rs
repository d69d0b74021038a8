//! Derivatives of a run-time-sized model ([`DynModel`]) by scalar dual numbers, one direction (or
//! pair of directions) per pass:
//!
//! | pass | dual type | passes | gives |
//! |---|---|---|---|
//! | A | `HyperDual` on `(q̇_i, q̇_j)`, `i ≤ j` | `n(n+1)/2` | `W_ij`, `p_i`, `L` |
//! | B | `HyperDual` on `q̇_i` and the direction `(q̇, 1)` | `n` | `g_i`, `∂L/∂q·q̇ + ∂L/∂t` |
//! | C | `Dual` on `q_i` | `n` | `∂L/∂q_i` |
//! | D | `Dual` on `q̇_i` | `n` (`k > 0` only) | column `i` of `J`, `f` |
//! | E | `Dual` along `(q̇, 1)` | 1 (`k > 0` only) | `c` |
//!
//! so one evaluation calls the Lagrangian `n(n+1)/2 + 2n` times, against 3 times for a static
//! model, whose vector dual numbers carry all directions at once.

use num_dual::{Dual, HyperDual};

use super::{ConstraintBlocks, LagrangianBlocks};
use crate::model::{DynModel, Point, Real};

/// Pass A: `W` (row-major `n × n`) into `w`, `p = ∂L/∂q̇` into `p` (when given); returns `L`.
pub(crate) fn hessian_pass<M, T>(model: &M, x: Point<T>, w: &mut [T], mut p: Option<&mut [T]>) -> T
where
    M: DynModel + ?Sized,
    T: Real,
{
    let (t, q, qd) = (x.t, x.q, x.qd);
    type H<T> = HyperDual<T, f64>;
    let n = q.len();
    let th = H::from_re(t);
    let q_hyper: Vec<H<T>> = q.iter().map(|&x| H::from_re(x)).collect();
    let mut qd_hyper: Vec<H<T>> = qd.iter().map(|&x| H::from_re(x)).collect();
    let mut l = T::zero();
    for i in 0..n {
        for j in i..n {
            qd_hyper[i].eps1 = T::one();
            qd_hyper[j].eps2 += T::one();
            let v = model.lagrangian(th, &q_hyper, &qd_hyper);
            qd_hyper[i].eps1 = T::zero();
            qd_hyper[j].eps2 = T::zero();
            w[i * n + j] = v.eps1eps2;
            w[j * n + i] = v.eps1eps2;
            if i == j {
                if let Some(p) = p.as_deref_mut() {
                    p[i] = v.eps1;
                }
                l = v.re;
            }
        }
    }
    l
}

/// Every block of `L` at `(t, q, q̇)` into `out`: passes A, B and C.
pub(crate) fn lagrangian_blocks<M, T>(model: &M, x: Point<T>, out: &mut LagrangianBlocks<T>)
where
    M: DynModel + ?Sized,
    T: Real,
{
    let (t, q, qd, n) = (x.t, x.q, x.qd, x.q.len());
    out.l = hessian_pass(model, x, &mut out.w, Some(&mut out.p));

    // Pass B: g_i, and the directional derivative ∂L/∂q·q̇ + ∂L/∂t.
    type H<T> = HyperDual<T, f64>;
    let th = H::new(t, T::zero(), T::one(), T::zero());
    let q_hyper: Vec<H<T>> = (0..n)
        .map(|i| H::new(q[i], T::zero(), qd[i], T::zero()))
        .collect();
    let mut qd_hyper: Vec<H<T>> = qd.iter().map(|&x| H::from_re(x)).collect();
    let mut dl_dir = T::zero();
    for i in 0..n {
        qd_hyper[i].eps1 = T::one();
        let v = model.lagrangian(th, &q_hyper, &qd_hyper);
        qd_hyper[i].eps1 = T::zero();
        out.g[i] = v.eps1eps2;
        dl_dir = v.eps2;
    }

    // Pass C: ∂L/∂q.
    type D<T> = Dual<T, f64>;
    let td = D::from_re(t);
    let mut q_dual: Vec<D<T>> = q.iter().map(|&x| D::from_re(x)).collect();
    let qd_dual: Vec<D<T>> = qd.iter().map(|&x| D::from_re(x)).collect();
    for i in 0..n {
        q_dual[i].eps = T::one();
        out.dl_dq[i] = model.lagrangian(td, &q_dual, &qd_dual).eps;
        q_dual[i].eps = T::zero();
    }
    let dl_dq_qd = out
        .dl_dq
        .iter()
        .zip(qd)
        .fold(T::zero(), |acc, (a, b)| acc + *a * *b);
    out.dl_dt = dl_dir - dl_dq_qd;
}

/// `f`, `J` (row-major `k × n`) and, with `with_c`, `c` into `out`: passes D and E.
pub(crate) fn constraint_blocks<M, T>(
    model: &M,
    x: Point<T>,
    with_c: bool,
    out: &mut ConstraintBlocks<T>,
) where
    M: DynModel + ?Sized,
    T: Real,
{
    type D<T> = Dual<T, f64>;
    // The velocity constraints' rows (holonomic rows, if any, follow).
    let (t, q, qd) = (x.t, x.q, x.qd);
    let (n, k) = (q.len(), model.sizes().1);
    let td = D::from_re(t);
    let q_dual: Vec<D<T>> = q.iter().map(|&x| D::from_re(x)).collect();
    let mut qd_dual: Vec<D<T>> = qd.iter().map(|&x| D::from_re(x)).collect();
    let mut f = vec![D::from_re(T::zero()); k];
    for i in 0..n {
        qd_dual[i].eps = T::one();
        model.constraints(td, &q_dual, &qd_dual, &mut f);
        qd_dual[i].eps = T::zero();
        for (a, fa) in f.iter().enumerate() {
            out.j[a * n + i] = fa.eps;
            out.f[a] = fa.re;
        }
    }
    if with_c {
        let te = D::new(t, T::one());
        let qe: Vec<D<T>> = (0..n).map(|i| D::new(q[i], qd[i])).collect();
        model.constraints(te, &qe, &qd_dual, &mut f);
        for (c, fa) in out.c.iter_mut().zip(&f) {
            *c = fa.eps;
        }
    }
}

/// The forces not derivable from `L`, `Q − ∂D/∂q̇` (length `n`), into `out`, `−∂D/∂q̇` by one scalar
/// dual pass per velocity; returns whether the model has any.
pub(crate) fn forces<M: DynModel + ?Sized, T: Real>(model: &M, x: Point<T>, out: &mut [T]) -> bool {
    let (t, q, qd) = (x.t, x.q, x.qd);
    let direct = model.forces(t, q, qd, out);
    type D<T> = Dual<T, f64>;
    let td = D::from_re(t);
    let q_dual: Vec<D<T>> = q.iter().map(|&x| D::from_re(x)).collect();
    let mut qd_dual: Vec<D<T>> = qd.iter().map(|&x| D::from_re(x)).collect();
    if model.dissipation(td, &q_dual, &qd_dual).is_none() {
        return direct;
    }
    if !direct {
        out.iter_mut().for_each(|v| *v = T::zero());
    }
    for i in 0..q.len() {
        qd_dual[i].eps = T::one();
        if let Some(d) = model.dissipation(td, &q_dual, &qd_dual) {
            out[i] -= d.eps;
        }
        qd_dual[i].eps = T::zero();
    }
    true
}
