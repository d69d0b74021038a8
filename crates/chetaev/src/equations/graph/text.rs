//! Expressions of the graph as plain text or LaTeX, for showing what the library derived.
//!
//! An expression is first brought to a light normal form, then printed:
//!
//! - a sum is a list of terms `c · Π aᵢ^pᵢ`, and terms with the same factors are collected
//!   (`ẋ + ẋ` is `2·ẋ`, `x − x` vanishes);
//! - a product multiplies its numbers into one coefficient and its equal factors into powers
//!   (`x·x` is `x^2`, `m·g/m` is `g`); a number multiplies into a sum (`2·(x + y)` is
//!   `2·x + 2·y`), but sums are not multiplied out with each other;
//! - a sum that is a factor (in a product, a quotient or a power) has its common number and
//!   factors taken out (`4·ẋ²/m + 4·ẏ²/m` as a denominator is `4·(ẋ² + ẏ²)/m`);
//! - numbers fold, and `×1`, `+0` and `^1` disappear.
//!
//! Numbers print the shortest way that reads back to the same `f64` (`10`, `0.5`, `1.5e-12`; in
//! LaTeX `1.5 \cdot 10^{-12}`). Terms print in the order they were first met, the factors of a
//! term in a fixed order: parameters, `t`, coordinates, velocities (each in input order), then
//! functions and sums.

use std::collections::HashMap;

use super::{Deps, Fun, Graph, Node, DEP_P, DEP_Q, DEP_QD, DEP_T};

/// Longest expression printed in full; longer ones are cut with `…`.
const MAX_CHARS: usize = 600;
/// Most terms (counted through every nested sum) an expression is normalised to; a larger
/// subexpression prints as `…`.
const MAX_TERMS: usize = 400;
/// Largest integer exponent applied to a sum's normal form (`x^n` with larger `|n|` stays a power
/// of its own).
const MAX_POWER: f64 = 64.0;

/// How an expression is printed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Style {
    /// Plain text: `2·x^2 - sin(y)/m`.
    Text,
    /// LaTeX: `2 x^{2} - \frac{\sin\left(y\right)}{m}`.
    Latex,
}

/// One term `coeff · Π factor^power`: factors in the order of [`order`], no power zero.
#[derive(Clone, Debug, PartialEq)]
struct Term {
    coeff: f64,
    factors: Vec<(Atom, i32)>,
    /// The factors as a canonical string: terms with equal keys are collected.
    key: String,
}

/// A sum of terms, none with the coefficient zero; the number term has no factors.
#[derive(Clone, Debug, Default, PartialEq)]
struct Sum {
    terms: Vec<Term>,
}

/// What is not a sum or a product.
#[derive(Clone, Debug, PartialEq)]
enum Atom {
    /// Input number `i`.
    Input(u32),
    /// A sum of two or more terms as a factor, its common number and factors taken out.
    Group(Sum),
    Fun(Fun, Sum),
    Powf(Sum, f64),
    Atan2(Sum, Sum),
    /// A subexpression too large to print.
    Cut,
}

impl Atom {
    fn key(&self) -> String {
        match self {
            Atom::Input(i) => format!("i{i}"),
            Atom::Group(s) => format!("({})", s.key()),
            Atom::Fun(f, s) => format!("{}({})", f.name(), s.key()),
            Atom::Powf(s, p) => format!("({})^{:x}", s.key(), p.to_bits()),
            Atom::Atan2(a, b) => format!("atan2({},{})", a.key(), b.key()),
            Atom::Cut => "…".to_string(),
        }
    }

    fn size(&self) -> usize {
        match self {
            Atom::Input(_) | Atom::Cut => 1,
            Atom::Group(s) | Atom::Fun(_, s) | Atom::Powf(s, _) => s.size(),
            Atom::Atan2(a, b) => a.size() + b.size(),
        }
    }

    #[cfg(test)]
    fn eval(&self, x: &[f64]) -> f64 {
        match self {
            Atom::Input(i) => x[*i as usize],
            Atom::Group(s) => s.eval(x),
            Atom::Fun(f, s) => f.apply(s.eval(x)),
            Atom::Powf(s, p) => super::powf(s.eval(x), *p),
            Atom::Atan2(a, b) => a.eval(x).atan2(b.eval(x)),
            Atom::Cut => f64::NAN,
        }
    }
}

fn factors_key(factors: &[(Atom, i32)]) -> String {
    let keys: Vec<String> = factors
        .iter()
        .map(|(a, p)| format!("{}^{p}", a.key()))
        .collect();
    keys.join("·")
}

impl Term {
    fn new(coeff: f64, factors: Vec<(Atom, i32)>) -> Self {
        let key = factors_key(&factors);
        Self {
            coeff,
            factors,
            key,
        }
    }

    /// The product of two terms; `classes` orders the factors.
    fn mul(&self, other: &Term, classes: &[Deps]) -> Term {
        let mut factors = self.factors.clone();
        for (atom, p) in &other.factors {
            let k = atom.key();
            match factors.iter().position(|(a, _)| a.key() == k) {
                Some(at) => {
                    factors[at].1 += p;
                    if factors[at].1 == 0 {
                        factors.remove(at);
                    }
                }
                None => factors.push((atom.clone(), *p)),
            }
        }
        factors.sort_by_cached_key(|(a, _)| order(a, classes));
        Term::new(self.coeff * other.coeff, factors)
    }

    #[cfg(test)]
    fn eval(&self, x: &[f64]) -> f64 {
        self.factors
            .iter()
            .fold(self.coeff, |v, (a, p)| v * a.eval(x).powi(*p))
    }
}

/// The order of factors in a term: parameters, `t`, coordinates, velocities (each by input
/// number), then the rest by their keys.
fn order(atom: &Atom, classes: &[Deps]) -> (u8, u32, String) {
    match atom {
        Atom::Input(i) => {
            let rank = match classes.get(*i as usize).copied().unwrap_or(0) {
                DEP_P => 0,
                DEP_T => 1,
                DEP_Q => 2,
                DEP_QD => 3,
                _ => 4,
            };
            (rank, *i, String::new())
        }
        other => (5, 0, other.key()),
    }
}

impl Sum {
    fn number(c: f64) -> Sum {
        let mut s = Sum::default();
        s.merge(Term::new(c, Vec::new()));
        s
    }

    fn atom(a: Atom) -> Sum {
        Sum {
            terms: vec![Term::new(1.0, vec![(a, 1)])],
        }
    }

    /// Its value if it is a number.
    fn as_number(&self) -> Option<f64> {
        match self.terms.as_slice() {
            [] => Some(0.0),
            [t] if t.factors.is_empty() => Some(t.coeff),
            _ => None,
        }
    }

    fn key(&self) -> String {
        let mut keys: Vec<String> = self
            .terms
            .iter()
            .map(|t| format!("{:x}*{}", t.coeff.to_bits(), t.key))
            .collect();
        keys.sort_unstable();
        keys.join("+")
    }

    fn size(&self) -> usize {
        self.terms
            .iter()
            .map(|t| 1 + t.factors.iter().map(|(a, _)| a.size()).sum::<usize>())
            .sum()
    }

    #[cfg(test)]
    fn eval(&self, x: &[f64]) -> f64 {
        self.terms.iter().map(|t| t.eval(x)).sum()
    }

    /// Adds one term, collecting it with an equal one; a number times a sum adds the sum's terms.
    fn merge(&mut self, t: Term) {
        if t.coeff == 0.0 {
            return;
        }
        if let [(Atom::Group(s), 1)] = t.factors.as_slice() {
            for inner in &s.terms {
                self.merge(Term::new(inner.coeff * t.coeff, inner.factors.clone()));
            }
            return;
        }
        match self.terms.iter().position(|u| u.key == t.key) {
            Some(at) => {
                self.terms[at].coeff += t.coeff;
                if self.terms[at].coeff == 0.0 {
                    self.terms.remove(at);
                }
            }
            None => self.terms.push(t),
        }
    }

    fn add(mut self, other: Sum) -> Sum {
        if self.terms.len() + other.terms.len() < 32 {
            for t in other.terms {
                self.merge(t);
            }
            return self;
        }
        // Many terms: collected through an index by key rather than by scanning.
        let mut out = Sum::default();
        let mut index: HashMap<String, usize> = HashMap::new();
        let mut flat = Sum::default();
        for t in self.terms.into_iter().chain(other.terms) {
            flat.terms.clear();
            flat.merge(t);
            for t in flat.terms.drain(..) {
                match index.get(&t.key) {
                    Some(&at) => out.terms[at].coeff += t.coeff,
                    None => {
                        index.insert(t.key.clone(), out.terms.len());
                        out.terms.push(t);
                    }
                }
            }
        }
        out.terms.retain(|t| t.coeff != 0.0);
        out
    }

    fn scale(self, c: f64) -> Sum {
        let mut out = Sum::default();
        for t in self.terms {
            out.merge(Term::new(t.coeff * c, t.factors));
        }
        out
    }

    /// As one term: itself if it has one, else its common number and factors times the rest as
    /// a [`Atom::Group`].
    fn into_term(self, classes: &[Deps]) -> Term {
        match self.terms.len() {
            0 => return Term::new(0.0, Vec::new()),
            1 => {
                return self
                    .terms
                    .into_iter()
                    .next()
                    .unwrap_or_else(|| unreachable!())
            }
            _ => {}
        }
        let coeffs: Vec<f64> = self.terms.iter().map(|t| t.coeff).collect();
        let sign = coeffs[0].signum();
        let integers = coeffs.iter().all(|c| c.fract() == 0.0 && c.abs() < 9.0e15);
        let content = if integers {
            sign * coeffs.iter().fold(0.0, |g, c| gcd(g, c.abs()))
        } else if coeffs.iter().all(|c| c.abs() == coeffs[0].abs()) {
            coeffs[0]
        } else {
            sign
        };
        // Factors in every term with powers of one sign: the smallest power in size.
        let mut common: Vec<(Atom, i32)> = Vec::new();
        for (atom, p) in &self.terms[0].factors {
            let k = atom.key();
            let mut least = *p;
            let everywhere = self.terms[1..].iter().all(|t| {
                t.factors
                    .iter()
                    .find(|(a, _)| a.key() == k)
                    .is_some_and(|(_, q)| {
                        if q.signum() != p.signum() {
                            return false;
                        }
                        if q.abs() < least.abs() {
                            least = *q;
                        }
                        true
                    })
            });
            if everywhere {
                common.push((atom.clone(), least));
            }
        }
        let divisor = Term::new(
            1.0 / content,
            common.iter().map(|(a, p)| (a.clone(), -p)).collect(),
        );
        let mut rest = Sum::default();
        for t in &self.terms {
            let mut u = t.mul(&divisor, classes);
            // The content divides each coefficient exactly where it was found as a divisor.
            u.coeff = t.coeff / content;
            rest.merge(u);
        }
        let mut factors = common;
        factors.push((Atom::Group(rest), 1));
        factors.sort_by_cached_key(|(a, _)| order(a, classes));
        Term::new(content, factors)
    }

    fn mul(self, other: Sum, classes: &[Deps]) -> Sum {
        if let Some(c) = self.as_number() {
            return other.scale(c);
        }
        if let Some(c) = other.as_number() {
            return self.scale(c);
        }
        let t = self
            .into_term(classes)
            .mul(&other.into_term(classes), classes);
        let mut out = Sum::default();
        out.merge(t);
        out
    }

    fn powi(self, n: i32, classes: &[Deps]) -> Sum {
        if n == 0 {
            return Sum::number(1.0);
        }
        if n == 1 {
            return self;
        }
        if let Some(c) = self.as_number() {
            return Sum::number(c.powi(n));
        }
        let t = self.into_term(classes);
        let factors = t.factors.iter().map(|(a, p)| (a.clone(), p * n)).collect();
        let mut out = Sum::default();
        out.merge(Term::new(t.coeff.powi(n), factors));
        out
    }
}

fn gcd(a: f64, b: f64) -> f64 {
    if b == 0.0 {
        a
    } else {
        gcd(b, a % b)
    }
}

/// Expressions of one graph in normal form, kept by node so that an expression shared by several
/// printed entries is normalised once.
pub(crate) struct Printer<'g> {
    graph: &'g Graph,
    names: &'g [String],
    style: Style,
    done: HashMap<u32, Sum>,
}

impl<'g> Printer<'g> {
    /// A printer of `graph`'s nodes with input `i` named `names[i]` (in LaTeX for
    /// [`Style::Latex`]).
    pub(crate) fn new(graph: &'g Graph, names: &'g [String], style: Style) -> Self {
        Self {
            graph,
            names,
            style,
            done: HashMap::new(),
        }
    }

    /// Node `id`, normalised and printed.
    pub(crate) fn print(&mut self, id: u32) -> String {
        let s = self.normalise(id).clone();
        cut(self.sum(&s))
    }

    /// Node `id`, normalised and printed, where it prints in full (no part too large, at most
    /// [`MAX_CHARS`] characters); `None` otherwise.
    pub(crate) fn print_whole(&mut self, id: u32) -> Option<String> {
        let s = self.normalise(id).clone();
        if s.key().contains('…') {
            return None;
        }
        let printed = self.sum(&s);
        (printed.chars().count() <= MAX_CHARS).then_some(printed)
    }

    /// The value of node `id`'s normal form at the inputs `x` (by input number): the printed
    /// expression evaluated, for checking it against the graph.
    #[cfg(test)]
    pub(crate) fn eval(&mut self, id: u32, x: &[f64]) -> f64 {
        self.normalise(id).eval(x)
    }

    fn normalise(&mut self, id: u32) -> &Sum {
        let classes = &self.graph.inputs;
        for at in self.graph.reachable(&[id]) {
            if self.done.contains_key(&at) {
                continue;
            }
            let get = |o: u32| self.done.get(&o).cloned().unwrap_or_default();
            let s = match self.graph.nodes[at as usize] {
                Node::Const(c) => Sum::number(c),
                Node::Input(i) => Sum::atom(Atom::Input(i)),
                Node::Add(a, b) => get(a).add(get(b)),
                Node::Sub(a, b) => get(a).add(get(b).scale(-1.0)),
                Node::Mul(a, b) => get(a).mul(get(b), classes),
                Node::Div(a, b) => get(a).mul(get(b).powi(-1, classes), classes),
                Node::Neg(a) => get(a).scale(-1.0),
                Node::Powi(a, n) => get(a).powi(n, classes),
                Node::Powf(a, p) => {
                    let base = get(a);
                    match base.as_number() {
                        Some(c) => Sum::number(super::powf(c, p)),
                        None if p.fract() == 0.0 && p.abs() <= MAX_POWER => {
                            base.powi(p as i32, classes)
                        }
                        None => Sum::atom(Atom::Powf(base, p)),
                    }
                }
                Node::Atan2(a, b) => Sum::atom(Atom::Atan2(get(a), get(b))),
                Node::Fun(Fun::Recip, a) => get(a).powi(-1, classes),
                Node::Fun(f, a) => {
                    let arg = get(a);
                    match arg.as_number() {
                        Some(c) => Sum::number(f.apply(c)),
                        None => Sum::atom(Atom::Fun(f, arg)),
                    }
                }
            };
            let s = if s.size() > MAX_TERMS {
                Sum::atom(Atom::Cut)
            } else {
                s
            };
            self.done.insert(at, s);
        }
        self.done
            .get(&id)
            .unwrap_or_else(|| unreachable!("a node reaches itself"))
    }

    fn sum(&self, s: &Sum) -> String {
        if s.terms.is_empty() {
            return "0".to_string();
        }
        let mut out = String::new();
        for (i, t) in s.terms.iter().enumerate() {
            let body = self.term(t);
            match (i, t.coeff < 0.0) {
                (0, true) => out.push_str(&format!("-{body}")),
                (0, false) => out.push_str(&body),
                (_, true) => out.push_str(&format!(" - {body}")),
                (_, false) => out.push_str(&format!(" + {body}")),
            }
        }
        out
    }

    /// A term without its sign.
    fn term(&self, t: &Term) -> String {
        let c = t.coeff.abs();
        let mut num: Vec<String> = Vec::new();
        let mut den: Vec<String> = Vec::new();
        // A coefficient 1/m with an integer m goes under the fraction bar as m.
        let inverse = 1.0 / c;
        if c != 1.0 {
            if c < 1.0 && inverse.fract() == 0.0 && inverse < 1e6 && 1.0 / inverse == c {
                den.push(number(inverse, self.style));
            } else {
                num.push(number(c, self.style));
            }
        }
        for (a, p) in &t.factors {
            if *p > 0 {
                num.push(self.factor(a, *p));
            } else {
                den.push(self.factor(a, -p));
            }
        }
        let sep = match self.style {
            Style::Text => "·",
            Style::Latex => " ",
        };
        let numerator = if num.is_empty() {
            "1".to_string()
        } else {
            num.join(sep)
        };
        if den.is_empty() {
            return numerator;
        }
        let denominator = den.join(sep);
        match self.style {
            Style::Latex => format!("\\frac{{{numerator}}}{{{denominator}}}"),
            Style::Text if den.len() > 1 => format!("{numerator}/({denominator})"),
            Style::Text => format!("{numerator}/{denominator}"),
        }
    }

    fn factor(&self, a: &Atom, p: i32) -> String {
        let base = self.atom(a);
        if p == 1 {
            return base;
        }
        match self.style {
            Style::Text => format!("{base}^{p}"),
            Style::Latex if matches!(a, Atom::Input(_) | Atom::Group(_)) => {
                format!("{base}^{{{p}}}")
            }
            Style::Latex => format!("{{{base}}}^{{{p}}}"),
        }
    }

    fn paren(&self, s: &str) -> String {
        match self.style {
            Style::Text => format!("({s})"),
            Style::Latex => format!("\\left({s}\\right)"),
        }
    }

    fn atom(&self, a: &Atom) -> String {
        match a {
            Atom::Input(i) => self
                .names
                .get(*i as usize)
                .cloned()
                .unwrap_or_else(|| format!("x{i}")),
            Atom::Group(s) => self.paren(&self.sum(s)),
            Atom::Cut => "…".to_string(),
            Atom::Powf(s, p) => {
                let base = match s.terms.as_slice() {
                    [t] if t.coeff == 1.0 && t.factors.len() == 1 && t.factors[0].1 == 1 => {
                        self.atom(&t.factors[0].0)
                    }
                    _ => self.paren(&self.sum(s)),
                };
                match self.style {
                    Style::Text => format!("{base}^{}", number(*p, self.style)),
                    Style::Latex => format!("{{{base}}}^{{{}}}", number(*p, self.style)),
                }
            }
            Atom::Atan2(y, x) => match self.style {
                Style::Latex => format!(
                    "\\operatorname{{atan2}}\\left({}, {}\\right)",
                    self.sum(y),
                    self.sum(x)
                ),
                Style::Text => format!("atan2({}, {})", self.sum(y), self.sum(x)),
            },
            Atom::Fun(f, s) => {
                let inner = self.sum(s);
                match (self.style, f) {
                    (Style::Latex, Fun::Sqrt) => format!("\\sqrt{{{inner}}}"),
                    (Style::Latex, Fun::Cbrt) => format!("\\sqrt[3]{{{inner}}}"),
                    (Style::Latex, Fun::Abs) => format!("\\left|{inner}\\right|"),
                    (Style::Latex, Fun::Exp) => format!("e^{{{inner}}}"),
                    (Style::Latex, _) => format!("{}\\left({inner}\\right)", latex_name(*f)),
                    (Style::Text, _) => format!("{}({inner})", f.name()),
                }
            }
        }
    }
}

#[cfg(test)]
impl Graph {
    /// Node `id` as plain text, with input `i` printed as `names[i]`.
    pub fn to_text(&self, id: u32, names: &[String]) -> String {
        Printer::new(self, names, Style::Text).print(id)
    }

    /// Node `id` as LaTeX, with input `i` printed as `names[i]` (given in LaTeX).
    pub fn to_latex(&self, id: u32, names: &[String]) -> String {
        Printer::new(self, names, Style::Latex).print(id)
    }
}

/// `x` the shortest way that reads back to the same `f64`: `10`, `0.5`, `1.5e-12` (in LaTeX
/// `1.5 \cdot 10^{-12}`); positional between `10⁻⁴` and `10¹⁶`, else with an exponent.
pub fn number(x: f64, style: Style) -> String {
    // `x + 0.0` prints a negative zero as 0.
    let x = x + 0.0;
    let a = x.abs();
    if !x.is_finite() || a == 0.0 || (1e-4..1e16).contains(&a) {
        return match (style, x.is_finite()) {
            (Style::Latex, false) if x.is_nan() => "\\mathrm{NaN}".to_string(),
            (Style::Latex, false) if x > 0.0 => "\\infty".to_string(),
            (Style::Latex, false) => "-\\infty".to_string(),
            _ => format!("{x}"),
        };
    }
    let s = format!("{x:e}");
    match style {
        Style::Text => s,
        Style::Latex => match s.split_once('e') {
            Some((mantissa, exponent)) if mantissa == "1" || mantissa == "-1" => {
                let sign = if mantissa == "-1" { "-" } else { "" };
                format!("{sign}10^{{{exponent}}}")
            }
            Some((mantissa, exponent)) => format!("{mantissa} \\cdot 10^{{{exponent}}}"),
            None => s,
        },
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

/// Greek letters LaTeX has commands for, by their names.
const GREEK: [&str; 33] = [
    "alpha", "beta", "gamma", "delta", "epsilon", "zeta", "eta", "theta", "iota", "kappa",
    "lambda", "mu", "nu", "xi", "pi", "rho", "sigma", "tau", "upsilon", "phi", "chi", "psi",
    "omega", "Gamma", "Delta", "Theta", "Lambda", "Xi", "Pi", "Sigma", "Phi", "Psi", "Omega",
];

/// A name as a LaTeX symbol, in the manner of sympy: a Greek letter's name as its letter
/// (`theta` is `\theta`), trailing digits or what follows the first `_` as a subscript (`v0` is
/// `v_{0}`, `x_tip` is `x_{\mathrm{tip}}`), and a longer word upright (`mass` is
/// `\mathrm{mass}`).
pub fn latex_symbol(name: &str) -> String {
    let (stem, sub) = match name.split_once('_') {
        Some((stem, sub)) if !stem.is_empty() && !sub.is_empty() => (stem, Some(sub.to_string())),
        _ => {
            let digits = name.trim_end_matches(|c: char| c.is_ascii_digit());
            if digits.is_empty() || digits.len() == name.len() {
                (name, None)
            } else {
                (digits, Some(name[digits.len()..].to_string()))
            }
        }
    };
    let word = |w: &str| {
        if GREEK.contains(&w) {
            format!("\\{w}")
        } else if w.chars().count() == 1 || w.chars().all(|c| c.is_ascii_digit()) {
            w.to_string()
        } else {
            format!("\\mathrm{{{w}}}")
        }
    };
    match sub {
        Some(sub) => format!("{}_{{{}}}", word(stem), word(&sub)),
        None => word(stem),
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
    use super::super::{record, Fun, Sym, DEP_P, DEP_Q, DEP_QD};
    use super::{latex_symbol, number, Style};
    use num_dual::DualNum;

    /// `f(x)` recorded, printed as LaTeX with `x` named `x`.
    fn latex(f: impl Fn(Sym) -> Sym) -> String {
        let (g, out) = record(|| f(Sym::input(DEP_Q, 0.5)));
        g.to_latex(out.node(), &["x".to_string()])
    }

    /// `f(x)` recorded, printed as text with `x` named `x`.
    fn text(f: impl Fn(Sym) -> Sym) -> String {
        let (g, out) = record(|| f(Sym::input(DEP_Q, 0.5)));
        g.to_text(out.node(), &["x".to_string()])
    }

    /// `f(m, x, ẋ)` recorded with `m` a parameter, printed both ways.
    fn both(f: impl Fn(Sym, Sym, Sym) -> Sym) -> (String, String) {
        let (g, out) = record(|| {
            f(
                Sym::input(DEP_P, 2.0),
                Sym::input(DEP_Q, 0.5),
                Sym::input(DEP_QD, 1.5),
            )
        });
        let text = ["m", "x", "x_dot"].map(String::from);
        let latex = ["m", "x", "\\dot{x}"].map(String::from);
        (g.to_text(out.node(), &text), g.to_latex(out.node(), &latex))
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
        assert_eq!(text(|x| x.sin() + -x.cos()), "sin(x) - cos(x)");
        assert_eq!(text(|x| x.sin() + -x.cos() * x), "sin(x) - x·cos(x)");
        assert_eq!(text(|x| x.sin() - -x.cos() * x), "sin(x) + x·cos(x)");
        assert_eq!(text(|x| x.sin() + x * -2.0), "sin(x) - 2·x");
        assert_eq!(text(|x| x.sin() * -x.cos()), "-cos(x)·sin(x)");
        assert_eq!(text(|x| -x.sin() * -x.cos()), "cos(x)·sin(x)");
        assert_eq!(text(|x| -(x.sin() * x.cos())), "-cos(x)·sin(x)");
        assert_eq!(text(|x| x.sin() - (x.cos() + x)), "sin(x) - x - cos(x)");
    }

    #[test]
    fn a_reciprocal_prints_as_one_over_its_operand() {
        assert_eq!(text(|x| x.recip()), "1/x");
        assert_eq!(latex(|x| x.recip()), "\\frac{1}{x}");
    }

    #[test]
    fn like_terms_are_collected_and_equal_factors_become_powers() {
        assert_eq!(
            both(|_, _, v| v + v),
            ("2·x_dot".into(), "2 \\dot{x}".into())
        );
        assert_eq!(
            both(|m, x, v| v * m * v * 0.5 + x * 3.0 - x),
            (
                "m·x_dot^2/2 + 2·x".into(),
                "\\frac{m \\dot{x}^{2}}{2} + 2 x".into()
            )
        );
        // ×1, +0 and a factor over itself vanish.
        assert_eq!(
            both(|m, x, _| (m * x * 1.0 + 0.0) / m),
            ("x".into(), "x".into())
        );
        assert_eq!(
            both(|m, x, v| m * x * v + x * v * m * 2.0 - v * m * x * 3.0 + v),
            ("x_dot".into(), "\\dot{x}".into())
        );
    }

    #[test]
    fn long_sums_are_collected_too() {
        // Σ (i x + sin(i x)) − Σ sin(i x) over i = 1 … 20: the last sums hold 40 terms.
        let sines = |x: Sym| (1..=20).fold(Sym::from(0.0), |s, i| s + (x * f64::from(i)).sin());
        let all = |x: Sym| (1..=20).fold(sines(x), |s, i| s + x * f64::from(i));
        assert_eq!(text(|x| all(x) - sines(x)), "210·x");
    }

    #[test]
    fn a_sum_under_a_fraction_bar_has_its_common_factors_taken_out() {
        // 2 g ẏ / (4 ẋ²/m + 4 ẏ²/m), the paper's multiplier before ẋ² + ẏ² = v0² is used.
        let (g, out) = record(|| {
            let (m, g) = (Sym::input(DEP_P, 1.0), Sym::input(DEP_P, 10.0));
            let (xd, yd) = (Sym::input(DEP_QD, 10.0), Sym::input(DEP_QD, 0.0));
            let s = xd * 2.0 * (xd * 2.0 / m) + yd * 2.0 * (yd * 2.0 / m);
            yd * 2.0 * g / s
        });
        let text = ["m", "g", "x_dot", "y_dot"].map(String::from);
        let latex = ["m", "g", "\\dot{x}", "\\dot{y}"].map(String::from);
        assert_eq!(
            g.to_text(out.node(), &text),
            "m·g·y_dot/(2·(x_dot^2 + y_dot^2))"
        );
        assert_eq!(
            g.to_latex(out.node(), &latex),
            "\\frac{m g \\dot{y}}{2 \\left(\\dot{x}^{2} + \\dot{y}^{2}\\right)}"
        );
    }

    #[test]
    fn numbers_print_the_shortest_way_that_reads_back() {
        for (x, text, latex) in [
            (10.0, "10", "10"),
            (0.5, "0.5", "0.5"),
            (-2.25, "-2.25", "-2.25"),
            (1.5e-12, "1.5e-12", "1.5 \\cdot 10^{-12}"),
            (1e20, "1e20", "10^{20}"),
            (-0.0, "0", "0"),
            (0.1 + 0.2, "0.30000000000000004", "0.30000000000000004"),
        ] {
            assert_eq!(number(x, Style::Text), text);
            assert_eq!(number(x, Style::Latex), latex);
            if x != 0.0 {
                assert_eq!(text.parse::<f64>(), Ok(x));
            }
        }
        assert_eq!(text(|x| x * 1.5e-12), "1.5e-12·x");
        assert_eq!(text(|x| x * 0.75), "0.75·x");
    }

    #[test]
    fn names_become_latex_symbols_as_sympy_writes_them() {
        assert_eq!(latex_symbol("x"), "x");
        assert_eq!(latex_symbol("theta"), "\\theta");
        assert_eq!(latex_symbol("v0"), "v_{0}");
        assert_eq!(latex_symbol("alpha2"), "\\alpha_{2}");
        assert_eq!(latex_symbol("x_tip"), "x_{\\mathrm{tip}}");
        assert_eq!(latex_symbol("mass"), "\\mathrm{mass}");
        assert_eq!(latex_symbol("Omega"), "\\Omega");
    }

    #[test]
    fn the_normal_form_has_the_value_of_the_expression() {
        let (g, out) = record(|| {
            let x = Sym::input(DEP_Q, 0.7);
            let v = Sym::input(DEP_QD, -1.3);
            let s = x * v + x.sin();
            (s * s / (v * 3.0 + x) - (s + 1.0).powi(3) * 0.25 + x.powf(2.5) - v / s).atan2(s)
        });
        let mut p = super::Printer::new(&g, &[], Style::Text);
        let printed = p.eval(out.node(), &[0.7, -1.3]);
        let value = g.value(out.node());
        assert!(
            (printed - value).abs() <= 1e-14 * value.abs().max(1.0),
            "{printed} against {value}"
        );
    }
}
