//! Which expression of a scene's model is not finite at a state, when `chetaev` reports only that
//! "the model" is ([`chetaev::Error::NonFiniteEvaluation`]).
//!
//! The library evaluates the Lagrangian, the constraints, the forces and their derivatives
//! together, so its error cannot say which of them left its domain. The scene knows its
//! expressions: each is evaluated again at the state, in this order, and the first that is not
//! finite is named, by its source in the file and its place there.
//!
//! | level | what is evaluated | of |
//! |---|---|---|
//! | 0 | the value | `L`, each `f_a`, each `h_b`, each `Q_i`, each component of a load's `r`, `F`, `ω`, `T`, `D` |
//! | 1 | the first derivatives by `t`, `q`, `q̇` (`Dual64`) | the same |
//! | 2 | the second derivatives the equations use (`HyperDual64`) | `L` (`∂²L/∂q̇∂(t, q, q̇)`, in `W` and the right-hand side), `h_b` (`∂²h/∂(t, q)²`, in `ḧ`), a load's `r` (`∂²r/∂q∂(t, q)`) and `ω` (`∂²ω/∂q̇∂(t, q, q̇)`), whose first derivatives are in `Q`, `D` (`∂²D/∂q̇∂(t, q, q̇)`, in the implicit methods' Jacobian) |
//!
//! Each level is first evaluated with every derivative seeded at once (their sum is not finite if
//! one of them is not), then, only for the expression found, one variable (or pair) at a time to
//! name the derivative where it can be told (see [`culprit`]).

use std::ops::Range;

use chetaev::prelude::Real;
use num_dual::{Dual64, HyperDual64};

use crate::expr::{Env, Expr};
use crate::Scene;

/// An expression of the model that is not finite at a state.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct NonFinitePart {
    /// What is not finite, as a clause: "constraint 1 (x_dot^2 - 1/x) is inf", "the derivative
    /// ∂L/∂y of the Lagrangian L (...) is -inf".
    pub what: String,
    /// Where the expression is written.
    pub span: Range<usize>,
}

/// One expression of the model, with the derivatives of it that the equations use. Variables are
/// numbered `0` for `t`, `1..=N` for the coordinates, `N+1..=2N` for the velocities.
struct Part<'a> {
    /// "the Lagrangian L (...)": the expression named as the scene writes it.
    name: String,
    /// "L", "f_1", "h_1", "Q_x", "D": the symbol in derivatives.
    symbol: String,
    expr: &'a Expr,
    span: Range<usize>,
    /// The first variables of the second derivatives used (`∂²/∂a∂b`, `a` in this set), if any.
    second_by: Option<Range<usize>>,
    /// The second variables of the second derivatives used.
    second_of: Range<usize>,
}

impl Scene {
    /// The first expression of the model (the Lagrangian, a constraint, a holonomic constraint,
    /// a force, the dissipation function) whose value, first derivatives or used second
    /// derivatives are not finite at `(t, q, q̇)`; `None` if all are finite there.
    pub(crate) fn non_finite_part(&self, t: f64, q: &[f64], qd: &[f64]) -> Option<NonFinitePart> {
        let n = self.n();
        if q.len() != n || qd.len() != n {
            return None;
        }
        let x: Vec<f64> = std::iter::once(t)
            .chain(q.iter().copied())
            .chain(qd.iter().copied())
            .collect();
        let all = 0..2 * n + 1;
        let velocities = n + 1..2 * n + 1;
        let s = &self.spans;
        let mut parts = vec![Part {
            name: format!("the Lagrangian L ({})", self.lagrangian.source()),
            symbol: "L".into(),
            expr: &self.lagrangian,
            span: s.lagrangian.clone(),
            second_by: Some(velocities.clone()),
            second_of: all.clone(),
        }];
        let v = self.constraints.len();
        for (a, f) in self.constraints.iter().enumerate() {
            parts.push(Part {
                name: self.constraint_name(a + 1),
                symbol: format!("f_{}", a + 1),
                expr: f,
                span: s
                    .constraints
                    .get(a)
                    .cloned()
                    .unwrap_or(s.lagrangian.clone()),
                second_by: None,
                second_of: all.clone(),
            });
        }
        for (b, h) in self.holonomic.iter().enumerate() {
            parts.push(Part {
                name: self.constraint_name(v + b + 1),
                symbol: format!("h_{}", b + 1),
                expr: h,
                span: s.holonomic.get(b).cloned().unwrap_or(s.lagrangian.clone()),
                second_by: Some(0..n + 1),
                second_of: 0..n + 1,
            });
        }
        for (i, f) in self.forces.iter().enumerate() {
            let c = &self.coordinates[i];
            parts.push(Part {
                name: format!("the force Q_{c} ({})", f.source()),
                symbol: format!("Q_{c}"),
                expr: f,
                span: s.forces.get(i).cloned().unwrap_or(s.lagrangian.clone()),
                second_by: None,
                second_of: all.clone(),
            });
        }
        for (l, load) in self.loads.iter().enumerate() {
            let (place, acting) = load.parts();
            let (place_spans, acting_spans) = s.loads.get(l).cloned().unwrap_or_default();
            let torque = matches!(load, crate::scene::LoadSpec::Torque { .. });
            let (place_name, place_symbol, acting_name, acting_symbol) = if torque {
                ("angular velocity", "ω", "torque", "T")
            } else {
                ("point", "r", "force", "F")
            };
            // `Q` reads `∂r/∂q` or `∂ω/∂q̇`, whose first derivatives the equations use.
            let second_by = if torque { velocities.clone() } else { 1..n + 1 };
            let second_of = if torque { all.clone() } else { 0..n + 1 };
            for (c, e) in place.iter().enumerate() {
                parts.push(Part {
                    name: format!(
                        "component {} of the {place_name} of load {} ({})",
                        c + 1,
                        l + 1,
                        e.source()
                    ),
                    symbol: format!("{place_symbol}_{}", c + 1),
                    expr: e,
                    span: place_spans.get(c).cloned().unwrap_or(s.lagrangian.clone()),
                    second_by: Some(second_by.clone()),
                    second_of: second_of.clone(),
                });
            }
            for (c, e) in acting.iter().enumerate() {
                parts.push(Part {
                    name: format!(
                        "component {} of the {acting_name} of load {} ({})",
                        c + 1,
                        l + 1,
                        e.source()
                    ),
                    symbol: format!("{acting_symbol}_{}", c + 1),
                    expr: e,
                    span: acting_spans.get(c).cloned().unwrap_or(s.lagrangian.clone()),
                    second_by: None,
                    second_of: all.clone(),
                });
            }
        }
        if let Some(d) = &self.dissipation {
            parts.push(Part {
                name: format!("the dissipation function D ({})", d.source()),
                symbol: "D".into(),
                expr: d,
                span: s.dissipation.clone().unwrap_or(s.lagrangian.clone()),
                second_by: Some(velocities),
                second_of: all.clone(),
            });
        }

        let found = |part: &Part<'_>, what: String| {
            Some(NonFinitePart {
                what,
                span: part.span.clone(),
            })
        };
        // Level 0: the values.
        for part in &parts {
            let value = eval(part.expr, &x, n, |i| x[i]);
            if !value.is_finite() {
                return found(part, format!("{} is {value}", part.name));
            }
        }
        // Level 1: the first derivatives, all seeded at once, then one at a time to name one.
        let first = |e: &Expr, seeded: &dyn Fn(usize) -> bool| {
            eval(e, &x, n, |i| {
                Dual64::new(x[i], if seeded(i) { 1.0 } else { 0.0 })
            })
            .eps
        };
        for part in &parts {
            if first(part.expr, &|_| true).is_finite() {
                continue;
            }
            let what = match culprit(all.clone(), |i| first(part.expr, &|j| j == i)) {
                Some((i, d)) => format!(
                    "the derivative ∂{}/∂{} of {} is {d}",
                    part.symbol,
                    self.variable(i),
                    part.name
                ),
                None => format!("the first derivatives of {} are not finite", part.name),
            };
            return found(part, what);
        }
        // Level 2: the second derivatives the equations use.
        let second = |e: &Expr, a: &dyn Fn(usize) -> bool, b: &dyn Fn(usize) -> bool| {
            eval(e, &x, n, |i| {
                let seed = |s: bool| if s { 1.0 } else { 0.0 };
                HyperDual64::new(x[i], seed(a(i)), seed(b(i)), 0.0)
            })
            .eps1eps2
        };
        for part in &parts {
            let Some(by) = &part.second_by else {
                continue;
            };
            let of = &part.second_of;
            let (in_by, in_of) = (|i: usize| by.contains(&i), |i: usize| of.contains(&i));
            if second(part.expr, &in_by, &in_of).is_finite() {
                continue;
            }
            // The row, then the column: 2(2N + 1) evaluations, not (2N + 1)².
            let pair = culprit(by.clone(), |i| second(part.expr, &|k| k == i, &in_of)).and_then(
                |(i, _)| {
                    culprit(of.clone(), |j| second(part.expr, &|k| k == i, &|k| k == j))
                        .map(|(j, d)| (i, j, d))
                },
            );
            let what = match pair {
                Some((i, j, d)) => format!(
                    "the second derivative ∂²{}/∂{}∂{} of {} is {d}",
                    part.symbol,
                    self.variable(i),
                    self.variable(j),
                    part.name
                ),
                None => format!("the second derivatives of {} are not finite", part.name),
            };
            return found(part, what);
        }
        None
    }

    /// Variable `i` by its name in the file: `t`, a coordinate, or a velocity (`x_dot`).
    fn variable(&self, i: usize) -> String {
        let n = self.n();
        match i {
            0 => "t".into(),
            i if i <= n => self.coordinates[i - 1].clone(),
            i => format!("{}_dot", self.coordinates[i - n - 1]),
        }
    }
}

/// The seed that a non-finite derivative is by: the first whose derivative `d(seed)` is infinite,
/// else the only one whose derivative is NaN; `None` if several are NaN and none is infinite. An
/// inner derivative that is not finite (`sqrt` at 0 has the derivative `0 · ∞ = NaN` in dual
/// numbers) makes the derivatives by every variable NaN, also by those that do not reach it, so
/// a NaN names a variable only when it is the only one.
fn culprit<S: Copy>(seeds: impl Iterator<Item = S>, d: impl Fn(S) -> f64) -> Option<(S, f64)> {
    let mut nan = Vec::new();
    for seed in seeds {
        let v = d(seed);
        if v.is_infinite() {
            return Some((seed, v));
        }
        if v.is_nan() {
            nan.push((seed, v));
        }
    }
    match nan.as_slice() {
        [one] => Some(*one),
        _ => None,
    }
}

/// `e` at the variables `var(0)` (= `t`), `var(1..=n)` (= `q`), `var(n+1..=2n)` (= `q̇`), with
/// `x` holding their values.
fn eval<R: Real>(e: &Expr, x: &[f64], n: usize, var: impl Fn(usize) -> R) -> R {
    let v: Vec<R> = (0..x.len()).map(var).collect();
    e.eval(&Env {
        t: v[0],
        q: &v[1..=n],
        qd: &v[n + 1..],
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene(model: &str) -> Scene {
        let text = format!(
            "[model]\ncoordinates = [\"x\", \"y\"]\n{model}\n[initial]\nq = [0.7, 1.0]\n\
             q_dot = [1.0, 0.0]\n[solve]\nt_end = 1.0\n"
        );
        Scene::parse(&text, "domain.toml").unwrap_or_else(|e| panic!("{e}"))
    }

    #[test]
    fn a_finite_model_has_no_part_to_blame() {
        let s = scene(
            "lagrangian = \"0.5*(x_dot^2 + y_dot^2) - 9.81*y\"\nholonomic = [\"x^2 + y^2 - 1.49\"]",
        );
        assert_eq!(s.non_finite_part(0.0, &[0.7, 1.0], &[1.0, 0.0]), None);
    }

    #[test]
    fn the_part_is_the_first_not_finite_by_value_then_first_then_second_derivatives() {
        // The constraint's value is not finite before the Lagrangian's derivative is looked at.
        let s = scene(
            "lagrangian = \"0.5*(x_dot^2 + y_dot^2) + acos(y)\"\nconstraints = [\"x_dot - 1/(y - 1)\"]",
        );
        let part = s
            .non_finite_part(0.0, &[0.7, 1.0], &[1.0, 0.0])
            .expect("found");
        assert_eq!(part.what, "constraint 1 (x_dot - 1/(y - 1)) is -inf");
        let text = &s.file.text[part.span.clone()];
        assert_eq!(text, "\"x_dot - 1/(y - 1)\"");
        // A holonomic constraint by its number among the holonomic ones, derivative named.
        let s =
            scene("lagrangian = \"0.5*(x_dot^2 + y_dot^2)\"\nholonomic = [\"x - 0.7 + acos(y)\"]");
        let part = s
            .non_finite_part(0.0, &[0.7, 1.0], &[1.0, 0.0])
            .expect("found");
        assert_eq!(
            part.what,
            "the derivative ∂h_1/∂y of holonomic constraint 1 (x - 0.7 + acos(y)) is -inf"
        );
        // Finite value and first derivatives (∂L/∂x = k e^(kx) ≈ 1.0e308), but the mixed second
        // derivative in the equations, 2 k e^(kx), overflows.
        let s = scene("lagrangian = \"x_dot^2*exp(1000*x) + y_dot^2\"");
        let part = s
            .non_finite_part(0.0, &[0.7023, 1.0], &[1.0, 0.0])
            .expect("found");
        assert_eq!(
            part.what,
            "the second derivative ∂²L/∂x_dot∂x of the Lagrangian L (x_dot^2*exp(1000*x) + y_dot^2) is inf"
        );
    }

    #[test]
    fn a_load_is_blamed_by_the_component_whose_derivative_is_not_finite() {
        // r_2 = sqrt(x − 0.7) is 0 at x = 0.7, but its first derivatives, read by the load's Q,
        // are not finite (with no single variable to name; see `culprit`).
        let s = scene(
            "lagrangian = \"0.5*(x_dot^2 + y_dot^2)\"\n[[loads]]\npoint = [\"y\", \"sqrt(x - 0.7)\"]\n\
             force = [\"0\", \"1\"]",
        );
        let part = s
            .non_finite_part(0.0, &[0.7, 1.0], &[1.0, 0.0])
            .expect("found");
        assert_eq!(
            part.what,
            "the first derivatives of component 2 of the point of load 1 (sqrt(x - 0.7)) are not finite"
        );
        assert_eq!(&s.file.text[part.span.clone()], "\"sqrt(x - 0.7)\"");
    }
}
