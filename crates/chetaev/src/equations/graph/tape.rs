//! A compiled list of the operations that some outputs of a [`Graph`] need, evaluated over any
//! scalar `T: Real` (`f64`, or a dual number for the Jacobian of the implicit methods).
//!
//! Slots are laid out as `[inputs | constants | computed]`; only nodes reachable from the outputs
//! (and from the guards) are kept, in topological order. Constant nodes are written once when
//! the slots are made ([`Tape::slots`]).

use std::cmp::Ordering;

use super::{Graph, Node};
use crate::model::Real;

/// A guard that no longer holds: the branch the model took when recorded is not the one it takes
/// here.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GuardFlip {
    /// The guard's index in [`Graph::guards`].
    pub index: usize,
}

/// Operations over slots; see the module docs.
#[derive(Clone, Debug)]
pub struct Tape {
    inputs: usize,
    constants: Vec<f64>,
    ops: Vec<Node>,
    outputs: Vec<u32>,
    guards: Vec<(u32, u32, Option<Ordering>)>,
}

impl Tape {
    /// The tape of `outputs` (node ids of `graph`), re-checking every guard of the graph.
    pub fn new(graph: &Graph, outputs: &[u32]) -> Self {
        let mut roots: Vec<u32> = outputs.to_vec();
        for g in graph.guards() {
            roots.push(g.a);
            roots.push(g.b);
        }
        let order = graph.reachable(&roots);
        let inputs = graph.inputs.len();
        let mut slot = vec![u32::MAX; graph.nodes().len()];
        let mut constants = Vec::new();
        for &id in &order {
            match graph.nodes()[id as usize] {
                Node::Input(i) => slot[id as usize] = i,
                Node::Const(c) => {
                    slot[id as usize] = (inputs + constants.len()) as u32;
                    constants.push(c);
                }
                _ => {}
            }
        }
        let base = inputs + constants.len();
        let mut ops = Vec::new();
        for &id in &order {
            let node = graph.nodes()[id as usize];
            if matches!(node, Node::Input(_) | Node::Const(_)) {
                continue;
            }
            let s = |o: u32| slot[o as usize];
            let op = match node {
                Node::Add(a, b) => Node::Add(s(a), s(b)),
                Node::Sub(a, b) => Node::Sub(s(a), s(b)),
                Node::Mul(a, b) => Node::Mul(s(a), s(b)),
                Node::Div(a, b) => Node::Div(s(a), s(b)),
                Node::Neg(a) => Node::Neg(s(a)),
                Node::Powi(a, n) => Node::Powi(s(a), n),
                Node::Powf(a, p) => Node::Powf(s(a), p),
                Node::Atan2(a, b) => Node::Atan2(s(a), s(b)),
                Node::Fun(f, a) => Node::Fun(f, s(a)),
                Node::Input(_) | Node::Const(_) => unreachable!("skipped above"),
            };
            slot[id as usize] = (base + ops.len()) as u32;
            ops.push(op);
        }
        Self {
            inputs,
            constants,
            ops,
            outputs: outputs.iter().map(|&o| slot[o as usize]).collect(),
            guards: graph
                .guards()
                .iter()
                .map(|g| (slot[g.a as usize], slot[g.b as usize], g.outcome))
                .collect(),
        }
    }

    /// Fresh slots for this tape, with the constants in place.
    pub fn slots<T: Real>(&self) -> Vec<T> {
        let mut s = vec![T::zero(); self.inputs + self.constants.len() + self.ops.len()];
        for (dst, &c) in s[self.inputs..].iter_mut().zip(&self.constants) {
            *dst = T::from(c);
        }
        s
    }

    /// The number of operations evaluated per call.
    pub fn len(&self) -> usize {
        self.ops.len()
    }

    /// Evaluates the tape with input `i` equal to `input(i)`, into `slots` (made by
    /// [`Tape::slots`]); then checks the guards.
    #[inline]
    pub fn eval<T: Real>(
        &self,
        slots: &mut [T],
        input: impl Fn(usize) -> T,
    ) -> Result<(), GuardFlip> {
        for (i, s) in slots[..self.inputs].iter_mut().enumerate() {
            *s = input(i);
        }
        let base = self.inputs + self.constants.len();
        for (k, op) in self.ops.iter().enumerate() {
            let v = op.eval(|o| slots[o as usize]);
            slots[base + k] = v;
        }
        for (index, &(a, b, outcome)) in self.guards.iter().enumerate() {
            let (a, b) = (slots[a as usize].re(), slots[b as usize].re());
            if a.partial_cmp(&b) != outcome {
                return Err(GuardFlip { index });
            }
        }
        Ok(())
    }

    /// Output `i` after [`Tape::eval`].
    #[inline]
    pub fn output<T: Copy>(&self, slots: &[T], i: usize) -> T {
        slots[self.outputs[i] as usize]
    }
}
