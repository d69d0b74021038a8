//! Constant powers `x^n` of any size: value, first, second and third derivatives against
//! `n x^(n−1)`, `n (n−1) x^(n−2)`, `n (n−1) (n−2) x^(n−3)`, with the nested dual numbers `chetaev`
//! uses (`HyperDual` for `∂²L/∂q̇²`, `Dual<HyperDual>` for the Jacobian of the implicit method).
//!
//! num-dual's own `powi` forms `n (n−1)` in `i32`, which overflows from `|n| = 46 341` on: a panic
//! in a debug build, wrong second derivatives in a release build.

use chetaev_scene::expr::{Env, Expr, Symbols, MAX_EXPONENT, POWI_MAX};
use chetaev_scene::Scene;
use num_dual::{Dual, Dual64, DualNum, HyperDual, HyperDual64};
use proptest::prelude::*;

/// `x^n` as the scene language reads it, `n` written as an integer literal.
fn power(n: i64) -> Expr {
    let src = if n < 0 {
        format!("x^-{}", n.unsigned_abs())
    } else {
        format!("x^{n}")
    };
    Expr::parse(&src, &Symbols::motion(&[], &["x"])).unwrap_or_else(|e| panic!("{src}: {e}"))
}

fn eval<D: DualNum<f64> + Copy>(e: &Expr, x: D) -> D {
    e.eval(&Env {
        t: D::from(0.0),
        q: &[x],
        qd: &[D::from(0.0)],
    })
}

/// `d^k/dx^k x^n = n (n−1) ... (n−k+1) x^(n−k)`, formed in `f64` from `|x|^(n−k) = exp((n−k) ln|x|)`
/// and the sign of `x^(n−k)`: independent of both `powi` and `powf`.
fn analytic(n: i64, x: f64, k: i64) -> f64 {
    let m = n - k;
    let factor: f64 = (0..k).map(|i| (n - i) as f64).product();
    let magnitude = ((m as f64) * x.abs().ln()).exp();
    let negative = x < 0.0 && m % 2 != 0;
    factor * if negative { -magnitude } else { magnitude }
}

fn rel(a: f64, b: f64) -> f64 {
    if a == b {
        0.0
    } else {
        (a - b).abs() / b.abs().max(f64::MIN_POSITIVE)
    }
}

/// Value and three derivatives of `x^n` at `x`, from `HyperDual` (second) and `Dual<HyperDual>`
/// (third), checked against [`analytic`] to `tol` relative.
fn check(n: i64, x: f64, tol: f64) {
    let e = power(n);
    let h: HyperDual64 = eval(&e, HyperDual64::new(x, 1.0, 1.0, 0.0));
    let d: Dual64 = eval(&e, Dual64::new(x, 1.0));
    let v: f64 = eval(&e, x);
    let nested: Dual<HyperDual64, f64> = eval(
        &e,
        Dual::new(
            HyperDual64::new(x, 1.0, 1.0, 0.0),
            HyperDual64::new(1.0, 0.0, 0.0, 0.0),
        ),
    );
    let want = [0, 1, 2, 3].map(|k| analytic(n, x, k));
    let got = [
        (v, want[0], "value"),
        (h.re, want[0], "HyperDual value"),
        (d.eps, want[1], "Dual first"),
        (h.eps1, want[1], "HyperDual first"),
        (h.eps1eps2, want[2], "HyperDual second"),
        (nested.eps.eps1eps2, want[3], "Dual<HyperDual> third"),
        (nested.re.eps1eps2, want[2], "Dual<HyperDual> second"),
    ];
    for (got, want, what) in got {
        assert!(want.is_finite(), "x^{n} at {x}: reference {what} {want}");
        assert!(
            rel(got, want) <= tol,
            "x^{n} at x = {x}: {what} {got:e}, expected {want:e} (relative error {:e})",
            rel(got, want)
        );
    }
}

/// Points where `x^n` and its first three derivatives are finite and far from zero:
/// `x = ±(1 + c/|n|)`, so that `x^n ≈ e^(±c)`.
fn points(n: i64) -> Vec<f64> {
    let a = (n.unsigned_abs().max(1)) as f64;
    [-0.5, 0.3, 1.0]
        .iter()
        .flat_map(|c| [1.0 + c / a, -(1.0 + c / a)])
        .collect()
}

#[test]
fn small_integer_powers_are_exact_to_rounding() {
    for n in -40..=40 {
        for x in [0.5, 2.0, -3.0, 1.1] {
            // x^(n−3) of the third derivative; skip 0^negative, which is not in the domain.
            check(n, x, 1e-13);
        }
    }
}

#[test]
fn the_whole_i32_range_and_beyond_differentiates_without_overflow() {
    let edges = [
        i64::from(POWI_MAX) - 1,
        i64::from(POWI_MAX),
        i64::from(POWI_MAX) + 1,
        1289,
        1290,
        1291,
        46_340,
        46_341,
        46_342,
        65_536,
        1_000_003,
        i64::from(i32::MAX) - 2,
        i64::from(i32::MAX),
        i64::from(i32::MAX) + 1,
        1 << 40,
        (1 << 52) - 1,
        1 << 52,
    ];
    for n in edges
        .iter()
        .flat_map(|n| [*n, -*n])
        .chain([i64::from(i32::MIN)])
    {
        for x in points(n) {
            check(n, x, 1e-12);
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]

    /// Exponents drawn log-uniformly up to 2^52 (`MAX_EXPONENT`), both signs.
    #[test]
    fn random_integer_exponents_give_analytic_derivatives(
        bits in 0u32..52,
        mantissa in any::<u64>(),
        negative in any::<bool>(),
        c in prop::sample::select(vec![-0.5, 0.3, 1.0]),
        flip in any::<bool>(),
    ) {
        let magnitude = (1i64 << bits) | (mantissa as i64 & ((1i64 << bits) - 1));
        let n = if negative { -magnitude } else { magnitude };
        let a = n.unsigned_abs() as f64;
        let x = if flip { -(1.0 + c / a) } else { 1.0 + c / a };
        check(n, x, 1e-12);
    }
}

#[test]
fn exponents_beyond_2_to_the_52_are_located_errors() {
    assert_eq!(MAX_EXPONENT, 2f64.powi(52));
    let s = Symbols::motion(&[("big", 1e16)], &["x"]);
    for (src, at) in [
        ("x^4503599627370497", 2),
        ("1 + x^-1e16", 6),
        ("x^big", 2),
        ("x^(big/2)", 3),
    ] {
        let e = Expr::parse(src, &s).expect_err(src);
        assert_eq!(e.start, at, "{src}: {e}");
        assert!(e.message.contains("too large"), "{src}: {e}");
    }
    // A constant base and the variable exponents are not limited.
    for src in ["0.5^big", "x^x_dot", "x^4503599627370496"] {
        Expr::parse(src, &s).unwrap_or_else(|e| panic!("{src}: {e}"));
    }
    // In a scene, the error points at the exponent's place in the file.
    let text = "[model]\ncoordinates = [\"x\"]\nlagrangian = \"x_dot^2 - x^1e17\"\n\
                [initial]\nq = [0.5]\nq_dot = [0.0]\n[solve]\nt_end = 1.0\n";
    let e = Scene::parse(text, "big.toml").expect_err("too large");
    assert_eq!(e.position(), Some((3, 27)), "{e}");
}

#[test]
fn a_scene_with_a_huge_exponent_checks_and_solves_with_every_method() {
    // L = ẋ²/2 − x^n/n: the force −x^(n−1) is negligible at x = 0.5, so x(t) = 0.5 + t/10.
    for method in ["dop853", "rodas4"] {
        let text = format!(
            "[model]\ncoordinates = [\"x\"]\nlagrangian = \"0.5*x_dot^2 - x^1000000/1000000\"\n\
             [initial]\nq = [0.5]\nq_dot = [0.1]\n[solve]\nmethod = \"{method}\"\nt_end = 1.0\n"
        );
        let scene = Scene::parse(&text, "huge.toml").unwrap_or_else(|e| panic!("{e}"));
        scene.check().unwrap_or_else(|e| panic!("{method}: {e}"));
        let o = scene.solve().unwrap_or_else(|e| panic!("{method}: {e}"));
        assert!(o.is_success(), "{method}: {:?}", o.status);
        let x = o.q.last().expect("points")[0];
        assert!((x - 0.6).abs() < 1e-9, "{method}: {x}");
    }
}

#[test]
fn nested_duals_of_a_huge_power_near_one() {
    // The second-order type `chetaev` uses for W, seeded in two directions at once.
    let e = power(50_000);
    let x = 1.0 + 1e-5;
    let h: HyperDual<f64, f64> = eval(&e, HyperDual::new(x, 1.0, 1.0, 0.0));
    assert!(rel(h.eps1eps2, analytic(50_000, x, 2)) < 1e-12, "{h:?}");
}
