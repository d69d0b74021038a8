//! Comparison at equal error: the time one code needs for the error another code reached.
//!
//! A work-precision curve is the set of points `(error, time)` over the tolerances. The time at a
//! given error is interpolated linearly in `(log error, log time)` between the two points of the
//! curve whose errors bracket it; outside the curve's range of errors there is no value (no
//! extrapolation).

/// The time at `error` on the curve `points = [(error, time)]`, or `None` when `error` is outside
/// the range of the curve's errors (or not positive). Points with a non-positive or non-finite
/// error or time are ignored.
pub fn time_at_error(points: &[(f64, f64)], error: f64) -> Option<f64> {
    if !(error.is_finite() && error > 0.0) {
        return None;
    }
    let mut p: Vec<(f64, f64)> = points
        .iter()
        .copied()
        .filter(|&(e, t)| e.is_finite() && e > 0.0 && t.is_finite() && t > 0.0)
        .map(|(e, t)| (e.ln(), t.ln()))
        .collect();
    p.sort_by(|a, b| a.0.total_cmp(&b.0));
    let x = error.ln();
    for w in p.windows(2) {
        let ((x0, y0), (x1, y1)) = (w[0], w[1]);
        if x0 <= x && x <= x1 {
            let y = if x1 > x0 {
                y0 + (y1 - y0) * (x - x0) / (x1 - x0)
            } else {
                0.5 * (y0 + y1)
            };
            return Some(y.exp());
        }
    }
    match p.as_slice() {
        [(x0, y0)] if *x0 == x => Some(y0.exp()),
        _ => None,
    }
}

/// The geometric mean of the values that are present; `None` if there are none.
pub fn geometric_mean(values: &[Option<f64>]) -> Option<f64> {
    let logs: Vec<f64> = values
        .iter()
        .flatten()
        .filter(|v| v.is_finite() && **v > 0.0)
        .map(|v| v.ln())
        .collect();
    (!logs.is_empty()).then(|| (logs.iter().sum::<f64>() / logs.len() as f64).exp())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolates_a_power_law_exactly() {
        // time = error^(-1/8): a straight line in log-log.
        let curve: Vec<(f64, f64)> = (3..=13)
            .map(|k| {
                let e = 10f64.powi(-k);
                (e, e.powf(-0.125))
            })
            .collect();
        for e in [3e-5, 1e-9, 7.7e-12] {
            let t = time_at_error(&curve, e).expect("inside the range");
            assert!((t / e.powf(-0.125) - 1.0).abs() < 1e-12);
        }
    }

    #[test]
    fn no_extrapolation() {
        let curve = [(1e-3, 1.0), (1e-6, 2.0)];
        assert_eq!(time_at_error(&curve, 1e-2), None);
        assert_eq!(time_at_error(&curve, 1e-7), None);
        assert_eq!(time_at_error(&curve, 0.0), None);
        assert_eq!(time_at_error(&curve, 1e-3), Some(1.0));
    }

    #[test]
    fn unordered_points_are_sorted_by_error() {
        let curve = [(1e-6, 4.0), (1e-2, 1.0), (1e-4, 2.0)];
        let t = time_at_error(&curve, 1e-5).expect("inside");
        assert!((t - 8f64.sqrt()).abs() < 1e-12);
    }

    #[test]
    fn equal_curves_give_ratio_one_and_a_slower_code_its_factor() {
        let b = [(1e-3, 1.0), (1e-5, 2.0), (1e-7, 4.0)];
        let r: Vec<Option<f64>> = b
            .iter()
            .map(|&(e, t)| time_at_error(&b, e).map(|tb| 1.25 * t / tb))
            .collect();
        assert!(r.iter().all(|x| (x.expect("inside") - 1.25).abs() < 1e-12));
        assert!((geometric_mean(&r).expect("some") - 1.25).abs() < 1e-12);
        assert_eq!(geometric_mean(&[None]), None);
    }
}
