//! Paying only for what is used, measured on whole solves: no constraint against a constraint that
//! does nothing, and diagnostics off against on. Each pair is timed interleaved, so that both see
//! the same background load.

use chetaev::integrate::Method;
use chetaev::prelude::*;
use uniform_projectile::closed_form::{table, Params};
use uniform_projectile::model::{classical_problem, uniform_problem};

use crate::measure::{time_interleaved, Budget, Run, Timing};
use crate::models::steady_horizontal_problem;

/// Two ways to run the same motion, timed.
#[derive(Clone, Debug, PartialEq)]
pub struct Comparison {
    /// What is compared.
    pub what: String,
    /// The method and tolerance.
    pub setting: String,
    /// Median time of the lean way, seconds.
    pub lean_seconds: f64,
    /// Median time of the costly way, seconds.
    pub costly_seconds: f64,
    /// Right-hand sides of the lean way.
    pub lean_rhs: usize,
    /// Right-hand sides of the costly way.
    pub costly_rhs: usize,
    /// Evaluations for diagnostics of the lean way.
    pub lean_output: usize,
    /// Evaluations for diagnostics of the costly way.
    pub costly_output: usize,
    /// Largest difference of the end states, relative to the largest component.
    pub end_difference: f64,
}

impl Comparison {
    /// `costly / lean` run time.
    pub fn ratio(&self) -> f64 {
        self.costly_seconds / self.lean_seconds
    }

    /// `costly / lean` time per right-hand side.
    pub fn ratio_per_rhs(&self) -> f64 {
        (self.costly_seconds / self.costly_rhs as f64) / (self.lean_seconds / self.lean_rhs as f64)
    }
}

fn end_difference<const N: usize, const K1: usize, const K2: usize>(
    a: &Solution<N, K1>,
    b: &Solution<N, K2>,
) -> f64 {
    match (a.last(), b.last()) {
        (Some((_, qa, va)), Some((_, qb, vb))) => {
            let scale = qa.abs().max().max(va.abs().max()).max(f64::MIN_POSITIVE);
            ((qa - qb).abs().max()).max((va - vb).abs().max()) / scale
        }
        _ => f64::NAN,
    }
}

/// Two runs timed interleaved ([`time_interleaved`]).
fn time_pair<A, B>(
    budget: &Budget,
    mut lean: impl FnMut() -> Result<A, chetaev::Error>,
    mut costly: impl FnMut() -> Result<B, chetaev::Error>,
) -> Result<[Timing; 2], chetaev::Error> {
    let mut runs: Vec<Run<'_, chetaev::Error>> = vec![
        Box::new(|| lean().map(|_| ())),
        Box::new(|| costly().map(|_| ())),
    ];
    let t = time_interleaved(budget, &mut runs)?;
    Ok([t[0], t[1]])
}

fn failed<const N: usize, const K: usize>(sol: &Solution<N, K>) -> Result<(), chetaev::Error> {
    match sol.error() {
        Some(e) => Err(e.clone()),
        None => Ok(()),
    }
}

/// The classical motion of the paper's particle to its impact, once as `Problem::unconstrained`
/// (`K = 0`) and once with the constraint `ẋ − v0 = 0`, which it satisfies anyway
/// ([`SteadyHorizontal`](crate::models::SteadyHorizontal)); diagnostics off.
pub fn constraint_overhead<Me: Method + Copy>(
    p: &Params,
    method: Me,
    tol: f64,
    budget: &Budget,
) -> Result<Comparison, chetaev::Error> {
    let t_end = table(p).classical.t_impact;
    let options = Options::until(t_end)
        .tolerances(tol, tol)
        .output_final()
        .record(Record::State);
    let free = classical_problem(p)?;
    let held = steady_horizontal_problem(p)?;
    let (a, b) = (
        solve(&free, method, &options)?,
        solve(&held, method, &options)?,
    );
    let [ta, tb] = time_pair(
        budget,
        || solve(&free, method, &options),
        || solve(&held, method, &options),
    )?;
    failed(&a)?;
    failed(&b)?;
    Ok(Comparison {
        what: "K = 0 (Problem::unconstrained) → K = 1 (ẋ − v0 = 0, same motion)".to_string(),
        setting: format!("{} at {tol:.0e}", method.name()),
        lean_seconds: ta.median,
        costly_seconds: tb.median,
        lean_rhs: a.stats.rhs_evaluations,
        costly_rhs: b.stats.rhs_evaluations,
        lean_output: a.stats.output_evaluations,
        costly_output: b.stats.output_evaluations,
        end_difference: end_difference(&a, &b),
    })
}

/// The paper's uniform motion to its impact time with diagnostics off (`Record::State`,
/// output at the end only) and on (`Record::Energy`, output at every step).
pub fn diagnostics_overhead<Me: Method + Copy>(
    p: &Params,
    method: Me,
    tol: f64,
    budget: &Budget,
) -> Result<Comparison, chetaev::Error> {
    let t_end = table(p).uniform.t_impact;
    let base = Options::until(t_end).tolerances(tol, tol);
    let off = base.clone().output_final().record(Record::State);
    let on = base.record(Record::Energy);
    let problem = uniform_problem(p)?;
    let (a, b) = (
        solve(&problem, method, &off)?,
        solve(&problem, method, &on)?,
    );
    let [ta, tb] = time_pair(
        budget,
        || solve(&problem, method, &off),
        || solve(&problem, method, &on),
    )?;
    failed(&a)?;
    failed(&b)?;
    Ok(Comparison {
        what: "diagnostics off (Record::State, output_final) → on (Record::Energy, every step)"
            .to_string(),
        setting: format!("{} at {tol:.0e}", method.name()),
        lean_seconds: ta.median,
        costly_seconds: tb.median,
        lean_rhs: a.stats.rhs_evaluations,
        costly_rhs: b.stats.rhs_evaluations,
        lean_output: a.stats.output_evaluations,
        costly_output: b.stats.output_evaluations,
        end_difference: end_difference(&a, &b),
    })
}
