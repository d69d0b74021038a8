//! The parser: recursive descent over the tokens, one function per precedence level.
//!
//! ```text
//! expr    := term (('+' | '-') term)*
//! term    := unary (('*' | '/') unary)*
//! unary   := ('-' | '+') unary | power
//! power   := atom ('^' unary)?              right-associative: 2^3^2 = 2^(3^2), -x^2 = -(x^2)
//! atom    := number | name | name '(' expr (',' expr)* ')' | '(' expr ')'
//! ```

use super::lex::{tokenize, Tok, Token};
use super::ExprError;

/// The most numbers, names, operators and parentheses an expression may have: a Lagrangian of a few
/// thousand coordinates written out. It bounds the work of loading a scene; the recursion of
/// parsing, folding and evaluation is bounded by [`MAX_DEPTH`], since a chain of sums or products
/// is one node of the syntax tree.
pub const MAX_TOKENS: usize = 100_000;

/// The deepest nesting of parentheses, signs and exponents an expression may have.
pub const MAX_DEPTH: usize = 64;

/// A binary operator.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum BinOp {
    Add,
    Sub,
    Mul,
    Div,
    Pow,
}

/// The syntax tree before names are resolved. Every node carries its byte span.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Ast {
    Num(f64, Span),
    Name(String, Span),
    Call(String, Span, Vec<Ast>),
    Neg(Box<Ast>, Span),
    Bin(BinOp, Box<Ast>, Box<Ast>, Span),
    /// `a op₁ b op₂ c …` of left-associative operators of one level (`+`, `−` or `×`, `÷`), read
    /// left to right: one node however long, so that no walk of the tree (nor dropping it)
    /// recurses through the terms of a long sum.
    Chain(Box<Ast>, Vec<(BinOp, Ast)>, Span),
}

/// A byte range `start..end` in the expression.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Span {
    pub start: usize,
    pub end: usize,
}

impl Ast {
    pub(crate) fn span(&self) -> Span {
        match self {
            Ast::Num(_, s) | Ast::Name(_, s) | Ast::Call(_, s, _) | Ast::Neg(_, s) => *s,
            Ast::Bin(_, _, _, s) | Ast::Chain(_, _, s) => *s,
        }
    }

    /// Every name the expression refers to (not the called functions), with its span.
    pub(crate) fn names(&self, out: &mut Vec<(String, Span)>) {
        match self {
            Ast::Num(..) => {}
            Ast::Name(n, s) => out.push((n.clone(), *s)),
            Ast::Call(_, _, args) => args.iter().for_each(|a| a.names(out)),
            Ast::Neg(a, _) => a.names(out),
            Ast::Chain(first, rest, _) => {
                first.names(out);
                rest.iter().for_each(|(_, b)| b.names(out));
            }
            Ast::Bin(_, a, b, _) => {
                a.names(out);
                b.names(out);
            }
        }
    }
}

/// Parses `src` into a syntax tree.
pub(crate) fn parse(src: &str) -> Result<Ast, ExprError> {
    let tokens = tokenize(src)?;
    if tokens.len() > MAX_TOKENS {
        return Err(ExprError::new(
            tokens[MAX_TOKENS].start,
            src.len(),
            format!(
                "the expression has {} numbers, names and operators, more than the {MAX_TOKENS} \
                 allowed; define constant parts of it as parameters, or write a model this large \
                 in Rust (the DynModel trait, docs/formulation.md), where L can be a loop",
                tokens.len() - 1
            ),
        ));
    }
    if tokens.len() == 1 {
        return Err(ExprError::new(
            0,
            src.len(),
            "the expression is empty: expected a number, a name or '('",
        ));
    }
    let mut p = Parser {
        tokens,
        pos: 0,
        depth: 0,
    };
    let ast = p.expr()?;
    let t = p.peek();
    if t.tok != Tok::End {
        let message = match &t.tok {
            Tok::RParen => "unmatched ')': there is no '(' to close".to_string(),
            Tok::Num(_) | Tok::Name(_) | Tok::LParen => format!(
                "expected an operator (+ - * / ^) or the end of the expression, found {}; \
                 products are written with '*', as in 2*x",
                t.tok.describe()
            ),
            other => format!(
                "expected an operator (+ - * / ^) or the end of the expression, found {}",
                other.describe()
            ),
        };
        return Err(ExprError::new(t.start, t.end, message));
    }
    Ok(ast)
}

struct Parser {
    tokens: Vec<Token>,
    pos: usize,
    /// Current nesting of parentheses, signs and exponents.
    depth: usize,
}

impl Parser {
    fn peek(&self) -> &Token {
        // The token list always ends with `End`, and `pos` never moves past it.
        &self.tokens[self.pos.min(self.tokens.len() - 1)]
    }

    fn next(&mut self) -> Token {
        let t = self.peek().clone();
        if t.tok != Tok::End {
            self.pos += 1;
        }
        t
    }

    fn expr(&mut self) -> Result<Ast, ExprError> {
        let first = self.term()?;
        let mut rest = Vec::new();
        loop {
            let op = match self.peek().tok {
                Tok::Plus => BinOp::Add,
                Tok::Minus => BinOp::Sub,
                _ => return Ok(chain(first, rest)),
            };
            let op_tok = self.next();
            rest.push((op, self.operand(&op_tok, Self::term)?));
        }
    }

    fn term(&mut self) -> Result<Ast, ExprError> {
        let first = self.unary()?;
        let mut rest = Vec::new();
        loop {
            let op = match self.peek().tok {
                Tok::Star => BinOp::Mul,
                Tok::Slash => BinOp::Div,
                _ => return Ok(chain(first, rest)),
            };
            let op_tok = self.next();
            rest.push((op, self.operand(&op_tok, Self::unary)?));
        }
    }

    fn unary(&mut self) -> Result<Ast, ExprError> {
        // The operand itself is level 0: MAX_DEPTH parentheses, signs or powers around it are
        // allowed, one more is not.
        if self.depth > MAX_DEPTH {
            let t = self.peek();
            return Err(ExprError::new(
                t.start,
                t.end.max(t.start + 1),
                format!(
                    "the expression nests parentheses, signs and powers more than {MAX_DEPTH} deep; \
                     define inner parts as parameters"
                ),
            ));
        }
        self.depth += 1;
        let result = self.unary_inner();
        self.depth -= 1;
        result
    }

    fn unary_inner(&mut self) -> Result<Ast, ExprError> {
        match self.peek().tok {
            Tok::Minus => {
                let op = self.next();
                let arg = self.operand(&op, Self::unary)?;
                let span = Span {
                    start: op.start,
                    end: arg.span().end,
                };
                Ok(Ast::Neg(Box::new(arg), span))
            }
            Tok::Plus => {
                let op = self.next();
                self.operand(&op, Self::unary)
            }
            _ => self.power(),
        }
    }

    fn power(&mut self) -> Result<Ast, ExprError> {
        let base = self.atom(None)?;
        if self.peek().tok == Tok::Caret {
            let op = self.next();
            let exponent = self.operand(&op, Self::unary)?;
            return Ok(join(BinOp::Pow, base, exponent));
        }
        Ok(base)
    }

    /// The operand after the operator `op`, parsed by `level`; a missing operand is reported at the
    /// token found instead.
    fn operand(
        &mut self,
        op: &Token,
        level: fn(&mut Self) -> Result<Ast, ExprError>,
    ) -> Result<Ast, ExprError> {
        if !starts_operand(&self.peek().tok) {
            return Err(self.missing_operand(Some(op)));
        }
        level(self)
    }

    fn missing_operand(&self, after: Option<&Token>) -> ExprError {
        let t = self.peek();
        let after = match after {
            Some(op) => format!(" after {}", op.tok.describe()),
            None => String::new(),
        };
        let hint = match (&t.tok, after.is_empty()) {
            (Tok::Star, false) | (Tok::Caret, false) | (Tok::Slash, false) => {
                " (two operators in a row: is one of them a typo?)"
            }
            (Tok::End, _) => " (the expression ends too early)",
            (Tok::RParen, _) => " (nothing between the parentheses?)",
            _ => "",
        };
        ExprError::new(
            t.start,
            t.end.max(t.start + 1),
            format!(
                "expected a number, a name or '('{after}, found {}{hint}",
                t.tok.describe()
            ),
        )
    }

    fn atom(&mut self, after: Option<&Token>) -> Result<Ast, ExprError> {
        let t = self.next();
        let span = Span {
            start: t.start,
            end: t.end,
        };
        match t.tok {
            Tok::Num(v) => Ok(Ast::Num(v, span)),
            Tok::Name(name) => {
                if self.peek().tok != Tok::LParen {
                    return Ok(Ast::Name(name, span));
                }
                let open = self.next();
                let mut args = Vec::new();
                if self.peek().tok == Tok::RParen {
                    let close = self.next();
                    return Err(ExprError::new(
                        open.start,
                        close.end,
                        format!("'{name}()' has no argument: expected an expression inside the parentheses"),
                    ));
                }
                loop {
                    if !starts_operand(&self.peek().tok) {
                        return Err(self.missing_operand(Some(&open)));
                    }
                    args.push(self.expr()?);
                    let sep = self.next();
                    match sep.tok {
                        Tok::Comma => continue,
                        Tok::RParen => {
                            let span = Span {
                                start: t.start,
                                end: sep.end,
                            };
                            return Ok(Ast::Call(name, span, args));
                        }
                        Tok::End => {
                            return Err(ExprError::new(
                                open.start,
                                open.end,
                                format!("unclosed '(' of '{name}(': expected ')'"),
                            ))
                        }
                        other => {
                            return Err(ExprError::new(
                                sep.start,
                                sep.end,
                                format!(
                                    "expected ',' or ')' in the arguments of '{name}', found {}",
                                    other.describe()
                                ),
                            ))
                        }
                    }
                }
            }
            Tok::LParen => {
                if !starts_operand(&self.peek().tok) {
                    return Err(self.missing_operand(Some(&t)));
                }
                let inner = self.expr()?;
                let close = self.next();
                match close.tok {
                    Tok::RParen => Ok(inner),
                    Tok::End => Err(ExprError::new(
                        t.start,
                        t.end,
                        "unclosed '(': expected ')' before the end of the expression",
                    )),
                    other => Err(ExprError::new(
                        close.start,
                        close.end,
                        format!("expected ')' or an operator, found {}", other.describe()),
                    )),
                }
            }
            _ => {
                // Put the token back so the message points at it.
                self.pos -= usize::from(t.tok != Tok::End);
                Err(self.missing_operand(after))
            }
        }
    }
}

fn starts_operand(t: &Tok) -> bool {
    matches!(
        t,
        Tok::Num(_) | Tok::Name(_) | Tok::LParen | Tok::Minus | Tok::Plus
    )
}

/// `first` alone, or the chain of it and the operations `rest`.
fn chain(first: Ast, rest: Vec<(BinOp, Ast)>) -> Ast {
    match rest.last() {
        None => first,
        Some((_, last)) => {
            let span = Span {
                start: first.span().start,
                end: last.span().end,
            };
            Ast::Chain(Box::new(first), rest, span)
        }
    }
}

fn join(op: BinOp, a: Ast, b: Ast) -> Ast {
    let span = Span {
        start: a.span().start,
        end: b.span().end,
    };
    Ast::Bin(op, Box::new(a), Box::new(b), span)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn symbol(op: BinOp) -> &'static str {
        match op {
            BinOp::Add => "+",
            BinOp::Sub => "-",
            BinOp::Mul => "*",
            BinOp::Div => "/",
            BinOp::Pow => "^",
        }
    }

    fn show(a: &Ast) -> String {
        match a {
            Ast::Num(v, _) => format!("{v}"),
            Ast::Name(n, _) => n.clone(),
            Ast::Call(f, _, args) => format!(
                "{f}({})",
                args.iter().map(show).collect::<Vec<_>>().join(", ")
            ),
            Ast::Neg(a, _) => format!("(-{})", show(a)),
            Ast::Bin(op, a, b, _) => format!("({} {} {})", show(a), symbol(*op), show(b)),
            // Shown as the left-associated operations it stands for.
            Ast::Chain(first, rest, _) => rest.iter().fold(show(first), |acc, (op, b)| {
                format!("({acc} {} {})", symbol(*op), show(b))
            }),
        }
    }

    #[test]
    fn precedence_and_associativity() {
        let p = |s: &str| show(&parse(s).expect(s));
        assert_eq!(p("1 + 2*3"), "(1 + (2 * 3))");
        assert_eq!(p("1 - 2 - 3"), "((1 - 2) - 3)");
        assert_eq!(p("8 / 4 / 2"), "((8 / 4) / 2)");
        assert_eq!(p("2^3^2"), "(2 ^ (3 ^ 2))");
        assert_eq!(p("-x^2"), "(-(x ^ 2))");
        assert_eq!(p("x^-2"), "(x ^ (-2))");
        assert_eq!(p("-2*x"), "((-2) * x)");
        assert_eq!(p("a*-b"), "(a * (-b))");
        assert_eq!(p("atan2(y, x) + sin(t)^2"), "(atan2(y, x) + (sin(t) ^ 2))");
        assert_eq!(p("1e-3*x_dot"), "(0.001 * x_dot)");
    }

    #[test]
    fn errors_point_at_the_offending_token() {
        let e = parse("x_dot^^2").expect_err("double caret");
        assert_eq!((e.start, e.end), (6, 7));
        let e = parse("(x + 1").expect_err("unclosed");
        assert_eq!(e.start, 0);
        let e = parse("2x").expect_err("implicit product");
        assert_eq!(e.start, 0);
        let e = parse("x +").expect_err("dangling");
        assert_eq!(e.start, 3);
        let long = vec!["x"; MAX_TOKENS / 2 + 1].join("+");
        assert!(parse(&long)
            .expect_err("too long")
            .message
            .contains(&format!("more than the {MAX_TOKENS}")));
        let nested = |n: usize| format!("{}x{}", "(".repeat(n), ")".repeat(n));
        assert!(parse(&nested(60)).is_ok());
        assert!(parse(&nested(MAX_DEPTH)).is_ok());
        let signs = |n: usize| format!("{}x", "-".repeat(n));
        assert!(parse(&signs(MAX_DEPTH)).is_ok());
        assert!(parse(&signs(MAX_DEPTH + 1)).is_err());
        assert!(parse(&nested(MAX_DEPTH + 1))
            .expect_err("deep")
            .message
            .contains("more than 64 deep"));
        assert!(parse(&"-".repeat(100)).is_err());
    }
}
