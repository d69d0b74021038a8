//! `chetaev describe`: the scene's equations by the scene's names, and the multipliers and
//! accelerations as expressions that are the solver's.

use chetaev_scene::expr::{Env, Expr, Symbols};
use chetaev_scene::Scene;

fn scene(name: &str) -> Scene {
    let path = format!("{}/../../scenes/{name}", env!("CARGO_MANIFEST_DIR"));
    Scene::load(&path).expect("the scene is valid")
}

/// The expression of row `label` in the plain-text description.
fn row(text: &str, label: &str) -> String {
    text.lines()
        .find_map(|l| {
            let (k, v) = l.trim().split_once(" = ")?;
            (k.trim() == label).then(|| v.trim().to_string())
        })
        .unwrap_or_else(|| panic!("no row {label} in\n{text}"))
}

/// A printed row read back in the scene's expression language (`·` written `*`).
fn parse(scene: &Scene, printed: &str) -> Expr {
    let parameters: Vec<(&str, f64)> = scene
        .parameters
        .iter()
        .map(|(n, v)| (n.as_str(), *v))
        .collect();
    let coordinates: Vec<&str> = scene.coordinates.iter().map(String::as_str).collect();
    let symbols = Symbols::motion(&parameters, &coordinates);
    Expr::parse(&printed.replace('·', "*"), &symbols)
        .unwrap_or_else(|e| panic!("{printed} does not read back: {e}"))
}

/// The printed `μ` and `q̈`, read back and evaluated at each state, against the solver's.
fn printed_rows_are_the_solvers(name: &str, states: &[(f64, Vec<f64>, Vec<f64>)]) {
    let s = scene(name);
    let text = s.describe().expect("describes");
    let problem = s.problem().expect("problem");
    let (n, k) = (s.n(), s.k());
    let mu: Vec<Expr> = (1..=k)
        .map(|a| parse(&s, &row(&text, &format!("μ[{a}]"))))
        .collect();
    let qdd: Vec<Expr> = (1..=n)
        .map(|i| parse(&s, &row(&text, &format!("q̈[{i}]"))))
        .collect();
    for (t, q, qd) in states {
        let d = problem.equations_at(*t, q, qd).expect("evaluates");
        let env = Env { t: *t, q, qd };
        for (e, solved) in mu.iter().zip(&d.mu).chain(qdd.iter().zip(&d.qdd)) {
            let printed = e.eval(&env);
            assert!(
                (printed - solved).abs() <= 1e-12 * solved.abs().max(1.0),
                "{}: {printed} printed, {solved} solved at t = {t}, q = {q:?}, q̇ = {qd:?}",
                e.source()
            );
        }
    }
}

#[test]
fn the_papers_multiplier_is_described_as_the_paper_eliminates_it() {
    let s = scene("uniform-projectile.toml");
    let text = s.describe().expect("describes");
    assert_eq!(row(&text, "μ[1]"), "m·g·y_dot/(2·(x_dot^2 + y_dot^2))");
    assert_eq!(row(&text, "q̈[2]"), "-g + g·y_dot^2/(x_dot^2 + y_dot^2)");
    assert_eq!(row(&text, "f[1]"), "x_dot^2 + y_dot^2 - v0^2");
    assert_eq!(row(&text, "J[1,1]"), "2·x_dot");
    let latex = s.describe_latex().expect("describes");
    for line in [
        "  \\mu &= \\frac{m g \\dot{y}}{2 \\left(\\dot{x}^{2} + \\dot{y}^{2}\\right)}",
        "  f_{1} &= \\dot{x}^{2} + \\dot{y}^{2} - v_{0}^{2}",
        "  \\frac{\\partial L}{\\partial y} &= -m g",
    ] {
        assert!(
            latex.lines().any(|l| l.trim_end_matches(" \\\\") == line),
            "{line} not in\n{latex}"
        );
    }
    printed_rows_are_the_solvers(
        "uniform-projectile.toml",
        &[
            (0.0, vec![0.0, 5.0], vec![10.0, 0.0]),
            (0.5, vec![4.0, 3.0], vec![6.0, -8.0]),
            (0.5, vec![4.0, 3.0], vec![3.0, 2.0]),
        ],
    );
}

#[test]
fn a_parameter_given_as_an_expression_is_shown_by_its_name() {
    let s = scene("your-own-constraint.toml");
    let latex = s.describe_latex().expect("describes");
    assert!(
        latex.contains("f_{2} &= \\dot{z} + \\dot{y} \\tan\\left(\\alpha\\right)"),
        "{latex}"
    );
    assert!(
        !latex.contains("0.36"),
        "tan(pi/9) folded to its value in\n{latex}"
    );
    assert!(!latex.contains("q_{"), "{latex}");
    // Its μ and q̈ are too long to print in full: the report says how they are solved.
    assert!(latex.contains("\\text{(solved numerically)}"), "{latex}");
    let text = s.describe().expect("describes");
    assert!(text.contains("μ, q̈ solved numerically"), "{text}");
    assert!(!text.contains("μ[1]       ="), "{text}");
}
