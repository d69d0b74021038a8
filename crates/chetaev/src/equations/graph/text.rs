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
            // A second term that prints with a leading minus and binds at least as a product
            // (`-b`, `-2`, `-b·c`) is subtracted: `a + -b·c` prints as `a - b·c`, `a - -b` as
            // `a + b`.
            Node::Add(a, b) | Node::Sub(a, b) => {
                let plus = matches!(self.nodes[id as usize], Node::Add(..));
                let left = wrap(p(a), 0);
                let (right, prec) = p(b);
                match right.strip_prefix('-') {
                    Some(rest) if prec >= 1 => {
                        (format!("{left} {} {rest}", if plus { '-' } else { '+' }), 0)
                    }
                    _ => (
                        format!(
                            "{left} {} {}",
                            if plus { '+' } else { '-' },
                            wrap((right, prec), 1)
                        ),
                        0,
                    ),
                }
            }
            // A constant factor prints first (`2·x`, not `x·2`). The sign of a negative factor on
            // the right goes to the front, `a·(-b)` printing as `-a·b`; where the left factor is
            // negative too, it stays in parentheses.
            Node::Mul(a, b) => {
                let is_const = |i: u32| matches!(self.nodes[i as usize], Node::Const(_));
                let (a, b) = if is_const(b) && !is_const(a) {
                    (b, a)
                } else {
                    (a, b)
                };
                let op = if style == Style::Latex { " \\, " } else { "·" };
                let left = wrap(p(a), 1);
                let (right, prec) = p(b);
                match right.strip_prefix('-') {
                    Some(rest) if prec == 2 && !left.starts_with('-') => {
                        (format!("-{left}{op}{rest}"), 1)
                    }
                    _ => (format!("{left}{op}{}", wrap((right, prec), 3)), 1),
                }
            }
            Node::Div(a, b) => match style {
                Style::Latex => (format!("\\frac{{{}}}{{{}}}", p(a).0, p(b).0), 4),
                Style::Text => (format!("{}/{}", wrap(p(a), 1), wrap(p(b), 2)), 1),
            },
            Node::Neg(a) => (format!("-{}", wrap(p(a), 3)), 2),
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
                let inner = p(a);
                match (style, f) {
                    (Style::Latex, Fun::Sqrt) => (format!("\\sqrt{{{}}}", inner.0), 4),
                    (Style::Latex, Fun::Cbrt) => (format!("\\sqrt[3]{{{}}}", inner.0), 4),
                    (Style::Latex, Fun::Abs) => (format!("\\left|{}\\right|", inner.0), 4),
                    (Style::Latex, Fun::Recip) => (format!("\\frac{{1}}{{{}}}", inner.0), 4),
                    (Style::Latex, Fun::Exp) => (format!("e^{{{}}}", inner.0), 4),
                    (Style::Latex, _) => {
                        (format!("{}\\left({}\\right)", latex_name(f), inner.0), 4)
                    }
                    (Style::Text, Fun::Recip) => (format!("1/{}", wrap(inner, 2)), 1),
                    (Style::Text, _) => (format!("{}({})", f.name(), inner.0), 4),
                }
            }
        }
    }
}

/// The LaTeX of a function applied with parentheses: the command LaTeX has for it (`\\sin`,
/// `\\arctan`, `\\log_{10}`), otherwise its name as an operator (`\\operatorname{expm1}`).
fn latex_name(f: Fun) -> String {
    let command = match f {
        Fun::Sin => "\\sin",
        Fun::Cos => "\\cos",
        Fun::Tan => "\\tan",
        Fun::Asin => "\\arcsin",
        Fun::Acos => "\\arccos",
        Fun::Atan => "\\arctan",
        Fun::Sinh => "\\sinh",
        Fun::Cosh => "\\cosh",
        Fun::Tanh => "\\tanh",
        Fun::Ln => "\\ln",
        Fun::Log2 => "\\log_{2}",
        Fun::Log10 => "\\log_{10}",
        Fun::Signum => "\\operatorname{sgn}",
        _ => return format!("\\operatorname{{{}}}", f.name()),
    };
    command.to_string()
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

#[cfg(test)]
mod tests {
    use super::super::{record, Fun, Sym, DEP_Q};
    use num_dual::DualNum;

    /// `f(x)` recorded, printed as LaTeX with `x` named `x`.
    fn latex(f: impl Fn(Sym) -> Sym) -> String {
        let (g, out) = record(|| f(Sym::input(DEP_Q, 0.5)));
        g.to_latex(out.node(), &["x".to_string()])
    }

    #[test]
    fn functions_print_with_the_commands_latex_has_for_them() {
        assert_eq!(latex(|x| x.sin()), "\\sin\\left(x\\right)");
        assert_eq!(latex(|x| x.atan()), "\\arctan\\left(x\\right)");
        assert_eq!(
            latex(|x| x.acosh()),
            "\\operatorname{acosh}\\left(x\\right)"
        );
        assert_eq!(latex(|x| x.log10()), "\\log_{10}\\left(x\\right)");
        assert_eq!(latex(|x| x.cbrt()), "\\sqrt[3]{x}");
        assert_eq!(latex(|x| x.ln()), "\\ln\\left(x\\right)");
        // Every function prints as a command or an operator name, never as bare letters that
        // LaTeX would set as a product of variables.
        for f in [
            Fun::Exp2,
            Fun::ExpM1,
            Fun::Ln1p,
            Fun::Asinh,
            Fun::Atanh,
            Fun::Signum,
        ] {
            assert!(super::latex_name(f).starts_with("\\"), "{}", f.name());
        }
    }

    #[test]
    fn signs_print_as_a_reader_writes_them() {
        let text = |f: fn(Sym) -> Sym| {
            let (g, out) = record(|| f(Sym::input(DEP_Q, 0.5)));
            g.to_text(out.node(), &["x".to_string()])
        };
        assert_eq!(text(|x| x.sin() + -x.cos()), "sin(x) - cos(x)");
        assert_eq!(text(|x| x.sin() + -x.cos() * x), "sin(x) - x·cos(x)");
        assert_eq!(text(|x| x.sin() - -x.cos() * x), "sin(x) + x·cos(x)");
        assert_eq!(text(|x| x.sin() + x * -2.0), "sin(x) - 2·x");
        assert_eq!(text(|x| x.sin() * -x.cos()), "-sin(x)·cos(x)");
        assert_eq!(text(|x| -x.sin() * -x.cos()), "-sin(x)·(-cos(x))");
        assert_eq!(text(|x| -(x.sin() * x.cos())), "-(sin(x)·cos(x))");
        assert_eq!(text(|x| x.sin() - (x.cos() + x)), "sin(x) - (x + cos(x))");
    }

    #[test]
    fn a_reciprocal_prints_as_one_over_its_operand() {
        let (g, out) = record(|| Sym::input(DEP_Q, 0.5).recip());
        assert_eq!(g.to_text(out.node(), &["x".to_string()]), "1/x");
    }
}
