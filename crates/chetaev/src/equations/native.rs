//! The integrator's right-hand side of compiled equations as machine code: the model's blocks and
//! the block solve written out as one straight-line program for its structure, compiled by
//! [`chetaev_native`].
//!
//! The interpreted route ([`Compiled::evaluate`]) runs the tape of `r`, `J`, `c` and `W`, then a
//! general Schur-complement solve with loops over `n` and `k`. Here both become one program:
//!
//! ```text
//! tape:   r (n), J (k × n), c (k), W (n × n, when it varies)
//! W = L Lᵀ                 (a constant W: its factor or inverse diagonal, as constants)
//! a = W⁻¹ r,   Y = W⁻¹ Jᵀ,   S = J Y (k × k),   S μ = −c − J a,   q̈ = a + Y μ
//! Φ = Jᵀ μ,   q̇·Φ,   ∂L/∂t,   q̇·Q                        (only where the energy is recorded)
//! ```
//!
//! with every entry the structure proves zero or one folded away (a zero of `W` or `J` costs
//! nothing), so that the program of the paper's particle is 26 operations. The program checks the
//! pivots of the two factorisations as the interpreted route does (positive, and above the singular
//! ratio of [`saddle`](super::saddle); with more than one constraint, `S`'s above the ratio below
//! which that route takes the null-space method), the guards of the recording, and that `q̈` and
//! `μ` are finite: where a check fails, [`NativeEquations::evaluate`] declines and the caller takes the
//! interpreted route, which pivots, falls back to dual numbers, or reports the failure exactly as
//! without this route. The program reads `t` and `(q, q̇)` where the integrator keeps them and
//! writes `(q̇, q̈)` in place. It is compiled when the tiering finds that it pays (compiling costs
//! a fraction of a millisecond to milliseconds; [`super::tiers`]), and not at all beyond
//! [`MAX_OPERATIONS`].
//!
//! The program performs the interpreted route's operations in its order, except that additions of
//! a structural zero and products with a structural one are left out; its results agree with the
//! interpreted ones to rounding (tested).

use std::cmp::Ordering;
use std::collections::HashMap;

use chetaev_native::{Effort, Guard, Native, Op, Program};

use super::compiled::{Compiled, Metric};
use super::graph::{Fun, Node};
use super::saddle::{NULL_SPACE_PIVOT_RATIO, SINGULAR_PIVOT_RATIO};
use super::Dynamics;

/// The largest program compiled. Beyond it the code generator's time grows faster than the
/// program (about 15 ms at 2,500 operations, 200 ms at 12,000, 15 s at 36,000 on one core of an
/// AMD EPYC), and large straight-line code is no faster than the tape's loops (a gas of 100
/// particles: 1.4 µs against 0.9 µs interpreted).
const MAX_OPERATIONS: usize = 2_500;

/// The model's functions the program calls, as the `f64` methods the interpreted route calls.
mod calls {
    macro_rules! unary {
        ($($name:ident => $method:ident),* $(,)?) => {
            $(pub(super) extern "C" fn $name(x: f64) -> f64 { x.$method() })*
        };
    }
    unary!(cbrt => cbrt, exp => exp, exp2 => exp2, exp_m1 => exp_m1, ln => ln, log2 => log2,
        log10 => log10, ln_1p => ln_1p, sin => sin, cos => cos, tan => tan, asin => asin,
        acos => acos, atan => atan, sinh => sinh, cosh => cosh, tanh => tanh, asinh => asinh,
        acosh => acosh, atanh => atanh, signum => signum);
    pub(super) extern "C" fn powf(x: f64, p: f64) -> f64 {
        x.powf(p)
    }
    pub(super) extern "C" fn atan2(y: f64, x: f64) -> f64 {
        y.atan2(x)
    }
    pub(super) extern "C" fn powi(x: f64, n: i32) -> f64 {
        x.powi(n)
    }
}

/// A program under construction, folding what is known: constants, and sums and products with a
/// structural zero or one.
#[derive(Default)]
struct Builder {
    ops: Vec<Op>,
    constants: HashMap<u64, u32>,
    /// Which function each call computes, for its derivative ([`tangents`]).
    kinds: HashMap<u32, Kind>,
}

/// The function an [`Op::Unary`] or [`Op::Binary`] calls.
#[derive(Clone, Copy, Debug)]
enum Kind {
    Fun(Fun),
    Powf,
    Atan2,
}

impl Builder {
    fn push(&mut self, op: Op) -> u32 {
        self.ops.push(op);
        (self.ops.len() - 1) as u32
    }

    fn constant(&mut self, c: f64) -> u32 {
        if let Some(&id) = self.constants.get(&c.to_bits()) {
            return id;
        }
        let id = self.push(Op::Const(c));
        self.constants.insert(c.to_bits(), id);
        id
    }

    fn value(&self, id: u32) -> Option<f64> {
        match self.ops[id as usize] {
            Op::Const(c) => Some(c),
            _ => None,
        }
    }

    fn add(&mut self, a: u32, b: u32) -> u32 {
        match (self.value(a), self.value(b)) {
            (Some(x), Some(y)) => self.constant(x + y),
            (Some(0.0), _) => b,
            (_, Some(0.0)) => a,
            _ => self.push(Op::Add(a, b)),
        }
    }

    fn sub(&mut self, a: u32, b: u32) -> u32 {
        match (self.value(a), self.value(b)) {
            (Some(x), Some(y)) => self.constant(x - y),
            (_, Some(0.0)) => a,
            (Some(0.0), _) => self.push(Op::Neg(b)),
            _ => self.push(Op::Sub(a, b)),
        }
    }

    fn mul(&mut self, a: u32, b: u32) -> u32 {
        match (self.value(a), self.value(b)) {
            (Some(x), Some(y)) => self.constant(x * y),
            (Some(0.0), _) | (_, Some(0.0)) => self.constant(0.0),
            (Some(1.0), _) => b,
            (_, Some(1.0)) => a,
            _ => self.push(Op::Mul(a, b)),
        }
    }

    fn div(&mut self, a: u32, b: u32) -> u32 {
        match (self.value(a), self.value(b)) {
            (Some(x), Some(y)) => self.constant(x / y),
            (_, Some(1.0)) => a,
            _ => self.push(Op::Div(a, b)),
        }
    }
    /// `a / p` for a pivot `p` that the program's checks keep positive and finite (or a positive
    /// constant), so that a zero `a` gives zero: the entries of the factors and solves that the
    /// structure makes zero stay constants, and the Jacobian's pattern ([`Colouring`]) sees that
    /// independent constraints do not couple. (The interpreted route computes them as exact
    /// zeros, with zero derivatives.)
    fn div_by_pivot(&mut self, a: u32, p: u32) -> u32 {
        match self.value(a) {
            Some(0.0) => a,
            _ => self.div(a, p),
        }
    }

    fn neg(&mut self, a: u32) -> u32 {
        match self.value(a) {
            Some(x) => self.constant(-x),
            None => self.push(Op::Neg(a)),
        }
    }

    /// `Σ_i x_i y_i`, summed from zero in order (as the interpreted route's `dot`).
    fn dot(&mut self, x: &[u32], y: &[u32]) -> u32 {
        let mut s = self.constant(0.0);
        for (&a, &b) in x.iter().zip(y) {
            let p = self.mul(a, b);
            s = self.add(s, p);
        }
        s
    }

    /// Solves `L Lᵀ x = b` in place, `l[i][m] = L_im` for `m ≤ i` (as `cholesky_solve`).
    fn cholesky_solve(&mut self, l: &[Vec<u32>], b: &mut [u32]) {
        let n = b.len();
        for i in 0..n {
            let mut s = b[i];
            for m in 0..i {
                let p = self.mul(l[i][m], b[m]);
                s = self.sub(s, p);
            }
            b[i] = self.div_by_pivot(s, l[i][i]);
        }
        for i in (0..n).rev() {
            let mut s = b[i];
            for m in i + 1..n {
                let p = self.mul(l[m][i], b[m]);
                s = self.sub(s, p);
            }
            b[i] = self.div_by_pivot(s, l[i][i]);
        }
    }

    /// The Cholesky factor of the symmetric `a` (as `cholesky`), with the pivots `(d_j, a_jj)`
    /// (`d_j = L_jj²` before the root) for the caller to check.
    #[allow(clippy::needless_range_loop)] // both triangles are indexed by (row, column)
    fn cholesky(&mut self, a: &[Vec<u32>]) -> (Vec<Vec<u32>>, Vec<(u32, u32)>) {
        let n = a.len();
        let mut l = a.to_vec();
        let mut pivots = Vec::with_capacity(n);
        for j in 0..n {
            let ajj = a[j][j];
            let mut d = ajj;
            for p in 0..j {
                let sq = self.mul(l[j][p], l[j][p]);
                d = self.sub(d, sq);
            }
            pivots.push((d, ajj));
            let ljj = match self.value(d) {
                Some(v) => self.constant(v.sqrt()),
                None => self.push(Op::Sqrt(d)),
            };
            l[j][j] = ljj;
            for i in j + 1..n {
                let mut s = l[i][j];
                for p in 0..j {
                    let prod = self.mul(l[i][p], l[j][p]);
                    s = self.sub(s, prod);
                }
                l[i][j] = self.div_by_pivot(s, ljj);
            }
        }
        (l, pivots)
    }
}

/// The operation of a graph node, on the program's ids of its operands.
fn op(b: &mut Builder, node: Node, id: impl Fn(u32) -> u32) -> u32 {
    use calls::*;
    match node {
        Node::Const(c) => b.constant(c),
        // t alone in the first input array, (q, q̇) in the second: the integrator's state as it is.
        Node::Input(0) => b.push(Op::Input(0, 0)),
        Node::Input(i) => b.push(Op::Input(1, i - 1)),
        Node::Add(x, y) => b.push(Op::Add(id(x), id(y))),
        Node::Sub(x, y) => b.push(Op::Sub(id(x), id(y))),
        Node::Mul(x, y) => b.push(Op::Mul(id(x), id(y))),
        Node::Div(x, y) => b.push(Op::Div(id(x), id(y))),
        Node::Neg(x) => b.push(Op::Neg(id(x))),
        Node::Powi(x, n) => b.push(Op::WithInt(powi, id(x), n)),
        Node::Powf(x, p) => {
            let p = b.constant(p);
            let v = b.push(Op::Binary(powf, id(x), p));
            b.kinds.insert(v, Kind::Powf);
            v
        }
        Node::Atan2(y, x) => {
            let v = b.push(Op::Binary(atan2, id(y), id(x)));
            b.kinds.insert(v, Kind::Atan2);
            v
        }
        Node::Fun(fun, x) => {
            let x = id(x);
            let f: chetaev_native::Unary = match fun {
                Fun::Sqrt => return b.push(Op::Sqrt(x)),
                Fun::Abs => return b.push(Op::Abs(x)),
                Fun::Recip => {
                    let one = b.constant(1.0);
                    return b.push(Op::Div(one, x));
                }
                Fun::Cbrt => cbrt,
                Fun::Exp => exp,
                Fun::Exp2 => exp2,
                Fun::ExpM1 => exp_m1,
                Fun::Ln => ln,
                Fun::Log2 => log2,
                Fun::Log10 => log10,
                Fun::Ln1p => ln_1p,
                Fun::Sin => sin,
                Fun::Cos => cos,
                Fun::Tan => tan,
                Fun::Asin => asin,
                Fun::Acos => acos,
                Fun::Atan => atan,
                Fun::Sinh => sinh,
                Fun::Cosh => cosh,
                Fun::Tanh => tanh,
                Fun::Asinh => asinh,
                Fun::Acosh => acosh,
                Fun::Atanh => atanh,
                Fun::Signum => signum,
            };
            let v = b.push(Op::Unary(f, x));
            b.kinds.insert(v, Kind::Fun(fun));
            v
        }
    }
}

/// The program writes `(q̇, q̈)` (2n), the state's derivative, to its first output array; and to
/// the second what the integrator reads besides: with the rates `q̇·Φ`, `∂L/∂t`, `q̇·Q` first,
/// then `J` (k × n) and the entries of a varying metric on and above the diagonal, for the
/// singular-point check ([`NativeEquations::fill`]). The multipliers and the pivots stay inside.
#[derive(Clone, Copy, Debug)]
struct Layout {
    n: usize,
    k: usize,
    w_entries: usize,
    varying: bool,
    rates: bool,
}

impl Layout {
    fn j(&self) -> usize {
        if self.rates {
            3
        } else {
            0
        }
    }
    fn w(&self) -> usize {
        self.j() + self.k * self.n
    }
    fn len(&self) -> usize {
        self.w() + self.w_entries
    }
}

/// The right-hand side of compiled equations as machine code; see the module docs.
#[derive(Debug)]
pub(crate) struct NativeEquations {
    native: Native,
    layout: Layout,
    /// `max |W_ij|` of a constant metric.
    w_scale: f64,
    /// How hard the code generator worked on it.
    effort: Effort,
}

/// Scratch space for [`NativeEquations::evaluate`]: its second output array.
#[derive(Clone, Debug, Default)]
pub(crate) struct NativeBuffers {
    outputs: Vec<f64>,
}

/// The guards that keep the program to what it can decide alone: `a > 0` and `d > ρ a` for each
/// pivot `(d, a, ρ)` (as `cholesky` checks them with `ρ` its singular ratio; together they give
/// `d > 0`), and that `q̈` and `μ` are finite, as one test: `Σ (x − x) = 0`, which a single
/// infinite or NaN entry breaks. A guard whose operands are constants is decided here: dropped
/// where it holds, and `None` (no program) where it does not.
fn checks(b: &mut Builder, pivots: &[(u32, u32, f64)], finite: &[u32]) -> Option<Vec<Guard>> {
    let zero = b.constant(0.0);
    let mut conditions = Vec::new();
    for &(d, a, rho) in pivots {
        let rho = b.constant(rho);
        let floor = b.mul(rho, a);
        conditions.push((a, zero, Ordering::Greater));
        conditions.push((d, floor, Ordering::Greater));
    }
    let mut sum = zero;
    for &x in finite {
        let diff = b.push(Op::Sub(x, x));
        sum = b.add(sum, diff);
    }
    conditions.push((sum, zero, Ordering::Equal));
    let mut guards = Vec::new();
    for (x, y, outcome) in conditions {
        match (b.value(x), b.value(y)) {
            (Some(u), Some(v)) if u.partial_cmp(&v) == Some(outcome) => {}
            (Some(_), Some(_)) => return None,
            _ => guards.push(Guard {
                a: x,
                b: y,
                outcome: Some(outcome),
            }),
        }
    }
    Some(guards)
}

/// A right-hand side's program before it is compiled.
struct Built {
    b: Builder,
    guards: Vec<Guard>,
    layout: Layout,
    /// `(q̇, q̈)`.
    derivative: Vec<u32>,
    /// The second output array (see [`Layout`]); the rates first, where there are some.
    outputs: Vec<u32>,
}

/// The program of `compiled`'s right-hand side, with the rates of the energy balance or without;
/// `None` where the metric is constant but not positive definite (the pivoted elimination's
/// case), where the equations have parameters as inputs, or where a check on constants fails.
fn build(compiled: &Compiled, rates: bool) -> Option<Built> {
    let parts = compiled.native_parts();
    if !parts.parameter_free || matches!(parts.metric, Metric::Indefinite) {
        return None;
    }
    let (n, k) = (parts.n, parts.k);
    let graph = parts.graph;
    let mut b = Builder::default();
    // The graph's nodes the program needs, translated in their order.
    let mut roots: Vec<u32> = parts.outputs.to_vec();
    for g in graph.guards() {
        roots.extend([g.a, g.b]);
    }
    let mut ids = vec![u32::MAX; graph.nodes().len()];
    for id in graph.reachable(&roots) {
        let node = graph.nodes()[id as usize];
        ids[id as usize] = op(&mut b, node, |x| ids[x as usize]);
    }
    let mut guards: Vec<Guard> = graph
        .guards()
        .iter()
        .map(|g| Guard {
            a: ids[g.a as usize],
            b: ids[g.b as usize],
            outcome: g.outcome,
        })
        .collect();
    // The core tape's outputs: r (n), J entries, c (k), W entries, ∂L/∂t, q̇·Q.
    let out: Vec<u32> = parts.outputs.iter().map(|&o| ids[o as usize]).collect();
    let zero = b.constant(0.0);
    let r = &out[..n];
    let mut j = vec![vec![zero; n]; k];
    let mut o = n;
    for &(a, i) in parts.j_entries {
        j[a][i] = out[o];
        o += 1;
    }
    let c = &out[o..o + k];
    o += k;
    let mut w = vec![vec![zero; n]; n];
    let mut w_out = Vec::new();
    for &(i, m) in parts.w_entries {
        w[i][m] = out[o];
        w[m][i] = out[o];
        w_out.push(out[o]);
        o += 1;
    }
    let (dl_dt, power_forces) = (out[o], out[o + 1]);

    // a = W⁻¹ r and the rows of Y = (W⁻¹ Jᵀ)ᵀ.
    let mut a = r.to_vec();
    let mut y = j.clone();
    let mut w_pivots = Vec::new();
    match parts.metric {
        Metric::Diagonal(inv) => {
            for (i, &di) in inv.iter().enumerate() {
                let di = b.constant(di);
                a[i] = b.mul(a[i], di);
                for row in &mut y {
                    row[i] = b.mul(row[i], di);
                }
            }
        }
        Metric::Factor(lf) => {
            let l: Vec<Vec<u32>> = (0..n)
                .map(|i| (0..n).map(|m| b.constant(lf[i * n + m])).collect())
                .collect();
            b.cholesky_solve(&l, &mut a);
            for row in &mut y {
                b.cholesky_solve(&l, row);
            }
        }
        Metric::Varying => {
            let (l, pivots) = b.cholesky(&w);
            w_pivots = pivots;
            b.cholesky_solve(&l, &mut a);
            for row in &mut y {
                b.cholesky_solve(&l, row);
            }
        }
        Metric::Indefinite => return None,
    }
    // S = J Y, S μ = −c − J a, q̈ = a + Y μ.
    let mut mu: Vec<u32> = (0..k)
        .map(|x| {
            let ja = b.dot(&j[x], &a);
            let nc = b.neg(c[x]);
            b.sub(nc, ja)
        })
        .collect();
    // The pivots of S; with one constraint S itself, which need only be positive (as in the
    // interpreted route): the pair (S, S) checks just that.
    let mut s_pivots = Vec::new();
    if k == 1 {
        let s0 = b.dot(&j[0], &y[0]);
        mu[0] = b.div_by_pivot(mu[0], s0);
        s_pivots.push((s0, s0));
    } else if k > 1 {
        let s: Vec<Vec<u32>> = (0..k)
            .map(|x| (0..k).map(|z| b.dot(&j[x], &y[z])).collect())
            .collect();
        let (l, pivots) = b.cholesky(&s);
        s_pivots = pivots;
        b.cholesky_solve(&l, &mut mu);
    }
    for (x, &m) in mu.iter().enumerate() {
        for i in 0..n {
            let p = b.mul(y[x][i], m);
            a[i] = b.add(a[i], p);
        }
    }
    let layout = Layout {
        n,
        k,
        varying: matches!(parts.metric, Metric::Varying),
        w_entries: w_out.len(),
        rates,
    };
    let qd: Vec<u32> = (0..n)
        .map(|i| b.push(Op::Input(1, (n + i) as u32)))
        .collect();
    let derivative: Vec<u32> = qd.iter().chain(&a).copied().collect();
    let mut outputs = Vec::new();
    if rates {
        // Φ = Jᵀ μ and q̇·Φ, summed as the interpreted route sums them.
        let phi: Vec<u32> = (0..n)
            .map(|i| {
                let col: Vec<u32> = j.iter().map(|row| row[i]).collect();
                b.dot(&col, &mu)
            })
            .collect();
        let power = b.dot(&qd, &phi);
        outputs.extend([power, dl_dt, power_forces]);
    }
    outputs.extend(j.iter().flatten());
    outputs.extend(&w_out);
    // The pivots of S with more than one constraint also keep the program to where the Schur
    // complement is accurate: below the null-space ratio the interpreted route solves otherwise.
    let s_floor = if k > 1 {
        NULL_SPACE_PIVOT_RATIO
    } else {
        SINGULAR_PIVOT_RATIO
    };
    let pivots: Vec<(u32, u32, f64)> = w_pivots
        .iter()
        .map(|&(d, a)| (d, a, SINGULAR_PIVOT_RATIO))
        .chain(s_pivots.iter().map(|&(d, a)| (d, a, s_floor)))
        .collect();
    let finite: Vec<u32> = a.iter().chain(&mu).copied().collect();
    guards.extend(checks(&mut b, &pivots, &finite)?);
    debug_assert_eq!(outputs.len(), layout.len());
    Some(Built {
        b,
        guards,
        layout,
        derivative,
        outputs,
    })
}

/// Operations times words of 64 columns beyond which [`Colouring::new`] makes no colouring (8 MiB of
/// bit sets): the models that large are the ones whose Jacobian is dense anyway (the gas of 1000
/// particles, whose constraint couples every velocity, would need 27 MiB).
const PATTERN_MAX_WORDS: usize = 1 << 20;

/// Columns reaching one row beyond which a Jacobian with such a row in more than half its columns
/// is not grouped ([`Colouring::new`]).
const DENSE_ROW: usize = 64;

/// The columns of the right-hand side's Jacobian `∂F/∂(q, q̇, t)` (`2n + 1` columns: `q`, `q̇`,
/// then `t`) in groups no two columns of which have a nonzero in the same row, so that one forward
/// pass seeded along every column of a group gives each of its columns (Curtis, Powell and Reid's
/// compression; the groups by greedy colouring of the columns that share a row). The rows are
/// those of [`NativeJacobian`]: `q̇`, `q̈`, then the three rates of the energy balance where asked
/// for. The nonzeros are those of the program that computes the right-hand side for the recorded
/// structure (which entries any of its operations can reach), so only equations without guards
/// have one: where no branch of the model's code was recorded, every route evaluates the same
/// function, whose derivatives outside the pattern are zero.
#[derive(Debug)]
pub(crate) struct Colouring {
    /// The groups of columns, each evaluated by one pass; columns with no nonzero are in none.
    pub(crate) groups: Vec<Vec<usize>>,
    /// The rows of each column's nonzeros.
    pub(crate) rows: Vec<Vec<usize>>,
}

impl Colouring {
    /// The colouring of `compiled`'s Jacobian, with the rates' rows or without; `None` where the
    /// equations have branches, where they have no program (see [`Prepared::new`]), where
    /// the pattern would take more than [`PATTERN_MAX_WORDS`], or where a row is reached by more
    /// than [`DENSE_ROW`] columns and more than half of them (grouping would save less than half
    /// the passes).
    pub(crate) fn new(compiled: &Compiled, rates: bool) -> Option<Self> {
        if compiled.branches() > 0 {
            return None;
        }
        let Built {
            b,
            derivative,
            outputs,
            layout,
            ..
        } = build(compiled, rates)?;
        let n = layout.n;
        let columns = 2 * n + 1;
        let words = columns.div_ceil(64);
        if b.ops.len().checked_mul(words)? > PATTERN_MAX_WORDS {
            return None;
        }
        // The columns each operation depends on, as bits.
        let mut bits = vec![0u64; b.ops.len() * words];
        for (i, op) in b.ops.iter().enumerate() {
            let (before, rest) = bits.split_at_mut(i * words);
            let own = &mut rest[..words];
            match *op {
                Op::Input(0, _) => own[(2 * n) / 64] |= 1 << ((2 * n) % 64),
                Op::Input(_, j) => own[j as usize / 64] |= 1 << (j % 64),
                _ => {
                    let (operands, count) = op.operands();
                    for &o in &operands[..count] {
                        let from = &before[o as usize * words..][..words];
                        own.iter_mut().zip(from).for_each(|(a, b)| *a |= b);
                    }
                }
            }
        }
        let mut row_ops = derivative;
        if rates {
            row_ops.extend(&outputs[..3]);
        }
        let mut rows = vec![Vec::new(); columns];
        for (r, &op) in row_ops.iter().enumerate() {
            let set = &bits[op as usize * words..][..words];
            for (c, column) in rows.iter_mut().enumerate() {
                if set[c / 64] >> (c % 64) & 1 == 1 {
                    column.push(r);
                }
            }
        }
        // A row reached by `widest` columns needs that many passes: where that is more than half
        // the columns, grouping saves less than half the passes, and for many columns the
        // colouring below (quadratic in the columns of such rows) costs more than it saves.
        let mut per_row = vec![0usize; row_ops.len()];
        rows.iter().flatten().for_each(|&r| per_row[r] += 1);
        let widest = per_row.iter().copied().max().unwrap_or(0);
        if widest > DENSE_ROW && 2 * widest > columns {
            return None;
        }
        // Greedy: each column takes the first group that has no column sharing a row with it
        // (`seen[g] == c + 1`: group `g` has such a column).
        let mut groups: Vec<Vec<usize>> = Vec::new();
        let mut group_of_row: Vec<Vec<usize>> = vec![Vec::new(); row_ops.len()];
        let mut seen: Vec<usize> = Vec::new();
        for (c, column) in rows.iter().enumerate() {
            if column.is_empty() {
                continue;
            }
            for &r in column {
                for &g in &group_of_row[r] {
                    seen[g] = c + 1;
                }
            }
            let g = (0..groups.len())
                .find(|&g| seen[g] != c + 1)
                .unwrap_or(groups.len());
            if g == groups.len() {
                groups.push(Vec::new());
                seen.push(0);
            }
            groups[g].push(c);
            for &r in column {
                group_of_row[r].push(g);
            }
        }
        Some(Self { groups, rows })
    }
}

/// The derivatives of every operation of `b` (those there now) along the `2n + 1` directions `q`,
/// `q̇`, `t`, by forward differentiation written out as operations: `tangents[op][d]`. A zero
/// folds away, so an operation that does not depend on an input costs nothing in its direction.
fn tangents(b: &mut Builder, n: usize) -> Option<Vec<Vec<u32>>> {
    use calls::*;
    let dirs = 2 * n + 1;
    let (zero, one) = (b.constant(0.0), b.constant(1.0));
    let len = b.ops.len();
    let mut tan: Vec<Vec<u32>> = Vec::with_capacity(len);
    for v in 0..len as u32 {
        let op = b.ops[v as usize];
        let t = |x: u32, d: usize, tan: &Vec<Vec<u32>>| tan[x as usize][d];
        // `factor · t(x)` in every direction, the factor made only where some direction needs it.
        let chain =
            |b: &mut Builder, x: u32, tan: &Vec<Vec<u32>>, factor: &dyn Fn(&mut Builder) -> u32| {
                if tan[x as usize].iter().all(|&id| b.value(id) == Some(0.0)) {
                    return vec![zero; dirs];
                }
                let f = factor(b);
                (0..dirs)
                    .map(|d| b.mul(tan[x as usize][d], f))
                    .collect::<Vec<u32>>()
            };
        let row: Vec<u32> = match op {
            Op::Input(0, _) => (0..dirs)
                .map(|d| if d == 2 * n { one } else { zero })
                .collect(),
            Op::Input(_, i) => (0..dirs)
                .map(|d| if d == i as usize { one } else { zero })
                .collect(),
            Op::Const(_) => vec![zero; dirs],
            Op::Add(x, y) => (0..dirs)
                .map(|d| b.add(t(x, d, &tan), t(y, d, &tan)))
                .collect(),
            Op::Sub(x, y) => (0..dirs)
                .map(|d| b.sub(t(x, d, &tan), t(y, d, &tan)))
                .collect(),
            Op::Neg(x) => (0..dirs).map(|d| b.neg(t(x, d, &tan))).collect(),
            Op::Mul(x, y) => (0..dirs)
                .map(|d| {
                    let p = b.mul(t(x, d, &tan), y);
                    let q = b.mul(x, t(y, d, &tan));
                    b.add(p, q)
                })
                .collect(),
            Op::Div(x, y) => (0..dirs)
                .map(|d| {
                    let p = b.mul(v, t(y, d, &tan));
                    let q = b.sub(t(x, d, &tan), p);
                    b.div(q, y)
                })
                .collect(),
            Op::Sqrt(x) => chain(b, x, &tan, &|b| {
                let two = b.constant(2.0);
                let tv = b.mul(two, v);
                b.div(one, tv)
            }),
            Op::Abs(x) => chain(b, x, &tan, &|b| b.push(Op::Unary(signum, x))),
            Op::WithInt(_, x, k) => chain(b, x, &tan, &|b| {
                let c = b.constant(f64::from(k));
                if k == 0 {
                    return b.constant(0.0);
                }
                let p = b.push(Op::WithInt(powi, x, k - 1));
                b.mul(c, p)
            }),
            Op::Binary(_, x, y) => match b.kinds.get(&v).copied() {
                Some(Kind::Powf) => chain(b, x, &tan, &|b| {
                    let p = b.value(y).unwrap_or(f64::NAN);
                    let c = b.constant(p);
                    let pm = b.constant(p - 1.0);
                    let q = b.push(Op::Binary(powf, x, pm));
                    b.mul(c, q)
                }),
                // atan2(x, y) = θ of the point (y, x): dθ = (y dx − x dy) / (x² + y²).
                _ => {
                    let xx = b.mul(x, x);
                    let yy = b.mul(y, y);
                    let r2 = b.add(xx, yy);
                    (0..dirs)
                        .map(|d| {
                            let p = b.mul(y, t(x, d, &tan));
                            let q = b.mul(x, t(y, d, &tan));
                            let num = b.sub(p, q);
                            b.div(num, r2)
                        })
                        .collect()
                }
            },
            Op::Unary(_, x) => {
                let Some(Kind::Fun(f)) = b.kinds.get(&v).copied() else {
                    return None;
                };
                chain(b, x, &tan, &|b| derivative(b, f, x, v))
            }
        };
        tan.push(row);
    }
    Some(tan)
}

/// `f′(x)` as operations, `v = f(x)` already computed.
fn derivative(b: &mut Builder, f: Fun, x: u32, v: u32) -> u32 {
    use calls::*;
    let one = b.constant(1.0);
    let sq = |b: &mut Builder, a: u32| b.mul(a, a);
    let inv_sqrt = |b: &mut Builder, a: u32| {
        let r = b.push(Op::Sqrt(a));
        b.div(one, r)
    };
    match f {
        Fun::Sin => b.push(Op::Unary(cos, x)),
        Fun::Cos => {
            let s = b.push(Op::Unary(sin, x));
            b.neg(s)
        }
        Fun::Tan => {
            let v2 = sq(b, v);
            b.add(one, v2)
        }
        Fun::Exp => v,
        Fun::Exp2 => {
            let c = b.constant(std::f64::consts::LN_2);
            b.mul(v, c)
        }
        Fun::ExpM1 => b.add(v, one),
        Fun::Ln => b.div(one, x),
        Fun::Log2 | Fun::Log10 => {
            let c = b.constant(if matches!(f, Fun::Log2) {
                std::f64::consts::LN_2
            } else {
                std::f64::consts::LN_10
            });
            let xc = b.mul(x, c);
            b.div(one, xc)
        }
        Fun::Ln1p => {
            let a = b.add(one, x);
            b.div(one, a)
        }
        Fun::Cbrt => {
            let three = b.constant(3.0);
            let v2 = sq(b, v);
            let d = b.mul(three, v2);
            b.div(one, d)
        }
        Fun::Asin | Fun::Acos => {
            let x2 = sq(b, x);
            let a = b.sub(one, x2);
            let r = inv_sqrt(b, a);
            if matches!(f, Fun::Asin) {
                r
            } else {
                b.neg(r)
            }
        }
        Fun::Atan => {
            let x2 = sq(b, x);
            let a = b.add(one, x2);
            b.div(one, a)
        }
        Fun::Sinh => b.push(Op::Unary(cosh, x)),
        Fun::Cosh => b.push(Op::Unary(sinh, x)),
        Fun::Tanh => {
            let v2 = sq(b, v);
            b.sub(one, v2)
        }
        Fun::Asinh => {
            let x2 = sq(b, x);
            let a = b.add(x2, one);
            inv_sqrt(b, a)
        }
        Fun::Acosh => {
            let x2 = sq(b, x);
            let a = b.sub(x2, one);
            inv_sqrt(b, a)
        }
        Fun::Atanh => {
            let x2 = sq(b, x);
            let a = b.sub(one, x2);
            b.div(one, a)
        }
        Fun::Signum => b.constant(0.0),
        // Translated to operations of their own, never calls.
        Fun::Sqrt | Fun::Abs | Fun::Recip => b.constant(f64::NAN),
    }
}

/// The integrator's Jacobian `∂F/∂y` and `∂F/∂t` of compiled equations as machine code: the
/// right-hand side's program differentiated forward along `q`, `q̇` and `t` ([`tangents`]), with
/// its checks. Rows: `q̇` (n), `q̈` (n), then the rates where compiled with them; columns `q`,
/// `q̇` (the quadratures do not feed back).
#[derive(Debug)]
pub(crate) struct NativeJacobian {
    native: Native,
    n: usize,
    rates: bool,
}

impl NativeJacobian {
    /// The Jacobian's program for `compiled`, compiled with `effort` (see [`Prepared::new`] for
    /// when there is none).
    pub(crate) fn new(compiled: &Compiled, rates: bool, effort: Effort) -> Option<Self> {
        let Built {
            mut b,
            guards,
            layout,
            derivative,
            outputs,
        } = build(compiled, rates)?;
        let n = layout.n;
        let tan = tangents(&mut b, n)?;
        let mut rows: Vec<u32> = derivative;
        if rates {
            rows.extend(&outputs[..3]);
        }
        let jac: Vec<u32> = rows
            .iter()
            .flat_map(|&r| tan[r as usize][..2 * n].to_vec())
            .collect();
        let dfdt: Vec<u32> = rows.iter().map(|&r| tan[r as usize][2 * n]).collect();
        if b.ops.len() > MAX_OPERATIONS {
            return None;
        }
        let program = Program {
            inputs: [1, 2 * n],
            ops: b.ops,
            outputs: [jac, dfdt],
            guards,
        };
        let native = Native::compile_with(&program, effort).ok()?;
        Some(Self { native, n, rates })
    }

    /// The rows: `2n`, and 3 with the rates.
    pub(crate) fn rows(&self) -> usize {
        2 * self.n + if self.rates { 3 } else { 0 }
    }

    /// `∂F/∂(q, q̇)` (row-major, [`NativeJacobian::rows`] × `2n`) into `jac` and `∂F/∂t` into `dfdt`
    /// at `t` and `y = (q, q̇)`; `false` where the interpreted route must decide, or a length is
    /// not the program's.
    pub(crate) fn evaluate(&self, t: f64, y: &[f64], jac: &mut [f64], dfdt: &mut [f64]) -> bool {
        self.native.call([std::slice::from_ref(&t), y], [jac, dfdt]) == Ok(true)
    }
}

/// The program of a right-hand side, built and checked, ready to be compiled at either effort
/// ([`Prepared::compile`]); it owns what it needs, so that another thread may compile it.
#[derive(Debug)]
pub(crate) struct Prepared {
    program: Program,
    layout: Layout,
    w_scale: f64,
}

impl Prepared {
    /// The program of `compiled`'s right-hand side, with the rates of the energy balance or
    /// without; `None` where the metric is constant but not positive definite (the pivoted
    /// elimination's case), where the equations have parameters as inputs, or beyond
    /// [`MAX_OPERATIONS`].
    pub(crate) fn new(compiled: &Compiled, rates: bool) -> Option<Self> {
        let built = build(compiled, rates)?;
        if built.b.ops.len() > MAX_OPERATIONS {
            return None;
        }
        Some(Self {
            program: Program {
                inputs: [1, 2 * built.layout.n],
                ops: built.b.ops,
                outputs: [built.derivative, built.outputs],
                guards: built.guards,
            },
            layout: built.layout,
            w_scale: compiled.native_parts().w_scale,
        })
    }

    /// The number of operations of the program.
    pub(crate) fn operations(&self) -> usize {
        self.program.ops.len()
    }

    /// The program as machine code, compiled with `effort`; `None` where no machine code can be
    /// made on this host. Every effort's code gives the same bits.
    pub(crate) fn compile(&self, effort: Effort) -> Option<NativeEquations> {
        let native = Native::compile_with(&self.program, effort).ok()?;
        Some(NativeEquations {
            native,
            layout: self.layout,
            w_scale: self.w_scale,
            effort,
        })
    }
}

impl NativeEquations {
    /// How hard the code generator worked on it.
    pub(crate) fn effort(&self) -> Effort {
        self.effort
    }

    /// The number of operations of the program.
    pub(crate) fn operations(&self) -> usize {
        self.native.operations()
    }

    /// Scratch space for [`NativeEquations::evaluate`].
    pub(crate) fn buffers(&self) -> NativeBuffers {
        NativeBuffers {
            outputs: vec![0.0; self.native.outputs()[1]],
        }
    }

    /// Runs the program at `t` and the state `y = (q, q̇)` (length `2n`), writing the state's
    /// derivative `(q̇, q̈)` to `dy` (length `2n`) and the rest to `buf` (made by
    /// [`NativeEquations::buffers`]): [`NativeEquations::rates`] and [`NativeEquations::fill`]
    /// read it. Returns `false` where the interpreted route must decide (see the module docs),
    /// with `dy` partly written, and where a length is not the equations'.
    #[inline]
    pub(crate) fn evaluate(
        &self,
        buf: &mut NativeBuffers,
        t: f64,
        y: &[f64],
        dy: &mut [f64],
    ) -> bool {
        self.native
            .call([std::slice::from_ref(&t), y], [dy, &mut buf.outputs])
            == Ok(true)
    }

    /// `(q̇·Φ, ∂L/∂t, q̇·Q)` of the last evaluation, with the rates compiled in.
    #[inline]
    pub(crate) fn rates(&self, buf: &NativeBuffers) -> Option<[f64; 3]> {
        let o = &buf.outputs;
        self.layout.rates.then(|| [o[0], o[1], o[2]])
    }

    /// Writes what the singular-point check reads of the last evaluation into `d` (of the model's
    /// sizes): `J` and `max |W_ij|`.
    pub(crate) fn fill(&self, buf: &NativeBuffers, d: &mut Dynamics<f64>) {
        let l = &self.layout;
        let o = &buf.outputs;
        // Element by element: `copy_from_slice` calls `memcpy`, which costs more for a few words.
        for (x, &v) in d.j.iter_mut().zip(&o[l.j()..l.w()]) {
            *x = v;
        }
        d.w_scale = if l.varying {
            o[l.w()..l.len()].iter().fold(0.0f64, |m, v| m.max(v.abs()))
        } else {
            self.w_scale
        };
        // The program runs only through the Cholesky factors of W and S: positive definite.
        d.det_sign = 1.0;
    }
}
