//! The lexer: an expression's text as numbers, names and operators, each with its byte span.

use super::ExprError;

/// A token of the expression language.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Tok {
    /// A number literal: `2`, `0.5`, `.5`, `1e-3`, `6.674E-11`.
    Num(f64),
    /// A name: a parameter, coordinate, velocity, function or constant.
    Name(String),
    Plus,
    Minus,
    Star,
    Slash,
    Caret,
    LParen,
    RParen,
    Comma,
    /// The end of the expression.
    End,
}

impl Tok {
    /// How the token is called in messages.
    pub(crate) fn describe(&self) -> String {
        match self {
            Tok::Num(v) => format!("the number {v}"),
            Tok::Name(n) => format!("the name '{n}'"),
            Tok::Plus => "'+'".into(),
            Tok::Minus => "'-'".into(),
            Tok::Star => "'*'".into(),
            Tok::Slash => "'/'".into(),
            Tok::Caret => "'^'".into(),
            Tok::LParen => "'('".into(),
            Tok::RParen => "')'".into(),
            Tok::Comma => "','".into(),
            Tok::End => "the end of the expression".into(),
        }
    }
}

/// A token and its byte span `start..end` in the expression.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Token {
    pub tok: Tok,
    pub start: usize,
    pub end: usize,
}

/// Splits `src` into tokens; the last one is [`Tok::End`].
pub(crate) fn tokenize(src: &str) -> Result<Vec<Token>, ExprError> {
    let bytes = src.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        let c = bytes[i];
        let start = i;
        let single = match c {
            b' ' | b'\t' | b'\n' | b'\r' => {
                i += 1;
                continue;
            }
            b'+' => Some(Tok::Plus),
            b'-' => Some(Tok::Minus),
            b'*' => {
                if bytes.get(i + 1) == Some(&b'*') {
                    return Err(ExprError::new(
                        start,
                        start + 2,
                        "'**' is not an operator: write powers with '^', as in x^2",
                    ));
                }
                Some(Tok::Star)
            }
            b'/' => Some(Tok::Slash),
            b'^' => Some(Tok::Caret),
            b'(' => Some(Tok::LParen),
            b')' => Some(Tok::RParen),
            b',' => Some(Tok::Comma),
            _ => None,
        };
        if let Some(tok) = single {
            i += 1;
            out.push(Token { tok, start, end: i });
            continue;
        }
        if c.is_ascii_digit() || (c == b'.' && bytes.get(i + 1).is_some_and(u8::is_ascii_digit)) {
            i = number_end(src, start)?;
            let text = &src[start..i];
            let value: f64 = text
                .parse()
                .map_err(|_| ExprError::new(start, i, format!("'{text}' is not a valid number")))?;
            out.push(Token {
                tok: Tok::Num(value),
                start,
                end: i,
            });
            continue;
        }
        if c.is_ascii_alphabetic() || c == b'_' {
            while i < bytes.len() && (bytes[i].is_ascii_alphanumeric() || bytes[i] == b'_') {
                i += 1;
            }
            out.push(Token {
                tok: Tok::Name(src[start..i].to_string()),
                start,
                end: i,
            });
            continue;
        }
        let ch = src[start..].chars().next().unwrap_or('?');
        let hint = match ch {
            '·' | '×' => " (write multiplication as '*')",
            '−' | '–' => " (write minus as '-')",
            '²' | '³' => " (write powers as x^2)",
            '[' | ']' | '{' | '}' => " (group with '(' and ')')",
            _ if !ch.is_ascii() => {
                " (names are ASCII letters, digits and '_'; velocities are written x_dot)"
            }
            _ => "",
        };
        return Err(ExprError::new(
            start,
            start + ch.len_utf8(),
            format!("unexpected character '{ch}'{hint}"),
        ));
    }
    out.push(Token {
        tok: Tok::End,
        start: src.len(),
        end: src.len(),
    });
    Ok(out)
}

/// The end of the number literal starting at `start`: digits, an optional fraction and an optional
/// exponent `e[+-]digits`.
fn number_end(src: &str, start: usize) -> Result<usize, ExprError> {
    let b = src.as_bytes();
    let mut i = start;
    let digits = |i: &mut usize| {
        let s = *i;
        while *i < b.len() && b[*i].is_ascii_digit() {
            *i += 1;
        }
        *i > s
    };
    digits(&mut i);
    if i < b.len() && b[i] == b'.' {
        i += 1;
        digits(&mut i);
    }
    if i < b.len() && (b[i] == b'e' || b[i] == b'E') {
        // An exponent only if digits follow (possibly signed); otherwise a malformed number.
        let mut j = i + 1;
        if j < b.len() && (b[j] == b'+' || b[j] == b'-') {
            j += 1;
        }
        if j < b.len() && b[j].is_ascii_digit() {
            i = j;
            digits(&mut i);
        } else {
            let end = j.min(b.len());
            return Err(ExprError::new(
                start,
                end,
                format!(
                    "malformed number '{}': expected digits after the exponent, as in 1e-3",
                    &src[start..end]
                ),
            ));
        }
    }
    if i < b.len() && (b[i].is_ascii_alphabetic() || b[i] == b'_') {
        return Err(ExprError::new(
            start,
            i + 1,
            format!(
                "a number directly followed by a name ('{}'): write the product with '*', as in 2*x",
                &src[start..=i]
            ),
        ));
    }
    Ok(i)
}
