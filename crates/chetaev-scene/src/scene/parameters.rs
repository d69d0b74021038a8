//! `[parameters]`: numbers, and expressions of other parameters in any order, resolved in an order
//! where each comes after the parameters it uses.
//!
//! The parameters and the names their expressions use form a directed graph. One depth-first
//! search, iterative so that a chain of any length does not deepen the stack, orders it in time
//! linear in the number of parameters and names, and finds a cycle if there is one; the cycle is
//! reported with its members in order. Each expression is then folded to its value once, against
//! the values already known.
//!
//! Where sensitivities are asked for, the parameters asked for and every parameter computed from
//! them (directly or through others) are *varying*: the expressions read them as parameter nodes.
//! The rate `dp_i/dp_a` of each varying parameter `p_i` with respect to each parameter asked for
//! `p_a` is its expression evaluated once more in the same order with dual numbers, `p_a` seeded
//! with 1: exact, and in time linear in the number of parameters per parameter asked for. A
//! parameter asked for that is itself computed from others is moved with its inputs held.

use std::collections::{BTreeMap, HashMap};

use num_dual::Dual64;
use toml::Spanned;

use super::schema::Number;
use super::validate::Builder;
use crate::error::Error;
use crate::expr::{check_name, closest, parse as expr_parse, Env, Expr, Symbols};
use crate::source::string_offset;

/// The most members of a cycle a message lists.
const CYCLE_LISTED: usize = 8;

/// A parameter as written: its name, its value or expression, and the parameters it uses.
struct Entry<'a> {
    name: &'a Spanned<String>,
    value: Value,
    uses: Vec<usize>,
}

enum Value {
    Number(f64),
    /// The expression as written (with its span in the file), and parsed.
    Expr(Spanned<String>, expr_parse::Ast),
}

/// The parameters resolved: their values, and what sensitivities need of them.
pub(super) struct Parameters {
    /// Names and values, in the order of the file.
    pub(super) values: Vec<(String, f64)>,
    /// The indices of the parameters sensitivities are asked for, in the order asked; empty for
    /// none.
    pub(super) asked: Vec<usize>,
    /// For each parameter, its rate with respect to each parameter asked for, `dp_i/dp_a`, or
    /// `None` where it is not computed from that parameter (it does not move with it).
    pub(super) rates: Vec<Vec<Option<f64>>>,
}

impl Parameters {
    /// The varying parameters (those with a rate), by name, with their index.
    pub(super) fn varying(&self) -> BTreeMap<String, usize> {
        self.values
            .iter()
            .enumerate()
            .filter(|(i, _)| self.rates[*i].iter().any(Option::is_some))
            .map(|(i, (name, _))| (name.clone(), i))
            .collect()
    }

    /// The parameters as dual numbers moving with parameter asked for `a` (index into `asked`).
    pub(super) fn duals(&self, a: usize) -> Vec<Dual64> {
        self.values
            .iter()
            .zip(&self.rates)
            .map(|((_, v), r)| Dual64::new(*v, r.get(a).copied().flatten().unwrap_or(0.0)))
            .collect()
    }
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Mark {
    New,
    Open,
    Done,
}

impl Builder {
    /// The parameters in the order of the file, with their values, and the parameters named in
    /// `asked` (the list of `[sensitivities] parameters`) with the rates of the others.
    pub(super) fn parameters(
        &self,
        raw: &BTreeMap<Spanned<String>, Spanned<Number>>,
        asked: Option<&Spanned<Vec<Spanned<String>>>>,
        coordinates: &[Spanned<String>],
    ) -> Result<Parameters, Error> {
        let mut written: Vec<(&Spanned<String>, &Spanned<Number>)> = raw.iter().collect();
        written.sort_by_key(|(k, _)| k.span().start);
        let index: HashMap<&str, usize> = written
            .iter()
            .enumerate()
            .map(|(i, (k, _))| (k.get_ref().as_str(), i))
            .collect();
        // Every name checked, every expression parsed, every use of another parameter an edge.
        let mut all_names: Option<Symbols> = None;
        let mut entries = Vec::with_capacity(written.len());
        for (name, value) in &written {
            self.name_check(name, "parameter")?;
            let mut uses = Vec::new();
            let value = match value.get_ref() {
                Number::Value(x) => {
                    if !x.is_finite() {
                        return Err(self.err(
                            value.span(),
                            format!(
                                "parameter '{}' is {x}; give a finite number",
                                name.get_ref()
                            ),
                        ));
                    }
                    Value::Number(*x)
                }
                Number::Expr(s) => {
                    let spanned = Spanned::new(value.span(), s.clone());
                    let ast = expr_parse::parse(s).map_err(|e| self.expr_error(&spanned, e))?;
                    let mut used = Vec::new();
                    ast.names(&mut used);
                    for (n, span) in used {
                        match index.get(n.as_str()) {
                            Some(&j) => uses.push(j),
                            None => {
                                // Not a parameter: the constant pi or e, or a mistake, reported with every
                                // parameter name as a candidate for "did you mean".
                                let symbols = all_names.get_or_insert_with(|| Symbols {
                                    parameters: written
                                        .iter()
                                        .map(|(k, _)| (k.get_ref().clone(), 0.0))
                                        .collect(),
                                    // Named, so that a coordinate is called one.
                                    coordinates: coordinates
                                        .iter()
                                        .map(|c| c.get_ref().clone())
                                        .collect(),
                                    varying: BTreeMap::new(),
                                    motion: false,
                                    recorded: Vec::new(),
                                });
                                check_name(&n, span, symbols)
                                    .map_err(|e| self.expr_error(&spanned, e))?;
                            }
                        }
                    }
                    Value::Expr(spanned, ast)
                }
            };
            entries.push(Entry { name, value, uses });
        }

        let order = self.dependency_order(&entries)?;
        let asked = match asked {
            Some(list) => self.asked(list, &entries, coordinates)?,
            None => Vec::new(),
        };
        let mut known = Symbols {
            parameters: BTreeMap::new(),
            coordinates: Vec::new(),
            varying: BTreeMap::new(),
            motion: false,
            recorded: Vec::new(),
        };
        let mut values = vec![0.0; entries.len()];
        for &i in &order {
            let e = &entries[i];
            let value = match &e.value {
                Value::Number(x) => *x,
                Value::Expr(s, ast) => {
                    let expr = Expr::from_ast(s.get_ref(), ast, &known)
                        .map_err(|err| self.expr_error(s, err))?;
                    self.warn_euler(s, &expr);
                    expr.constant().ok_or_else(|| {
                        self.err(s.span(), "a parameter must be a constant expression")
                    })?
                }
            };
            known.parameters.insert(e.name.get_ref().clone(), value);
            values[i] = value;
        }
        let rates = self.rates(&entries, &order, &asked, known.parameters)?;
        Ok(Parameters {
            values: entries
                .iter()
                .zip(values)
                .map(|(e, v)| (e.name.get_ref().clone(), v))
                .collect(),
            asked,
            rates,
        })
    }

    /// The indices of the parameters named in `[sensitivities] parameters`, each checked.
    fn asked(
        &self,
        list: &Spanned<Vec<Spanned<String>>>,
        entries: &[Entry<'_>],
        coordinates: &[Spanned<String>],
    ) -> Result<Vec<usize>, Error> {
        if list.get_ref().is_empty() {
            return Err(self.err(
                list.span(),
                "[sensitivities] parameters lists no parameter: name the parameters to \
                 differentiate with respect to, as in parameters = [\"g\"], or remove the \
                 [sensitivities] table",
            ));
        }
        let names: Vec<String> = entries.iter().map(|e| e.name.get_ref().clone()).collect();
        let mut asked: Vec<usize> = Vec::new();
        for name in list.get_ref() {
            let n = name.get_ref();
            let Some(i) = names.iter().position(|p| p == n) else {
                let coordinate = coordinates.iter().map(Spanned::get_ref).find(|c| {
                    c.as_str() == n.as_str() || n.strip_suffix("_dot") == Some(c.as_str())
                });
                let hint = if let Some(c) = coordinate {
                    let (key, example) = if c == n {
                        ("q", format!("{c}0"))
                    } else {
                        ("q_dot", format!("{c}_dot0"))
                    };
                    format!(
                        "it is the initial value of a coordinate or velocity; to differentiate \
                         with respect to it, make it a parameter ({example} = ... under \
                         [parameters], written as \"{example}\" in initial.{key}) and name that"
                    )
                } else if names.is_empty() {
                    "the scene has no [parameters]; a sensitivity is taken with respect to a \
                     parameter, so define one there (an initial value too: q = [\"x0\"] with \
                     x0 = 1.0 under [parameters])"
                        .to_string()
                } else if let Some(near) = closest(n, &names) {
                    format!("did you mean '{near}'?")
                } else {
                    let listed: Vec<&str> = names.iter().take(20).map(String::as_str).collect();
                    let more = if names.len() > 20 {
                        format!(", and {} more", names.len() - 20)
                    } else {
                        String::new()
                    };
                    format!(
                        "the parameters are {}{more}; to differentiate with respect to an initial \
                         value, make it a parameter (q = [\"x0\", ...] with x0 under \
                         [parameters]) and name that",
                        listed.join(", ")
                    )
                };
                return Err(self.err(
                    self.inside(name),
                    format!("'{n}' is not a parameter of the scene: {hint}"),
                ));
            };
            if asked.contains(&i) {
                return Err(self.err(
                    self.inside(name),
                    format!("the parameter '{n}' is listed twice under [sensitivities]"),
                ));
            }
            asked.push(i);
        }
        Ok(asked)
    }

    /// The place of a string's text in the file, without its quotes.
    pub(super) fn inside(&self, s: &Spanned<String>) -> std::ops::Range<usize> {
        let text = &self.file.text;
        let span = s.span();
        let start = string_offset(text, &span, s.get_ref(), 0);
        let end = string_offset(text, &span, s.get_ref(), s.get_ref().len());
        start..end.max(start + 1)
    }

    /// For each parameter and each parameter asked for, `dp_i/dp_a` where `p_i` is computed from
    /// `p_a` (or is `p_a`), by dual numbers in dependency `order`.
    fn rates(
        &self,
        entries: &[Entry<'_>],
        order: &[usize],
        asked: &[usize],
        values: BTreeMap<String, f64>,
    ) -> Result<Vec<Vec<Option<f64>>>, Error> {
        let mut rates = vec![vec![None; asked.len()]; entries.len()];
        if asked.is_empty() {
            return Ok(rates);
        }
        // Which parameters move with which parameter asked for, following the definitions.
        for &i in order {
            for (a, &p) in asked.iter().enumerate() {
                if i == p || entries[i].uses.iter().any(|&u| rates[u][a].is_some()) {
                    rates[i][a] = Some(0.0);
                }
            }
        }
        let symbols = Symbols {
            varying: entries
                .iter()
                .enumerate()
                .filter(|(i, _)| rates[*i].iter().any(Option::is_some))
                .map(|(i, e)| (e.name.get_ref().clone(), i))
                .collect(),
            parameters: values,
            coordinates: Vec::new(),
            motion: false,
            recorded: Vec::new(),
        };
        let mut varying = vec![None; entries.len()];
        for (i, e) in entries.iter().enumerate() {
            if let (Value::Expr(s, ast), true) =
                (&e.value, symbols.varying.contains_key(e.name.get_ref()))
            {
                let expr = Expr::from_ast(s.get_ref(), ast, &symbols)
                    .map_err(|err| self.expr_error(s, err))?;
                varying[i] = Some(expr);
            }
        }
        let env = Env {
            t: Dual64::from(0.0),
            q: &[],
            qd: &[],
        };
        for (a, &p) in asked.iter().enumerate() {
            let mut duals: Vec<Dual64> = entries
                .iter()
                .map(|e| Dual64::from(symbols.parameters[e.name.get_ref()]))
                .collect();
            for &i in order {
                if rates[i][a].is_none() {
                    continue;
                }
                let re = duals[i].re;
                let eps = match &varying[i] {
                    // Computed from the parameter asked for.
                    Some(expr) if i != p => expr.eval_with_parameters(&env, &duals).eps,
                    // The parameter asked for itself (a number, or an expression whose inputs
                    // are held): rate 1.
                    _ => 1.0,
                };
                if !eps.is_finite() {
                    let e = &entries[i];
                    let span = match &e.value {
                        Value::Expr(s, _) => s.span(),
                        Value::Number(_) => e.name.span(),
                    };
                    return Err(self.err(
                        span,
                        format!(
                            "the derivative of '{}' with respect to '{}' is {eps} at the values \
                             given (a square root or logarithm at 0?), so sensitivities with \
                             respect to '{}' do not exist here",
                            e.name.get_ref(),
                            entries[p].name.get_ref(),
                            entries[p].name.get_ref(),
                        ),
                    ));
                }
                duals[i] = Dual64::new(re, eps);
                rates[i][a] = Some(eps);
            }
        }
        Ok(rates)
    }

    /// The parameters in an order where each follows those it uses, or the error naming a cycle.
    fn dependency_order(&self, entries: &[Entry<'_>]) -> Result<Vec<usize>, Error> {
        let mut mark = vec![Mark::New; entries.len()];
        let mut order = Vec::with_capacity(entries.len());
        // The path of the search: a parameter, and how many of its uses have been followed.
        let mut path: Vec<(usize, usize)> = Vec::new();
        for root in 0..entries.len() {
            if mark[root] != Mark::New {
                continue;
            }
            mark[root] = Mark::Open;
            path.push((root, 0));
            while let Some((node, next)) = path.last_mut() {
                let node = *node;
                match entries[node].uses.get(*next).copied() {
                    Some(used) => {
                        *next += 1;
                        match mark[used] {
                            Mark::New => {
                                mark[used] = Mark::Open;
                                path.push((used, 0));
                            }
                            Mark::Open => {
                                let start = path.iter().position(|(p, _)| *p == used).unwrap_or(0);
                                let cycle: Vec<usize> =
                                    path[start..].iter().map(|(p, _)| *p).collect();
                                return Err(self.cycle_error(entries, &cycle));
                            }
                            Mark::Done => {}
                        }
                    }
                    None => {
                        mark[node] = Mark::Done;
                        order.push(node);
                        path.pop();
                    }
                }
            }
        }
        Ok(order)
    }

    /// `cycle[i]` uses `cycle[i + 1]`, and the last uses the first.
    fn cycle_error(&self, entries: &[Entry<'_>], cycle: &[usize]) -> Error {
        // Start at the member written first, so the message does not depend on the search.
        let first = (0..cycle.len()).min_by_key(|&i| cycle[i]).unwrap_or(0);
        let members: Vec<&str> = cycle[first..]
            .iter()
            .chain(&cycle[..first])
            .map(|&i| entries[i].name.get_ref().as_str())
            .collect();
        let e = &entries[cycle[first]];
        let span = match &e.value {
            Value::Expr(s, _) => s.span(),
            Value::Number(_) => e.name.span(),
        };
        if members.len() == 1 {
            return self.err(
                span,
                format!(
                    "the parameter '{}' is defined in terms of itself; give it a number",
                    members[0]
                ),
            );
        }
        let mut chain: Vec<&str> = members.iter().take(CYCLE_LISTED).copied().collect();
        if members.len() > CYCLE_LISTED {
            chain.push("…");
        }
        chain.push(members[0]);
        self.err(
            span,
            format!(
                "the parameters are defined in terms of each other in a cycle of {}, each using the next: \
                 {}; give one of them a number",
                members.len(),
                chain.join(" → "),
            ),
        )
    }
}
