//! Symbolic differentiation on the graph: reverse mode for gradients, forward mode for directional
//! derivatives. Both build new nodes in the same graph, so derivatives are folded and shared like
//! everything else, and parts that do not depend on the differentiation variables are never
//! visited.

use super::{Deps, Fun, Graph, Node};

/// No adjoint or tangent (yet) in the dense tables of [`Graph::gradient`] and
/// [`Graph::directional`]: no node has this id.
const NONE: u32 = u32::MAX;

impl Graph {
    /// The partial derivatives of node `id` with respect to its operands, as nodes.
    fn partials(&mut self, id: u32) -> ([(u32, u32); 2], usize) {
        let one = self.constant_node(1.0);
        let none = [(0, 0); 2];
        match self.nodes[id as usize] {
            Node::Const(_) | Node::Input(_) => (none, 0),
            Node::Add(a, b) => ([(a, one), (b, one)], 2),
            Node::Sub(a, b) => {
                let m = self.constant_node(-1.0);
                ([(a, one), (b, m)], 2)
            }
            Node::Mul(a, b) => ([(a, b), (b, a)], 2),
            Node::Div(a, b) => {
                let rb = self.fun(Fun::Recip, b);
                let q = self.div(id, b);
                let nq = self.neg(q);
                ([(a, rb), (b, nq)], 2)
            }
            Node::Neg(a) => {
                let m = self.constant_node(-1.0);
                ([(a, m), (0, 0)], 1)
            }
            Node::Powi(a, n) => {
                let p = self.push(Node::Powi(a, n - 1));
                let d = self.scale(n as f64, p);
                ([(a, d), (0, 0)], 1)
            }
            Node::Powf(a, e) => {
                let p = self.push(Node::Powf(a, e - 1.0));
                let d = self.scale(e, p);
                ([(a, d), (0, 0)], 1)
            }
            Node::Atan2(a, b) => {
                let (aa, bb) = (self.mul(a, a), self.mul(b, b));
                let r = self.add(aa, bb);
                let da = self.div(b, r);
                let q = self.div(a, r);
                let db = self.neg(q);
                ([(a, da), (b, db)], 2)
            }
            Node::Fun(f, a) => {
                let d = self.fun_derivative(f, a, id);
                match d {
                    Some(d) => ([(a, d), (0, 0)], 1),
                    None => (none, 0),
                }
            }
        }
    }

    /// `f'(a)` as a node, where `y = f(a)` is node `y`; `None` where it is zero.
    fn fun_derivative(&mut self, f: Fun, a: u32, y: u32) -> Option<u32> {
        let one = self.constant_node(1.0);
        let aa = |g: &mut Self| g.mul(a, a);
        Some(match f {
            Fun::Sqrt => {
                let h = self.constant_node(0.5);
                self.div(h, y)
            }
            Fun::Cbrt => {
                let a3 = self.scale(3.0, a);
                self.div(y, a3)
            }
            Fun::Exp => y,
            Fun::Exp2 => self.scale(std::f64::consts::LN_2, y),
            Fun::ExpM1 => self.add(y, one),
            Fun::Ln => self.fun(Fun::Recip, a),
            Fun::Log2 => {
                let s = self.scale(std::f64::consts::LN_2, a);
                self.fun(Fun::Recip, s)
            }
            Fun::Log10 => {
                let s = self.scale(std::f64::consts::LN_10, a);
                self.fun(Fun::Recip, s)
            }
            Fun::Ln1p => {
                let s = self.add(one, a);
                self.fun(Fun::Recip, s)
            }
            Fun::Sin => self.fun(Fun::Cos, a),
            Fun::Cos => {
                let s = self.fun(Fun::Sin, a);
                self.neg(s)
            }
            Fun::Tan => {
                let yy = self.mul(y, y);
                self.add(one, yy)
            }
            Fun::Asin | Fun::Acos => {
                let a2 = aa(self);
                let d = self.sub(one, a2);
                let r = self.fun(Fun::Sqrt, d);
                let inv = self.fun(Fun::Recip, r);
                if f == Fun::Asin {
                    inv
                } else {
                    self.neg(inv)
                }
            }
            Fun::Atan => {
                let a2 = aa(self);
                let d = self.add(one, a2);
                self.fun(Fun::Recip, d)
            }
            Fun::Sinh => self.fun(Fun::Cosh, a),
            Fun::Cosh => self.fun(Fun::Sinh, a),
            Fun::Tanh => {
                let yy = self.mul(y, y);
                self.sub(one, yy)
            }
            Fun::Asinh => {
                let a2 = aa(self);
                let d = self.add(a2, one);
                let r = self.fun(Fun::Sqrt, d);
                self.fun(Fun::Recip, r)
            }
            Fun::Acosh => {
                let a2 = aa(self);
                let d = self.sub(a2, one);
                let r = self.fun(Fun::Sqrt, d);
                self.fun(Fun::Recip, r)
            }
            Fun::Atanh => {
                let a2 = aa(self);
                let d = self.sub(one, a2);
                self.fun(Fun::Recip, d)
            }
            Fun::Abs => self.fun(Fun::Signum, a),
            Fun::Signum => return None,
            Fun::Recip => {
                let yy = self.mul(y, y);
                self.neg(yy)
            }
        })
    }

    /// Reverse mode: `∂y/∂x` for each node `x` of `wrt`, which must be inputs of the classes in
    /// `mask` (nodes that depend on none of those classes are not visited).
    pub fn gradient(&mut self, y: u32, wrt: &[u32], mask: Deps) -> Vec<u32> {
        let zero = self.constant_node(0.0);
        if self.deps(y) & mask == 0 {
            return vec![zero; wrt.len()];
        }
        let order = self.reachable(&[y]);
        // Adjoints by node id: every node visited is at most `y`, and the nodes made on the way
        // are never read back.
        let mut adjoint = vec![NONE; y as usize + 1];
        adjoint[y as usize] = self.constant_node(1.0);
        for &id in order.iter().rev() {
            let a = adjoint[id as usize];
            if a == NONE || matches!(self.nodes[id as usize], Node::Input(_)) {
                continue;
            }
            let (parts, count) = self.partials(id);
            for &(operand, d) in &parts[..count] {
                if self.deps(operand) & mask == 0 {
                    continue;
                }
                let contribution = self.mul(a, d);
                let prev = adjoint[operand as usize];
                adjoint[operand as usize] = if prev == NONE {
                    contribution
                } else {
                    self.add(prev, contribution)
                };
            }
        }
        wrt.iter()
            .map(|&x| match adjoint.get(x as usize) {
                Some(&a) if a != NONE => a,
                _ => zero,
            })
            .collect()
    }

    /// Forward mode: the derivative of each of `ys` along the tangent that gives input node `x`
    /// the tangent node `dx` for each `(x, dx)` of `seeds` (and every other input zero). `mask`
    /// names the classes of the seeded inputs.
    pub fn directional(&mut self, ys: &[u32], seeds: &[(u32, u32)], mask: Deps) -> Vec<u32> {
        let zero = self.constant_node(0.0);
        let order = self.reachable(ys);
        // Tangents by node id, up to the last node visited or seeded.
        let len = order
            .last()
            .copied()
            .into_iter()
            .chain(seeds.iter().map(|&(x, _)| x))
            .max()
            .map_or(0, |m| m as usize + 1);
        let mut tangent = vec![NONE; len];
        for &(x, dx) in seeds {
            tangent[x as usize] = dx;
        }
        for &id in &order {
            if self.deps(id) & mask == 0 || matches!(self.nodes[id as usize], Node::Input(_)) {
                continue;
            }
            let (parts, count) = self.partials(id);
            let mut acc: Option<u32> = None;
            for &(operand, d) in &parts[..count] {
                let t = tangent[operand as usize];
                if t == NONE {
                    continue;
                }
                let term = self.mul(d, t);
                acc = Some(match acc {
                    Some(s) => self.add(s, term),
                    None => term,
                });
            }
            if let Some(t) = acc {
                tangent[id as usize] = t;
            }
        }
        ys.iter()
            .map(|&y| match tangent.get(y as usize) {
                Some(&t) if t != NONE => t,
                _ => zero,
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::super::{record, Sym, DEP_Q, DEP_QD};
    use crate::model::Real;

    fn f<R: Real>(x: R, y: R) -> R {
        (x * y).sin() + x.powi(3) / y - (x * x + y * y).sqrt() + y.atan2(x) * x.exp()
    }

    #[test]
    fn gradient_and_directional_agree_with_dual_numbers() {
        let (x0, y0) = (0.7, -1.3);
        let (mut g, (x, y, out)) = record(|| {
            let x = Sym::input(DEP_Q, x0);
            let y = Sym::input(DEP_QD, y0);
            (x, y, f(x, y))
        });
        let (xn, yn, on) = (x.node(), y.node(), out.node());
        let grad_y = g.gradient(on, &[yn], DEP_QD)[0];
        let grad_x = g.gradient(on, &[xn], DEP_Q)[0];
        // Along (δx, δy) = (y, 0): the shape of g in the equations.
        let dir = g.directional(&[on], &[(xn, yn)], DEP_Q)[0];
        let tape = super::super::Tape::new(&g, &[grad_x, grad_y, dir]);
        let mut slots = tape.slots::<f64>();
        tape.eval(&mut slots, |x| x.copy_from_slice(&[x0, y0]))
            .expect("no guards");
        let dx = num_dual::first_derivative(|x| f(x, num_dual::Dual64::from(y0)), x0).1;
        let dy = num_dual::first_derivative(|y| f(num_dual::Dual64::from(x0), y), y0).1;
        assert!((tape.output(&slots, 0) - dx).abs() < 1e-13 * dx.abs().max(1.0));
        assert!((tape.output(&slots, 1) - dy).abs() < 1e-13 * dy.abs().max(1.0));
        assert!((tape.output(&slots, 2) - dx * y0).abs() < 1e-13 * dx.abs().max(1.0));
    }
}
