//! Expressions of the graph as plain text or LaTeX, for showing what the library derived.

use super::{Fun, Graph, Node};

/// Longest expression printed in full; longer ones are cut with `…`.
const MAX_CHARS: usize = 600;
/// Most nodes visited when printing one expression (shared subexpressions are printed again at
/// each use, so a deep graph could otherwise take exponential time).
const MAX_NODES: usize = 400;

#[derive(Clone, Copy, PartialEq)]
enum Style {
    Text,
    Latex,
}

impl Graph {
    /// Node `id` as plain text, with input `i` printed as `names[i]`.
    pub fn to_text(&self, id: u32, names: &[String]) -> String {
        cut(self
            .print(id, names, Style::Text, &std::cell::Cell::new(MAX_NODES))
            .0)
    }

    /// Node `id` as LaTeX, with input `i` printed as `names[i]` (given in LaTeX).
    pub fn to_latex(&self, id: u32, names: &[String]) -> String {
        cut(self
            .print(id, names, Style::Latex, &std::cell::Cell::new(MAX_NODES))
            .0)
    }

    /// The printed node and its precedence (0 sum, 1 product, 2 unary minus, 3 power, 4 atom).
    fn print(
        &self,
        id: u32,
        names: &[String],
        style: Style,
        budget: &std::cell::Cell<usize>,
    ) -> (String, u8) {
        if budget.get() == 0 {
            return ("…".to_string(), 4);
        }
        budget.set(budget.get() - 1);
        let p = |o: u32| self.print(o, names, style, budget);
        let wrap = |(s, prec): (String, u8), min: u8| {
            if prec < min {
                if style == Style::Latex {
                    format!("\\left({s}\\right)")
                } else {
                    format!("({s})")
                }
            } else {
                s
            }
        };
        match self.nodes[id as usize] {
            Node::Const(c) => {
                let s = format!("{c}");
                if c < 0.0 {
                    (s, 2)
                } else {
                    (s, 4)
                }
            }
            Node::Input(i) => (names[i as usize].clone(), 4),
            Node::Add(a, b) => (format!("{} + {}", wrap(p(a), 0), wrap(p(b), 1)), 0),
            Node::Sub(a, b) => (format!("{} - {}", wrap(p(a), 0), wrap(p(b), 1)), 0),
            Node::Mul(a, b) => {
                let op = if style == Style::Latex { " \\, " } else { "·" };
                (format!("{}{op}{}", wrap(p(a), 1), wrap(p(b), 2)), 1)
            }
            Node::Div(a, b) => match style {
                Style::Latex => (format!("\\frac{{{}}}{{{}}}", p(a).0, p(b).0), 4),
                Style::Text => (format!("{}/{}", wrap(p(a), 1), wrap(p(b), 2)), 1),
            },
            Node::Neg(a) => (format!("-{}", wrap(p(a), 2)), 2),
            Node::Powi(a, n) => power(wrap(p(a), 4), &n.to_string(), style),
            Node::Powf(a, e) => power(wrap(p(a), 4), &e.to_string(), style),
            Node::Atan2(a, b) => match style {
                Style::Latex => (
                    format!(
                        "\\operatorname{{atan2}}\\left({}, {}\\right)",
                        p(a).0,
                        p(b).0
                    ),
                    4,
                ),
                Style::Text => (format!("atan2({}, {})", p(a).0, p(b).0), 4),
            },
            Node::Fun(f, a) => {
                let inner = p(a).0;
                match (style, f) {
                    (Style::Latex, Fun::Sqrt) => (format!("\\sqrt{{{inner}}}"), 4),
                    (Style::Latex, Fun::Abs) => (format!("\\left|{inner}\\right|"), 4),
                    (Style::Latex, Fun::Recip) => (format!("\\frac{{1}}{{{inner}}}"), 4),
                    (Style::Latex, Fun::Exp) => (format!("e^{{{inner}}}"), 4),
                    (Style::Latex, _) => (
                        format!("\\operatorname{{{}}}\\left({inner}\\right)", f.name()),
                        4,
                    ),
                    (Style::Text, Fun::Recip) => (format!("1/{}", wrap(p(a), 2)), 1),
                    (Style::Text, _) => (format!("{}({inner})", f.name()), 4),
                }
            }
        }
    }
}

fn power(base: String, exponent: &str, style: Style) -> (String, u8) {
    match style {
        Style::Latex => (format!("{{{base}}}^{{{exponent}}}"), 3),
        Style::Text => (format!("{base}^{exponent}"), 3),
    }
}

fn cut(s: String) -> String {
    if s.chars().count() <= MAX_CHARS {
        s
    } else {
        let mut t: String = s.chars().take(MAX_CHARS).collect();
        t.push('…');
        t
    }
}
