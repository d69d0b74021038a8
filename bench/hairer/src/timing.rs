//! Interleaved timing of two codes: calibrate a batch per code, then alternate batches
//! (A, B, B, A, A, B, ...) so both see the same background load; report the time per solve.

use std::time::{Duration, Instant};

/// How the rounds' times per solve are summarised.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Estimator {
    /// The median over rounds; the ratio is the median of the per-round ratios.
    Median,
    /// The minimum over rounds (the time of an undisturbed batch); the ratio is the ratio of the
    /// minima. Robust on a machine whose load comes and goes, where the times are bimodal.
    Min,
}

/// The times per solve, seconds, and what was timed.
#[derive(Clone, Debug, PartialEq)]
pub struct Paired {
    /// A's time per solve, as the estimator says.
    pub a: f64,
    /// B's time per solve, as the estimator says.
    pub b: f64,
    /// A's time over B's, as the estimator says.
    pub ratio: f64,
    /// The interquartile range of the per-round ratios A/B: how far one round's ratio can be
    /// trusted (a quiet machine gives a few hundredths).
    pub ratio_iqr: f64,
    /// Solves per batch of A.
    pub batch_a: usize,
    /// Solves per batch of B.
    pub batch_b: usize,
    /// Rounds (one batch of each per round).
    pub rounds: usize,
    /// A's time per solve in each round, in the order timed.
    pub samples_a: Vec<f64>,
    /// B's time per solve in each round, in the order timed.
    pub samples_b: Vec<f64>,
}

/// Seconds per solve of one batch of `n` solves.
fn batch(n: usize, run: &mut dyn FnMut()) -> f64 {
    let start = Instant::now();
    for _ in 0..n {
        run();
    }
    start.elapsed().as_secs_f64() / n as f64
}

/// Solves per batch so that a batch takes at least `min_batch`: one warm-up solve, then the
/// solve is timed in growing batches until one reaches a tenth of `min_batch`.
fn calibrate(min_batch: Duration, run: &mut dyn FnMut()) -> usize {
    run();
    let target = min_batch.as_secs_f64();
    let mut n = 1usize;
    loop {
        let per = batch(n, run);
        if per * n as f64 >= 0.1 * target || n >= 1 << 20 {
            return ((target / per.max(1e-9)).ceil() as usize).clamp(1, 1 << 24);
        }
        n *= 4;
    }
}

/// The median of `v` (the mean of the two middle values for an even length); NaN when empty.
pub fn median(v: &mut [f64]) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    let m = v.len() / 2;
    if v.len() % 2 == 1 {
        v[m]
    } else {
        0.5 * (v[m - 1] + v[m])
    }
}

/// The `q`-quantile of `v` (linear between order statistics); NaN when empty.
pub fn quantile(v: &mut [f64], q: f64) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    let x = q.clamp(0.0, 1.0) * (v.len() - 1) as f64;
    let (i, f) = (x.floor() as usize, x.fract());
    if i + 1 < v.len() {
        v[i] + f * (v[i + 1] - v[i])
    } else {
        v[i]
    }
}

/// Times `a` against `b`: `rounds` rounds, each one batch of each (at least `min_batch` long),
/// the order alternating from round to round, summarised by `estimator`.
pub fn interleaved(
    rounds: usize,
    min_batch: Duration,
    estimator: Estimator,
    a: &mut dyn FnMut(),
    b: &mut dyn FnMut(),
) -> Paired {
    let batch_a = calibrate(min_batch, a);
    let batch_b = calibrate(min_batch, b);
    let rounds = rounds.max(1);
    let (mut ta, mut tb, mut r) = (Vec::new(), Vec::new(), Vec::new());
    for round in 0..rounds {
        let (x, y) = if round % 2 == 0 {
            let x = batch(batch_a, a);
            (x, batch(batch_b, b))
        } else {
            let y = batch(batch_b, b);
            (batch(batch_a, a), y)
        };
        ta.push(x);
        tb.push(y);
        r.push(x / y);
    }
    let (samples_a, samples_b) = (ta.clone(), tb.clone());
    let ratio_iqr = {
        let mut r = r.clone();
        quantile(&mut r, 0.75) - quantile(&mut r, 0.25)
    };
    let (a, b, ratio) = match estimator {
        Estimator::Median => (median(&mut ta), median(&mut tb), median(&mut r)),
        Estimator::Min => {
            let min = |v: &[f64]| v.iter().copied().fold(f64::INFINITY, f64::min);
            let (a, b) = (min(&ta), min(&tb));
            (a, b, a / b)
        }
    };
    Paired {
        a,
        b,
        ratio,
        ratio_iqr,
        samples_a,
        samples_b,
        batch_a,
        batch_b,
        rounds,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_of_odd_and_even_lengths() {
        assert_eq!(median(&mut [3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&mut [4.0, 1.0, 3.0, 2.0]), 2.5);
        assert!(median(&mut []).is_nan());
    }

    #[test]
    fn quantiles_interpolate_between_order_statistics() {
        let mut v = [5.0, 1.0, 3.0, 2.0, 4.0];
        assert_eq!(quantile(&mut v, 0.25), 2.0);
        assert_eq!(quantile(&mut v, 0.5), 3.0);
        assert_eq!(quantile(&mut v, 1.0), 5.0);
        assert_eq!(quantile(&mut [1.0, 2.0], 0.25), 1.25);
        assert!(quantile(&mut [], 0.5).is_nan());
    }
}
