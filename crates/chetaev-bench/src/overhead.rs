//! Paying only for what is used, measured on whole solves: no constraint against a constraint that
//! does nothing, and diagnostics off against on. Each pair is timed interleaved, so that both see
//! the same background load.

use chetaev::model::Fixed;
use chetaev::prelude::*;
use chetaev_catalogue::benchmarks::SteadyHorizontal;
use uniform_projectile::closed_form::{table, Params};
use uniform_projectile::model::{classical_problem, uniform_problem};

use crate::measure::{time_interleaved, Budget, Run};

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

/// The classical projectile of `p` through the constrained path: [`SteadyHorizontal`], the same
/// Lagrangian as `classical_problem(p)` with the constraint `ẋ − v0 = 0`, from the same state.
pub fn steady_horizontal_problem(
    p: &Params,
) -> Result<Problem<Fixed<SteadyHorizontal, 2, 1>>, chetaev_catalogue::Error> {
    SteadyHorizontal {
        m: p.m,
        g: p.g,
        v0: p.v0,
    }
    .problem(p.h0)
}

/// The largest of `|a_i − b_i|` over the components of two slices.
fn max_difference(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
}

/// The largest of `|a_i|`.
fn max_abs(a: &[f64]) -> f64 {
    a.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

/// The largest difference of the end states `(q, q̇)` of `a` and `b`, relative to the largest
/// component of `a`'s; NaN when either recorded nothing.
fn end_difference(a: &Solution, b: &Solution) -> f64 {
    match (a.last(), b.last()) {
        (Some((_, qa, va)), Some((_, qb, vb))) => {
            let scale = max_abs(qa).max(max_abs(va)).max(f64::MIN_POSITIVE);
            max_difference(qa, qb).max(max_difference(va, vb)) / scale
        }
        _ => f64::NAN,
    }
}

/// The comparison `what` of two ways to the same motion: each solved once for its statistics and
/// end state (a failed solve is the error), then both timed interleaved ([`time_interleaved`]).
fn compare_runs(
    what: &str,
    setting: String,
    budget: &Budget,
    mut lean: impl FnMut() -> Result<Solution, chetaev::Error>,
    mut costly: impl FnMut() -> Result<Solution, chetaev::Error>,
) -> Result<Comparison, chetaev::Error> {
    let (a, b) = (lean()?.ok()?, costly()?.ok()?);
    let mut runs: Vec<Run<'_, chetaev::Error>> = vec![
        Box::new(|| lean().map(|_| ())),
        Box::new(|| costly().map(|_| ())),
    ];
    let t = time_interleaved(budget, &mut runs)?;
    Ok(Comparison {
        what: what.to_string(),
        setting,
        lean_seconds: t[0].median,
        costly_seconds: t[1].median,
        lean_rhs: a.stats.rhs_evaluations,
        costly_rhs: b.stats.rhs_evaluations,
        lean_output: a.stats.output_evaluations,
        costly_output: b.stats.output_evaluations,
        end_difference: end_difference(&a, &b),
    })
}

/// The classical motion of the paper's particle to its impact, once as `Problem::unconstrained`
/// (`K = 0`) and once with the constraint `ẋ − v0 = 0`, which it satisfies anyway
/// ([`steady_horizontal_problem`]); diagnostics off.
pub fn constraint_overhead<Me: Method + Copy>(
    p: &Params,
    method: Me,
    tol: f64,
    budget: &Budget,
) -> Result<Comparison, chetaev_catalogue::Error> {
    let t_end = table(p).classical.t_impact;
    let options = Options::until(t_end)
        .tolerances(tol, tol)
        .output_final()
        .record(Record::State);
    let free = classical_problem(p)?;
    let held = steady_horizontal_problem(p)?;
    Ok(compare_runs(
        "K = 0 (Problem::unconstrained) → K = 1 (ẋ − v0 = 0, same motion)",
        format!("{} at {tol:e}", method.name()),
        budget,
        || solve(&free, method, &options),
        || solve(&held, method, &options),
    )?)
}

/// The paper's uniform motion to its impact time with diagnostics off (`Record::State`,
/// output at the end only) and on (`Record::Energy`, output at every step).
pub fn diagnostics_overhead<Me: Method + Copy>(
    p: &Params,
    method: Me,
    tol: f64,
    budget: &Budget,
) -> Result<Comparison, chetaev_catalogue::Error> {
    let t_end = table(p).uniform.t_impact;
    let base = Options::until(t_end).tolerances(tol, tol);
    let off = base.clone().output_final().record(Record::State);
    let on = base.record(Record::Energy);
    let problem = uniform_problem(p)?;
    Ok(compare_runs(
        "diagnostics off (Record::State, output_final) → on (Record::Energy, every step)",
        format!("{} at {tol:e}", method.name()),
        budget,
        || solve(&problem, method, &off),
        || solve(&problem, method, &on),
    )?)
}
