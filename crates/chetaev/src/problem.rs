//! A model with its initial state, validated.

use std::sync::{Arc, OnceLock};

use nalgebra::SVector;

use crate::equations::compiled::Compiled;
use crate::equations::{evaluate, evaluate_with, Need, Workspace};
use crate::error::Error;
use crate::integrate::projection::{
    constraint_scale, project_positions, project_velocity, Projection,
};
use crate::integrate::system::locate;
use crate::model::{Constraints, DynModel, Fixed, Lagrangian, Model, Point, Unconstrained};

/// Relative tolerance on the initial constraint residual: `|f_a| ≤ tol · |J_a|·|q̇|` with
/// `J_a = ∂f_a/∂q̇` (or `≤ tol` where `|J_a|·|q̇|` vanishes) is accepted as consistent.
pub const INITIAL_RESIDUAL_TOLERANCE: f64 = 1e-10;

/// A model, an initial time and a consistent initial state `(q0, q̇0)`, for a model of either
/// flavour: [`Problem::new`] for static sizes, [`Problem::dynamic`] for run-time sizes. Both give
/// the same `Problem`, solved by the same [`solve`](crate::solve).
#[derive(Clone, Debug)]
pub struct Problem<M> {
    model: M,
    t0: f64,
    q0: Vec<f64>,
    qd0: Vec<f64>,
    route: Route,
    machine_code: MachineCode,
    /// The compiled equations, made on first use (by the first solve).
    compiled: OnceLock<Option<Arc<Compiled>>>,
}

/// When a problem's right-hand side runs as machine code ([`Problem::with_machine_code`]), on
/// [`Route::Graph`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum MachineCode {
    /// When it pays: compiled quickly once the right-hand sides still expected would save more
    /// than compiling costs, and again with full effort (on another thread) once its use repays
    /// that; judged by a cost model from the program's size (`equations::tiers` in the source,
    /// `docs/formulation.md`). Solves repeat themselves to the bit: the decisions depend on
    /// counts and times of the solve, never on the clock. A problem solved again may switch at
    /// another point than before, and its results then differ at the tolerance's level.
    #[default]
    Auto,
    /// Never: the interpreted route always (the recorded tape and a general block solve).
    Never,
    /// From the first right-hand side of the first solve, compiled with full effort before it
    /// starts: every solve of the problem the same to the bit.
    AtOnce,
}

impl MachineCode {
    /// Whether this build of the library can make machine code: the feature `native` (on by
    /// default). Without it [`MachineCode::Auto`] and [`MachineCode::AtOnce`] keep to the
    /// interpreted route, whose results agree with the machine code's to rounding.
    pub const fn available() -> bool {
        chetaev_native::Native::available()
    }
}

/// How a problem's equations are evaluated ([`Problem::with_route`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Route {
    /// By the model's expression graph, recorded and differentiated once, with its structure
    /// (zero and constant blocks, a constant metric factorised once) used at every evaluation;
    /// by dual numbers where the model cannot be recorded. The default.
    #[default]
    Graph,
    /// By dual numbers at every evaluation: the reference the compiled equations are checked
    /// against.
    Dual,
}

impl<M, const N: usize, const K: usize> Problem<Fixed<M, N, K>>
where
    M: Lagrangian<N> + Constraints<N, K>,
{
    /// Builds a problem for a static model after checking that `t0`, `q0`, `q̇0` are finite, that
    /// `q̇0` satisfies the constraints (see [`INITIAL_RESIDUAL_TOLERANCE`]) and that the Chetaev
    /// block system is regular at the start.
    pub fn new(
        model: M,
        t0: f64,
        q0: SVector<f64, N>,
        qd0: SVector<f64, N>,
    ) -> Result<Self, Error> {
        Self::from_model(
            Fixed(model),
            t0,
            q0.as_slice().to_vec(),
            qd0.as_slice().to_vec(),
        )
    }

    /// Builds a problem whose initial state is first made consistent with the constraints, in
    /// two steps ([`Problem::from_model_projected`]):
    ///
    /// 1. the position: with holonomic constraints, `q0` is projected onto `h(t0, ·) = 0`, the
    ///    smallest change of `q0` in the metric `W = ∂²L/∂q̇²`, by Newton iteration (without
    ///    holonomic constraints `q0` is kept as given);
    /// 2. the velocity: `q̇0` is projected onto the velocity constraints `f(t0, q0, ·) = 0` and the
    ///    rates `ḣ(t0, q0, ·) = 0` of the holonomic ones, at the projected position, the smallest
    ///    change of `q̇0` in the same metric.
    ///
    /// Both to a relative residual of `1e-14`, in at most 20 iterations each
    /// ([`Error::InitialProjectionFailed`] otherwise). This is an explicit opt-in; [`Problem::new`]
    /// never changes the state it is given. The corrections applied are `problem.q0() − q0` and
    /// `problem.qd0() − qd0`.
    pub fn with_projected_state(
        model: M,
        t0: f64,
        q0: SVector<f64, N>,
        qd0: SVector<f64, N>,
    ) -> Result<Self, Error> {
        Self::from_model_projected(
            Fixed(model),
            t0,
            q0.as_slice().to_vec(),
            qd0.as_slice().to_vec(),
        )
    }

    /// The same as [`Problem::with_projected_state`], under its older name: it projects the
    /// position onto the holonomic constraints too, not only the velocity.
    pub fn with_projected_velocity(
        model: M,
        t0: f64,
        q0: SVector<f64, N>,
        qd0: SVector<f64, N>,
    ) -> Result<Self, Error> {
        Self::with_projected_state(model, t0, q0, qd0)
    }
}

impl<M: Lagrangian<N>, const N: usize> Problem<Fixed<Unconstrained<M>, N, 0>> {
    /// The motion of `model` without constraints (`K = 0`): plain Euler–Lagrange equations.
    pub fn unconstrained(
        model: M,
        t0: f64,
        q0: SVector<f64, N>,
        qd0: SVector<f64, N>,
    ) -> Result<Self, Error> {
        Self::new(Unconstrained(model), t0, q0, qd0)
    }
}

impl<M: DynModel> Problem<M> {
    /// Builds a problem for a run-time-sized model ([`DynModel`]), validated as [`Problem::new`]
    /// validates a static one, and also checking the sizes: `N ≥ 1`, `K ≤ N`, and `q0`, `q̇0` of
    /// length `N`.
    pub fn dynamic(model: M, t0: f64, q0: Vec<f64>, qd0: Vec<f64>) -> Result<Self, Error> {
        Self::from_model(model, t0, q0, qd0)
    }

    /// [`Problem::dynamic`] with the initial state first made consistent: the position projected
    /// onto the holonomic constraints, then the velocity onto the velocity constraints and `ḣ = 0`
    /// (the explicit opt-in of [`Problem::with_projected_state`], which says how).
    pub fn dynamic_with_projected_state(
        model: M,
        t0: f64,
        q0: Vec<f64>,
        qd0: Vec<f64>,
    ) -> Result<Self, Error> {
        Self::from_model_projected(model, t0, q0, qd0)
    }

    /// The same as [`Problem::dynamic_with_projected_state`], under its older name: it projects
    /// the position onto the holonomic constraints too, not only the velocity.
    pub fn dynamic_with_projected_velocity(
        model: M,
        t0: f64,
        q0: Vec<f64>,
        qd0: Vec<f64>,
    ) -> Result<Self, Error> {
        Self::from_model_projected(model, t0, q0, qd0)
    }
}

impl<M: Model> Problem<M> {
    /// Builds a problem for any [`Model`]; see [`Problem::new`] and [`Problem::dynamic`].
    pub fn from_model(model: M, t0: f64, q0: Vec<f64>, qd0: Vec<f64>) -> Result<Self, Error> {
        check_state(&model, INITIAL, t0, &q0, &qd0)?;
        let problem = Self {
            model,
            t0,
            q0,
            qd0,
            route: Route::Graph,
            machine_code: MachineCode::Auto,
            compiled: OnceLock::new(),
        };
        problem.check_initial_state()?;
        Ok(problem)
    }

    /// The same problem with its equations evaluated by `route` ([`Route::Graph`], the default, or
    /// [`Route::Dual`]).
    pub fn with_route(mut self, route: Route) -> Self {
        self.route = route;
        self
    }

    /// How the equations are evaluated.
    pub fn route(&self) -> Route {
        self.route
    }

    /// The same problem with its right-hand side running as machine code as `machine_code` says
    /// ([`MachineCode::Auto`] by default); nothing changes on [`Route::Dual`].
    pub fn with_machine_code(mut self, machine_code: MachineCode) -> Self {
        self.machine_code = machine_code;
        if let Some(Some(compiled)) = self.compiled.get_mut() {
            Arc::make_mut(compiled).set_machine_code(machine_code);
        }
        self
    }

    /// When the right-hand side runs as machine code.
    pub fn machine_code(&self) -> MachineCode {
        self.machine_code
    }

    /// The compiled equations and the structure found in them, when the model could be recorded
    /// (see [`equations::compiled`](crate::equations::compiled)); `None` on [`Route::Dual`]. They
    /// are made on the first call (the first solve), once per problem: recording and
    /// differentiating a model costs about as much as one short solve of it.
    pub fn compiled(&self) -> Option<&Compiled> {
        if self.route == Route::Dual {
            return None;
        }
        self.compiled
            .get_or_init(|| {
                compile(&self.model, self.t0, &self.q0, &self.qd0).map(|mut c| {
                    c.set_machine_code(self.machine_code);
                    Arc::new(c)
                })
            })
            .as_deref()
    }

    /// [`Problem::from_model`] with the initial state first made consistent: the position
    /// projected onto the holonomic constraints `h(t0, ·) = 0`, then the velocity onto the velocity
    /// constraints and `ḣ = 0` at that position (see [`Problem::with_projected_state`]).
    pub fn from_model_projected(
        model: M,
        t0: f64,
        q0: Vec<f64>,
        mut qd0: Vec<f64>,
    ) -> Result<Self, Error> {
        check_state(&model, INITIAL, t0, &q0, &qd0)?;
        let settings = Projection {
            tol: 1e-14,
            max_iterations: 20,
        };
        let mut ws = Workspace::for_model(&model);
        let mut q0 = q0;
        let initial = |e| match e {
            Error::ProjectionFailed {
                t,
                residual,
                iterations,
            } => Error::InitialProjectionFailed {
                t,
                residual,
                iterations,
            },
            e => e,
        };
        project_positions(&model, &mut ws, t0, &mut q0, &qd0, settings).map_err(initial)?;
        project_velocity(&model, &mut ws, t0, &q0, &mut qd0, settings).map_err(initial)?;
        Self::from_model(model, t0, q0, qd0)
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
    /// `(n, k)`: the number of coordinates `N` and of multipliers `k = K + H`, one per
    /// constraint of either kind: the `K` velocity constraints (of [`Constraints`] or
    /// [`DynModel::sizes`]) and the `H` holonomic ones. `k` is the width of
    /// [`Solution::mu`](crate::Solution::mu); for `K` and `H` apart, see
    /// [`Problem::velocity_constraint_count`] and [`Problem::holonomic_count`].
    pub fn sizes(&self) -> (usize, usize) {
        self.model.sizes()
    }

    /// The number of multipliers `k = K + H` (the `k` of [`Problem::sizes`]).
    pub fn multiplier_count(&self) -> usize {
        self.model.sizes().1
    }

    /// The number `K` of velocity constraints `f(t, q, q̇) = 0`.
    pub fn velocity_constraint_count(&self) -> usize {
        self.model.sizes().1 - self.model.holonomic_count()
    }

    /// The number `H` of holonomic constraints `h(t, q) = 0`.
    pub fn holonomic_count(&self) -> usize {
        self.model.holonomic_count()
    }

    /// The Chetaev equations at a state `(t, q, q̇)`, without a solve: `q̈`, `μ`, `Φ`, the residual
    /// `f`, `L`, `E`, `∂L/∂t`, the power `q̇·Φ` and the block system's pivot ratio (its conditioning:
    /// 1 is perfect, near [`SINGULAR_PIVOT_RATIO`](crate::equations::saddle::SINGULAR_PIVOT_RATIO)
    /// is singular). For checking a new constraint at chosen states before integrating. The state
    /// need not satisfy the constraints (`f` says how far it is off). A failure is the library's
    /// [`Error`] with `t` and the state.
    ///
    /// ```
    /// use chetaev::prelude::*;
    ///
    /// struct Uniform;
    /// impl Lagrangian<2> for Uniform {
    ///     fn lagrangian<R: Real>(&self, _t: R, q: &SVector<R, 2>, qd: &SVector<R, 2>) -> R {
    ///         qd.dot(qd) * 0.5 - q[1] * 10.0
    ///     }
    /// }
    /// impl Constraints<2, 1> for Uniform {
    ///     fn constraints<R: Real>(&self, _t: R, _q: &SVector<R, 2>, qd: &SVector<R, 2>) -> SVector<R, 1> {
    ///         SVector::from([qd.dot(qd) - 100.0])
    ///     }
    /// }
    /// let problem = Problem::new(Uniform, 0.0, SVector::from([0.0, 5.0]), SVector::from([10.0, 0.0]))?;
    /// // Falling at 45°: J = 2q̇ and J q̈ = 0 give μ = g·ẏ / (2|q̇|²) in Newton form, negative (42.40).
    /// let v = 10.0 / 2f64.sqrt();
    /// let eq = problem.equations_at(0.3, &[3.0, 4.0], &[v, -v])?;
    /// assert!((eq.mu[0] - 10.0 * -v / (2.0 * 100.0)).abs() < 1e-12);
    /// assert!(eq.f[0].abs() < 1e-12 && eq.pivot_ratio > 0.1);
    /// # Ok::<(), chetaev::Error>(())
    /// ```
    pub fn equations_at(
        &self,
        t: f64,
        q: &[f64],
        qd: &[f64],
    ) -> Result<crate::equations::Dynamics<f64>, Error> {
        check_state(&self.model, STATE, t, q, qd)?;
        let mut ws = Workspace::for_model(&self.model);
        let (d, _) = evaluate_with(&self.model, self.compiled(), &mut ws, t, q, qd, Need::All)
            .map_err(|e| locate(e, t, q, qd))?;
        Ok(d.clone())
    }

    /// What the library derived for the model, at a state `(t, q, q̇)`: which blocks of the Chetaev
    /// equations vanish or are constant and what each depends on (proved from the model's compiled
    /// expressions, [`equations::compiled`](crate::equations::compiled); probed around the state
    /// where the model cannot be recorded, see
    /// [`equations::structure`](crate::equations::structure)), the sparsity patterns of `W` and
    /// `J`, the derived blocks as expressions (plain text and LaTeX), the numerical blocks, and
    /// `q̈`, `μ`, `Φ` and the block system's conditioning there.
    /// `println!("{}", problem.describe(t, q, qd)?)` prints it as plain text.
    ///
    /// ```
    /// use chetaev::prelude::*;
    ///
    /// struct Uniform;
    /// impl Lagrangian<2> for Uniform {
    ///     fn lagrangian<R: Real>(&self, _t: R, q: &SVector<R, 2>, qd: &SVector<R, 2>) -> R {
    ///         qd.dot(qd) * 0.5 - q[1] * 10.0
    ///     }
    /// }
    /// impl Constraints<2, 1> for Uniform {
    ///     fn constraints<R: Real>(&self, _t: R, _q: &SVector<R, 2>, qd: &SVector<R, 2>) -> SVector<R, 1> {
    ///         SVector::from([qd.dot(qd) - 100.0])
    ///     }
    /// }
    /// let problem = Problem::new(Uniform, 0.0, SVector::from([0.0, 5.0]), SVector::from([10.0, 0.0]))?;
    /// let d = problem.describe(0.0, &[0.0, 5.0], &[10.0, 0.0])?;
    /// assert!(d.structure.w.is_constant() && d.structure.g.zero && d.structure.c.zero);
    /// assert!(d.structure.j.qd && !d.structure.j.q);
    /// assert!(d.to_string().contains("W = ∂²L/∂q̇²"));
    /// # Ok::<(), chetaev::Error>(())
    /// ```
    pub fn describe(
        &self,
        t: f64,
        q: &[f64],
        qd: &[f64],
    ) -> Result<crate::equations::structure::Description, Error> {
        let n = self.model.sizes().0;
        self.describe_named(t, q, qd, &crate::equations::structure::Names::numbered(n))
    }

    /// [`Problem::describe`] with the coordinates and velocities named by `names` in the
    /// expressions, and the parameters the model reads by [`Real::parameter`](crate::model::Real::parameter) kept
    /// as symbols there, by their names (the expressions are recorded once more for this, with
    /// the parameters as inputs; the structure and the numbers are those of the problem).
    ///
    /// ```
    /// use chetaev::equations::structure::Names;
    /// use chetaev::prelude::*;
    ///
    /// struct Fall;
    /// impl Lagrangian<1> for Fall {
    ///     fn lagrangian<R: Real>(&self, _t: R, q: &SVector<R, 1>, qd: &SVector<R, 1>) -> R {
    ///         let (m, g) = (R::parameter("m", 2.0), R::parameter("g", 9.81));
    ///         qd[0] * qd[0] * m * 0.5 - m * g * q[0]
    ///     }
    /// }
    /// let problem = Problem::unconstrained(Fall, 0.0, SVector::from([1.0]), SVector::from([0.0]))?;
    /// let d = problem.describe_named(0.0, &[1.0], &[0.0], &Names::coordinates(&["y"]))?;
    /// let row = |name: &str| d.equations.iter().find(|(k, _)| k == name).map(|(_, e)| e.clone());
    /// assert_eq!(row("L").as_deref(), Some("m·y_dot^2/2 - m·g·y"));
    /// assert_eq!(row("q̈[1]").as_deref(), Some("-g"));
    /// # Ok::<(), chetaev::Error>(())
    /// ```
    ///
    /// # Errors
    ///
    /// As [`Problem::describe`]; and [`Error::InvalidModel`] where `names` does not name `n`
    /// coordinates.
    pub fn describe_named(
        &self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        names: &crate::equations::structure::Names,
    ) -> Result<crate::equations::structure::Description, Error> {
        let dynamics = self.equations_at(t, q, qd)?;
        let (n, k) = self.model.sizes();
        if [&names.q, &names.qd, &names.q_latex, &names.qd_latex]
            .iter()
            .any(|v| v.len() != n)
        {
            return Err(Error::InvalidModel {
                what: format!(
                    "the names of a description name {} coordinates, the model has N = {n}; give \
                     one name per coordinate",
                    names.q.len()
                ),
            });
        }
        let mut lagrangian = crate::equations::derivatives::LagrangianBlocks::new(n);
        let x = Point::new(t, q, qd);
        self.model.lagrangian_blocks(x, &mut lagrangian);
        let mut constraints = crate::equations::derivatives::ConstraintBlocks::new(n, k);
        if k > 0 {
            self.model.constraint_blocks(x, true, &mut constraints);
        }
        let compiled = self.compiled();
        // The expressions with the parameters as symbols; the problem's own where the model
        // reads none or cannot be recorded so.
        let symbolic = compiled.and_then(|_| {
            crate::equations::compiled::Compiled::with_parameters(&self.model, t, q, qd).ok()
        });
        let shown = symbolic.as_ref().or(compiled);
        let (mut equations, text_reduced) =
            shown.map_or((Vec::new(), false), |c| c.describe_rows(names, false));
        let (mut latex, latex_reduced) =
            shown.map_or((Vec::new(), false), |c| c.describe_rows(names, true));
        // μ and q̈ are written out only where both forms print them in full.
        let reduced = text_reduced && latex_reduced;
        for (rows, had) in [(&mut equations, text_reduced), (&mut latex, latex_reduced)] {
            if had && !reduced {
                rows.truncate(rows.len().saturating_sub(n + k));
            }
        }
        let inputs = std::iter::once("t".to_string())
            .chain(names.q.iter().cloned())
            .chain(names.qd.iter().cloned())
            .chain(
                shown
                    .map(|c| {
                        c.parameters()
                            .iter()
                            .map(|(p, _)| p.clone())
                            .collect::<Vec<_>>()
                    })
                    .unwrap_or_default(),
            )
            .collect();
        Ok(crate::equations::structure::Description {
            structure: match compiled {
                Some(c) => c.structure().clone(),
                None => crate::equations::structure::probe(&self.model, t, q, qd),
            },
            proved: compiled.is_some(),
            guards: compiled.map_or(0, |c| c.branches()),
            equations,
            latex,
            reduced,
            inputs,
            jacobian_passes: compiled
                .and_then(|c| c.jacobian_passes())
                .map(|p| (p, 2 * n + 1)),
            state: (t, q.to_vec(), qd.to_vec()),
            lagrangian,
            constraints,
            dynamics,
        })
    }

    /// Evaluates the equations at the initial state, checks that every value is finite and that
    /// the initial position satisfies the holonomic constraints and the initial velocity the
    /// velocity constraints (`ḣ = 0` among them).
    fn check_initial_state(&self) -> Result<(), Error> {
        let (t0, q0, qd0) = (self.t0, &self.q0[..], &self.qd0[..]);
        let holonomic = self.model.holonomic_count();
        if holonomic > 0 {
            let n = q0.len();
            let (mut h, mut hq) = (vec![0.0; holonomic], vec![0.0; holonomic * n]);
            self.model.holonomic_blocks(t0, q0, &mut h, Some(&mut hq));
            // A residual or a gradient that overflows (a position far out of scale) has no
            // tolerance to be measured against.
            if h.iter().chain(&hq).any(|v| !v.is_finite()) {
                return Err(Error::NonFiniteEvaluation {
                    t: t0,
                    q: q0.to_vec(),
                    qd: qd0.to_vec(),
                });
            }
            let q_norm = norm(q0);
            // Next to the coordinates' origin `|∂h/∂q|·|q0|` vanishes while `h` is still the
            // difference of terms of their own size: there its rounding sets the tolerance.
            let rounding = holonomic_rounding(&self.model, t0, q0, qd0);
            for b in 0..holonomic {
                let scale = constraint_scale(norm(&hq[b * n..(b + 1) * n]), q_norm);
                let floor = rounding
                    .as_ref()
                    .map_or(0.0, |r| ROUNDING_ULPS * f64::EPSILON * r[b]);
                let tolerance = (INITIAL_RESIDUAL_TOLERANCE * scale).max(floor);
                if h[b].abs() > tolerance {
                    return Err(Error::InconsistentInitialPosition {
                        t: t0,
                        index: b + 1,
                        residual: h[b],
                        tolerance,
                    });
                }
            }
            if let Some((index, dependent_on)) = redundant_rows(&hq, holonomic, n) {
                return Err(Error::RedundantHolonomic {
                    t: t0,
                    index,
                    dependent_on,
                });
            }
        }
        // Large models are checked through their compiled equations: the dual-number path takes
        // O(n³) there (n(n + 1)/2 passes for W), minutes at a few thousand coordinates.
        let large = q0.len() > DUAL_CHECK_MAX_N;
        let plan = if large { self.compiled() } else { None };
        let mut ws = Workspace::for_model(&self.model);
        let (d, _) = evaluate_with(&self.model, plan, &mut ws, t0, q0, qd0, Need::All)
            .map_err(|e| locate(e, t0, q0, qd0))?;
        if d.f.iter().any(|f| !f.is_finite()) || !d.energy.is_finite() || !d.l.is_finite() {
            return Err(Error::NonFiniteEvaluation {
                t: t0,
                q: q0.to_vec(),
                qd: qd0.to_vec(),
            });
        }
        let (n, k) = self.model.sizes();
        let qd_norm = norm(qd0);
        let mut cb = crate::equations::derivatives::ConstraintBlocks::new(n, k);
        if k > 0 {
            self.model
                .constraint_blocks(Point::new(t0, q0, qd0), false, &mut cb);
        }
        for a in 0..k {
            let scale = constraint_scale(norm(&cb.j[a * n..(a + 1) * n]), qd_norm);
            let tolerance = INITIAL_RESIDUAL_TOLERANCE * scale;
            let residual = cb.f[a];
            if residual.is_nan() || residual.abs() > tolerance {
                return Err(Error::InconsistentInitialState {
                    t: t0,
                    index: a + 1,
                    holonomic: a.checked_sub(k - holonomic).map(|b| b + 1),
                    residual,
                    tolerance,
                });
            }
        }
        Ok(())
    }
}

/// Relative size below which a gradient's part outside the span of others counts as none
/// ([`redundant_rows`]).
const REDUNDANCY_TOLERANCE: f64 = 1e-10;

/// The first row of `rows` (`count × n`, row-major: the holonomic gradients `∂h/∂q`) that is a
/// combination of the rows before it, to [`REDUNDANCY_TOLERANCE`] of its size, with the earlier
/// rows that take part in the combination; all numbered from 1. A zero row is left out (a
/// gradient that vanishes is a degenerate constraint of its own, told as such by the block
/// system's check).
fn redundant_rows(rows: &[f64], count: usize, n: usize) -> Option<(usize, Vec<usize>)> {
    // Orthonormal basis of the rows kept so far, and for each basis vector its expression in
    // those rows (so that a dependent row's combination is known in the rows themselves).
    let mut basis: Vec<Vec<f64>> = Vec::new();
    let mut in_rows: Vec<Vec<f64>> = Vec::new();
    let mut kept: Vec<usize> = Vec::new();
    for b in 0..count {
        let row = &rows[b * n..(b + 1) * n];
        let size = norm(row);
        if size == 0.0 {
            continue;
        }
        let mut r = row.to_vec();
        // The row in terms of the kept rows: row = Σ c_k kept_k + r.
        let mut c = vec![0.0; kept.len()];
        // Twice, for orthogonality to rounding (classical Gram–Schmidt, reorthogonalised).
        for _ in 0..2 {
            for (e, coeffs) in basis.iter().zip(&in_rows) {
                let p: f64 = e.iter().zip(&r).map(|(a, x)| a * x).sum();
                for (ri, ei) in r.iter_mut().zip(e) {
                    *ri -= p * ei;
                }
                for (ck, wk) in c.iter_mut().zip(coeffs) {
                    *ck += p * wk;
                }
            }
        }
        let rest = norm(&r);
        if rest <= REDUNDANCY_TOLERANCE * size {
            let involved = kept
                .iter()
                .zip(&c)
                .filter(|(k, ck)| {
                    ck.abs() * norm(&rows[**k * n..(**k + 1) * n]) > REDUNDANCY_TOLERANCE * size
                })
                .map(|(k, _)| k + 1)
                .collect();
            return Some((b + 1, involved));
        }
        // The new basis vector e = (row − Σ c_k kept_k) / rest, in the kept rows and this one.
        let mut coeffs: Vec<f64> = c.iter().map(|ck| -ck / rest).collect();
        coeffs.push(1.0 / rest);
        for w in &mut in_rows {
            w.push(0.0);
        }
        basis.push(r.iter().map(|x| x / rest).collect());
        in_rows.push(coeffs);
        kept.push(b);
    }
    None
}

/// How many units of roundoff of a holonomic constraint's rounding scale
/// ([`Graph::rounding_scale`](crate::equations::graph::Graph::rounding_scale)) its initial
/// residual may be, where that exceeds the relative tolerance.
pub(crate) const ROUNDING_ULPS: f64 = 16.0;

/// The rounding scale of each holonomic constraint at `(t, q)` (from `h` recorded there), or
/// `None` where the model offers no recording or a value leaves it; a scale that is not finite
/// (an infinite derivative on the way) counts as none.
pub(crate) fn holonomic_rounding<M: Model + ?Sized>(
    model: &M,
    t: f64,
    q: &[f64],
    qd: &[f64],
) -> Option<Vec<f64>> {
    let (n, k) = model.sizes();
    let holonomic = model.holonomic_count();
    let (g, _, (offered, h), _) = crate::sensitivity::record_at(t, q, qd, |ts, qs, qds| {
        let mut out = crate::model::Functions::new(n, k - holonomic, holonomic);
        let offered = model.functions(Point::new(ts, qs, qds), &mut out);
        (
            offered,
            out.h.iter().map(|s| s.node()).collect::<Vec<u32>>(),
        )
    })?;
    offered.then(|| {
        h.iter()
            .map(|&b| {
                Some(g.rounding_scale(b))
                    .filter(|e| e.is_finite())
                    .unwrap_or(0.0)
            })
            .collect()
    })
}

/// Above this many coordinates the initial state is checked through the compiled equations, and
/// the compiled equations are checked against the model's own values rather than against a full
/// dual-number evaluation (which costs `O(n³)`).
pub const DUAL_CHECK_MAX_N: usize = 64;

/// The compiled equations of `model`, if it can be recorded and they agree with the dual-number
/// path at the initial state (to 1e-9 relative in `q̈`, `μ` and `E`).
///
/// Above [`DUAL_CHECK_MAX_N`] coordinates, where one dual-number evaluation costs `O(n³)`, only `L`
/// and the constraint values are compared with the model's own `f64` functions (the tests compare
/// the two routes in full on smaller models).
fn compile<M: Model>(model: &M, t0: f64, q0: &[f64], qd0: &[f64]) -> Option<Compiled> {
    let compiled = Compiled::new(model, t0, q0, qd0)?;
    if q0.len() > DUAL_CHECK_MAX_N {
        let (n, k) = model.sizes();
        let kh = model.holonomic_count();
        let mut own = crate::model::Functions::<f64>::new(n, k - kh, kh);
        model.functions(Point::new(t0, q0, qd0), &mut own);
        let mut ws = Workspace::for_model(model);
        let (fast, _) =
            evaluate_with(model, Some(&compiled), &mut ws, t0, q0, qd0, Need::All).ok()?;
        let same = |a: f64, b: f64| (a - b).abs() <= 1e-12 * a.abs().max(b.abs()).max(1.0);
        let agree = same(own.l, fast.l) && own.f.iter().zip(&fast.f).all(|(&a, &b)| same(a, b));
        return agree.then_some(compiled);
    }
    let mut ws = Workspace::for_model(model);
    let reference = evaluate(model, &mut ws, t0, q0, qd0).ok()?.clone();
    let mut ws = Workspace::for_model(model);
    let (fast, _) = evaluate_with(model, Some(&compiled), &mut ws, t0, q0, qd0, Need::All).ok()?;
    let close = |a: &[f64], b: &[f64]| {
        let scale = a.iter().fold(1.0f64, |m, v| m.max(v.abs()));
        a.iter().zip(b).all(|(x, y)| (x - y).abs() <= 1e-9 * scale)
    };
    let agree = close(&reference.qdd, &fast.qdd)
        && close(&reference.mu, &fast.mu)
        && close(&[reference.energy], &[fast.energy]);
    agree.then_some(compiled)
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// Checks the sizes of a model and its initial state, and that the state is finite.
/// The names of `(t, q, q̇)` in [`check_state`]'s errors: of the initial state, or of a state the
/// equations are asked at.
const INITIAL: [&str; 3] = ["t0", "q0", "q̇0"];
pub(crate) const STATE: [&str; 3] = ["t", "q", "q̇"];

pub(crate) fn check_state<M: Model + ?Sized>(
    model: &M,
    [t_name, q_name, qd_name]: [&'static str; 3],
    t0: f64,
    q0: &[f64],
    qd0: &[f64],
) -> Result<(), Error> {
    let (n, k) = model.sizes();
    if n == 0 {
        return Err(Error::InvalidModel {
            what: "the model has no coordinates (N = 0); give it at least one".to_string(),
        });
    }
    if k > n {
        let holonomic = model.holonomic_count();
        let which = if holonomic > 0 {
            format!(
                "{} velocity and {holonomic} holonomic constraints ({k} in all)",
                k.saturating_sub(holonomic)
            )
        } else {
            format!("{k} velocity constraints")
        };
        return Err(Error::InvalidModel {
            what: format!(
                "the model has {which} on {n} coordinates; at most N = {n} independent \
                 constraints can hold"
            ),
        });
    }
    for (name, v) in [(q_name, q0), (qd_name, qd0)] {
        if v.len() != n {
            return Err(Error::InvalidModel {
                what: format!(
                    "{name} has {} entries, the model has N = {n} coordinates; give one per coordinate",
                    v.len()
                ),
            });
        }
    }
    check_finite(t_name, std::slice::from_ref(&t0))?;
    check_finite(q_name, q0)?;
    check_finite(qd_name, qd0)?;
    Ok(())
}

/// Checks that every number in `values` is finite.
pub(crate) fn check_finite(what: &str, values: &[f64]) -> Result<(), Error> {
    match values.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(i) if values.len() == 1 => Err(Error::NonFiniteInput {
            what: what.to_string(),
            value: values[i],
        }),
        Some(i) => Err(Error::NonFiniteInput {
            what: format!("{what}[{i}]"),
            value: values[i],
        }),
    }
}
