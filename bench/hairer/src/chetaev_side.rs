//! The chetaev side: one solve with `chetaev::integrate::driver::solve_ode`.
//!
//! Everything this benchmark asks of chetaev's API is in this file (and in the two `OdeSystem`
//! implementations of `problems.rs`), so a change of `solve_ode`, `OdeOptions` or `OdeSystem`
//! is adapted here.

use chetaev::integrate::driver::{solve_ode, OdeOptions};
use chetaev::integrate::options::Output;
use chetaev::integrate::system::OdeSystem;
use chetaev::integrate::Method;

use crate::problems::Problem;

/// The work counters of one chetaev solve.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counts {
    /// Right-hand side evaluations (counted by the system, including the initial step guess).
    pub evaluations: usize,
    /// Accepted steps.
    pub accepted: usize,
    /// Rejected steps.
    pub rejected: usize,
}

/// A system that counts its own right-hand side evaluations.
pub trait Counted: OdeSystem {
    /// Evaluations so far.
    fn evaluations(&self) -> usize;
}

impl Counted for crate::problems::ArenstorfRhs {
    fn evaluations(&self) -> usize {
        self.evaluations
    }
}

impl Counted for crate::problems::ParticleRhs {
    fn evaluations(&self) -> usize {
        self.evaluations
    }
}

/// The options of every chetaev solve: `rtol`, `atol`, the final state only, the same step limit
/// as given to Hairer's codes (1 000 000), everything else at its default.
pub fn options(problem: &Problem, rtol: f64, atol: f64) -> OdeOptions {
    let mut o = OdeOptions::until(problem.t1).tolerances(rtol, atol);
    o.output = Output::Final;
    o.max_steps = 1_000_000;
    o
}

/// One solve of `problem` with `method` on the fresh system `sys`: the final state and the work,
/// or the error text when the integration did not reach `t1`.
pub fn solve<S: Counted, M: Method>(
    mut sys: S,
    method: M,
    problem: &Problem,
    options: &OdeOptions,
) -> Result<([f64; 4], Counts), String> {
    let sol =
        solve_ode(&mut sys, method, problem.t0, &problem.y0, options).map_err(|e| e.to_string())?;
    if let Some(e) = sol.error {
        return Err(e.to_string());
    }
    let last = sol
        .y
        .last()
        .ok_or_else(|| "no final state recorded".to_string())?;
    let mut y = [0.0; 4];
    if last.len() != 4 {
        return Err(format!("final state of length {}", last.len()));
    }
    y.copy_from_slice(last);
    Ok((
        y,
        Counts {
            evaluations: sys.evaluations(),
            accepted: sol.stats.accepted_steps,
            rejected: sol.stats.rejected_steps,
        },
    ))
}
