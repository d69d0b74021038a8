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
//!
//! This is the one equations engine: it works on slices with the sizes of the [`Model`], whatever
//! the flavour the model was written in.

pub mod compiled;
pub mod derivatives;
pub(crate) mod graph;
pub(crate) mod native;
pub mod saddle;
pub mod structure;
pub(crate) mod tiers;

use crate::model::{Model, Plan, Point, Real};
use compiled::{Compiled, CompiledFailure, CompiledWorkspace};
use derivatives::{ConstraintBlocks, LagrangianBlocks};
use saddle::{SaddleFailure, SaddleWorkspace};

/// Directions of differentiation carried together by one evaluation (the Jacobian's columns, the
/// sensitivities' seeds).
pub(crate) const LANES: usize = 4;

/// A value with its derivatives in [`LANES`] directions.
pub(crate) type Lanes = num_dual::DualVec<f64, f64, nalgebra::Const<LANES>>;

/// `re` with the derivative `rate(l)` in lane `l`.
#[inline]
pub(crate) fn lanes(re: f64, rate: impl Fn(usize) -> f64) -> Lanes {
    Lanes::new(
        re,
        num_dual::Derivative::some(nalgebra::SVector::from_fn(|l, _| rate(l))),
    )
}

/// The derivative of `x` in lane `l`.
#[inline]
pub(crate) fn lane(x: &Lanes, l: usize) -> f64 {
    x.eps.unwrap_generic(nalgebra::Const::<LANES>, nalgebra::U1)[l]
}

/// What an evaluation of the reduced equations must produce, so that a caller pays only for what
/// it reads: the right-hand side of a run without the energy balance needs `q̈` alone.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Need {
    /// `q̈`, `μ`, `J` and the conditioning: the right-hand side of the motion.
    Motion,
    /// And the rates of the energy balance, `q̇·Φ` (with `Φ`), `∂L/∂t` and `q̇·Q`.
    Rates,
    /// Everything in [`Dynamics`], with `L`, `E`, `f` and `Q`: what is recorded at output points.
    All,
}

impl Need {
    /// Whether the rates of the energy balance are needed.
    pub fn rates(self) -> bool {
        self != Need::Motion
    }
}

/// Everything known at one point `(t, q, q̇)` after the multipliers are eliminated.
#[derive(Clone, Debug)]
pub struct Dynamics<T> {
    /// `q̈`, length `n`.
    pub qdd: Vec<T>,
    /// `μ`, length `k` (Newton form, see the module docs).
    pub mu: Vec<T>,
    /// The Chetaev force `Φ = Jᵀμ = Σ_a μ_a ∂f_a/∂q̇`, length `n`.
    pub phi: Vec<T>,
    /// The constraint residual `f`, length `k`.
    pub f: Vec<T>,
    /// `L`.
    pub l: T,
    /// The energy `E = q̇·∂L/∂q̇ − L`.
    pub energy: T,
    /// `∂L/∂t`.
    pub dl_dt: T,
    /// The power of the Chetaev force, `q̇·Φ`; `dE/dt = q̇·Φ + q̇·Q − ∂L/∂t`.
    pub power: T,
    /// The forces not derivable from `L`, `Q − ∂D/∂q̇`, length `n` (zero for a model without them).
    pub forces: Vec<T>,
    /// Their power `q̇·Q` (with `Q` including `−∂D/∂q̇`).
    pub power_forces: T,
    /// Smallest over largest pivot of the block solve.
    pub pivot_ratio: f64,
    /// `J = ∂f/∂q̇` (real parts), row-major `k × n`.
    pub j: Vec<f64>,
    /// The size of the kinetic metric, `max_ij |W_ij|`.
    pub w_scale: f64,
    /// The sign of the determinant of the block matrix `[W −Jᵀ; J 0]`: `+1` where `W` is
    /// positive definite; it changes only where the block system passes through a singular one.
    pub det_sign: f64,
}

/// Scratch space of the equations engine for one model's sizes, reused across evaluations so the
/// hot path never allocates; it also holds the last evaluation's [`Dynamics`].
#[derive(Clone, Debug)]
pub struct Workspace<T> {
    n: usize,
    k: usize,
    lagrangian: LagrangianBlocks<T>,
    constraints: ConstraintBlocks<T>,
    saddle: SaddleWorkspace<T>,
    compiled: Option<CompiledWorkspace<T>>,
    dynamics: Dynamics<T>,
}

impl<T: Real> Workspace<T> {
    /// Scratch space for `n` coordinates and `k` constraints.
    pub fn new(n: usize, k: usize) -> Self {
        Self {
            n,
            k,
            // Made on first use by the route that needs them (a static model never does).
            lagrangian: LagrangianBlocks::new(0),
            constraints: ConstraintBlocks::new(0, 0),
            saddle: SaddleWorkspace::default(),
            compiled: None,
            dynamics: Dynamics {
                qdd: vec![T::zero(); n],
                mu: vec![T::zero(); k],
                phi: vec![T::zero(); n],
                f: vec![T::zero(); k],
                l: T::zero(),
                energy: T::zero(),
                dl_dt: T::zero(),
                power: T::zero(),
                forces: vec![T::zero(); n],
                power_forces: T::zero(),
                pivot_ratio: 1.0,
                j: vec![0.0; k * n],
                w_scale: 0.0,
                det_sign: 1.0,
            },
        }
    }

    /// Scratch space for `model`'s sizes.
    pub fn for_model<M: Model + ?Sized>(model: &M) -> Self {
        let (n, k) = model.sizes();
        Self::new(n, k)
    }

    /// The result of the last successful [`evaluate`].
    pub fn dynamics(&self) -> &Dynamics<T> {
        &self.dynamics
    }

    /// The dynamics, for a route that writes them itself.
    pub(crate) fn dynamics_mut(&mut self) -> &mut Dynamics<T> {
        &mut self.dynamics
    }

    /// Whether this workspace, `q` and `q̇` have `model`'s sizes.
    fn fits<M: Model + ?Sized>(&self, model: &M, q: &[T], qd: &[T]) -> Result<(), SaddleFailure> {
        let (n, k) = model.sizes();
        saddle::check_sizes(
            &[
                "the length of q",
                "the length of q̇",
                "the workspace's coordinates",
                "the workspace's constraints",
            ],
            [(n, q.len()), (n, qd.len()), (n, self.n), (k, self.k)],
        )
    }

    pub(crate) fn saddle(&mut self) -> &mut SaddleWorkspace<T> {
        &mut self.saddle
    }
}

/// Evaluates the reduced Chetaev equations at `(t, q, q̇)` (slices of length `n`): builds the
/// block system from the derivatives of `L` and `f` and solves it for `q̈` and `μ`,
///
/// ```text
/// [ W   −Jᵀ ] [ q̈ ]   [ ∂L/∂q − g + Q ]
/// [ J    0  ] [ μ ] = [      −c       ]
/// ```
///
/// with `Q` the forces not derivable from `L` (and `−∂D/∂q̇` of a Rayleigh function), if any.
///
/// With `k = 0` no constraint derivative is taken and the system is `W q̈ = ∂L/∂q − g`. The result
/// is in [`Workspace::dynamics`] (and returned). `q`, `q̇` of another length than `n`, or a
/// workspace made for other sizes, give [`SaddleFailure::SizeMismatch`].
#[inline]
pub fn evaluate<'w, M, T>(
    model: &M,
    ws: &'w mut Workspace<T>,
    t: T,
    q: &[T],
    qd: &[T],
) -> Result<&'w Dynamics<T>, SaddleFailure>
where
    M: Model + ?Sized,
    T: Real,
{
    ws.fits(model, q, qd)?;
    model.evaluate_into(ws, Point::new(t, q, qd))?;
    Ok(&ws.dynamics)
}

/// [`evaluate`] by the compiled equations of the model when there are some ([`Compiled`]), and by
/// the dual-number blocks otherwise or where a guard of the compiled equations flips (a branch of
/// the model's code taken the other way). Only what `need` asks for is sure to be written (a route
/// may write more); the rest of [`Dynamics`] may hold an earlier evaluation's values. Returns the
/// dynamics and whether the dual-number path was taken in place of compiled equations. Sizes that
/// do not fit the model (and `compiled`, which must be the model's) give
/// [`SaddleFailure::SizeMismatch`].
#[inline]
#[allow(clippy::too_many_arguments)]
pub fn evaluate_with<'w, M, T>(
    model: &M,
    compiled: Option<&Compiled>,
    ws: &'w mut Workspace<T>,
    t: T,
    q: &[T],
    qd: &[T],
    need: Need,
) -> Result<(&'w Dynamics<T>, bool), SaddleFailure>
where
    M: Model + ?Sized,
    T: Real,
{
    ws.fits(model, q, qd)?;
    if let Some(c) = compiled {
        // `ws` has the model's sizes now.
        saddle::check_sizes(
            &[
                "the compiled equations' coordinates",
                "the compiled equations' constraints",
            ],
            [(ws.n, c.sizes().0), (ws.k, c.sizes().1)],
        )?;
    }
    evaluate_with_unchecked(model, compiled, ws, Point::new(t, q, qd), need)
}

/// [`evaluate_with`] without the check of the sizes, for callers that made `ws`, `q`, `q̇` and
/// `compiled` for `model` themselves (the integrator's right-hand side).
#[inline]
pub(crate) fn evaluate_with_unchecked<'w, M: Model + ?Sized, T: Real>(
    model: &M,
    compiled: Option<&Compiled>,
    ws: &'w mut Workspace<T>,
    x: Point<T>,
    need: Need,
) -> Result<(&'w Dynamics<T>, bool), SaddleFailure> {
    let Some(c) = compiled else {
        model.evaluate_into(ws, x)?;
        return Ok((&ws.dynamics, false));
    };
    let plan = Plan { compiled: c, need };
    if let Some(result) = model.evaluate_planned(plan, ws, x) {
        return result.map(|()| (&ws.dynamics, false));
    }
    if c.guards() > 0 {
        if let Some(result) = model.evaluate_bounded(plan, ws, x) {
            return result.map(|()| (&ws.dynamics, false));
        }
    }
    let cws = ws.compiled.get_or_insert_with(|| CompiledWorkspace::new(c));
    match c.evaluate_unchecked(cws, &mut ws.dynamics, x, need) {
        Ok(()) => Ok((&ws.dynamics, false)),
        Err(CompiledFailure::Saddle(e)) => Err(e),
        Err(CompiledFailure::Guard(_)) => {
            model.evaluate_into(ws, x)?;
            Ok((&ws.dynamics, true))
        }
    }
}

/// The reduced equations by `compiled` alone (no fallback), with its parameters set to `params`:
/// what sensitivities differentiate.
pub(crate) fn evaluate_compiled<'w, T: Real>(
    compiled: &Compiled,
    ws: &'w mut Workspace<T>,
    params: &[T],
    x: Point<T>,
    need: Need,
) -> Result<&'w Dynamics<T>, CompiledFailure> {
    let cws = ws
        .compiled
        .get_or_insert_with(|| CompiledWorkspace::new(compiled));
    cws.params.copy_from_slice(params);
    compiled.evaluate_unchecked(cws, &mut ws.dynamics, x, need)?;
    Ok(&ws.dynamics)
}

/// [`evaluate`] at the point `x` from the blocks of [`Model::lagrangian_blocks`] and
/// [`Model::constraint_blocks`] on slices: the route of every model that has no faster one. `q`,
/// `q̇` or a workspace of other sizes than the model's give [`SaddleFailure::SizeMismatch`], and
/// nothing is evaluated.
#[inline]
pub fn evaluate_blocks<M, T>(
    model: &M,
    ws: &mut Workspace<T>,
    x: Point<T>,
) -> Result<(), SaddleFailure>
where
    M: Model + ?Sized,
    T: Real,
{
    // A few comparisons against passes over `L` that cost microseconds on this route.
    ws.fits(model, x.q, x.qd)?;
    let Workspace {
        n,
        k,
        lagrangian: lb,
        constraints: cb,
        saddle: sw,
        dynamics: d,
        ..
    } = ws;
    let (n, k) = (*n, *k);
    if lb.p.len() != n {
        *lb = LagrangianBlocks::new(n);
        *cb = ConstraintBlocks::new(n, k);
    }
    model.lagrangian_blocks(x, lb);
    if k > 0 {
        model.constraint_blocks(x, true, cb);
    }
    let has_forces = model.force_blocks(x, &mut d.forces);
    if !has_forces {
        d.forces.iter_mut().for_each(|v| *v = T::zero());
    }
    // The values themselves, not only their derivatives: a model that leaves its domain may keep
    // finite derivatives while `L` or `f` turns NaN.
    if !lb.l.re().is_finite() || cb.f.iter().any(|f| !f.re().is_finite()) {
        return Err(SaddleFailure::NonFinite);
    }
    let pivot_ratio = saddle::solve_blocks(
        sw,
        n,
        k,
        |i, m| lb.w[i * n + m],
        |a, i| cb.j[a * n + i],
        |i| lb.dl_dq[i] - lb.g[i] + d.forces[i],
        |a| -cb.c[a],
    )?;
    let solution = sw.solution();
    d.qdd.copy_from_slice(&solution[..n]);
    d.mu.copy_from_slice(&solution[n..n + k]);
    let mut power = T::zero();
    let mut p_qd = T::zero();
    let mut power_forces = T::zero();
    for (i, (phi_i, (&qd_i, &p_i))) in d.phi.iter_mut().zip(x.qd.iter().zip(&lb.p)).enumerate() {
        let mut phi = T::zero();
        for (a, &mu_a) in d.mu.iter().enumerate() {
            phi += cb.j[a * n + i] * mu_a;
        }
        *phi_i = phi;
        power += qd_i * phi;
        p_qd += qd_i * p_i;
        power_forces += qd_i * d.forces[i];
    }
    d.f.copy_from_slice(&cb.f);
    d.l = lb.l;
    d.energy = p_qd - lb.l;
    d.dl_dt = lb.dl_dt;
    d.power = power;
    d.power_forces = power_forces;
    d.pivot_ratio = pivot_ratio;
    for (dst, src) in d.j.iter_mut().zip(&cb.j) {
        *dst = src.re();
    }
    d.w_scale = lb.w.iter().fold(0.0f64, |m, v| m.max(v.re().abs()));
    d.det_sign = sw.det_sign();
    Ok(())
}

/// [`evaluate`] for a static model: the same equations and the same block solve, with every block
/// a fixed-size `SVector`/`SMatrix` on the stack, so the sizes are known to the compiler
/// throughout.
///
/// With the model's compiled equations (`plan`), only what their structure needs is evaluated: a
/// constant `W` is never differentiated again (its factor is the plan's), a constant `r` needs no
/// pass over `L` at all, `g`, `c` and `Q` are skipped where they are zero, and the block system is
/// solved by the Schur complement. What the plan's `need` leaves out is not evaluated: `L`, `E` (which needs
/// `p = ∂L/∂q̇`) and `Q` outside [`Need::All`], `Φ` and the rates of the energy balance under
/// [`Need::Motion`]. Without a plan every block is evaluated, as for [`Need::All`].
#[inline(always)]
pub(crate) fn evaluate_fixed<M, T, const N: usize, const K: usize>(
    model: &M,
    plan: Option<Plan>,
    ws: &mut Workspace<T>,
    x: Point<T>,
) -> Result<(), SaddleFailure>
where
    M: crate::model::Lagrangian<N> + crate::model::Constraints<N, K> + ?Sized,
    T: Real,
{
    use compiled::{cholesky, cholesky_solve, Metric};
    use nalgebra::{SMatrix, SVector};
    let need = plan.map_or(Need::All, |p| p.need);
    let plan = plan.map(|p| p.compiled);
    let at = derivatives::fixed::At::<M, T, N>::from_point(model, x);
    let qd = at.qd;
    let s = plan.map(|p| p.structure());
    let zero = |b: fn(&structure::Structure) -> bool| s.is_some_and(b);
    let known_w = plan.and_then(|p| p.constant_factor());
    let (full, rates) = (need == Need::All, need.rates());

    // L, p = ∂L/∂q̇ (for E) and W.
    let (l, p, w) = match known_w {
        Some(_) if full => {
            let (l, p) = at.momentum();
            (Some(l), Some(p), None)
        }
        // The right-hand side needs neither L nor E: `d.l` keeps its last value.
        Some(_) => (None, None, None),
        None => {
            let (l, p, w) = at.velocity_hessian();
            (Some(l), Some(p), Some(w))
        }
    };
    // r = ∂L/∂q − g + Q, and ∂L/∂t and Q for the energy balance (when they are needed).
    let quiet = !rates || (zero(|s| s.dl_dt.zero) && zero(|s| s.forces.zero));
    let (r, dl_dt, forces) = match plan.and_then(|p| p.r_constant()) {
        Some(rc) if quiet => (
            SVector::<T, N>::from_fn(|i, _| T::from(rc[i])),
            T::zero(),
            None,
        ),
        _ => {
            let dl_dq = match plan.and_then(|p| p.dl_dq_constant()) {
                Some(c) => SVector::<T, N>::from_fn(|i, _| T::from(c[i])),
                None => at.position_gradient(),
            };
            let (g, dl_dt) = if zero(|s| s.g.zero) && (!rates || zero(|s| s.dl_dt.zero)) {
                (SVector::<T, N>::zeros(), T::zero())
            } else {
                let (g, dl_dir) = at.along_motion();
                (g, dl_dir - dl_dq.dot(&qd))
            };
            let forces = if zero(|s| s.forces.zero) {
                None
            } else {
                at.forces()
            };
            let r = match forces {
                Some(f) => dl_dq - g + f,
                None => dl_dq - g,
            };
            (r, dl_dt, forces)
        }
    };
    // f, J = ∂f/∂q̇, c = (∂f/∂q) q̇ + ∂f/∂t.
    let (f, j, c) = if K == 0 {
        (
            SVector::<T, K>::zeros(),
            SMatrix::<T, K, N>::zeros(),
            SVector::<T, K>::zeros(),
        )
    } else {
        let (f, j) = at.constraint_jacobian::<K>();
        let c = if zero(|s| s.c.zero) {
            SVector::<T, K>::zeros()
        } else {
            at.constraint_direction::<K>()
        };
        (f, j, c)
    };
    if l.is_some_and(|l| !l.re().is_finite()) || f.iter().any(|f| !f.re().is_finite()) {
        return Err(SaddleFailure::NonFinite);
    }
    for a in 0..K {
        if j.row(a).iter().all(|v| v.re() == 0.0) {
            return Err(SaddleFailure::ZeroConstraintRow { row: a });
        }
    }

    // a = W⁻¹ r and Y = W⁻¹ Jᵀ (column a is W⁻¹ J_aᵀ), by the plan's factor or a Cholesky
    // factorisation of W here; the pivoted elimination where W is not positive definite.
    let mut a0 = r;
    let mut y: SMatrix<T, N, K> = j.transpose();
    let mut wf = w.unwrap_or_else(SMatrix::<T, N, N>::zeros);
    let w_ratio = match known_w {
        Some((Metric::Diagonal(inv), ratio, _)) => {
            for i in 0..N {
                a0[i] *= inv[i];
                for b in 0..K {
                    y[(i, b)] *= inv[i];
                }
            }
            Some(ratio)
        }
        Some((Metric::Factor(lf), ratio, _)) => {
            let l = |i: usize, m: usize| T::from(lf[i * N + m]);
            cholesky_solve(l, N, a0.as_mut_slice());
            for b in 0..K {
                cholesky_solve(l, N, y.column_mut(b).as_mut_slice());
            }
            Some(ratio)
        }
        _ => cholesky(wf.as_mut_slice(), N).ok().inspect(|_| {
            let wf = &wf;
            let l = |i: usize, m: usize| wf.as_slice()[i * N + m];
            cholesky_solve(l, N, a0.as_mut_slice());
            for b in 0..K {
                cholesky_solve(l, N, y.column_mut(b).as_mut_slice());
            }
        }),
    };
    // Through the Cholesky factors `W` and `S` are positive definite, and so is the sign of the
    // block matrix's determinant; otherwise the pivoted elimination finds it.
    let mut det_sign = 1.0;
    // The blocks and the solution as the whole system's solves take them.
    let (jf, rf, sf) = (
        |a: usize, i: usize| j[(a, i)],
        |i: usize| r[i],
        |a: usize| -c[a],
    );
    let solution = |ws: &saddle::SaddleWorkspace<T>| {
        let x = ws.solution();
        (
            SVector::<T, N>::from_column_slice(&x[..N]),
            SVector::<T, K>::from_column_slice(&x[N..N + K]),
        )
    };
    let (qdd, mu, pivot_ratio) = match w_ratio {
        Some(w_ratio) if K == 0 => (a0, SVector::<T, K>::zeros(), w_ratio),
        Some(w_ratio) => {
            // S = J Y, S μ = −c − J a, q̈ = a + Y μ.
            let mut sm: SMatrix<T, K, K> = j * y;
            let mut mu = -c - j * a0;
            let s_ratio = if K == 1 {
                // One constraint: S is a positive number unless J_1 W⁻¹ J_1ᵀ vanishes.
                let s0 = sm[(0, 0)];
                mu[0] /= s0;
                if s0.re() > 0.0 {
                    1.0
                } else {
                    0.0
                }
            } else {
                let ratio = match cholesky(sm.as_mut_slice(), K) {
                    Ok(ratio) => ratio,
                    Err(ratio) => return Err(SaddleFailure::Singular { pivot_ratio: ratio }),
                };
                let sm = &sm;
                cholesky_solve(|i, m| sm.as_slice()[i * K + m], K, mu.as_mut_slice());
                ratio
            };
            if s_ratio < saddle::SINGULAR_PIVOT_RATIO {
                return Err(SaddleFailure::Singular {
                    pivot_ratio: s_ratio,
                });
            }
            if K > 1 && s_ratio < saddle::NULL_SPACE_PIVOT_RATIO {
                // Nearly dependent constraints: `a + Y μ` would cancel what the large `μ` carries.
                let wm = match (w, plan.map(|p| p.constant_w())) {
                    (Some(w), _) => w,
                    (None, Some(cw)) => SMatrix::<T, N, N>::from_fn(|i, m| T::from(cw[i * N + m])),
                    (None, None) => unreachable!("a constant W comes with the plan"),
                };
                saddle::solve_null_space(&mut ws.saddle, (N, K), |i, m| wm[(i, m)], jf, rf, sf)?;
                let (qdd, mu) = solution(&ws.saddle);
                (qdd, mu, w_ratio.min(s_ratio))
            } else {
                (a0 + y * mu, mu, w_ratio.min(s_ratio))
            }
        }
        None => {
            let wm = w.unwrap_or_else(SMatrix::<T, N, N>::zeros);
            let ratio = saddle::solve_blocks(&mut ws.saddle, N, K, |i, m| wm[(i, m)], jf, rf, sf)?;
            det_sign = ws.saddle.det_sign();
            let (qdd, mu) = solution(&ws.saddle);
            (qdd, mu, ratio)
        }
    };
    if qdd.iter().chain(mu.iter()).any(|v| !v.re().is_finite()) {
        return Err(SaddleFailure::NonFinite);
    }
    let d = &mut ws.dynamics;
    let put = |dst: &mut [T], src: &[T]| {
        for (x, &y) in dst.iter_mut().zip(src) {
            *x = y;
        }
    };
    put(&mut d.qdd[..N], qdd.as_slice());
    put(&mut d.mu[..K], mu.as_slice());
    put(&mut d.f[..K], f.as_slice());
    if let Some(l) = l {
        d.l = l;
    }
    if rates {
        let phi = j.tr_mul(&mu);
        put(&mut d.phi[..N], phi.as_slice());
        if let (Some(p), Some(l), true) = (p, l, full) {
            d.energy = qd.dot(&p) - l;
        }
        d.dl_dt = dl_dt;
        d.power = qd.dot(&phi);
        match forces {
            Some(f) => {
                put(&mut d.forces[..N], f.as_slice());
                d.power_forces = qd.dot(&f);
            }
            None => {
                if full {
                    d.forces[..N].iter_mut().for_each(|v| *v = T::zero());
                }
                d.power_forces = T::zero();
            }
        }
    }
    d.pivot_ratio = pivot_ratio;
    d.det_sign = det_sign;
    for a in 0..K {
        for i in 0..N {
            d.j[a * N + i] = j[(a, i)].re();
        }
    }
    d.w_scale = match (known_w, w) {
        (Some((_, _, scale)), _) => scale,
        (None, Some(w)) => w.iter().fold(0.0f64, |m, v| m.max(v.re().abs())),
        (None, None) => 0.0,
    };
    Ok(())
}
