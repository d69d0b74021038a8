//! The reduced Chetaev equations as a first-order ODE on flat `f64` slices, which is all an
//! integrator sees.
//!
//! State layout: `y = [q (n), q̇ (n)]`, followed, when the energy balance is recorded, by three
//! quadratures `[W_Φ, ∫∂L/∂t dt, W_Q]` with `dW_Φ/dt = q̇·Φ` and `dW_Q/dt = q̇·Q`. The quadratures
//! are outside error control, so recording them never changes the motion.

use num_dual::Dual64;

use crate::equations::compiled::Compiled;
use crate::equations::native::{NativeBuffers, NativeEquations};
use crate::equations::tiers;
use crate::equations::{
    evaluate_with, evaluate_with_unchecked, saddle::SaddleFailure, Dynamics, Need, Workspace,
};
use crate::error::{Error, Singularity};
use crate::model::{Model, Point};
use crate::sensitivity::Variational;
use crate::solution::{row_residual, velocity_terms};
use chetaev_native::Effort;

/// The Jacobian of a right-hand side `F(t, y)` at one point, as [`OdeSystem::jacobian`] writes it.
/// An implicit method makes one for its dimension and keeps it across steps, so every call writes
/// every entry of it, zeros included.
#[derive(Clone, Debug, PartialEq)]
pub struct Jacobian {
    /// `∂F/∂y`, row-major `dim × dim`.
    pub dy: Vec<f64>,
    /// `∂F/∂t`, length `dim`.
    pub dt: Vec<f64>,
}

impl Jacobian {
    /// Zeros for a system of dimension `dim`.
    pub fn new(dim: usize) -> Self {
        Self {
            dy: vec![0.0; dim * dim],
            dt: vec![0.0; dim],
        }
    }
}

/// A first-order system `y' = F(t, y)` on flat slices.
pub trait OdeSystem {
    /// Length of `y`.
    fn dim(&self) -> usize;
    /// The first `controlled_dim()` components are under error control.
    fn controlled_dim(&self) -> usize;
    /// `dy = F(t, y)`.
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), Error>;
    /// The Jacobian `∂F/∂y` and `∂F/∂t` at `(t, y)` into `out`, every entry (`out` holds the
    /// last call's values). Only implicit methods call it.
    fn jacobian(&mut self, t: f64, y: &[f64], out: &mut Jacobian) -> Result<(), Error>;
    /// Records one LU decomposition of an implicit method's iteration matrix.
    fn count_lu(&mut self) {}
    /// A step to `(t, y)` was accepted (its last evaluation of `F` was the step's last stage): a
    /// system may check what it evaluated there. The default accepts.
    fn accepted(&mut self, t: f64, y: &[f64]) -> Result<(), Error> {
        let _ = (t, y);
        Ok(())
    }
    /// A trial step left the model's domain (or the floating-point range) and is retried smaller.
    fn left_domain(&mut self) {}
}

/// Counts of the work done, kept where user code is called so that no method can forget one.
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Stats {
    /// Evaluations of the reduced right-hand side by the integrator.
    pub rhs_evaluations: usize,
    /// Evaluations of the exact Jacobian: as machine code once the right-hand side is, before that
    /// by dual evaluations of the equations, one per group of columns that share no row
    /// ([`Compiled::jacobian_passes`](crate::equations::compiled::Compiled::jacobian_passes)) or
    /// one per column (`2n + 1`).
    pub jacobian_evaluations: usize,
    /// LU decompositions of the implicit methods' iteration matrix.
    pub lu_decompositions: usize,
    /// Evaluations for the recorded diagnostics (`q̈`, `μ`, `Φ`, `f`, `E`) at output points.
    pub output_evaluations: usize,
    /// Accepted steps.
    pub accepted_steps: usize,
    /// Rejected steps.
    pub rejected_steps: usize,
    /// Projections onto the constraints.
    pub projections: usize,
    /// Newton iterations spent in projections (each one derivative evaluation and block solve).
    pub projection_iterations: usize,
    /// Evaluations of event functions.
    pub event_evaluations: usize,
    /// Evaluations by dual numbers in place of the compiled equations, where a comparison in the
    /// model's code went the other way than when it was recorded.
    pub graph_fallbacks: usize,
}

impl Stats {
    /// The step loop's counts (steps) combined with the system's (evaluations, projections) and
    /// the hooks' event evaluations.
    pub(crate) fn merged(self, system: Stats, event_evaluations: usize) -> Stats {
        Stats {
            accepted_steps: self.accepted_steps,
            rejected_steps: self.rejected_steps,
            event_evaluations,
            ..system
        }
    }
}

/// Whether the rates of the energy balance the machine code wrote (`None`: it writes none) are
/// finite; where they are not, the general route evaluates again and reports them.
#[inline(always)]
fn finite_rates(rates: Option<[f64; 3]>) -> bool {
    rates.is_none_or(|r| r.iter().all(|x| x.is_finite()))
}

/// Adds `t` and the state to a failure of the block solve. Constraints are numbered from 1.
#[cold]
pub(crate) fn locate(e: SaddleFailure, t: f64, q: &[f64], qd: &[f64]) -> Error {
    let (q, qd) = (q.to_vec(), qd.to_vec());
    match e {
        SaddleFailure::NonFinite => Error::NonFiniteEvaluation { t, q, qd },
        SaddleFailure::ZeroConstraintRow { row } => Error::DegenerateConstraint {
            t,
            index: row + 1,
            q,
            qd,
        },
        SaddleFailure::Singular { pivot_ratio } => Error::Singular {
            t,
            // 0/0 where every pivot vanished (entries that underflow): as singular as it gets.
            pivot_ratio: if pivot_ratio.is_nan() {
                0.0
            } else {
                pivot_ratio
            },
            q,
            qd,
        },
        SaddleFailure::SizeMismatch {
            what,
            expected,
            got,
        } => Error::InvalidModel {
            what: format!(
                "{what} is {got} where the model calls for {expected}; give q and q̇ one entry per \
                 coordinate, and a workspace made for this model (Workspace::for_model)"
            ),
        },
        SaddleFailure::ForeignWorkspace => Error::InvalidModel {
            what: "the compiled workspace was made for other compiled equations; make it with \
                   CompiledWorkspace::new for these"
                .to_string(),
        },
    }
}

/// Right-hand sides evaluated by the interpreted route between two reports to the compiled
/// equations' count ([`Compiled::native_after`]).
const NATIVE_REPORT: usize = 256;

/// How much a constraint's gradient must have grown, once the motion has met the edge of the
/// model's domain, before the check of [`ReducedOde::check_edge`] looks at its residual: a
/// gradient of steady size is a wall the motion turns at, not the end of a constraint.
pub(crate) const EDGE_GROWTH: f64 = 1e3;

/// The relative residual `|f_a|/(Σ_i |J_ai q̇_i| + |f_a|)` at which the check of
/// [`ReducedOde::check_edge`] takes a constraint as left: at most ½ for a row `J q̇` with no term
/// free of `q̇`, ⅓ for a speed lost altogether under `|q̇|² = v0²`, of the order of the tolerance
/// along a motion that keeps to it.
pub(crate) const EDGE_RESIDUAL: f64 = 0.25;

/// The fraction of their largest size so far below which a constraint's velocity terms
/// `Σ_i |J_ai q̇_i|` are taken as a turning point by the check of [`ReducedOde::check_edge`],
/// which passes there.
pub(crate) const EDGE_TERMS: f64 = 1e-3;

/// What the check of [`ReducedOde::check_edge`] compares with: `|J_a|²` at the start, the largest
/// `Σ_i |J_ai q̇_i|` at the accepted steps so far, and whether a trial step has left the model's
/// domain.
#[derive(Clone, Debug, Default)]
struct Edge {
    start: Vec<f64>,
    terms: Vec<f64>,
    left_domain: bool,
}

/// Whether the right-hand side runs as machine code ([`crate::equations::native`]).
enum NativeState<'a> {
    /// Not yet.
    Pending(Unreported<'a>),
    /// Never, for this system.
    Off,
    /// Yes, with its scratch space.
    On(&'a NativeEquations, NativeBuffers),
}

/// Right-hand sides evaluated by the interpreted route and not yet counted towards the machine
/// code ([`Compiled::native_after`]); reported when dropped too, so that many short solves of one
/// problem reach it as a long one does.
struct Unreported<'a> {
    compiled: &'a Compiled,
    need: Need,
    count: usize,
}

impl Drop for Unreported<'_> {
    fn drop(&mut self) {
        if self.count > 0 {
            self.compiled.count_interpreted(self.count);
        }
    }
}

/// Scratch space for [`ReducedOde`]'s Jacobian by dual numbers.
struct JacobianScratch {
    ws: Workspace<Dual64>,
    /// The seeded `q`, `q̇`.
    q: Vec<Dual64>,
    qd: Vec<Dual64>,
    /// The seeds of one pass along `(q, q̇, t)`.
    seeds: Vec<f64>,
}

/// The reduced Chetaev equations of one model as a first-order system on `y = [q, q̇]` (and, with
/// `energy`, the two quadratures `[W_Φ, ∫∂L/∂t dt]`), with scratch space and counters: what the
/// driver integrates, and what another integrator (a backend) can integrate.
pub struct ReducedOde<'a, M: ?Sized> {
    pub(crate) model: &'a M,
    /// The compiled equations, when the problem has them.
    compiled: Option<&'a Compiled>,
    /// Their right-hand side as machine code, once there is some.
    native: NativeState<'a>,
    /// The last `rhs` took the machine-code route, whose results are in its buffers, not in `ws`.
    native_last: bool,
    /// Scratch for the Jacobian as machine code: `∂F/∂(q, q̇)` and `∂F/∂t` of its rows.
    native_jac: (Vec<f64>, Vec<f64>),
    pub(crate) n: usize,
    pub(crate) ws: Workspace<f64>,
    /// Scratch space for the dual evaluations of the Jacobian, made on first use.
    jac_ws: Option<JacobianScratch>,
    energy: bool,
    /// Whether the energy quadratures include the work of forces not derivable from `L`.
    forces: bool,
    /// The threshold of the singular-point check (0: no check).
    rank_tolerance: f64,
    /// `J` (row-major `k × n`) and `max |W_ij|` at the last checked evaluation, and its time (NaN
    /// before the first).
    previous_j: Vec<f64>,
    previous_w: f64,
    /// The sign of the block matrix's determinant there.
    previous_sign: f64,
    previous_t: f64,
    /// Scratch space for the dependence test of the singular-point check: an orthonormal basis
    /// of the previous gradients (`k × n`) and the current ones in it (`k × k`).
    frame: Vec<f64>,
    /// The time of the last evaluation by `rhs`.
    last_t: f64,
    /// What the check of [`ReducedOde::check_edge`] compares with.
    edge: Edge,
    /// The variational equations, when sensitivities are asked for: `S` follows `(q, q̇)`.
    pub(crate) sens: Option<Variational>,
    /// The start and end of the solve, from which the tiering estimates the right-hand sides
    /// still to come ([`ReducedOde::with_horizon`]).
    horizon: Option<(f64, f64)>,
    /// Where the right-hand side runs as quick machine code: the evaluations already counted
    /// towards the full machine code ([`crate::equations::tiers`]); `None` otherwise.
    quick: Option<usize>,
    /// The work done so far.
    pub stats: Stats,
}

impl<'a, M: Model + ?Sized> ReducedOde<'a, M> {
    /// Stops with [`Error::SingularPoint`] where a constraint's gradient `J_a` passes through zero
    /// between two checked states (the ends of consecutive accepted steps): taken as varying
    /// linearly between them, it has a minimum inside the segment, below `tolerance` times the
    /// larger of its sizes at the two ends and below half the smaller. Found so, a zero is seen
    /// even when no evaluation lands near it (the speed reversing under a constraint on its
    /// magnitude). Also where the size of the kinetic metric, `max |W_ij|`, changes by more than a
    /// factor `1/tolerance` from one checked state to the next (a pole of the model crossed within
    /// a step). `0` turns the check off.
    ///
    /// Both compare a state with the one before it, not with the start: a gradient or metric
    /// that grows or shrinks steadily (`L = e^(γt) L0`, a prescribed speed decaying
    /// exponentially) is regular however far it goes.
    ///
    /// The first state checked is that of the next evaluation (the start of a solve).
    pub fn with_rank_tolerance(mut self, tolerance: f64) -> Self {
        self.rank_tolerance = tolerance;
        self.previous_t = f64::NAN;
        self
    }

    /// The singular-point check of [`ReducedOde::with_rank_tolerance`] on the last evaluation, made
    /// at time `t`, at state `(q, q̇)` (for the error).
    fn check_singular(&mut self, t: f64, q: &[f64], qd: &[f64]) -> Result<(), Error> {
        let tol = self.rank_tolerance;
        if tol <= 0.0 {
            return Ok(());
        }
        let d = self.ws.dynamics();
        let n = self.n;
        let mut culprit = None;
        if !self.previous_t.is_nan() {
            // Per constraint, in one pass over J_a and without square roots unless something is
            // off: the smallest |J_a|² on the segment from the previous J_a (p) to this one (c),
            // which is |p|² − (p·(c − p))²/|c − p|² where the segment's closest point lies inside it.
            for a in 0..d.j.len() / n.max(1) {
                let (p, c) = (
                    &self.previous_j[a * n..(a + 1) * n],
                    &d.j[a * n..(a + 1) * n],
                );
                let (mut pp, mut cc, mut pd, mut dd) = (0.0, 0.0, 0.0, 0.0);
                for (x, y) in p.iter().zip(c) {
                    pp += x * x;
                    cc += y * y;
                    pd += x * (y - x);
                    dd += (y - x) * (y - x);
                }
                // Only a minimum inside the segment is a pass through zero: one at an end is a
                // gradient that shrinks over the step (by a factor e^(−h) for a fading e^(−t) in
                // f, say), however much.
                let s = if dd > 0.0 { -pd / dd } else { 0.0 };
                if !(s > 0.0 && s < 1.0) {
                    continue;
                }
                // Formed as a vector: |p|² − (p·(c − p))²/|c − p|² would cancel.
                let closest = p
                    .iter()
                    .zip(c)
                    .map(|(x, y)| (x + s * (y - x)).powi(2))
                    .sum::<f64>();
                let ends = pp.max(cc);
                // Below both ends, too: a gradient that shrinks a hair and then grows by many
                // orders within the step (coordinates of very different units) has its minimum
                // a hair inside the segment, at the size of its smaller end.
                if closest < tol * tol * ends && closest < 0.25 * pp.min(cc) {
                    let r = (closest / ends).sqrt();
                    culprit = Some((
                        Singularity::Gradient(a + 1),
                        r,
                        self.previous_t + s * (t - self.previous_t),
                    ));
                    break;
                }
            }
            let k = d.j.len() / n.max(1);
            if culprit.is_none() && (2..=n).contains(&k) {
                culprit =
                    dependence(&self.previous_j, &d.j, k, tol, &mut self.frame).map(|(r, s)| {
                        (
                            Singularity::DependentGradients,
                            r,
                            self.previous_t + s * (t - self.previous_t),
                        )
                    });
            }
            culprit = culprit.or_else(|| {
                let ratio = d.w_scale / self.previous_w;
                if self.previous_w > 0.0 && !(tol..=1.0 / tol).contains(&ratio) {
                    Some((Singularity::Metric, ratio, t))
                } else {
                    // The block matrix's determinant changed sign: it passed through a singular
                    // one (W, on the constraints' tangent space, through zero), however little
                    // W changed in size.
                    (d.det_sign * self.previous_sign < 0.0).then_some((
                        Singularity::BlockSystem,
                        ratio,
                        t,
                    ))
                }
            });
        }
        if let Some((cause, ratio, t)) = culprit {
            // What was seen last stays that of the last accepted step: the step across the
            // point may be taken again, shorter.
            return Err(Error::SingularPoint {
                t,
                cause,
                ratio,
                q: q.to_vec(),
                qd: qd.to_vec(),
            });
        }
        // Element by element: `clone_from` calls `memcpy`, which costs more for a few words.
        if self.previous_j.len() == d.j.len() {
            for (dst, &v) in self.previous_j.iter_mut().zip(&d.j) {
                *dst = v;
            }
        } else {
            self.previous_j.clone_from(&d.j);
        }
        self.previous_w = d.w_scale;
        self.previous_sign = d.det_sign;
        self.previous_t = t;
        Ok(())
    }

    /// Where the motion has met the edge of the model's domain (a trial step left it), a
    /// constraint can end there: the curve `y = √(1 − x)` at `x = 1`, whose gradient grows without
    /// bound as its tangent turns across the motion. Steps that stay inside the domain then creep
    /// along its edge, and the velocity leaves the constraint unseen by error control, which the
    /// gradient's growth makes blind. So, from then on, where a constraint's gradient has grown
    /// by more than [`EDGE_GROWTH`] over its size at the start of the run, and the velocity
    /// misses it by at least [`EDGE_RESIDUAL`] of its terms (`|f_a|/(Σ_i |J_ai q̇_i| + |f_a|)`,
    /// at most ½ for a row `J q̇` with no term free of `q̇`), the run ends there with
    /// [`Singularity::Unbounded`], at the start of the step. Unless those terms are below
    /// [`EDGE_TERMS`] of their largest size so far: near a turning point, where the velocity
    /// through the constraint passes zero, the residual of any motion is large against them (a
    /// pendulum against a wall with its circle written as `e^(γt)(x² + y² − 1)`, whose gradient
    /// grows without bound in time).
    #[cold]
    fn check_edge(&mut self, t_start: f64, t: f64, y: &[f64]) -> Result<(), Error> {
        let n = self.n;
        let before = &self.edge.start;
        let grown = self
            .ws
            .dynamics()
            .j
            .chunks(n.max(1))
            .zip(before)
            .any(|(ja, &b)| ja.iter().map(|x| x * x).sum::<f64>() > EDGE_GROWTH * EDGE_GROWTH * b);
        if !grown {
            return Ok(());
        }
        let (q, qd) = y[..2 * n].split_at(n);
        let Edge { start, terms, .. } = std::mem::take(&mut self.edge);
        let d = self.evaluate(t, q, qd)?;
        let worst =
            d.f.iter()
                .zip(d.j.chunks(n.max(1)))
                .zip(start.iter().zip(&terms))
                .enumerate()
                .filter_map(|(a, ((fa, ja), (&b, &largest)))| {
                    let size = ja.iter().map(|x| x * x).sum::<f64>();
                    let now = velocity_terms(ja, qd);
                    let r = row_residual(*fa, now);
                    (size > EDGE_GROWTH * EDGE_GROWTH * b
                        && now >= EDGE_TERMS * largest
                        && r >= EDGE_RESIDUAL)
                        .then_some((a, r))
                })
                .max_by(|x, y| x.1.total_cmp(&y.1));
        self.edge = Edge {
            start,
            terms,
            left_domain: true,
        };
        match worst {
            Some((a, ratio)) => Err(Error::SingularPoint {
                t: t_start,
                cause: Singularity::Unbounded(a + 1),
                ratio,
                q: q.to_vec(),
                qd: qd.to_vec(),
            }),
            None => Ok(()),
        }
    }

    /// Keeps what the singular-point check compares from the first evaluation of a solve, at its
    /// start (every method evaluates there first), so that the first step is checked as every
    /// other one.
    #[cold]
    fn seed_singular_check(&mut self, t: f64) {
        self.previous_t = t;
        if self.rank_tolerance <= 0.0 {
            return;
        }
        if self.native_last {
            if let NativeState::On(native, buf) = &self.native {
                native.fill(buf, self.ws.dynamics_mut());
            }
        }
        let d = self.ws.dynamics();
        self.previous_j.clone_from(&d.j);
        self.previous_w = d.w_scale;
        self.previous_sign = d.det_sign;
        let n = self.n.max(1);
        self.edge.start.clear();
        self.edge.start.extend(
            d.j.chunks(n)
                .map(|ja| ja.iter().map(|x| x * x).sum::<f64>()),
        );
        self.edge.terms.clear();
        self.edge.terms.resize(self.edge.start.len(), 0.0);
        self.edge.left_domain = false;
    }

    /// The reduced equations of `model`; with `energy` the state carries the three quadratures of
    /// the energy balance (`W_Φ`, `∫∂L/∂t dt`, `W_Q`).
    pub fn new(model: &'a M, energy: bool) -> Self {
        Self {
            model,
            compiled: None,
            native: NativeState::Off,
            native_last: false,
            native_jac: (Vec::new(), Vec::new()),
            n: model.sizes().0,
            ws: Workspace::for_model(model),
            jac_ws: None,
            energy,
            forces: true,
            rank_tolerance: 0.0,
            previous_j: Vec::new(),
            previous_w: 0.0,
            previous_sign: 1.0,
            previous_t: f64::NAN,
            frame: Vec::new(),
            last_t: f64::NAN,
            edge: Edge::default(),
            sens: None,
            horizon: None,
            quick: None,
            stats: Stats::default(),
        }
    }

    /// The reduced equations of `problem`'s model, as [`ReducedOde::new`]: with `energy` the state
    /// carries the forces' work `W_Q` too, whatever the model states at its start, since a model
    /// may state forces from some time on only; unless its compiled equations prove that it has
    /// none anywhere ([`Compiled::without_forces`]), where `W_Q` would stay zero.
    ///
    /// [`Compiled::without_forces`]: crate::equations::compiled::Compiled::without_forces
    pub fn for_problem(problem: &'a crate::Problem<M>, energy: bool) -> Self
    where
        M: Sized,
    {
        let model = problem.model();
        let compiled = problem.compiled();
        let need = if energy { Need::Rates } else { Need::Motion };
        let native = match compiled.map(|c| (c, c.native_after(need, 0, 0.0))) {
            Some((compiled, None)) => NativeState::Pending(Unreported {
                compiled,
                need,
                count: 0,
            }),
            Some((_, Some(Some(native)))) => NativeState::On(native, native.buffers()),
            _ => NativeState::Off,
        };
        let quick = match &native {
            NativeState::On(native, _) => (native.effort() == Effort::Quick).then_some(0),
            _ => None,
        };
        Self {
            compiled,
            native,
            quick,
            forces: !compiled.is_some_and(|c| c.without_forces()),
            ..Self::new(model, energy)
        }
    }

    /// The solve runs from `t0` to `t_end` (`None`: it may end earlier, at a terminal event): the
    /// tiering (`equations::tiers`) counts on the right-hand sides still to come,
    /// extrapolated from those so far. Without an end, it counts on those so far only.
    pub fn with_horizon(mut self, t0: f64, t_end: Option<f64>) -> Self {
        self.horizon = t_end.map(|t_end| (t0, t_end));
        self
    }

    /// The evaluations the running solve still expects at `t`, having made `done` (see
    /// [`ReducedOde::with_horizon`]).
    fn expected_remaining(&self, done: usize, t: f64) -> f64 {
        self.horizon.map_or(0.0, |(t0, t_end)| {
            tiers::expected_remaining(done, t0, t_end, t)
        })
    }

    /// At an accepted step, on quick machine code: takes up the full machine code where it is
    /// ready, else starts it where it now pays ([`crate::equations::tiers`]). Both give the same
    /// bits, so the step at which it happens changes nothing.
    #[cold]
    #[inline(never)]
    fn tier_up(&mut self) {
        let (Some(compiled), Some(reported)) = (self.compiled, self.quick) else {
            return;
        };
        let need = self.need();
        if let Some(full) = compiled.full_ready(need) {
            compiled.count_quick(self.stats.rhs_evaluations - reported);
            // The same program, so the same buffers: the last evaluation's outputs stay where
            // the checks read them.
            if let NativeState::On(native, _) = &mut self.native {
                *native = full;
            }
            self.quick = None;
            return;
        }
        let total = compiled.count_quick(self.stats.rhs_evaluations - reported);
        self.quick = Some(self.stats.rhs_evaluations);
        if compiled
            .program_operations(need)
            .is_some_and(|ops| tiers::full_pays(ops, total as f64))
        {
            compiled.request_full(need);
        }
    }

    /// Whether the state carries the quadrature of the forces' work `W_Q` when it carries the
    /// energy balance (by default it does): an integrator whose error norm spans the whole state
    /// may leave it out for a model without forces, where it would stay zero.
    pub fn with_forces_quadrature(mut self, on: bool) -> Self {
        self.forces = on;
        self
    }

    /// Whether the state carries the quadrature of the forces' work `W_Q` (after `W_Φ` and
    /// `∫∂L/∂t dt`).
    pub fn has_forces_quadrature(&self) -> bool {
        self.energy && self.forces
    }

    /// Carries the sensitivities of `sens` after `(q, q̇)`.
    pub(crate) fn with_sensitivities(mut self, sens: Variational) -> Self {
        self.sens = Some(sens);
        self
    }

    /// The length of the sensitivities `S` in the state (0 without).
    pub fn sensitivity_len(&self) -> usize {
        self.sens.as_ref().map_or(0, Variational::len)
    }

    /// Where the energy quadratures start in the state: after `(q, q̇)` and the sensitivities.
    pub fn quadratures(&self) -> usize {
        2 * self.n + self.sensitivity_len()
    }

    /// Whether the state carries the energy quadratures.
    pub fn has_energy(&self) -> bool {
        self.energy
    }

    /// What the right-hand side needs of an evaluation: the rates of the energy balance only when
    /// the state carries its quadratures.
    fn need(&self) -> Need {
        if self.energy {
            Need::Rates
        } else {
            Need::Motion
        }
    }

    /// [`OdeSystem::rhs`] in every case but the common one (machine code, no sensitivities), which
    /// `rhs` takes itself; `native_failed`: the machine code was just run there and its guards did
    /// not all hold.
    #[inline]
    fn rhs_general(
        &mut self,
        t: f64,
        y: &[f64],
        dy: &mut [f64],
        native_failed: bool,
    ) -> Result<(), Error> {
        self.stats.rhs_evaluations += 1;
        let (n, e) = (self.n, self.quadratures());
        let (q, qd) = (&y[..n], &y[n..2 * n]);
        // The right-hand side needs q̈, and the rates of the quadratures (q̇·Φ, ∂L/∂t, q̇·Q) only
        // when they are recorded; never E.
        let need = self.need();
        if let NativeState::Pending(u) = &mut self.native {
            u.count += 1;
            if u.count >= NATIVE_REPORT {
                let evaluations = std::mem::take(&mut u.count);
                let remaining = self.expected_remaining(self.stats.rhs_evaluations, t);
                let NativeState::Pending(u) = &mut self.native else {
                    unreachable!("matched above")
                };
                match u.compiled.native_after(u.need, evaluations, remaining) {
                    Some(Some(native)) => {
                        self.quick = (native.effort() == Effort::Quick)
                            .then_some(self.stats.rhs_evaluations);
                        self.native = NativeState::On(native, native.buffers());
                    }
                    Some(None) => self.native = NativeState::Off,
                    None => {}
                }
            }
        }
        let done = match &mut self.native {
            NativeState::On(native, buf) if !native_failed => native
                .evaluate(buf, t, &y[..2 * n], &mut dy[..2 * n])
                .then(|| native.rates(buf))
                .filter(|&r| finite_rates(r)),
            _ => None,
        };
        if let Some(rates) = done {
            self.native_done(rates, dy);
        } else {
            let x = Point::new(t, q, qd);
            let (d, fell_back) =
                evaluate_with_unchecked(self.model, self.compiled, &mut self.ws, x, need)
                    .map_err(|e| locate(e, t, q, qd))?;
            self.stats.graph_fallbacks += usize::from(fell_back);
            // Element by element: `copy_from_slice` calls `memcpy`, which costs more for a few
            // words.
            let (dq, dqd) = dy[..2 * n].split_at_mut(n);
            for (((dq, dqd), &v), &a) in dq.iter_mut().zip(dqd).zip(qd).zip(&d.qdd) {
                *dq = v;
                *dqd = a;
            }
            if self.energy {
                // The rates may leave their domain where the motion does not (a term of `L` in
                // `t` alone): a step there is rejected as at any non-finite evaluation.
                if !(d.power.is_finite() && d.dl_dt.is_finite() && d.power_forces.is_finite()) {
                    return Err(locate(SaddleFailure::NonFinite, t, q, qd));
                }
                dy[e] = d.power;
                dy[e + 1] = d.dl_dt;
                if self.forces {
                    dy[e + 2] = d.power_forces;
                }
            }
            self.native_last = false;
        }
        self.last_t = t;
        if self.previous_t.is_nan() {
            self.seed_singular_check(t);
        }
        if let Some(sens) = &mut self.sens {
            sens.rhs(
                self.model,
                Point::new(t, q, qd),
                &y[2 * n..e],
                &mut dy[2 * n..e],
            )?;
        }
        Ok(())
    }

    /// The machine code evaluated `dy`'s first `2n` entries; the rates of the energy balance, when
    /// they are compiled in, go after the sensitivities.
    #[inline(always)]
    fn native_done(&mut self, rates: Option<[f64; 3]>, dy: &mut [f64]) {
        if let Some([power, dl_dt, power_forces]) = rates {
            // Entry by entry: a copy of a run of two or three words compiles to a call of
            // `memcpy`, which costs more than the copy.
            let e = self.quadratures();
            dy[e] = power;
            dy[e + 1] = dl_dt;
            if self.forces {
                dy[e + 2] = power_forces;
            }
        }
        self.native_last = true;
    }

    /// The number of coordinates `n`.
    pub fn n(&self) -> usize {
        self.n
    }

    /// The full dynamics at a state, for output (counted as an output evaluation).
    pub fn evaluate(&mut self, t: f64, q: &[f64], qd: &[f64]) -> Result<&Dynamics<f64>, Error> {
        self.stats.output_evaluations += 1;
        let (d, fell_back) =
            evaluate_with(self.model, self.compiled, &mut self.ws, t, q, qd, Need::All)
                .map_err(|e| locate(e, t, q, qd))?;
        self.stats.graph_fallbacks += usize::from(fell_back);
        Ok(d)
    }
}

impl<M: Model + ?Sized> ReducedOde<'_, M> {
    /// The checks of an accepted step to `(t_new, y)`: singular points and the end of a
    /// constraint ([`OdeSystem::accepted`]).
    fn check_accepted(&mut self, t_new: f64, y: &[f64]) -> Result<(), Error> {
        if self.rank_tolerance <= 0.0 || self.last_t.is_nan() {
            return Ok(());
        }
        let n = self.n;
        let t = self.last_t;
        if self.native_last {
            if let NativeState::On(native, buf) = &self.native {
                native.fill(buf, self.ws.dynamics_mut());
            }
        }
        let t_start = self.previous_t;
        self.check_singular(t, &y[..n], &y[n..2 * n])?;
        // The largest velocity terms of each constraint so far, as the check of `check_edge`
        // compares with.
        let qd = &y[n..2 * n];
        for (largest, ja) in self
            .edge
            .terms
            .iter_mut()
            .zip(self.ws.dynamics().j.chunks(n.max(1)))
        {
            *largest = largest.max(velocity_terms(ja, qd));
        }
        if self.edge.left_domain {
            self.check_edge(t_start, t_new, y)?;
        }
        Ok(())
    }
}

impl<M: Model + ?Sized> OdeSystem for ReducedOde<'_, M> {
    fn left_domain(&mut self) {
        self.edge.left_domain = true;
    }

    fn accepted(&mut self, t_new: f64, y: &[f64]) -> Result<(), Error> {
        let checked = self.check_accepted(t_new, y);
        if self.quick.is_some() {
            self.tier_up();
        }
        checked
    }

    fn dim(&self) -> usize {
        self.quadratures()
            + match (self.energy, self.forces) {
                (true, true) => 3,
                (true, false) => 2,
                (false, _) => 0,
            }
    }

    fn controlled_dim(&self) -> usize {
        match &self.sens {
            Some(s) if s.controlled => 2 * self.n + s.len(),
            _ => 2 * self.n,
        }
    }

    #[inline]
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), Error> {
        // The common case here, in a small frame: machine code, no sensitivities. Everything else
        // in `rhs_general`, whose frame is large (about 5 KB with the interpreted route).
        if self.sens.is_none() {
            if let NativeState::On(native, buf) = &mut self.native {
                let n = self.n;
                if native.evaluate(buf, t, &y[..2 * n], &mut dy[..2 * n]) {
                    let rates = native.rates(buf);
                    // Non-finite rates take the general route, which reports them.
                    if finite_rates(rates) {
                        self.stats.rhs_evaluations += 1;
                        self.native_done(rates, dy);
                        self.last_t = t;
                        if self.previous_t.is_nan() {
                            self.seed_singular_check(t);
                        }
                        return Ok(());
                    }
                }
                return self.rhs_general(t, y, dy, true);
            }
        }
        self.rhs_general(t, y, dy, false)
    }

    fn count_lu(&mut self) {
        self.stats.lu_decompositions += 1;
    }

    fn jacobian(&mut self, t: f64, y: &[f64], out: &mut Jacobian) -> Result<(), Error> {
        self.stats.jacobian_evaluations += 1;
        let (jac, dfdt) = (&mut out.dy[..], &mut out.dt[..]);
        let (n, dim, e) = (self.n, self.dim(), self.quadratures());
        if self.sens.is_some() {
            jac.fill(0.0);
            dfdt.fill(0.0);
        }
        let (model, need) = (self.model, self.need());
        // As machine code, once the right-hand side is (and without sensitivities): with full
        // effort at once where the right-hand side is, else when it pays.
        let native_jacobian = match (&self.native, &self.sens, self.compiled) {
            (NativeState::On(native, _), None, Some(c)) => {
                if native.effort() == Effort::Full {
                    c.native_jacobian(need, Effort::Full)
                } else {
                    let remaining = self.expected_remaining(self.stats.jacobian_evaluations, t);
                    let autonomous = c.autonomous();
                    let columns = if autonomous { 2 * n } else { 2 * n + 1 };
                    let passes = c.colouring_groups(need).unwrap_or(columns);
                    c.native_jacobian_after(need, remaining, passes)
                }
            }
            _ => None,
        };
        {
            if let Some(nj) = native_jacobian {
                let rows = nj.rows();
                let (jb, db) = &mut self.native_jac;
                jb.resize(rows * 2 * n, 0.0);
                db.resize(rows, 0.0);
                if nj.evaluate(t, &y[..2 * n], jb, db)
                    && jb.iter().chain(db.iter()).all(|v| v.is_finite())
                {
                    jac.fill(0.0);
                    dfdt.fill(0.0);
                    // Rows q̇, q̈, then the quadratures that are carried (W_Φ, ∫∂L/∂t, W_Q).
                    let carried = if self.energy { dim - 2 * n } else { 0 };
                    for row in 0..2 * n + carried.min(rows - 2 * n) {
                        let (src, dst) = if row < 2 * n {
                            (row, row)
                        } else {
                            (row, e + row - 2 * n)
                        };
                        jac[dst * dim..dst * dim + 2 * n]
                            .copy_from_slice(&jb[src * 2 * n..(src + 1) * 2 * n]);
                        dfdt[dst] = db[src];
                    }
                    return Ok(());
                }
            }
        }
        let JacobianScratch { ws, q, qd, seeds } = self.jac_ws.get_or_insert_with(|| {
            let zero = Dual64::from(0.0);
            JacobianScratch {
                ws: Workspace::for_model(model),
                q: vec![zero; n],
                qd: vec![zero; n],
                seeds: vec![0.0; 2 * n + 1],
            }
        });
        // Forward passes along the directions y_j (j < 2n), then t. The quadratures do not feed
        // back.
        let autonomous = self.compiled.is_some_and(Compiled::autonomous);
        let directions = if autonomous { 2 * n } else { 2 * n + 1 };
        if let Some(colouring) = self
            .compiled
            .and_then(|c| c.colouring_after(need, directions))
        {
            // One pass per group of directions no two of which reach the same row (the recorded
            // structure's pattern), each entry read from the pass of its column's group.
            jac.fill(0.0);
            dfdt.fill(0.0);
            // The rows: q̇, q̈, then the rates of the energy balance that the state carries (at
            // `e`, after the sensitivities).
            let rows = 2 * n
                + match (self.energy, self.forces) {
                    (true, true) => 3,
                    (true, false) => 2,
                    (false, _) => 0,
                };
            for group in &colouring.groups {
                for x in seeds.iter_mut() {
                    *x = 0.0;
                }
                for &j in group {
                    seeds[j] = 1.0;
                }
                for i in 0..n {
                    q[i] = Dual64::new(y[i], seeds[i]);
                    qd[i] = Dual64::new(y[n + i], seeds[n + i]);
                }
                let td = Dual64::new(t, seeds[2 * n]);
                let point = Point::new(td, q, qd);
                let (d, fell_back) = evaluate_with_unchecked(model, self.compiled, ws, point, need)
                    .map_err(|e| locate(e, t, &y[..n], &y[n..2 * n]))?;
                self.stats.graph_fallbacks += usize::from(fell_back);
                let value = |row: usize| match row {
                    row if row < n => qd[row].eps,
                    row if row < 2 * n => d.qdd[row - n].eps,
                    row => [d.power.eps, d.dl_dt.eps, d.power_forces.eps][row - 2 * n],
                };
                for &column in group {
                    for &row in colouring.rows[column].iter().filter(|&&row| row < rows) {
                        let at = if row < 2 * n { row } else { e + row - 2 * n };
                        if column < 2 * n {
                            jac[at * dim + column] = value(row);
                        } else {
                            dfdt[at] = value(row);
                        }
                    }
                }
            }
        } else {
            // One pass per direction, t left out where the compiled equations prove that nothing
            // depends on it.
            if autonomous {
                dfdt[..2 * n].fill(0.0);
                dfdt[e..dim].fill(0.0);
            }
            for dir in 0..directions {
                let seed = |i: usize| if i == dir { 1.0 } else { 0.0 };
                for i in 0..n {
                    q[i] = Dual64::new(y[i], seed(i));
                    qd[i] = Dual64::new(y[n + i], seed(n + i));
                }
                let td = Dual64::new(t, seed(2 * n));
                let point = Point::new(td, q, qd);
                let (d, fell_back) = evaluate_with_unchecked(model, self.compiled, ws, point, need)
                    .map_err(|e| locate(e, t, &y[..n], &y[n..2 * n]))?;
                self.stats.graph_fallbacks += usize::from(fell_back);
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
                    put(e, d.power.eps);
                    put(e + 1, d.dl_dt.eps);
                    if self.forces {
                        put(e + 2, d.power_forces.eps);
                    }
                }
            }
        }
        if self.energy {
            for row in 0..dim {
                for quadrature in e..dim {
                    jac[row * dim + quadrature] = 0.0;
                }
            }
        }
        if let Some(sens) = &mut self.sens {
            sens.jacobian(model, t, y, dim, jac, dfdt)?;
        }
        if jac.iter().chain(dfdt.iter()).any(|v| !v.is_finite()) {
            return Err(locate(SaddleFailure::NonFinite, t, &y[..n], &y[n..2 * n]));
        }
        Ok(())
    }
}

/// The dependence test of the singular-point check, for `2 ≤ k ≤ n` constraints: whether the
/// gradients `J` (row-major `k × n`) became linearly dependent between the previous state (`p`)
/// and this one (`c`), each row staying away from zero (the per-row test sees that case).
///
/// With `Q` an orthonormal basis of the rows of `p` (Gram–Schmidt, `p = L Q`, `det L > 0`), `J`
/// taken as varying linearly over the step is `(1 − s) L + s C̃` in that basis plus `s C⊥`, where
/// `C̃ = c Qᵀ` and `C⊥` is the part of `c` outside the rows of `p`. A regular step keeps the
/// orientation, `det C̃ > 0`; where it reverses, the square part passes through a singular matrix
/// inside the step, and `J` with it but for `s C⊥`. So it is a rank loss when `det C̃ < 0` and
/// every row of `c` lies in the span of `p` but for less than `tol` of its size (each row of `p`
/// and `c` is scaled to unit size first, so that rows of very different sizes are judged alike);
/// for `k = n`, `C⊥ = 0` and it is `det J` changing sign, a zero between the states whatever the
/// path. Returns the largest such part and where on the step (`0 … 1`) the
/// determinant, taken as linear, is zero. Gradients that turn fast but stay independent (by more
/// than a right angle in a step) leave a large `C⊥` and are not flagged.
fn dependence(
    p: &[f64],
    c: &[f64],
    k: usize,
    tol: f64,
    scratch: &mut Vec<f64>,
) -> Option<(f64, f64)> {
    let n = p.len() / k;
    scratch.clear();
    scratch.resize(k * n + k * k, 0.0);
    let (q, m) = scratch.split_at_mut(k * n);
    // The size of a row, `None` for a zero (or NaN) one: then there is nothing to judge.
    let size = |row: &[f64]| {
        let s = row.iter().map(|a| a * a).sum::<f64>().sqrt();
        (s > 0.0).then_some(s)
    };
    // Modified Gram–Schmidt on the rows of p, each first scaled to unit size (which changes no
    // orientation, and keeps a large row from hiding a small one); det L is the product of the
    // norms.
    let mut det_l = 1.0;
    for i in 0..k {
        let row = &p[i * n..(i + 1) * n];
        let unit = size(row)?;
        q[i * n..(i + 1) * n]
            .iter_mut()
            .zip(row)
            .for_each(|(a, b)| *a = b / unit);
        for j in 0..i {
            let (done, row) = q.split_at_mut(i * n);
            let (qj, qi) = (&done[j * n..(j + 1) * n], &mut row[..n]);
            let d: f64 = qi.iter().zip(qj).map(|(a, b)| a * b).sum();
            qi.iter_mut().zip(qj).for_each(|(a, b)| *a -= d * b);
        }
        let norm = size(&q[i * n..(i + 1) * n])?;
        q[i * n..(i + 1) * n].iter_mut().for_each(|a| *a /= norm);
        det_l *= norm;
    }
    // C̃ = ĉ Qᵀ for the rows of c scaled to unit size, and the largest part of one of them that
    // lies outside the rows of p.
    let mut outside = 0.0f64;
    for i in 0..k {
        let ci = &c[i * n..(i + 1) * n];
        let unit = size(ci)?;
        for j in 0..k {
            m[i * k + j] = ci
                .iter()
                .zip(&q[j * n..(j + 1) * n])
                .map(|(a, b)| a * b)
                .sum::<f64>()
                / unit;
        }
        let mut out_i = 0.0;
        for l in 0..n {
            let inside: f64 = (0..k).map(|j| m[i * k + j] * q[j * n + l]).sum();
            out_i += (ci[l] / unit - inside).powi(2);
        }
        outside = outside.max(out_i);
    }
    let det_c = determinant(m, k);
    if det_c.is_nan() || det_c >= 0.0 {
        return None;
    }
    let ratio = if k == n { 0.0 } else { outside.sqrt() };
    (ratio <= tol).then(|| (ratio, det_l / (det_l - det_c)))
}

/// The determinant of the `k × k` row-major matrix `a`, by elimination with partial pivoting
/// (`a` is overwritten).
fn determinant(a: &mut [f64], k: usize) -> f64 {
    let mut det = 1.0;
    for col in 0..k {
        let pivot = (col..k)
            .max_by(|&i, &j| a[i * k + col].abs().total_cmp(&a[j * k + col].abs()))
            .unwrap_or(col);
        if a[pivot * k + col] == 0.0 {
            return 0.0;
        }
        if pivot != col {
            for j in 0..k {
                a.swap(pivot * k + j, col * k + j);
            }
            det = -det;
        }
        let d = a[col * k + col];
        det *= d;
        for i in col + 1..k {
            let factor = a[i * k + col] / d;
            for j in col + 1..k {
                a[i * k + j] -= factor * a[col * k + j];
            }
        }
    }
    det
}
