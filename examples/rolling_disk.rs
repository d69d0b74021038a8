//! The vertical rolling disk against its closed form (Bloch, Nonholonomic Mechanics and Control,
//! §1.4): uniform rolling and turning, the contact point on a circle of radius `R ω / Ω`.
//!
//! ```sh
//! cargo run --release --example rolling_disk
//! ```

use std::io::{self, Write};
use std::process::ExitCode;

use chetaev::prelude::*;
use chetaev_catalogue::{compare, rolling_disk, Reference};
use chetaev_suite::{finish, run_summary, sci, verdict};
use clap::Parser;

/// The vertical rolling disk against its closed form (Bloch, §1.4).
#[derive(Parser)]
struct Cli {}

fn main() -> ExitCode {
    Cli::parse();
    finish(run(&mut io::stdout().lock()))
}

fn run(out: &mut impl Write) -> Result<(), Box<dyn std::error::Error>> {
    let p = rolling_disk::Params::default();
    let entry = rolling_disk::entry(&p)?;
    let cf = &entry.reference;
    let tol = 1e-10;
    let times: Vec<f64> = (1..=8).map(|k| 0.8 * f64::from(k)).collect();
    let options = Options::until(6.4).tolerances(tol, tol).output_times(times);
    let sol = solve(&entry.problem, Dop853::default(), &options)?;

    writeln!(
        out,
        "Vertical rolling disk: L = ½m(ẋ²+ẏ²) + ½Iθ̇² + ½Jφ̇², f = (ẋ − R cos φ θ̇, ẏ − R sin φ θ̇)"
    )?;
    writeln!(
        out,
        "m = {}, R = {}, I = {}, J = {}, ω = θ̇ = {}, Ω = φ̇ = {}; Dop853, rtol = atol = {tol:e}",
        p.m, p.radius, p.i_roll, p.i_spin, p.omega, p.spin
    )?;
    if let Some((centre, rho)) = cf.circle() {
        writeln!(
        out,
            "the contact point runs on the circle of centre ({}, {}) and radius ρ = R ω / Ω = {rho}",
            centre[0], centre[1]
        )?;
    }
    writeln!(out, "reference: {}", cf.sources()[0])?;
    writeln!(out)?;
    writeln!(
        out,
        "{:>5} {:>13} {:>13} {:>13} {:>13} {:>11} {:>13} {:>13} {:>9}",
        "t", "x", "x exact", "y", "y exact", "θ", "μ2", "μ2 exact", "error"
    )?;
    for i in 0..sol.len() {
        let (t, q, qd, mu) = (sol.t[i], &sol.q[i], &sol.qd[i], &sol.mu[i]);
        let (exact, mu_exact) = (cf.position(t), cf.multiplier(t));
        let error = cf.error_at(t, q, qd, Some(mu))?;
        writeln!(
            out,
            "{t:>5.2} {:>13.9} {:>13.9} {:>13.9} {:>13.9} {:>11.7} {:>13.9} {:>13.9} {:>9}",
            q[0],
            exact[0],
            q[1],
            exact[1],
            q[2],
            mu[1],
            mu_exact[1],
            sci(error)
        )?;
    }
    writeln!(out)?;
    let error = compare(&sol, cf)?.max();
    writeln!(
        out,
        "largest |numerical − exact| over x, y, θ, φ, q̇, μ, E, each against its scale \
         (ρ, R ω, m R ω Ω, E, ...): {:.2e}",
        error
    )?;
    writeln!(out, "{}", run_summary(&sol, ""))?;
    verdict(out, error, tol)
}
