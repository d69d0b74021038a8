//! The expression language of scene files, evaluated generically over `chetaev`'s scalar type.
//!
//! An expression is parsed once into a syntax tree, its names are resolved against the scene's
//! parameters and coordinates ([`Symbols`]), parameters are replaced by their values and every
//! subexpression without `t`, a coordinate or a velocity is folded to one constant. What remains
//! is evaluated by [`Expr::eval`] for any `R: Real`: `f64` for values, num-dual's dual numbers for
//! the derivatives `chetaev` takes. Nothing is differentiated symbolically.
//!
//! A parameter that sensitivities are asked for (or one computed from such a parameter) is the one
//! exception: it is kept as a parameter node ([`Symbols::varying`]), read as
//! `R::parameter(name, value)`, so that `chetaev` differentiates the motion with respect to it.
//! Scenes without sensitivities have no such nodes and are folded as before.
//!
//! ```text
//! numbers     2   0.5   .5   1e-3   6.674E-11
//! names       parameters, coordinates (x), velocities (x_dot), time t, constants pi and e
//! operators   + - * / ^, unary minus; ^ binds tightest and is right-associative: -x^2 = -(x^2)
//! functions   sqrt cbrt exp ln log10 log2 sin cos tan asin acos atan atan2(y, x)
//!             sinh cosh tanh asinh acosh atanh abs
//! ```
//!
//! The constants `pi` and `e` are the language's own names only where the scene declares no
//! parameter or coordinate of that name: a declared name shadows a constant (a charge `e`, a
//! momentum `pi`). `t` cannot be declared. An `e` that means Euler's number is listed by
//! [`Expr::euler`], so that it can be pointed out: it is easily a forgotten parameter.
//!
//! A constant integer exponent with `|n| ≤ 32` (`x^2`, `x^-1`, `x^(n+1)` with a parameter `n`) is
//! evaluated by repeated multiplication (`powi`), any other constant exponent by `powf` (an
//! integer-valued one keeps the sign of a negative base), and a variable exponent by
//! `exp(b ln a)` (`a > 0`). A constant exponent of a variable may be as large as
//! [`MAX_EXPONENT`] `= 2^52` in size; its derivatives `n x^(n−1)`, `n (n−1) x^(n−2)`, ... are formed
//! in floating point, so no integer product overflows.
//!
//! ```
//! use chetaev_scene::expr::{Env, Expr, Symbols};
//! use num_dual::{Dual64, DualNum};
//!
//! let symbols = Symbols::motion(&[("g", 9.81)], &["x", "y"]);
//! let v = Expr::parse("x_dot^2 + y_dot^2 + 2*g*y", &symbols)?;
//! // d/dy at (x, y) = (0, 1), (x_dot, y_dot) = (3, 4): 2 g
//! let q = [Dual64::from(0.0), Dual64::new(1.0, 1.0)];
//! let qd = [Dual64::from(3.0), Dual64::from(4.0)];
//! let value = v.eval(&Env { t: Dual64::from(0.0), q: &q, qd: &qd });
//! assert_eq!(value.re, 25.0 + 2.0 * 9.81);
//! assert_eq!(value.eps, 2.0 * 9.81);
//! # Ok::<(), chetaev_scene::expr::ExprError>(())
//! ```

mod lex;
pub(crate) mod parse;

use std::collections::BTreeMap;
use std::sync::Arc;

use chetaev::model::Real;

use parse::{Ast, BinOp, Span};

/// A mistake in an expression: its byte range in the expression's text and what was expected.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{message} (at byte {start} of the expression)")]
pub struct ExprError {
    /// First byte of the offending text.
    pub start: usize,
    /// One past its last byte.
    pub end: usize,
    /// What was wrong and what to write instead.
    pub message: String,
}

impl ExprError {
    pub(crate) fn new(start: usize, end: usize, message: impl Into<String>) -> Self {
        Self {
            start,
            end,
            message: message.into(),
        }
    }

    fn at(span: Span, message: impl Into<String>) -> Self {
        Self::new(span.start, span.end, message)
    }
}

/// The names an expression may use.
#[derive(Clone, Debug, Default)]
pub struct Symbols {
    /// Parameters and their values; folded into constants, except those in `varying`.
    pub parameters: BTreeMap<String, f64>,
    /// Parameters kept as parameter nodes (`R::parameter(name, value)`), by name, with their index
    /// in the scene's list of parameters: those sensitivities are asked for and those computed
    /// from them. Empty for a scene without sensitivities.
    pub varying: BTreeMap<String, usize>,
    /// Coordinate names `q_i`; each also gives the velocity `<name>_dot`.
    pub coordinates: Vec<String>,
    /// Whether `t`, the coordinates and the velocities may be used (the model, events and output
    /// quantities), or only parameters and constants (parameters, initial values, times).
    pub motion: bool,
    /// Names of quantities recorded along the motion that an expression may read, by their index
    /// in the values given to [`Expr::eval_recorded`]: for output quantities, the multipliers
    /// `mu_1`, `mu_2`, ... and the Chetaev force `Phi_<coordinate>`. A parameter of the same name
    /// is read instead. Empty for every other expression.
    pub recorded: Vec<String>,
}

impl Symbols {
    /// Names for expressions along the motion: parameters, coordinates, velocities, `t`.
    pub fn motion(parameters: &[(&str, f64)], coordinates: &[&str]) -> Self {
        Self {
            parameters: parameters
                .iter()
                .map(|(n, v)| (n.to_string(), *v))
                .collect(),
            coordinates: coordinates.iter().map(|c| c.to_string()).collect(),
            varying: BTreeMap::new(),
            motion: true,
            recorded: Vec::new(),
        }
    }

    /// Whether `name` is declared: a parameter or a coordinate (which then shadows a constant of
    /// the same name).
    pub fn declares(&self, name: &str) -> bool {
        self.parameters.contains_key(name) || self.coordinates.iter().any(|c| c == name)
    }

    /// Names for constant expressions: parameters and the constants `pi`, `e` only.
    pub fn constants(parameters: &BTreeMap<String, f64>) -> Self {
        Self {
            parameters: parameters.clone(),
            coordinates: Vec::new(),
            varying: BTreeMap::new(),
            motion: false,
            recorded: Vec::new(),
        }
    }
}

/// The values an expression is evaluated at: time, coordinates and velocities.
#[derive(Clone, Copy, Debug)]
pub struct Env<'a, R> {
    /// Time `t`.
    pub t: R,
    /// Coordinates `q`, in the order of [`Symbols::coordinates`].
    pub q: &'a [R],
    /// Velocities `q̇`, same order.
    pub qd: &'a [R],
}

/// A parsed, resolved and constant-folded expression.
#[derive(Clone, Debug, PartialEq)]
pub struct Expr {
    source: String,
    node: Node,
    max_index: Option<usize>,
    /// Byte ranges in `source` of each `e` read as Euler's number.
    euler: Vec<std::ops::Range<usize>>,
}

impl Expr {
    /// Parses `source` and resolves its names against `symbols`.
    pub fn parse(source: &str, symbols: &Symbols) -> Result<Self, ExprError> {
        let ast = parse::parse(source)?;
        Self::from_ast(source, &ast, symbols)
    }

    pub(crate) fn from_ast(source: &str, ast: &Ast, symbols: &Symbols) -> Result<Self, ExprError> {
        let node = resolve(ast, symbols)?;
        let mut max_index = None;
        node.visit_indices(&mut |i| max_index = Some(max_index.map_or(i, |m: usize| m.max(i))));
        let mut names = Vec::new();
        ast.names(&mut names);
        let euler = names
            .into_iter()
            .filter(|(n, _)| n == "e" && !symbols.declares("e"))
            .map(|(_, span)| span.start..span.end)
            .collect();
        Ok(Self {
            source: source.to_string(),
            node,
            max_index,
            euler,
        })
    }

    /// The byte ranges in [`Expr::source`] of each `e` read as Euler's number (no parameter or
    /// coordinate is named `e`), in the order written; empty for most expressions.
    pub fn euler(&self) -> &[std::ops::Range<usize>] {
        &self.euler
    }

    /// Whether it depends on a velocity.
    pub fn uses_velocities(&self) -> bool {
        self.node.uses_velocities()
    }

    /// The text it was parsed from.
    pub fn source(&self) -> &str {
        &self.source
    }

    /// Its value if it does not depend on `t`, the coordinates or the velocities.
    pub fn constant(&self) -> Option<f64> {
        match self.node {
            Node::Const(c) => Some(c),
            _ => None,
        }
    }

    /// Whether it depends on `t`.
    pub fn uses_time(&self) -> bool {
        self.node.uses_time()
    }

    /// The indices of the parameters it reads as parameter nodes ([`Symbols::varying`]), each
    /// once, in increasing order; empty for an expression resolved without varying parameters.
    pub fn varying_parameters(&self) -> Vec<usize> {
        let mut found = Vec::new();
        self.node.visit_parameters(&mut |i| found.push(i));
        found.sort_unstable();
        found.dedup();
        found
    }

    /// The value with the parameter nodes taken from `parameters` (indexed as the scene's
    /// parameters) instead of `R::parameter`: with dual numbers there, the derivative of the
    /// expression with respect to the parameters.
    ///
    /// # Panics
    ///
    /// As [`Expr::eval`], and if `parameters` is shorter than an index the expression reads.
    pub(crate) fn eval_with_parameters<R: Real>(&self, env: &Env<'_, R>, parameters: &[R]) -> R {
        self.node.eval(env, &Slots(parameters))
    }

    /// Whether it reads a recorded quantity ([`Symbols::recorded`]).
    pub fn reads_recorded(&self) -> bool {
        self.node.reads_recorded()
    }

    /// The value at `env` with the recorded quantities ([`Symbols::recorded`]) taken from
    /// `recorded`, by their index there; NaN for one that `recorded` does not hold (the
    /// multipliers where they were not recorded).
    ///
    /// # Panics
    ///
    /// As [`Expr::eval`].
    pub fn eval_recorded(&self, env: &Env<'_, f64>, recorded: &[f64]) -> f64 {
        self.check_env(env);
        self.node.eval(env, &Recorded(recorded))
    }

    /// The value at `env`, for `f64` or any dual number.
    ///
    /// # Panics
    ///
    /// If `env.q` or `env.qd` is shorter than the coordinates the expression uses (the length of
    /// [`Symbols::coordinates`] it was resolved with is always enough).
    #[inline]
    pub fn eval<R: Real>(&self, env: &Env<'_, R>) -> R {
        self.check_env(env);
        self.node.eval(env, &Named)
    }

    /// Panics unless `env` has every coordinate the expression uses.
    #[inline]
    fn check_env<R>(&self, env: &Env<'_, R>) {
        if let Some(i) = self.max_index {
            assert!(
                i < env.q.len() && i < env.qd.len(),
                "the expression '{}' uses coordinate {i} but the environment has {} coordinates",
                self.source,
                env.q.len().min(env.qd.len())
            );
        }
    }
}

/// Where a parameter node takes its value.
trait ParameterValues<R: Real> {
    fn value(&self, name: &str, index: usize, value: f64) -> R;

    /// The recorded quantity `index` ([`Symbols::recorded`]): none outside output quantities.
    fn recorded(&self, _index: usize) -> R {
        R::from(f64::NAN)
    }
}

/// `R::parameter` for the parameter nodes, and the recorded quantities from a slice.
struct Recorded<'a>(&'a [f64]);

impl ParameterValues<f64> for Recorded<'_> {
    #[inline]
    fn value(&self, name: &str, _index: usize, value: f64) -> f64 {
        f64::parameter(name, value)
    }

    fn recorded(&self, index: usize) -> f64 {
        self.0.get(index).copied().unwrap_or(f64::NAN)
    }
}

/// `R::parameter(name, value)`: the constant, except where `chetaev` records the equations with
/// the parameters as inputs.
struct Named;

impl<R: Real> ParameterValues<R> for Named {
    #[inline]
    fn value(&self, name: &str, _index: usize, value: f64) -> R {
        R::parameter(name, value)
    }
}

/// Values given by the parameter's index.
struct Slots<'a, R>(&'a [R]);

impl<R: Real> ParameterValues<R> for Slots<'_, R> {
    #[inline]
    fn value(&self, _name: &str, index: usize, _value: f64) -> R {
        self.0[index]
    }
}

/// A function of one argument.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Func {
    Sqrt,
    Cbrt,
    Exp,
    Ln,
    Log10,
    Log2,
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
}

/// Every function name, with its number of arguments (`None` for the two-argument `atan2`).
const FUNCTIONS: [(&str, Option<Func>); 20] = [
    ("sqrt", Some(Func::Sqrt)),
    ("cbrt", Some(Func::Cbrt)),
    ("exp", Some(Func::Exp)),
    ("ln", Some(Func::Ln)),
    ("log10", Some(Func::Log10)),
    ("log2", Some(Func::Log2)),
    ("sin", Some(Func::Sin)),
    ("cos", Some(Func::Cos)),
    ("tan", Some(Func::Tan)),
    ("asin", Some(Func::Asin)),
    ("acos", Some(Func::Acos)),
    ("atan", Some(Func::Atan)),
    ("atan2", None),
    ("sinh", Some(Func::Sinh)),
    ("cosh", Some(Func::Cosh)),
    ("tanh", Some(Func::Tanh)),
    ("asinh", Some(Func::Asinh)),
    ("acosh", Some(Func::Acosh)),
    ("atanh", Some(Func::Atanh)),
    ("abs", Some(Func::Abs)),
];

/// Names that cannot be given to a parameter or a coordinate: time.
pub const RESERVED: [&str; 1] = ["t"];

/// The constants of the language, each meant only where no parameter or coordinate of its name is
/// declared (a declared name shadows it).
pub const CONSTANTS: [(&str, f64); 2] = [("pi", std::f64::consts::PI), ("e", std::f64::consts::E)];

/// Whether `name` is a function of the language.
pub fn is_function(name: &str) -> bool {
    FUNCTIONS.iter().any(|(n, _)| *n == name) || name == "log"
}

fn function_list() -> String {
    FUNCTIONS
        .iter()
        .map(|(n, _)| *n)
        .collect::<Vec<_>>()
        .join(" ")
}

impl Func {
    /// The function of this name (`sqrt`, ..., `abs`; not `atan2`).
    pub(crate) fn from_name(name: &str) -> Option<Func> {
        FUNCTIONS
            .iter()
            .find(|(n, _)| *n == name)
            .and_then(|(_, f)| *f)
    }

    /// The names of the functions of one argument, separated by spaces.
    pub(crate) fn names() -> String {
        FUNCTIONS
            .iter()
            .filter(|(_, f)| f.is_some())
            .map(|(n, _)| *n)
            .collect::<Vec<_>>()
            .join(" ")
    }

    #[inline]
    pub(crate) fn apply<R: Real>(self, x: R) -> R {
        match self {
            Func::Sqrt => x.sqrt(),
            Func::Cbrt => x.cbrt(),
            Func::Exp => x.exp(),
            Func::Ln => x.ln(),
            Func::Log10 => x.log10(),
            Func::Log2 => x.log2(),
            Func::Sin => x.sin(),
            Func::Cos => x.cos(),
            Func::Tan => x.tan(),
            Func::Asin => x.asin(),
            Func::Acos => x.acos(),
            Func::Atan => x.atan(),
            Func::Sinh => x.sinh(),
            Func::Cosh => x.cosh(),
            Func::Tanh => x.tanh(),
            Func::Asinh => x.asinh(),
            Func::Acosh => x.acosh(),
            Func::Atanh => x.atanh(),
            Func::Abs => x.abs(),
        }
    }
}

/// The resolved tree. Constants are folded, and an operation with one constant operand keeps the
/// constant as an `f64` (`R op f64` is cheaper than `R op R` for dual numbers).
#[derive(Clone, Debug, PartialEq)]
enum Node {
    Const(f64),
    /// A parameter kept for sensitivities: its name, its index among the scene's parameters, and
    /// its value.
    Param(Arc<str>, usize, f64),
    Time,
    Coord(usize),
    Vel(usize),
    /// A quantity recorded along the motion, by its index in [`Symbols::recorded`].
    Recorded(usize),
    Neg(Box<Node>),
    /// `a ± b ± c ...`, evaluated left to right; `true` subtracts. A chain of sums is one node, so
    /// the depth of the tree (and of the recursion that evaluates it) follows the nesting of
    /// parentheses, not the number of terms.
    Sum(Box<Node>, Vec<(bool, Node)>),
    /// `a ×/÷ b ×/÷ c ...`, evaluated left to right; `true` divides.
    Product(Box<Node>, Vec<(bool, Node)>),
    /// `a + c`.
    AddC(Box<Node>, f64),
    /// `c − a`.
    CSub(f64, Box<Node>),
    /// `a · c`.
    MulC(Box<Node>, f64),
    /// `a / c`.
    DivC(Box<Node>, f64),
    /// `c / a`.
    CDiv(f64, Box<Node>),
    /// `a^n`, integer `n`, `|n| ≤ POWI_MAX`.
    PowI(Box<Node>, i32),
    /// `a^p`, any other constant `p` (an integer-valued `p` keeps the sign of a negative `a`).
    PowF(Box<Node>, f64),
    /// `a^b`, variable `b`: `exp(b ln a)`.
    Pow(Box<Node>, Box<Node>),
    F1(Func, Box<Node>),
    Atan2(Box<Node>, Box<Node>),
}

impl Node {
    fn eval<R: Real, V: ParameterValues<R>>(&self, env: &Env<'_, R>, v: &V) -> R {
        match self {
            Node::Const(c) => R::from(*c),
            Node::Param(name, index, value) => v.value(name, *index, *value),
            Node::Time => env.t,
            Node::Coord(i) => env.q[*i],
            Node::Vel(i) => env.qd[*i],
            Node::Recorded(i) => v.recorded(*i),
            Node::Neg(a) => -a.eval(env, v),
            Node::Sum(first, rest) => rest.iter().fold(first.eval(env, v), |acc, (minus, term)| {
                match (minus, term) {
                    (false, Node::Const(c)) => acc + *c,
                    (true, Node::Const(c)) => acc - *c,
                    (false, term) => acc + term.eval(env, v),
                    (true, term) => acc - term.eval(env, v),
                }
            }),
            Node::Product(first, rest) => {
                rest.iter()
                    .fold(first.eval(env, v), |acc, (divide, factor)| {
                        match (divide, factor) {
                            (false, Node::Const(c)) => acc * *c,
                            (true, Node::Const(c)) => acc / *c,
                            (false, factor) => acc * factor.eval(env, v),
                            (true, factor) => acc / factor.eval(env, v),
                        }
                    })
            }
            Node::AddC(a, c) => a.eval(env, v) + *c,
            Node::CSub(c, a) => -a.eval(env, v) + *c,
            Node::MulC(a, c) => a.eval(env, v) * *c,
            Node::DivC(a, c) => a.eval(env, v) / *c,
            Node::CDiv(c, a) => R::from(*c) / a.eval(env, v),
            Node::PowI(a, n) => a.eval(env, v).powi(*n),
            Node::PowF(a, p) => a.eval(env, v).powf(*p),
            Node::Pow(a, b) => a.eval(env, v).powd(b.eval(env, v)),
            Node::F1(f, a) => f.apply(a.eval(env, v)),
            Node::Atan2(a, b) => a.eval(env, v).atan2(b.eval(env, v)),
        }
    }

    fn children(&self) -> Vec<&Node> {
        match self {
            Node::Const(_)
            | Node::Param(..)
            | Node::Time
            | Node::Coord(_)
            | Node::Vel(_)
            | Node::Recorded(_) => Vec::new(),
            Node::Sum(first, rest) | Node::Product(first, rest) => std::iter::once(&**first)
                .chain(rest.iter().map(|(_, n)| n))
                .collect(),
            Node::Neg(a)
            | Node::AddC(a, _)
            | Node::CSub(_, a)
            | Node::MulC(a, _)
            | Node::DivC(a, _)
            | Node::CDiv(_, a)
            | Node::PowI(a, _)
            | Node::PowF(a, _)
            | Node::F1(_, a) => vec![a],
            Node::Pow(a, b) | Node::Atan2(a, b) => vec![a, b],
        }
    }

    fn visit_indices(&self, f: &mut impl FnMut(usize)) {
        match self {
            Node::Coord(i) | Node::Vel(i) => f(*i),
            _ => self.children().into_iter().for_each(|c| c.visit_indices(f)),
        }
    }

    fn visit_parameters(&self, f: &mut impl FnMut(usize)) {
        match self {
            Node::Param(_, i, _) => f(*i),
            _ => self
                .children()
                .into_iter()
                .for_each(|c| c.visit_parameters(f)),
        }
    }

    fn uses_time(&self) -> bool {
        matches!(self, Node::Time) || self.children().into_iter().any(Node::uses_time)
    }

    fn uses_velocities(&self) -> bool {
        matches!(self, Node::Vel(_)) || self.children().into_iter().any(Node::uses_velocities)
    }

    fn reads_recorded(&self) -> bool {
        matches!(self, Node::Recorded(_)) || self.children().into_iter().any(Node::reads_recorded)
    }
}

/// Resolves names and folds constants, bottom-up; a constant that is not finite (a division by
/// zero, a logarithm of a negative parameter) is reported at the subexpression that produced it.
fn resolve(ast: &Ast, sym: &Symbols) -> Result<Node, ExprError> {
    let node = match ast {
        Ast::Num(v, _) => Node::Const(*v),
        Ast::Name(name, span) => resolve_name(name, *span, sym)?,
        Ast::Neg(a, _) => match resolve(a, sym)? {
            Node::Const(c) => Node::Const(-c),
            a => Node::Neg(Box::new(a)),
        },
        Ast::Bin(op, a, b, span) => {
            let exponent_span = b.span();
            let (a, b) = (resolve(a, sym)?, resolve(b, sym)?);
            if let (BinOp::Pow, Node::Const(p)) = (op, &b) {
                if !matches!(a, Node::Const(_)) && p.abs() > MAX_EXPONENT {
                    return Err(ExprError::at(
                        exponent_span,
                        format!(
                            "the exponent {p:e} is too large: a power of a variable takes exponents up to \
                             2^52 ≈ 4.5e15 in size, where the exponents n−1, n−2 of its derivatives are \
                             still exact in floating point"
                        ),
                    ));
                }
            }
            binary(*op, a, b, *span)?
        }
        Ast::Chain(first, rest, _) => {
            // Left to right, each partial result checked as the node of a binary tree would be.
            let start = first.span().start;
            let mut acc = resolve(first, sym)?;
            for (op, b) in rest {
                let span = Span {
                    start,
                    end: b.span().end,
                };
                acc = finite(binary(*op, acc, resolve(b, sym)?, span)?, span)?;
            }
            acc
        }
        Ast::Call(name, span, args) => call(name, *span, args, sym)?,
    };
    finite(node, ast.span())
}

/// `node`, unless it is a constant that is not finite: then an error at `span`, the part that
/// produced it.
fn finite(node: Node, span: Span) -> Result<Node, ExprError> {
    if let Node::Const(c) = node {
        if !c.is_finite() {
            let what = if c.is_nan() { "NaN" } else { "infinite" };
            return Err(ExprError::at(
                span,
                format!(
                    "this part is {what} with the parameters given (a division by zero, a square root \
                     or logarithm of a negative number, or an overflow); check the parameters"
                ),
            ));
        }
    }
    Ok(node)
}

fn binary(op: BinOp, a: Node, b: Node, span: Span) -> Result<Node, ExprError> {
    use Node::Const;
    let bx = Box::new;
    if let (BinOp::Div, Const(c)) = (op, &b) {
        if *c == 0.0 {
            return Err(ExprError::at(span, "division by zero (the divisor is 0)"));
        }
    }
    Ok(match (op, a, b) {
        (BinOp::Add, Const(x), Const(y)) => Const(x + y),
        (BinOp::Sub, Const(x), Const(y)) => Const(x - y),
        (BinOp::Mul, Const(x), Const(y)) => Const(x * y),
        (BinOp::Div, Const(x), Const(y)) => Const(x / y),
        // Chains extend the node they continue.
        (BinOp::Add | BinOp::Sub, Node::Sum(first, mut rest), b) => {
            rest.push((op == BinOp::Sub, b));
            Node::Sum(first, rest)
        }
        (BinOp::Mul | BinOp::Div, Node::Product(first, mut rest), b) => {
            rest.push((op == BinOp::Div, b));
            Node::Product(first, rest)
        }
        // One constant operand stays an f64.
        (BinOp::Add, a, Const(c)) | (BinOp::Add, Const(c), a) => Node::AddC(bx(a), c),
        (BinOp::Sub, a, Const(c)) => Node::AddC(bx(a), -c),
        (BinOp::Sub, Const(c), a) => Node::CSub(c, bx(a)),
        (BinOp::Mul, a, Const(c)) | (BinOp::Mul, Const(c), a) => Node::MulC(bx(a), c),
        (BinOp::Div, a, Const(c)) => Node::DivC(bx(a), c),
        (BinOp::Div, Const(c), a) => Node::CDiv(c, bx(a)),
        (BinOp::Add | BinOp::Sub, a, b) => Node::Sum(bx(a), vec![(op == BinOp::Sub, b)]),
        (BinOp::Mul | BinOp::Div, a, b) => Node::Product(bx(a), vec![(op == BinOp::Div, b)]),
        (BinOp::Pow, Const(x), Const(y)) => Const(power(x, y)),
        (BinOp::Pow, a, Const(p)) => match small_integer(p) {
            Some(n) => Node::PowI(bx(a), n),
            None => Node::PowF(bx(a), p),
        },
        (BinOp::Pow, a, b) => Node::Pow(bx(a), bx(b)),
    })
}

/// The largest `|n|` of an integer exponent evaluated by `powi`.
///
/// num-dual's `powi` forms the factors of its derivatives, `n (n−1)` and `n (n−1) (n−2)`, in `i32`,
/// which overflows from `|n| ≈ 1290` on (third derivatives) and `|n| ≈ 46 341` (second); and
/// repeated multiplication loses about one ulp per factor. Beyond this bound `powf` is both exact
/// to an ulp and free of integer arithmetic: its derivative factors are `f64`.
pub const POWI_MAX: i32 = 32;

/// The largest `|p|` of a constant exponent of a variable base, `2^52`: up to there `p − 1`,
/// `p − 2`, `p − 3` are exact in `f64`, so the derivatives keep the parity (the sign of a negative
/// base) of an integer exponent.
pub const MAX_EXPONENT: f64 = 4_503_599_627_370_496.0;

/// `p` as an `i32` if it is an integer with `|p| ≤ POWI_MAX`.
fn small_integer(p: f64) -> Option<i32> {
    (p.fract() == 0.0 && p.abs() <= f64::from(POWI_MAX)).then_some(p as i32)
}

/// `x^y` on constants, with the same choice of `powi`/`powf` as at run time.
fn power(x: f64, y: f64) -> f64 {
    match small_integer(y) {
        Some(n) => x.powi(n),
        None => x.powf(y),
    }
}

fn resolve_name(name: &str, span: Span, sym: &Symbols) -> Result<Node, ExprError> {
    if let (Some(&i), Some(v)) = (sym.varying.get(name), sym.parameters.get(name)) {
        return Ok(Node::Param(Arc::from(name), i, *v));
    }
    if let Some(v) = sym.parameters.get(name) {
        return Ok(Node::Const(*v));
    }
    if let Some(i) = sym.recorded.iter().position(|r| r == name) {
        return Ok(Node::Recorded(i));
    }
    let coordinate = sym.coordinates.iter().position(|c| c == name);
    let velocity = name
        .strip_suffix("_dot")
        .and_then(|base| sym.coordinates.iter().position(|c| c == base));
    let kind = if name == "t" {
        Some(("time", Node::Time))
    } else if let Some(i) = coordinate {
        Some(("a coordinate", Node::Coord(i)))
    } else {
        velocity.map(|i| ("a velocity", Node::Vel(i)))
    };
    // A constant, unless a coordinate (above: a parameter) of its name shadows it.
    if let (None, Some((_, c))) = (&kind, CONSTANTS.iter().find(|(n, _)| *n == name)) {
        return Ok(Node::Const(*c));
    }
    if let Some((what, node)) = kind {
        if sym.motion {
            return Ok(node);
        }
        return Err(ExprError::at(
            span,
            format!(
                "'{name}' is {what}, which has no value here: parameters, initial values and times \
                 can use only parameters and the constants pi and e"
            ),
        ));
    }
    if is_function(name) {
        return Err(ExprError::at(
            span,
            format!("'{name}' is a function: call it with parentheses, as in {name}(x)"),
        ));
    }
    Err(ExprError::at(span, unknown_name(name, sym)))
}

/// `Ok` if `name` has a value in an expression with `symbols`, or the error
/// [`Expr::parse`] would give for it (what the name is, or the names it is close to).
pub(crate) fn check_name(name: &str, span: Span, sym: &Symbols) -> Result<(), ExprError> {
    resolve_name(name, span, sym).map(|_| ())
}

fn unknown_name(name: &str, sym: &Symbols) -> String {
    let mut known: Vec<String> = sym.parameters.keys().cloned().collect();
    known.extend(
        CONSTANTS
            .iter()
            .filter(|(n, _)| !sym.declares(n))
            .map(|(n, _)| n.to_string()),
    );
    if sym.motion {
        known.push("t".into());
        for c in &sym.coordinates {
            known.push(c.clone());
            known.push(format!("{c}_dot"));
        }
        known.extend(sym.recorded.iter().cloned());
    }
    // A velocity written another way: xdot, xd, x_d, dx, vx, x', ...
    if sym.motion {
        for c in &sym.coordinates {
            let variants = [
                format!("{c}dot"),
                format!("{c}d"),
                format!("{c}_d"),
                format!("d{c}"),
                format!("v{c}"),
                format!("v_{c}"),
                format!("{c}_t"),
                format!("{c}_dt"),
            ];
            if variants.iter().any(|v| v == name) {
                return format!("unknown name '{name}': the velocity of '{c}' is written {c}_dot");
            }
        }
    }
    let what = if sym.motion {
        "a parameter, coordinate, velocity (x_dot), t, pi or e"
    } else {
        "a parameter, pi or e"
    };
    match closest(name, &known) {
        Some(s) => format!("unknown name '{name}': not {what}; did you mean '{s}'?"),
        None if known.is_empty() => format!("unknown name '{name}': not {what}"),
        None => format!(
            "unknown name '{name}': not {what} (the names here are {})",
            listing(&known)
        ),
    }
}

/// The most names a message lists.
const NAMES_LISTED: usize = 20;

/// `a, b, c`, or the first [`NAMES_LISTED`] names and how many more there are.
fn listing(names: &[String]) -> String {
    let shown: Vec<&str> = names
        .iter()
        .take(NAMES_LISTED)
        .map(String::as_str)
        .collect();
    if names.len() > NAMES_LISTED {
        format!(
            "{}, and {} more",
            shown.join(", "),
            names.len() - NAMES_LISTED
        )
    } else {
        shown.join(", ")
    }
}

/// The longest name, in characters, for which a near name is looked for.
const SUGGEST_MAX_LEN: usize = 64;

/// The most known names compared with an unknown one.
const SUGGEST_MAX_CANDIDATES: usize = 10_000;

/// The known name nearest to `name` by edit distance, if it is near enough to be a typo.
///
/// Bounded whatever the scene: names longer than [`SUGGEST_MAX_LEN`] get no suggestion, only names
/// whose length is within the distance allowed are compared, at most [`SUGGEST_MAX_CANDIDATES`]
/// of them, and each comparison stops once the distance allowed is exceeded.
pub(crate) fn closest<'a>(name: &str, known: &'a [String]) -> Option<&'a str> {
    let len = name.chars().count();
    if len > SUGGEST_MAX_LEN {
        return None;
    }
    let limit = if len <= 3 { 1 } else { 2 };
    known
        .iter()
        .filter(|k| k.len().abs_diff(name.len()) <= 4 * limit)
        .filter(|k| k.chars().count().abs_diff(len) <= limit)
        .take(SUGGEST_MAX_CANDIDATES)
        .filter_map(|k| edit_distance_within(name, k, limit).map(|d| (d, k)))
        .min_by_key(|(d, _)| *d)
        .map(|(_, k)| k.as_str())
}

/// The Levenshtein distance between `a` and `b` if it is at most `limit`.
fn edit_distance_within(a: &str, b: &str, limit: usize) -> Option<usize> {
    let (a, b): (Vec<char>, Vec<char>) = (a.chars().collect(), b.chars().collect());
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for i in 1..=a.len() {
        let mut prev = row[0];
        row[0] = i;
        for j in 1..=b.len() {
            let cur = row[j];
            row[j] = (row[j] + 1)
                .min(row[j - 1] + 1)
                .min(prev + usize::from(a[i - 1] != b[j - 1]));
            prev = cur;
        }
        // Every later row is at least the smallest entry of this one.
        if row.iter().min().is_some_and(|m| *m > limit) {
            return None;
        }
    }
    Some(row[b.len()]).filter(|d| *d <= limit)
}

fn call(name: &str, span: Span, args: &[Ast], sym: &Symbols) -> Result<Node, ExprError> {
    let Some((_, func)) = FUNCTIONS.iter().find(|(n, _)| *n == name) else {
        let message = if name == "log" {
            "'log' is ambiguous: write ln (natural logarithm) or log10".to_string()
        } else if sym.parameters.contains_key(name)
            || sym.coordinates.iter().any(|c| c == name)
            || name
                .strip_suffix("_dot")
                .is_some_and(|b| sym.coordinates.iter().any(|c| c == b))
            || RESERVED.contains(&name)
            || CONSTANTS.iter().any(|(n, _)| *n == name)
        {
            format!("'{name}' is not a function: write a product with '*', as in {name}*(...)")
        } else {
            let names: Vec<String> = FUNCTIONS.iter().map(|(n, _)| n.to_string()).collect();
            match closest(name, &names) {
                Some(s) => format!("unknown function '{name}'; did you mean '{s}'?"),
                None => format!(
                    "unknown function '{name}'; the functions are {}",
                    function_list()
                ),
            }
        };
        return Err(ExprError::new(span.start, span.start + name.len(), message));
    };
    let want = if func.is_some() { 1 } else { 2 };
    if args.len() != want {
        let plural = if want == 1 { "" } else { "s" };
        return Err(ExprError::at(
            span,
            format!(
                "'{name}' takes {want} argument{plural}, found {}",
                args.len()
            ),
        ));
    }
    let mut nodes = Vec::with_capacity(args.len());
    for a in args {
        nodes.push(resolve(a, sym)?);
    }
    let mut nodes = nodes.into_iter();
    let (Some(a), b) = (nodes.next(), nodes.next()) else {
        return Err(ExprError::at(span, format!("'{name}' needs an argument")));
    };
    Ok(match (func, a, b) {
        (Some(f), Node::Const(c), _) => Node::Const(f.apply(c)),
        (Some(f), a, _) => Node::F1(*f, Box::new(a)),
        (None, Node::Const(y), Some(Node::Const(x))) => Node::Const(y.atan2(x)),
        (None, a, Some(b)) => Node::Atan2(Box::new(a), Box::new(b)),
        (None, _, None) => {
            return Err(ExprError::at(span, "'atan2' takes 2 arguments, found 1"));
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn folds_parameters_and_constants() {
        let s = Symbols::motion(&[("v0", 10.0), ("m", 2.0)], &["x"]);
        let e = Expr::parse("v0^2 * m / 4 + sin(pi/2)", &s).expect("parses");
        assert_eq!(e.constant(), Some(51.0));
        let e = Expr::parse("0.5*m*x_dot^2", &s).expect("parses");
        assert_eq!(
            e.node,
            Node::MulC(Box::new(Node::PowI(Box::new(Node::Vel(0)), 2)), 1.0)
        );
    }

    #[test]
    fn edit_distance_counts_edits_up_to_the_limit() {
        assert_eq!(edit_distance_within("x_dto", "x_dot", 2), Some(2));
        assert_eq!(edit_distance_within("x_dto", "x_dot", 1), None);
        assert_eq!(edit_distance_within("sine", "sin", 2), Some(1));
        assert_eq!(edit_distance_within("", "ab", 2), Some(2));
        assert_eq!(edit_distance_within("abcdef", "uvwxyz", 2), None);
    }

    #[test]
    fn suggestions_are_bounded_and_listings_short() {
        let known: Vec<String> = (0..30).map(|i| format!("p{i}")).collect();
        assert_eq!(closest("p29x", &known), Some("p29"));
        let long = "a".repeat(SUGGEST_MAX_LEN + 1);
        assert_eq!(closest(&long, &[format!("{long}b")]), None);
        assert_eq!(listing(&known).matches(", ").count(), NAMES_LISTED);
        assert!(listing(&known).ends_with("and 10 more"));
    }
}
