//! Shared helpers of the verification tests and example programs.

/// Relative difference `|a − b| / max(|b|, tiny)`.
pub fn rel_err(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(f64::MIN_POSITIVE)
}

/// Euclidean norm of a vector given as a slice.
pub fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// Euclidean distance `|a − b|` of two vectors of the same length.
pub fn distance(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len(), "vectors of different lengths");
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y) * (x - y))
        .sum::<f64>()
        .sqrt()
}

/// Observed order of convergence from errors at step sizes `h` and `h/ratio`.
pub fn observed_order(err_coarse: f64, err_fine: f64, ratio: f64) -> f64 {
    (err_coarse / err_fine).ln() / ratio.ln()
}

/// The README's code, compiled and run as a doctest.
#[cfg(doctest)]
#[doc = include_str!("../../README.md")]
pub struct ReadmeDoctests;

// The guides of docs/ are compiled and run as doctests of `chetaev` (its module `guides`).
