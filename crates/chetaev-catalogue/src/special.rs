//! Elementary functions in forms that stay accurate where the textbook form cancels.

/// `sin x / x`, `1` at `x = 0`.
pub(crate) fn sinc(x: f64) -> f64 {
    if x.abs() < 1e-2 {
        let x2 = x * x;
        1.0 - x2 / 6.0 * (1.0 - x2 / 20.0 * (1.0 - x2 / 42.0))
    } else {
        x.sin() / x
    }
}

/// `sinh x / x`, `1` at `x = 0`.
pub(crate) fn sinhc(x: f64) -> f64 {
    if x.abs() < 1e-2 {
        let x2 = x * x;
        1.0 + x2 / 6.0 * (1.0 + x2 / 20.0 * (1.0 + x2 / 42.0))
    } else {
        x.sinh() / x
    }
}

/// `tanh x / x`, `1` at `x = 0`.
pub(crate) fn tanhc(x: f64) -> f64 {
    if x.abs() < 1e-2 {
        let x2 = x * x;
        1.0 - x2 / 3.0 * (1.0 - 0.4 * x2 * (1.0 - 17.0 / 42.0 * x2))
    } else {
        x.tanh() / x
    }
}

/// `atan x / x`, `1` at `x = 0`.
pub(crate) fn atanc(x: f64) -> f64 {
    if x.abs() < 1e-2 {
        let x2 = x * x;
        1.0 - x2 / 3.0 * (1.0 - 0.6 * x2 * (1.0 - 5.0 / 7.0 * x2))
    } else {
        x.atan() / x
    }
}

/// `(u − sin u) / u²`, `0` at `u = 0`; by its Taylor series `Σ_k (−1)^k u^(2k+1) / (2k+3)!` for
/// `|u| < 1`, where the difference would cancel.
pub(crate) fn u_minus_sin_over_u2(u: f64) -> f64 {
    if u.abs() < 1.0 {
        let u2 = u * u;
        // term_k = (−1)^k u^(2k+1) / (2k+3)!
        let mut term = u / 6.0;
        let mut sum = term;
        for k in 1..12 {
            let k = k as f64;
            term *= -u2 / ((2.0 * k + 2.0) * (2.0 * k + 3.0));
            sum += term;
        }
        sum
    } else {
        (u - u.sin()) / (u * u)
    }
}

/// `((A − B e^(−2y)) / (A + B e^(−2y)), 2 e^(−y) / (A + B e^(−2y)))` from `ln A`, `ln B` and
/// `y ≥ 0`, each divided through by the larger term of its denominator: neither overflows nor
/// underflows where `A` or `B` is far below 1 or `e^(−2y)` below the smallest number. These are
/// `tanh` and `sech` of `y + ½ ln(A/B)`, the latter over `√(A B)`: the turning of a velocity held
/// at constant speed (the Chaplygin sleigh, the isokinetic thermostat).
pub(crate) fn turning(ln_a: f64, ln_b: f64, y: f64) -> (f64, f64) {
    let l = ln_a - ln_b + 2.0 * y;
    if l >= 0.0 {
        let inv = (-l).exp();
        (
            (1.0 - inv) / (1.0 + inv),
            2.0 * (-y - ln_a).exp() / (1.0 + inv),
        )
    } else {
        let rho = l.exp();
        (
            (rho - 1.0) / (rho + 1.0),
            2.0 * (y - ln_b).exp() / (rho + 1.0),
        )
    }
}

/// The Gudermannian function `gd x = 2 arctan(tanh(x/2))`, odd, bounded by `π/2`.
pub(crate) fn gd(x: f64) -> f64 {
    2.0 * (0.5 * x).tanh().atan()
}

/// Nodes and weights of the 10-point Gauss–Legendre rule on `[−1, 1]` (symmetric halves).
const GL10: [(f64, f64); 5] = [
    (0.148_874_338_981_631_2, 0.295_524_224_714_752_9),
    (0.433_395_394_129_247_2, 0.269_266_719_309_996_4),
    (0.679_409_568_299_024_4, 0.219_086_362_515_982_04),
    (0.865_063_366_688_984_5, 0.149_451_349_150_580_6),
    (0.973_906_528_517_171_7, 0.066_671_344_308_688_14),
];

fn gauss10(f: &impl Fn(f64) -> f64, a: f64, b: f64) -> f64 {
    let (c, h) = (0.5 * (a + b), 0.5 * (b - a));
    h * GL10
        .iter()
        .map(|&(x, w)| w * (f(c - h * x) + f(c + h * x)))
        .sum::<f64>()
}

/// `∫_a^b f` for a smooth `f`, by 10-point Gauss–Legendre on halves of the interval until the
/// halves agree with the whole to `tol` relative (bisection depth at most 30).
pub(crate) fn integrate(f: impl Fn(f64) -> f64, a: f64, b: f64, tol: f64) -> f64 {
    fn rec(f: &impl Fn(f64) -> f64, a: f64, b: f64, whole: f64, tol: f64, depth: u32) -> f64 {
        let m = 0.5 * (a + b);
        let (l, r) = (gauss10(f, a, m), gauss10(f, m, b));
        if depth == 0 || (l + r - whole).abs() <= tol * (l + r).abs().max(f64::MIN_POSITIVE) {
            l + r
        } else {
            rec(f, a, m, l, tol, depth - 1) + rec(f, m, b, r, tol, depth - 1)
        }
    }
    if a == b {
        return 0.0;
    }
    rec(&f, a, b, gauss10(&f, a, b), tol, 30)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cancelling_forms_match_direct_forms_away_from_zero() {
        for x in [1e-3f64, 9.9e-3, 1.01e-2, 0.3, 0.999, 1.001, 2.0] {
            // Both sides within about one ulp each.
            assert!((sinc(x) - x.sin() / x).abs() <= 4e-16);
            assert!((sinhc(x) - x.sinh() / x).abs() <= 4e-16);
            assert!((tanhc(x) - x.tanh() / x).abs() <= 4e-16);
            assert!((atanc(x) - x.atan() / x).abs() <= 4e-16);
        }
        // Near 1 the direct form loses about one digit; the series must agree to that.
        for u in [0.5f64, 0.999, 1.001] {
            let direct = (u - u.sin()) / (u * u);
            assert!((u_minus_sin_over_u2(u) - direct).abs() <= 1e-15 * direct);
        }
        // Small arguments: the two leading terms, u/6 − u³/120.
        let u = 1e-5;
        let leading = u / 6.0 - u * u * u / 120.0;
        assert!((u_minus_sin_over_u2(u) - leading).abs() <= 2e-16 * leading);
    }

    #[test]
    fn gudermannian_and_quadrature() {
        assert!((gd(1.0) - 0.865_769_483_239_658_6).abs() <= 2e-16);
        let i = integrate(|x| x.cos(), 0.0, 1.5, 1e-15);
        assert!((i - 1.5f64.sin()).abs() <= 1e-15);
        // An integrand with a sharp peak: 1/(1 + 1e4 x²) on [−1, 1] = 2 atan(100) / 100.
        let i = integrate(|x| 1.0 / (1.0 + 1e4 * x * x), -1.0, 1.0, 1e-14);
        assert!((i - 2.0 * 100f64.atan() / 100.0).abs() <= 1e-14);
    }
}
