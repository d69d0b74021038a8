//! Verifies `chetaev` against the closed forms of the paper "Uniform horizontal projectile motion"
//! (Swaczyna and Volný) and prints Table 42.1 rebuilt, the errors along both motions, observed
//! orders of convergence, and error against run time.

use clap::Parser;
use uniform_projectile::closed_form::Params;
use uniform_projectile::report::{build, MotionErrors, Report, Row, TableRow};

/// Command-line options.
#[derive(Parser, Debug)]
#[command(
    version,
    about = "Verify chetaev against the paper's closed forms (42.4)-(42.42)"
)]
struct Cli {
    /// Initial speed v0 [m/s].
    #[arg(long, default_value_t = 10.0)]
    v0: f64,
    /// Gravitational acceleration g [m/s²].
    #[arg(long, default_value_t = 10.0)]
    g: f64,
    /// Initial height h0 [m].
    #[arg(long, default_value_t = 5.0)]
    h0: f64,
    /// Mass m [kg].
    #[arg(long, default_value_t = 1.0)]
    m: f64,
    /// Relative and absolute tolerance of the table and error runs.
    #[arg(long, default_value_t = 1e-12)]
    tol: f64,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
}

fn main() {
    let cli = Cli::parse();
    let params = Params {
        v0: cli.v0,
        g: cli.g,
        h0: cli.h0,
        m: cli.m,
    };
    for (name, v) in [
        ("v0", cli.v0),
        ("g", cli.g),
        ("h0", cli.h0),
        ("m", cli.m),
        ("tol", cli.tol),
    ] {
        if !(v.is_finite() && v > 0.0) {
            eprintln!("error: --{name} must be a finite positive number, got {v}");
            std::process::exit(2);
        }
    }
    let report = match build(&params, cli.tol) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(1);
        }
    };
    if cli.json {
        match serde_json::to_string_pretty(&report) {
            Ok(s) => println!("{s}"),
            Err(e) => {
                eprintln!("error: {e}");
                std::process::exit(1);
            }
        }
    } else {
        print_text(&report);
    }
}

fn row(name: &str, r: &Row) {
    println!(
        "  {name:<13} {:>19.12} {:>19.12} {:>19.12} {:>19.12} {:>19.12}",
        r.t, r.r, r.v_r, r.impact_angle_deg, r.s
    );
}

fn err_row(r: &Row) {
    println!(
        "  {:<13} {:>19.1e} {:>19.1e} {:>19.1e} {:>19.1e} {:>19.1e}",
        "rel. error", r.t, r.r, r.v_r, r.impact_angle_deg, r.s
    );
}

fn motion(name: &str, t: &TableRow) {
    println!("{name}");
    row("numerical", &t.numerical);
    row("closed form", &t.closed_form);
    err_row(&t.rel_error);
}

fn errors(name: &str, e: &MotionErrors) {
    let opt = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.1e}"));
    println!(
        "  {name:<9} {:>8.1e} {:>8.1e} {:>8.1e} {:>8.1e} {:>8.1e} {:>8.1e} {:>8.1e} {:>8} {:>8} {:>8} {:>8} {:>8.1e}  ({} points)",
        e.x,
        e.y,
        e.xd,
        e.yd,
        e.xdd,
        e.ydd,
        e.curvature,
        opt(e.mu),
        opt(e.phi),
        opt(e.residual),
        opt(e.work_vs_potential),
        e.energy_balance,
        e.points
    );
}

fn print_text(r: &Report) {
    let p = &r.params;
    println!(
        "Uniform horizontal projectile (Swaczyna and Volný): v0 = {} m/s, g = {} m/s², h0 = {} m, m = {} kg",
        p.v0, p.g, p.h0, p.m
    );
    println!(
        "Integrated by chetaev (Dop853, rtol = atol = {:e}), impact located as an event y = 0.\n",
        r.tolerance
    );
    println!("Table 42.1 rebuilt");
    println!(
        "  {:<13} {:>19} {:>19} {:>19} {:>19} {:>19}",
        "", "T [s]", "R [m]", "v_R [m/s]", "angle [deg]", "s [m]"
    );
    motion("classical (42.4)-(42.16)", &r.table.classical);
    motion("uniform (42.29)-(42.38)", &r.table.uniform);

    println!("\nLargest error along the motion (relative: x/R, y/h0, ẋ/v0, ẏ/v_R, q̈/g, κ/(g/v0²), μ/(mg/2v0), |Φ|/(mg), |f|/v0², work/(mgh0), balance/(mv0²+mgh0))");
    println!(
        "  {:<9} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8}",
        "motion", "x", "y", "ẋ", "ẏ", "ẍ", "ÿ", "κ", "μ", "|Φ|", "|f|", "W_Φ−ΔV", "E bal."
    );
    errors("classical", &r.classical_errors);
    errors("uniform", &r.uniform_errors);
    println!("  W_Φ − ΔV: the work of the Chetaev force minus the change of potential energy m g (y − h0);");
    println!("  E bal.: E − E(0) − W_Φ + ∫∂L/∂t dt, with E = q̇·∂L/∂q̇ − L.");

    println!("\nObserved order of convergence (uniform motion, end state at t = T)");
    for c in &r.convergence {
        let what = if c.against == "h" {
            "order: error vs fixed step h, halving"
        } else {
            "tolerance proportionality: error vs tol"
        };
        println!(
            "  {:<7} {:<48} observed {:>5.2}   expected {:.0}",
            c.method, what, c.order, c.expected
        );
    }

    println!("\nError against run time (uniform motion to t = T; state only recorded; median of repeated runs)");
    println!(
        "  {:<7} {:>10} {:>10} {:>12} {:>8} {:>7} {:>8}",
        "method", "tol or h", "error", "time [µs]", "RHS", "steps", "repeats"
    );
    for w in &r.work_precision {
        println!(
            "  {:<7} {:>10.0e} {:>10.1e} {:>12.1} {:>8} {:>7} {:>8}",
            w.method,
            w.tolerance,
            w.error,
            w.seconds * 1e6,
            w.rhs_evaluations,
            w.steps,
            w.repeats
        );
    }
}
