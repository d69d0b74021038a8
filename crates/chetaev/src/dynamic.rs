//! Models whose sizes are known only at run time (scene files, generated models).
//!
//! The same equations, block solve, methods, step control, events and projection as the static
//! path ([`Problem`](crate::Problem), [`solve`](crate::solve)), with vectors as slices. The
//! derivatives are taken by scalar dual numbers, one direction (or pair of directions) per pass:
//!
//! | pass | dual type | passes | gives |
//! |---|---|---|---|
//! | A | `HyperDual` on `(q̇_i, q̇_j)`, `i ≤ j` | `N(N+1)/2` | `W_ij`, `p_i` |
//! | B | `HyperDual` on `q̇_i` and the direction `(q̇, 1)` | `N` | `g_i`, `∂L/∂q·q̇ + ∂L/∂t` |
//! | C | `Dual` on `q_i` | `N` | `∂L/∂q_i` |
//! | D | `Dual` on `q̇_i` | `N` (`K > 0` only) | column `i` of `J`, `f` |
//! | E | `Dual` along `(q̇, 1)` | 1 (`K > 0` only) | `c` |
//!
//! so one evaluation calls the Lagrangian `N(N+1)/2 + 2N` times, against 3 times on the static path,
//! whose vector dual numbers carry all directions at once. Prefer the static path where the sizes
//! are known when compiling.

use std::sync::Arc;

use num_dual::{Dual, Dual64, HyperDual};

use crate::equations::saddle::{solve_blocks, SaddleFailure, SaddleWorkspace};
use crate::error::Error;
use crate::integrate::driver::{drive, validate, Hooks};
use crate::integrate::events::{crosses, Direction};
use crate::integrate::options::{Atol, Options, Record};
use crate::integrate::projection::{constraint_scale, newton_projection, Projection};
use crate::integrate::system::{locate_slices as locate, OdeSystem, Stats};
use crate::integrate::{ErrorNorm, Method};
use crate::model::Real;
use crate::problem::{check_finite, INITIAL_RESIDUAL_TOLERANCE};
use crate::solution::Status;

/// A Lagrangian with `K` constraints on `N` coordinates, sizes known at run time.
///
/// ```
/// use chetaev::dynamic::*;
/// use chetaev::prelude::Real;
///
/// /// `n` unit masses on a line, each at constant speed `v0` relative to ... any count at run time.
/// struct Chain { n: usize, v0: f64 }
/// impl DynModel for Chain {
///     fn sizes(&self) -> (usize, usize) { (self.n, 1) }
///     fn lagrangian<R: Real>(&self, _t: R, q: &[R], qd: &[R]) -> R {
///         let mut l = R::zero();
///         for i in 0..q.len() { l += qd[i] * qd[i] * 0.5 - q[i] * q[i] * 0.5; }
///         l
///     }
///     fn constraints<R: Real>(&self, _t: R, _q: &[R], qd: &[R], f: &mut [R]) {
///         f[0] = qd.iter().fold(R::zero(), |a, v| a + *v * *v) - self.v0 * self.v0;
///     }
/// }
/// let model = Chain { n: 3, v0: 1.0 };
/// let problem = DynProblem::new(model, 0.0, vec![0.0, 1.0, 0.0], vec![1.0, 0.0, 0.0])?;
/// let sol = solve_dyn(&problem, chetaev::prelude::Dop853::default(), &DynOptions::until(2.0).tolerances(1e-10, 1e-10))?;
/// assert!(sol.is_success() && sol.max_residual() < 1e-8);
/// # Ok::<(), chetaev::Error>(())
/// ```
pub trait DynModel {
    /// `(N, K)`: the number of coordinates and of constraints. Fixed for the model's lifetime.
    fn sizes(&self) -> (usize, usize);
    /// `L(t, q, q̇)`; `q` and `q̇` have length `N`.
    fn lagrangian<R: Real>(&self, t: R, q: &[R], qd: &[R]) -> R;
    /// Writes `f(t, q, q̇)` (length `K`) to `f`. The default has no constraints.
    fn constraints<R: Real>(&self, t: R, q: &[R], qd: &[R], f: &mut [R]) {
        let _ = (t, q, qd, f);
    }
}

/// Everything known at one point after the multipliers are eliminated (run-time sizes).
#[derive(Clone, Debug)]
pub struct DynDynamics<T> {
    /// `q̈`, length `N`.
    pub qdd: Vec<T>,
    /// `μ`, length `K`.
    pub mu: Vec<T>,
    /// `Φ = Jᵀμ`, length `N`.
    pub phi: Vec<T>,
    /// `f`, length `K`.
    pub f: Vec<T>,
    /// `E = q̇·∂L/∂q̇ − L`.
    pub energy: T,
    /// `∂L/∂t`.
    pub dl_dt: T,
    /// `q̇·Φ`.
    pub power: T,
    /// Smallest over largest pivot of the block solve.
    pub pivot_ratio: f64,
}

/// `W = ∂²L/∂q̇²` (row-major `N × N`) and `p = ∂L/∂q̇`: pass A.
fn velocity_hessian<M: DynModel + ?Sized, T: Real>(
    model: &M,
    t: T,
    q: &[T],
    qd: &[T],
    w: &mut [T],
    p: &mut [T],
) -> T {
    type H<T> = HyperDual<T, f64>;
    let n = q.len();
    let th = H::from_re(t);
    let qh: Vec<H<T>> = q.iter().map(|&x| H::from_re(x)).collect();
    let mut qdh: Vec<H<T>> = qd.iter().map(|&x| H::from_re(x)).collect();
    let mut l = T::zero();
    for i in 0..n {
        for j in i..n {
            qdh[i].eps1 = T::one();
            qdh[j].eps2 += T::one();
            let v = model.lagrangian(th, &qh, &qdh);
            qdh[i].eps1 = T::zero();
            qdh[j].eps2 = T::zero();
            w[i * n + j] = v.eps1eps2;
            w[j * n + i] = v.eps1eps2;
            if i == j {
                p[i] = v.eps1;
                l = v.re;
            }
        }
    }
    l
}

/// `f` and `J` (row-major `K × N`): pass D.
fn constraint_jacobian<M: DynModel + ?Sized, T: Real>(
    model: &M,
    t: T,
    q: &[T],
    qd: &[T],
    f: &mut [T],
    j: &mut [T],
) {
    type D<T> = Dual<T, f64>;
    let (n, k) = (q.len(), f.len());
    let td = D::from_re(t);
    let qdl: Vec<D<T>> = q.iter().map(|&x| D::from_re(x)).collect();
    let mut qdd: Vec<D<T>> = qd.iter().map(|&x| D::from_re(x)).collect();
    let mut out = vec![D::from_re(T::zero()); k];
    for i in 0..n {
        qdd[i].eps = T::one();
        model.constraints(td, &qdl, &qdd, &mut out);
        qdd[i].eps = T::zero();
        for a in 0..k {
            j[a * n + i] = out[a].eps;
            f[a] = out[a].re;
        }
    }
}

/// Evaluates the reduced Chetaev equations at `(t, q, q̇)` for run-time sizes.
pub fn dynamics<M: DynModel + ?Sized, T: Real>(
    model: &M,
    ws: &mut SaddleWorkspace<T>,
    t: T,
    q: &[T],
    qd: &[T],
) -> Result<DynDynamics<T>, SaddleFailure> {
    let (n, k) = (q.len(), model.sizes().1);
    let mut w = vec![T::zero(); n * n];
    let mut p = vec![T::zero(); n];
    let l = velocity_hessian(model, t, q, qd, &mut w, &mut p);

    // Pass B: g_i, and the directional derivative ∂L/∂q·q̇ + ∂L/∂t.
    type H<T> = HyperDual<T, f64>;
    let th = H::new(t, T::zero(), T::one(), T::zero());
    let qh: Vec<H<T>> = (0..n)
        .map(|i| H::new(q[i], T::zero(), qd[i], T::zero()))
        .collect();
    let mut qdh: Vec<H<T>> = qd.iter().map(|&x| H::from_re(x)).collect();
    let mut g = vec![T::zero(); n];
    let mut dl_dir = T::zero();
    for i in 0..n {
        qdh[i].eps1 = T::one();
        let v = model.lagrangian(th, &qh, &qdh);
        qdh[i].eps1 = T::zero();
        g[i] = v.eps1eps2;
        dl_dir = v.eps2;
    }

    // Pass C: ∂L/∂q.
    type D<T> = Dual<T, f64>;
    let td = D::from_re(t);
    let mut qdl: Vec<D<T>> = q.iter().map(|&x| D::from_re(x)).collect();
    let qdd_d: Vec<D<T>> = qd.iter().map(|&x| D::from_re(x)).collect();
    let mut dl_dq = vec![T::zero(); n];
    for i in 0..n {
        qdl[i].eps = T::one();
        dl_dq[i] = model.lagrangian(td, &qdl, &qdd_d).eps;
        qdl[i].eps = T::zero();
    }
    let dot = |a: &[T], b: &[T]| a.iter().zip(b).fold(T::zero(), |acc, (x, y)| acc + *x * *y);
    let dl_dt = dl_dir - dot(&dl_dq, qd);
    let energy = dot(qd, &p) - l;

    // Passes D and E: f, J, and c = (∂f/∂q) q̇ + ∂f/∂t.
    let mut f = vec![T::zero(); k];
    let mut j = vec![T::zero(); k * n];
    let mut c = vec![T::zero(); k];
    if k > 0 {
        constraint_jacobian(model, t, q, qd, &mut f, &mut j);
        let te = D::new(t, T::one());
        let qe: Vec<D<T>> = (0..n).map(|i| D::new(q[i], qd[i])).collect();
        let mut out = vec![D::from_re(T::zero()); k];
        model.constraints(te, &qe, &qdd_d, &mut out);
        for a in 0..k {
            c[a] = out[a].eps;
        }
    }

    let pivot_ratio = solve_blocks(
        ws,
        n,
        k,
        |i, m| w[i * n + m],
        |a, i| j[a * n + i],
        |i| dl_dq[i] - g[i],
        |a| -c[a],
    )?;
    let x = ws.solution();
    let qdd = x[..n].to_vec();
    // `+ 0` turns a −0 from the elimination order into +0, as on the static path.
    let mu: Vec<T> = x[n..n + k].iter().map(|m| *m + 0.0).collect();
    let phi: Vec<T> = (0..n)
        .map(|i| (0..k).fold(T::zero(), |acc, a| acc + j[a * n + i] * mu[a]))
        .collect();
    let power = dot(qd, &phi);
    Ok(DynDynamics {
        qdd,
        mu,
        phi,
        f,
        energy,
        dl_dt,
        power,
        pivot_ratio,
    })
}

/// A run-time-sized model with a consistent initial state, validated like
/// [`Problem`](crate::Problem).
#[derive(Clone, Debug)]
pub struct DynProblem<M> {
    model: M,
    t0: f64,
    q0: Vec<f64>,
    qd0: Vec<f64>,
}

impl<M: DynModel> DynProblem<M> {
    /// Builds a problem after checking sizes, finiteness, the initial constraint residual and the
    /// regularity of the block system at the start.
    pub fn new(model: M, t0: f64, q0: Vec<f64>, qd0: Vec<f64>) -> Result<Self, Error> {
        let (n, k) = model.sizes();
        if n == 0 || k > n {
            return Err(Error::InvalidOption {
                name: "DynModel::sizes",
                value: n as f64,
                hint: "a model needs N ≥ 1 coordinates and at most N constraints",
            });
        }
        for (name, v) in [("q0 (length)", &q0), ("q̇0 (length)", &qd0)] {
            if v.len() != n {
                return Err(Error::InvalidOption {
                    name,
                    value: v.len() as f64,
                    hint:
                        "the initial state must have one entry per coordinate (DynModel::sizes().0)",
                });
            }
        }
        check_finite("t0", std::slice::from_ref(&t0))?;
        check_finite("q0", &q0)?;
        check_finite("q̇0", &qd0)?;
        let d = dynamics(&model, &mut SaddleWorkspace::default(), t0, &q0, &qd0)
            .map_err(|e| locate(e, t0, &q0, &qd0))?;
        if d.f.iter().any(|f| !f.is_finite()) || !d.energy.is_finite() {
            return Err(locate(SaddleFailure::NonFinite, t0, &q0, &qd0));
        }
        let mut f = vec![0.0; k];
        let mut j = vec![0.0; k * n];
        constraint_jacobian(&model, t0, &q0, &qd0, &mut f, &mut j);
        let qd_norm = qd0.iter().map(|v| v * v).sum::<f64>().sqrt();
        for a in 0..k {
            let j_norm = j[a * n..(a + 1) * n]
                .iter()
                .map(|v| v * v)
                .sum::<f64>()
                .sqrt();
            let tolerance = INITIAL_RESIDUAL_TOLERANCE * constraint_scale(j_norm, qd_norm);
            if f[a].abs() > tolerance {
                return Err(Error::InconsistentInitialState {
                    t: t0,
                    index: a,
                    residual: f[a],
                    tolerance,
                });
            }
        }
        Ok(Self { model, t0, q0, qd0 })
    }

    /// Builds a problem whose initial velocity is first projected onto `f(t0, q0, ·) = 0` (the
    /// explicit opt-in of [`Problem::with_projected_velocity`](crate::Problem::with_projected_velocity)).
    pub fn with_projected_velocity(
        model: M,
        t0: f64,
        q0: Vec<f64>,
        mut qd0: Vec<f64>,
    ) -> Result<Self, Error> {
        let n = model.sizes().0;
        if q0.len() != n || qd0.len() != n {
            return Self::new(model, t0, q0, qd0);
        }
        check_finite("t0", std::slice::from_ref(&t0))?;
        check_finite("q0", &q0)?;
        check_finite("q̇0", &qd0)?;
        project_velocity(
            &model,
            &mut SaddleWorkspace::default(),
            t0,
            &q0,
            &mut qd0,
            1e-14,
            20,
        )?;
        Self::new(model, t0, q0, qd0)
    }

    /// The model.
    pub fn model(&self) -> &M {
        &self.model
    }
    /// The initial time.
    pub fn t0(&self) -> f64 {
        self.t0
    }
    /// The initial position.
    pub fn q0(&self) -> &[f64] {
        &self.q0
    }
    /// The initial velocity.
    pub fn qd0(&self) -> &[f64] {
        &self.qd0
    }
}

/// An event function `g(t, q, q̇)` on slices, shared so options can be cloned.
pub type DynEventFn = Arc<dyn Fn(f64, &[f64], &[f64]) -> f64 + Send + Sync>;

/// An event `g(t, q, q̇)` on slices.
#[derive(Clone)]
pub struct DynEvent {
    /// A name for reports.
    pub name: String,
    /// The event function.
    pub g: DynEventFn,
    /// Which crossings count.
    pub direction: Direction,
    /// Whether the integration stops at the first crossing.
    pub terminal: bool,
}

impl DynEvent {
    /// An event counting crossings in both directions, not terminal.
    pub fn new(
        name: impl Into<String>,
        g: impl Fn(f64, &[f64], &[f64]) -> f64 + Send + Sync + 'static,
    ) -> Self {
        Self {
            name: name.into(),
            g: Arc::new(g),
            direction: Direction::Either,
            terminal: false,
        }
    }
    /// Counts only crossings from positive to negative.
    pub fn falling(mut self) -> Self {
        self.direction = Direction::Falling;
        self
    }
    /// Counts only crossings from negative to positive.
    pub fn rising(mut self) -> Self {
        self.direction = Direction::Rising;
        self
    }
    /// Stops the integration at the first crossing.
    pub fn terminal(mut self) -> Self {
        self.terminal = true;
        self
    }
}

/// Options of [`solve_dyn`]: the same as [`Options`] with events on slices.
#[derive(Clone)]
pub struct DynOptions {
    /// Everything but the events (its `events` stay empty).
    pub common: Options<0>,
    /// Event functions.
    pub events: Vec<DynEvent>,
}

impl DynOptions {
    /// Integrate to `t_end`; the defaults of [`Options::until`].
    pub fn until(t_end: f64) -> Self {
        Self {
            common: Options::until(t_end),
            events: Vec::new(),
        }
    }
    /// Sets the relative and (scalar) absolute tolerance.
    pub fn tolerances(mut self, rtol: f64, atol: f64) -> Self {
        self.common = self.common.tolerances(rtol, atol);
        self
    }
    /// One absolute tolerance per component: the `N` positions, then the `N` velocities.
    pub fn atol_per_component(mut self, atol: Vec<f64>) -> Self {
        self.common.atol = Atol::PerComponent(atol);
        self
    }
    /// Records at these times only.
    pub fn output_times(mut self, times: Vec<f64>) -> Self {
        self.common = self.common.output_times(times);
        self
    }
    /// Records at the start and the end only.
    pub fn output_final(mut self) -> Self {
        self.common = self.common.output_final();
        self
    }
    /// Chooses what is recorded.
    pub fn record(mut self, record: Record) -> Self {
        self.common = self.common.record(record);
        self
    }
    /// Projects onto `f = 0` after each accepted step and at every recorded point.
    pub fn project(mut self, projection: Projection) -> Self {
        self.common = self.common.project(projection);
        self
    }
    /// Sets the step limit.
    pub fn max_steps(mut self, n: usize) -> Self {
        self.common = self.common.max_steps(n);
        self
    }
    /// Sets the first step size.
    pub fn initial_step(mut self, h: f64) -> Self {
        self.common = self.common.initial_step(h);
        self
    }
    /// Bounds the step size.
    pub fn max_step(mut self, h: f64) -> Self {
        self.common = self.common.max_step(h);
        self
    }
    /// Adds an event function.
    pub fn event(mut self, event: DynEvent) -> Self {
        self.events.push(event);
        self
    }
}

/// A located event (run-time sizes).
#[derive(Clone, Debug, PartialEq)]
pub struct DynEventHit {
    /// Index of the event in the options.
    pub index: usize,
    /// Time.
    pub t: f64,
    /// Position.
    pub q: Vec<f64>,
    /// Velocity.
    pub qd: Vec<f64>,
}

/// The motion and its diagnostics (run-time sizes); the fields mean what they mean in
/// [`Solution`](crate::Solution), and are empty where the [`Record`] level did not ask for them.
#[derive(Clone, Debug)]
#[must_use = "a solution carries a status that says whether the integration succeeded"]
pub struct DynSolution {
    /// The method that produced it.
    pub method: &'static str,
    /// What was recorded.
    pub record: Record,
    /// Output times.
    pub t: Vec<f64>,
    /// `q` at the output times.
    pub q: Vec<Vec<f64>>,
    /// `q̇`.
    pub qd: Vec<Vec<f64>>,
    /// `q̈`.
    pub qdd: Vec<Vec<f64>>,
    /// `μ`.
    pub mu: Vec<Vec<f64>>,
    /// `Φ = Jᵀμ`.
    pub phi: Vec<Vec<f64>>,
    /// `f`.
    pub residual: Vec<Vec<f64>>,
    /// `E`.
    pub energy: Vec<f64>,
    /// `W_Φ`.
    pub work: Vec<f64>,
    /// `∫∂L/∂t dt`.
    pub dl_dt_integral: Vec<f64>,
    /// Located events.
    pub events: Vec<DynEventHit>,
    /// Work counters.
    pub stats: Stats,
    /// Why it stopped.
    pub status: Status,
}

impl DynSolution {
    /// Whether the end time or a terminal event was reached.
    pub fn is_success(&self) -> bool {
        !matches!(self.status, Status::Failed(_))
    }
    /// The error, if the integration failed.
    pub fn error(&self) -> Option<&Error> {
        match &self.status {
            Status::Failed(e) => Some(e),
            _ => None,
        }
    }
    /// Number of recorded points.
    pub fn len(&self) -> usize {
        self.t.len()
    }
    /// Whether nothing was recorded.
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }
    /// `max |f_a|` over the recorded points.
    pub fn max_residual(&self) -> f64 {
        self.residual
            .iter()
            .flatten()
            .fold(0.0f64, |a, v| a.max(v.abs()))
    }
    /// `E(t) − E(t0) − W_Φ(t) + ∫∂L/∂t dt` at each recorded point ([`Record::Energy`]).
    pub fn energy_balance(&self) -> Vec<f64> {
        if self.work.is_empty() {
            return Vec::new();
        }
        (0..self.work.len())
            .map(|i| self.energy[i] - self.energy[0] - self.work[i] + self.dl_dt_integral[i])
            .collect()
    }
}

/// The reduced equations of a run-time-sized model as an ODE: `y = [q, q̇, (W_Φ, ∫∂L/∂t)]`.
struct DynOde<'a, M> {
    model: &'a M,
    n: usize,
    energy: bool,
    ws: SaddleWorkspace<f64>,
    stats: Stats,
}

impl<M: DynModel> OdeSystem for DynOde<'_, M> {
    fn dim(&self) -> usize {
        2 * self.n + if self.energy { 2 } else { 0 }
    }
    fn controlled_dim(&self) -> usize {
        2 * self.n
    }
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), Error> {
        self.stats.rhs_evaluations += 1;
        let n = self.n;
        let (q, qd) = (&y[..n], &y[n..2 * n]);
        let d = dynamics(self.model, &mut self.ws, t, q, qd).map_err(|e| locate(e, t, q, qd))?;
        dy[..n].copy_from_slice(qd);
        dy[n..2 * n].copy_from_slice(&d.qdd);
        if self.energy {
            dy[2 * n] = d.power;
            dy[2 * n + 1] = d.dl_dt;
        }
        Ok(())
    }
    fn jacobian(
        &mut self,
        t: f64,
        y: &[f64],
        jac: &mut [f64],
        dfdt: &mut [f64],
    ) -> Result<(), Error> {
        self.stats.jacobian_evaluations += 1;
        let (n, dim) = (self.n, self.dim());
        let mut ws = SaddleWorkspace::<Dual64>::default();
        jac.iter_mut().for_each(|v| *v = 0.0);
        for dir in 0..=2 * n {
            let seed = |i: usize| if i == dir { 1.0 } else { 0.0 };
            let q: Vec<Dual64> = (0..n).map(|i| Dual64::new(y[i], seed(i))).collect();
            let qd: Vec<Dual64> = (0..n).map(|i| Dual64::new(y[n + i], seed(n + i))).collect();
            let d = dynamics(self.model, &mut ws, Dual64::new(t, seed(2 * n)), &q, &qd)
                .map_err(|e| locate(e, t, &y[..n], &y[n..2 * n]))?;
            let mut put = |row: usize, v: f64| {
                if dir < 2 * n {
                    jac[row * dim + dir] = v;
                } else {
                    dfdt[row] = v;
                }
            };
            for (i, (v, a)) in qd.iter().zip(&d.qdd).enumerate() {
                put(i, v.eps);
                put(n + i, a.eps);
            }
            if self.energy {
                put(2 * n, d.power.eps);
                put(2 * n + 1, d.dl_dt.eps);
            }
        }
        if jac.iter().chain(dfdt.iter()).any(|v| !v.is_finite()) {
            return Err(locate(SaddleFailure::NonFinite, t, &y[..n], &y[n..2 * n]));
        }
        Ok(())
    }
    fn count_lu(&mut self) {
        self.stats.lu_decompositions += 1;
    }
}

struct DynHooks<'s> {
    n: usize,
    sol: &'s mut DynSolution,
    options: &'s DynOptions,
    event_evaluations: usize,
}

impl<M: DynModel> Hooks<DynOde<'_, M>> for DynHooks<'_> {
    fn record(&mut self, sys: &mut DynOde<'_, M>, t: f64, y: &[f64]) -> Result<(), Error> {
        let n = sys.n;
        let (q, qd) = (&y[..n], &y[n..2 * n]);
        let record = self.options.common.record;
        let d = if record >= Record::Dynamics {
            sys.stats.output_evaluations += 1;
            Some(dynamics(sys.model, &mut sys.ws, t, q, qd).map_err(|e| locate(e, t, q, qd))?)
        } else {
            None
        };
        let sol = &mut *self.sol;
        sol.t.push(t);
        sol.q.push(q.to_vec());
        sol.qd.push(qd.to_vec());
        if let Some(d) = d {
            sol.qdd.push(d.qdd);
            sol.mu.push(d.mu);
            sol.phi.push(d.phi);
            sol.residual.push(d.f);
            sol.energy.push(d.energy);
        }
        if record >= Record::Energy {
            sol.work.push(y[2 * n]);
            sol.dl_dt_integral.push(y[2 * n + 1]);
        }
        Ok(())
    }
    fn n_events(&self) -> usize {
        self.options.events.len()
    }
    fn event_value(&mut self, i: usize, t: f64, y: &[f64]) -> Result<f64, Error> {
        let n = self.n;
        self.event_evaluations += 1;
        let v = (self.options.events[i].g)(t, &y[..n], &y[n..2 * n]);
        if v.is_finite() {
            Ok(v)
        } else {
            Err(Error::NonFiniteEvent {
                index: i,
                t,
                value: v,
            })
        }
    }
    fn crosses(&self, i: usize, g0: f64, g1: f64) -> bool {
        crosses(self.options.events[i].direction, g0, g1)
    }
    fn is_terminal(&self, i: usize) -> bool {
        self.options.events[i].terminal
    }
    fn event_hit(&mut self, i: usize, t: f64, y: &[f64]) {
        let n = self.n;
        self.sol.events.push(DynEventHit {
            index: i,
            t,
            q: y[..n].to_vec(),
            qd: y[n..2 * n].to_vec(),
        });
    }
    fn terminated(&mut self, i: usize) {
        self.sol.status = Status::Terminated { event: i };
    }
    fn project(&mut self, sys: &mut DynOde<'_, M>, t: f64, y: &mut [f64]) -> Result<bool, Error> {
        let Some(p) = self.options.common.projection else {
            return Ok(false);
        };
        if sys.model.sizes().1 == 0 {
            return Ok(false);
        }
        let n = sys.n;
        let (q, rest) = y.split_at_mut(n);
        let iterations = project_velocity(
            sys.model,
            &mut sys.ws,
            t,
            q,
            &mut rest[..n],
            p.tol,
            p.max_iterations,
        )?;
        sys.stats.projections += 1;
        sys.stats.projection_iterations += iterations;
        Ok(iterations > 0)
    }
}

/// Projects `q̇` (in place) onto `f(t, q, ·) = 0`: the smallest change in the metric `W`, by the
/// Newton iteration of [`project_velocity`](crate::integrate::projection::project_velocity).
/// Returns the iterations done.
pub fn project_velocity<M: DynModel + ?Sized>(
    model: &M,
    ws: &mut SaddleWorkspace<f64>,
    t: f64,
    q: &[f64],
    qd: &mut [f64],
    tol: f64,
    max_iterations: usize,
) -> Result<usize, Error> {
    let (n, k) = (q.len(), model.sizes().1);
    let mut p = vec![0.0; n];
    newton_projection(
        n,
        k,
        qd,
        Projection {
            tol,
            max_iterations,
        },
        ws,
        |qd, f, j| constraint_jacobian(model, t, q, qd, f, j),
        |qd, w| {
            velocity_hessian(model, t, q, qd, w, &mut p);
        },
    )
    .map(|(iterations, _)| iterations)
    .map_err(|e| e.locate(t, q, qd))
}

/// Integrates a run-time-sized `problem` with `method`; the counterpart of [`solve`](crate::solve).
pub fn solve_dyn<M: DynModel, Me: Method>(
    problem: &DynProblem<M>,
    method: Me,
    options: &DynOptions,
) -> Result<DynSolution, Error> {
    let o = &options.common;
    let n = problem.q0.len();
    let atol = match &o.atol {
        Atol::Scalar(a) => vec![*a; 2 * n],
        Atol::PerComponent(v) => {
            if v.len() != 2 * n {
                return Err(Error::InvalidOption {
                    name: "atol (length)",
                    value: v.len() as f64,
                    hint: "give one absolute tolerance per component of (q, q̇), 2N in all",
                });
            }
            v.clone()
        }
    };
    let mut check = o.clone();
    check.atol = Atol::Scalar(atol.iter().copied().fold(f64::INFINITY, f64::min));
    validate(&check)?;
    method.validate()?;
    let mut sys = DynOde {
        model: &problem.model,
        n,
        energy: o.record >= Record::Energy,
        ws: SaddleWorkspace::default(),
        stats: Stats::default(),
    };
    let mut y = vec![0.0; sys.dim()];
    y[..n].copy_from_slice(&problem.q0);
    y[n..2 * n].copy_from_slice(&problem.qd0);
    let mut sol = DynSolution {
        method: method.name(),
        record: o.record,
        t: Vec::new(),
        q: Vec::new(),
        qd: Vec::new(),
        qdd: Vec::new(),
        mu: Vec::new(),
        phi: Vec::new(),
        residual: Vec::new(),
        energy: Vec::new(),
        work: Vec::new(),
        dl_dt_integral: Vec::new(),
        events: Vec::new(),
        stats: Stats::default(),
        status: Status::Success,
    };
    let mut hooks = DynHooks {
        n,
        sol: &mut sol,
        options,
        event_evaluations: 0,
    };
    let norm = ErrorNorm::new(o.rtol, atol);
    let (outcome, counts) = drive(&mut sys, &mut hooks, method, problem.t0, &mut y, &norm, o);
    let event_evaluations = hooks.event_evaluations;
    if let Err(e) = outcome {
        sol.status = Status::Failed(e);
    }
    sol.stats = counts.merged(sys.stats, event_evaluations);
    Ok(sol)
}
