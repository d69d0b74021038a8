//! One work-precision comparison: a problem, a chetaev method and the Hairer code of the same
//! name, over a list of tolerances, timed interleaved.

use std::hint::black_box;
use std::time::Duration;

use chetaev::integrate::{Dop853, Dopri5, Method};

use crate::chetaev_side::{self, Counted};
use crate::equal_error::{geometric_mean, time_at_error};
use crate::hairer::{self, Code};
use crate::problems::{ArenstorfRhs, ParticleRhs, Problem, ProblemId};
use crate::timing::{interleaved, Estimator, Paired};

/// The method pair: chetaev's `Dop853`/`Dopri5` against Hairer's DOP853/DOPRI5.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pair {
    /// `Dop853::default()` against DOP853.
    Dop853,
    /// `Dopri5::default()` against DOPRI5.
    Dopri5,
}

impl Pair {
    /// Hairer's code of the pair.
    pub fn code(self) -> Code {
        match self {
            Pair::Dop853 => Code::Dop853,
            Pair::Dopri5 => Code::Dopri5,
        }
    }
}

/// What one code did at one tolerance.
#[derive(Clone, Debug, PartialEq)]
pub struct Outcome {
    /// The final state.
    pub y: [f64; 4],
    /// `|y − reference|` (Euclidean).
    pub error: f64,
    /// Right-hand side evaluations.
    pub evaluations: usize,
    /// Accepted steps.
    pub accepted: usize,
    /// Rejected steps (Hairer's count leaves out rejections of the first step).
    pub rejected: usize,
}

/// One tolerance of a comparison.
#[derive(Clone, Debug, PartialEq)]
pub struct Point {
    /// `rtol = atol`.
    pub tol: f64,
    /// chetaev's result, or why it failed.
    pub chetaev: Result<Outcome, String>,
    /// Hairer's result, or why it failed.
    pub hairer: Result<Outcome, String>,
    /// Times (A = chetaev, B = Hairer), when both succeeded.
    pub timing: Option<Paired>,
}

/// A whole comparison: the points, and the ratio time(chetaev) / time(Hairer) at equal error,
/// read both ways.
#[derive(Clone, Debug, PartialEq)]
pub struct Comparison {
    /// Problem name.
    pub problem: &'static str,
    /// The method pair.
    pub pair: Pair,
    /// One point per tolerance.
    pub points: Vec<Point>,
    /// Per point: chetaev's time over Hairer's time interpolated at chetaev's error.
    pub ratio_at_chetaev_error: Vec<Option<f64>>,
    /// Per point: chetaev's time interpolated at Hairer's error over Hairer's time.
    pub ratio_at_hairer_error: Vec<Option<f64>>,
}

impl Comparison {
    fn all_ratios(&self) -> impl Iterator<Item = f64> + '_ {
        self.ratio_at_chetaev_error
            .iter()
            .chain(&self.ratio_at_hairer_error)
            .flatten()
            .copied()
    }

    /// The geometric mean of the equal-error ratios, both readings together.
    pub fn geometric_mean(&self) -> Option<f64> {
        geometric_mean(&self.all_ratios().map(Some).collect::<Vec<_>>())
    }

    /// The median of the equal-error ratios, both readings together.
    pub fn median_ratio(&self) -> Option<f64> {
        let mut r: Vec<f64> = self.all_ratios().collect();
        (!r.is_empty()).then(|| crate::timing::median(&mut r))
    }

    /// The largest equal-error ratio.
    pub fn max_ratio(&self) -> Option<f64> {
        self.all_ratios().reduce(f64::max)
    }

    /// The smallest equal-error ratio.
    pub fn min_ratio(&self) -> Option<f64> {
        self.all_ratios().reduce(f64::min)
    }

    /// How many equal-error ratios there are (both readings).
    pub fn ratio_count(&self) -> usize {
        self.all_ratios().count()
    }
}

/// How long and how often to time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Budget {
    /// Interleaved rounds per tolerance.
    pub rounds: usize,
    /// Shortest batch.
    pub min_batch: Duration,
    /// How the rounds are summarised.
    pub estimator: Estimator,
}

/// One chetaev solve as an [`Outcome`].
fn chetaev_once<S: Counted, M: Method + Copy>(
    make: &impl Fn() -> S,
    method: M,
    problem: &Problem,
    tol: f64,
) -> Result<Outcome, String> {
    let options = chetaev_side::options(problem, tol, tol);
    let (y, c) = chetaev_side::solve(make(), method, problem, &options)?;
    Ok(Outcome {
        y,
        error: problem.error(&y),
        evaluations: c.evaluations,
        accepted: c.accepted,
        rejected: c.rejected,
    })
}

/// One Hairer solve as an [`Outcome`].
pub fn hairer_once(code: Code, problem: &Problem, tol: f64) -> Result<Outcome, String> {
    let (y, c) = hairer::solve(code, problem, tol, tol)
        .map_err(|idid| format!("{} returned IDID = {idid}", code.name()))?;
    Ok(Outcome {
        y,
        error: problem.error(&y),
        evaluations: c.nfcn,
        accepted: c.naccpt,
        rejected: c.nrejct,
    })
}

fn point<S: Counted, M: Method + Copy>(
    make: &impl Fn() -> S,
    method: M,
    code: Code,
    problem: &Problem,
    tol: f64,
    budget: Budget,
) -> Point {
    let chetaev = chetaev_once(make, method, problem, tol);
    let hairer = hairer_once(code, problem, tol);
    let timing = (chetaev.is_ok() && hairer.is_ok()).then(|| {
        let options = chetaev_side::options(problem, tol, tol);
        let mut a = || {
            let r = chetaev_side::solve(make(), method, problem, &options);
            black_box(r.ok());
        };
        let mut b = || {
            black_box(hairer::solve(code, problem, tol, tol).ok());
        };
        interleaved(
            budget.rounds,
            budget.min_batch,
            budget.estimator,
            &mut a,
            &mut b,
        )
    });
    Point {
        tol,
        chetaev,
        hairer,
        timing,
    }
}

fn points_for<S: Counted, M: Method + Copy>(
    make: impl Fn() -> S,
    method: M,
    code: Code,
    problem: &Problem,
    tolerances: &[f64],
    budget: Budget,
    progress: &mut dyn FnMut(&Point),
) -> Vec<Point> {
    tolerances
        .iter()
        .map(|&tol| {
            let p = point(&make, method, code, problem, tol, budget);
            progress(&p);
            p
        })
        .collect()
}

/// Runs one comparison over `tolerances`; `progress` sees each point as it is done.
pub fn compare(
    problem: &Problem,
    pair: Pair,
    tolerances: &[f64],
    budget: Budget,
    progress: &mut dyn FnMut(&Point),
) -> Comparison {
    let code = pair.code();
    let points = match (problem.id, pair) {
        (ProblemId::Arenstorf, Pair::Dop853) => points_for(
            || ArenstorfRhs::new(problem),
            Dop853::default(),
            code,
            problem,
            tolerances,
            budget,
            progress,
        ),
        (ProblemId::Arenstorf, Pair::Dopri5) => points_for(
            || ArenstorfRhs::new(problem),
            Dopri5::default(),
            code,
            problem,
            tolerances,
            budget,
            progress,
        ),
        (ProblemId::Particle, Pair::Dop853) => points_for(
            || ParticleRhs::new(problem),
            Dop853::default(),
            code,
            problem,
            tolerances,
            budget,
            progress,
        ),
        (ProblemId::Particle, Pair::Dopri5) => points_for(
            || ParticleRhs::new(problem),
            Dopri5::default(),
            code,
            problem,
            tolerances,
            budget,
            progress,
        ),
    };
    let chetaev_curve: Vec<Option<(f64, f64)>> = points
        .iter()
        .map(|p| match (&p.chetaev, &p.timing) {
            (Ok(o), Some(t)) => Some((o.error, t.a)),
            _ => None,
        })
        .collect();
    let hairer_curve: Vec<Option<(f64, f64)>> = points
        .iter()
        .map(|p| match (&p.hairer, &p.timing) {
            (Ok(o), Some(t)) => Some((o.error, t.b)),
            _ => None,
        })
        .collect();
    let all = |c: &[Option<(f64, f64)>]| c.iter().flatten().copied().collect::<Vec<_>>();
    let (all_c, all_h) = (all(&chetaev_curve), all(&hairer_curve));
    let ratio_at_chetaev_error = chetaev_curve
        .iter()
        .map(|c| c.and_then(|(e, t)| time_at_error(&all_h, e).map(|th| t / th)))
        .collect();
    let ratio_at_hairer_error = hairer_curve
        .iter()
        .map(|h| h.and_then(|(e, t)| time_at_error(&all_c, e).map(|tc| tc / t)))
        .collect();
    Comparison {
        problem: problem.name,
        pair,
        points,
        ratio_at_chetaev_error,
        ratio_at_hairer_error,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::problems::{arenstorf, particle};

    /// Both codes at `rtol = atol = 1e-12` reach the reference (the bounds allow for the
    /// Arenstorf orbit's amplification of local errors, about 1e5 at this tolerance), with step
    /// counts within 15% of each other: the step control agrees.
    #[test]
    fn both_codes_reach_the_reference_with_similar_steps() {
        let tol = 1e-12;
        for (p, bound) in [(arenstorf(), 1e-5), (particle(), 1e-9)] {
            for pair in [Pair::Dop853, Pair::Dopri5] {
                let c = match (p.id, pair) {
                    (ProblemId::Arenstorf, Pair::Dop853) => {
                        chetaev_once(&|| ArenstorfRhs::new(&p), Dop853::default(), &p, tol)
                    }
                    (ProblemId::Arenstorf, Pair::Dopri5) => {
                        chetaev_once(&|| ArenstorfRhs::new(&p), Dopri5::default(), &p, tol)
                    }
                    (ProblemId::Particle, Pair::Dop853) => {
                        chetaev_once(&|| ParticleRhs::new(&p), Dop853::default(), &p, tol)
                    }
                    (ProblemId::Particle, Pair::Dopri5) => {
                        chetaev_once(&|| ParticleRhs::new(&p), Dopri5::default(), &p, tol)
                    }
                };
                let c = c.unwrap_or_else(|e| panic!("chetaev {pair:?} on {}: {e}", p.name));
                let h = hairer_once(pair.code(), &p, tol)
                    .unwrap_or_else(|e| panic!("Hairer {pair:?} on {}: {e}", p.name));
                assert!(
                    c.error < bound,
                    "{} {pair:?}: chetaev error {}",
                    p.name,
                    c.error
                );
                assert!(
                    h.error < bound,
                    "{} {pair:?}: Hairer error {}",
                    p.name,
                    h.error
                );
                let (a, b) = (c.accepted as f64, h.accepted as f64);
                assert!(
                    (a / b - 1.0).abs() < 0.15,
                    "{} {pair:?}: accepted steps {a} vs {b}",
                    p.name
                );
                // Evaluations per step: 12 (DOP853, FSAL stage shared) or 6 (DOPRI5), plus setup.
                assert!(c.evaluations > c.accepted && h.evaluations > h.accepted);
            }
        }
    }
}
