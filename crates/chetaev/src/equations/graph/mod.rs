//! An expression graph of a model, recorded once by evaluating the user's `L`, `f`, `h`, `Q` and
//! `D` with a tracing scalar ([`Sym`]), then differentiated symbolically, folded and shared, and
//! evaluated as a compact [`Tape`].
//!
//! This is how the library finds a model's structure by itself (in the manner of CasADi's SX
//! graphs): a block whose expression folds to `0` is identically zero; one that depends on no input
//! is constant and computed once; the inputs each expression depends on give the sparsity of `W`,
//! `J` and the reduced Jacobian. These are proofs about the recorded expressions, not samples.
//!
//! - Every node is created once (hash-consing): equal subexpressions are shared.
//! - Constants fold at creation, with the algebraic identities `x + 0`, `x·1`, `x·0`, `x − x`, ...
//!   (`x·0 = 0` also where `x` would be infinite: the finiteness of `L` and `f` themselves is
//!   checked where they are evaluated, at the start, at recorded points and in a fallback).
//! - A comparison of recorded values (a branch in the user's code: `if x > 0.0`) becomes a
//!   [`Guard`]: the tape re-checks it at every evaluation and reports a flip, and the engine then
//!   falls back to the dual-number path for that evaluation.
//! - So does the bound of the domain of `ln`, `log2`, `log10`, `ln_1p` and `atanh`, whose
//!   derivatives stay finite outside it (`1/x` for `ln x` at `x < 0`): the fallback evaluates the
//!   value, NaN there, and reports it. The other functions' derivatives are NaN wherever their
//!   value is (`√x` and `1/(2√x)`, `asin x` and `1/√(1 − x²)`, `x^a` and `a x^(a−1)`).
//! - A value taken out of the graph (`x.re()` on a recorded value) cannot be followed: the
//!   recording is marked as escaped and not used.
//!
//! The graph is thread-local while recording ([`record`]); a finished [`Graph`] is plain data.

mod diff;
mod sym;
mod tape;
mod text;

pub use sym::Sym;
pub use tape::{GuardFlip, Tape};
pub(crate) use text::Printer;
pub use text::{latex_symbol, number, Style};

use std::cell::RefCell;
use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

use crate::model::Real;

/// Elementary functions of one argument.
#[allow(missing_docs)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Fun {
    Sqrt,
    Cbrt,
    Exp,
    Exp2,
    ExpM1,
    Ln,
    Log2,
    Log10,
    Ln1p,
    Sin,
    Cos,
    Tan,
    Asin,
    Acos,
    Atan,
    Sinh,
    Cosh,
    Tanh,
    Asinh,
    Acosh,
    Atanh,
    Abs,
    Signum,
    Recip,
}

impl Fun {
    /// `f(x)` for any scalar.
    #[inline]
    pub fn apply<T: Real>(self, x: T) -> T {
        match self {
            Fun::Sqrt => x.sqrt(),
            Fun::Cbrt => x.cbrt(),
            Fun::Exp => x.exp(),
            Fun::Exp2 => x.exp2(),
            Fun::ExpM1 => x.exp_m1(),
            Fun::Ln => x.ln(),
            Fun::Log2 => x.log2(),
            Fun::Log10 => x.log10(),
            Fun::Ln1p => x.ln_1p(),
            Fun::Sin => x.sin(),
            Fun::Cos => x.cos(),
            Fun::Tan => x.tan(),
            Fun::Asin => x.asin(),
            Fun::Acos => x.acos(),
            Fun::Atan => x.atan(),
            Fun::Sinh => x.sinh(),
            Fun::Cosh => x.cosh(),
            Fun::Tanh => x.tanh(),
            Fun::Asinh => x.asinh(),
            Fun::Acosh => x.acosh(),
            Fun::Atanh => x.atanh(),
            Fun::Abs => x.abs(),
            // `f64::signum` of the value for every scalar, the slope zero: the rule the graph
            // differentiates `abs` by (num-dual's own `signum` of a dual number is 0 at `-0.0`).
            Fun::Signum => T::from(x.re().signum()),
            Fun::Recip => x.recip(),
        }
    }

    /// The name used when printing.
    pub fn name(self) -> &'static str {
        match self {
            Fun::Sqrt => "sqrt",
            Fun::Cbrt => "cbrt",
            Fun::Exp => "exp",
            Fun::Exp2 => "exp2",
            Fun::ExpM1 => "expm1",
            Fun::Ln => "ln",
            Fun::Log2 => "log2",
            Fun::Log10 => "log10",
            Fun::Ln1p => "ln1p",
            Fun::Sin => "sin",
            Fun::Cos => "cos",
            Fun::Tan => "tan",
            Fun::Asin => "asin",
            Fun::Acos => "acos",
            Fun::Atan => "atan",
            Fun::Sinh => "sinh",
            Fun::Cosh => "cosh",
            Fun::Tanh => "tanh",
            Fun::Asinh => "asinh",
            Fun::Acosh => "acosh",
            Fun::Atanh => "atanh",
            Fun::Abs => "abs",
            Fun::Signum => "sign",
            Fun::Recip => "recip",
        }
    }
}

/// One node of the graph; operands are indices of earlier nodes, so the node list is in
/// topological order.
#[allow(missing_docs)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Node {
    Const(f64),
    /// Input number `i` (the engine's layout: `t`, then `q`, then `q̇`).
    Input(u32),
    Add(u32, u32),
    Sub(u32, u32),
    Mul(u32, u32),
    Div(u32, u32),
    Neg(u32),
    Powi(u32, i32),
    Powf(u32, f64),
    Atan2(u32, u32),
    Fun(Fun, u32),
}

/// `x^p` for any scalar. num-dual forms `x^p` and its derivatives from `x^(p−3)·x³`, which is
/// `∞·0 = NaN` at `x = 0` for `p < 3`, even where every derivative it carries is `0` (`p` above
/// their highest order): there the value and those derivatives are returned as the zeros they are.
#[inline]
pub(super) fn powf<T: Real>(x: T, p: f64) -> T {
    if x.re() == 0.0 && p > f64::from(T::NDERIV as u32) {
        // The value as f64 gives it (−0 for `(−0)^3`), the derivatives zero.
        T::from(x.re().powf(p))
    } else {
        x.powf(p)
    }
}

impl Node {
    /// A bit for this node's kind of operation, its operands and parameters aside (the kinds
    /// modulo 64: functions beyond the 53rd share bits).
    #[inline]
    pub(crate) fn kind_bit(&self) -> u64 {
        1 << (key(self).0 % 64)
    }

    /// The value of this node from its operands' values `v`.
    #[inline]
    pub fn eval<T: Real>(&self, v: impl Fn(u32) -> T) -> T {
        match *self {
            Node::Const(c) => T::from(c),
            Node::Input(_) => unreachable!("inputs are set, not evaluated"),
            Node::Add(a, b) => v(a) + v(b),
            Node::Sub(a, b) => v(a) - v(b),
            Node::Mul(a, b) => v(a) * v(b),
            Node::Div(a, b) => v(a) / v(b),
            Node::Neg(a) => -v(a),
            Node::Powi(a, n) => v(a).powi(n),
            Node::Powf(a, p) => powf(v(a), p),
            Node::Atan2(a, b) => v(a).atan2(v(b)),
            Node::Fun(f, a) => f.apply(v(a)),
        }
    }

    /// This node with operand number `i` (0 or 1), `o`, replaced by `f(i, o)`.
    pub fn map_operands(self, f: impl Fn(usize, u32) -> u32) -> Node {
        match self {
            Node::Const(_) | Node::Input(_) => self,
            Node::Add(a, b) => Node::Add(f(0, a), f(1, b)),
            Node::Sub(a, b) => Node::Sub(f(0, a), f(1, b)),
            Node::Mul(a, b) => Node::Mul(f(0, a), f(1, b)),
            Node::Div(a, b) => Node::Div(f(0, a), f(1, b)),
            Node::Neg(a) => Node::Neg(f(0, a)),
            Node::Powi(a, n) => Node::Powi(f(0, a), n),
            Node::Powf(a, p) => Node::Powf(f(0, a), p),
            Node::Atan2(a, b) => Node::Atan2(f(0, a), f(1, b)),
            Node::Fun(fun, a) => Node::Fun(fun, f(0, a)),
        }
    }

    /// The operands.
    pub fn operands(&self) -> ([u32; 2], usize) {
        match *self {
            Node::Const(_) | Node::Input(_) => ([0, 0], 0),
            Node::Neg(a) | Node::Powi(a, _) | Node::Powf(a, _) | Node::Fun(_, a) => ([a, 0], 1),
            Node::Add(a, b)
            | Node::Sub(a, b)
            | Node::Mul(a, b)
            | Node::Div(a, b)
            | Node::Atan2(a, b) => ([a, b], 2),
        }
    }
}

/// A fast hasher for the graph's small integer keys (the multiplicative hash of rustc's FxHasher):
/// the standard SipHash costs more than everything else in recording a small model, and the keys
/// here come from the library, not from an adversary.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Fx(u64);

impl Hasher for Fx {
    #[inline]
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(u64::from(b));
        }
    }
    #[inline]
    fn write_u8(&mut self, i: u8) {
        self.write_u64(u64::from(i));
    }
    #[inline]
    fn write_u32(&mut self, i: u32) {
        self.write_u64(u64::from(i));
    }
    #[inline]
    fn write_u64(&mut self, i: u64) {
        self.0 = (self.0.rotate_left(5) ^ i).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
    #[inline]
    fn write_usize(&mut self, i: usize) {
        self.write_u64(i as u64);
    }
    #[inline]
    fn finish(&self) -> u64 {
        self.0
    }
}

/// A hash map keyed by the graph's integers.
pub(crate) type FastMap<K, V> = HashMap<K, V, BuildHasherDefault<Fx>>;

/// The hash-consing key of a node (floating-point payloads by their bits).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
struct Key(u8, u32, u32, u64);

fn key(node: &Node) -> Key {
    match *node {
        Node::Const(c) => Key(0, 0, 0, c.to_bits()),
        Node::Input(i) => Key(1, i, 0, 0),
        Node::Add(a, b) => Key(2, a, b, 0),
        Node::Sub(a, b) => Key(3, a, b, 0),
        Node::Mul(a, b) => Key(4, a, b, 0),
        Node::Div(a, b) => Key(5, a, b, 0),
        Node::Neg(a) => Key(6, a, 0, 0),
        Node::Powi(a, n) => Key(7, a, n as u32, 0),
        Node::Powf(a, p) => Key(8, a, 0, p.to_bits()),
        Node::Atan2(a, b) => Key(9, a, b, 0),
        Node::Fun(f, a) => Key(10 + f as u8, a, 0, 0),
    }
}

/// On which inputs a node depends, as bits: [`DEP_T`], [`DEP_Q`], [`DEP_QD`].
pub type Deps = u8;
/// Depends on time.
pub const DEP_T: Deps = 1;
/// Depends on a position.
pub const DEP_Q: Deps = 2;
/// Depends on a velocity.
pub const DEP_QD: Deps = 4;
/// Depends on a model parameter (read with [`Real::parameter`](crate::model::Real::parameter)).
pub const DEP_P: Deps = 8;

/// A comparison made while recording, with its outcome there.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Guard {
    /// Left operand (a node).
    pub a: u32,
    /// Right operand (a node).
    pub b: u32,
    /// `a.partial_cmp(b)` when recorded.
    pub outcome: Option<std::cmp::Ordering>,
    /// A bound of an elementary function's domain (`x > 0` under `ln x`), not a branch of the
    /// model's code: where it flips the value is NaN while the derivatives may not be (`1/x`), and
    /// the dual-number evaluation it falls back to reports it. It changes no structure.
    pub domain: bool,
}

/// A recorded expression graph.
#[derive(Debug, Default)]
pub struct Graph {
    nodes: Vec<Node>,
    deps: Vec<Deps>,
    /// Each node's value at the recorded point.
    values: Vec<f64>,
    map: FastMap<Key, u32>,
    guards: Vec<Guard>,
    escaped: bool,
    /// Input classes, by input number.
    inputs: Vec<Deps>,
    /// Visit stamps of [`Graph::reachable`], and the last stamp used.
    marks: std::sync::Mutex<(Vec<u64>, u64)>,
}

impl Clone for Graph {
    fn clone(&self) -> Self {
        Self {
            nodes: self.nodes.clone(),
            deps: self.deps.clone(),
            values: self.values.clone(),
            map: self.map.clone(),
            guards: self.guards.clone(),
            escaped: self.escaped,
            inputs: self.inputs.clone(),
            marks: std::sync::Mutex::default(),
        }
    }
}

/// A node index that is a free constant in a [`Sym`] (no node yet).
pub(crate) const FREE: u32 = u32::MAX;

impl Graph {
    /// The nodes, in topological order.
    pub fn nodes(&self) -> &[Node] {
        &self.nodes
    }

    /// The dependence bits of node `id`.
    pub fn deps(&self, id: u32) -> Deps {
        self.deps[id as usize]
    }

    /// The comparisons recorded as guards.
    pub fn guards(&self) -> &[Guard] {
        &self.guards
    }

    /// The number of guards that are branches of the model's code (not bounds of a domain).
    pub fn branches(&self) -> usize {
        self.guards.iter().filter(|g| !g.domain).count()
    }

    /// Whether a recorded value left the graph (`re()`), so that the recording cannot be trusted.
    pub fn escaped(&self) -> bool {
        self.escaped
    }

    /// The constant value of `id`, if it is a constant node.
    pub fn constant(&self, id: u32) -> Option<f64> {
        match self.nodes[id as usize] {
            Node::Const(c) => Some(c),
            _ => None,
        }
    }

    /// The value of `id` at the recorded point.
    pub fn value(&self, id: u32) -> f64 {
        self.values[id as usize]
    }

    /// The size of the rounding error of `id`'s value, in units of the unit roundoff: the running
    /// bound `E_i = |v_i| + Σ_j |∂v_i/∂v_j| E_j` over the operations that make it (Wilkinson's
    /// first-order bound, with every input and constant taken as rounded once). A value that is
    /// the difference of large terms (`0.3 − 0.1·3 cos x` next to `x = 0`) has `E` of the terms'
    /// size, where `|v|` itself is of the size of the rounding: `ε·E` is how far from zero a
    /// computed residual can be that is zero exactly.
    pub fn rounding_scale(&self, id: u32) -> f64 {
        let end = id as usize + 1;
        let mut e = vec![0.0f64; end];
        let v = &self.values;
        for i in 0..end {
            let a = |k: u32| (v[k as usize], e[k as usize]);
            let propagated = match self.nodes[i] {
                Node::Const(_) | Node::Input(_) => 0.0,
                Node::Add(x, y) | Node::Sub(x, y) => e[x as usize] + e[y as usize],
                Node::Mul(x, y) => {
                    let ((vx, ex), (vy, ey)) = (a(x), a(y));
                    ex * vy.abs() + vx.abs() * ey
                }
                Node::Div(x, y) => {
                    let ((vx, ex), (vy, ey)) = (a(x), a(y));
                    (ex + (vx / vy).abs() * ey) / vy.abs()
                }
                Node::Neg(x) => e[x as usize],
                Node::Powi(x, n) => {
                    let (vx, ex) = a(x);
                    f64::from(n).abs() * vx.abs().powi(n - 1) * ex
                }
                Node::Powf(x, p) => {
                    let (vx, ex) = a(x);
                    p.abs() * vx.abs().powf(p - 1.0) * ex
                }
                Node::Atan2(y, x) => {
                    let ((vy, ey), (vx, ex)) = (a(y), a(x));
                    (vx.abs() * ey + vy.abs() * ex) / (vx * vx + vy * vy)
                }
                Node::Fun(f, x) => {
                    let (vx, ex) = a(x);
                    let slope = f.apply(num_dual::Dual64::new(vx, 1.0)).eps;
                    slope.abs() * ex
                }
            };
            e[i] = v[i].abs() + propagated;
            if !e[i].is_finite() {
                // A derivative that is infinite at the point (a square root at 0): no bound.
                e[i] = f64::INFINITY;
            }
        }
        e[id as usize]
    }

    /// Whether `id` is the constant zero.
    pub fn is_zero(&self, id: u32) -> bool {
        self.constant(id) == Some(0.0)
    }

    /// A new input node of class `class` with value `value`; inputs are numbered in creation order.
    pub fn input(&mut self, class: Deps, value: f64) -> u32 {
        let i = self.inputs.len() as u32;
        self.inputs.push(class);
        let id = self.nodes.len() as u32;
        self.nodes.push(Node::Input(i));
        self.deps.push(class);
        self.values.push(value);
        id
    }

    /// The constant `c` as a node.
    pub fn constant_node(&mut self, c: f64) -> u32 {
        self.intern(Node::Const(c))
    }

    /// The id of `node` (its operands given as node ids) if the graph holds it.
    pub(crate) fn find(&self, node: &Node) -> Option<u32> {
        self.map.get(&key(node)).copied()
    }

    fn intern(&mut self, node: Node) -> u32 {
        let k = key(&node);
        if let Some(&id) = self.map.get(&k) {
            return id;
        }
        let (ops, count) = node.operands();
        let deps = ops[..count]
            .iter()
            .fold(0, |d, &o| d | self.deps[o as usize]);
        let value = match node {
            Node::Const(c) => c,
            _ => node.eval(|o| self.values[o as usize]),
        };
        let id = self.nodes.len() as u32;
        self.nodes.push(node);
        self.deps.push(deps);
        self.values.push(value);
        self.map.insert(k, id);
        id
    }

    /// Adds `node` after folding constants and applying algebraic identities; returns its id.
    pub fn push(&mut self, node: Node) -> u32 {
        let c = |g: &Self, id: u32| g.constant(id);
        // Fold a node whose operands are all constant.
        let (ops, count) = node.operands();
        if count > 0 && ops[..count].iter().all(|&o| c(self, o).is_some()) {
            let v = node.eval(|o| self.values[o as usize]);
            return self.constant_node(v);
        }
        let node = match node {
            Node::Add(a, b) => {
                if c(self, a) == Some(0.0) {
                    return b;
                }
                if c(self, b) == Some(0.0) {
                    return a;
                }
                if let Node::Neg(nb) = self.nodes[b as usize] {
                    return self.push(Node::Sub(a, nb));
                }
                Node::Add(a.min(b), a.max(b))
            }
            Node::Sub(a, b) => {
                if a == b {
                    return self.constant_node(0.0);
                }
                if c(self, b) == Some(0.0) {
                    return a;
                }
                if c(self, a) == Some(0.0) {
                    return self.push(Node::Neg(b));
                }
                if let Node::Neg(nb) = self.nodes[b as usize] {
                    return self.push(Node::Add(a, nb));
                }
                Node::Sub(a, b)
            }
            Node::Mul(a, b) => {
                for (x, y) in [(a, b), (b, a)] {
                    match c(self, x) {
                        Some(0.0) => return self.constant_node(0.0),
                        Some(1.0) => return y,
                        Some(-1.0) => return self.push(Node::Neg(y)),
                        _ => {}
                    }
                }
                Node::Mul(a.min(b), a.max(b))
            }
            Node::Div(a, b) => {
                if c(self, b) == Some(1.0) {
                    return a;
                }
                if c(self, a) == Some(0.0) {
                    return a;
                }
                if c(self, a) == Some(1.0) {
                    return self.push(Node::Fun(Fun::Recip, b));
                }
                Node::Div(a, b)
            }
            Node::Neg(a) => {
                if let Node::Neg(x) = self.nodes[a as usize] {
                    return x;
                }
                Node::Neg(a)
            }
            Node::Powi(a, n) => match n {
                0 => return self.constant_node(1.0),
                1 => return a,
                2 => return self.push(Node::Mul(a, a)),
                -1 => return self.push(Node::Fun(Fun::Recip, a)),
                _ => Node::Powi(a, n),
            },
            Node::Powf(a, p) => {
                if p == 1.0 {
                    return a;
                }
                if p == 0.0 {
                    return self.constant_node(1.0);
                }
                Node::Powf(a, p)
            }
            other => other,
        };
        self.intern(node)
    }

    /// Shorthands for building derivative expressions.
    pub(crate) fn add(&mut self, a: u32, b: u32) -> u32 {
        self.push(Node::Add(a, b))
    }
    pub(crate) fn sub(&mut self, a: u32, b: u32) -> u32 {
        self.push(Node::Sub(a, b))
    }
    pub(crate) fn mul(&mut self, a: u32, b: u32) -> u32 {
        self.push(Node::Mul(a, b))
    }
    pub(crate) fn div(&mut self, a: u32, b: u32) -> u32 {
        self.push(Node::Div(a, b))
    }
    pub(crate) fn neg(&mut self, a: u32) -> u32 {
        self.push(Node::Neg(a))
    }
    pub(crate) fn scale(&mut self, s: f64, a: u32) -> u32 {
        let s = self.constant_node(s);
        self.mul(s, a)
    }
    pub(crate) fn fun(&mut self, f: Fun, a: u32) -> u32 {
        self.push(Node::Fun(f, a))
    }

    /// Records a comparison of two nodes: a branch of the model's code, or a bound of an
    /// elementary function's domain (`domain`).
    pub(crate) fn guard(
        &mut self,
        a: u32,
        b: u32,
        outcome: Option<std::cmp::Ordering>,
        domain: bool,
    ) {
        let g = Guard {
            a,
            b,
            outcome,
            domain,
        };
        if !self.guards.contains(&g) {
            self.guards.push(g);
        }
    }

    /// The nodes reachable from `roots`, in ascending (topological) order. The work is in the
    /// number of nodes reached, not in the size of the graph (visits are marked with a stamp per
    /// call in a buffer kept with the graph).
    pub fn reachable(&self, roots: &[u32]) -> Vec<u32> {
        let mut marks = self.marks.lock().unwrap_or_else(|e| e.into_inner());
        let (stamps, epoch) = &mut *marks;
        *epoch += 1;
        if stamps.len() < self.nodes.len() {
            stamps.resize(self.nodes.len(), 0);
        }
        let mut out = Vec::with_capacity(64);
        let mut stack: Vec<u32> = Vec::with_capacity(64);
        stack.extend_from_slice(roots);
        while let Some(id) = stack.pop() {
            let stamp = &mut stamps[id as usize];
            if *stamp == *epoch {
                continue;
            }
            *stamp = *epoch;
            out.push(id);
            let (ops, count) = self.nodes[id as usize].operands();
            stack.extend_from_slice(&ops[..count]);
        }
        out.sort_unstable();
        out
    }
}

thread_local! {
    static RECORDING: RefCell<Option<Graph>> = const { RefCell::new(None) };
    /// While recording with parameters as inputs: each parameter read so far, by name, with its
    /// input scalar; and the first one read again with another value.
    static PARAMETERS: RefCell<Option<Reads>> = const { RefCell::new(None) };
}

/// The parameters read while recording.
#[derive(Default)]
struct Reads {
    list: Vec<(String, Sym)>,
    conflict: Option<ParameterConflict>,
}

/// A parameter read twice under one name with two values: the recording cannot say which one a
/// derivative with respect to it is about.
#[derive(Clone, Debug, PartialEq)]
pub struct ParameterConflict {
    /// The name.
    pub name: String,
    /// The value read first.
    pub first: f64,
    /// The other value.
    pub second: f64,
}

/// The parameter `name` with value `value` in the graph being recorded: an input of class
/// [`DEP_P`] (the same one each time the name is read) when the recording takes parameters as
/// inputs ([`record_with_parameters`]), else the constant `value`.
pub(crate) fn parameter(name: &str, value: f64) -> Sym {
    PARAMETERS.with(|p| {
        let mut p = p.borrow_mut();
        let Some(reads) = p.as_mut() else {
            return Sym::constant(value);
        };
        if let Some((_, s)) = reads.list.iter().find(|(n, _)| n == name) {
            if s.value().to_bits() != value.to_bits() && reads.conflict.is_none() {
                reads.conflict = Some(ParameterConflict {
                    name: name.to_string(),
                    first: s.value(),
                    second: value,
                });
            }
            return *s;
        }
        let s = Sym::input(DEP_P, value);
        reads.list.push((name.to_string(), s));
        s
    })
}

/// [`record`] with every parameter that `f` reads ([`parameter`]) an input of the graph. Returns
/// also the parameters read, in the order first read, each as `(name, value, input number,
/// node)`, or the first name read with two values.
#[allow(clippy::type_complexity)]
pub fn record_with_parameters<O>(
    f: impl FnOnce() -> O,
) -> Result<(Graph, O, Vec<(String, f64, u32, u32)>), ParameterConflict> {
    struct Reset;
    impl Drop for Reset {
        fn drop(&mut self) {
            PARAMETERS.with(|p| *p.borrow_mut() = None);
        }
    }
    let mut read = Vec::new();
    let mut conflict = None;
    let (graph, out) = record(|| {
        PARAMETERS.with(|p| *p.borrow_mut() = Some(Reads::default()));
        let reset = Reset;
        let out = f();
        let reads = PARAMETERS
            .with(|p| p.borrow_mut().take())
            .unwrap_or_default();
        conflict = reads.conflict;
        read = with_graph(|g| {
            reads
                .list
                .into_iter()
                .map(|(name, s)| match g.nodes[s.node_id() as usize] {
                    Node::Input(i) => (name, s.value(), i, s.node_id()),
                    _ => unreachable!("a parameter is made as an input"),
                })
                .collect()
        });
        drop(reset);
        out
    });
    match conflict {
        Some(c) => Err(c),
        None => Ok((graph, out, read)),
    }
}

/// Runs `f` on the graph being recorded on this thread. Outside [`record`] there is none, and a
/// [`Sym`] can then only be a free constant.
pub(crate) fn with_graph<R>(f: impl FnOnce(&mut Graph) -> R) -> R {
    RECORDING.with(|r| {
        let mut r = r.borrow_mut();
        let g = r
            .as_mut()
            .unwrap_or_else(|| unreachable!("a recorded Sym is used only while recording"));
        f(g)
    })
}

/// Records on this thread: `f` receives a fresh graph's builder (the input scalars are made with
/// [`Sym::input`]) and returns its outputs; the finished graph is returned with them. Panics in `f`
/// (a model that panics) leave no graph behind.
pub fn record<O>(f: impl FnOnce() -> O) -> (Graph, O) {
    struct Reset;
    impl Drop for Reset {
        fn drop(&mut self) {
            RECORDING.with(|r| *r.borrow_mut() = None);
        }
    }
    let mut fresh = Graph::default();
    fresh.nodes.reserve(256);
    fresh.deps.reserve(256);
    fresh.values.reserve(256);
    fresh.map.reserve(256);
    RECORDING.with(|r| *r.borrow_mut() = Some(fresh));
    let reset = Reset;
    let out = f();
    let graph = RECORDING
        .with(|r| r.borrow_mut().take())
        .unwrap_or_default();
    drop(reset);
    (graph, out)
}
