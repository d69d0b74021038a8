//! Verifies `chetaev` against the closed forms of the paper "Uniform horizontal projectile motion"
//! (Swaczyna and Volný).
//!
//! The first line of the output is the verdict (`VERIFIED: ...` or `NOT VERIFIED: ...`), then
//! Table 42.1 rebuilt; the errors along both motions (with the impact's derivatives), the observed orders of convergence and error
//! against run time follow on request (`--errors`, `--orders`, `--timing`, or all with `--full`).
//! `--json` prints everything as one JSON object. The exit status is 0 when verified, 1 when not
//! (or when the verification could not run), 2 on bad arguments.

use std::io::{self, Write};
use std::process::ExitCode;

use chetaev::integrate::Method;
use chetaev::prelude::{AnyMethod, MachineCode, Options};
use clap::Parser;
use uniform_projectile::closed_form::Params;
use uniform_projectile::report::{
    build, MotionErrors, Report, Row, Studies, TableRow, LIMIT_PER_TOLERANCE, ORDER_SIGNAL,
};

/// Command-line options.
#[derive(Parser, Debug)]
#[command(
    version,
    allow_negative_numbers = true,
    about = "Verify chetaev against the paper's closed forms (42.4)-(42.42)",
    long_about = "Verify chetaev against the closed forms (42.4)-(42.42) of the paper \"Uniform \
                  horizontal projectile motion\" (Swaczyna and Volný).\n\n\
                  Prints one line with the verdict (VERIFIED or NOT VERIFIED, with the largest \
                  relative error and the limit), then Table 42.1 rebuilt. The other sections \
                  follow on request.",
    after_help = "Exit status: 0 verified, 1 not verified (or the verification could not run), \
                  2 bad arguments."
)]
struct Cli {
    /// Initial speed v0 [m/s].
    #[arg(long, default_value_t = 10.0, value_parser = positive)]
    v0: f64,
    /// Gravitational acceleration g [m/s²].
    #[arg(long, default_value_t = 10.0, value_parser = positive)]
    g: f64,
    /// Initial height h0 [m].
    #[arg(long, default_value_t = 5.0, value_parser = positive)]
    h0: f64,
    /// Mass m [kg].
    #[arg(long, default_value_t = 1.0, value_parser = positive)]
    m: f64,
    /// Relative and absolute tolerance of the table and error runs (from the library's floor,
    /// 100 ulps ≈ 2.2e-14, to 1e-4).
    #[arg(long, default_value = "1e-12", value_parser = tolerance)]
    tol: f64,
    /// The method of the table, error and derivative runs: dopri5, dop853, tsit5, rodas4 or
    /// rodas5p (the orders and timings run every method).
    #[arg(long, default_value = "dop853", value_parser = method)]
    method: AnyMethod,
    /// Largest relative error accepted by the verdict, for the closed forms and the derivatives,
    /// below 1 [default: 100 × tol].
    #[arg(long, value_parser = limit)]
    limit: Option<f64>,
    /// Also print the largest errors along both motions, and the impact's derivatives in v0, g,
    /// h0 against the closed form's.
    #[arg(long)]
    errors: bool,
    /// Also print the observed orders of convergence of every method: in fixed steps halving,
    /// and against the tolerance. The fixed steps run to the impact T, or to 4 v0/g if that is
    /// earlier: at large z = g h0/v0² the velocity turns within a few v0/g and the motion then
    /// falls straight down, stiff, where steps of T/2^k would cross the turn in one step.
    #[arg(long)]
    orders: bool,
    /// Also print error against run time of every method to the impact (machine-dependent).
    #[arg(long)]
    timing: bool,
    /// Print every section (--errors --orders --timing).
    #[arg(long)]
    full: bool,
    /// Print one JSON object with everything (verdict, table, errors, orders, timing) instead of
    /// text.
    #[arg(long, conflicts_with_all = ["errors", "orders", "timing", "full"])]
    json: bool,
}

/// A finite, strictly positive number.
fn positive(s: &str) -> Result<f64, String> {
    let v: f64 = s.parse().map_err(|e| format!("{e}"))?;
    if v.is_finite() && v >= f64::MIN_POSITIVE {
        Ok(v)
    } else {
        Err(format!(
            "must be a finite positive number, at least {:e} (the smallest normal one), got {v:e}",
            f64::MIN_POSITIVE
        ))
    }
}

/// A tolerance the library accepts (as `rtol` and `atol` both), tight enough for a verdict to
/// mean something (its default limit is 100 × tol).
fn tolerance(s: &str) -> Result<f64, String> {
    let v = positive(s)?;
    if v > 1e-4 {
        return Err(format!(
            "{v} is too loose to verify anything (the verdict's limit would be {}): give 1e-4 or less, \
             such as the default 1e-12",
            LIMIT_PER_TOLERANCE * v
        ));
    }
    Options::until(1.0)
        .tolerances(v, v)
        .validate(0.0, 2)
        .map_err(|e| e.to_string())?;
    Ok(v)
}

/// A method with error control, by its name in the literature (case-insensitive).
fn method(s: &str) -> Result<AnyMethod, String> {
    match AnyMethod::from_name(s, Some(1.0)) {
        Ok(m) if m.info().fixed_step.is_none() => Ok(m),
        Ok(_) => Err(format!(
            "{s} has no error control, and the table is integrated to a tolerance: choose one of \
             {}",
            adaptive_names()
        )),
        Err(_) => Err(format!(
            "unknown method \"{s}\": choose one of {}",
            adaptive_names()
        )),
    }
}

/// The lower-case names of the methods with error control, "dopri5, dop853, …".
fn adaptive_names() -> String {
    AnyMethod::all(1.0)
        .iter()
        .filter(|m| m.info().fixed_step.is_none())
        .map(|m| m.info().name.to_lowercase())
        .collect::<Vec<_>>()
        .join(", ")
}

/// A relative error limit: positive and below 1 (a limit of 1 accepts any answer of the right
/// sign).
fn limit(s: &str) -> Result<f64, String> {
    let v = positive(s)?;
    if v >= 1.0 {
        return Err(format!(
            "a relative error of {v} accepts any answer: give a limit below 1, such as 1e-10"
        ));
    }
    Ok(v)
}

/// Which optional sections to print.
#[derive(Clone, Copy)]
struct Sections {
    errors: bool,
    orders: bool,
    timing: bool,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let params = Params {
        v0: cli.v0,
        g: cli.g,
        h0: cli.h0,
        m: cli.m,
    };
    let sections = Sections {
        errors: cli.errors || cli.full,
        orders: cli.orders || cli.full,
        timing: cli.timing || cli.full,
    };
    // The JSON object is complete; the text computes only the studies it prints.
    let studies = if cli.json {
        Studies::ALL
    } else {
        Studies {
            orders: sections.orders,
            timing: sections.timing,
        }
    };
    let mut report = match build(&params, cli.tol, cli.method, studies) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("error: the verification could not run: {e}");
            if cli.json {
                // Still one JSON object on stdout, saying that nothing was verified and why.
                let object = serde_json::json!({
                    "verdict": { "verified": false, "error": e.to_string() },
                    "params": { "v0": params.v0, "g": params.g, "h0": params.h0, "m": params.m },
                    "tolerance": cli.tol,
                    "method": cli.method.name(),
                });
                println!("{object:#}");
            }
            if matches!(e, chetaev::Error::Stiff { .. }) {
                eprintln!(
                    "note: {} is explicit and meets its stability limit at large z = g h0/v0² \
                     (Dop853 succeeds up to about 1e2 and stops from about 1e4; here z = \
                     {:.3e}). Verify with an implicit method: add `--method rodas4`. \
                     docs/where-it-breaks.md (Extreme parameters) shows both methods over z.",
                    cli.method.name(),
                    params.z()
                );
            }
            return ExitCode::FAILURE;
        }
    };
    if let Some(limit) = cli.limit {
        report.judge(limit);
    }
    let verified = report.verdict.verified && report.sensitivity_verdict.verified;
    let status = if verified {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    };
    let written = if cli.json {
        if !verified {
            eprintln!("{}", verdict_line(&report));
        }
        write_json(&report)
    } else {
        write_text(&mut io::stdout().lock(), &report, sections)
    };
    // After the verdict, which stays the first line.
    if !verified {
        if let Some(note) = outside_checked_range(&params) {
            eprintln!("{note}");
        }
    }
    match written {
        // A reader that stops early (`| head`) is not an error; the verdict stands.
        Err(e) if e.kind() != io::ErrorKind::BrokenPipe => {
            eprintln!("error: writing the output: {e}");
            ExitCode::FAILURE
        }
        _ => status,
    }
}

fn write_json(report: &Report) -> io::Result<()> {
    let mut out = io::stdout().lock();
    serde_json::to_writer_pretty(&mut out, report)?;
    writeln!(out)?;
    out.flush()
}

/// A relative error: `0` when exact, otherwise two significant digits (`6.7e-16`).
fn sci(v: f64) -> String {
    if v == 0.0 {
        "0".into()
    } else {
        format!("{v:.1e}")
    }
}

/// A tolerance or limit: three significant digits at most, no trailing zeros (`1e-12`, `2.5e-3`).
fn short(v: f64) -> String {
    let rounded: f64 = format!("{v:.2e}").parse().unwrap_or(v);
    format!("{rounded:e}")
}

fn opt(v: Option<f64>) -> String {
    v.map_or_else(|| "-".into(), sci)
}

/// `rtol = atol = 1e-12`, or the absolute tolerances one by one where some were tightened to the
/// motion's scales.
fn tolerances(r: &Report) -> String {
    if r.atol.iter().all(|&a| a == r.tolerance) {
        format!("rtol = atol = {}", short(r.tolerance))
    } else {
        let [x, y, xd, yd] = r.atol.map(short);
        format!(
            "rtol = {}, atol = {x} m, {y} m, {xd} m/s, {yd} m/s for x, y, ẋ, ẏ",
            short(r.tolerance)
        )
    }
}

/// A note for parameters outside the range over which the closed forms themselves are checked
/// (`tests/extreme.rs`): there a failed verdict may be the reference's, which overflows or
/// underflows in places (∂T/∂g at `g = 1e-200`), rather than chetaev's.
fn outside_checked_range(p: &Params) -> Option<String> {
    let inside = |x: f64, lo: f64, hi: f64| (lo..=hi).contains(&x);
    if inside(p.v0, 1e-6, 1e6)
        && inside(p.h0, 1e-6, 1e6)
        && inside(p.z(), 1e-8, 1e6)
        && inside(p.g, 1.0, 100.0)
    {
        return None;
    }
    Some(format!(
        "note: v0 = {:e}, h0 = {:e}, g = {:e}, z = g h0/v0² = {:e} lie outside the range over \
         which the closed forms themselves are checked (g from 1 to 100, v0 and h0 within \
         1e-6 … 1e6, z within 1e-8 … 1e6): \
         here the reference, evaluated in floating point, may fail as well as chetaev; compare \
         with --errors",
        p.v0,
        p.h0,
        p.g,
        p.z()
    ))
}

/// The one-line verdict.
fn verdict_line(r: &Report) -> String {
    let v = &r.verdict;
    let limit = if v.limit == LIMIT_PER_TOLERANCE * r.tolerance {
        format!("{} = {} × tol", short(v.limit), LIMIT_PER_TOLERANCE)
    } else {
        short(v.limit)
    };
    let d = &r.sensitivity_verdict;
    if v.verified && d.verified {
        format!(
            "VERIFIED: chetaev reproduces the paper's closed forms (Table 42.1, motion, μ, Φ, \
             energy) to {} relative, and the impact's derivatives ∂Q/∂θ in v0, g, h0 to {} of \
             max(|∂Q/∂θ|, |Q/θ|) (limit {limit})",
            sci(v.largest),
            sci(d.largest),
        )
    } else if v.verified {
        format!(
            "NOT VERIFIED: the largest error of the impact's derivatives ∂Q/∂θ, {} of \
             max(|∂Q/∂θ|, |Q/θ|) ({}), is above the limit {limit}",
            sci(d.largest),
            d.largest_of,
        )
    } else {
        format!(
            "NOT VERIFIED: the largest relative error, {} ({}), is above the limit {limit} \
             ({} quantities compared against the closed forms)",
            sci(v.largest),
            v.largest_of,
            v.compared
        )
    }
}

fn write_text(out: &mut impl Write, r: &Report, s: Sections) -> io::Result<()> {
    writeln!(out, "{}", verdict_line(r))?;
    let p = &r.params;
    writeln!(out)?;
    writeln!(
        out,
        "Table 42.1 rebuilt: v0 = {} m/s, g = {} m/s², h0 = {} m, m = {} kg;",
        parameter(p.v0),
        parameter(p.g),
        parameter(p.h0),
        parameter(p.m)
    )?;
    writeln!(
        out,
        "integrated by chetaev ({}, {}), impact located as the event y = 0",
        r.method,
        tolerances(r)
    )?;
    writeln!(
        out,
        "  {:<13} {:>16} {:>16} {:>16} {:>16} {:>16}",
        "", "T [s]", "R [m]", "v_R [m/s]", "angle [deg]", "s [m]"
    )?;
    motion(out, "classical (42.4)-(42.16)", &r.table.classical)?;
    motion(out, "uniform (42.29)-(42.38)", &r.table.uniform)?;
    if s.errors {
        errors_section(out, r)?;
        sensitivity_section(out, r)?;
    }
    if s.orders {
        orders_section(out, r)?;
    }
    if s.timing {
        timing_section(out, r)?;
    }
    if (s.orders || s.timing) && !r.stopped.is_empty() {
        stopped_section(out, r)?;
    }
    if !(s.errors && s.orders && s.timing) {
        writeln!(
            out,
            "\nMore: --errors (along the motion), --orders (convergence), --timing (error against \
             run time), --full (all), --json."
        )?;
    }
    out.flush()
}

/// The studies that stopped before their end, and why.
fn stopped_section(out: &mut impl Write, r: &Report) -> io::Result<()> {
    writeln!(
        out,
        "\nStopped before the end (the rest of that method's study is left out)"
    )?;
    for s in &r.stopped {
        let at = if s.study == "h" {
            format!("h = {:.3e}", s.at)
        } else {
            format!("tol = {}", short(s.at))
        };
        writeln!(out, "  {:<7} at {at}: {}", s.method, s.error)?;
    }
    Ok(())
}

/// The impact's derivatives in `v0`, `g`, `h0` against the closed form's.
fn sensitivity_section(out: &mut impl Write, r: &Report) -> io::Result<()> {
    writeln!(
        out,
        "\nHow the uniform impact moves with the data (sensitivities carried through the solve, \
         against (42.38) differentiated):"
    )?;
    for d in &r.sensitivities {
        writeln!(
            out,
            "  {:<8} {:>20.15} (closed form {:>20.15}, relative error {}{})",
            d.name,
            d.numerical,
            d.closed_form,
            sci(d.rel_error),
            if d.scale > d.closed_form.abs() {
                format!(
                    ", {} of |{}| = {}",
                    sci(d.error),
                    d.name.replace('∂', ""),
                    sci(d.scale)
                )
            } else {
                String::new()
            }
        )?;
    }
    Ok(())
}

fn row(out: &mut impl Write, name: &str, r: &Row) -> io::Result<()> {
    writeln!(
        out,
        "  {name:<13} {:>16} {:>16} {:>16} {:>16} {:>16}",
        cell(r.t),
        cell(r.r),
        cell(r.v_r),
        cell(r.impact_angle_deg),
        cell(r.s)
    )
}

/// A value of Table 42.1: twelve decimals where that shows it (from 1e-4 to 1e6, and 0),
/// otherwise eleven significant digits in exponent form, not 150 digits or a row of zeros.
fn cell(v: f64) -> String {
    if v == 0.0 || (1e-4..1e6).contains(&v.abs()) {
        format!("{v:.12}")
    } else {
        format!("{v:.10e}")
    }
}

/// A parameter as given where it is of a size to read in full (`10`, `0.5`), else in exponent
/// form (`1e150`).
fn parameter(v: f64) -> String {
    if (1e-4..1e6).contains(&v.abs()) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

fn motion(out: &mut impl Write, name: &str, t: &TableRow) -> io::Result<()> {
    writeln!(out, "{name}")?;
    row(out, "numerical", &t.numerical)?;
    row(out, "closed form", &t.closed_form)?;
    let e = &t.rel_error;
    writeln!(
        out,
        "  {:<13} {:>16} {:>16} {:>16} {:>16} {:>16}",
        "rel. error",
        sci(e.t),
        sci(e.r),
        sci(e.v_r),
        sci(e.impact_angle_deg),
        sci(e.s)
    )
}

fn errors_row(out: &mut impl Write, name: &str, e: &MotionErrors) -> io::Result<()> {
    writeln!(
        out,
        "  {name:<9} {:>7} {:>7} {:>7} {:>7} {:>7} {:>7} {:>7} {:>7} {:>7} {:>7} {:>7} {:>7} {:>6}",
        sci(e.x),
        sci(e.y),
        sci(e.xd),
        sci(e.yd),
        sci(e.xdd),
        sci(e.ydd),
        sci(e.curvature),
        opt(e.mu),
        opt(e.phi),
        opt(e.residual),
        opt(e.work_vs_potential),
        sci(e.energy_balance),
        e.points
    )
}

fn errors_section(out: &mut impl Write, r: &Report) -> io::Result<()> {
    writeln!(
        out,
        "\nLargest error along the motion, at the accepted steps, each relative to its scale"
    )?;
    writeln!(
        out,
        "  {:<9} {:>7} {:>7} {:>7} {:>7} {:>7} {:>7} {:>7} {:>7} {:>7} {:>7} {:>7} {:>7} {:>6}",
        "motion",
        "x",
        "y",
        "ẋ",
        "ẏ",
        "ẍ",
        "ÿ",
        "κ",
        "μ",
        "|Φ|",
        "|f|",
        "W_Φ−ΔV",
        "E bal.",
        "points"
    )?;
    errors_row(out, "classical", &r.classical_errors)?;
    errors_row(out, "uniform", &r.uniform_errors)?;
    for line in [
        "  scales: x/R, y/h0, ẋ/v0, ẏ/v_R, ẍ/g, ÿ/g, κ/(g/v0²), μ/(m g/2v0), |Φ|/(m g), |f|/v0²,",
        "          (W_Φ − ΔV)/(m g h0), E bal./(m v0² + m g h0); μ, Φ, f: uniform motion only",
        "  W_Φ − ΔV: the work of the Chetaev force minus the change of potential energy m g (y − h0)",
        "  E bal.: E − E(0) − W_Φ + ∫∂L/∂t dt, with E = q̇·∂L/∂q̇ − L",
    ] {
        writeln!(out, "{line}")?;
    }
    Ok(())
}

fn orders_section(out: &mut impl Write, r: &Report) -> io::Result<()> {
    let until = if r.orders_until < r.table.uniform.closed_form.t {
        format!(
            "fixed steps to t = 4 v0/g = {:.3e} s, when the velocity has turned (steps of T/2^k \
             would cross the turn in one); tolerances to t = T",
            r.orders_until
        )
    } else {
        "end state at t = T".into()
    };
    writeln!(
        out,
        "\nObserved order of convergence (uniform motion, {until})"
    )?;
    for c in &r.convergence {
        let what = if c.against == "h" {
            "order: error vs fixed step h, halving"
        } else {
            "tolerance proportionality: error vs tol"
        };
        match c.order {
            Some(order) => writeln!(
                out,
                "  {:<7} {:<40} observed {order:>5.2}   expected {}",
                c.method, what, c.expected
            )?,
            None => writeln!(
                out,
                "  {:<7} {:<40} observed     -   expected {} (no error above {} to fit: \
                 rounding, not an order)",
                c.method,
                what,
                c.expected,
                short(ORDER_SIGNAL)
            )?,
        }
    }
    Ok(())
}

fn timing_section(out: &mut impl Write, r: &Report) -> io::Result<()> {
    writeln!(
        out,
        "\nError against run time (uniform motion to t = T; median of repeated runs, machine-dependent)"
    )?;
    if !MachineCode::available() {
        // The repeated solves of one problem switch to machine code when it pays, where the build
        // has it; the verification does not need it, so the main job's build leaves it out.
        writeln!(
            out,
            "  (built without machine code: the times are the interpreted route's; `--features native` \
             adds it, as a crate depending on chetaev has it by default)"
        )?;
    }
    writeln!(
        out,
        "  {:<7} {:>6} {:>9} {:>8} {:>10} {:>6} {:>6} {:>8}",
        "method", "tol", "h [s]", "error", "time [µs]", "RHS", "steps", "repeats"
    )?;
    for w in &r.work_precision {
        let (tol, h) = if w.fixed_step {
            ("-".to_string(), format!("{:.3e}", w.tolerance))
        } else {
            (short(w.tolerance), "-".to_string())
        };
        writeln!(
            out,
            "  {:<7} {:>6} {:>9} {:>8} {:>10.1} {:>6} {:>6} {:>8}",
            w.method,
            tol,
            h,
            sci(w.error),
            w.seconds * 1e6,
            w.rhs_evaluations,
            w.steps,
            w.repeats
        )?;
    }
    writeln!(
        out,
        "  error: the largest of |Δx|, |Δy| over max(h0, R) and |Δẋ|, |Δẏ| over v0 at t = T;\n  \
         state only recorded"
    )
}
