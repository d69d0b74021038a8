//! Every derivative of `L` and `f` the Chetaev equations need, by forward-mode automatic
//! differentiation. This is the one place where num-dual's types appear.
//!
//! Each model flavour takes its derivatives in its own way and writes them into the same blocks,
//! which are all the engine sees:
//!
//! - [`fixed`]: static sizes, vector dual numbers on the stack (three passes over `L`, two over `f`);
//! - [`scalar`]: run-time sizes, scalar dual numbers (one direction, or pair of directions, per pass).
//!
//! All functions are generic over the outer scalar `T`: `f64` for values, and a dual number when
//! the caller differentiates the reduced equations once more (the Jacobian of the implicit methods).

pub mod fixed;
pub mod scalar;

pub use fixed::{
    constraint_derivatives, lagrangian_derivatives, velocity_hessian, ConstraintDerivatives,
    LagrangianDerivatives, DENSE_HESSIAN_MAX_N,
};

use num_dual::{Dual, Dual2};

use crate::model::{Point, Real};

/// The Lagrangian and its derivatives at one point `(t, q, q̇)`, for `n` coordinates.
#[derive(Clone, Debug)]
pub struct LagrangianBlocks<T> {
    /// `L`.
    pub l: T,
    /// `p = ∂L/∂q̇`, length `n`.
    pub p: Vec<T>,
    /// `W = ∂²L/∂q̇²`, row-major `n × n`.
    pub w: Vec<T>,
    /// `∂L/∂q`, length `n`.
    pub dl_dq: Vec<T>,
    /// `g = (∂²L/∂q̇∂q) q̇ + ∂²L/∂q̇∂t`, length `n`: the part of `d/dt ∂L/∂q̇` without `q̈`.
    pub g: Vec<T>,
    /// `∂L/∂t`.
    pub dl_dt: T,
}

impl<T: Real> LagrangianBlocks<T> {
    /// Zeroed blocks for `n` coordinates.
    pub fn new(n: usize) -> Self {
        Self {
            l: T::zero(),
            p: vec![T::zero(); n],
            w: vec![T::zero(); n * n],
            dl_dq: vec![T::zero(); n],
            g: vec![T::zero(); n],
            dl_dt: T::zero(),
        }
    }
}

/// The constraints and their derivatives at one point `(t, q, q̇)`, for `k` constraints on `n`
/// coordinates.
#[derive(Clone, Debug)]
pub struct ConstraintBlocks<T> {
    /// `f`, length `k`.
    pub f: Vec<T>,
    /// `J = ∂f/∂q̇`, row-major `k × n`.
    pub j: Vec<T>,
    /// `c = (∂f/∂q) q̇ + ∂f/∂t`, length `k`: the part of `df/dt` without `q̈`.
    pub c: Vec<T>,
}

impl<T: Real> ConstraintBlocks<T> {
    /// Zeroed blocks for `k` constraints on `n` coordinates.
    pub fn new(n: usize, k: usize) -> Self {
        Self {
            f: vec![T::zero(); k],
            j: vec![T::zero(); k * n],
            c: vec![T::zero(); k],
        }
    }
}

/// A model's holonomic constraints `h(t, q)` on slices, over any scalar: what their rows in the
/// constraint blocks are derived from. A trait, not a closure, because it is evaluated over two
/// kinds of dual number (see [`holonomic_rows`]).
pub(crate) trait Holonomic {
    /// Writes `h(t, q)` to `h` (length: the number of holonomic constraints).
    fn h<R: Real>(&self, t: R, q: &[R], h: &mut [R]);
}

/// The rows of holonomic constraints `h(t, q) = 0` in the constraint blocks, after the `kv`
/// velocity constraints: each enters as its time derivative `ḣ = H q̇ + ∂h/∂t = 0`, so its row of
/// `J` is `H = ∂h/∂q` and its `c` is the second derivative of `h` along `(δq, δt) = (q̇, 1)`,
/// `d²/ds² h(t + s, q + s q̇)` at `s = 0`.
///
/// `h` is evaluated over second-order duals once (`ḣ` and `c`), and over first-order duals once per
/// coordinate (the columns of `H`). Nothing is done when there are no holonomic rows.
pub(crate) fn holonomic_rows<T: Real>(
    model: &impl Holonomic,
    kv: usize,
    x: Point<T>,
    with_c: bool,
    out: &mut ConstraintBlocks<T>,
) {
    let (t, q, qd, n) = (x.t, x.q, x.qd, x.q.len());
    let count = out.f.len() - kv;
    if count == 0 {
        return;
    }
    let t2 = Dual2::new(t, T::one(), T::zero());
    let q2: Vec<Dual2<T, f64>> = (0..n).map(|i| Dual2::new(q[i], qd[i], T::zero())).collect();
    let mut h2 = vec![Dual2::from_re(T::zero()); count];
    model.h(t2, &q2, &mut h2);
    for (b, hb) in h2.iter().enumerate() {
        out.f[kv + b] = hb.v1;
        if with_c {
            out.c[kv + b] = hb.v2;
        }
    }
    let t1 = Dual::from_re(t);
    let mut q1: Vec<Dual<T, f64>> = q.iter().map(|&x| Dual::from_re(x)).collect();
    let mut h1 = vec![Dual::from_re(T::zero()); count];
    for i in 0..n {
        q1[i].eps = T::one();
        model.h(t1, &q1, &mut h1);
        q1[i].eps = T::zero();
        for (b, hb) in h1.iter().enumerate() {
            out.j[(kv + b) * n + i] = hb.eps;
        }
    }
}

/// `ḣ = d/ds h(t + s, q + s q̇)` at `s = 0` into `f[kv..]`: the velocity residual of the holonomic
/// constraints (nothing when there are none).
pub(crate) fn holonomic_velocities(
    model: &impl Holonomic,
    kv: usize,
    x: Point<f64>,
    f: &mut [f64],
) {
    if f.len() == kv {
        return;
    }
    let te = Dual::new(x.t, 1.0);
    let qe: Vec<Dual<f64, f64>> = (0..x.q.len()).map(|i| Dual::new(x.q[i], x.qd[i])).collect();
    let mut h = vec![Dual::from_re(0.0); f.len() - kv];
    model.h(te, &qe, &mut h);
    for (dst, hb) in f[kv..].iter_mut().zip(&h) {
        *dst = hb.eps;
    }
}

/// `h(t, q)` into `h`, and `H = ∂h/∂q` (row-major `h.len() × n`) into `hq` when given.
pub(crate) fn holonomic_blocks(
    model: &impl Holonomic,
    t: f64,
    q: &[f64],
    h: &mut [f64],
    hq: Option<&mut [f64]>,
) {
    model.h(t, q, h);
    if let Some(hq) = hq {
        let n = q.len();
        let mut q_dual: Vec<Dual<f64, f64>> = q.iter().map(|&x| Dual::from_re(x)).collect();
        let mut hd = vec![Dual::from_re(0.0); h.len()];
        for i in 0..n {
            q_dual[i].eps = 1.0;
            model.h(Dual::from_re(t), &q_dual, &mut hd);
            q_dual[i].eps = 0.0;
            for (b, hb) in hd.iter().enumerate() {
                hq[b * n + i] = hb.eps;
            }
        }
    }
}
