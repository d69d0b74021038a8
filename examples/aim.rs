//! Aiming the constant-speed projectile: which launch speed `v0` lands it at a given distance?
//!
//! Newton's method on `R(v0) = target`, with `R` and `dR/dv0` from one solve each: the impact is
//! a smooth event, and the seed `v0` moves both the constraint `|q̇|² = v0²` and the initial speed
//! `ẋ(0) = v0`. The closed form (42.38), `R = (v0²/g) arccos e^(−g h0/v0²)`, checks the answer.
//!
//! ```sh
//! cargo run --release --example aim -- --target 20
//! ```

use std::io::{self, Write};
use std::process::ExitCode;

use chetaev::prelude::*;
use chetaev_suite::{finish, positive};
use clap::Parser;
use uniform_projectile::closed_form::{uniform, Params};
use uniform_projectile::model::{impact, scaled_atol, uniform_problem};

/// Find the launch speed that lands the constant-speed projectile at a target distance.
#[derive(Parser)]
struct Cli {
    /// The distance to land at [m]: any positive distance (R grows from 0 to ∞ with v0).
    #[arg(long, default_value_t = 12.0, value_parser = positive, allow_negative_numbers = true)]
    target: f64,
    /// Gravity [m/s²].
    #[arg(long, default_value_t = 10.0, value_parser = positive, allow_negative_numbers = true)]
    g: f64,
    /// Launch height [m].
    #[arg(long, default_value_t = 5.0, value_parser = positive, allow_negative_numbers = true)]
    h0: f64,
    /// First guess of the speed [m/s].
    #[arg(long, default_value_t = 10.0, value_parser = positive, allow_negative_numbers = true)]
    v0: f64,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    finish(run(&cli, &mut io::stdout().lock()))
}

/// How far the aimed range may differ from the closed form's (relative).
const AGREEMENT: f64 = 1e-8;

/// `(R, dR/dv0)` at speed `v0`, from one solve carrying the seed `v0`.
fn range_and_slope(p: &Params) -> Result<(f64, f64), Box<dyn std::error::Error>> {
    // T ≈ h0/v0 for a slow launch, ≈ √(2 h0/g) for a fast one: ten times both is enough.
    let t_max = 10.0 * (p.h0 / p.v0 + (2.0 * p.h0 / p.g).sqrt() + p.v0 / p.g);
    // Absolute tolerances scaled to the motion (a tenth of rtol times its lengths and speeds), so
    // that a range of a micrometre is resolved as well as one of a kilometre.
    let (atol_q, atol_qd) = scaled_atol(p, 1e-13);
    let options = Options::until(t_max)
        .tolerances(1e-12, 0.0)
        .atol_per_component(&atol_q, &atol_qd)
        .output_final()
        .record(Record::State)
        .event(impact())
        .sensitivity(Seed::parameter("v0").with_velocity(0, 1.0))
        .sensitivity_control(true);
    let problem = uniform_problem(p)?;
    let mut sol = solve(&problem, Dop853::default(), &options)?;
    // A slow launch turns stiff long before the impact (v0² ≪ g h0): the implicit method the
    // error names takes over.
    if matches!(sol.error(), Some(chetaev::Error::Stiff { .. })) {
        sol = solve(&problem, Rodas4, &options)?;
    }
    if let Some(e) = sol.error() {
        return Err(e.clone().into());
    }
    let hit = sol.events.first().ok_or("no impact before the end time")?;
    let moved = sol
        .sensitivities
        .as_ref()
        .and_then(|s| s.events.first().cloned().flatten())
        .ok_or("the impact's sensitivity is missing")?;
    Ok((hit.q[0], moved.q[0][0]))
}

fn run(cli: &Cli, out: &mut impl Write) -> Result<(), Box<dyn std::error::Error>> {
    let mut p = Params {
        v0: cli.v0,
        g: cli.g,
        h0: cli.h0,
        m: 1.0,
    };
    writeln!(
        out,
        "Aim: land at R = {} m from h0 = {} m under g = {} m/s², at constant speed v0 (Newton on v0,",
        cli.target, cli.h0, cli.g
    )?;
    writeln!(
        out,
        "dR/dv0 from the impact's sensitivity; Dop853 at 1e-12, Rodas4 where it turns stiff)"
    )?;
    writeln!(
        out,
        "{:>4} {:>22} {:>22} {:>22}",
        "step", "v0 [m/s]", "R(v0) [m]", "dR/dv0 [s]"
    )?;
    for step in 0..30 {
        let (r, slope) = range_and_slope(&p)?;
        writeln!(
            out,
            "{step:>4} {:>22.15e} {:>22.15e} {:>22.15e}",
            p.v0, r, slope
        )?;
        if (r - cli.target).abs() <= 1e-12 * cli.target {
            let closed = uniform::kinematics(&p).range;
            let difference = ((closed - cli.target) / cli.target).abs();
            writeln!(
                out,
                "\nv0 = {:.12e} m/s lands at R = {:.12e} m; the closed form (42.38) gives {:.12e} m \
                 (relative difference {:.1e})",
                p.v0,
                r,
                closed,
                difference
            )?;
            // The solve and the closed form must agree; where they do not (at scales whose
            // numbers underflow, such as g = 1e-300), the aim is not to be trusted.
            if difference.is_nan() || difference > AGREEMENT {
                return Err(format!(
                    "the solve and the closed form differ by {difference:.1e}, more than \
                     {AGREEMENT:.0e}: the aim is not verified at these scales (state the problem \
                     in units in which g, h0 and the target are nearer 1)"
                )
                .into());
            }
            return Ok(());
        }
        if !(slope.is_finite() && slope > 0.0 && r > 0.0) {
            return Err(format!("dR/dv0 = {slope} at v0 = {}: cannot aim from here", p.v0).into());
        }
        // A Newton step on ln R(ln v0) = ln target: R grows as v0² for a slow launch and as v0
        // for a fast one, so the slope d ln R/d ln v0 stays between 1 and 2 and the step is as good
        // for a target of a micrometre as for one of a kilometre.
        let elasticity = p.v0 * slope / r;
        p.v0 *= (-(r / cli.target).ln() / elasticity).exp();
    }
    Err("Newton's method did not reach the target in 30 steps".into())
}
