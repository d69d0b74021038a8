//! The traits a user implements: a Lagrangian and, optionally, velocity constraints.
//!
//! Both are written once, generically over the scalar type `R: Real`, so that the same code is
//! evaluated with `f64` for values and with num-dual's dual numbers for every derivative the
//! Chetaev equations need. Nothing else is asked of the user: no mass matrix, no Jacobian, no
//! multiplier algebra.
//!
//! There are two flavours, for the two ways sizes become known, and one engine behind them:
//!
//! | flavour | user writes | sizes | becomes a [`Model`] by |
//! |---|---|---|---|
//! | static | [`Lagrangian<N>`] and [`Constraints<N, K>`] on `SVector` | when compiling | [`Problem::new`](crate::Problem::new) (wraps it in [`Fixed`]) |
//! | run-time | [`DynModel`] on slices | at run time (scene files, generated models) | itself (every `DynModel` is a `Model`) |
//!
//! [`Model`] is what the engine needs of either flavour: every derivative block of `L` and `f` at
//! a point, on slices. Everything above it (the block solve, the driver, events, projection,
//! recording) exists once.

use nalgebra::SVector;
use num_dual::DualNum;

use crate::equations::compiled::Compiled;
use crate::equations::derivatives::fixed::At;
use crate::equations::derivatives::{self, ConstraintBlocks, Holonomic, LagrangianBlocks};
use crate::equations::graph::Sym;
use crate::equations::saddle::SaddleFailure;
use crate::equations::{Need, Workspace};

/// A scalar the library can differentiate: `f64`, or any (nested) num-dual number over `f64`.
///
/// It offers the arithmetic operators (also with `f64` on the right: `x * 2.0`), comparisons with
/// `f64`, and the elementary functions of [`num_dual::DualNum`] (`sqrt`, `sin`, `cosh`, `ln`,
/// `powi`, ...), called as methods: `x.sqrt()`; `y.atan2(x)` is [`Real::atan2`], whose derivatives
/// are also finite where `x = 0`.
pub trait Real: DualNum<f64> + Copy + 'static {
    /// A model parameter: the value `value`, named `name` so that derivatives of the motion with
    /// respect to it can be asked for ([`Seed::parameter`](crate::Seed::parameter)).
    ///
    /// Write `R::parameter("g", self.g)` where the model would write `self.g`. In every
    /// evaluation it is the constant `value` (at no cost); only where sensitivities are asked for
    /// is it an input of the recorded equations, so that `∂F/∂p` is exact. A parameter read
    /// as a plain number (`self.g`) is a constant for sensitivities. One name stands for one
    /// value: a name read with two values is an [`Error::Sensitivity`](crate::Error::Sensitivity)
    /// when sensitivities are asked for.
    ///
    /// ```
    /// use chetaev::prelude::*;
    /// struct Fall { g: f64 }
    /// impl Lagrangian<1> for Fall {
    ///     fn lagrangian<R: Real>(&self, _t: R, q: &SVector<R, 1>, qd: &SVector<R, 1>) -> R {
    ///         qd[0] * qd[0] * 0.5 - q[0] * R::parameter("g", self.g)
    ///     }
    /// }
    /// ```
    #[inline]
    fn parameter(name: &str, value: f64) -> Self {
        use std::any::{Any, TypeId};
        if TypeId::of::<Self>() == TypeId::of::<Sym>() {
            let s = crate::equations::graph::parameter(name, value);
            if let Some(&r) = (&s as &dyn Any).downcast_ref::<Self>() {
                return r;
            }
        }
        // Read inside a dual number over the recorded scalar (a load's point, differentiated by
        // the coordinates while the equations are recorded): the same input, with no derivative.
        if TypeId::of::<Self>() == TypeId::of::<num_dual::Dual<Sym, f64>>() {
            let s = num_dual::Dual::from_re(crate::equations::graph::parameter(name, value));
            if let Some(&r) = (&s as &dyn Any).downcast_ref::<Self>() {
                return r;
            }
        }
        Self::from(value)
    }

    /// The angle of the point `(x, self)`, in `(−π, π]`, as [`f64::atan2`], with its derivatives
    /// also where `x = 0`: `y.atan2(x)` in a model calls this.
    ///
    /// num-dual's own `atan2` takes the derivatives from `atan(y/x)`, which are NaN where `x` is
    /// exactly zero, for instance at the polar angle `π/2` of a point on the `y` axis. Here they
    /// come from `atan(y/x)` where `|x| ≥ |y|` and from `±π/2 − atan(x/y)` elsewhere; the value is
    /// that of [`f64::atan2`].
    ///
    /// ```
    /// use chetaev::num_dual::{Dual64, DualNum};
    /// use chetaev::prelude::*;
    /// // θ = atan2(y, x) at (0, 1), moved along x: dθ/dx = −y/(x² + y²) = −1.
    /// let theta = Real::atan2(Dual64::from(1.0), Dual64::new(0.0, 1.0));
    /// assert_eq!((theta.re, theta.eps), (std::f64::consts::FRAC_PI_2, -1.0));
    /// assert!(DualNum::atan2(&Dual64::from(1.0), Dual64::new(0.0, 1.0)).eps.is_nan());
    /// ```
    #[inline]
    fn atan2(self, x: Self) -> Self {
        use std::any::TypeId;
        // A plain number, or a recorded one (whose derivatives are taken symbolically).
        if TypeId::of::<Self>() == TypeId::of::<f64>()
            || TypeId::of::<Self>() == TypeId::of::<Sym>()
        {
            return DualNum::atan2(&self, x);
        }
        let (yr, xr) = (self.re(), x.re());
        if xr == 0.0 && yr == 0.0 {
            // The origin, where the angle has no derivative.
            return DualNum::atan2(&self, x);
        }
        let angle = if xr.abs() >= yr.abs() {
            let a = (self / x).atan();
            match (xr < 0.0, yr < 0.0) {
                (false, _) => a,
                (true, false) => a + std::f64::consts::PI,
                (true, true) => a - std::f64::consts::PI,
            }
        } else {
            let a = -(x / self).atan();
            a + std::f64::consts::FRAC_PI_2.copysign(yr)
        };
        // A constant shift (no derivative) to the value of `atan2` itself.
        angle + (yr.atan2(xr) - angle.re())
    }
}
impl<T: DualNum<f64> + Copy + 'static> Real for T {}

/// A Lagrangian `L(t, q, q̇)` on `N` generalised coordinates (sizes known when compiling).
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

    /// Generalised forces `Q(t, q, q̇)` not derivable from `L` (friction, drag, driving forces), on
    /// the force side of the equations: `d/dt ∂L/∂q̇ − ∂L/∂q = Q + Jᵀμ`. `None` (the default) for
    /// none, which costs nothing.
    fn forces<R: Real>(
        &self,
        t: R,
        q: &SVector<R, N>,
        qd: &SVector<R, N>,
    ) -> Option<SVector<R, N>> {
        let _ = (t, q, qd);
        None
    }

    /// A Rayleigh dissipation function `D(t, q, q̇)`, whose force `Q_D = −∂D/∂q̇` is added to
    /// [`Lagrangian::forces`] (derived by automatic differentiation). `None` (the default) for none.
    fn dissipation<R: Real>(&self, t: R, q: &SVector<R, N>, qd: &SVector<R, N>) -> Option<R> {
        let _ = (t, q, qd);
        None
    }
}

/// `K` velocity constraints `f_a(t, q, q̇) = 0`, `a = 1..K`, possibly nonlinear in `q̇` and
/// dependent on `q` and `t` (sizes known when compiling).
///
/// The constraint force is Chetaev's, `Φ = Σ_a μ_a ∂f_a/∂q̇` (see `docs/conventions.md`). The
/// Jacobian `J = ∂f/∂q̇` (shape `K × N`) must have full row rank along the motion.
///
/// The unconstrained motion of any Lagrangian needs no extra code: wrap it in [`Unconstrained`]
/// (`K = 0`), which pays for no multiplier work, or write `impl Constraints<N, 0> for Model {}`.
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
    ///
    /// Provided only for `K = 0`: a model with holonomic constraints alone, or none, writes
    /// `impl Constraints<N, 0> for Model {}` and at most the holonomic methods. A model with
    /// `K > 0` that leaves it out and is solved does not build (`cargo build`, `test` or `run`;
    /// `cargo check` does not evaluate the assertion), with a message that names this method:
    ///
    /// ```compile_fail,E0080
    /// use chetaev::prelude::*;
    ///
    /// struct Forgotten;
    /// impl Lagrangian<2> for Forgotten {
    ///     fn lagrangian<R: Real>(&self, _t: R, _q: &SVector<R, 2>, qd: &SVector<R, 2>) -> R {
    ///         qd.dot(qd) * 0.5
    ///     }
    /// }
    /// impl Constraints<2, 1> for Forgotten {}
    ///
    /// let problem = Problem::new(Forgotten, 0.0, SVector::zeros(), SVector::from([1.0, 0.0]));
    /// ```
    fn constraints<R: Real>(&self, t: R, q: &SVector<R, N>, qd: &SVector<R, N>) -> SVector<R, K> {
        const {
            assert!(
                K == 0,
                "a model with K > 0 velocity constraints must implement Constraints::constraints"
            )
        };
        let _ = (t, q, qd);
        SVector::zeros()
    }

    /// The number `H` of holonomic constraints `h(t, q) = 0` besides the `K` velocity constraints
    /// (0, the default, for none). See [`Constraints::holonomic`].
    fn holonomic_count(&self) -> usize {
        0
    }

    /// Writes the holonomic constraints `h(t, q)` (length [`Constraints::holonomic_count`]) to `h`.
    ///
    /// They are enforced at acceleration level by their second time derivative (by automatic
    /// differentiation), their multipliers `λ` follow the `K` velocity multipliers in `μ`, and
    /// their force is `Hᵀλ`, `H = ∂h/∂q`. Position residuals are recorded, and the projection
    /// option corrects positions onto `h = 0` before velocities (see `docs/holonomic.md`).
    fn holonomic<R: Real>(&self, t: R, q: &SVector<R, N>, h: &mut [R]) {
        let _ = (t, q, h);
    }
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
    #[inline(always)]
    fn forces<R: Real>(
        &self,
        t: R,
        q: &SVector<R, N>,
        qd: &SVector<R, N>,
    ) -> Option<SVector<R, N>> {
        self.0.forces(t, q, qd)
    }
    #[inline(always)]
    fn dissipation<R: Real>(&self, t: R, q: &SVector<R, N>, qd: &SVector<R, N>) -> Option<R> {
        self.0.dissipation(t, q, qd)
    }
}

impl<M, const N: usize> Constraints<N, 0> for Unconstrained<M> {}

/// A Lagrangian with `K` constraints on `N` coordinates, sizes known only at run time (scene
/// files, generated models). Every `DynModel` is a [`Model`]; build its problem with
/// [`Problem::dynamic`](crate::Problem::dynamic).
///
/// ```
/// use chetaev::prelude::*;
///
/// /// `n` unit masses in harmonic wells, their total speed held at `v0`: any `n` at run time.
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
/// let problem = Problem::dynamic(Chain { n: 3, v0: 1.0 }, 0.0, vec![0.0, 1.0, 0.0], vec![1.0, 0.0, 0.0])?;
/// let sol = solve(&problem, Dop853::default(), &Options::until(2.0).tolerances(1e-10, 1e-10))?;
/// assert!(sol.is_success() && sol.max_residual().is_some_and(|r| r < 1e-8));
/// # Ok::<(), chetaev::Error>(())
/// ```
pub trait DynModel {
    /// `(N, K)`: the number of coordinates and of velocity constraints `f = 0` (those written by
    /// [`DynModel::constraints`]); the holonomic ones are counted apart, by
    /// [`DynModel::holonomic_count`] (`H`). Fixed for the model's lifetime. The problem's `k`
    /// ([`Problem::sizes`](crate::Problem::sizes), the number of multipliers) is `K + H`.
    fn sizes(&self) -> (usize, usize);
    /// `L(t, q, q̇)`; `q` and `q̇` have length `N`.
    fn lagrangian<R: Real>(&self, t: R, q: &[R], qd: &[R]) -> R;
    /// Writes `f(t, q, q̇)` (length `K`) to `f`. The default has no constraints.
    fn constraints<R: Real>(&self, t: R, q: &[R], qd: &[R], f: &mut [R]) {
        let _ = (t, q, qd, f);
    }
    /// Writes the generalised forces `Q(t, q, q̇)` not derivable from `L` (length `N`) to `out` and
    /// returns `true`; the default has none and returns `false`. See [`Lagrangian::forces`].
    fn forces<R: Real>(&self, t: R, q: &[R], qd: &[R], out: &mut [R]) -> bool {
        let _ = (t, q, qd, out);
        false
    }
    /// A Rayleigh dissipation function `D(t, q, q̇)` (its force `−∂D/∂q̇` is derived); `None`, the
    /// default, for none. See [`Lagrangian::dissipation`].
    fn dissipation<R: Real>(&self, t: R, q: &[R], qd: &[R]) -> Option<R> {
        let _ = (t, q, qd);
        None
    }
    /// The number of holonomic constraints `h(t, q) = 0` besides the `K` of
    /// [`DynModel::sizes`] (0, the default). See [`Constraints::holonomic`].
    fn holonomic_count(&self) -> usize {
        0
    }
    /// Writes `h(t, q)` (length [`DynModel::holonomic_count`]) to `h`.
    fn holonomic<R: Real>(&self, t: R, q: &[R], h: &mut [R]) {
        let _ = (t, q, h);
    }
}

/// A point `(t, q, q̇)` over the scalar `T`, with `q` and `q̇` of the model's `n` coordinates: where
/// the engine evaluates a [`Model`].
#[derive(Debug)]
pub struct Point<'a, T> {
    /// The time.
    pub t: T,
    /// The coordinates.
    pub q: &'a [T],
    /// The velocities.
    pub qd: &'a [T],
}

impl<'a, T> Point<'a, T> {
    /// The point `(t, q, q̇)`.
    #[inline(always)]
    pub fn new(t: T, q: &'a [T], qd: &'a [T]) -> Self {
        Self { t, q, qd }
    }
}

impl<T: Copy> Clone for Point<'_, T> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<T: Copy> Copy for Point<'_, T> {}

/// A model's own functions at one point, as [`Model::functions`] writes them.
#[derive(Clone, Debug)]
pub struct Functions<T> {
    /// `L`.
    pub l: T,
    /// The velocity constraints `f`.
    pub f: Vec<T>,
    /// The holonomic constraints `h`.
    pub h: Vec<T>,
    /// The forces `Q` not derivable from `L`, when `has_forces`.
    pub forces: Vec<T>,
    /// Whether the model has forces `Q`.
    pub has_forces: bool,
    /// The dissipation function `D`, if any.
    pub dissipation: Option<T>,
}

impl<T: Real> Functions<T> {
    /// Zeroed values for a model with `n` coordinates, `kv` velocity and `kh` holonomic
    /// constraints.
    pub fn new(n: usize, kv: usize, kh: usize) -> Self {
        Self {
            l: T::zero(),
            f: vec![T::zero(); kv],
            h: vec![T::zero(); kh],
            forces: vec![T::zero(); n],
            has_forces: false,
            dissipation: None,
        }
    }
}

/// What the equations engine needs of a model: its sizes and the derivative blocks of `L` and `f`
/// at a point `(t, q, q̇)` given as slices of length `n`, for any scalar `T` (`f64` for values, a
/// dual number when the engine differentiates the reduced equations once more).
///
/// Users do not implement it: a static model becomes one through [`Fixed`], and every
/// [`DynModel`] is one. Each flavour takes its derivatives in the way that suits it (vector dual
/// numbers on the stack for static sizes, scalar dual numbers for run-time sizes); see
/// [`derivatives`].
pub trait Model {
    /// `(n, k)`: coordinates and multipliers, `k = K + H`: the `K` velocity constraints first and
    /// then the `H` holonomic ones, each of those entering as its time derivative `ḣ = 0`. (A
    /// [`DynModel`]'s own `sizes` gives `K` alone.)
    fn sizes(&self) -> (usize, usize);

    /// How many of the `k` constraints are holonomic (the last ones).
    fn holonomic_count(&self) -> usize {
        0
    }

    /// The model's own functions over any scalar, with nothing derived: `L`, the velocity
    /// constraints `f` (the first `k − holonomic_count` rows) into `f`, the holonomic constraints
    /// `h` into `h`, the forces `Q` into `forces` (returning whether there are any) and the
    /// dissipation function `D`. The engine records them once as an expression graph
    /// ([`equations::compiled`](crate::equations::compiled)). Returns whether it wrote them; the
    /// default does not, and such a model is evaluated by the dual-number blocks alone.
    fn functions<T: Real>(&self, x: Point<T>, out: &mut Functions<T>) -> bool {
        let _ = (x, out);
        false
    }

    /// The holonomic constraints `h(t, q)` (length [`Model::holonomic_count`]) into `h`, and, when
    /// given, `H = ∂h/∂q` (row-major `count × n`) into `hq`.
    fn holonomic_blocks(&self, t: f64, q: &[f64], h: &mut [f64], hq: Option<&mut [f64]>) {
        let _ = (t, q, h, hq);
    }

    /// `L`, `p = ∂L/∂q̇`, `W = ∂²L/∂q̇²`, `∂L/∂q`, `g = (∂²L/∂q̇∂q) q̇ + ∂²L/∂q̇∂t` and `∂L/∂t` into
    /// `out` (whose vectors have the model's sizes).
    fn lagrangian_blocks<T: Real>(&self, x: Point<T>, out: &mut LagrangianBlocks<T>);

    /// `W = ∂²L/∂q̇²` alone (row-major `n × n`), for the projection's metric.
    fn velocity_hessian<T: Real>(&self, x: Point<T>, w: &mut [T]);

    /// `f`, `J = ∂f/∂q̇` and `c = (∂f/∂q) q̇ + ∂f/∂t` into `out`; with `with_c = false` only `f` and
    /// `J` (the projection needs no `c`). Never called when `k = 0`.
    fn constraint_blocks<T: Real>(&self, x: Point<T>, with_c: bool, out: &mut ConstraintBlocks<T>);

    /// `f(t, q, q̇)` alone (length `k`).
    fn constraint_values(&self, x: Point<f64>, f: &mut [f64]);

    /// The forces not derivable from `L`, `Q − ∂D/∂q̇` (length `n`), into `out`; returns whether
    /// the model has any (when `false`, `out` is untouched and nothing was evaluated).
    fn force_blocks<T: Real>(&self, x: Point<T>, out: &mut [T]) -> bool;

    /// The reduced equations at `x` into `ws` (see [`equations::evaluate`]). The default builds
    /// them from [`Model::lagrangian_blocks`] and [`Model::constraint_blocks`]; a flavour may take
    /// a faster route to the same numbers (a static model keeps every block on the stack with its
    /// sizes known to the compiler).
    ///
    /// [`equations::evaluate`]: crate::equations::evaluate
    #[inline]
    fn evaluate_into<T: Real>(
        &self,
        ws: &mut Workspace<T>,
        x: Point<T>,
    ) -> Result<(), SaddleFailure> {
        crate::equations::evaluate_blocks(self, ws, x)
    }

    /// The reduced equations by a route of the flavour's own that uses the structure found in
    /// the plan's compiled equations (the model's), or `None` to evaluate the compiled tape. A
    /// static model of a few coordinates keeps its fixed-size dual passes and skips the blocks
    /// the plan proves zero or constant, and what the plan's [`Need`] leaves out; a larger one
    /// takes the tape, which is then faster.
    #[inline]
    fn evaluate_planned<T: Real>(&self, plan: Plan, ws: &mut Workspace<T>, x: Point<T>) -> Planned {
        let _ = (plan, ws, x);
        None
    }

    /// [`Model::evaluate_planned`] for a model whose compiled equations re-check bounds of
    /// domains (`ln x`, `atanh x`, …) and no branch, asked where `evaluate_planned` had no route
    /// of its own: a route that checks the model's values instead of the bounds, or `None` to
    /// evaluate the compiled tape, which re-checks them.
    fn evaluate_bounded<T: Real>(&self, plan: Plan, ws: &mut Workspace<T>, x: Point<T>) -> Planned {
        let _ = (plan, ws, x);
        None
    }
}

/// The model's compiled equations and what the caller needs of the dynamics: what
/// [`Model::evaluate_planned`] may use.
#[derive(Clone, Copy, Debug)]
pub struct Plan<'a> {
    /// The model's compiled equations.
    pub compiled: &'a Compiled,
    /// What is needed.
    pub need: Need,
}

/// What [`Model::evaluate_planned`] returns: the outcome of the model's own route, or `None` where
/// it has none for the plan (and the compiled tape is evaluated).
pub type Planned = Option<Result<(), SaddleFailure>>;

/// A static model (`Lagrangian<N> + Constraints<N, K>`) as a [`Model`]. [`Problem::new`] wraps
/// the user's model in it; it dereferences to the user's model.
///
/// [`Problem::new`]: crate::Problem::new
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Fixed<M, const N: usize, const K: usize>(pub M);

impl<M, const N: usize, const K: usize> std::ops::Deref for Fixed<M, N, K> {
    type Target = M;
    fn deref(&self) -> &M {
        &self.0
    }
}

impl<M, const N: usize, const K: usize> Model for Fixed<M, N, K>
where
    M: Lagrangian<N> + Constraints<N, K>,
{
    fn sizes(&self) -> (usize, usize) {
        (N, K + self.0.holonomic_count())
    }

    fn holonomic_count(&self) -> usize {
        self.0.holonomic_count()
    }

    fn functions<T: Real>(&self, x: Point<T>, out: &mut Functions<T>) -> bool {
        let (m, x) = (&self.0, At::<M, T, N>::from_point(&self.0, x));
        let (t, q, qd) = (x.t, &x.q, &x.qd);
        out.l = m.lagrangian(t, q, qd);
        out.f.copy_from_slice(m.constraints(t, q, qd).as_slice());
        m.holonomic(t, q, &mut out.h);
        out.has_forces = match m.forces(t, q, qd) {
            Some(f) => {
                out.forces.copy_from_slice(f.as_slice());
                true
            }
            None => false,
        };
        out.dissipation = m.dissipation(t, q, qd);
        true
    }

    fn holonomic_blocks(&self, t: f64, q: &[f64], h: &mut [f64], hq: Option<&mut [f64]>) {
        derivatives::holonomic_blocks(self, t, q, h, hq);
    }

    #[inline]
    fn lagrangian_blocks<T: Real>(&self, x: Point<T>, out: &mut LagrangianBlocks<T>) {
        At::<M, T, N>::from_point(&self.0, x).lagrangian_blocks(out);
    }

    fn velocity_hessian<T: Real>(&self, x: Point<T>, w: &mut [T]) {
        At::<M, T, N>::from_point(&self.0, x).velocity_hessian_into(w);
    }

    #[inline]
    fn constraint_blocks<T: Real>(&self, x: Point<T>, with_c: bool, out: &mut ConstraintBlocks<T>) {
        At::<M, T, N>::from_point(&self.0, x).constraint_blocks::<K>(with_c, out);
        derivatives::holonomic_rows(self, K, x, with_c, out);
    }

    #[inline(never)]
    fn evaluate_into<T: Real>(
        &self,
        ws: &mut Workspace<T>,
        x: Point<T>,
    ) -> Result<(), SaddleFailure> {
        if self.0.holonomic_count() > 0 {
            // The holonomic rows have sizes known only at run time.
            return crate::equations::evaluate_blocks(self, ws, x);
        }
        crate::equations::evaluate_fixed::<M, T, N, K>(&self.0, None, ws, x)
    }

    #[inline]
    fn evaluate_planned<T: Real>(&self, plan: Plan, ws: &mut Workspace<T>, x: Point<T>) -> Planned {
        // The fixed-size passes skip what the recorded structure proves, but they do not re-check
        // the recorded guards: a model with branches takes the compiled tape, which does, and one
        // with bounds of domains only `evaluate_bounded`. So does a model too large for
        // the passes to be the faster route.
        // A constant metric leaves a short body, inlined into the caller; the longer one of a
        // metric that varies is called, which keeps the caller's loop lean.
        let c = plan.compiled;
        let passes = fixed_passes_pay::<T>(N, c.constant_metric());
        (passes && self.0.holonomic_count() == 0 && c.guards() == 0).then(|| {
            if c.constant_factor().is_some() {
                crate::equations::evaluate_fixed::<M, T, N, K>(&self.0, Some(plan), ws, x)
            } else {
                self.evaluate_outlined(plan, ws, x)
            }
        })
    }

    /// A bound of a domain needs no re-check on the fixed-size passes when the values are
    /// checked: beyond the bound the value is NaN while every derivative may be finite (`ln x`
    /// beyond 0, `1/x` there). The passes check `f`'s and, where they make it, `L`'s; `L`'s is
    /// checked here first where they do not make it (a constant metric, `L` and `E` not needed). Apart from
    /// [`Model::evaluate_planned`], so that the passes of every other model stay as they are.
    #[inline(never)]
    fn evaluate_bounded<T: Real>(&self, plan: Plan, ws: &mut Workspace<T>, x: Point<T>) -> Planned {
        let c = plan.compiled;
        let passes = fixed_passes_pay::<T>(N, c.constant_metric());
        (passes && self.0.holonomic_count() == 0 && c.guards() > 0 && c.branches() == 0).then(
            || {
                // The passes make `L` (and check it) unless `W` is constant and factorised once
                // and the caller needs neither `L` nor `E`.
                let made = c.constant_factor().is_none() || plan.need == Need::All;
                if !made
                    && !At::<M, T, N>::from_point(&self.0, x)
                        .value()
                        .re()
                        .is_finite()
                {
                    return Err(SaddleFailure::NonFinite);
                }
                crate::equations::evaluate_fixed::<M, T, N, K>(&self.0, Some(plan), ws, x)
            },
        )
    }

    #[inline]
    fn force_blocks<T: Real>(&self, x: Point<T>, out: &mut [T]) -> bool {
        match At::<M, T, N>::from_point(&self.0, x).forces() {
            Some(f) => {
                out.copy_from_slice(f.as_slice());
                true
            }
            None => false,
        }
    }

    fn constraint_values(&self, x: Point<f64>, f: &mut [f64]) {
        let at = At::<M, f64, N>::from_point(&self.0, x);
        f[..K].copy_from_slice(self.0.constraints(at.t, &at.q, &at.qd).as_slice());
        derivatives::holonomic_velocities(self, K, x, f);
    }
}

/// The most coordinates for which a static model's fixed-size dual passes evaluate its reduced
/// equations faster than the compiled tape, `[[value, dual]; 2]`: the right-hand side in `f64`,
/// and in dual numbers for the Jacobian of the implicit methods; for a metric `W` that is
/// constant (first row) and for one that varies. The passes carry `W` in every dual number (or,
/// above [`DENSE_HESSIAN_MAX_N`](crate::equations::derivatives::DENSE_HESSIAN_MAX_N), its columns
/// pass by pass): `O(n²)` work for each operation of `L`, where the tape does a fixed amount for
/// each operation of the derived equations. A metric that varies adds its derivatives to the
/// passes' work, and only a factorisation to the tape's.
///
/// The bounds are where the two crossed in whole solves (`bench/revisions -- --sizes`,
/// docs/performance/history.md, "Large static models take the tape"). On a chain of springs (`W`
/// constant), solves took 1.4× the passes' time with the tape at `n = 8`, 0.9× at 12 and 0.5–0.6×
/// at 24 for the right-hand side, and 1.0× at `n = 6`, 0.7× at 8 for the Jacobian. On a chain of
/// pendulums (`W` varying), 1.1× at `n = 3`, 0.9× at 4 and 0.07–0.1× at 16 for the right-hand
/// side, and 1.0× at `n = 2`, 0.6–0.8× at 3 and 0.04× at 16 for the Jacobian.
const FIXED_PASSES_MAX_N: [[usize; 2]; 2] = [[10, 5], [3, 2]];

/// Whether a static model of `n` coordinates evaluates its reduced equations in the scalar `T` by
/// its fixed-size dual passes rather than by the compiled tape ([`FIXED_PASSES_MAX_N`]).
#[inline(always)]
fn fixed_passes_pay<T: 'static>(n: usize, constant_metric: bool) -> bool {
    let dual = std::any::TypeId::of::<T>() != std::any::TypeId::of::<f64>();
    n <= FIXED_PASSES_MAX_N[usize::from(!constant_metric)][usize::from(dual)]
}

impl<M, const N: usize, const K: usize> Fixed<M, N, K>
where
    M: Lagrangian<N> + Constraints<N, K>,
{
    /// [`evaluate_fixed`](crate::equations::evaluate_fixed) with a plan, called rather than
    /// inlined: for a metric `W` that varies the body is long, and inlined into the integrator's
    /// right-hand side it slows the loop around it.
    #[inline(never)]
    fn evaluate_outlined<T: Real>(
        &self,
        plan: Plan,
        ws: &mut Workspace<T>,
        x: Point<T>,
    ) -> Result<(), SaddleFailure> {
        crate::equations::evaluate_fixed::<M, T, N, K>(&self.0, Some(plan), ws, x)
    }
}

impl<M, const N: usize, const K: usize> Holonomic for Fixed<M, N, K>
where
    M: Constraints<N, K>,
{
    fn h<R: Real>(&self, t: R, q: &[R], h: &mut [R]) {
        self.0.holonomic(t, &SVector::from_column_slice(q), h);
    }
}

impl<M: DynModel> Model for M {
    fn sizes(&self) -> (usize, usize) {
        let (n, k) = DynModel::sizes(self);
        (n, k + DynModel::holonomic_count(self))
    }

    fn holonomic_count(&self) -> usize {
        DynModel::holonomic_count(self)
    }

    fn functions<T: Real>(&self, x: Point<T>, out: &mut Functions<T>) -> bool {
        let (t, q, qd) = (x.t, x.q, x.qd);
        out.l = DynModel::lagrangian(self, t, q, qd);
        DynModel::constraints(self, t, q, qd, &mut out.f);
        DynModel::holonomic(self, t, q, &mut out.h);
        out.has_forces = DynModel::forces(self, t, q, qd, &mut out.forces);
        out.dissipation = DynModel::dissipation(self, t, q, qd);
        true
    }

    fn holonomic_blocks(&self, t: f64, q: &[f64], h: &mut [f64], hq: Option<&mut [f64]>) {
        derivatives::holonomic_blocks(self, t, q, h, hq);
    }

    fn lagrangian_blocks<T: Real>(&self, x: Point<T>, out: &mut LagrangianBlocks<T>) {
        derivatives::scalar::lagrangian_blocks(self, x, out);
    }

    fn velocity_hessian<T: Real>(&self, x: Point<T>, w: &mut [T]) {
        derivatives::scalar::hessian_pass(self, x, w, None);
    }

    fn constraint_blocks<T: Real>(&self, x: Point<T>, with_c: bool, out: &mut ConstraintBlocks<T>) {
        derivatives::scalar::constraint_blocks(self, x, with_c, out);
        derivatives::holonomic_rows(self, DynModel::sizes(self).1, x, with_c, out);
    }

    fn constraint_values(&self, x: Point<f64>, f: &mut [f64]) {
        let k = DynModel::sizes(self).1;
        DynModel::constraints(self, x.t, x.q, x.qd, &mut f[..k]);
        derivatives::holonomic_velocities(self, k, x, f);
    }

    fn force_blocks<T: Real>(&self, x: Point<T>, out: &mut [T]) -> bool {
        derivatives::scalar::forces(self, x, out)
    }
}

impl<M: DynModel> Holonomic for M {
    fn h<R: Real>(&self, t: R, q: &[R], h: &mut [R]) {
        DynModel::holonomic(self, t, q, h);
    }
}
