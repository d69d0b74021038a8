//! Models given as expression graphs: a straight-line program whose operations name their operands
//! by index, so that a subexpression used many times is one node, evaluated once.
//!
//! This is the door for front ends that hold their own expression trees, such as the Python
//! package, which converts a sympy expression (`sympy.physics.mechanics`' Lagrangians, constraints
//! and loads) node by node, each distinct subexpression once. The graph is evaluated generically
//! over `chetaev`'s scalar type like any model, so `chetaev` records it into its own expression
//! graph with every shared node kept, proves its structure and compiles it as it does a model
//! written in Rust ([`chetaev::Problem::describe`] shows what it derived).
//!
//! ```text
//! op          operands    value       meaning
//! const       —           c           the number c
//! param       —           index p     parameter p of the graph (R::parameter(name, value))
//! t           —           —           time
//! q, qd       —           index i     coordinate q_i, velocity q̇_i (from 0)
//! add, mul    a, b, ...   —           a + b + ..., a · b · ...
//! pow         a, b        —           a^b: powi for an integer constant |b| ≤ 32, powf for any other
//!                                     constant b, exp(b ln a) for a variable b
//! sqrt ... abs   a        —           the functions of the scene language (crate::expr)
//! atan2       y, x        —           the angle of (x, y)
//! ```
//!
//! Operations whose operands are all constants are folded when they are added.
//!
//! ```
//! use chetaev_scene::graph::{Graph, GraphModel, Parts};
//!
//! // L = ½ m (ẋ² + ẏ²) − m g y, f = ẋ² + ẏ² − v0²: the paper's particle.
//! let mut g = Graph::new(2, vec![("m".into(), 1.0), ("g".into(), 10.0), ("v0".into(), 10.0)])?;
//! let (m, grav, v0) = (g.push("param", &[], 0.0)?, g.push("param", &[], 1.0)?, g.push("param", &[], 2.0)?);
//! let (y, xd, yd) = (g.push("q", &[], 1.0)?, g.push("qd", &[], 0.0)?, g.push("qd", &[], 1.0)?);
//! let two = g.push("const", &[], 2.0)?;
//! let (xd2, yd2) = (g.push("pow", &[xd, two], 0.0)?, g.push("pow", &[yd, two], 0.0)?);
//! let speed2 = g.push("add", &[xd2, yd2], 0.0)?;
//! let half = g.push("const", &[], 0.5)?;
//! let kinetic = g.push("mul", &[half, m, speed2], 0.0)?;
//! let minus = g.push("const", &[], -1.0)?;
//! let potential = g.push("mul", &[minus, m, grav, y], 0.0)?;
//! let lagrangian = g.push("add", &[kinetic, potential], 0.0)?;
//! let v02 = g.push("pow", &[v0, two], 0.0)?;
//! let minus_v02 = g.push("mul", &[minus, v02], 0.0)?;
//! let f = g.push("add", &[speed2, minus_v02], 0.0)?;
//! let model = GraphModel::new(g, Parts { lagrangian, constraints: vec![f], ..Parts::default() })?;
//!
//! let problem = chetaev::Problem::dynamic(model, 0.0, vec![0.0, 5.0], vec![10.0, 0.0])?;
//! let eq = problem.equations_at(0.0, &[0.0, 5.0], &[10.0, 0.0])?;
//! assert!(eq.mu[0].abs() < 1e-15); // μ(0) = 0, (42.40)
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::sync::Arc;

use chetaev::integrate::events::EventFunction;
use chetaev::model::DynModel;
use chetaev::prelude::Real;

use crate::expr::{Func, POWI_MAX};

/// A mistake in a graph: which operation, and what was wrong.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{message}")]
pub struct GraphError {
    /// The operation at fault (its index), where there is one.
    pub op: Option<usize>,
    /// What was wrong and what to do.
    pub message: String,
}

impl GraphError {
    fn at(op: usize, message: impl Into<String>) -> Self {
        Self {
            op: Some(op),
            message: message.into(),
        }
    }

    fn whole(message: impl Into<String>) -> Self {
        Self {
            op: None,
            message: message.into(),
        }
    }
}

/// One operation of a [`Graph`]; operands are indices of earlier operations.
#[derive(Clone, Debug, PartialEq)]
enum Op {
    Const(f64),
    Param(usize),
    Time,
    Coord(usize),
    Vel(usize),
    Add(Box<[u32]>),
    Mul(Box<[u32]>),
    PowI(u32, i32),
    PowF(u32, f64),
    Pow(u32, u32),
    F1(Func, u32),
    Atan2(u32, u32),
}

impl Op {
    /// Calls `f` on each operand.
    fn for_operands(&self, mut f: impl FnMut(u32)) {
        match self {
            Op::Const(_) | Op::Param(_) | Op::Time | Op::Coord(_) | Op::Vel(_) => {}
            Op::Add(a) | Op::Mul(a) => a.iter().copied().for_each(f),
            Op::PowI(a, _) | Op::PowF(a, _) | Op::F1(_, a) => f(*a),
            Op::Pow(a, b) | Op::Atan2(a, b) => {
                f(*a);
                f(*b);
            }
        }
    }
}

/// What a node depends on, as bits.
const USES_T: u8 = 1;
const USES_Q: u8 = 2;
const USES_QD: u8 = 4;

/// A straight-line program on `n` coordinates and named parameters: operations in order, each
/// reading earlier ones. Build with [`Graph::new`] and [`Graph::push`].
#[derive(Clone, Debug)]
pub struct Graph {
    n: usize,
    parameters: Vec<(Arc<str>, f64)>,
    ops: Vec<Op>,
    uses: Vec<u8>,
}

impl Graph {
    /// An empty graph on `n ≥ 1` coordinates with these parameters (names distinct, values
    /// finite).
    pub fn new(n: usize, parameters: Vec<(String, f64)>) -> Result<Self, GraphError> {
        if n == 0 {
            return Err(GraphError::whole(
                "a model needs at least one coordinate (n = 0)",
            ));
        }
        let mut seen = std::collections::BTreeSet::new();
        for (name, value) in &parameters {
            if !seen.insert(name.as_str()) {
                return Err(GraphError::whole(format!(
                    "the parameter '{name}' is given twice; give each parameter one value"
                )));
            }
            if !value.is_finite() {
                return Err(GraphError::whole(format!(
                    "the parameter '{name}' has the value {value}; give it a finite number"
                )));
            }
        }
        Ok(Self {
            n,
            parameters: parameters
                .into_iter()
                .map(|(n, v)| (Arc::from(n), v))
                .collect(),
            ops: Vec::new(),
            uses: Vec::new(),
        })
    }

    /// The number of coordinates.
    pub fn n(&self) -> usize {
        self.n
    }

    /// The number of operations.
    pub fn len(&self) -> usize {
        self.ops.len()
    }

    /// Whether there is no operation yet.
    pub fn is_empty(&self) -> bool {
        self.ops.is_empty()
    }

    /// The parameters and their values, in order.
    pub fn parameters(&self) -> impl ExactSizeIterator<Item = (&str, f64)> {
        self.parameters.iter().map(|(n, v)| (&**n, *v))
    }

    /// Sets the value of the parameter `name` (a sweep over it reuses the graph).
    pub fn set_parameter(&mut self, name: &str, value: f64) -> Result<(), GraphError> {
        if !value.is_finite() {
            return Err(GraphError::whole(format!(
                "the parameter '{name}' would have the value {value}; give it a finite number"
            )));
        }
        match self.parameters.iter_mut().find(|(n, _)| &**n == name) {
            Some((_, v)) => {
                *v = value;
                Ok(())
            }
            None => Err(GraphError::whole(format!(
                "no parameter is named '{name}'; the parameters are {}",
                self.parameter_list()
            ))),
        }
    }

    fn parameter_list(&self) -> String {
        if self.parameters.is_empty() {
            return "none".into();
        }
        self.parameters
            .iter()
            .map(|(n, _)| format!("'{n}'"))
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// Appends the operation `op` (see the [module](self) docs) on the operands `args` (indices of
    /// earlier operations) with the number `value` (the constant, or the index of a parameter,
    /// coordinate or velocity), and returns its index. An operation on constants only is folded
    /// into a constant.
    pub fn push(&mut self, op: &str, args: &[u32], value: f64) -> Result<u32, GraphError> {
        let at = self.ops.len();
        if at >= u32::MAX as usize {
            return Err(GraphError::at(at, "the graph has too many operations"));
        }
        if let Some(&bad) = args.iter().find(|&&a| a as usize >= at) {
            return Err(GraphError::at(
                at,
                format!("operation {at} ('{op}') reads operation {bad}, which does not come before it; operands must be added first"),
            ));
        }
        let arity = |want: usize| -> Result<(), GraphError> {
            if args.len() == want {
                Ok(())
            } else {
                Err(GraphError::at(
                    at,
                    format!(
                        "operation {at} ('{op}') takes {want} operand(s), found {}",
                        args.len()
                    ),
                ))
            }
        };
        let index = |limit: usize, what: &str| -> Result<usize, GraphError> {
            if value.fract() == 0.0 && value >= 0.0 && (value as usize) < limit {
                Ok(value as usize)
            } else {
                Err(GraphError::at(
                    at,
                    format!("operation {at} ('{op}') names {what} {value}, but there are {limit}"),
                ))
            }
        };
        let node = match op {
            "const" => {
                arity(0)?;
                if !value.is_finite() {
                    return Err(GraphError::at(
                        at,
                        format!("operation {at} is the constant {value}; constants must be finite (is a division by zero or an infinity, zoo or nan, in the expression?)"),
                    ));
                }
                Op::Const(value)
            }
            "param" => {
                arity(0)?;
                Op::Param(index(self.parameters.len(), "parameter")?)
            }
            "t" => {
                arity(0)?;
                Op::Time
            }
            "q" => {
                arity(0)?;
                Op::Coord(index(self.n, "coordinate")?)
            }
            "qd" => {
                arity(0)?;
                Op::Vel(index(self.n, "velocity")?)
            }
            "add" | "mul" => {
                if args.is_empty() {
                    return Err(GraphError::at(
                        at,
                        format!("operation {at} ('{op}') needs at least one operand"),
                    ));
                }
                if op == "add" {
                    Op::Add(args.into())
                } else {
                    Op::Mul(args.into())
                }
            }
            "pow" => {
                arity(2)?;
                match self.ops[args[1] as usize] {
                    Op::Const(p) if p.fract() == 0.0 && p.abs() <= f64::from(POWI_MAX) => {
                        Op::PowI(args[0], p as i32)
                    }
                    Op::Const(p) => Op::PowF(args[0], p),
                    _ => Op::Pow(args[0], args[1]),
                }
            }
            "atan2" => {
                arity(2)?;
                Op::Atan2(args[0], args[1])
            }
            name => {
                let Some(f) = Func::from_name(name) else {
                    return Err(GraphError::at(
                        at,
                        format!(
                            "operation {at}: unknown operation '{name}'; the operations are const, param, t, q, qd, add, mul, pow, atan2 and {}",
                            Func::names()
                        ),
                    ));
                };
                arity(1)?;
                Op::F1(f, args[0])
            }
        };
        let folded = self.fold(&node);
        let uses = match (&folded, &node) {
            (Some(_), _) => 0,
            (None, Op::Time) => USES_T,
            (None, Op::Coord(_)) => USES_Q,
            (None, Op::Vel(_)) => USES_QD,
            (None, node) => {
                let mut u = 0;
                node.for_operands(|a| u |= self.uses[a as usize]);
                u
            }
        };
        match folded {
            Some(c) if !c.is_finite() => {
                return Err(GraphError::at(
                    at,
                    format!("operation {at} ('{op}') on constants gives {c}; check the expression for a division by zero or a function outside its domain"),
                ));
            }
            Some(c) => self.ops.push(Op::Const(c)),
            None => self.ops.push(node),
        }
        self.uses.push(uses);
        Ok(at as u32)
    }

    /// The value of `node` if every operand is a constant.
    fn fold(&self, node: &Op) -> Option<f64> {
        let c = |a: u32| match self.ops[a as usize] {
            Op::Const(c) => Some(c),
            _ => None,
        };
        match node {
            Op::Add(a) => a.iter().try_fold(0.0, |s, &x| Some(s + c(x)?)),
            Op::Mul(a) => a.iter().try_fold(1.0, |s, &x| Some(s * c(x)?)),
            Op::PowI(a, n) => Some(c(*a)?.powi(*n)),
            Op::PowF(a, p) => Some(c(*a)?.powf(*p)),
            Op::F1(f, a) => Some(f.apply(c(*a)?)),
            Op::Atan2(y, x) => Some(c(*y)?.atan2(c(*x)?)),
            _ => None,
        }
    }

    /// Whether node `i` depends on the velocities.
    fn uses_velocity(&self, i: u32) -> bool {
        self.uses[i as usize] & USES_QD != 0
    }

    fn check_root(&self, root: u32, what: &str) -> Result<(), GraphError> {
        if (root as usize) < self.ops.len() {
            Ok(())
        } else {
            Err(GraphError::whole(format!(
                "{what} is operation {root}, but the graph has only {} operation(s)",
                self.ops.len()
            )))
        }
    }

    /// The operations `roots` need, in order.
    fn plan(&self, roots: &[u32]) -> Plan {
        let mut needed = vec![false; self.ops.len()];
        for &r in roots {
            needed[r as usize] = true;
        }
        for i in (0..self.ops.len()).rev() {
            if needed[i] {
                self.ops[i].for_operands(|a| needed[a as usize] = true);
            }
        }
        Plan {
            order: (0..self.ops.len() as u32)
                .filter(|&i| needed[i as usize])
                .collect(),
            roots: roots.to_vec(),
        }
    }

    /// Evaluates the operations of `plan` into `buf` (one slot per operation).
    #[inline]
    fn run<R: Real>(&self, plan: &Plan, t: R, q: &[R], qd: &[R], buf: &mut [R]) {
        for &i in &plan.order {
            let v = match &self.ops[i as usize] {
                Op::Const(c) => R::from(*c),
                Op::Param(p) => {
                    let (name, value) = &self.parameters[*p];
                    R::parameter(name, *value)
                }
                Op::Time => t,
                Op::Coord(j) => q[*j],
                Op::Vel(j) => qd[*j],
                Op::Add(a) => {
                    let mut s = buf[a[0] as usize];
                    for &x in &a[1..] {
                        match self.ops[x as usize] {
                            Op::Const(c) => s += c,
                            _ => s += buf[x as usize],
                        }
                    }
                    s
                }
                Op::Mul(a) => {
                    let mut s = buf[a[0] as usize];
                    for &x in &a[1..] {
                        match self.ops[x as usize] {
                            Op::Const(c) => s *= c,
                            _ => s *= buf[x as usize],
                        }
                    }
                    s
                }
                Op::PowI(a, n) => buf[*a as usize].powi(*n),
                Op::PowF(a, p) => buf[*a as usize].powf(*p),
                Op::Pow(a, b) => buf[*a as usize].powd(buf[*b as usize]),
                Op::F1(f, a) => f.apply(buf[*a as usize]),
                Op::Atan2(y, x) => Real::atan2(buf[*y as usize], buf[*x as usize]),
            };
            buf[i as usize] = v;
        }
    }

    /// Evaluates `plan` and writes its roots' values to `out`.
    fn values<R: Real>(&self, plan: &Plan, t: R, q: &[R], qd: &[R], out: &mut [R]) {
        let mut buf = vec![R::zero(); self.ops.len()];
        self.run(plan, t, q, qd, &mut buf);
        for (o, &r) in out.iter_mut().zip(&plan.roots) {
            *o = buf[r as usize];
        }
    }
}

/// The operations a set of roots needs, in order.
#[derive(Clone, Debug, Default)]
struct Plan {
    order: Vec<u32>,
    roots: Vec<u32>,
}

/// Which operations of a graph are the model's functions (indices returned by [`Graph::push`]).
#[derive(Clone, Debug, Default)]
pub struct Parts {
    /// `L(t, q, q̇)`.
    pub lagrangian: u32,
    /// `f_a(t, q, q̇)`, the velocity constraints.
    pub constraints: Vec<u32>,
    /// `h_b(t, q)`, the holonomic constraints (no velocity).
    pub holonomic: Vec<u32>,
    /// `Q_i(t, q, q̇)`, one per coordinate, or empty for none.
    pub forces: Vec<u32>,
    /// `D(t, q, q̇)`, a Rayleigh dissipation function (`Q_i = −∂D/∂q̇_i` added), or none.
    pub dissipation: Option<u32>,
}

/// A model whose `L`, `f`, `h`, `Q` and `D` are operations of one [`Graph`], shared nodes
/// evaluated once per call. A [`DynModel`], so [`chetaev::Problem::dynamic`] takes it.
#[derive(Clone, Debug)]
pub struct GraphModel {
    graph: Arc<Graph>,
    lagrangian: Plan,
    constraints: Plan,
    holonomic: Plan,
    forces: Plan,
    dissipation: Option<Plan>,
}

impl GraphModel {
    /// The model of `parts` on `graph`: every index within the graph, the holonomic constraints
    /// free of velocities, and one force per coordinate if any.
    pub fn new(graph: Graph, parts: Parts) -> Result<Self, GraphError> {
        Self::on(Arc::new(graph), parts)
    }

    fn on(graph: Arc<Graph>, parts: Parts) -> Result<Self, GraphError> {
        let g = &*graph;
        g.check_root(parts.lagrangian, "the Lagrangian")?;
        for (a, &f) in parts.constraints.iter().enumerate() {
            g.check_root(f, &format!("velocity constraint {}", a + 1))?;
        }
        for (b, &h) in parts.holonomic.iter().enumerate() {
            g.check_root(h, &format!("holonomic constraint {}", b + 1))?;
            if g.uses_velocity(h) {
                return Err(GraphError::whole(format!(
                    "holonomic constraint {} (numbered from 1) depends on the velocities; a holonomic constraint h(t, q) = 0 has none (a constraint on velocities is a velocity constraint)",
                    b + 1
                )));
            }
        }
        if !parts.forces.is_empty() && parts.forces.len() != g.n {
            return Err(GraphError::whole(format!(
                "{} generalised forces for {} coordinates; give one per coordinate (0 where none acts)",
                parts.forces.len(),
                g.n
            )));
        }
        for (i, &f) in parts.forces.iter().enumerate() {
            g.check_root(f, &format!("generalised force {}", i + 1))?;
        }
        if let Some(d) = parts.dissipation {
            g.check_root(d, "the dissipation function")?;
        }
        if parts.constraints.len() + parts.holonomic.len() > g.n {
            return Err(GraphError::whole(format!(
                "{} velocity and {} holonomic constraints on {} coordinates: at most as many constraints as coordinates",
                parts.constraints.len(),
                parts.holonomic.len(),
                g.n
            )));
        }
        Ok(Self {
            lagrangian: g.plan(&[parts.lagrangian]),
            constraints: g.plan(&parts.constraints),
            holonomic: g.plan(&parts.holonomic),
            forces: g.plan(&parts.forces),
            dissipation: parts.dissipation.map(|d| g.plan(&[d])),
            graph,
        })
    }

    /// The graph.
    pub fn graph(&self) -> &Graph {
        &self.graph
    }

    /// The same model with the parameter `name` set to `value`.
    pub fn with_parameter(&self, name: &str, value: f64) -> Result<Self, GraphError> {
        let mut m = self.clone();
        Arc::make_mut(&mut m.graph).set_parameter(name, value)?;
        Ok(m)
    }

    /// An expression on the same graph's coordinates and parameters, built on a copy of the graph
    /// (`build` adds its operations and returns its root): an event function or an output
    /// quantity.
    pub fn expression(
        &self,
        build: impl FnOnce(&mut Graph) -> Result<u32, GraphError>,
    ) -> Result<GraphExpr, GraphError> {
        let mut g = Graph {
            n: self.graph.n,
            parameters: self.graph.parameters.clone(),
            ops: Vec::new(),
            uses: Vec::new(),
        };
        let root = build(&mut g)?;
        GraphExpr::new(g, root)
    }
}

impl DynModel for GraphModel {
    fn sizes(&self) -> (usize, usize) {
        (self.graph.n, self.constraints.roots.len())
    }

    fn lagrangian<R: Real>(&self, t: R, q: &[R], qd: &[R]) -> R {
        let mut out = [R::zero()];
        self.graph.values(&self.lagrangian, t, q, qd, &mut out);
        out[0]
    }

    fn constraints<R: Real>(&self, t: R, q: &[R], qd: &[R], f: &mut [R]) {
        if !self.constraints.roots.is_empty() {
            self.graph.values(&self.constraints, t, q, qd, f);
        }
    }

    fn forces<R: Real>(&self, t: R, q: &[R], qd: &[R], out: &mut [R]) -> bool {
        if self.forces.roots.is_empty() {
            return false;
        }
        self.graph.values(&self.forces, t, q, qd, out);
        true
    }

    fn dissipation<R: Real>(&self, t: R, q: &[R], qd: &[R]) -> Option<R> {
        self.dissipation.as_ref().map(|d| {
            let mut out = [R::zero()];
            self.graph.values(d, t, q, qd, &mut out);
            out[0]
        })
    }

    fn holonomic_count(&self) -> usize {
        self.holonomic.roots.len()
    }

    fn holonomic<R: Real>(&self, t: R, q: &[R], h: &mut [R]) {
        // The plan reads no velocity (checked at construction).
        self.graph.values(&self.holonomic, t, q, q, h);
    }
}

/// One expression `g(t, q, q̇)` of a graph: an event function ([`EventFunction`], so its
/// gradient is exact) or an output quantity.
#[derive(Clone, Debug)]
pub struct GraphExpr {
    graph: Arc<Graph>,
    plan: Arc<Plan>,
}

impl GraphExpr {
    /// The expression at operation `root` of `graph`.
    pub fn new(graph: Graph, root: u32) -> Result<Self, GraphError> {
        graph.check_root(root, "the expression")?;
        let plan = Arc::new(graph.plan(&[root]));
        Ok(Self {
            graph: Arc::new(graph),
            plan,
        })
    }

    /// The value at `(t, q, q̇)`, for `f64` or any dual number.
    pub fn eval<R: Real>(&self, t: R, q: &[R], qd: &[R]) -> R {
        let mut out = [R::zero()];
        self.graph.values(&self.plan, t, q, qd, &mut out);
        out[0]
    }
}

impl EventFunction for GraphExpr {
    fn value<R: Real>(&self, t: R, q: &[R], qd: &[R]) -> R {
        self.eval(t, q, qd)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn particle() -> (Graph, Parts) {
        let mut g = Graph::new(2, vec![("g".into(), 10.0)]).expect("graph");
        let p = |g: &mut Graph, op: &str, args: &[u32], v: f64| g.push(op, args, v).expect(op);
        let grav = p(&mut g, "param", &[], 0.0);
        let y = p(&mut g, "q", &[], 1.0);
        let xd = p(&mut g, "qd", &[], 0.0);
        let yd = p(&mut g, "qd", &[], 1.0);
        let two = p(&mut g, "const", &[], 2.0);
        let xd2 = p(&mut g, "pow", &[xd, two], 0.0);
        let yd2 = p(&mut g, "pow", &[yd, two], 0.0);
        let v2 = p(&mut g, "add", &[xd2, yd2], 0.0);
        let half = p(&mut g, "const", &[], 0.5);
        let t = p(&mut g, "mul", &[half, v2], 0.0);
        let minus = p(&mut g, "const", &[], -1.0);
        let v = p(&mut g, "mul", &[minus, grav, y], 0.0);
        let l = p(&mut g, "add", &[t, v], 0.0);
        let c = p(&mut g, "const", &[], -100.0);
        let f = p(&mut g, "add", &[v2, c], 0.0);
        let parts = Parts {
            lagrangian: l,
            constraints: vec![f],
            ..Parts::default()
        };
        (g, parts)
    }

    #[test]
    fn a_shared_node_is_one_operation_and_the_model_evaluates_it() {
        let (g, parts) = particle();
        let model = GraphModel::new(g, parts).expect("model");
        let l = model.lagrangian(0.0, &[0.0, 5.0], &[3.0, 4.0]);
        assert_eq!(l, 12.5 - 50.0);
        let mut f = [0.0];
        model.constraints(0.0, &[0.0, 5.0], &[6.0, 8.0], &mut f);
        assert_eq!(f[0], 0.0);
        assert_eq!(model.sizes(), (2, 1));
    }

    #[test]
    fn constants_fold_and_powers_choose_their_evaluation() {
        let mut g = Graph::new(1, vec![]).expect("graph");
        let a = g.push("const", &[], 2.0).expect("a");
        let b = g.push("const", &[], 3.0).expect("b");
        let s = g.push("mul", &[a, b], 0.0).expect("s");
        assert_eq!(g.ops[s as usize], Op::Const(6.0));
        let x = g.push("q", &[], 0.0).expect("x");
        let half = g.push("const", &[], 0.5).expect("half");
        let cube = g.push("pow", &[x, b], 0.0).expect("cube");
        let root = g.push("pow", &[x, half], 0.0).expect("root");
        let exp = g.push("pow", &[a, x], 0.0).expect("exp");
        assert_eq!(g.ops[cube as usize], Op::PowI(x, 3));
        assert_eq!(g.ops[root as usize], Op::PowF(x, 0.5));
        assert_eq!(g.ops[exp as usize], Op::Pow(a, x));
    }

    #[test]
    fn bad_operations_are_refused_with_their_index() {
        let mut g = Graph::new(2, vec![]).expect("graph");
        let e = g.push("q", &[], 2.0).expect_err("coordinate 2 of 2");
        assert_eq!(e.op, Some(0));
        assert!(e.message.contains("coordinate 2"), "{e}");
        let e = g.push("add", &[3], 0.0).expect_err("forward reference");
        assert!(e.message.contains("does not come before"), "{e}");
        let e = g.push("sinc", &[], 0.0).expect_err("unknown");
        assert!(e.message.contains("unknown operation 'sinc'"), "{e}");
        let zero = g.push("const", &[], 0.0).expect("zero");
        let e = g.push("ln", &[zero], 0.0).expect_err("ln 0");
        assert!(e.message.contains("-inf"), "{e}");
        assert!(Graph::new(1, vec![("a".into(), 1.0), ("a".into(), 2.0)]).is_err());
        assert!(Graph::new(1, vec![("a".into(), f64::NAN)]).is_err());
    }

    #[test]
    fn a_holonomic_constraint_with_a_velocity_is_refused() {
        let (g, mut parts) = particle();
        parts.holonomic = parts.constraints.clone();
        parts.constraints.clear();
        let e = GraphModel::new(g, parts).expect_err("velocity in h");
        assert!(e.message.contains("depends on the velocities"), "{e}");
    }

    #[test]
    fn a_parameter_is_read_by_name_and_can_be_changed() {
        let (g, parts) = particle();
        let model = GraphModel::new(g, parts).expect("model");
        let moon = model.with_parameter("g", 1.62).expect("g");
        let l = moon.lagrangian(0.0, &[0.0, 1.0], &[0.0, 0.0]);
        assert_eq!(l, -1.62);
        assert!(model.with_parameter("G", 1.0).is_err());
    }
}
