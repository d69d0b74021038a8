//! The Gaussian isokinetic thermostat: four charged particles in 3D (N = 12 coordinates) in a
//! uniform field, their total kinetic energy held fixed by one constraint nonlinear in the
//! velocities, against the closed form for constant forces (Zhang 1997; Minary, Martyna &
//! Tuckerman 2003; Tuckerman, Statistical Mechanics, §4.12), with `μ = −α`, minus the friction
//! coefficient of the isokinetic equations (Evans & Morriss).
//!
//! ```sh
//! cargo run --release --example isokinetic_thermostat
//! ```

use std::io::{self, Write};
use std::process::ExitCode;

use chetaev::prelude::*;
use chetaev_catalogue::isokinetic_thermostat::{self, friction_coefficient, Params};
use chetaev_catalogue::{compare, Reference};
use chetaev_suite::{finish, run_summary, verdict};
use clap::Parser;

/// The Gaussian isokinetic thermostat (four particles in 3D) against its closed form for constant forces.
#[derive(Parser)]
struct Cli {}

fn main() -> ExitCode {
    Cli::parse();
    finish(run(&mut io::stdout().lock()))
}

fn run(out: &mut impl Write) -> Result<(), Box<dyn std::error::Error>> {
    let p = Params::four_particles();
    let entry = isokinetic_thermostat::entry(&p)?;
    let cf = &entry.reference;
    let (a, b) = cf.coefficients();
    let tol = 1e-10;
    let t_end = 8.0 / b.sqrt();
    let times: Vec<f64> = (1..=8).map(|k| t_end * f64::from(k) / 8.0).collect();
    let options = Options::until(t_end)
        .tolerances(tol, tol)
        .output_times(times);
    let sol = solve(&entry.problem, Dop853::default(), &options)?;

    writeln!(
        out,
        "Gaussian isokinetic thermostat: L = Σ ½ m_k q̇_k² + Σ F_k q_k, f = Σ ½ m_k q̇_k² − K0"
    )?;
    writeln!(
        out,
        "4 particles in 3D (N = 12), masses 1 2 3 4, charges 1 −1 2 −½, field (0.5, 0, −1); K0 = {:.6}",
        cf.kinetic_energy()
    )?;
    writeln!(
        out,
        "a = F·q̇0/2K0 = {a:.6}, b = Σ F²/m / 2K0 = {b:.6} (time scale 1/√b = {:.4}); Dop853, rtol = atol = {tol:e}",
        1.0 / b.sqrt()
    )?;
    for s in cf.sources() {
        writeln!(out, "reference: {s}")?;
    }
    writeln!(out)?;
    writeln!(
        out,
        "{:>6} {:>13} {:>13} {:>13} {:>13} {:>13} {:>13} {:>9}",
        "t", "z₄", "z₄ exact", "ż₄", "ż₄ exact", "μ", "−α(q̇)", "error"
    )?;
    for i in 0..sol.len() {
        let (t, q, qd, mu) = (sol.t[i], &sol.q[i], &sol.qd[i], &sol.mu[i]);
        let (exact, v_exact) = (cf.position(t), cf.velocity(t));
        let alpha = friction_coefficient(&p.mass, &p.force, &SVector::from_column_slice(qd));
        let error = cf.error_at(t, q, qd, Some(mu))?;
        writeln!(
            out,
            "{t:>6.3} {:>13.9} {:>13.9} {:>13.9} {:>13.9} {:>13.10} {:>13.10} {error:>9.1e}",
            q[11], exact[11], qd[11], v_exact[11], mu[0], -alpha
        )?;
    }
    writeln!(out)?;
    let error = compare(&sol, cf)?.max();
    writeln!(
        out,
        "largest |numerical − exact| over all 12 positions and velocities, μ (closed form) \
         and K, each against its scale: {error:.2e}"
    )?;
    writeln!(
        out,
        "{}",
        run_summary(&sol, " (E = K − F·q changes by the work of Φ = μ M q̇)")
    )?;
    verdict(out, error, tol)
}
