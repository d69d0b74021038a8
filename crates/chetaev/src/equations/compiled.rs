//! The Chetaev equations of a model compiled from its expression graph: the structure found once
//! per problem, and a right-hand side that evaluates only what the structure needs.
//!
//! At construction the model's `L`, `f`, `h`, `Q` and `D` are recorded once at the initial state
//! (the crate's `equations/graph/`), and every block the equations need is derived symbolically:
//!
//! ```text
//! p = ∂L/∂q̇,  W = ∂p/∂q̇,  r = ∂L/∂q − (∂p/∂q) q̇ − ∂p/∂t + Q − ∂D/∂q̇     (n, n × n, n)
//! f = [f_v; ḣ],  J = ∂f/∂q̇,  c = (∂f/∂q) q̇ + ∂f/∂t                     (k, k × n, k)
//! ```
//!
//! with `ḣ = (∂h/∂q) q̇ + ∂h/∂t`, so holonomic rows need nothing of their own. Each block is then
//! known to be zero, constant, or dependent on `t`, `q`, `q̇` (a proof about the expressions, not a
//! sample), and the right-hand side is a tape of only the operations that vary. The block
//! system `W q̈ − Jᵀμ = r`, `J q̈ = −c` is solved by the Schur complement,
//!
//! ```text
//! a = W⁻¹ r,   Y = W⁻¹ Jᵀ (n × k),   S = J Y (k × k),   S μ = −c − J a,   q̈ = a + Y μ
//! ```
//!
//! with `W` factorised by Cholesky once when it is constant (inverted outright when diagonal), and
//! at each evaluation when it varies. Where `W` is not positive definite (a singular or indefinite
//! metric that is regular only on the null space of `J`), the pivoted elimination of [`saddle`]
//! solves the whole block system instead, as the dual-number path does. Where the constraint
//! gradients are nearly dependent (`S`'s pivot ratio below [`saddle::NULL_SPACE_PIVOT_RATIO`]),
//! `a + Y μ` would cancel what a large `μ` carries, and the null-space method of [`saddle`] solves
//! the system instead.
//!
//! A comparison in the model's code is a guard of the tape: when one flips, [`Compiled::evaluate`] reports
//! it and the caller falls back to the dual-number path ([`super::evaluate`]) for that evaluation.
//!
//! [`saddle`]: super::saddle

use std::fmt;
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};

use chetaev_native::Effort;
use std::sync::{Arc, OnceLock};

use super::graph::{
    latex_symbol, record, record_with_parameters, Deps, Fun, Graph, GuardFlip, ParameterConflict,
    Printer, Style, Sym, Tape, DEP_Q, DEP_QD, DEP_T,
};
use super::native::{Colouring, NativeEquations, NativeJacobian, Prepared};
use super::saddle::{self, SaddleFailure, SaddleWorkspace, SINGULAR_PIVOT_RATIO};
use super::structure::{dotted, Dependence, Names, Structure};
use super::tiers;
use super::{Dynamics, Need};
use crate::error::Error;
use crate::model::{Functions, Model, Point, Real};
use crate::problem::MachineCode;

/// How `W` is handled.
#[derive(Clone, Debug)]
pub(crate) enum Metric {
    /// Constant and diagonal: `1/W_ii`.
    Diagonal(Vec<f64>),
    /// Constant and positive definite: its Cholesky factor (row-major lower triangle).
    Factor(Vec<f64>),
    /// Constant but not positive definite: solved by the pivoted elimination, with the entries
    /// kept in `Compiled::w_values`.
    Indefinite,
    /// Varying: its entries on and above the diagonal come from the tape.
    Varying,
}

/// The pattern of the Schur solve `S = J W⁻¹ Jᵀ` for a diagonal `W` and a `J` with zero entries:
/// `Y = J W⁻¹` has the pattern of `J`, and `S_ab` sums over the columns where rows `a` and `b` of
/// `J` both can be nonzero. Each sum runs over its columns in increasing order, as the dense
/// products do, and leaves out only terms whose factor from `J` is an exact zero, so the result
/// is the dense one (but for the sign of a zero).
#[derive(Clone, Debug)]
struct SparseSchur {
    /// Row `a`'s entries are `columns[rows[a]..rows[a + 1]]`.
    rows: Vec<usize>,
    /// The columns of `J`'s entries, by rows, each row's in increasing order.
    columns: Vec<usize>,
    /// `(a, b, start, end)` for each `b ≤ a` whose rows share a column: the shared columns are
    /// `shared[start..end]`. `S_ab` of the other pairs is zero.
    pairs: Vec<(usize, usize, usize, usize)>,
    shared: Vec<usize>,
}

impl SparseSchur {
    /// The pattern for `J`'s entries `(row, column)` in row-major order, `k` rows of `n`; `None`
    /// where `J` is dense (nothing to leave out).
    fn new(entries: &[(usize, usize)], n: usize, k: usize) -> Option<Self> {
        if entries.len() == n * k {
            return None;
        }
        let mut rows = vec![0; k + 1];
        for &(a, _) in entries {
            rows[a + 1] += 1;
        }
        for a in 0..k {
            rows[a + 1] += rows[a];
        }
        let columns: Vec<usize> = entries.iter().map(|&(_, i)| i).collect();
        let row = |a: usize| &columns[rows[a]..rows[a + 1]];
        let (mut pairs, mut shared) = (Vec::new(), Vec::new());
        for a in 0..k {
            for b in 0..=a {
                let start = shared.len();
                shared.extend(row(a).iter().filter(|i| row(b).contains(i)));
                if shared.len() > start {
                    pairs.push((a, b, start, shared.len()));
                }
            }
        }
        Some(Self {
            rows,
            columns,
            pairs,
            shared,
        })
    }

    /// Row `a`'s columns.
    fn row(&self, a: usize) -> &[usize] {
        &self.columns[self.rows[a]..self.rows[a + 1]]
    }
}

/// The node ids of every block, for showing the equations.
#[derive(Clone, Debug)]
struct Blocks {
    l: u32,
    p: Vec<u32>,
    w: Vec<u32>,
    dl_dq: Vec<u32>,
    g: Vec<u32>,
    dl_dt: u32,
    f: Vec<u32>,
    j: Vec<u32>,
    c: Vec<u32>,
    forces: Vec<u32>,
    r: Vec<u32>,
    energy: u32,
    power_forces: u32,
}

/// The compiled equations of one model; see the module docs. Built by
/// [`Problem`](crate::Problem) once per problem.
#[derive(Clone)]
pub struct Compiled {
    n: usize,
    k: usize,
    graph: Graph,
    blocks: Blocks,
    structure: Structure,
    /// The right-hand side: `L`, `f`, `r`, `J` (its nonzero entries), `c`, `W` (when varying), and
    /// the rates of the energy quadratures `∂L/∂t`, `q̇·Q`.
    core: OnceLock<Tape>,
    /// The same and the diagnostics at output points: `E`, `Q`.
    full: OnceLock<Tape>,
    /// The outputs of the two tapes (node ids), from which they are made on first use: a static
    /// model evaluates by its own dual passes and never needs them.
    core_out: Vec<u32>,
    full_out: Vec<u32>,
    j_entries: Vec<(usize, usize)>,
    w_entries: Vec<(usize, usize)>,
    metric: Metric,
    /// Where `W` is diagonal and `J` has zeros, the Schur solve's products over `J`'s nonzero
    /// entries only (`None` otherwise).
    sparse_schur: Option<SparseSchur>,
    /// Pivot ratio of a constant `W`'s factorisation (1 when varying: taken per evaluation).
    w_ratio: f64,
    /// `max |W_ij|` of a constant `W`.
    w_scale: f64,
    /// The entries of a constant `W` (empty where it varies): for the elimination where it is
    /// indefinite, and for the null-space solve.
    w_values: Vec<f64>,
    /// `r` and `∂L/∂q`, where constant.
    r_const: Option<Vec<f64>>,
    dl_dq_const: Option<Vec<f64>>,
    /// Which compilation these are (clones share it): a [`CompiledWorkspace`] carries the id of
    /// the equations it was made for, whose tapes and constants its slots hold.
    id: u64,
    /// The model's parameters that are inputs (after `t`, `q`, `q̇`), with their values: only in
    /// equations compiled for sensitivities ([`Compiled::with_parameters`]).
    parameters: Vec<(String, f64)>,
    /// The program of the right-hand side, without and with the rates of the energy balance,
    /// built on first use: its size decides when it is compiled ([`super::tiers`]).
    program: [OnceLock<Option<Arc<Prepared>>>; 2],
    /// The right-hand side as machine code, the same two ways, as first made: quickly when the
    /// tiering decides, with full effort by [`Compiled::native_operations`].
    native: [OnceLock<Option<Arc<NativeEquations>>>; 2],
    /// The same compiled with full effort on another thread, where the first was quick
    /// ([`Compiled::request_full`]).
    native_full: [Arc<OnceLock<Option<Arc<NativeEquations>>>>; 2],
    /// Whether that thread was started, the same two ways.
    full_requested: [Arc<AtomicBool>; 2],
    /// Right-hand sides evaluated by quick machine code, as reported.
    quick: Arc<AtomicUsize>,
    /// Jacobians evaluated by dual numbers while the right-hand side ran as quick machine code.
    jacobians: Arc<AtomicUsize>,
    /// When the right-hand side runs as machine code.
    machine_code: MachineCode,
    /// The Jacobian of the right-hand side as machine code, the same two ways.
    native_jacobian: [OnceLock<Option<Arc<NativeJacobian>>>; 2],
    /// The groups of the Jacobian's columns for compressed forward passes, the same two ways.
    colouring: [OnceLock<Option<Arc<Colouring>>>; 2],
    /// Forward passes the Jacobian took by dual numbers before its colouring was made
    /// ([`Compiled::colouring_after`]).
    dense_passes: Arc<AtomicUsize>,
    /// Right-hand sides evaluated by the interpreted route, as reported ([`Compiled::native_after`]).
    interpreted: Arc<AtomicUsize>,
}

/// Forward passes by dual numbers (one per column of the Jacobian) a problem's Jacobian takes
/// before the columns are grouped for compressed passes ([`Compiled::jacobian_passes`]): making one
/// set of groups costs about as much as 50 passes for the paper's particle (2.3–2.5 µs;
/// `examples/jacobian_passes` in `chetaev-bench`), so a problem solved briefly never pays for them,
/// and one with many columns makes them within its first Jacobians.
pub const COLOUR_AFTER: usize = 256;

/// What [`NativeEquations::new`] reads of compiled equations.
pub(crate) struct NativeParts<'a> {
    pub(crate) n: usize,
    pub(crate) k: usize,
    pub(crate) graph: &'a Graph,
    /// The core tape's outputs (node ids): `r`, `J` entries, `c`, `W` entries, `∂L/∂t`, `q̇·Q`.
    pub(crate) outputs: &'a [u32],
    pub(crate) j_entries: &'a [(usize, usize)],
    pub(crate) w_entries: &'a [(usize, usize)],
    pub(crate) metric: &'a Metric,
    pub(crate) w_scale: f64,
    /// No parameters are inputs.
    pub(crate) parameter_free: bool,
}

impl fmt::Debug for Compiled {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Compiled")
            .field("sizes", &(self.n, self.k))
            .field("structure", &self.structure)
            .field("operations", &self.operations())
            .field("runs", &self.runs())
            .field("guards", &self.graph.guards().len())
            .finish()
    }
}

/// Why a compiled evaluation did not give the equations.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CompiledFailure {
    /// The block system failed, as the dual-number path would.
    Saddle(SaddleFailure),
    /// A branch of the model's code goes the other way here: evaluate by dual numbers instead.
    Guard(GuardFlip),
}

impl From<SaddleFailure> for CompiledFailure {
    fn from(e: SaddleFailure) -> Self {
        Self::Saddle(e)
    }
}

/// Scratch space of a compiled evaluation for one scalar type.
#[derive(Clone, Debug)]
pub struct CompiledWorkspace<T> {
    core: Vec<T>,
    full: Vec<T>,
    /// `W` (row-major `n × n`), then its factor.
    w: Vec<T>,
    wf: Vec<T>,
    /// `J` dense (row-major `k × n`), `Y` (`k × n`: row `a` is `W⁻¹ J_aᵀ`), `a = W⁻¹ r`, `S`.
    j: Vec<T>,
    y: Vec<T>,
    a: Vec<T>,
    s: Vec<T>,
    r: Vec<T>,
    c: Vec<T>,
    mu: Vec<T>,
    /// The values of the parameters that are inputs (set by the caller to seed them).
    pub(crate) params: Vec<T>,
    /// The id of the [`Compiled`] this was made for.
    owner: u64,
    saddle: SaddleWorkspace<T>,
    /// The sign of the block matrix's determinant at the last solve: `+1` through the Cholesky
    /// factors, the pivoted elimination's otherwise.
    det_sign: f64,
}

impl<T: Real> CompiledWorkspace<T> {
    /// Scratch space for `compiled`.
    pub fn new(compiled: &Compiled) -> Self {
        let (n, k) = (compiled.n, compiled.k);
        let varying = matches!(compiled.metric, Metric::Varying);
        Self {
            core: compiled.core().slots(),
            full: compiled.full().slots(),
            w: vec![T::zero(); if varying { n * n } else { 0 }],
            wf: vec![T::zero(); if varying { n * n } else { 0 }],
            j: vec![T::zero(); k * n],
            y: vec![T::zero(); k * n],
            a: vec![T::zero(); n],
            s: vec![T::zero(); k * k],
            r: vec![T::zero(); n],
            c: vec![T::zero(); k],
            mu: vec![T::zero(); k],
            params: compiled.parameters.iter().map(|p| T::from(p.1)).collect(),
            owner: compiled.id,
            saddle: SaddleWorkspace::default(),
            det_sign: 1.0,
        }
    }
}

fn dependence(graph: &Graph, ids: &[u32]) -> Dependence {
    let deps: Deps = ids.iter().fold(0, |d, &id| d | graph.deps(id));
    Dependence {
        t: deps & DEP_T != 0,
        q: deps & DEP_Q != 0,
        qd: deps & DEP_QD != 0,
        zero: ids.iter().all(|&id| graph.is_zero(id)),
    }
}

impl Compiled {
    /// Records `model` at `(t, q, q̇)` and derives its equations; `None` where the model does not
    /// offer its functions ([`Model::functions`]) or its recording cannot be trusted (a value
    /// taken out of the graph), and where `q` or `q̇` is not of the model's length `n`.
    pub fn new<M: Model + ?Sized>(model: &M, t: f64, q: &[f64], qd: &[f64]) -> Option<Self> {
        let n = model.sizes().0;
        if q.len() != n || qd.len() != n {
            return None;
        }
        Self::build(model, t, q, qd, false).ok()
    }

    /// As [`Compiled::new`], with every parameter the model reads by
    /// [`Real::parameter`] an input after `t`, `q`, `q̇` rather than a constant: the equations
    /// whose derivatives with respect to parameters give sensitivities. Blocks that depend on a
    /// parameter are not constant here.
    ///
    /// Fails where the model cannot be recorded (as [`Compiled::new`]) or reads one parameter
    /// name with two values, with an [`Error::Sensitivity`] that says so, and where `q` or `q̇` is
    /// not of the model's length, with [`Error::InvalidModel`].
    pub fn with_parameters<M: Model + ?Sized>(
        model: &M,
        t: f64,
        q: &[f64],
        qd: &[f64],
    ) -> Result<Self, Error> {
        let n = model.sizes().0;
        if let Some((name, v)) = [("q", q), ("q̇", qd)]
            .into_iter()
            .find(|(_, v)| v.len() != n)
        {
            return Err(Error::InvalidModel {
                what: format!(
                    "{name} has {} entries, the model has N = {n} coordinates; give one per \
                     coordinate",
                    v.len()
                ),
            });
        }
        Self::build(model, t, q, qd, true).map_err(|conflict| Error::Sensitivity {
            what: match conflict {
                Some(c) => format!(
                    "parameter {:?} is read with two values, {} and {}; read each value under a \
                     name of its own",
                    c.name, c.first, c.second
                ),
                None => "the model's equations cannot be recorded (it takes a value out of its \
                         scalar with re(), or does not offer its functions), and sensitivities \
                         are derivatives of them; write the model without re()"
                    .to_string(),
            },
        })
    }

    /// The parameters that are inputs, in input order, with their recorded values.
    pub fn parameters(&self) -> &[(String, f64)] {
        &self.parameters
    }

    /// The compiled equations, or why not: `Some` conflict of a parameter's values, or `None` for
    /// a model that does not offer its functions or whose recording cannot be trusted.
    fn build<M: Model + ?Sized>(
        model: &M,
        t: f64,
        q: &[f64],
        qd: &[f64],
        parametric: bool,
    ) -> Result<Self, Option<ParameterConflict>> {
        let (n, k) = model.sizes();
        let holonomic = model.holonomic_count();
        let kv = k - holonomic;
        let run = || {
            let ts = Sym::input(DEP_T, t);
            let qs: Vec<Sym> = q.iter().map(|&v| Sym::input(DEP_Q, v)).collect();
            let qds: Vec<Sym> = qd.iter().map(|&v| Sym::input(DEP_QD, v)).collect();
            let mut out = Functions::<Sym>::new(n, kv, holonomic);
            let offered = model.functions(Point::new(ts, &qs, &qds), &mut out);
            offered.then(|| {
                let nodes = |v: &[Sym]| v.iter().map(|s| s.node()).collect::<Vec<u32>>();
                (
                    ts.node(),
                    nodes(&qs),
                    nodes(&qds),
                    out.l.node(),
                    nodes(&out.f),
                    nodes(&out.h),
                    out.has_forces.then(|| nodes(&out.forces)),
                    out.dissipation.map(|d| d.node()),
                )
            })
        };
        let (mut g, recorded, parameters) = if parametric {
            record_with_parameters(run).map_err(Some)?
        } else {
            let (g, recorded) = record(run);
            (g, recorded, Vec::new())
        };
        let (tn, qn, qdn, l, fv, h, forces, dissipation) = recorded.ok_or(None)?;
        // Parameters are read after t, q, q̇ are made: their inputs follow, in the order read.
        if parameters
            .iter()
            .enumerate()
            .any(|(i, p)| p.2 as usize != 1 + 2 * n + i)
        {
            return Err(None);
        }
        let parameters = parameters.into_iter().map(|(n, v, ..)| (n, v)).collect();
        if g.escaped() {
            return Err(None);
        }
        let one = g.constant_node(1.0);
        let zero = g.constant_node(0.0);
        // Moving along (δq, δt) = (q̇, 1) with q̇ held: the total time derivative without q̈.
        let along: Vec<(u32, u32)> = qn
            .iter()
            .zip(&qdn)
            .map(|(&qi, &vi)| (qi, vi))
            .chain([(tn, one)])
            .collect();

        let p = g.gradient(l, &qdn, DEP_QD);
        let mut w = Vec::with_capacity(n * n);
        for &pi in &p {
            w.extend(g.gradient(pi, &qdn, DEP_QD));
        }
        let dl_dq = g.gradient(l, &qn, DEP_Q);
        let dl_dt = g.gradient(l, &[tn], DEP_T)[0];
        let gv = g.directional(&p, &along, DEP_Q | DEP_T);
        let hdot = g.directional(&h, &along, DEP_Q | DEP_T);
        let f: Vec<u32> = fv.iter().copied().chain(hdot).collect();
        let mut j = Vec::with_capacity(k * n);
        for &fa in &f {
            j.extend(g.gradient(fa, &qdn, DEP_QD));
        }
        let c = g.directional(&f, &along, DEP_Q | DEP_T);
        let mut qf = forces.unwrap_or_else(|| vec![zero; n]);
        if let Some(d) = dissipation {
            for (qi, dd) in qf.iter_mut().zip(g.gradient(d, &qdn, DEP_QD)) {
                *qi = g.sub(*qi, dd);
            }
        }
        let r: Vec<u32> = (0..n)
            .map(|i| {
                let x = g.sub(dl_dq[i], gv[i]);
                g.add(x, qf[i])
            })
            .collect();
        let mut energy = g.neg(l);
        let mut power_forces = zero;
        for i in 0..n {
            let e = g.mul(qdn[i], p[i]);
            energy = g.add(energy, e);
            let pf = g.mul(qdn[i], qf[i]);
            power_forces = g.add(power_forces, pf);
        }

        let structure = Structure {
            sizes: (n, k),
            holonomic,
            w: dependence(&g, &w),
            dl_dq: dependence(&g, &dl_dq),
            g: dependence(&g, &gv),
            dl_dt: dependence(&g, &[dl_dt]),
            j: dependence(&g, &j),
            c: dependence(&g, &c),
            forces: dependence(&g, &qf),
            w_pattern: w.iter().map(|&id| !g.is_zero(id)).collect(),
            j_pattern: j.iter().map(|&id| !g.is_zero(id)).collect(),
        };

        let j_entries: Vec<(usize, usize)> = (0..k * n)
            .filter(|&e| structure.j_pattern[e])
            .map(|e| (e / n, e % n))
            .collect();
        let w_constant = w.iter().all(|&id| g.constant(id).is_some());
        let w_values: Vec<f64> = w.iter().map(|&id| g.constant(id).unwrap_or(0.0)).collect();
        let w_scale = w_values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let (metric, w_ratio) = if w_constant {
            constant_metric(&w_values, n)
        } else {
            (Metric::Varying, 1.0)
        };
        let sparse_schur = match metric {
            Metric::Diagonal(_) if k > 1 => SparseSchur::new(&j_entries, n, k),
            _ => None,
        };
        let w_entries: Vec<(usize, usize)> = if matches!(metric, Metric::Varying) {
            (0..n)
                .flat_map(|i| (i..n).map(move |m| (i, m)))
                .filter(|&(i, m)| structure.w_pattern[i * n + m])
                .collect()
        } else {
            Vec::new()
        };

        let mut core_out = r.clone();
        core_out.extend(j_entries.iter().map(|&(a, i)| j[a * n + i]));
        core_out.extend(&c);
        core_out.extend(w_entries.iter().map(|&(i, m)| w[i * n + m]));
        core_out.extend([dl_dt, power_forces]);
        let mut full_out = core_out.clone();
        full_out.extend(&f);
        full_out.extend([l, energy]);
        full_out.extend(&qf);
        let constants = |ids: &[u32]| {
            ids.iter()
                .map(|&id| g.constant(id))
                .collect::<Option<Vec<f64>>>()
        };
        let r_const = constants(&r);
        let dl_dq_const = constants(&dl_dq);
        Ok(Self {
            n,
            k,
            graph: g,
            blocks: Blocks {
                l,
                p,
                w,
                dl_dq,
                g: gv,
                dl_dt,
                f,
                j,
                c,
                forces: qf,
                r,
                energy,
                power_forces,
            },
            structure,
            core: OnceLock::new(),
            full: OnceLock::new(),
            core_out,
            full_out,
            j_entries,
            w_entries,
            metric,
            sparse_schur,
            w_ratio,
            w_scale,
            w_values: if w_constant { w_values } else { Vec::new() },
            r_const,
            dl_dq_const,
            parameters,
            program: Default::default(),
            native: Default::default(),
            native_full: Default::default(),
            full_requested: Default::default(),
            quick: Arc::default(),
            jacobians: Arc::default(),
            machine_code: MachineCode::Auto,
            native_jacobian: Default::default(),
            colouring: Default::default(),
            dense_passes: Arc::default(),
            interpreted: Arc::default(),
            id: {
                static NEXT: AtomicU64 = AtomicU64::new(0);
                NEXT.fetch_add(1, Ordering::Relaxed)
            },
        })
    }

    /// `W` when it is constant and factorised once, with its pivot ratio and `max |W_ij|`.
    pub(crate) fn constant_factor(&self) -> Option<(&Metric, f64, f64)> {
        matches!(self.metric, Metric::Diagonal(_) | Metric::Factor(_)).then_some((
            &self.metric,
            self.w_ratio,
            self.w_scale,
        ))
    }

    /// The entries of a constant `W`, row-major (empty where it varies).
    pub(crate) fn constant_w(&self) -> &[f64] {
        &self.w_values
    }

    /// `r = ∂L/∂q − g + Q` where it is constant.
    pub(crate) fn r_constant(&self) -> Option<&[f64]> {
        self.r_const.as_deref()
    }

    /// `∂L/∂q` where it is constant.
    pub(crate) fn dl_dq_constant(&self) -> Option<&[f64]> {
        self.dl_dq_const.as_deref()
    }

    /// The parts of these equations [`NativeEquations::new`] builds its program from.
    pub(crate) fn native_parts(&self) -> NativeParts<'_> {
        NativeParts {
            n: self.n,
            k: self.k,
            graph: &self.graph,
            outputs: &self.core_out,
            j_entries: &self.j_entries,
            w_entries: &self.w_entries,
            metric: &self.metric,
            w_scale: self.w_scale,
            parameter_free: self.parameters.is_empty(),
        }
    }

    /// The program of the integrator's right-hand side for `need` ([`Need::Motion`] or
    /// [`Need::Rates`]), built on the first call; `None` for [`Need::All`] and where there is
    /// none (see [`Prepared::new`]).
    fn prepared(&self, need: Need) -> Option<&Arc<Prepared>> {
        let rates = native_rates(need)?;
        self.program[usize::from(rates)]
            .get_or_init(|| Prepared::new(self, rates).map(Arc::new))
            .as_ref()
    }

    /// The integrator's right-hand side as machine code for `need`, as fast as it is so far: with
    /// full effort where that is made, else as first made (compiled here with `effort` if it was
    /// not yet); `None` for [`Need::All`] and where there is none.
    pub(crate) fn native(&self, need: Need, effort: Effort) -> Option<&NativeEquations> {
        let rates = native_rates(need)?;
        if let Some(Some(full)) = self.native_full[usize::from(rates)].get() {
            return Some(full);
        }
        self.native[usize::from(rates)]
            .get_or_init(|| {
                self.prepared(need)
                    .and_then(|p| p.compile(effort))
                    .map(Arc::new)
            })
            .as_deref()
    }

    /// The right-hand side as machine code with full effort for `need` where it is made already
    /// (by [`Compiled::request_full`] or [`Compiled::native_operations`]).
    pub(crate) fn full_ready(&self, need: Need) -> Option<&NativeEquations> {
        let rates = native_rates(need)?;
        if let Some(Some(first)) = self.native[usize::from(rates)].get() {
            if first.effort() == Effort::Full {
                return Some(first);
            }
        }
        self.native_full[usize::from(rates)].get()?.as_deref()
    }

    /// Starts compiling the right-hand side for `need` with full effort on another thread, once
    /// ([`super::tiers`]); the result appears in [`Compiled::full_ready`]. Nothing where it was
    /// started before, where there is no program, or where no thread can be started.
    pub(crate) fn request_full(&self, need: Need) {
        let Some(rates) = native_rates(need) else {
            return;
        };
        let r = usize::from(rates);
        if self.full_requested[r].swap(true, Ordering::Relaxed) {
            return;
        }
        let Some(program) = self.prepared(need).cloned() else {
            return;
        };
        let slot = Arc::clone(&self.native_full[r]);
        // A thread that cannot start leaves the quick machine code in use.
        let _ = std::thread::Builder::new()
            .name("chetaev-compile".to_owned())
            .spawn(move || {
                slot.get_or_init(|| program.compile(Effort::Full).map(Arc::new));
            });
    }

    /// The number of operations of the right-hand side's program for `need`, built if it was
    /// not yet; `None` where there is none.
    pub(crate) fn program_operations(&self, need: Need) -> Option<usize> {
        self.prepared(need).map(|p| p.operations())
    }

    /// The Jacobian of the integrator's right-hand side as machine code for `need`, made on the
    /// first call with `effort`; `None` for [`Need::All`] and where there is none. The integrator
    /// asks for it only once its right-hand side runs as machine code ([`Compiled::native_after`]).
    pub(crate) fn native_jacobian(&self, need: Need, effort: Effort) -> Option<&NativeJacobian> {
        let rates = native_rates(need)?;
        self.native_jacobian[usize::from(rates)]
            .get_or_init(|| NativeJacobian::new(self, rates, effort).map(Arc::new))
            .as_deref()
    }

    /// One more Jacobian evaluated by dual numbers for `need`, with `remaining` more expected by
    /// the running solve and `passes` forward passes each: the Jacobian as quick machine code once
    /// the tiering ([`super::tiers`]) finds that it pays, or where it was made already; `None`
    /// before.
    pub(crate) fn native_jacobian_after(
        &self,
        need: Need,
        remaining: f64,
        passes: usize,
    ) -> Option<&NativeJacobian> {
        let rates = native_rates(need)?;
        if let Some(made) = self.native_jacobian[usize::from(rates)].get() {
            return made.as_deref();
        }
        let total = self.jacobians.fetch_add(1, Ordering::Relaxed) + 1;
        let expected = tiers::expected(total, remaining);
        let operations = self.program_operations(need)?;
        tiers::jacobian_pays(operations, passes, expected)
            .then(|| self.native_jacobian(need, Effort::Quick))
            .flatten()
    }

    /// [`Compiled::colouring`] once the Jacobian has taken [`COLOUR_AFTER`] forward passes by
    /// dual numbers without it, counting `passes` more (one per column) where it is not made yet:
    /// a problem whose solves evaluate few Jacobians does not pay for it.
    pub(crate) fn colouring_after(&self, need: Need, passes: usize) -> Option<&Colouring> {
        let rates = native_rates(need)?;
        if let Some(made) = self.colouring[usize::from(rates)].get() {
            return made.as_deref();
        }
        let before = self.dense_passes.fetch_add(passes, Ordering::Relaxed);
        if before + passes < COLOUR_AFTER {
            return None;
        }
        self.colouring(need)
    }

    /// The columns of the Jacobian of the integrator's right-hand side for `need`, grouped for
    /// compressed forward passes ([`Colouring`]), made on the first call; `None` for [`Need::All`]
    /// and where there is none.
    pub(crate) fn colouring(&self, need: Need) -> Option<&Colouring> {
        let rates = native_rates(need)?;
        self.colouring[usize::from(rates)]
            .get_or_init(|| Colouring::new(self, rates).map(Arc::new))
            .as_deref()
    }

    /// The number of groups of the colouring for `need` where it is made already.
    pub(crate) fn colouring_groups(&self, need: Need) -> Option<usize> {
        let rates = native_rates(need)?;
        Some(
            self.colouring[usize::from(rates)]
                .get()?
                .as_ref()?
                .groups
                .len(),
        )
    }

    /// The forward passes the Jacobian of the integrator's right-hand side takes by dual numbers
    /// (before it runs as machine code): one per group of columns that share no row of the
    /// Jacobian's pattern, found from the recorded structure, instead of one per column
    /// (`2n + 1`, or `2n` without time). The groups are made at once (with and without the rows
    /// of the energy balance), so that solves use them from their first Jacobian rather than after
    /// [`COLOUR_AFTER`] passes. `None` where the passes are not compressed: equations whose
    /// recording has branches, whose metric is constant but not positive definite, or too large to
    /// find their pattern cheaply (more than 2²⁰ operations × 64 columns).
    pub fn jacobian_passes(&self) -> Option<usize> {
        self.colouring(Need::Rates);
        self.colouring(Need::Motion).map(|c| c.groups.len())
    }

    /// `evaluations` more right-hand sides evaluated by the interpreted route for `need`, with
    /// `remaining` more expected by the running solve: the machine code once the tiering
    /// ([`super::tiers`]) finds that quick machine code pays (or where it was made already),
    /// `Some(None)` where there will be none, and `None` to keep counting.
    pub(crate) fn native_after(
        &self,
        need: Need,
        evaluations: usize,
        remaining: f64,
    ) -> Option<Option<&NativeEquations>> {
        let Some(rates) = native_rates(need) else {
            return Some(None);
        };
        match self.machine_code {
            MachineCode::Never => return Some(None),
            MachineCode::AtOnce => return Some(self.native(need, Effort::Full)),
            MachineCode::Auto => {}
        }
        if let Some(made) = self.native[usize::from(rates)].get() {
            return Some(made.as_ref().and(self.native(need, Effort::Quick)));
        }
        let total = self.count_interpreted(evaluations);
        let expected = tiers::expected(total, remaining);
        if !tiers::quick_may_pay(expected) {
            return None;
        }
        let Some(operations) = self.program_operations(need) else {
            return Some(None);
        };
        tiers::quick_pays(operations, expected).then(|| self.native(need, Effort::Quick))
    }

    /// When the right-hand side runs as machine code ([`Problem::with_machine_code`]).
    ///
    /// [`Problem::with_machine_code`]: crate::Problem::with_machine_code
    pub(crate) fn set_machine_code(&mut self, machine_code: MachineCode) {
        self.machine_code = machine_code;
    }

    /// Adds `evaluations` right-hand sides by the interpreted route (with or without the rates) to
    /// the count of [`Compiled::native_after`], and returns the new count.
    pub(crate) fn count_interpreted(&self, evaluations: usize) -> usize {
        self.interpreted.fetch_add(evaluations, Ordering::Relaxed) + evaluations
    }

    /// Adds `evaluations` right-hand sides by quick machine code to their count, and returns the
    /// new count.
    pub(crate) fn count_quick(&self, evaluations: usize) -> usize {
        self.quick.fetch_add(evaluations, Ordering::Relaxed) + evaluations
    }

    /// The number of operations of the right-hand side compiled to machine code (the motion, without
    /// the energy balance), compiling it with full effort (with and without the energy balance) if
    /// it was not yet, so that solves use it from their first right-hand side rather than when the
    /// tiering decides (`equations::tiers` in the source); `None` where there is none: a constant metric that is not
    /// positive definite (solved by pivoted elimination), equations with parameters as inputs, or a
    /// host the code generator does not support. The integrator's right-hand side takes it where it
    /// exists (`docs/formulation.md`, "The right-hand side as machine code").
    pub fn native_operations(&self) -> Option<usize> {
        for need in [Need::Rates, Need::Motion] {
            if self.native(need, Effort::Full).is_some() && self.full_ready(need).is_none() {
                // Quick machine code was made first: the full one here, on this thread.
                if let (Some(rates), Some(program)) = (native_rates(need), self.prepared(need)) {
                    self.native_full[usize::from(rates)]
                        .get_or_init(|| program.compile(Effort::Full).map(Arc::new));
                }
            }
        }
        self.native(Need::Motion, Effort::Full)
            .map(NativeEquations::operations)
    }

    /// As [`Compiled::native_operations`], but compiling quickly, as the tiering does first
    /// (`docs/formulation.md`): the code is about 1.3 times as slow, made in about a quarter of
    /// the time. Where machine code was made already, its size.
    pub fn quick_native_operations(&self) -> Option<usize> {
        self.native(Need::Rates, Effort::Quick);
        self.native(Need::Motion, Effort::Quick)
            .map(NativeEquations::operations)
    }

    /// The right-hand side's tape, made on first use.
    fn core(&self) -> &Tape {
        self.core
            .get_or_init(|| Tape::new(&self.graph, &self.core_out))
    }

    /// The tape with the diagnostics, made on first use.
    fn full(&self) -> &Tape {
        self.full
            .get_or_init(|| Tape::new(&self.graph, &self.full_out))
    }

    /// The sizes `(n, k)` of the model these equations were compiled from (`k` counts the
    /// holonomic constraints too).
    pub fn sizes(&self) -> (usize, usize) {
        (self.n, self.k)
    }

    /// The structure found: which blocks are zero, constant, or depend on `t`, `q`, `q̇`, and the
    /// sparsity of `W` and `J` (proved from the expressions).
    pub fn structure(&self) -> &Structure {
        &self.structure
    }

    /// Operations per evaluation: `(right-hand side, with the energy balance)`.
    pub fn operations(&self) -> (usize, usize) {
        (self.core().len(), self.full().len())
    }

    /// The runs the operations of [`Compiled::operations`] are grouped into, each evaluated by one
    /// loop: `(right-hand side, with the energy balance)`. A model written with loops over its
    /// coordinates has far fewer runs than operations.
    pub fn runs(&self) -> (usize, usize) {
        (self.core().runs(), self.full().runs())
    }

    /// Whether the reduced equations provably do not depend on `t`: no block of the structure
    /// varies with it, and no comparison in the model's code could switch to a branch that does.
    /// An implicit method's `∂F/∂t` is then zero without evaluating it.
    pub fn autonomous(&self) -> bool {
        let s = &self.structure;
        self.graph.branches() == 0
            && ![s.w, s.dl_dq, s.g, s.dl_dt, s.j, s.c, s.forces]
                .iter()
                .any(|d| d.t)
    }

    /// Whether the model provably has no forces `Q` and no dissipation `D` anywhere: both are zero
    /// in the recording, and no comparison in the model's code could switch to a branch that
    /// states them. The energy balance then needs no quadrature of the forces' work.
    pub fn without_forces(&self) -> bool {
        self.graph.branches() == 0 && self.blocks.forces.iter().all(|&id| self.graph.is_zero(id))
    }

    /// The number of comparisons the tape re-checks: the branches of the model's code
    /// ([`Compiled::branches`]) and the bounds of the domains of `ln`, `log2`, `log10`, `ln_1p` and
    /// `atanh`, whose derivatives stay finite beyond them.
    pub fn guards(&self) -> usize {
        self.graph.guards().len()
    }

    /// The number of comparisons in the model's code (branches) that the tape re-checks: where
    /// one flips, another branch may have other equations and another structure.
    pub fn branches(&self) -> usize {
        self.graph.branches()
    }

    /// Whether `W` is constant and factorised once (diagonal or by Cholesky).
    pub fn constant_metric(&self) -> bool {
        matches!(self.metric, Metric::Diagonal(_) | Metric::Factor(_))
    }

    /// The derived equations as text, with the inputs named `t`, `q1…qn`, `q̇1…q̇n` (plain) or
    /// `t`, `q_1…`, `\dot q_1…` (LaTeX): the rows of [`Compiled::describe_rows`].
    pub fn equations_text(&self, latex: bool) -> Vec<(String, String)> {
        self.describe_rows(&Names::numbered(self.n), latex).0
    }

    /// The names of the graph's inputs in `style`: `t`, the coordinates, the velocities, then the
    /// parameters that are inputs (by their names, in LaTeX as [`latex_symbol`] writes them).
    fn input_names(&self, names: &Names, style: Style) -> Vec<String> {
        let (q, qd) = match style {
            Style::Text => (&names.q, &names.qd),
            Style::Latex => (&names.q_latex, &names.qd_latex),
        };
        std::iter::once("t".to_string())
            .chain(q.iter().cloned())
            .chain(qd.iter().cloned())
            .chain(self.parameters.iter().map(|(p, _)| match style {
                Style::Text => p.clone(),
                Style::Latex => latex_symbol(p),
            }))
            .collect()
    }

    /// The derived equations as `(label, expression)` rows, plain text or LaTeX, with the inputs named by
    /// `names` (and the parameters that are inputs by their own names): `L`, `∂L/∂q`, `W`, `g`,
    /// `f`, `J`, `c`, `Q`, the right-hand side `r` of `W q̈ − Jᵀμ = r`, each entry an expression
    /// (zero entries left out), then the multipliers `μ` and the accelerations `q̈` as
    /// expressions where the block system is small enough to solve symbolically
    /// (the reduced nodes); the flag says whether it was. LaTeX labels are LaTeX
    /// (`W_{1,2}`, `\mu_{1}`, `\ddot{x}`).
    pub fn describe_rows(&self, names: &Names, latex: bool) -> (Vec<(String, String)>, bool) {
        let n = self.n;
        let style = if latex { Style::Latex } else { Style::Text };
        let inputs = self.input_names(names, style);
        let mut graph = self.graph.clone();
        let reduced = self.reduced_nodes(&mut graph);
        let mut printer = Printer::new(&graph, &inputs, style);
        let b = &self.blocks;
        let mut out = vec![("L".to_string(), printer.print(b.l))];
        let vector = |out: &mut Vec<(String, String)>,
                      name: &str,
                      ids: &[u32],
                      cols: usize,
                      printer: &mut Printer<'_>| {
            for (e, &id) in ids.iter().enumerate() {
                if graph.is_zero(id) {
                    continue;
                }
                let label = match (e.checked_div(cols), latex) {
                    (None, false) => format!("{name}[{}]", e + 1),
                    (None, true) => format!("{name}_{{{}}}", e + 1),
                    (Some(row), false) => format!("{name}[{},{}]", row + 1, e % cols + 1),
                    (Some(row), true) => format!("{name}_{{{},{}}}", row + 1, e % cols + 1),
                };
                out.push((label, printer.print(id)));
            }
        };
        if latex {
            for (i, &id) in b.dl_dq.iter().enumerate() {
                if !graph.is_zero(id) {
                    let label = format!("\\frac{{\\partial L}}{{\\partial {}}}", names.q_latex[i]);
                    out.push((label, printer.print(id)));
                }
            }
        } else {
            vector(&mut out, "∂L/∂q", &b.dl_dq, 0, &mut printer);
        }
        vector(&mut out, "W", &b.w, n, &mut printer);
        vector(&mut out, "g", &b.g, 0, &mut printer);
        vector(&mut out, "f", &b.f, 0, &mut printer);
        vector(&mut out, "J", &b.j, n, &mut printer);
        vector(&mut out, "c", &b.c, 0, &mut printer);
        vector(&mut out, "Q", &b.forces, 0, &mut printer);
        vector(&mut out, "r", &b.r, 0, &mut printer);
        let _ = (&b.p, b.dl_dt, b.energy, b.power_forces);
        let Some((mu, qdd)) = reduced else {
            return (out, false);
        };
        // Expressions too long to print in full are stated as solved numerically instead.
        let whole: Option<Vec<String>> = mu
            .iter()
            .chain(&qdd)
            .map(|&id| printer.print_whole(id))
            .collect();
        let Some(whole) = whole else {
            return (out, false);
        };
        let (mu, qdd) = whole.split_at(mu.len());
        for (a, e) in mu.iter().enumerate() {
            let label = match (latex, self.k) {
                (true, 1) => "\\mu".to_string(),
                (true, _) => format!("\\mu_{{{}}}", a + 1),
                (false, _) => format!("μ[{}]", a + 1),
            };
            out.push((label, e.clone()));
        }
        for (i, e) in qdd.iter().enumerate() {
            let label = if latex {
                dotted(&names.q_latex[i], "\\ddot")
            } else {
                format!("q̈[{}]", i + 1)
            };
            out.push((label, e.clone()));
        }
        (out, true)
    }

    /// The multipliers `μ` (`k`) and accelerations `q̈` (`n`) as expressions added to `graph` (a
    /// copy of these equations' graph), where the block system is small enough to write out:
    /// at most two constraints, and `W` diagonal or at most `2 × 2`. With `a = W⁻¹ r`,
    /// `Y = W⁻¹ Jᵀ` and `S = J Y`,
    ///
    /// ```text
    /// μ = S⁻¹ (−c − J a),   q̈ = a + Y μ
    /// ```
    ///
    /// (`S⁻¹` and a `2 × 2` `W⁻¹` by their adjugates over their determinants). `None` for larger
    /// systems, which are solved numerically at each evaluation.
    pub(crate) fn reduced_nodes(&self, graph: &mut Graph) -> Option<(Vec<u32>, Vec<u32>)> {
        let (n, k) = (self.n, self.k);
        let b = &self.blocks;
        let w = |i: usize, m: usize| b.w[i * n + m];
        let diagonal = (0..n).all(|i| (0..n).all(|m| i == m || graph.is_zero(w(i, m))));
        if k > 2 || !(diagonal || n <= 2) {
            return None;
        }
        let g = graph;
        let zero = g.constant_node(0.0);
        // W⁻¹, row-major.
        let mut winv = vec![zero; n * n];
        if diagonal {
            for i in 0..n {
                winv[i * n + i] = g.fun(Fun::Recip, w(i, i));
            }
        } else {
            // n = 2: the adjugate over the determinant.
            let d1 = g.mul(w(0, 0), w(1, 1));
            let d2 = g.mul(w(0, 1), w(1, 0));
            let det = g.sub(d1, d2);
            winv[0] = g.div(w(1, 1), det);
            winv[3] = g.div(w(0, 0), det);
            let off01 = g.neg(w(0, 1));
            let off10 = g.neg(w(1, 0));
            winv[1] = g.div(off01, det);
            winv[2] = g.div(off10, det);
        }
        let dot = |g: &mut Graph, x: &[u32], y: &[u32]| {
            x.iter().zip(y).fold(zero, |acc, (&u, &v)| {
                let p = g.mul(u, v);
                g.add(acc, p)
            })
        };
        let a: Vec<u32> = (0..n)
            .map(|i| dot(g, &winv[i * n..(i + 1) * n], &b.r))
            .collect();
        // Y row `a` is W⁻¹ J_aᵀ.
        let y: Vec<Vec<u32>> = (0..k)
            .map(|c| {
                (0..n)
                    .map(|i| dot(g, &winv[i * n..(i + 1) * n], &b.j[c * n..(c + 1) * n]))
                    .collect()
            })
            .collect();
        let s: Vec<u32> = (0..k * k)
            .map(|e| dot(g, &b.j[(e / k) * n..(e / k + 1) * n], &y[e % k]))
            .collect();
        let rhs: Vec<u32> = (0..k)
            .map(|c| {
                let ja = dot(g, &b.j[c * n..(c + 1) * n], &a);
                let sum = g.add(b.c[c], ja);
                g.neg(sum)
            })
            .collect();
        let mu: Vec<u32> = match k {
            0 => Vec::new(),
            1 => vec![g.div(rhs[0], s[0])],
            _ => {
                let d1 = g.mul(s[0], s[3]);
                let d2 = g.mul(s[1], s[2]);
                let det = g.sub(d1, d2);
                let m0a = g.mul(s[3], rhs[0]);
                let m0b = g.mul(s[1], rhs[1]);
                let m0 = g.sub(m0a, m0b);
                let m1a = g.mul(s[0], rhs[1]);
                let m1b = g.mul(s[2], rhs[0]);
                let m1 = g.sub(m1a, m1b);
                vec![g.div(m0, det), g.div(m1, det)]
            }
        };
        let qdd: Vec<u32> = (0..n)
            .map(|i| {
                let yi: Vec<u32> = y.iter().map(|row| row[i]).collect();
                let ymu = dot(g, &yi, &mu);
                g.add(a[i], ymu)
            })
            .collect();
        Some((mu, qdd))
    }

    /// Evaluates the reduced equations at `(t, q, q̇)` into `d`, what `need` asks for: `q̈`, `μ`,
    /// `∂L/∂t`, `q̇·Q`, `J` and the conditioning always; `Φ` and `q̇·Φ` from [`Need::Rates`]; `f`,
    /// `L`, `E` and `Q` with [`Need::All`] (otherwise those keep their last values).
    ///
    /// `ws` must be made for these equations or a clone of them ([`CompiledWorkspace::new`]),
    /// else [`SaddleFailure::ForeignWorkspace`]; `d` must have their sizes
    /// ([`Workspace::new`](crate::equations::Workspace::new)) and `q`, `q̇` the length `n`, else
    /// [`SaddleFailure::SizeMismatch`]. Either way nothing is evaluated.
    #[inline]
    #[allow(clippy::too_many_arguments)]
    pub fn evaluate<T: Real>(
        &self,
        ws: &mut CompiledWorkspace<T>,
        d: &mut Dynamics<T>,
        t: T,
        q: &[T],
        qd: &[T],
        need: Need,
    ) -> Result<(), CompiledFailure> {
        let (n, k) = (self.n, self.k);
        if ws.owner != self.id {
            return Err(SaddleFailure::ForeignWorkspace.into());
        }
        const NAMES: [&str; 8] = [
            "the length of q",
            "the length of q̇",
            "the dynamics' coordinates",
            "the dynamics' forces",
            "the dynamics' Chetaev forces",
            "the dynamics' constraints",
            "the dynamics' residual",
            "the dynamics' J",
        ];
        saddle::check_sizes(
            &NAMES,
            [
                (n, q.len()),
                (n, qd.len()),
                (n, d.qdd.len()),
                (n, d.forces.len()),
                (n, d.phi.len()),
                (k, d.mu.len()),
                (k, d.f.len()),
                (k * n, d.j.len()),
            ],
        )?;
        self.evaluate_unchecked(ws, d, Point::new(t, q, qd), need)
    }

    /// [`Compiled::evaluate`] at `x` without the check of the sizes.
    #[inline]
    pub(crate) fn evaluate_unchecked<T: Real>(
        &self,
        ws: &mut CompiledWorkspace<T>,
        d: &mut Dynamics<T>,
        x: Point<T>,
        need: Need,
    ) -> Result<(), CompiledFailure> {
        let (n, t, q, qd) = (self.n, x.t, x.q, x.qd);
        let full = need == Need::All;
        let tape = if full { self.full() } else { self.core() };
        let mut slots = std::mem::take(if full { &mut ws.full } else { &mut ws.core });
        let params = &ws.params;
        let input = |x: &mut [T]| {
            x[0] = t;
            x[1..=n].copy_from_slice(q);
            x[n + 1..=2 * n].copy_from_slice(qd);
            x[2 * n + 1..].copy_from_slice(params);
        };
        let read = tape
            .eval(&mut slots, input)
            .map_err(CompiledFailure::Guard)
            .and_then(|()| self.read(tape, &slots, ws, d, full));
        if full {
            ws.full = slots;
        } else {
            ws.core = slots;
        }
        read?;
        d.pivot_ratio = self.solve(ws).map_err(|e| {
            // A factorisation fails on a NaN as on a zero pivot: the inputs tell which it was (a
            // model that left its domain is no singular point, and a smaller step may avoid it).
            let finite = |x: &[T]| x.iter().all(|v| v.re().is_finite());
            if finite(&ws.r) && finite(&ws.j) && finite(&ws.c) && finite(&ws.w) {
                e
            } else {
                SaddleFailure::NonFinite
            }
        })?;
        d.qdd.copy_from_slice(&ws.a);
        d.mu.copy_from_slice(&ws.mu);
        // Without a branch per entry, so that the loop is vectorised.
        let finite = |x: &[T]| x.iter().fold(true, |ok, v| ok & v.re().is_finite());
        if !(finite(&d.qdd) && finite(&d.mu)) {
            return Err(SaddleFailure::NonFinite.into());
        }
        if need.rates() {
            let mut power = T::zero();
            for (i, (phi_i, &qd_i)) in d.phi.iter_mut().zip(qd).enumerate() {
                let mut phi = T::zero();
                for (a, &mu_a) in ws.mu.iter().enumerate() {
                    phi += ws.j[a * n + i] * mu_a;
                }
                *phi_i = phi;
                power += qd_i * phi;
            }
            d.power = power;
        }
        for (dst, src) in d.j.iter_mut().zip(&ws.j) {
            *dst = src.re();
        }
        d.w_scale = match self.metric {
            Metric::Varying => ws.w.iter().fold(0.0f64, |m, v| m.max(v.re().abs())),
            _ => self.w_scale,
        };
        d.det_sign = ws.det_sign;
        Ok(())
    }

    /// Reads the outputs of `tape` (`full` or `core`), evaluated into `slots`, into `ws` (`r`, `J`,
    /// `c`, `W`) and `d` (`∂L/∂t`, `q̇·Q`, and with `full` `f`, `L`, `E` and `Q`).
    ///
    /// Output layout: `r` (n), `J` entries, `c` (k), `W` entries, `∂L/∂t`, `q̇·Q`, then with
    /// `full` `f` (k), `L`, `E`, `Q` (n). The right-hand side needs neither `f` nor `L` (a model
    /// written with loops spends a loop on each), so only the full tape has them.
    #[inline]
    fn read<T: Real>(
        &self,
        tape: &Tape,
        slots: &[T],
        ws: &mut CompiledWorkspace<T>,
        d: &mut Dynamics<T>,
        full: bool,
    ) -> Result<(), CompiledFailure> {
        let (n, k) = (self.n, self.k);
        let out = |i: usize| tape.output(slots, i);
        tape.outputs(slots, 0, &mut ws.r);
        let mut o = n;
        if self.j_entries.len() == k * n {
            // Dense, in row-major order.
            tape.outputs(slots, o, &mut ws.j);
        } else {
            for (e, &(a, i)) in self.j_entries.iter().enumerate() {
                ws.j[a * n + i] = out(o + e);
            }
        }
        o += self.j_entries.len();
        for (a, ca) in ws.c.iter_mut().enumerate() {
            *ca = out(o + a);
        }
        o += k;
        for (e, &(i, m)) in self.w_entries.iter().enumerate() {
            let v = out(o + e);
            ws.w[i * n + m] = v;
            ws.w[m * n + i] = v;
        }
        o += self.w_entries.len();
        d.dl_dt = out(o);
        d.power_forces = out(o + 1);
        if full {
            o += 2;
            tape.outputs(slots, o, &mut d.f);
            o += k;
            d.l = out(o);
            if !d.l.re().is_finite() || d.f.iter().any(|f| !f.re().is_finite()) {
                return Err(SaddleFailure::NonFinite.into());
            }
            d.energy = out(o + 1);
            tape.outputs(slots, o + 2, &mut d.forces);
        }
        Ok(())
    }

    /// Solves the block system from `ws.r`, `ws.j`, `ws.c` (and `ws.w` when varying): `q̈` into
    /// `ws.a`, `μ` into `ws.mu`; returns the pivot ratio.
    fn solve<T: Real>(&self, ws: &mut CompiledWorkspace<T>) -> Result<f64, SaddleFailure> {
        let (n, k) = (self.n, self.k);
        ws.det_sign = 1.0;
        // A constraint row that vanishes is reported as such. The Schur complement finds it as a
        // singular `S` (checked then, below); the elimination needs it checked first.
        let zero_row = |ws: &CompiledWorkspace<T>| {
            (0..k)
                .find(|&a| ws.j[a * n..(a + 1) * n].iter().all(|v| v.re() == 0.0))
                .map(|row| SaddleFailure::ZeroConstraintRow { row })
        };
        if matches!(self.metric, Metric::Indefinite | Metric::Varying) {
            if let Some(e) = zero_row(ws) {
                return Err(e);
            }
        }
        let w_ratio = match &self.metric {
            Metric::Diagonal(inv) if k == 1 => {
                // a = W⁻¹ r, y = W⁻¹ Jᵀ, S = J y and J a in one pass (the sums in the same order
                // as `dot`'s, so that the result is that of the separate passes).
                let (mut s, mut j_a) = (T::zero(), T::zero());
                let CompiledWorkspace { r, j, a, y, .. } = &mut *ws;
                for ((((ai, yi), &ri), &ji), &di) in
                    a.iter_mut().zip(y.iter_mut()).zip(&*r).zip(&*j).zip(inv)
                {
                    *ai = ri * di;
                    *yi = ji * di;
                    s += ji * *yi;
                    j_a += ji * *ai;
                }
                ws.s[0] = s;
                ws.mu[0] = -ws.c[0] - j_a;
                return self.finish(ws, self.w_ratio, zero_row);
            }
            Metric::Diagonal(inv) => {
                if let Some(pattern) = &self.sparse_schur {
                    return self.sparse_diagonal(ws, inv, pattern, zero_row);
                }
                let mul = |x: &mut [T]| {
                    for (xi, &di) in x.iter_mut().zip(inv) {
                        *xi *= di;
                    }
                };
                ws.a.copy_from_slice(&ws.r);
                mul(&mut ws.a);
                ws.y.copy_from_slice(&ws.j);
                for row in ws.y.chunks_exact_mut(n.max(1)) {
                    mul(row);
                }
                self.w_ratio
            }
            Metric::Factor(lf) => {
                let l = |i: usize, m: usize| T::from(lf[i * n + m]);
                self.metric_solves(ws, l);
                self.w_ratio
            }
            Metric::Indefinite => {
                let w = &self.w_values;
                return self.eliminate(ws, |i, m| T::from(w[i * n + m]));
            }
            Metric::Varying => {
                ws.wf.copy_from_slice(&ws.w);
                match cholesky(&mut ws.wf, n) {
                    Ok(ratio) => {
                        let wf = std::mem::take(&mut ws.wf);
                        self.metric_solves(ws, |i, m| wf[i * n + m]);
                        ws.wf = wf;
                        ratio
                    }
                    Err(_) => {
                        let w = std::mem::take(&mut ws.w);
                        let result = self.eliminate(ws, |i, m| w[i * n + m]);
                        ws.w = w;
                        return result;
                    }
                }
            }
        };
        if k == 0 {
            return Ok(w_ratio);
        }
        // S = J Y, the right-hand side −c − J a, then μ and q̈ = a + Yᵀ μ.
        for a in 0..k {
            let ja = &ws.j[a * n..(a + 1) * n];
            for b in 0..=a {
                let yb = &ws.y[b * n..(b + 1) * n];
                let s = dot(ja, yb);
                ws.s[a * k + b] = s;
                ws.s[b * k + a] = s;
            }
            ws.mu[a] = -ws.c[a] - dot(ja, &ws.a);
        }
        self.finish(ws, w_ratio, zero_row)
    }

    /// Solves `S μ = −c − J a` from `ws.s` and `ws.mu`, then `q̈ = a + Yᵀ μ` into `ws.a`; returns
    /// the smaller of `w_ratio` and `S`'s pivot ratio.
    fn finish<T: Real>(
        &self,
        ws: &mut CompiledWorkspace<T>,
        w_ratio: f64,
        zero_row: impl Fn(&CompiledWorkspace<T>) -> Option<SaddleFailure>,
    ) -> Result<f64, SaddleFailure> {
        let (n, k) = (self.n, self.k);
        let s_ratio = if k == 1 {
            // One constraint: S is a positive number unless J_1 W⁻¹ J_1ᵀ vanishes (as in the
            // static route, so that both round alike).
            let s0 = ws.s[0];
            ws.mu[0] /= s0;
            if s0.re() > 0.0 {
                1.0
            } else {
                0.0
            }
        } else {
            let ratio = match cholesky(&mut ws.s, k) {
                Ok(ratio) => ratio,
                Err(ratio) => {
                    return Err(
                        zero_row(ws).unwrap_or(SaddleFailure::Singular { pivot_ratio: ratio })
                    )
                }
            };
            let s = std::mem::take(&mut ws.s);
            cholesky_solve(|i, m| s[i * k + m], k, &mut ws.mu);
            ws.s = s;
            ratio
        };
        if s_ratio < SINGULAR_PIVOT_RATIO {
            return Err(zero_row(ws).unwrap_or(SaddleFailure::Singular {
                pivot_ratio: s_ratio,
            }));
        }
        if k > 1 && s_ratio < saddle::NULL_SPACE_PIVOT_RATIO {
            // Nearly dependent constraints: `a + Yᵀ μ` would cancel what the large `μ` carries.
            let CompiledWorkspace {
                j, r, c, w, saddle, ..
            } = &mut *ws;
            let w: &[T] = w;
            let cw = &self.w_values;
            let w_at = |i: usize, m: usize| match self.metric {
                Metric::Varying => w[i * n + m],
                _ => T::from(cw[i * n + m]),
            };
            saddle::solve_null_space(
                saddle,
                (n, k),
                w_at,
                |a, i| j[a * n + i],
                |i| r[i],
                |a| -c[a],
            )?;
            let x = ws.saddle.solution();
            ws.a.copy_from_slice(&x[..n]);
            ws.mu.copy_from_slice(&x[n..n + k]);
            return Ok(w_ratio.min(s_ratio));
        }
        // `Y` is written only at `J`'s entries where there is a pattern.
        if let Some(pattern) = &self.sparse_schur {
            for a in 0..k {
                let mu = ws.mu[a];
                for &i in pattern.row(a) {
                    ws.a[i] += ws.y[a * n + i] * mu;
                }
            }
        } else {
            for a in 0..k {
                let mu = ws.mu[a];
                for (ai, &yi) in ws.a.iter_mut().zip(&ws.y[a * n..(a + 1) * n]) {
                    *ai += yi * mu;
                }
            }
        }
        Ok(w_ratio.min(s_ratio))
    }

    /// [`Compiled::solve`] for a diagonal `W` (`inv` its inverse) and `J` with zeros at
    /// `pattern`: `a = W⁻¹ r`, `Y = J W⁻¹`, `S = J Yᵀ` and `−c − J a` over `J`'s entries.
    fn sparse_diagonal<T: Real>(
        &self,
        ws: &mut CompiledWorkspace<T>,
        inv: &[f64],
        pattern: &SparseSchur,
        zero_row: impl Fn(&CompiledWorkspace<T>) -> Option<SaddleFailure>,
    ) -> Result<f64, SaddleFailure> {
        let (n, k) = (self.n, self.k);
        let CompiledWorkspace {
            r,
            j,
            c,
            a,
            y,
            s,
            mu,
            ..
        } = &mut *ws;
        for ((ai, &ri), &di) in a.iter_mut().zip(&*r).zip(inv) {
            *ai = ri * di;
        }
        for row in 0..k {
            let mut j_a = T::zero();
            for &i in pattern.row(row) {
                let e = row * n + i;
                y[e] = j[e] * inv[i];
                j_a += j[e] * a[i];
            }
            mu[row] = -c[row] - j_a;
        }
        s.fill(T::zero());
        for &(ra, rb, start, end) in &pattern.pairs {
            let mut sum = T::zero();
            for &i in &pattern.shared[start..end] {
                sum += j[ra * n + i] * y[rb * n + i];
            }
            s[ra * k + rb] = sum;
            s[rb * k + ra] = sum;
        }
        self.finish(ws, self.w_ratio, zero_row)
    }

    /// `a = W⁻¹ r` and the rows of `Y = (W⁻¹ Jᵀ)ᵀ` with `W = L Lᵀ`, `l(i, m) = L_im`.
    fn metric_solves<T: Real>(&self, ws: &mut CompiledWorkspace<T>, l: impl Fn(usize, usize) -> T) {
        let n = self.n;
        ws.a.copy_from_slice(&ws.r);
        cholesky_solve(&l, n, &mut ws.a);
        ws.y.copy_from_slice(&ws.j);
        for row in ws.y.chunks_exact_mut(n.max(1)) {
            cholesky_solve(&l, n, row);
        }
    }

    /// The whole block system by pivoted elimination (a metric that is not positive definite).
    fn eliminate<T: Real>(
        &self,
        ws: &mut CompiledWorkspace<T>,
        w: impl Fn(usize, usize) -> T,
    ) -> Result<f64, SaddleFailure> {
        let (n, k) = (self.n, self.k);
        let CompiledWorkspace {
            j, r, c, saddle, ..
        } = ws;
        let ratio =
            saddle::solve_blocks(saddle, n, k, w, |a, i| j[a * n + i], |i| r[i], |a| -c[a])?;
        ws.det_sign = ws.saddle.det_sign();
        let x = ws.saddle.solution();
        ws.a.copy_from_slice(&x[..n]);
        ws.mu.copy_from_slice(&x[n..n + k]);
        Ok(ratio)
    }
}

/// Whether the machine code for `need` carries the rates of the energy balance; `None` for
/// [`Need::All`], which has none (output points take the interpreted route).
fn native_rates(need: Need) -> Option<bool> {
    match need {
        Need::Motion => Some(false),
        Need::Rates => Some(true),
        Need::All => None,
    }
}

/// The handling of a constant `W` and its pivot ratio.
fn constant_metric(w: &[f64], n: usize) -> (Metric, f64) {
    let diagonal = (0..n).all(|i| (0..n).all(|m| i == m || w[i * n + m] == 0.0));
    if diagonal {
        let d: Vec<f64> = (0..n).map(|i| w[i * n + i]).collect();
        if d.iter().all(|&v| v > 0.0) {
            return (Metric::Diagonal(d.iter().map(|v| 1.0 / v).collect()), 1.0);
        }
        return (Metric::Indefinite, 1.0);
    }
    let mut f = w.to_vec();
    match cholesky(&mut f, n) {
        Ok(ratio) => (Metric::Factor(f), ratio),
        Err(_) => (Metric::Indefinite, 1.0),
    }
}

#[inline]
fn dot<T: Real>(a: &[T], b: &[T]) -> T {
    a.iter().zip(b).fold(T::zero(), |s, (&x, &y)| s + x * y)
}

/// Cholesky factorisation `A = L Lᵀ` in place (row-major `n × n`, the lower triangle becomes `L`).
/// Returns `min_i L_ii² / A_ii` (1 for a diagonal matrix; small when a column is nearly dependent
/// on the earlier ones), or, where `A` is not positive definite to working precision, `Err` with
/// that ratio at the column where it failed (0 where it is not positive at all).
#[inline]
pub(crate) fn cholesky<T: Real>(a: &mut [T], n: usize) -> Result<f64, f64> {
    let mut ratio = 1.0f64;
    for j in 0..n {
        let ajj = a[j * n + j];
        let mut d = ajj;
        for p in 0..j {
            let l = a[j * n + p];
            d -= l * l;
        }
        let (dr, ar) = (d.re(), ajj.re());
        if !(dr > 0.0 && ar > 0.0) || dr <= SINGULAR_PIVOT_RATIO * ar {
            return Err(if ar > 0.0 { (dr / ar).max(0.0) } else { 0.0 });
        }
        ratio = ratio.min(dr / ar);
        let ljj = d.sqrt();
        a[j * n + j] = ljj;
        for i in j + 1..n {
            let mut s = a[i * n + j];
            for p in 0..j {
                s -= a[i * n + p] * a[j * n + p];
            }
            a[i * n + j] = s / ljj;
        }
    }
    Ok(ratio)
}

/// Solves `L Lᵀ x = b` in place, `l(i, m) = L_im` for `m ≤ i`.
#[inline]
#[allow(clippy::needless_range_loop)] // both triangles are indexed by (row, column)
pub(crate) fn cholesky_solve<T: Real>(l: impl Fn(usize, usize) -> T, n: usize, b: &mut [T]) {
    for i in 0..n {
        let mut s = b[i];
        for m in 0..i {
            s -= l(i, m) * b[m];
        }
        b[i] = s / l(i, i);
    }
    for i in (0..n).rev() {
        let mut s = b[i];
        for m in i + 1..n {
            s -= l(m, i) * b[m];
        }
        b[i] = s / l(i, i);
    }
}

#[cfg(test)]
mod tests {
    use super::{cholesky, Compiled, CompiledWorkspace, Metric, Names, Printer, Style};
    use crate::equations::{Need, Workspace};
    use crate::model::{DynModel, Real};
    use num_dual::Dual64;

    /// Eight masses `1 + i/10` (a constant diagonal `W`) joined by springs, with
    /// `q̇_a² + q̇_(a+1)² = 1` for `a = 0 … 3`: neighbouring constraints share a velocity, so `S` is
    /// tridiagonal, and the last three velocities are free.
    struct Band;
    impl DynModel for Band {
        fn sizes(&self) -> (usize, usize) {
            (8, 4)
        }
        fn lagrangian<R: Real>(&self, _t: R, q: &[R], qd: &[R]) -> R {
            let mut l = R::zero();
            for (i, v) in qd.iter().enumerate() {
                l += *v * *v * (0.5 + i as f64 / 20.0);
            }
            for i in 1..8 {
                let d = q[i] - q[i - 1] - 1.0;
                l -= d * d * (q[i].sin() * 0.1 + 0.5);
            }
            l
        }
        fn constraints<R: Real>(&self, _t: R, _q: &[R], qd: &[R], f: &mut [R]) {
            for (a, f) in f.iter_mut().enumerate() {
                *f = qd[a] * qd[a] + qd[a + 1] * qd[a + 1] - 1.0;
            }
        }
    }

    /// `q̈` and `μ` of `compiled` at a state off the constraints, by `T`: `lift(x, true)` makes
    /// `q̇_2`, which carries the derivative of a dual number, `lift(x, false)` the others.
    fn solve_at<T: Real>(
        compiled: &Compiled,
        seed: f64,
        lift: impl Fn(f64, bool) -> T,
    ) -> (Vec<T>, Vec<T>) {
        let mut ws = CompiledWorkspace::<T>::new(compiled);
        let mut d = Workspace::<T>::new(8, 4).dynamics().clone();
        let x = |i: usize, s: f64| (i as f64 * s + seed).sin();
        let q: Vec<T> = (0..8).map(|i| lift(x(i, 1.3) + i as f64, false)).collect();
        let qd: Vec<T> = (0..8).map(|i| lift(x(i, 0.7), i == 2)).collect();
        compiled
            .evaluate(&mut ws, &mut d, lift(0.0, false), &q, &qd, Need::All)
            .expect("regular");
        (d.qdd, d.mu)
    }

    #[test]
    fn the_sparse_schur_solve_gives_the_dense_one_to_the_last_bit() {
        let q: Vec<f64> = (0..8).map(|i| i as f64 * 1.1).collect();
        let qd: Vec<f64> = (0..8).map(|i| [0.6, 0.8][i % 2]).collect();
        let sparse = Compiled::new(&Band, 0.0, &q, &qd).expect("recordable");
        assert!(matches!(sparse.metric, Metric::Diagonal(_)));
        let pattern = sparse.sparse_schur.as_ref().expect("J has zeros");
        // S's lower triangle: the four diagonal entries and the three below them.
        assert_eq!(pattern.pairs.len(), 7);
        let mut dense = sparse.clone();
        dense.sparse_schur = None;
        for seed in [0.1, 0.7, 2.3] {
            let real = |x: f64, _| x;
            assert_eq!(solve_at(&sparse, seed, real), solve_at(&dense, seed, real));
            let dual = |x: f64, seeded: bool| Dual64::new(x, if seeded { 1.0 } else { 0.0 });
            let (a, b) = (solve_at(&sparse, seed, dual), solve_at(&dense, seed, dual));
            let parts = |v: &[Dual64]| v.iter().map(|x| (x.re, x.eps)).collect::<Vec<_>>();
            assert_eq!((parts(&a.0), parts(&a.1)), (parts(&b.0), parts(&b.1)));
            assert!(a.0.iter().any(|x| x.eps != 0.0), "a derivative carried");
        }
    }

    /// A failed factorisation says how near to dependent the columns are, as a success does: the
    /// ratio the error reports (`pivot ratio` of [`Error::Singular`](crate::Error::Singular)).
    #[test]
    fn cholesky_reports_its_ratio_also_where_it_fails() {
        let mut a = [4.0, 0.0, 0.0, 1.0];
        assert_eq!(cholesky(&mut a, 2), Ok(1.0));
        let mut a = [1.0, 1.0, 1.0, 1.0 + 1e-12];
        let r = cholesky(&mut a, 2).expect("regular enough");
        assert!((r - 1e-12).abs() < 1e-15, "{r}");
        let mut a = [1.0, 1.0, 1.0, 1.0 + 1e-15];
        let r = cholesky(&mut a, 2).expect_err("nearly dependent");
        // (1 + δ − 1)/(1 + δ), δ the rounded 1e-15.
        assert!((r / (a[3] - 1.0) - 1.0).abs() < 1e-14, "{r}");
        let mut a = [1.0, 2.0, 2.0, 1.0];
        assert_eq!(cholesky(&mut a, 2), Err(0.0));
    }

    /// The paper's particle (Swaczyna and Volný (42.2), (42.23)) with `m`, `g`, `v0` read as
    /// parameters: `L = ½ m (ẋ² + ẏ²) − m g y`, `f = ẋ² + ẏ² − v0²`.
    #[derive(Clone)]
    struct Paper;
    impl DynModel for Paper {
        fn sizes(&self) -> (usize, usize) {
            (2, 1)
        }
        fn lagrangian<R: Real>(&self, _t: R, q: &[R], qd: &[R]) -> R {
            let (m, g) = (R::parameter("m", 1.5), R::parameter("g", 10.0));
            m * 0.5 * (qd[0] * qd[0] + qd[1] * qd[1]) - m * g * q[1]
        }
        fn constraints<R: Real>(&self, _t: R, _q: &[R], qd: &[R], f: &mut [R]) {
            let v0 = R::parameter("v0", 10.0);
            f[0] = qd[0] * qd[0] + qd[1] * qd[1] - v0 * v0;
        }
    }

    /// Two coordinates, two constraints, a metric that is not diagonal, and constraints that
    /// depend on `t` and `q`: every part of the symbolic solve is used.
    #[derive(Clone)]
    struct Coupled;
    impl DynModel for Coupled {
        fn sizes(&self) -> (usize, usize) {
            (2, 2)
        }
        fn lagrangian<R: Real>(&self, t: R, q: &[R], qd: &[R]) -> R {
            (qd[0] * qd[0] + qd[1] * qd[1]) * 0.5 + qd[0] * qd[1] * 0.3 - q[1] * t.sin()
        }
        fn constraints<R: Real>(&self, t: R, q: &[R], qd: &[R], f: &mut [R]) {
            f[0] = qd[0] * qd[1] - q[0];
            f[1] = qd[0] + t * qd[1] * qd[1] - q[1].exp();
        }
    }

    /// Three coordinates with a diagonal metric that varies, two constraints.
    #[derive(Clone)]
    struct Diagonal;
    impl DynModel for Diagonal {
        fn sizes(&self) -> (usize, usize) {
            (3, 2)
        }
        fn lagrangian<R: Real>(&self, _t: R, q: &[R], qd: &[R]) -> R {
            let k = R::parameter("k", 2.0);
            (q[1] * q[1] + 1.0) * qd[0] * qd[0] * 0.5 + qd[1] * qd[1] + qd[2] * qd[2] * 1.5
                - k * q[0] * q[2]
        }
        fn constraints<R: Real>(&self, _t: R, q: &[R], qd: &[R], f: &mut [R]) {
            f[0] = qd[0] * qd[0] + qd[1] * qd[1] + qd[2] * qd[2] - 4.0;
            f[1] = qd[2] - q[0] * qd[1];
        }
    }

    /// `μ` and `q̈` as printed (their normal forms, [`Printer::eval`]) at `(t, q, q̇)`.
    fn printed<M: DynModel>(model: &M, t: f64, q: &[f64], qd: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let c = Compiled::with_parameters(model, t, q, qd).expect("recorded");
        let mut graph = c.graph.clone();
        let (mu, qdd) = c.reduced_nodes(&mut graph).expect("small enough");
        let names = c.input_names(&Names::numbered(c.n), Style::Text);
        let mut printer = Printer::new(&graph, &names, Style::Text);
        let inputs: Vec<f64> = std::iter::once(t)
            .chain(q.iter().copied())
            .chain(qd.iter().copied())
            .chain(c.parameters().iter().map(|p| p.1))
            .collect();
        let mut at = |ids: &[u32]| ids.iter().map(|&id| printer.eval(id, &inputs)).collect();
        (at(&mu), at(&qdd))
    }

    fn close(a: &[f64], b: &[f64], what: &str) {
        assert_eq!(a.len(), b.len());
        for (x, y) in a.iter().zip(b) {
            assert!(
                (x - y).abs() <= 1e-12 * y.abs().max(1.0),
                "{what}: printed {a:?}, solved {b:?}"
            );
        }
    }

    /// The printed `μ`, `q̈` against the solver's at each state (`Problem::equations_at`).
    fn check<M: DynModel + Clone>(model: M, states: &[(f64, Vec<f64>, Vec<f64>)]) {
        let (t0, q0, qd0) = &states[0];
        let problem = crate::Problem::dynamic(model.clone(), *t0, q0.clone(), qd0.clone())
            .expect("consistent start");
        for (t, q, qd) in states {
            let (mu, qdd) = printed(&model, *t, q, qd);
            let d = problem.equations_at(*t, q, qd).expect("evaluates");
            close(&mu, &d.mu, "μ");
            close(&qdd, &d.qdd, "q̈");
        }
    }

    #[test]
    fn the_printed_multiplier_of_the_paper_is_its_eliminated_multiplier() {
        let (m, g, v0) = (1.5, 10.0, 10.0);
        let mut states = Vec::new();
        for yd in [0.0, -3.0, -7.5, 4.0] {
            let xd = f64::sqrt(v0 * v0 - yd * yd);
            states.push((0.0, vec![1.0, 2.0], vec![xd, yd]));
        }
        for (_, q, qd) in &states {
            let (mu, qdd) = printed(&Paper, 0.0, q, qd);
            // (42.28) ÿ = −g (v0² − ẏ²)/v0², then (42.27) μ = −m ẏ ÿ / (2 (v0² − ẏ²)).
            let yd = qd[1];
            let ydd = -g * (v0 * v0 - yd * yd) / (v0 * v0);
            let paper_mu = m * g * yd / (2.0 * v0 * v0);
            close(&mu, &[paper_mu], "μ against (42.27)");
            close(&qdd[1..], &[ydd], "ÿ against (42.28)");
        }
        let c =
            Compiled::with_parameters(&Paper, 0.0, &[1.0, 2.0], &[10.0, 0.0]).expect("recorded");
        let names = Names::coordinates(&["x", "y"]);
        let row = |rows: &[(String, String)], label: &str| {
            rows.iter()
                .find(|(k, _)| k == label)
                .map(|(_, e)| e.clone())
                .unwrap_or_else(|| panic!("no {label} in {rows:?}"))
        };
        let (text, reduced) = c.describe_rows(&names, false);
        assert!(reduced);
        assert_eq!(row(&text, "μ[1]"), "m·g·y_dot/(2·(x_dot^2 + y_dot^2))");
        assert_eq!(row(&text, "J[1,2]"), "2·y_dot");
        assert_eq!(row(&text, "f[1]"), "x_dot^2 + y_dot^2 - v0^2");
        let (latex, _) = c.describe_rows(&names, true);
        assert_eq!(
            row(&latex, "\\mu"),
            "\\frac{m g \\dot{y}}{2 \\left(\\dot{x}^{2} + \\dot{y}^{2}\\right)}"
        );
        assert_eq!(
            row(&latex, "f_{1}"),
            "\\dot{x}^{2} + \\dot{y}^{2} - v_{0}^{2}"
        );
        assert_eq!(row(&latex, "\\frac{\\partial L}{\\partial y}"), "-m g");
        // The velocity stays off the constraint here: the printed μ is the solver's there too.
        check(
            Paper,
            &[
                (0.0, vec![0.0, 5.0], vec![10.0, 0.0]),
                (0.3, vec![1.0, 2.0], vec![6.0, -8.0]),
                (0.3, vec![1.0, 2.0], vec![7.0, 9.0]),
            ],
        );
    }

    #[test]
    fn the_printed_solution_of_two_constraints_is_the_solvers() {
        check(
            Coupled,
            &[
                (0.0, vec![0.3, 0.0], vec![1.0, 0.3]),
                (0.4, vec![0.3, -0.2], vec![1.1, 0.7]),
                (1.3, vec![-0.8, 0.5], vec![0.6, -1.4]),
            ],
        );
        check(
            Diagonal,
            &[
                (0.0, vec![0.5, 0.2, -0.3], vec![2.75f64.sqrt(), 1.0, 0.5]),
                (0.0, vec![0.5, 0.2, -0.3], vec![1.2, 0.9, 0.45]),
                (0.0, vec![-1.0, 0.7, 0.1], vec![0.4, 1.1, -1.1]),
            ],
        );
    }

    #[test]
    fn a_large_block_system_is_stated_not_printed() {
        let c = Compiled::with_parameters(&Band, 0.0, &[0.0; 8], &[0.6; 8]).expect("recorded");
        let (rows, reduced) = c.describe_rows(&Names::numbered(8), false);
        assert!(!reduced);
        assert!(rows.iter().all(|(k, _)| !k.starts_with('μ')));
    }
}
