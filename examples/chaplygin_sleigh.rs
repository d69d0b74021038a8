//! The Chaplygin sleigh against the closed form of its body velocities (Bloch, Nonholonomic
//! Mechanics and Control, §1.7): the forward speed tends to its limit `V` along a `tanh` law, the
//! turning rate dies out along a `sech` law, and the energy is conserved.
//!
//! ```sh
//! cargo run --release --example chaplygin_sleigh
//! ```

use std::io::{self, Write};
use std::process::ExitCode;

use chetaev::prelude::*;
use chetaev_catalogue::chaplygin_sleigh::{self, body_velocities};
use chetaev_catalogue::{compare, Reference};
use chetaev_suite::{finish, run_summary, verdict};
use clap::Parser;

/// The Chaplygin sleigh against the closed form of its body velocities (Bloch, §1.7).
#[derive(Parser)]
struct Cli {}

fn main() -> ExitCode {
    Cli::parse();
    finish(run(&mut io::stdout().lock()))
}

fn run(out: &mut impl Write) -> Result<(), Box<dyn std::error::Error>> {
    let p = chaplygin_sleigh::Params::default();
    let entry = chaplygin_sleigh::entry(&p)?;
    let cf = &entry.reference;
    let tol = 1e-10;
    let times: Vec<f64> = (1..=8).map(|k| 0.5 * f64::from(k)).collect();
    let options = Options::until(4.0).tolerances(tol, tol).output_times(times);
    let sol = solve(&entry.problem, Dop853::default(), &options)?;

    writeln!(out, "Chaplygin sleigh: L = ½m[(ẋ − a sin θ θ̇)² + (ẏ + a cos θ θ̇)²] + ½Iθ̇², f = −ẋ sin θ + ẏ cos θ")?;
    writeln!(
        out,
        "m = {}, I = {}, a = {}, u0 = {}, ω0 = {}; limit speed V = {:.12}; Dop853, rtol = atol = {tol:e}",
        p.m,
        p.inertia,
        p.a,
        p.u0,
        p.omega0,
        cf.limit_speed()
    )?;
    writeln!(out, "reference: {}", cf.sources()[0])?;
    writeln!(out)?;
    writeln!(
        out,
        "{:>5} {:>14} {:>14} {:>14} {:>14} {:>13} {:>13} {:>9}",
        "t", "u", "u exact", "ω", "ω exact", "θ", "θ exact", "error"
    )?;
    for i in 0..sol.len() {
        let (t, q, qd, mu) = (sol.t[i], &sol.q[i], &sol.qd[i], &sol.mu[i]);
        let (u, w) = body_velocities(
            &SVector::from_column_slice(q),
            &SVector::from_column_slice(qd),
        );
        let error = cf.error_at(t, q, qd, Some(mu))?;
        writeln!(
            out,
            "{t:>5.2} {u:>14.11} {:>14.11} {w:>14.11} {:>14.11} {:>13.10} {:>13.10} {error:>9.1e}",
            cf.forward_speed(t),
            cf.turning_rate(t),
            q[2],
            cf.heading(t)
        )?;
    }
    writeln!(out)?;
    let error = compare(&sol, cf)?.max();
    writeln!(
        out,
        "largest |numerical − exact| over u, ω, θ, μ and E, each against its scale \
         (V, V √(m/(I + m a²)), ...): {:.2e}",
        error
    )?;
    writeln!(out, "{}", run_summary(&sol, ""))?;
    verdict(out, error, tol)
}
