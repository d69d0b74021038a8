//! `ensemble`: the ratio of the uniform to the classical range over a log-spaced grid of
//! `(v0, h0)`, every point solved by `chetaev` to the impact and compared with the closed forms,
//! in parallel with rayon. Runs the sweep on 1 thread and on the requested number (default 2),
//! interleaved, three rounds of each, and reports the median times, their ratio and the speed-up
//! of each round. A progress bar is drawn when stdout is a terminal.
//!
//! Writes `ensemble.md`, `ensemble.csv`, two SVG diagrams and `ensemble.json` (every point, from
//! which `merge` writes the rest again) into `--out` (default `./chetaev-bench-out/ensemble`).
//! With `--shard k/n` only the grid points `i` with `i mod n = k − 1` are solved and written to
//! `ensemble.part-k-of-n.json`; `ensemble merge` joins the `n` parts into the files of the whole
//! run (see `docs/sweeps.md`).
//!
//! ```sh
//! cargo run --release -p chetaev-bench --bin ensemble -- --out docs/performance
//! cargo run --release -p chetaev-bench --bin ensemble -- --n 20 --out /tmp/ensemble
//! cargo run --release -p chetaev-bench --bin ensemble -- --shard 2/8 --out parts
//! cargo run --release -p chetaev-bench --bin ensemble -- merge --out results parts/ensemble.part-*-of-8.json
//! ```

use std::error::Error;
use std::fmt::Write as _;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use chetaev::prelude::Options;
use chetaev_bench::cli::{exit, output_dir, print_summary, refuse_argument};
use chetaev_bench::ensemble::{grid, sweep, SweepPoint};
use chetaev_bench::parts::{
    number, read_number, sweep_point_from_json, sweep_point_to_json, Fields, Part, Shard,
};
use chetaev_bench::report::{csv_field, format_seconds};
use chetaev_plot::{Figure, Style};
use clap::{Args, Parser, Subcommand};
use indicatif::{ProgressBar, ProgressStyle};
use serde_json::{json, Value};

/// The range ratio R_uniform / R_classical over a grid of (v0, h0), solved in parallel.
#[derive(Parser, Debug)]
#[command(
    name = "ensemble",
    version,
    args_conflicts_with_subcommands = true,
    allow_negative_numbers = true
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    #[command(flatten)]
    run: RunArgs,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Join the part files of `--shard k/n` runs into the output of the whole sweep.
    Merge(MergeArgs),
}

#[derive(Args, Debug)]
struct RunArgs {
    /// Points per axis (the grid has n² points).
    #[arg(long, default_value_t = 100)]
    n: usize,
    /// Smallest v0 and h0.
    #[arg(long, default_value_t = 0.1, allow_hyphen_values = true)]
    lo: f64,
    /// Largest v0 and h0.
    #[arg(long, default_value_t = 100.0, allow_hyphen_values = true)]
    hi: f64,
    /// Gravitational acceleration.
    #[arg(long, default_value_t = 9.81, allow_hyphen_values = true)]
    g: f64,
    /// Relative tolerance (absolute tolerances scaled to each point's motion).
    #[arg(long, default_value = "1e-10", allow_hyphen_values = true)]
    tol: f64,
    /// Threads of the parallel run (compared with one thread).
    #[arg(long, default_value_t = 2)]
    threads: usize,
    /// Solve only shard K of N (K from 1 to N): the grid points i, counted from 0 in the order of
    /// ensemble.csv, with i mod N = K − 1; writes ensemble.part-K-of-N.json for `merge`.
    #[arg(long, value_name = "K/N")]
    shard: Option<Shard>,
    /// Output directory [default: ./chetaev-bench-out/ensemble].
    #[arg(long)]
    out: Option<PathBuf>,
}

#[derive(Args, Debug)]
struct MergeArgs {
    /// Output directory [default: ./chetaev-bench-out/ensemble].
    #[arg(long)]
    out: Option<PathBuf>,
    /// The part files of all N shards (ensemble.part-K-of-N.json); a merged ensemble.json also
    /// counts as all of its shards.
    #[arg(required = true)]
    parts: Vec<PathBuf>,
}

/// The settings that define the sweep, equal in all its parts.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Settings {
    n: usize,
    lo: f64,
    hi: f64,
    g: f64,
    tol: f64,
    threads: usize,
}

impl Settings {
    fn to_json(self) -> Value {
        json!({
            "n": self.n,
            "lo": number(self.lo),
            "hi": number(self.hi),
            "g": number(self.g),
            "tol": number(self.tol),
            "threads": self.threads,
        })
    }

    fn from_json(v: &Value) -> Result<Self, Box<dyn Error>> {
        let f = Fields::of(v, "settings")?;
        Ok(Self {
            n: f.usize("n")?,
            lo: f.f64("lo")?,
            hi: f.f64("hi")?,
            g: f.f64("g")?,
            tol: f.f64("tol")?,
            threads: f.usize("threads")?,
        })
    }
}

fn main() -> ExitCode {
    exit("ensemble", run())
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
    let cli = Cli::parse();
    let (out, summary) = match cli.command {
        Some(Command::Merge(m)) => {
            let out = output_dir(m.out, "ensemble")?;
            let summary = merge_parts(&m.parts, &out)?;
            (out, summary)
        }
        None => {
            if let Err(message) = check_arguments(&cli.run) {
                refuse_argument::<Cli>(message);
            }
            let out = output_dir(cli.run.out.clone(), "ensemble")?;
            let summary = solve_sweep(&cli.run, &out)?;
            (out, summary)
        }
    };
    print_summary(&summary, &out)
}

/// The most points per axis: a grid of 10⁶ points, 100 times the default.
const MAX_N: usize = 1000;

/// The most threads of the parallel run.
const MAX_THREADS: usize = 1024;

/// The checks of the arguments of a sweep that clap cannot make alone: ranges, and `lo < hi`.
fn check_arguments(args: &RunArgs) -> Result<(), String> {
    if !(args.lo > 0.0 && args.hi > args.lo && args.hi.is_finite()) {
        return Err(format!(
            "--lo {} --hi {}: need finite 0 < lo < hi, such as --lo 0.1 --hi 100",
            args.lo, args.hi
        ));
    }
    if !(2..=MAX_N).contains(&args.n) {
        return Err(format!(
            "--n {}: need 2 ≤ n ≤ {MAX_N} points per axis (the grid has n² points)",
            args.n
        ));
    }
    if !(2..=MAX_THREADS).contains(&args.threads) {
        return Err(format!(
            "--threads {}: need 2 ≤ threads ≤ {MAX_THREADS}, such as the number of cores (the \
             sweep is timed on one thread and on this many)",
            args.threads
        ));
    }
    if !(args.g.is_finite() && args.g > 0.0) {
        return Err(format!(
            "--g {}: need a finite gravity g > 0, such as 9.81",
            args.g
        ));
    }
    // Every point's tolerances are `tol` and atol scaled from it: a `tol` the library refuses
    // would give a sweep of failures, so it is refused here, with the library's reason.
    if !(args.tol > 0.0 && args.tol < 1.0) {
        return Err(format!(
            "--tol {:e}: need a relative tolerance between 0 and 1, such as 1e-10",
            args.tol
        ));
    }
    Options::until(1.0)
        .tolerances(args.tol, args.tol)
        .validate(0.0, 2)
        .map_err(|e| format!("--tol {:e}: {e}", args.tol))
}

/// Solves the sweep (or one shard of it), with arguments that passed [`check_arguments`]; writes
/// the part file, and for the whole sweep the report. Returns the summary for stdout.
fn solve_sweep(args: &RunArgs, out: &Path) -> Result<String, Box<dyn Error>> {
    let settings = Settings {
        n: args.n,
        lo: args.lo,
        hi: args.hi,
        g: args.g,
        tol: args.tol,
        threads: args.threads,
    };
    let shard = args.shard.unwrap_or(Shard::WHOLE);
    let all = grid(args.lo, args.hi, args.n);
    let mine: Vec<usize> = shard.items(all.len()).collect();
    let points: Vec<(f64, f64)> = mine.iter().map(|&i| all[i]).collect();

    // Timed interleaved, one thread then `threads`, ROUNDS times: the machine's load changes
    // between runs, and one pair alone gave speed-ups from 1.8 to 2.4 on 2 threads for sweeps of
    // a fraction of a second.
    let (mut serial, mut parallel) = (Vec::new(), Vec::new());
    let mut solved: Option<Vec<SweepPoint>> = None;
    for round in 1..=ROUNDS {
        for threads in [1, args.threads] {
            let pb = bar(
                points.len(),
                &format!(
                    "{threads} thread{}, round {round} of {ROUNDS}",
                    if threads == 1 { "" } else { "s" }
                ),
            );
            let tick = || pb.inc(1);
            let (run, seconds) = sweep(&points, args.g, args.tol, threads, &tick)?;
            pb.finish_and_clear();
            if let Some(first) = &solved {
                let same = first.len() == run.len()
                    && first.iter().zip(&run).all(|(a, b)| {
                        a.ratio.to_bits() == b.ratio.to_bits()
                            && a.failure == b.failure
                            && a.steps == b.steps
                    });
                if !same {
                    return Err(format!(
                        "the run on {threads} thread(s) in round {round} differs from the first"
                    )
                    .into());
                }
            } else {
                solved = Some(run);
            }
            if threads == 1 {
                &mut serial
            } else {
                &mut parallel
            }
            .push(seconds);
        }
    }
    let solved = solved.unwrap_or_default();
    let (t1, tn) = (median(&serial), median(&parallel));
    let speedups = round_speedups(&serial, &parallel);
    let seconds = |v: &[f64]| Value::Array(v.iter().map(|&x| number(x)).collect());
    let part = Part::new(
        "ensemble",
        settings.to_json(),
        all.len(),
        shard,
        json!({
            "serial_seconds": number(t1),
            "parallel_seconds": number(tn),
            "serial_rounds_seconds": seconds(&serial),
            "parallel_rounds_seconds": seconds(&parallel),
        }),
        mine.iter()
            .zip(&solved)
            .map(|(&i, p)| (i, sweep_point_to_json(p)))
            .collect(),
    );
    part.write_into(out)?;
    if shard == Shard::WHOLE {
        return report(&settings, &solved, t1, tn, &speedups, 1, out);
    }
    Ok(format!(
        "shard {shard}: {} of {} points, {t1:.2} s on 1 thread, {tn:.2} s on {} threads (medians \
         of {ROUNDS} interleaved rounds), in {}\n",
        points.len(),
        all.len(),
        args.threads,
        part.file_name()
    ))
}

/// Joins the parts and writes the report of the whole sweep.
fn merge_parts(files: &[PathBuf], out: &Path) -> Result<String, Box<dyn Error>> {
    let whole = Part::read_merged(files, "ensemble")?;
    let settings = Settings::from_json(&whole.settings)?;
    let points = whole
        .items
        .iter()
        .map(|(_, v)| sweep_point_from_json(v))
        .collect::<Result<Vec<_>, _>>()?;
    let (mut t1, mut tn) = (0.0, 0.0);
    let mut speedups = Vec::new();
    for r in &whole.runs {
        let about = Fields::of(&r.about, "shard's measurements")?;
        t1 += about.f64("serial_seconds")?;
        tn += about.f64("parallel_seconds")?;
        let rounds = |key: &str| -> Result<Vec<f64>, Box<dyn Error>> {
            about
                .array(key)?
                .iter()
                .map(|v| read_number(v).ok_or_else(|| format!("{key}: not a number").into()))
                .collect()
        };
        speedups.extend(round_speedups(
            &rounds("serial_rounds_seconds")?,
            &rounds("parallel_rounds_seconds")?,
        ));
    }
    whole.write_into(out)?;
    report(&settings, &points, t1, tn, &speedups, whole.runs.len(), out)
}

/// Rounds of the timed sweep: each solves the points on one thread, then on `--threads`.
const ROUNDS: usize = 3;

/// The median of `v` (the mean of the middle two for an even count); 0 for none.
fn median(v: &[f64]) -> f64 {
    let mut v = v.to_vec();
    v.sort_by(f64::total_cmp);
    match v.len() {
        0 => 0.0,
        n if n % 2 == 1 => v[n / 2],
        n => 0.5 * (v[n / 2 - 1] + v[n / 2]),
    }
}

/// The speed-up of each round: its serial time over its parallel time.
fn round_speedups(serial: &[f64], parallel: &[f64]) -> Vec<f64> {
    serial.iter().zip(parallel).map(|(s, p)| s / p).collect()
}

/// The error diagram draws the least and the greatest error of this many groups of neighbouring
/// points in z (all points when there are at most twice as many).
const ERROR_GROUPS: usize = 400;

/// The colour of the mark on the largest error (vermillion, unlike the points' blue).
const WORST_COLOUR: &str = "#D55E00";

/// Writes `ensemble.csv`, the diagrams and `ensemble.md` from the solved points of the whole grid
/// (in grid order) and the wall times of the serial and the parallel sweep (sums over the shards
/// of a merged run). Returns the summary for stdout.
fn report(
    args: &Settings,
    solved: &[SweepPoint],
    t1: f64,
    tn: f64,
    speedups: &[f64],
    shards: usize,
    out: &Path,
) -> Result<String, Box<dyn Error>> {
    let threads = args.threads;
    let speedup = t1 / tn;
    let (lo, hi) = speedups
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), &r| {
            (lo.min(r), hi.max(r))
        });
    let rounds = if speedups.is_empty() {
        String::new()
    } else {
        format!(
            " (rounds: {lo:.2}–{hi:.2} over {} interleaved pairs)",
            speedups.len()
        )
    };
    let failures: Vec<&SweepPoint> = solved.iter().filter(|p| p.failure.is_some()).collect();
    let ok: Vec<&SweepPoint> = solved.iter().filter(|p| p.failure.is_none()).collect();
    let max_of = |f: &dyn Fn(&SweepPoint) -> f64| ok.iter().map(|p| f(p)).fold(0.0f64, f64::max);
    // The largest error over the solved points; with none solved, there is none to state.
    let largest = |f: &dyn Fn(&SweepPoint) -> f64| {
        if ok.is_empty() {
            "— (no point solved)".to_string()
        } else {
            format!("{:.1e}", max_of(f))
        }
    };
    let ratio_err = largest(&|p| p.ratio_error());
    let u_err = largest(&|p| p.uniform_error);
    let c_err = largest(&|p| p.classical_error);
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
    // The errors by z, thinned to the least and greatest of each of ERROR_GROUPS groups of
    // neighbours in z, so that the largest error is drawn whatever the grid; it is also marked.
    let mut errors: Vec<(f64, f64)> = ok
        .iter()
        .map(|p| (p.z, p.ratio_error().max(1e-17)))
        .collect();
    errors.sort_by(|a, b| a.0.total_cmp(&b.0));
    let worst = ok
        .iter()
        .max_by(|a, b| a.ratio_error().total_cmp(&b.ratio_error()));
    let drawn = chetaev_plot::thin(&errors, ERROR_GROUPS);
    let errors_name = if drawn.len() < errors.len() {
        format!(
            "{} points, least and greatest of {ERROR_GROUPS} groups by z",
            errors.len()
        )
    } else {
        format!("all {} points", errors.len())
    };
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
    let mut error_figure = Figure::new("Relative error of the range ratio against z")
        .x_label("z = g h0 / v0²")
        .y_label("|ratio − closed form| / closed form")
        .log_x()
        .log_y()
        .line_styled(
            &errors_name,
            &drawn,
            Style {
                width: 0.0,
                markers: true,
                ..Style::default()
            },
        );
    if let Some(w) = worst {
        let e = w.ratio_error().max(1e-17);
        error_figure = error_figure.line_styled(
            &format!(
                "largest: {e:.1e} at z = {:.2e} (v0 = {:.3}, h0 = {:.3})",
                w.z, w.v0, w.h0
            ),
            &[(w.z, e)],
            Style {
                width: 3.0,
                markers: true,
                color: Some(WORST_COLOUR),
                ..Style::default()
            },
        );
    }
    error_figure.save(out.join("ensemble-error.svg"))?;

    let mut md = String::new();
    let _ = writeln!(
        md,
        "## Ensemble: the range ratio over {} points\n\n\
         `v0`, `h0` log-spaced over [{}, {}] ({} × {}), `g = {}`, rtol = {:e} with absolute \
         tolerances scaled to each motion (`scaled_atol`), every point solved to the impact (uniform \
         by Dop853, and by Rodas4 where Dop853 reports stiffness; classical by Dop853).\n\n\
         | | |\n|---|---|\n\
         | wall time, 1 thread | {} |\n\
         | wall time, {threads} threads | {} |\n\
         | speed-up | {speedup:.2}{rounds} |\n\
         | points solved / failed | {} / {} |\n\
         | uniform motions that needed Rodas4 | {rodas} |\n\
         | steps, all uniform motions | {steps} |\n\
         | largest relative error of the ratio | {ratio_err} |\n\
         | largest relative error of R_uniform / R_classical | {u_err} / {c_err} |\n\n\
         ![range ratio](ensemble-ratio.svg)\n\n![error](ensemble-error.svg)\n",
        solved.len(),
        args.lo,
        args.hi,
        args.n,
        args.n,
        args.g,
        args.tol,
        format_seconds(t1),
        format_seconds(tn),
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
    let mut summary = String::new();
    let over = if shards > 1 {
        format!(" (sums over {shards} shards)")
    } else {
        String::new()
    };
    let _ = writeln!(
        summary,
        "{} points on 1 thread: {t1:.2} s, on {threads} threads: {tn:.2} s{over}",
        solved.len()
    );
    let _ = writeln!(
        summary,
        "speed-up {speedup:.2}{rounds} on {threads} threads; {} solved, {} failed, {rodas} by \
         Rodas4; \
         largest ratio error {ratio_err}",
        ok.len(),
        failures.len(),
    );
    Ok(summary)
}
