//! Derivatives through the expression tree, by num-dual, against derivatives worked out by hand.

use chetaev_scene::expr::{Env, Expr, Symbols};
use num_dual::{Dual64, DualNum, HyperDual64};

fn symbols() -> Symbols {
    Symbols::motion(&[("m", 1.5), ("k", 0.7)], &["x", "y"])
}

/// Evaluates `e` with `x`, `y`, `x_dot`, `y_dot`, `t` given as dual numbers.
fn eval<D: DualNum<f64> + Copy>(e: &Expr, t: D, x: D, y: D, xd: D, yd: D) -> D {
    e.eval(&Env {
        t,
        q: &[x, y],
        qd: &[xd, yd],
    })
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(1.0)
}

#[test]
fn first_derivatives_match_hand_derivatives() {
    // f = m x_dot^2 y / 2 + sin(k t) ln(1 + x^2) + exp(-y) x_dot^3 + atan2(y, x) + (x^2 + y^2)^0.75
    let f = Expr::parse(
        "m*x_dot^2*y/2 + sin(k*t)*ln(1 + x^2) + exp(-y)*x_dot^3 + atan2(y, x) + (x^2 + y^2)^0.75",
        &symbols(),
    )
    .expect("parses");
    let (m, k) = (1.5, 0.7);
    let (t, x, y, xd, yd) = (0.3, 1.2, -0.4, 2.0, 0.5);
    let r2 = x * x + y * y;
    let hand = [
        // ∂f/∂t
        k * (k * t).cos() * (1.0 + x * x).ln(),
        // ∂f/∂x
        (k * t).sin() * 2.0 * x / (1.0 + x * x) - y / r2 + 1.5 * x * r2.powf(-0.25),
        // ∂f/∂y
        m * xd * xd / 2.0 - (-y).exp() * xd.powi(3) + x / r2 + 1.5 * y * r2.powf(-0.25),
        // ∂f/∂x_dot
        m * xd * y + 3.0 * (-y).exp() * xd * xd,
        // ∂f/∂y_dot
        0.0,
    ];
    let c = Dual64::from;
    let seeded = |i: usize| {
        let v = [t, x, y, xd, yd];
        let d: Vec<Dual64> = (0..5)
            .map(|j| {
                if j == i {
                    Dual64::new(v[j], 1.0)
                } else {
                    c(v[j])
                }
            })
            .collect();
        eval(&f, d[0], d[1], d[2], d[3], d[4])
    };
    for (i, want) in hand.iter().enumerate() {
        let got = seeded(i).eps;
        assert!(rel(got, *want) < 1e-14, "derivative {i}: {got} vs {want}");
    }
}

#[test]
fn second_derivatives_give_the_mass_matrix_and_mixed_terms() {
    // A configuration-dependent mass matrix and a gyroscopic term:
    // L = ½ m (x_dot² + (1 + x²) y_dot²) + k x y_dot − m cosh(y)
    let l = Expr::parse(
        "0.5*m*(x_dot^2 + (1 + x^2)*y_dot^2) + k*x*y_dot - m*cosh(y)",
        &symbols(),
    )
    .expect("parses");
    let (m, k) = (1.5, 0.7);
    let (x, y, xd, yd) = (0.8, 0.2, -1.0, 0.4);
    let h = |a: HyperDual64| a;
    let c = HyperDual64::from;
    // ∂²L/∂y_dot² = m (1 + x²)
    let v = eval(
        &l,
        c(0.0),
        c(x),
        c(y),
        c(xd),
        h(HyperDual64::new(yd, 1.0, 1.0, 0.0)),
    );
    assert!(rel(v.eps1eps2, m * (1.0 + x * x)) < 1e-15);
    // ∂²L/∂y_dot∂x = 2 m x y_dot + k
    let v = eval(
        &l,
        c(0.0),
        HyperDual64::new(x, 1.0, 0.0, 0.0),
        c(y),
        c(xd),
        HyperDual64::new(yd, 0.0, 1.0, 0.0),
    );
    assert!(rel(v.eps1eps2, 2.0 * m * x * yd + k) < 1e-15);
    // ∂²L/∂y² = −m cosh(y)
    let v = eval(
        &l,
        c(0.0),
        c(x),
        HyperDual64::new(y, 1.0, 1.0, 0.0),
        c(xd),
        c(yd),
    );
    assert!(rel(v.eps1eps2, -m * y.cosh()) < 1e-15);
    // ∂²L/∂x_dot∂y_dot = 0
    let v = eval(
        &l,
        c(0.0),
        c(x),
        c(y),
        HyperDual64::new(xd, 1.0, 0.0, 0.0),
        HyperDual64::new(yd, 0.0, 1.0, 0.0),
    );
    assert_eq!(v.eps1eps2, 0.0);
}

#[test]
fn powers_differentiate_as_powers() {
    let s = symbols();
    let d = |src: &str, x: f64| {
        let e = Expr::parse(src, &s).expect("parses");
        let z = Dual64::from(0.0);
        eval(&e, z, Dual64::new(x, 1.0), z, z, z).eps
    };
    assert!(rel(d("x^3", 2.0), 12.0) < 1e-15);
    assert!(rel(d("x^-2", 2.0), -0.25) < 1e-15);
    assert!(rel(d("x^2.5", 2.0), 2.5 * 2f64.powf(1.5)) < 1e-15);
    assert!(rel(d("2^x", 2.0), 4.0 * 2f64.ln()) < 1e-15);
    assert!(rel(d("x^x", 2.0), 4.0 * (2f64.ln() + 1.0)) < 1e-15);
    assert!(rel(d("sqrt(x)", 4.0), 0.25) < 1e-15);
    assert!(rel(d("1/x", 4.0), -1.0 / 16.0) < 1e-15);
    assert!(rel(d("3 - x", 4.0), -1.0) < 1e-15);
    assert!(rel(d("abs(x)", -4.0), -1.0) < 1e-15);
}

#[test]
fn time_derivative_along_the_motion() {
    // d/dt of f(t, q, q̇) along the direction (q̇, 1): one Dual64 pass, as chetaev's pass E does.
    let f = Expr::parse("x_dot^2 + y_dot^2 - (2 + 0.5*t)^2 + x*y", &symbols()).expect("parses");
    let (t, x, y, xd, yd) = (1.0, 0.5, 2.0, 1.5, -0.5);
    let v = eval(
        &f,
        Dual64::new(t, 1.0),
        Dual64::new(x, xd),
        Dual64::new(y, yd),
        Dual64::from(xd),
        Dual64::from(yd),
    );
    let hand = -2.0 * (2.0 + 0.5 * t) * 0.5 + xd * y + x * yd;
    assert!(rel(v.eps, hand) < 1e-15, "{} vs {hand}", v.eps);
}
