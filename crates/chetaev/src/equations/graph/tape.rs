//! A compiled list of the operations that some outputs of a [`Graph`] need, evaluated over any
//! scalar `T: Real` (`f64`, or a dual number for the Jacobian of the implicit methods).
//!
//! Slots are laid out as `[inputs | constants | computed]`; only nodes reachable from the outputs
//! (and from the guards) are kept, in an order that respects their dependencies. Constant nodes are
//! written once when the slots are made ([`Tape::slots`]).
//!
//! **Runs.** A model written with loops over its coordinates records the same operation once per
//! coordinate: `q̇_i · q̇_i` for every `i`, then the sum `s_i = s_{i−1} + m_i`. The tape orders its
//! operations so that such repetitions stand next to each other and stores each as one [`Run`]:
//! `len` operations of one kind whose operand slots advance by fixed strides (`0` for a shared
//! operand, `1` for consecutive coordinates; a sum's running total is the run's own previous
//! element). A run is evaluated by one loop, with no dispatch per operation, so the cost of a large
//! model's right-hand side approaches that of the loops a person would write. Every operation is
//! the same arithmetic on the same operands as in the graph, so the values do not depend on how
//! the operations were grouped.

use std::cmp::{Ordering, Reverse};
use std::collections::BinaryHeap;

use super::{Graph, Node};
use crate::model::Real;

/// A guard that no longer holds: the branch the model took when recorded is not the one it takes
/// here.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GuardFlip {
    /// The guard's index in [`Graph::guards`].
    pub index: usize,
}

/// `len` operations of the kind of `first`, writing consecutive slots: element `j` applies that
/// operation to the slots `a + j·da` and `b + j·db`, where `a` and `b` are `first`'s operand
/// slots (`b` and `db` unused for an operation of one operand).
#[derive(Clone, Copy, Debug)]
struct Run {
    first: Node,
    da: i32,
    db: i32,
    len: u32,
    /// How the elements depend on each other.
    links: Links,
}

/// How the elements of a [`Run`] depend on each other.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Links {
    /// Every operand comes before the run: the elements are independent.
    Apart,
    /// Operand `a` (`0`) or `b` (`1`) is the previous element, the other operand comes before
    /// the run: a running sum or product, kept in a register from element to element.
    Running(u8),
    /// Any other reference into the run: the elements are evaluated one after the other from the
    /// slots as they are written.
    Chained,
}

impl Run {
    /// Classifies the run's dependences, the run starting at slot `out`.
    fn link(&mut self, out: u32) {
        let ([a, b], count) = self.first.operands();
        let len = i64::from(self.len);
        let last = |x: u32, d: i32| i64::from(x) + i64::from(d.max(0)) * (len - 1);
        let before = |x: u32, d: i32| last(x, d) < i64::from(out);
        let previous = |x: u32, d: i32| d == 1 && x + 1 == out;
        let b_before = count < 2 || before(b, self.db);
        self.links = if before(a, self.da) && b_before {
            Links::Apart
        } else if previous(a, self.da) && b_before {
            Links::Running(0)
        } else if count == 2 && previous(b, self.db) && before(a, self.da) {
            Links::Running(1)
        } else {
            Links::Chained
        };
    }
}

/// Operations over slots; see the module docs.
#[derive(Clone, Debug)]
pub struct Tape {
    inputs: usize,
    constants: Vec<f64>,
    runs: Vec<Run>,
    operations: usize,
    outputs: Vec<u32>,
    /// The outputs as stretches of slots one apart (rising or falling), for copying them out by
    /// the stretch: `(first output, first slot, len, rising)`.
    stretches: Vec<(u32, u32, u32, bool)>,
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
        let mut fixed = Vec::new();
        for &id in &order {
            match graph.nodes()[id as usize] {
                Node::Input(i) => {
                    slot[id as usize] = i;
                    fixed.push((i, id));
                }
                Node::Const(c) => {
                    let s = (inputs + constants.len()) as u32;
                    slot[id as usize] = s;
                    fixed.push((s, id));
                    constants.push(c);
                }
                _ => {}
            }
        }
        let base = inputs + constants.len();
        let ops: Vec<u32> = order
            .iter()
            .copied()
            .filter(|&id| !matches!(graph.nodes()[id as usize], Node::Input(_) | Node::Const(_)))
            .collect();
        let mut node_at = vec![u32::MAX; base + ops.len()];
        for (s, id) in fixed {
            node_at[s as usize] = id;
        }
        let runs = Scheduler::new(graph, &ops, slot, node_at, base).run();
        let slot = runs.1;
        let outputs: Vec<u32> = outputs.iter().map(|&o| slot[o as usize]).collect();
        Self {
            inputs,
            constants,
            runs: runs.0,
            operations: ops.len(),
            stretches: stretches(&outputs),
            outputs,
            guards: graph
                .guards()
                .iter()
                .map(|g| (slot[g.a as usize], slot[g.b as usize], g.outcome))
                .collect(),
        }
    }

    /// The number of slots of [`Tape::slots`].
    pub fn slot_count(&self) -> usize {
        self.inputs + self.constants.len() + self.operations
    }

    /// Fresh slots for this tape, with the constants in place.
    pub fn slots<T: Real>(&self) -> Vec<T> {
        let mut s = vec![T::zero(); self.slot_count()];
        for (dst, &c) in s[self.inputs..].iter_mut().zip(&self.constants) {
            *dst = T::from(c);
        }
        s
    }

    /// The number of operations evaluated per call.
    pub fn len(&self) -> usize {
        self.operations
    }

    /// The number of runs the operations are grouped into (see the module docs): the dispatches
    /// per call.
    pub fn runs(&self) -> usize {
        self.runs.len()
    }

    /// Evaluates the tape into `slots` (made by [`Tape::slots`]), after `inputs` has written the
    /// inputs into the first of them; then checks the guards.
    #[inline]
    pub fn eval<T: Real>(
        &self,
        slots: &mut [T],
        inputs: impl FnOnce(&mut [T]),
    ) -> Result<(), GuardFlip> {
        inputs(&mut slots[..self.inputs]);
        let mut out = self.inputs + self.constants.len();
        for run in &self.runs {
            if run.len == 1 {
                slots[out] = run.first.eval(|o| slots[o as usize]);
            } else {
                run.eval(slots, out);
            }
            out += run.len as usize;
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

    /// Outputs `first..first + dst.len()` after [`Tape::eval`] into `dst`, a stretch of slots at a
    /// time.
    #[inline]
    pub fn outputs<T: Copy>(&self, slots: &[T], first: usize, dst: &mut [T]) {
        let end = first + dst.len();
        let at = self
            .stretches
            .partition_point(|s| (s.0 + s.2) as usize <= first);
        for &(o, slot, len, rising) in &self.stretches[at..] {
            let (o, slot, len) = (o as usize, slot as usize, len as usize);
            if o >= end {
                break;
            }
            // The part of this stretch inside the range, as outputs `lo..hi`.
            let (lo, hi) = (o.max(first), (o + len).min(end));
            let out = &mut dst[lo - first..hi - first];
            if rising {
                let from = slot + (lo - o);
                out.copy_from_slice(&slots[from..from + out.len()]);
            } else {
                let top = slot - (lo - o);
                let src = &slots[top + 1 - out.len()..=top];
                for (d, &v) in out.iter_mut().zip(src.iter().rev()) {
                    *d = v;
                }
            }
        }
    }
}

/// The stretches of [`Tape::outputs`]: maximal runs of output slots one apart.
fn stretches(outputs: &[u32]) -> Vec<(u32, u32, u32, bool)> {
    let mut out: Vec<(u32, u32, u32, bool)> = Vec::new();
    for (i, &s) in outputs.iter().enumerate() {
        if let Some(last) = out.last_mut() {
            let (start, len, s) = (i64::from(last.1), i64::from(last.2), i64::from(s));
            let (up, down) = (s == start + len, s == start - len);
            if (len == 1 && (up || down)) || (last.3 && up) || (!last.3 && down) {
                last.2 += 1;
                last.3 = up;
                continue;
            }
        }
        out.push((i as u32, s, 1, true));
    }
    out
}

impl Run {
    /// Evaluates the run's elements into `slots[out..out + len]`.
    #[inline]
    fn eval<T: Real>(&self, slots: &mut [T], out: usize) {
        let ([a, b], _) = self.first.operands();
        let (a, b) = (a as usize, b as usize);
        let (da, db) = (self.da as isize, self.db as isize);
        match self.first {
            Node::Add(..) => self.binary(slots, out, (a, da), (b, db), |x, y| x + y),
            Node::Sub(..) => self.binary(slots, out, (a, da), (b, db), |x, y| x - y),
            Node::Mul(..) => self.binary(slots, out, (a, da), (b, db), |x, y| x * y),
            Node::Div(..) => self.binary(slots, out, (a, da), (b, db), |x, y| x / y),
            Node::Atan2(..) => self.binary(slots, out, (a, da), (b, db), |x, y| x.atan2(y)),
            Node::Neg(_) => self.unary(slots, out, (a, da), |x| -x),
            Node::Powi(_, n) => self.unary(slots, out, (a, da), |x| x.powi(n)),
            Node::Powf(_, p) => self.unary(slots, out, (a, da), |x| super::powf(x, p)),
            Node::Fun(f, _) => self.unary(slots, out, (a, da), |x| f.apply(x)),
            Node::Const(_) | Node::Input(_) => unreachable!("inputs and constants are not run"),
        }
    }

    /// A run of an operation of two operands.
    #[inline(always)]
    fn binary<T: Copy>(
        &self,
        slots: &mut [T],
        out: usize,
        (a, da): (usize, isize),
        (b, db): (usize, isize),
        op: impl Fn(T, T) -> T,
    ) {
        let len = self.len as usize;
        let at = |s: usize, d: isize, j: usize| s.wrapping_add_signed(d * j as isize);
        if self.links == Links::Chained {
            for j in 0..len {
                slots[out + j] = op(slots[at(a, da, j)], slots[at(b, db, j)]);
            }
            return;
        }
        // Every operand read from the slots comes before the run: the read and written halves
        // can be borrowed apart.
        let (src, dst) = slots.split_at_mut(out);
        let dst = &mut dst[..len];
        match (self.links, da, db) {
            (Links::Running(0), _, 1) => running(dst, src[a], &src[b..b + len], &op),
            (Links::Running(1), 1, _) => {
                running(dst, src[b], &src[a..a + len], |acc, x| op(x, acc))
            }
            (Links::Running(0), _, _) => {
                let mut acc = src[a];
                for (j, d) in dst.iter_mut().enumerate() {
                    acc = op(acc, src[at(b, db, j)]);
                    *d = acc;
                }
            }
            (Links::Running(_), _, _) => {
                let mut acc = src[b];
                for (j, d) in dst.iter_mut().enumerate() {
                    acc = op(src[at(a, da, j)], acc);
                    *d = acc;
                }
            }
            (_, 1, 1) => {
                for ((d, &x), &y) in dst.iter_mut().zip(&src[a..a + len]).zip(&src[b..b + len]) {
                    *d = op(x, y);
                }
            }
            (_, 0, 1) => {
                let x = src[a];
                for (d, &y) in dst.iter_mut().zip(&src[b..b + len]) {
                    *d = op(x, y);
                }
            }
            (_, 1, 0) => {
                let y = src[b];
                for (d, &x) in dst.iter_mut().zip(&src[a..a + len]) {
                    *d = op(x, y);
                }
            }
            // Reverse-mode derivatives come out in the reverse order of the coordinates.
            (_, -1, -1) => {
                let (xs, ys) = (&src[a + 1 - len..=a], &src[b + 1 - len..=b]);
                for ((d, &x), &y) in dst.iter_mut().zip(xs.iter().rev()).zip(ys.iter().rev()) {
                    *d = op(x, y);
                }
            }
            (_, -1, 0) => {
                let y = src[b];
                for (d, &x) in dst.iter_mut().zip(src[a + 1 - len..=a].iter().rev()) {
                    *d = op(x, y);
                }
            }
            (_, 0, -1) => {
                let x = src[a];
                for (d, &y) in dst.iter_mut().zip(src[b + 1 - len..=b].iter().rev()) {
                    *d = op(x, y);
                }
            }
            _ => {
                for (j, d) in dst.iter_mut().enumerate() {
                    *d = op(src[at(a, da, j)], src[at(b, db, j)]);
                }
            }
        }
    }

    /// A run of an operation of one operand.
    #[inline(always)]
    fn unary<T: Copy>(
        &self,
        slots: &mut [T],
        out: usize,
        (a, da): (usize, isize),
        op: impl Fn(T) -> T,
    ) {
        let len = self.len as usize;
        let at = |j: usize| a.wrapping_add_signed(da * j as isize);
        if self.links != Links::Apart {
            for j in 0..len {
                slots[out + j] = op(slots[at(j)]);
            }
            return;
        }
        let (src, dst) = slots.split_at_mut(out);
        if da == 1 {
            for (d, &x) in dst[..len].iter_mut().zip(&src[a..a + len]) {
                *d = op(x);
            }
        } else if da == -1 {
            for (d, &x) in dst[..len].iter_mut().zip(src[a + 1 - len..=a].iter().rev()) {
                *d = op(x);
            }
        } else {
            for (j, d) in dst[..len].iter_mut().enumerate() {
                *d = op(src[at(j)]);
            }
        }
    }
}

/// `dst[j] = acc = op(acc, other[j])` from `acc = start`: a running sum or product.
#[inline(always)]
fn running<T: Copy>(dst: &mut [T], start: T, other: &[T], op: impl Fn(T, T) -> T) {
    let mut acc = start;
    for (d, &y) in dst.iter_mut().zip(other) {
        acc = op(acc, y);
        *d = acc;
    }
}

/// Orders the operations of a tape into runs: after each operation it takes, if it is ready, the
/// one that continues the current run (same kind, operands at the run's strides); otherwise the
/// earliest ready operation of the graph's own order, which starts a new run.
struct Scheduler<'g> {
    graph: &'g Graph,
    /// Each node's slot (`u32::MAX` until it is placed).
    slot: Vec<u32>,
    /// Each slot's node.
    node_at: Vec<u32>,
    /// The next free slot.
    next: u32,
    /// For each operation (by position in the graph's order), how many of its operands are
    /// operations not yet placed; and the positions of the operations using each one.
    pending: Vec<u8>,
    users: Vec<Vec<u32>>,
    /// For each node, a bit for each kind of operation among its users here (see
    /// [`Node::kind_bit`]): a continuation of a kind that no user of its operands has is ruled
    /// out without a search.
    user_kinds: Vec<u64>,
    position: Vec<u32>,
    ops: &'g [u32],
    ready: BinaryHeap<Reverse<u32>>,
}

impl<'g> Scheduler<'g> {
    fn new(
        graph: &'g Graph,
        ops: &'g [u32],
        slot: Vec<u32>,
        node_at: Vec<u32>,
        base: usize,
    ) -> Self {
        let mut position = vec![u32::MAX; graph.nodes().len()];
        for (p, &id) in ops.iter().enumerate() {
            position[id as usize] = p as u32;
        }
        let mut pending = vec![0u8; ops.len()];
        let mut users = vec![Vec::new(); ops.len()];
        let mut ready = BinaryHeap::new();
        let mut user_kinds = vec![0u64; graph.nodes().len()];
        for (p, &id) in ops.iter().enumerate() {
            let node = &graph.nodes()[id as usize];
            let (operands, count) = node.operands();
            let operands = &operands[..count];
            for (i, &o) in operands.iter().enumerate() {
                user_kinds[o as usize] |= node.kind_bit();
                let op = position[o as usize];
                if op != u32::MAX && !operands[..i].contains(&o) {
                    pending[p] += 1;
                    users[op as usize].push(p as u32);
                }
            }
            if pending[p] == 0 {
                ready.push(Reverse(p as u32));
            }
        }
        Self {
            graph,
            slot,
            node_at,
            next: base as u32,
            pending,
            users,
            user_kinds,
            position,
            ops,
            ready,
        }
    }

    /// The runs in evaluation order, their operands as slots; and every node's slot.
    fn run(mut self) -> (Vec<Run>, Vec<u32>) {
        let mut runs: Vec<Run> = Vec::new();
        let mut placed = vec![false; self.ops.len()];
        let mut left = self.ops.len();
        while left > 0 {
            let continued = runs.last().and_then(|r| self.continuation(r, &placed));
            let (p, strides) = match continued {
                Some(c) => c,
                None => {
                    let Some(Reverse(p)) = self.ready.pop() else {
                        unreachable!("a graph in topological order always has a ready operation")
                    };
                    if placed[p as usize] {
                        continue;
                    }
                    (p, None)
                }
            };
            placed[p as usize] = true;
            left -= 1;
            self.place(p);
            let node = self.graph.nodes()[self.ops[p as usize] as usize];
            let node = node.map_operands(|_, o| self.slot[o as usize]);
            match (strides, runs.last_mut()) {
                (Some((da, db)), Some(run)) => {
                    if run.len == 1 {
                        (run.da, run.db) = (da, db);
                    }
                    run.len += 1;
                }
                _ => runs.push(Run {
                    first: node,
                    da: 0,
                    db: 0,
                    len: 1,
                    links: Links::Apart,
                }),
            }
        }
        let mut out = self.next;
        for run in runs.iter_mut().rev() {
            out -= run.len;
            run.link(out);
        }
        (runs, self.slot)
    }

    /// Gives operation `p` the next slot and releases its users.
    fn place(&mut self, p: u32) {
        let id = self.ops[p as usize];
        let s = self.next;
        self.next += 1;
        self.slot[id as usize] = s;
        self.node_at[s as usize] = id;
        for &u in &self.users[p as usize] {
            self.pending[u as usize] -= 1;
            if self.pending[u as usize] == 0 {
                self.ready.push(Reverse(u));
            }
        }
    }

    /// The ready operation that continues `run` and its strides `(da, db)`: with two or more
    /// elements at the run's strides; after its first element at the first of the usual strides
    /// (the next coordinate, the same operand, the element just written) that finds one.
    fn continuation(&self, run: &Run, placed: &[bool]) -> Option<(u32, Option<(i32, i32)>)> {
        let last = self.next - 1;
        let ([a0, b0], count) = run.first.operands();
        let steps = (run.len - 1) as i64;
        let (a, b) = (
            i64::from(a0) + steps * i64::from(run.da),
            i64::from(b0) + steps * i64::from(run.db),
        );
        let chain = |s: i64| (i64::from(last) - s) as i32;
        // The next coordinate either way, the same operand, or the element just written; after
        // the run's second element, its strides.
        let steps = |s: i64| [1, -1, 0, chain(s)];
        let (steps_a, steps_b) = (steps(a), steps(b));
        let (steps_a, steps_b): (&[i32], &[i32]) = match (run.len > 1, count) {
            (true, _) => (&[run.da], &[run.db]),
            (false, 2) => (&steps_a, &steps_b),
            (false, _) => (&steps_a, &[0]),
        };
        let guesses = steps_a
            .iter()
            .flat_map(|&da| steps_b.iter().map(move |&db| (da, db)))
            .filter(|&(da, db)| run.len > 1 || (da, db) != (0, 0));
        let node_of = |s: i64| {
            let s = usize::try_from(s).ok()?;
            self.node_at.get(s).copied().filter(|&id| id != u32::MAX)
        };
        let bit = run.first.kind_bit();
        let used = |id: u32| self.user_kinds[id as usize] & bit != 0;
        guesses.into_iter().find_map(|(da, db)| {
            let na = node_of(a + i64::from(da)).filter(|&id| used(id))?;
            let nb = if count == 2 {
                node_of(b + i64::from(db)).filter(|&id| used(id))?
            } else {
                0
            };
            let candidate = run.first.map_operands(|i, _| if i == 0 { na } else { nb });
            let p = *self.position.get(self.graph.find(&candidate)? as usize)?;
            let ready = p != u32::MAX && !placed[p as usize] && self.pending[p as usize] == 0;
            ready.then_some((p, Some((da, db))))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::super::{record, Sym, DEP_Q, DEP_QD};
    use super::*;

    /// Loops of the shapes a model's code takes: elementwise products, running sums and
    /// products, loops run backwards, strides of two, a shared operand, unary functions, and a
    /// value used inside and outside its loop.
    fn loops<R: Real>(q: &[R], qd: &[R]) -> Vec<R> {
        let n = q.len();
        let kinetic = qd.iter().fold(R::zero(), |acc, &v| acc + v * v);
        let potential = q
            .iter()
            .rev()
            .fold(R::zero(), |acc, &x| acc + x.cos() * 3.0);
        let product = q.iter().fold(R::one(), |acc, &x| acc * (x + 2.0));
        let mut out = vec![kinetic - potential, product];
        out.extend((0..n).step_by(2).map(|i| q[i] * qd[n - 1 - i] - kinetic));
        out.extend((0..n).rev().map(|i| (qd[i] / q[i]).sqrt().exp()));
        out.extend(
            q.iter()
                .zip(qd)
                .map(|(&x, &v)| x.atan2(v).powi(3) - v.powf(0.5)),
        );
        out
    }

    #[test]
    fn runs_give_the_values_of_the_recorded_operations() {
        let n = 9u32;
        let q0: Vec<f64> = (0..n).map(|i| 0.3 + 0.1 * f64::from(i)).collect();
        let qd0: Vec<f64> = (0..n).map(|i| 1.7 - 0.15 * f64::from(i)).collect();
        let (graph, outs) = record(|| {
            let q: Vec<Sym> = q0.iter().map(|&x| Sym::input(DEP_Q, x)).collect();
            let qd: Vec<Sym> = qd0.iter().map(|&v| Sym::input(DEP_QD, v)).collect();
            loops(&q, &qd).iter().map(|o| o.node()).collect::<Vec<_>>()
        });
        let tape = Tape::new(&graph, &outs);
        assert!(
            tape.runs() * 3 < tape.len(),
            "{} runs for {} operations: the loops were not found",
            tape.runs(),
            tape.len()
        );
        let mut slots = tape.slots::<f64>();
        tape.eval(&mut slots, |x| {
            x[..n as usize].copy_from_slice(&q0);
            x[n as usize..].copy_from_slice(&qd0);
        })
        .expect("no guards");
        let direct = loops(&q0, &qd0);
        for (i, (&node, &d)) in outs.iter().zip(&direct).enumerate() {
            let v = tape.output(&slots, i);
            assert_eq!(v.to_bits(), graph.value(node).to_bits(), "output {i}");
            assert_eq!(
                v.to_bits(),
                d.to_bits(),
                "output {i} against the code itself"
            );
        }
        // At another point, against the code run directly.
        let (q1, qd1): (Vec<f64>, Vec<f64>) = (0..n)
            .map(|i| (0.9 - 0.05 * f64::from(i), 0.4 + 0.2 * f64::from(i)))
            .unzip();
        tape.eval(&mut slots, |x| {
            x[..n as usize].copy_from_slice(&q1);
            x[n as usize..].copy_from_slice(&qd1);
        })
        .expect("no guards");
        for (i, d) in loops(&q1, &qd1).into_iter().enumerate() {
            assert_eq!(tape.output(&slots, i).to_bits(), d.to_bits(), "output {i}");
        }
    }

    #[test]
    fn outputs_are_copied_by_stretches_as_one_by_one() {
        // Rising, falling, single and repeated slots, and a stretch split by the range.
        let slots: Vec<f64> = (0..20).map(|i| f64::from(i) * 1.5).collect();
        let outputs = vec![3, 4, 5, 9, 8, 7, 6, 12, 12, 0, 19, 18];
        let tape = Tape {
            inputs: 0,
            constants: Vec::new(),
            runs: Vec::new(),
            operations: 0,
            stretches: stretches(&outputs),
            outputs: outputs.clone(),
            guards: Vec::new(),
        };
        assert_eq!(
            tape.stretches,
            vec![
                (0, 3, 3, true),
                (3, 9, 4, false),
                (7, 12, 1, true),
                (8, 12, 1, true),
                (9, 0, 1, true),
                (10, 19, 2, false),
            ]
        );
        for first in 0..outputs.len() {
            for len in 0..=outputs.len() - first {
                let mut dst = vec![f64::NAN; len];
                tape.outputs(&slots, first, &mut dst);
                let expected: Vec<f64> = (first..first + len)
                    .map(|i| tape.output(&slots, i))
                    .collect();
                assert_eq!(dst, expected, "outputs {first}..{}", first + len);
            }
        }
    }
}
