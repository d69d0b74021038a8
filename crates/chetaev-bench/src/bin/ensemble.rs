//! `ensemble`: the ratio of the uniform to the classical range over a log-spaced grid of
//! `(v0, h0)`, every point solved by `chetaev` to the impact and compared with the closed forms,
//! in parallel with rayon. Runs the sweep on 1 thread and on the requested number (default 2) and
//! reports the speed-up. A progress bar is drawn when stdout is a terminal.
//!
//! ```sh
//! cargo run --release -p chetaev-bench --bin ensemble
//! cargo run --release -p chetaev-bench --bin ensemble -- --n 20 --out /tmp/ensemble
//! ```

use std::error::Error;
use std::fmt::Write as _;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use chetaev_bench::ensemble::{grid, sweep, SweepPoint};
use chetaev_bench::report::{csv_field, format_seconds};
use chetaev_plot::{Figure, Style};
use clap::Parser;
use indicatif::{ProgressBar, ProgressStyle};

/// The range ratio R_uniform / R_classical over a grid of (v0, h0), solved in parallel.
#[derive(Parser, Debug)]
#[command(version)]
struct Args {
    /// Points per axis (the grid has n² points).
    #[arg(long, default_value_t = 100)]
    n: usize,
    /// Smallest v0 and h0.
    #[arg(long, default_value_t = 0.1)]
    lo: f64,
    /// Largest v0 and h0.
    #[arg(long, default_value_t = 100.0)]
    hi: f64,
    /// Gravitational acceleration.
    #[arg(long, default_value_t = 9.81)]
    g: f64,
    /// Relative tolerance (absolute tolerances scaled to each point's motion).
    #[arg(long, default_value_t = 1e-10)]
    tol: f64,
    /// Threads of the parallel run (compared with one thread).
    #[arg(long, default_value_t = 2)]
    threads: usize,
    /// Output directory (default: the workspace's docs/performance).
    #[arg(long)]
    out: Option<PathBuf>,
}

fn main() -> ExitCode {
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("ensemble: {e}");
            ExitCode::FAILURE
        }
    }
}

fn bar(len: usize, label: &str) -> ProgressBar {
    if !std::io::stdout().is_terminal() {
        return ProgressBar::hidden();
    }
    let pb =
        ProgressBar::with_draw_target(Some(len as u64), indicatif::ProgressDrawTarget::stdout());
    if let Ok(style) = ProgressStyle::with_template(
        "{msg:>10} [{bar:40}] {pos}/{len} points, {elapsed} (eta {eta})",
    ) {
        pb.set_style(style.progress_chars("=> "));
    }
    pb.set_message(label.to_string());
    pb
}

fn run() -> Result<(), Box<dyn Error>> {
    let args = Args::parse();
    if !(args.lo > 0.0 && args.hi > args.lo && args.n >= 2 && args.threads >= 1) {
        return Err("need 0 < lo < hi, n ≥ 2 and threads ≥ 1".into());
    }
    let out = args
        .out
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/performance"));
    std::fs::create_dir_all(&out)?;
    let out = out.canonicalize().unwrap_or(out);
    let points = grid(args.lo, args.hi, args.n);

    let mut runs = Vec::new();
    for threads in [1, args.threads] {
        let pb = bar(
            points.len(),
            &format!("{threads} thread{}", if threads == 1 { "" } else { "s" }),
        );
        let tick = || pb.inc(1);
        let (solved, seconds) = sweep(&points, args.g, args.tol, threads, &tick)?;
        pb.finish_and_clear();
        println!(
            "{} points on {threads} thread(s): {seconds:.2} s",
            solved.len()
        );
        runs.push((threads, solved, seconds));
    }
    let (_, solved, t1) = &runs[0];
    let (threads, solved_n, tn) = &runs[runs.len() - 1];
    let speedup = t1 / tn;
    let same = solved.len() == solved_n.len()
        && solved.iter().zip(solved_n.iter()).all(|(a, b)| {
            a.ratio.to_bits() == b.ratio.to_bits() && a.failure == b.failure && a.steps == b.steps
        });
    if !same {
        return Err("the parallel run differs from the serial one".into());
    }

    let failures: Vec<&SweepPoint> = solved.iter().filter(|p| p.failure.is_some()).collect();
    let ok: Vec<&SweepPoint> = solved.iter().filter(|p| p.failure.is_none()).collect();
    let max_of = |f: &dyn Fn(&SweepPoint) -> f64| ok.iter().map(|p| f(p)).fold(0.0f64, f64::max);
    let ratio_err = max_of(&|p| p.ratio_error());
    let u_err = max_of(&|p| p.uniform_error);
    let c_err = max_of(&|p| p.classical_error);
    let rodas = ok.iter().filter(|p| p.method == "Rodas4").count();
    let steps: usize = ok.iter().map(|p| p.steps).sum();

    let mut csv = String::from(
        "v0,h0,z,ratio,ratio_error,uniform_error,classical_error,method,steps,failure\n",
    );
    for p in solved {
        let _ = writeln!(
            csv,
            "{:.6e},{:.6e},{:.6e},{:.15e},{:.2e},{:.2e},{:.2e},{},{},{}",
            p.v0,
            p.h0,
            p.z,
            p.ratio,
            p.ratio_error(),
            p.uniform_error,
            p.classical_error,
            p.method,
            p.steps,
            csv_field(p.failure.as_deref().unwrap_or(""))
        );
    }
    std::fs::write(out.join("ensemble.csv"), csv)?;

    // The ratio depends on z = g h0 / v0² alone: the closed form as a line, every 37th point of
    // the sweep as a marker.
    let mut closed: Vec<(f64, f64)> = solved.iter().map(|p| (p.z, p.closed_ratio)).collect();
    closed.sort_by(|a, b| a.0.total_cmp(&b.0));
    closed.dedup_by(|a, b| (a.0 / b.0 - 1.0).abs() < 1e-3);
    let numerical: Vec<(f64, f64)> = ok.iter().step_by(37).map(|p| (p.z, p.ratio)).collect();
    let errors: Vec<(f64, f64)> = ok
        .iter()
        .step_by(7)
        .map(|p| (p.z, p.ratio_error().max(1e-17)))
        .collect();
    Figure::new("Range ratio R_uniform / R_classical against z = g h0 / v0²")
        .x_label("z = g h0 / v0²")
        .y_label("R_uniform / R_classical")
        .log_x()
        .line("closed form arccos(e^(−z)) / √(2z)", &closed)
        .line_styled(
            "chetaev (every 37th grid point)",
            &numerical,
            Style {
                width: 0.0,
                markers: true,
                ..Style::default()
            },
        )
        .save(out.join("ensemble-ratio.svg"))?;
    Figure::new("Relative error of the range ratio against z")
        .x_label("z = g h0 / v0²")
        .y_label("|ratio − closed form| / closed form")
        .log_x()
        .log_y()
        .line_styled(
            "every 7th grid point",
            &errors,
            Style {
                width: 0.0,
                markers: true,
                ..Style::default()
            },
        )
        .save(out.join("ensemble-error.svg"))?;

    let mut md = String::new();
    let _ = writeln!(
        md,
        "## Ensemble: the range ratio over {} points\n\n\
         `v0`, `h0` log-spaced over [{}, {}] ({} × {}), `g = {}`, rtol = {:.0e} with absolute \
         tolerances scaled to each motion (`scaled_atol`), every point solved to the impact (uniform \
         by Dop853, and by Rodas4 where Dop853 reports stiffness; classical by Dop853).\n\n\
         | | |\n|---|---|\n\
         | wall time, 1 thread | {} |\n\
         | wall time, {threads} threads | {} |\n\
         | speed-up | {speedup:.2} |\n\
         | points solved / failed | {} / {} |\n\
         | uniform motions that needed Rodas4 | {rodas} |\n\
         | steps, all uniform motions | {steps} |\n\
         | largest relative error of the ratio | {ratio_err:.1e} |\n\
         | largest relative error of R_uniform / R_classical | {u_err:.1e} / {c_err:.1e} |\n\n\
         ![range ratio](ensemble-ratio.svg)\n\n![error](ensemble-error.svg)\n",
        solved.len(),
        args.lo,
        args.hi,
        args.n,
        args.n,
        args.g,
        args.tol,
        format_seconds(*t1),
        format_seconds(*tn),
        ok.len(),
        failures.len(),
    );
    for f in failures.iter().take(5) {
        let _ = writeln!(
            md,
            "\n- failed at v0 = {}, h0 = {}: {}",
            f.v0,
            f.h0,
            f.failure.as_deref().unwrap_or("")
        );
    }
    std::fs::write(out.join("ensemble.md"), &md)?;
    println!(
        "speed-up {speedup:.2} on {threads} threads; {} solved, {} failed, {rodas} by Rodas4; \
         largest ratio error {ratio_err:.1e}; written to {}",
        ok.len(),
        failures.len(),
        out.display()
    );
    Ok(())
}
