//! The knife edge (a skate) on an inclined plane against its closed form (Neimark & Fufaev;
//! Bloch, Nonholonomic Mechanics and Control, §1.6).
//!
//! ```sh
//! cargo run --release --example knife_edge
//! ```

use std::io::{self, Write};
use std::process::ExitCode;

use chetaev::prelude::*;
use chetaev_catalogue::{compare, knife_edge, Reference};
use chetaev_suite::{finish, run_summary, sci, verdict};
use clap::Parser;

/// The knife edge on an inclined plane against its closed form (Bloch, §1.6).
#[derive(Parser)]
struct Cli {}

fn main() -> ExitCode {
    Cli::parse();
    finish(run(&mut io::stdout().lock()))
}

fn run(out: &mut impl Write) -> Result<(), Box<dyn std::error::Error>> {
    let p = knife_edge::Params::default();
    let entry = knife_edge::entry(&p)?;
    let cf = &entry.reference;
    let tol = 1e-10;
    let times: Vec<f64> = (1..=8).map(|k| 2.5 * f64::from(k)).collect();
    let options = Options::until(20.0)
        .tolerances(tol, tol)
        .output_times(times);
    let sol = solve(&entry.problem, Dop853::default(), &options)?;

    writeln!(out, "Knife edge on an inclined plane: L = ½m(ẋ²+ẏ²) + ½Iφ̇² + m g sin α x, f = ẋ sin φ − ẏ cos φ")?;
    writeln!(
        out,
        "m = {}, I = {}, g = {}, α = {:.4} rad, ω = {}; Dop853, rtol = atol = {tol:e}",
        p.m, p.inertia, p.g, p.alpha, p.omega
    )?;
    writeln!(out, "reference: {}", cf.sources()[0])?;
    writeln!(out)?;
    writeln!(
        out,
        "{:>5} {:>13} {:>13} {:>13} {:>13} {:>9} {:>13} {:>13} {:>9}",
        "t", "x", "x exact", "y", "y exact", "φ", "μ", "μ exact", "error"
    )?;
    for i in 0..sol.len() {
        let (t, q, qd, mu) = (sol.t[i], &sol.q[i], &sol.qd[i], &sol.mu[i]);
        let (exact, mu_exact) = (cf.position(t), cf.multiplier(t));
        let error = cf.error_at(t, q, qd, Some(mu))?;
        writeln!(
            out,
            "{t:>5.2} {:>13.9} {:>13.9} {:>13.9} {:>13.9} {:>9.5} {:>13.9} {:>13.9} {:>9}",
            q[0],
            exact[0],
            q[1],
            exact[1],
            q[2],
            mu[0],
            mu_exact,
            sci(error)
        )?;
    }
    writeln!(out)?;
    let error = compare(&sol, cf)?.max();
    writeln!(
        out,
        "largest |numerical − exact| over x, y, φ, q̇, μ, E, each against its scale \
         (g sin α/ω², g sin α/ω, m g sin α, ...): {:.2e}",
        error
    )?;
    writeln!(out, "{}", run_summary(&sol, ""))?;
    verdict(out, error, tol)
}
