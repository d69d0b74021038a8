//! The expression language: precedence, unary minus, powers, functions, constants, and errors
//! that point at the line and column of the scene file.

use chetaev_scene::expr::{Env, Expr, Symbols};
use chetaev_scene::Scene;

fn value(src: &str) -> f64 {
    let s = Symbols::motion(&[("m", 2.0), ("g", 10.0)], &["x", "y"]);
    let e = Expr::parse(src, &s).unwrap_or_else(|e| panic!("{src}: {e}"));
    // x = 3, y = -0.5, x_dot = 0.25, y_dot = 4, t = 1.5
    e.eval(&Env {
        t: 1.5,
        q: &[3.0, -0.5],
        qd: &[0.25, 4.0],
    })
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-15 * b.abs().max(1.0)
}

#[test]
fn precedence_and_associativity() {
    assert_eq!(value("1 + 2*3"), 7.0);
    assert_eq!(value("(1 + 2)*3"), 9.0);
    assert_eq!(value("10 - 4 - 3"), 3.0);
    assert_eq!(value("64 / 4 / 2"), 8.0);
    assert_eq!(value("2*3^2"), 18.0);
    assert_eq!(value("2^3^2"), 512.0); // right-associative
    assert_eq!(value("1 + 2*x - y/4"), 1.0 + 6.0 + 0.125);
    assert_eq!(value("m*g*y"), -10.0);
}

#[test]
fn unary_minus() {
    assert_eq!(value("-2^2"), -4.0); // -(2^2)
    assert_eq!(value("(-2)^2"), 4.0);
    assert_eq!(value("-x"), -3.0);
    assert_eq!(value("--x"), 3.0);
    assert_eq!(value("2*-x"), -6.0);
    assert_eq!(value("2^-1"), 0.5);
    assert_eq!(value("x - -1"), 4.0);
    assert_eq!(value("+x"), 3.0);
}

#[test]
fn powers_integer_real_and_variable() {
    assert_eq!(value("x^2"), 9.0);
    assert_eq!(value("x^-2"), 1.0 / 9.0);
    assert_eq!(value("x^(m+1)"), 27.0); // a constant integer exponent from parameters
    assert!(close(value("x^0.5"), 3f64.sqrt()));
    assert!(close(value("x^t"), 3f64.powf(1.5))); // variable exponent
    assert!(close(value("2^x_dot"), 2f64.powf(0.25)));
    assert_eq!(value("y^3"), -0.125); // integer powers of negative numbers are fine
}

#[test]
fn numbers_names_constants_and_functions() {
    assert_eq!(value("1e-3"), 1e-3);
    assert_eq!(value("2.5E+2"), 250.0);
    assert_eq!(value(".5"), 0.5);
    assert_eq!(value("t"), 1.5);
    assert_eq!(value("x_dot + y_dot"), 4.25);
    assert!(close(value("pi"), std::f64::consts::PI));
    assert!(close(value("e"), std::f64::consts::E));
    let cases: [(&str, f64); 20] = [
        ("sqrt(x)", 3f64.sqrt()),
        ("cbrt(x)", 3f64.cbrt()),
        ("exp(y)", (-0.5f64).exp()),
        ("ln(x)", 3f64.ln()),
        ("log10(x)", 3f64.log10()),
        ("log2(x)", 3f64.log2()),
        ("sin(x)", 3f64.sin()),
        ("cos(x)", 3f64.cos()),
        ("tan(y)", (-0.5f64).tan()),
        ("asin(y)", (-0.5f64).asin()),
        ("acos(y)", (-0.5f64).acos()),
        ("atan(x)", 3f64.atan()),
        ("atan2(y, x)", (-0.5f64).atan2(3.0)),
        ("sinh(y)", (-0.5f64).sinh()),
        ("cosh(y)", (-0.5f64).cosh()),
        ("tanh(x)", 3f64.tanh()),
        ("asinh(x)", 3f64.asinh()),
        ("acosh(x)", 3f64.acosh()),
        ("atanh(y)", (-0.5f64).atanh()),
        ("abs(y)", 0.5),
    ];
    for (src, want) in cases {
        assert!(close(value(src), want), "{src}: {} vs {want}", value(src));
    }
    assert!(close(value("sin(x)^2 + cos(x)^2"), 1.0));
    assert!(close(value("atan2(sin(t), cos(t))"), 1.5));
}

#[test]
fn parameters_are_folded_to_constants() {
    let s = Symbols::motion(&[("v0", 10.0), ("g", 10.0)], &["x"]);
    let e = Expr::parse("v0^2/g + sqrt(g*10)", &s).expect("parses");
    assert_eq!(e.constant(), Some(20.0));
    assert_eq!(Expr::parse("x*v0", &s).expect("parses").constant(), None);
}

fn expr_error(src: &str) -> String {
    let s = Symbols::motion(&[("v0", 10.0)], &["x", "y"]);
    Expr::parse(src, &s).expect_err(src).message
}

#[test]
fn expression_errors_say_what_was_expected() {
    assert!(expr_error("x_dot^^2").contains("after '^', found '^'"));
    assert!(expr_error("2x").contains("write the product with '*'"));
    assert!(expr_error("x**2").contains("'**' is not an operator"));
    assert!(expr_error("(x + 1").contains("unclosed '('"));
    assert!(expr_error("x + 1)").contains("unmatched ')'"));
    assert!(expr_error("x +").contains("ends too early"));
    assert!(expr_error("").contains("empty"));
    assert!(expr_error("1e").contains("malformed number"));
    assert!(expr_error("xdot").contains("written x_dot"));
    assert!(expr_error("v00").contains("did you mean 'v0'?"));
    assert!(expr_error("sine(x)").contains("did you mean 'sin'?"));
    assert!(expr_error("log(x)").contains("ln (natural logarithm) or log10"));
    assert!(expr_error("sin").contains("call it with parentheses"));
    assert!(expr_error("atan2(x)").contains("takes 2 arguments, found 1"));
    assert!(expr_error("sin(x, y)").contains("takes 1 argument, found 2"));
    assert!(expr_error("v0(x)").contains("not a function"));
    assert!(expr_error("ẋ").contains("velocities are written x_dot"));
    assert!(expr_error("x/0").contains("division by zero"));
    assert!(expr_error("ln(-v0)").contains("NaN"));
}

#[test]
fn initial_values_cannot_use_the_motion() {
    let mut params = std::collections::BTreeMap::new();
    params.insert("h0".to_string(), 5.0);
    let e = Expr::parse("h0 + t", &Symbols::constants(&params)).expect_err("t");
    assert!(e.message.contains("'t' is time"), "{}", e.message);
}

const UNIFORM: &str = include_str!("../../../../scenes/uniform-projectile.toml");

/// The line and column of the first occurrence of `needle` (plus `offset` characters) in `text`.
fn line_col(text: &str, needle: &str, offset: usize) -> (usize, usize) {
    let at = text.find(needle).expect("needle") + offset;
    let line = text[..at].matches('\n').count() + 1;
    let col = text[..at]
        .rsplit('\n')
        .next()
        .map_or(0, |l| l.chars().count())
        + 1;
    (line, col)
}

#[test]
fn a_typo_in_the_constraints_points_at_its_line_and_column() {
    let text = UNIFORM.replace("x_dot^2 + y_dot^2 - v0^2", "x_dot^^2 + y_dot^2 - v0^2");
    let e = Scene::parse(&text, "typo.toml").expect_err("typo");
    let (line, col) = line_col(&text, "x_dot^^2", 6); // the second '^'
    assert_eq!(e.position(), Some((line, col)), "{e}");
    let shown = e.to_string();
    assert!(
        shown.starts_with(&format!("typo.toml:{line}:{col}: ")),
        "{shown}"
    );
    assert!(
        shown.contains("expected a number, a name or '(' after '^', found '^'"),
        "{shown}"
    );
    let snippet = e.snippet().expect("snippet");
    assert!(snippet.contains("constraints = [\"x_dot^^2"), "{snippet}");
    // The caret stands under the second '^'.
    let lines: Vec<&str> = snippet.lines().collect();
    let caret = lines[2].find('^').expect("caret");
    assert_eq!(&lines[1][caret..caret + 1], "^");
    assert_eq!(&lines[1][caret - 1..caret + 2], "^^2");
}

#[test]
fn positions_survive_escapes_and_literal_strings() {
    // A basic string with an escape before the mistake, and a literal string.
    let text = UNIFORM.replace(
        "lagrangian = \"0.5*m*(x_dot^2 + y_dot^2) - m*g*y\"",
        "lagrangian = \"0.5*m*(x_dot^2 +\\t y_dot^2) - m*g*yy\"",
    );
    let e = Scene::parse(&text, "s.toml").expect_err("unknown name");
    assert_eq!(e.position(), Some(line_col(&text, "yy\"", 0)), "{e}");
    let text = UNIFORM.replace(
        "constraints = [\"x_dot^2 + y_dot^2 - v0^2\"]",
        "constraints = ['x_dot^2 + y_dot^2 - v0 ^ 2 )']",
    );
    let e = Scene::parse(&text, "s.toml").expect_err("unmatched");
    assert_eq!(e.position(), Some(line_col(&text, ")']", 0)), "{e}");
}

#[test]
fn schema_errors_are_located_too() {
    let cases: [(&str, &str, &str, &str); 7] = [
        // (replace, with, expected text in the message, where the error points)
        (
            "method = \"dop853\"",
            "method = \"dop85\"",
            "choose one of dopri5, dop853",
            "\"dop85\"",
        ),
        (
            "lagrangian =",
            "lagrangain =",
            "unknown field `lagrangain`",
            "lagrangain",
        ),
        (
            "q = [0.0, \"h0\"]",
            "q = [0.0]",
            "expected 2, one for each of x, y",
            "[0.0]",
        ),
        ("h0 = 5.0", "h0 = \"2*hh\"", "unknown name 'hh'", "hh\""),
        (
            "direction = \"falling\"",
            "direction = \"down\"",
            "unknown variant `down`",
            "\"down\"",
        ),
        (
            "tables = [\"state\",",
            "tables = [\"states\",",
            "unknown variant `states`",
            "\"states\"",
        ),
        (
            "rtol = 1e-12",
            "rtol = \"tight\"",
            "invalid type",
            "\"tight\"",
        ),
    ];
    for (from, to, message, at) in cases {
        assert!(UNIFORM.contains(from), "{from}");
        let text = UNIFORM.replace(from, to);
        let e = Scene::parse(&text, "s.toml").expect_err(to);
        assert!(e.to_string().contains(message), "{to}: {e}");
        assert_eq!(e.position(), Some(line_col(&text, at, 0)), "{to}: {e}");
    }
}
