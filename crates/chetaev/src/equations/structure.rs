//! What the library derived for a model, shown: which blocks of the Chetaev equations vanish or are
//! constant, what each depends on, and their numbers at a state ([`Problem::describe`]).
//!
//! Where the model is recorded as an expression graph ([`compiled`](super::compiled)) the structure
//! is proved from the expressions. Otherwise the dependences are found by evaluating the blocks (each itself by automatic differentiation)
//! at a few states around the one given, moving `t`, `q` and `q̇` one at a time by relative steps
//! of a few per cent: a block whose values do not change (to 1e-12 relative) when `q` moves is
//! reported as independent of `q`, and so on. This is a probe, not a proof: a block that varies only
//! far from the probed states, or whose variation cancels exactly at them, is reported as constant.
//!
//! [`Problem::describe`]: crate::Problem::describe

use std::fmt;

use super::derivatives::{ConstraintBlocks, LagrangianBlocks};
pub use super::graph::latex_symbol;
use super::graph::{number, Style};
use crate::model::{Model, Point};

/// The names a description prints the coordinates and velocities with, as plain text and as
/// LaTeX. The parameters a model reads by [`Real::parameter`](crate::model::Real::parameter)
/// print by their own names (in LaTeX as [`latex_symbol`] writes them).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Names {
    /// The coordinates in plain text.
    pub q: Vec<String>,
    /// The velocities in plain text.
    pub qd: Vec<String>,
    /// The coordinates in LaTeX.
    pub q_latex: Vec<String>,
    /// The velocities in LaTeX.
    pub qd_latex: Vec<String>,
}

impl Names {
    /// `q1…qn`, `q̇1…q̇n`; in LaTeX `q_{1}…`, `\dot q_{1}…`.
    pub fn numbered(n: usize) -> Self {
        Self {
            q: (1..=n).map(|i| format!("q{i}")).collect(),
            qd: (1..=n).map(|i| format!("q̇{i}")).collect(),
            q_latex: (1..=n).map(|i| format!("q_{{{i}}}")).collect(),
            qd_latex: (1..=n).map(|i| format!("\\dot q_{{{i}}}")).collect(),
        }
    }

    /// The coordinates by their names (`x`), the velocities as `x_dot`; in LaTeX as
    /// [`latex_symbol`] writes them (`theta` is `\theta`, `\dot{\theta}` its velocity).
    pub fn coordinates<S: AsRef<str>>(names: &[S]) -> Self {
        let latex: Vec<String> = names.iter().map(|s| latex_symbol(s.as_ref())).collect();
        Self::with_latex(names, &latex)
    }

    /// The coordinates by their names (`x`), the velocities as `x_dot`, with the coordinates'
    /// LaTeX given (sympy's, for instance); the velocities' LaTeX is `\dot{…}` of it.
    pub fn with_latex<S: AsRef<str>, T: AsRef<str>>(names: &[S], latex: &[T]) -> Self {
        Self {
            q: names.iter().map(|s| s.as_ref().to_string()).collect(),
            qd: names
                .iter()
                .map(|s| format!("{}_dot", s.as_ref()))
                .collect(),
            q_latex: latex.iter().map(|s| s.as_ref().to_string()).collect(),
            qd_latex: latex.iter().map(|s| dotted(s.as_ref(), "\\dot")).collect(),
        }
    }
}

/// `\dot{x}` of the LaTeX symbol `x` (`accent` is `\dot` or `\ddot`), with a subscript kept
/// outside the accent (`\dot{x}_{1}`).
pub(crate) fn dotted(symbol: &str, accent: &str) -> String {
    match symbol.split_once("_{") {
        Some((stem, sub)) if !stem.is_empty() && !stem.contains('{') => {
            format!("{accent}{{{stem}}}_{{{sub}")
        }
        _ => format!("{accent}{{{symbol}}}"),
    }
}

/// On which of `t`, `q`, `q̇` a block depends (as probed).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Dependence {
    /// Varies with time.
    pub t: bool,
    /// Varies with the positions.
    pub q: bool,
    /// Varies with the velocities.
    pub qd: bool,
    /// Identically zero at every probed state.
    pub zero: bool,
}

impl Dependence {
    /// Neither zero nor varying: constant.
    pub fn is_constant(&self) -> bool {
        !(self.t || self.q || self.qd)
    }
}

impl fmt::Display for Dependence {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.zero {
            return write!(f, "zero");
        }
        let on: Vec<&str> = [(self.t, "t"), (self.q, "q"), (self.qd, "q̇")]
            .iter()
            .filter_map(|&(d, name)| d.then_some(name))
            .collect();
        if on.is_empty() {
            write!(f, "constant")
        } else {
            write!(f, "depends on {}", on.join(", "))
        }
    }
}

/// The structure of a model's Chetaev equations, as probed (see the module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct Structure {
    /// Coordinates `n` and constraints `k` (velocity, then holonomic).
    pub sizes: (usize, usize),
    /// Holonomic constraints among the `k`.
    pub holonomic: usize,
    /// `W = ∂²L/∂q̇²`.
    pub w: Dependence,
    /// `∂L/∂q`.
    pub dl_dq: Dependence,
    /// `g = (∂²L/∂q̇∂q) q̇ + ∂²L/∂q̇∂t`.
    pub g: Dependence,
    /// `∂L/∂t`.
    pub dl_dt: Dependence,
    /// `J = ∂f/∂q̇`.
    pub j: Dependence,
    /// `c = (∂f/∂q) q̇ + ∂f/∂t`.
    pub c: Dependence,
    /// The forces not derivable from `L` (`Q − ∂D/∂q̇`).
    pub forces: Dependence,
    /// The pattern of nonzero entries of `W` (row-major `n × n`), at any probed state.
    pub w_pattern: Vec<bool>,
    /// The pattern of nonzero entries of `J` (row-major `k × n`), at any probed state.
    pub j_pattern: Vec<bool>,
}

/// All blocks at one state, flattened, in a fixed order per block.
struct Sample {
    w: Vec<f64>,
    dl_dq: Vec<f64>,
    g: Vec<f64>,
    dl_dt: Vec<f64>,
    j: Vec<f64>,
    c: Vec<f64>,
    forces: Vec<f64>,
}

fn sample<M: Model + ?Sized>(model: &M, t: f64, q: &[f64], qd: &[f64]) -> Sample {
    let (n, k) = model.sizes();
    let x = Point::new(t, q, qd);
    let mut lb = LagrangianBlocks::new(n);
    model.lagrangian_blocks(x, &mut lb);
    let mut cb = ConstraintBlocks::new(n, k);
    if k > 0 {
        model.constraint_blocks(x, true, &mut cb);
    }
    let mut forces = vec![0.0; n];
    model.force_blocks(x, &mut forces);
    Sample {
        w: lb.w,
        dl_dq: lb.dl_dq,
        g: lb.g,
        dl_dt: vec![lb.dl_dt],
        j: cb.j,
        c: cb.c,
        forces,
    }
}

/// Whether two evaluations of a block differ beyond rounding.
fn differ(a: &[f64], b: &[f64]) -> bool {
    let scale = a
        .iter()
        .chain(b)
        .fold(0.0f64, |m, v| m.max(v.abs()))
        .max(f64::MIN_POSITIVE);
    a.iter()
        .zip(b)
        .any(|(x, y)| (x - y).abs() > 1e-12 * scale || x.is_nan() != y.is_nan())
}

/// Probes `model` around `(t, q, q̇)`; see the module docs.
pub(crate) fn probe<M: Model + ?Sized>(model: &M, t: f64, q: &[f64], qd: &[f64]) -> Structure {
    let (n, k) = model.sizes();
    // Fixed, irregular relative steps, so that no probe lands on a symmetry of the model.
    const STEPS: [f64; 3] = [0.0313, -0.0271, 0.0457];
    let moved = |x: &[f64], s: f64, shift: usize| -> Vec<f64> {
        x.iter()
            .enumerate()
            .map(|(i, v)| {
                let r = s * (1.0 + 0.37 * ((i + shift) % 5) as f64);
                v + r * v.abs().max(1.0)
            })
            .collect()
    };
    let base = sample(model, t, q, qd);
    let mut dependence: [Dependence; 7] = Default::default();
    let blocks = |s: &Sample| -> [Vec<f64>; 7] {
        [
            s.w.clone(),
            s.dl_dq.clone(),
            s.g.clone(),
            s.dl_dt.clone(),
            s.j.clone(),
            s.c.clone(),
            s.forces.clone(),
        ]
    };
    let b0 = blocks(&base);
    let mut w_pattern: Vec<bool> = base.w.iter().map(|v| *v != 0.0).collect();
    let mut j_pattern: Vec<bool> = base.j.iter().map(|v| *v != 0.0).collect();
    let mut nonzero: [bool; 7] = std::array::from_fn(|b| b0[b].iter().any(|v| *v != 0.0));
    for (p, &s) in STEPS.iter().enumerate() {
        let probes = [
            (0usize, sample(model, t + s * t.abs().max(1.0), q, qd)),
            (1, sample(model, t, &moved(q, s, p), qd)),
            (2, sample(model, t, q, &moved(qd, s, p + 1))),
        ];
        for (which, other) in probes {
            let bo = blocks(&other);
            for b in 0..7 {
                nonzero[b] |= bo[b].iter().any(|v| *v != 0.0);
                if differ(&b0[b], &bo[b]) {
                    match which {
                        0 => dependence[b].t = true,
                        1 => dependence[b].q = true,
                        _ => dependence[b].qd = true,
                    }
                }
            }
            for (m, v) in w_pattern.iter_mut().zip(&other.w) {
                *m |= *v != 0.0;
            }
            for (m, v) in j_pattern.iter_mut().zip(&other.j) {
                *m |= *v != 0.0;
            }
        }
    }
    for (d, nz) in dependence.iter_mut().zip(nonzero) {
        d.zero = !nz;
    }
    let [w, dl_dq, g, dl_dt, j, c, forces] = dependence;
    Structure {
        sizes: (n, k),
        holonomic: model.holonomic_count(),
        w,
        dl_dq,
        g,
        dl_dt,
        j,
        c,
        forces,
        w_pattern,
        j_pattern,
    }
}

/// A model's equations described at a state: the structure, the blocks there and the solution of
/// the block system ([`Problem::describe`](crate::Problem::describe)). Its `Display` is a plain-text
/// report.
#[derive(Clone, Debug)]
pub struct Description {
    /// The structure: proved from the compiled expressions, or probed around the state.
    pub structure: Structure,
    /// Whether [`Description::structure`] is proved (from the expression graph) rather than probed.
    pub proved: bool,
    /// Comparisons in the model's code (branches) recorded as guards: the proof holds for the
    /// branches taken at the recorded state, and each evaluation re-checks them.
    pub guards: usize,
    /// The derived blocks as plain-text expressions, `(name, expression)`, zero entries left out
    /// (empty where the model cannot be recorded), then `μ` and `q̈` where
    /// [`Description::reduced`].
    pub equations: Vec<(String, String)>,
    /// The same in LaTeX, the names in LaTeX too (`W_{1,1}`, `\mu`, `\ddot{x}`).
    pub latex: Vec<(String, String)>,
    /// Whether `μ` and `q̈` are among the expressions: where the block system is small (at most
    /// two constraints, `W` diagonal or at most `2 × 2`). Otherwise they are solved numerically at
    /// each evaluation, from `S μ = −c − J W⁻¹ r`, `S = J W⁻¹ Jᵀ`, `q̈ = W⁻¹ (r + Jᵀ μ)`.
    pub reduced: bool,
    /// The names of the expressions' inputs in plain text: `t`, the coordinates, the velocities,
    /// then the parameters kept as symbols.
    pub inputs: Vec<String>,
    /// The state `(t, q, q̇)`.
    pub state: (f64, Vec<f64>, Vec<f64>),
    /// `W` (row-major `n × n`), `∂L/∂q`, `g`, `∂L/∂t` at the state.
    pub lagrangian: LagrangianBlocks<f64>,
    /// `f`, `J` (row-major `k × n`), `c` at the state.
    pub constraints: ConstraintBlocks<f64>,
    /// `q̈`, `μ`, `Φ`, `E`, the pivot ratio, ... at the state.
    pub dynamics: super::Dynamics<f64>,
    /// The Jacobian of the reduced equations `∂F/∂(q, q̇, t)` by dual numbers: the forward passes
    /// it takes, one per group of columns that share no row of its pattern, and its columns
    /// (`2n + 1`); `None` where the passes are not grouped
    /// ([`Compiled::jacobian_passes`](super::compiled::Compiled::jacobian_passes)).
    pub jacobian_passes: Option<(usize, usize)>,
}

impl Description {
    /// The derived blocks as one LaTeX `align*` environment (empty where the model cannot be
    /// recorded).
    pub fn latex(&self) -> String {
        if self.latex.is_empty() {
            return String::new();
        }
        let mut rows: Vec<String> = self
            .latex
            .iter()
            .map(|(name, e)| format!("  {name} &= {e}"))
            .collect();
        if !self.reduced && self.structure.sizes.1 > 0 {
            rows.push(
                "  S \\mu &= -c - J W^{-1} r, \\quad S = J W^{-1} J^{T}, \\quad \\ddot q = W^{-1} \\left(r + J^{T} \\mu\\right) \\quad \\text{(solved numerically)}"
                    .to_string(),
            );
        }
        format!(
            "\\begin{{align*}}\n{}\n\\end{{align*}}",
            rows.join(" \\\\\n")
        )
    }
}

fn vector(v: &[f64]) -> String {
    let items: Vec<String> = v.iter().map(|&x| number(x, Style::Text)).collect();
    format!("[{}]", items.join(", "))
}

fn matrix(m: &[f64], cols: usize) -> String {
    if cols == 0 || m.is_empty() {
        return "[]".to_string();
    }
    let rows: Vec<String> = m.chunks(cols).map(vector).collect();
    rows.join("\n            ")
}

fn pattern(p: &[bool], cols: usize) -> String {
    if cols == 0 || p.is_empty() {
        return "(none)".to_string();
    }
    let rows: Vec<String> = p
        .chunks(cols)
        .map(|r| r.iter().map(|&b| if b { '×' } else { '·' }).collect())
        .collect();
    rows.join(" / ")
}

/// A block's dependence and its pattern of nonzero entries (`cols` columns).
fn with_pattern(dependence: &Dependence, p: &[bool], cols: usize) -> String {
    format!("{dependence}   pattern {}", pattern(p, cols))
}

impl fmt::Display for Description {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let s = &self.structure;
        let (n, k) = s.sizes;
        let (t, q, qd) = &self.state;
        let d = &self.dynamics;
        writeln!(
            f,
            "Chetaev equations (Newton form): W q̈ − Jᵀμ = ∂L/∂q − g + Q,  J q̈ = −c"
        )?;
        let plural = |count: usize, one: &'static str, many: &'static str| {
            if count == 1 {
                one
            } else {
                many
            }
        };
        let coordinates = plural(n, "coordinate", "coordinates");
        if s.holonomic > 0 {
            writeln!(
                f,
                "  sizes      n = {n} {coordinates}, k = {k} {} ({} velocity, {} holonomic, entering as ḣ = 0)",
                plural(k, "constraint", "constraints"),
                k - s.holonomic,
                s.holonomic
            )?;
        } else {
            writeln!(
                f,
                "  sizes      n = {n} {coordinates}, k = {k} {}",
                plural(k, "velocity constraint", "velocity constraints")
            )?;
        }
        if self.proved && self.guards > 0 {
            writeln!(
                f,
                "  structure  (proved from the recorded expressions, for the branches taken at the initial state; {} comparison(s) re-checked at every evaluation)",
                self.guards
            )?;
        } else if self.proved {
            writeln!(f, "  structure  (proved from the recorded expressions)")?;
        } else {
            writeln!(f, "  structure  (probed around the state below)")?;
        }
        let w = with_pattern(&s.w, &s.w_pattern, n);
        writeln!(f, "    W = ∂²L/∂q̇²              {w}")?;
        writeln!(f, "    ∂L/∂q                    {}", s.dl_dq)?;
        writeln!(f, "    g = (∂²L/∂q̇∂q)q̇ + ∂²L/∂q̇∂t  {}", s.g)?;
        writeln!(f, "    ∂L/∂t                    {}", s.dl_dt)?;
        if k > 0 {
            let j = with_pattern(&s.j, &s.j_pattern, n);
            writeln!(f, "    J = ∂f/∂q̇                {j}")?;
            writeln!(f, "    c = (∂f/∂q)q̇ + ∂f/∂t     {}", s.c)?;
        }
        writeln!(f, "    Q (forces not from L)    {}", s.forces)?;
        if let Some((passes, columns)) = self.jacobian_passes {
            writeln!(
                f,
                "    ∂F/∂(q, q̇, t)            {passes} forward passes for its {columns} columns"
            )?;
        }
        if !self.equations.is_empty() {
            writeln!(
                f,
                "  derived    (inputs {}; r = ∂L/∂q − g + Q (Q with −∂D/∂q̇), the right side of W q̈ − Jᵀμ = r; \
                 zero entries left out)",
                self.inputs.join(", ")
            )?;
            for (name, e) in &self.equations {
                writeln!(f, "    {name:<10} = {e}")?;
            }
            if !self.reduced && k > 0 {
                writeln!(
                    f,
                    "    μ, q̈ solved numerically at each evaluation: S μ = −c − J W⁻¹ r with S = J W⁻¹ Jᵀ, \
                     q̈ = W⁻¹ (r + Jᵀ μ)"
                )?;
            }
        }
        writeln!(
            f,
            "  at t = {}, q = {}, q̇ = {}",
            number(*t, Style::Text),
            vector(q),
            vector(qd)
        )?;
        writeln!(f, "    W     = {}", matrix(&self.lagrangian.w, n))?;
        writeln!(f, "    ∂L/∂q = {}", vector(&self.lagrangian.dl_dq))?;
        writeln!(f, "    g     = {}", vector(&self.lagrangian.g))?;
        if k > 0 {
            writeln!(f, "    f     = {}", vector(&self.constraints.f))?;
            writeln!(f, "    J     = {}", matrix(&self.constraints.j, n))?;
            writeln!(f, "    c     = {}", vector(&self.constraints.c))?;
        }
        writeln!(f, "    Q     = {}", vector(&d.forces))?;
        writeln!(f, "    q̈     = {}", vector(&d.qdd))?;
        if k > 0 {
            writeln!(f, "    μ     = {}", vector(&d.mu))?;
            writeln!(f, "    Φ     = {}", vector(&d.phi))?;
        }
        writeln!(
            f,
            "    E     = {}, ∂L/∂t = {}",
            number(d.energy, Style::Text),
            number(d.dl_dt, Style::Text)
        )?;
        write!(
            f,
            "    block system: smallest over largest pivot {:.3e} (1 is perfect, below 1.4e-14 singular)",
            d.pivot_ratio
        )
    }
}
