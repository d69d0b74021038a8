//! `[parameters]`: numbers, and expressions of other parameters in any order, resolved in an order
//! where each comes after the parameters it uses.
//!
//! The parameters and the names their expressions use form a directed graph. One depth-first
//! search, iterative so that a chain of any length does not deepen the stack, orders it in time
//! linear in the number of parameters and names, and finds a cycle if there is one; the cycle is
//! reported with its members in order. Each expression is then folded to its value once, against
//! the values already known.

use std::collections::{BTreeMap, HashMap};

use toml::Spanned;

use super::schema::Number;
use super::validate::Builder;
use crate::error::Error;
use crate::expr::{check_name, parse as expr_parse, Expr, Symbols};

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

#[derive(Clone, Copy, PartialEq, Eq)]
enum Mark {
    New,
    Open,
    Done,
}

impl Builder {
    /// The parameters in the order of the file, with their values.
    pub(super) fn parameters(
        &self,
        raw: &BTreeMap<Spanned<String>, Spanned<Number>>,
    ) -> Result<Vec<(String, f64)>, Error> {
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
                                // Not a parameter: pi or e, or a mistake, reported with every
                                // parameter name as a candidate for "did you mean".
                                let symbols = all_names.get_or_insert_with(|| Symbols {
                                    parameters: written
                                        .iter()
                                        .map(|(k, _)| (k.get_ref().clone(), 0.0))
                                        .collect(),
                                    coordinates: Vec::new(),
                                    motion: false,
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
        let mut known = Symbols {
            parameters: BTreeMap::new(),
            coordinates: Vec::new(),
            motion: false,
        };
        let mut values = vec![0.0; entries.len()];
        for i in order {
            let e = &entries[i];
            let value = match &e.value {
                Value::Number(x) => *x,
                Value::Expr(s, ast) => Expr::from_ast(s.get_ref(), ast, &known)
                    .map_err(|err| self.expr_error(s, err))?
                    .constant()
                    .ok_or_else(|| {
                        self.err(s.span(), "a parameter must be a constant expression")
                    })?,
            };
            known.parameters.insert(e.name.get_ref().clone(), value);
            values[i] = value;
        }
        Ok(entries
            .iter()
            .zip(values)
            .map(|(e, v)| (e.name.get_ref().clone(), v))
            .collect())
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
