//! A particle held at constant speed in a Kepler field, `L = ½ m |q̇|² + k m / r`,
//! `f = |q̇|² − v0²`: the invariant `C = (q × q̇) exp(k / (v0² r))` along the motion, and the
//! scattering orbit against its quadratures (docs/catalogue/kepler_constant_speed.md).
//!
//! ```sh
//! cargo run --release --example kepler_constant_speed
//! ```

use std::io::{self, Write};
use std::process::ExitCode;

use chetaev::prelude::*;
use chetaev_catalogue::kepler_constant_speed::{self, invariant, Params};
use chetaev_catalogue::{compare, Kind};
use chetaev_suite::{finish, run_summary, sci, verdict};
use clap::Parser;

/// A particle at constant speed in a Kepler field: its invariant and its orbit against the quadratures.
#[derive(Parser)]
struct Cli {}

fn main() -> ExitCode {
    Cli::parse();
    finish(run(&mut io::stdout().lock()))
}

fn run(out: &mut impl Write) -> Result<(), Box<dyn std::error::Error>> {
    let p = Params::default();
    let entry = kepler_constant_speed::entry(&p)?;
    let reference = &entry.reference;
    let lambda = reference.lambda();
    let c0 = reference.value();
    let tol = 1e-10;
    let times = vec![5.0, 15.0, 20.0, 22.5, 25.0, 30.0, 50.0, 100.0, 200.0, 400.0];
    let options = Options::until(400.0)
        .tolerances(tol, tol)
        .output_times(times);
    let sol = solve(&entry.problem, Dop853::default(), &options)?;

    writeln!(
        out,
        "Constant speed in a Kepler field: L = ½m|q̇|² + k m/r, f = |q̇|² − v0²"
    )?;
    writeln!(
        out,
        "m = {}, k = {}, v0 = {:.6}, λ = k/v0² = {lambda:.6}; q0 = {:.6?}, q̇0 = {:.6?}",
        p.m,
        p.k,
        p.v0(),
        p.q0,
        p.qd0
    )?;
    if let Some(orbit) = reference.orbit() {
        writeln!(
            out,
            "scattering orbit: periapsis r_p = {:.12} at t_p = {:.9}, total turn {:.6}°",
            orbit.r_periapsis,
            orbit.t_periapsis,
            orbit.total_angle.to_degrees()
        )?;
    }
    writeln!(
        out,
        "invariant C = (q × q̇) exp(λ/r) = {:.12?}",
        c0.as_slice()
    )?;
    writeln!(out)?;
    writeln!(
        out,
        "{:>6} {:>10} {:>15} {:>15} {:>15} {:>9} {:>9}",
        "t", "r", "|C|", "x", "x quadrature", "C error", "q error"
    )?;
    for i in 0..sol.len() {
        let t = sol.t[i];
        let q = SVector::<f64, 3>::from_column_slice(&sol.q[i]);
        let qd = SVector::<f64, 3>::from_column_slice(&sol.qd[i]);
        let c = invariant(lambda, &q, &qd);
        let (x_ref, q_err) = match reference.state(t) {
            Some((qr, _)) => (qr[0], (q - qr).norm() / qr.norm()),
            None => (f64::NAN, f64::NAN),
        };
        writeln!(
            out,
            "{t:>6.1} {:>10.5} {:>15.12} {:>15.10} {:>15.10} {:>9} {:>9}",
            q.norm(),
            c.norm(),
            q[0],
            x_ref,
            sci((c - c0).norm() / c0.norm()),
            sci(q_err)
        )?;
    }
    let cmp = compare(&sol, reference)?;
    writeln!(out)?;
    writeln!(
        out,
        "deviation: |C − C0|/|C0| ≤ {:.1e}; q against the quadrature, relative to r: ≤ {:.1e}; \
         μ against k m ṙ/(2 v0² r²): ≤ {:.1e}",
        cmp.max_of(Kind::Invariant),
        cmp.max_of(Kind::Position),
        cmp.max_of(Kind::Multiplier)
    )?;
    writeln!(
        out,
        "{}",
        run_summary(
            &sol,
            " (E = ½ m v0² − k m/r changes by the work of Φ = 2μ q̇)"
        )
    )?;
    verdict(out, cmp.max(), tol)
}
