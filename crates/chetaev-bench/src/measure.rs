//! Timing by the median of repeated runs, and comparisons of work-precision curves at equal error.

use std::time::Instant;

/// How long a configuration is timed: at least `min_repeats` runs, more until `min_seconds` have
/// passed, never more than `max_repeats`. One untimed run comes first (caches, allocator).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Budget {
    /// Fewest timed runs.
    pub min_repeats: usize,
    /// Most timed runs.
    pub max_repeats: usize,
    /// Keep repeating (up to `max_repeats`) until this much time has been spent.
    pub min_seconds: f64,
}

impl Default for Budget {
    fn default() -> Self {
        Self {
            min_repeats: 5,
            max_repeats: 1000,
            min_seconds: 0.3,
        }
    }
}

/// A median wall time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Timing {
    /// Median of the timed runs, seconds.
    pub median: f64,
    /// Number of timed runs.
    pub repeats: usize,
}

/// Runs `run` once untimed, then as `budget` says, and returns the last result with the median
/// wall time. The first error ends the timing and is returned.
pub fn time_median<T, E>(
    budget: &Budget,
    mut run: impl FnMut() -> Result<T, E>,
) -> Result<(T, Timing), E> {
    let mut last = run()?;
    let mut times = Vec::with_capacity(budget.min_repeats.max(1));
    let start = Instant::now();
    while times.len() < budget.min_repeats.max(1)
        || (start.elapsed().as_secs_f64() < budget.min_seconds && times.len() < budget.max_repeats)
    {
        let t0 = Instant::now();
        last = run()?;
        times.push(t0.elapsed().as_secs_f64());
    }
    Ok((
        last,
        Timing {
            median: median(&mut times),
            repeats: times.len(),
        },
    ))
}

/// A run to be timed by [`time_interleaved`].
pub type Run<'a, E> = Box<dyn FnMut() -> Result<(), E> + 'a>;

/// Times several runs against each other: one untimed round, then rounds in which each run is
/// timed once, in turn, until every run has `min_repeats` times and the rounds have taken
/// `min_seconds` per run (at most `max_repeats` rounds). Interleaving exposes every run to the
/// same background load, so their ratio is steadier than that of runs timed one after the other.
/// The first error ends the timing and is returned.
pub fn time_interleaved<E>(budget: &Budget, runs: &mut [Run<'_, E>]) -> Result<Vec<Timing>, E> {
    for run in runs.iter_mut() {
        run()?;
    }
    let mut times: Vec<Vec<f64>> = vec![Vec::new(); runs.len()];
    let start = Instant::now();
    let wanted = budget.min_seconds * runs.len() as f64;
    let mut rounds = 0;
    while rounds < budget.min_repeats.max(1)
        || (start.elapsed().as_secs_f64() < wanted && rounds < budget.max_repeats)
    {
        for (run, t) in runs.iter_mut().zip(times.iter_mut()) {
            let t0 = Instant::now();
            run()?;
            t.push(t0.elapsed().as_secs_f64());
        }
        rounds += 1;
    }
    Ok(times
        .iter_mut()
        .map(|t| Timing {
            median: median(t),
            repeats: t.len(),
        })
        .collect())
}

/// A batch of work to be timed: `batch(n)` does `n` items and returns the seconds per item.
pub type Batch<'a> = &'a mut dyn FnMut(usize) -> f64;

/// The number of items that makes one batch of `batch` last at least `min_seconds` (doubling, or
/// more where one batch was far too short). A batch that reports no finite time ends the search
/// at its size: there is nothing to scale by.
pub fn batch_size(min_seconds: f64, batch: Batch<'_>) -> usize {
    let mut n = 1;
    loop {
        let s = batch(n) * n as f64;
        if s >= min_seconds || !s.is_finite() {
            return n;
        }
        n = (n * 2).max((n as f64 * 1.2 * min_seconds / s.max(1e-9)).ceil() as usize);
    }
}

/// The median seconds per item of each of `batches` over `rounds` rounds, timed interleaved: each
/// round runs one batch of each, in order, every batch sized once to last at least `min_seconds`.
/// For work too short to time one item at a time (a solve of microseconds, one right-hand side).
pub fn interleaved_batches(rounds: usize, min_seconds: f64, batches: &mut [Batch<'_>]) -> Vec<f64> {
    let sizes: Vec<usize> = batches
        .iter_mut()
        .map(|b| batch_size(min_seconds, &mut **b))
        .collect();
    let mut samples = vec![Vec::with_capacity(rounds); batches.len()];
    for _ in 0..rounds {
        for ((b, &n), s) in batches.iter_mut().zip(&sizes).zip(&mut samples) {
            s.push(b(n));
        }
    }
    samples.iter_mut().map(|s| median(s)).collect()
}

/// The median of `values` (the mean of the middle two for an even count); NaN when empty.
pub fn median(values: &mut [f64]) -> f64 {
    if values.is_empty() {
        return f64::NAN;
    }
    values.sort_by(f64::total_cmp);
    let n = values.len();
    if n % 2 == 1 {
        values[n / 2]
    } else {
        0.5 * (values[n / 2 - 1] + values[n / 2])
    }
}

/// The run time at which a work-precision curve reaches `error`.
///
/// `points` are `(error, seconds)` in the order of tightening tolerance (or shrinking step).
/// Between the first consecutive pair whose errors bracket `error`, `log seconds` is interpolated
/// linearly in `log error`. Points with a non-positive or non-finite error or time are left out.
/// `None` when no pair brackets `error` (the curve never reaches it, or starts below it).
pub fn time_at_error(points: &[(f64, f64)], error: f64) -> Option<f64> {
    let usable: Vec<(f64, f64)> = points
        .iter()
        .copied()
        .filter(|&(e, s)| e > 0.0 && e.is_finite() && s > 0.0 && s.is_finite())
        .map(|(e, s)| (e.ln(), s.ln()))
        .collect();
    let target = error.ln();
    for pair in usable.windows(2) {
        let ((e0, s0), (e1, s1)) = (pair[0], pair[1]);
        let (lo, hi) = if e0 <= e1 { (e0, e1) } else { (e1, e0) };
        if target < lo || target > hi {
            continue;
        }
        if e1 == e0 {
            return Some(s0.min(s1).exp());
        }
        let w = (target - e0) / (e1 - e0);
        return Some((s0 + w * (s1 - s0)).exp());
    }
    None
}

/// The ratio of the run times of two work-precision curves at the same `error`
/// ([`time_at_error`] of each); `None` where either curve does not reach it.
pub fn ratio_at_error(
    numerator: &[(f64, f64)],
    denominator: &[(f64, f64)],
    error: f64,
) -> Option<f64> {
    Some(time_at_error(numerator, error)? / time_at_error(denominator, error)?)
}

/// Least-squares slope of `log y` against `log x` over the points with both positive
/// (the growth exponent of `y` in `x`).
pub fn log_slope(points: &[(f64, f64)]) -> f64 {
    uniform_projectile::report::log_slope(points)
}

/// The processor's model name from `/proc/cpuinfo` ("unknown" where there is none), for reports.
pub fn cpu_model() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|m| m.trim().to_string())
        })
        .unwrap_or_else(|| "unknown".to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn time_at_error_interpolates_log_time_in_log_error() {
        // time ∝ error^(-1/4): between (1e-4, 1e-3) and (1e-8, 1e-2), at 1e-6 the geometric mean.
        let curve = [(1e-2, 1e-4), (1e-4, 1e-3), (1e-8, 1e-2), (1e-12, 1e-1)];
        let t = time_at_error(&curve, 1e-6).expect("bracketed");
        assert!((t / (1e-3f64 * 1e-2).sqrt() - 1.0).abs() < 1e-12, "{t}");
        assert!((time_at_error(&curve, 1e-4).expect("a point") - 1e-3).abs() < 1e-15);
        assert_eq!(time_at_error(&curve, 1e-13), None);
        assert_eq!(time_at_error(&curve, 1.0), None);
    }

    #[test]
    fn time_at_error_skips_zero_errors_and_takes_the_first_crossing() {
        let curve = [
            (1e-3, 1.0),
            (0.0, 1.5),
            (1e-5, 2.0),
            (1e-4, 3.0),
            (1e-6, 4.0),
        ];
        // Once the zero is dropped, the first pair bracketing 1e-4 is (1e-3, 1.0)–(1e-5, 2.0), not
        // the later (1e-5, 2.0)–(1e-4, 3.0).
        let t = time_at_error(&curve, 1e-4).expect("bracketed");
        assert!((t - 2f64.powf(0.5)).abs() < 1e-12, "{t}");
    }

    #[test]
    fn ratio_and_slope() {
        let a = [(1e-2, 2e-3), (1e-10, 2e-1)];
        let b = [(1e-2, 1e-3), (1e-10, 1e-1)];
        let r = ratio_at_error(&a, &b, 1e-6).expect("both reach it");
        assert!((r - 2.0).abs() < 1e-12);
        let cubic: Vec<(f64, f64)> = [2.0, 4.0, 8.0]
            .iter()
            .map(|&n: &f64| (n, n.powi(3)))
            .collect();
        assert!((log_slope(&cubic) - 3.0).abs() < 1e-12);
    }

    #[test]
    fn batches_are_sized_once_and_timed_in_rounds() {
        // Batches that report what they are told: 1 ms an item for the first, 0.1 ms for the
        // second, which needs at least 50 items to last 5 ms.
        let (mut calls_a, mut calls_b) = (Vec::new(), Vec::new());
        let mut a = |n: usize| {
            calls_a.push(n);
            1e-3
        };
        let mut b = |n: usize| {
            calls_b.push(n);
            1e-4 * (1.0 + n as f64 * 1e-6)
        };
        let t = interleaved_batches(3, 5e-3, &mut [&mut a, &mut b]);
        assert_eq!(t[0], 1e-3);
        assert!((t[1] / 1e-4 - 1.0).abs() < 1e-3, "{t:?}");
        // Sizing, then three rounds of the size found.
        let (&na, &nb) = (calls_a.last().unwrap_or(&0), calls_b.last().unwrap_or(&0));
        assert_eq!(calls_a[calls_a.len() - 3..], [na; 3]);
        assert_eq!(calls_b[calls_b.len() - 3..], [nb; 3]);
        assert!(
            na as f64 * 1e-3 >= 5e-3 && nb as f64 * 1e-4 >= 5e-3,
            "{na}, {nb}"
        );
        assert!(nb < 200, "{nb}: sized far above what was needed");
        // A batch that reports NaN ends the sizing instead of growing without end.
        assert_eq!(batch_size(5e-3, &mut |_| f64::NAN), 1);
    }

    #[test]
    fn interleaved_runs_are_timed_in_rounds() {
        let (mut a, mut b) = (0, 0);
        let budget = Budget {
            min_repeats: 3,
            max_repeats: 3,
            min_seconds: 10.0,
        };
        let timings = {
            let mut runs: Vec<Run<'_, ()>> = vec![
                Box::new(|| {
                    a += 1;
                    Ok(())
                }),
                Box::new(|| {
                    b += 1;
                    Ok(())
                }),
            ];
            time_interleaved(&budget, &mut runs).expect("no error")
        };
        // One untimed round, then three timed ones (max_repeats bounds the time budget).
        assert_eq!((a, b), (4, 4));
        assert!(timings.iter().all(|t| t.repeats == 3 && t.median >= 0.0));
    }

    #[test]
    fn median_of_even_and_odd_counts() {
        assert_eq!(median(&mut [3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&mut [4.0, 1.0, 2.0, 3.0]), 2.5);
        assert!(median(&mut []).is_nan());
    }
}
