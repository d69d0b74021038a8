//! Drift off the constraint over a long run, with and without projection.
//!
//! The reduced equations keep only df/dt = 0, so the constraint residual f = |q̇|² − v0² drifts
//! with the integration error. This prints |f|/v0² every 1000 time units over 10^4 units of the
//! paper's motion (which keeps falling below y = 0), for fixed-step Rk4 (h = 0.05) and Rodas4,
//! each without and with `Options::project`.
//!
//! Run: `cargo run --release --example drift`

use std::io::{self, Write};
use std::process::ExitCode;

use chetaev::integrate::system::Stats;
use chetaev::prelude::*;
use chetaev_suite::{finish, sci};
use clap::Parser;
use uniform_projectile::closed_form::Params;
use uniform_projectile::model::{uniform_problem, UniformProblem};

fn residuals<Me: Method>(
    problem: &UniformProblem,
    method: Me,
    options: &Options,
) -> Result<(Vec<f64>, Stats), Error> {
    let sol = solve(problem, method, options)?.ok()?;
    Ok((sol.residual.iter().map(|f| f[0].abs()).collect(), sol.stats))
}

/// Drift off the constraint over 10^4 time units of the paper's motion, with and without projection.
#[derive(Parser)]
struct Cli {}

fn main() -> ExitCode {
    Cli::parse();
    finish(run(&mut io::stdout().lock()))
}

fn run(out: &mut impl Write) -> Result<(), Box<dyn std::error::Error>> {
    let params = Params::PAPER;
    let problem = uniform_problem(&params)?;
    let times: Vec<f64> = (1..=10).map(|k| 1e3 * f64::from(k)).collect();
    let base = Options::until(1e4)
        .record(Record::Dynamics)
        .output_times(times.clone());
    let tight = base.clone().tolerances(1e-10, 1e-10);
    // This constraint is well conditioned: hold it at 1e-14 relative (the default is 1e-12).
    let strict = Projection {
        tol: 1e-14,
        ..Projection::default()
    };
    let runs = [
        ("Rk4 h=0.05", residuals(&problem, Rk4::new(0.05), &base)?),
        (
            "Rk4 h=0.05 + projection",
            residuals(&problem, Rk4::new(0.05), &base.clone().project(strict))?,
        ),
        ("Rodas4 1e-10", residuals(&problem, Rodas4, &tight)?),
        (
            "Rodas4 1e-10 + projection",
            residuals(&problem, Rodas4, &tight.clone().project(strict))?,
        ),
    ];
    let scale = params.v0 * params.v0;
    write!(out, "{:>8}", "t")?;
    for (name, _) in &runs {
        write!(out, " {name:>26}")?;
    }
    writeln!(out)?;
    for (i, t) in std::iter::once(0.0)
        .chain(times.iter().copied())
        .enumerate()
    {
        write!(out, "{t:>8.0}")?;
        for (_, (r, _)) in &runs {
            write!(out, " {:>26}", sci(r[i] / scale))?;
        }
        writeln!(out)?;
    }
    writeln!(out, "\n|f|/v0² at each time. Work:")?;
    for (name, (_, s)) in &runs {
        writeln!(
        out,
            "  {name:<26} steps {:>7}, RHS {:>8}, Jacobians {:>5}, projections {:>7}, Newton iterations {:>5}",
            s.accepted_steps, s.rhs_evaluations, s.jacobian_evaluations, s.projections, s.projection_iterations
        )?;
    }
    Ok(())
}
