//! `chetaev-hairer-bench`: chetaev's `Dop853`/`Dopri5` against Hairer's DOP853/DOPRI5, interleaved
//! in one process, compared at equal error. See README.md.

use std::time::Duration;

use clap::{Parser, ValueEnum};
use serde_json::{json, Value};

use chetaev_hairer_bench::compare::{
    compare, hairer_once, Budget, Comparison, Outcome, Pair, Point,
};
use chetaev_hairer_bench::hairer::{build_info, Code};
use chetaev_hairer_bench::problems::{arenstorf, particle, Problem};
use chetaev_hairer_bench::timing::Estimator;

/// How the rounds' times are summarised.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum EstimatorArg {
    /// Median over rounds (ratio: median of the per-round ratios).
    Median,
    /// Minimum over rounds (ratio of the minima): for a machine whose load comes and goes.
    Min,
}

/// chetaev's Dop853 and Dopri5 against E. Hairer's Fortran DOP853 and DOPRI5, at equal error.
#[derive(Parser, Debug)]
#[command(version, about)]
struct Cli {
    /// Interleaved rounds per tolerance (the medians are over these).
    #[arg(long, default_value_t = 21)]
    rounds: usize,
    /// Shortest timed batch, in milliseconds.
    #[arg(long, default_value_t = 5.0)]
    min_batch_ms: f64,
    /// Tolerances per decade from 1e-3 to 1e-13 (1 gives 1e-3, 1e-4, ..., 1e-13).
    #[arg(long, default_value_t = 1)]
    per_decade: u32,
    /// A quick look: every second decade of tolerance, 5 rounds, 2 ms batches.
    #[arg(long)]
    quick: bool,
    /// How the rounds' times per solve are summarised.
    #[arg(long, value_enum, default_value_t = EstimatorArg::Median)]
    estimator: EstimatorArg,
    /// Also write every number to this JSON file.
    #[arg(long, value_name = "PATH")]
    json: Option<std::path::PathBuf>,
}

fn main() -> Result<(), String> {
    let cli = Cli::parse();
    if !(cli.min_batch_ms.is_finite() && cli.min_batch_ms > 0.0) {
        return Err(format!(
            "--min-batch-ms {} : give a positive number of milliseconds, e.g. 5",
            cli.min_batch_ms
        ));
    }
    let estimator = match cli.estimator {
        EstimatorArg::Median => Estimator::Median,
        EstimatorArg::Min => Estimator::Min,
    };
    let (tolerances, budget) = if cli.quick {
        (
            (3..=13)
                .step_by(2)
                .map(|k| 10f64.powi(-k))
                .collect::<Vec<_>>(),
            Budget {
                rounds: 5,
                min_batch: Duration::from_millis(2),
                estimator,
            },
        )
    } else {
        let k = cli.per_decade.max(1);
        (
            (3 * k..=13 * k)
                .map(|i| 10f64.powf(-f64::from(i) / f64::from(k)))
                .collect(),
            Budget {
                rounds: cli.rounds.max(1),
                min_batch: Duration::from_secs_f64(cli.min_batch_ms * 1e-3),
                estimator,
            },
        )
    };

    let machine = machine();
    println!("chetaev vs E. Hairer's DOP853 (2009) and DOPRI5 (1996/2005), at equal error");
    println!("  CPU: {}", machine["cpu"].as_str().unwrap_or("unknown"));
    println!(
        "  load average at start: {}",
        machine["load_start"].as_str().unwrap_or("unknown")
    );
    println!(
        "  Fortran: {} with {}",
        build_info::COMPILER,
        build_info::FLAGS
    );
    println!(
        "  {} rounds per tolerance, batches of at least {:.1} ms, rtol = atol = 1e-3 ... 1e-13 ({} values)",
        budget.rounds,
        budget.min_batch.as_secs_f64() * 1e3,
        tolerances.len()
    );
    match estimator {
        Estimator::Median => {
            println!("  time = median over rounds of (batch time / solves per batch)");
            println!(
                "  C/H@tol  = median over rounds of t_chetaev / t_Hairer at the same tolerance"
            );
        }
        Estimator::Min => {
            println!("  time = minimum over rounds of (batch time / solves per batch)");
            println!("  C/H@tol  = min t_chetaev / min t_Hairer at the same tolerance");
        }
    }
    println!(
        "  C/H@errC = t_chetaev / t_Hairer(err_chetaev): Hairer's log t interpolated in log err"
    );
    println!(
        "  C/H@errH = t_chetaev(err_Hairer) / t_Hairer: chetaev's log t interpolated in log err"
    );
    println!("  (no extrapolation: '-' where the error lies outside the other code's range)");
    println!("  IQR = interquartile range of the per-round ratios t_chetaev / t_Hairer\n");
    let cores = machine["cores"].as_f64().unwrap_or(1.0);
    let load1 = machine["load_start"]
        .as_str()
        .and_then(|s| s.split_whitespace().next())
        .and_then(|s| s.parse::<f64>().ok());
    if let Some(load) = load1.filter(|&l| l > cores - 0.5) {
        println!(
            "  WARNING: load average {load} on {cores} cores: other processes compete for the CPU and \
             the times will be noisy (see the IQR column). Rerun on an idle machine, or with \
             --estimator min and more --rounds.\n"
        );
    }

    let problems = [arenstorf(), particle()];
    let mut checks = Vec::new();
    for p in &problems {
        checks.push(reference_check(p));
    }
    println!();

    let mut comparisons = Vec::new();
    for p in &problems {
        for pair in [Pair::Dop853, Pair::Dopri5] {
            let mut progress =
                |pt: &Point| eprint!("  {} {} {:.0e} done\r", p.name, pair.code().name(), pt.tol);
            let c = compare(p, pair, &tolerances, budget, &mut progress);
            eprint!("{:60}\r", "");
            print_table(&c);
            comparisons.push(c);
        }
    }
    print_summary(&comparisons);
    let load_end = loadavg();
    println!("\n  load average at end: {load_end}");

    if let Some(path) = &cli.json {
        let doc = json!({
            "machine": machine,
            "load_end": load_end,
            "fortran": { "compiler": build_info::COMPILER, "flags": build_info::FLAGS },
            "rounds": budget.rounds,
            "estimator": format!("{estimator:?}"),
            "min_batch_ms": budget.min_batch.as_secs_f64() * 1e3,
            "reference_checks": checks,
            "comparisons": comparisons.iter().map(comparison_json).collect::<Vec<_>>(),
        });
        let text = serde_json::to_string_pretty(&doc).map_err(|e| e.to_string())?;
        std::fs::write(path, text).map_err(|e| format!("writing {}: {e}", path.display()))?;
        println!("  wrote {}", path.display());
    }
    Ok(())
}

/// The CPU model, core count and load average (Linux; "unknown" elsewhere).
fn machine() -> Value {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|m| m.trim().to_string())
        })
        .unwrap_or_else(|| "unknown".to_string());
    let cores = std::thread::available_parallelism().map_or(0, |n| n.get());
    json!({ "cpu": cpu, "cores": cores, "load_start": loadavg() })
}

/// The 1, 5 and 15 minute load averages from /proc/loadavg.
fn loadavg() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .ok()
        .map(|s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_else(|| "unknown".to_string())
}

/// How far DOP853 at `rtol = atol = 1e-14` lands from the reference: the floor below which the
/// errors of the table say nothing.
fn reference_check(p: &Problem) -> Value {
    let tol = 1e-14;
    match hairer_once(Code::Dop853, p, tol) {
        Ok(o) => {
            println!(
                "  {}: reference = {}; DOP853 at rtol = atol = 1e-14 lands {:.2e} from it",
                p.name, p.reference_source, o.error
            );
            json!({ "problem": p.name, "reference": p.reference, "reference_source": p.reference_source,
                    "dop853_tol": tol, "dop853_error": o.error, "dop853_y": o.y })
        }
        Err(e) => {
            println!("  {}: reference check failed: {e}", p.name);
            json!({ "problem": p.name, "error": e })
        }
    }
}

fn micros(s: f64) -> String {
    format!("{:.1}", s * 1e6)
}

fn opt(v: Option<f64>, prec: usize) -> String {
    v.map_or_else(|| "-".to_string(), |x| format!("{x:.prec$}"))
}

fn print_table(c: &Comparison) {
    let code = c.pair.code().name();
    let ours = match c.pair {
        Pair::Dop853 => "Dop853",
        Pair::Dopri5 => "Dopri5",
    };
    println!("{}: chetaev {ours} (C) vs Hairer {code} (H)", c.problem);
    println!(
        "  {:>7} {:>9} {:>9} {:>9} {:>9} {:>7} {:>5} {:>8} {:>8} {:>13} {:>11} {:>7}",
        "tol",
        "err C",
        "err H",
        "t C [us]",
        "t H [us]",
        "C/H@tol",
        "IQR",
        "C/H@errC",
        "C/H@errH",
        "rhs evals C/H",
        "accepted C/H",
        "rejected C/H"
    );
    for ((p, r), r2) in c
        .points
        .iter()
        .zip(&c.ratio_at_chetaev_error)
        .zip(&c.ratio_at_hairer_error)
    {
        match (&p.chetaev, &p.hairer) {
            (Ok(a), Ok(b)) => {
                let (ta, tb, rt, iqr) = p.timing.as_ref().map_or(
                    ("-".into(), "-".into(), "-".into(), "-".into()),
                    |t| {
                        (
                            micros(t.a),
                            micros(t.b),
                            format!("{:.3}", t.ratio),
                            format!("{:.2}", t.ratio_iqr),
                        )
                    },
                );
                println!(
                    "  {:>7.1e} {:>9.2e} {:>9.2e} {:>9} {:>9} {:>7} {:>5} {:>8} {:>8} {:>13} {:>11} {:>7}",
                    p.tol,
                    a.error,
                    b.error,
                    ta,
                    tb,
                    rt,
                    iqr,
                    opt(*r, 3),
                    opt(*r2, 3),
                    format!("{}/{}", a.evaluations, b.evaluations),
                    format!("{}/{}", a.accepted, b.accepted),
                    format!("{}/{}", a.rejected, b.rejected),
                );
            }
            (a, b) => println!(
                "  {:>7.1e} failed: chetaev {:?}, Hairer {:?}",
                p.tol,
                a.as_ref().err(),
                b.as_ref().err()
            ),
        }
    }
    println!(
        "  C/H at equal error (both readings): median {}, geometric mean {}, min {}, max {} over {} values\n",
        opt(c.median_ratio(), 3),
        opt(c.geometric_mean(), 3),
        opt(c.min_ratio(), 3),
        opt(c.max_ratio(), 3),
        c.ratio_count()
    );
}

fn print_summary(cs: &[Comparison]) {
    println!("Summary: time of chetaev / time of Hairer at equal error");
    println!(
        "  {:<10} {:<15} {:>7} {:>9} {:>7} {:>7} {:>7}",
        "problem", "method", "median", "geo-mean", "min", "max", "points"
    );
    for c in cs {
        println!(
            "  {:<10} {:<15} {:>7} {:>9} {:>7} {:>7} {:>7}",
            c.problem,
            format!("{:?}/{}", c.pair, c.pair.code().name()),
            opt(c.median_ratio(), 3),
            opt(c.geometric_mean(), 3),
            opt(c.min_ratio(), 3),
            opt(c.max_ratio(), 3),
            c.ratio_count()
        );
    }
}

fn outcome_json(o: &Result<Outcome, String>) -> Value {
    match o {
        Ok(o) => json!({ "y": o.y, "error": o.error, "rhs_evaluations": o.evaluations,
                         "accepted": o.accepted, "rejected": o.rejected }),
        Err(e) => json!({ "failed": e }),
    }
}

fn comparison_json(c: &Comparison) -> Value {
    json!({
        "problem": c.problem,
        "chetaev": format!("{:?}", c.pair),
        "hairer": c.pair.code().name(),
        "ratio_at_equal_error_median": c.median_ratio(),
        "ratio_at_equal_error_geometric_mean": c.geometric_mean(),
        "ratio_at_equal_error_min": c.min_ratio(),
        "ratio_at_equal_error_max": c.max_ratio(),
        "points": c.points.iter().zip(&c.ratio_at_chetaev_error).zip(&c.ratio_at_hairer_error).map(|((p, r), r2)| json!({
            "tol": p.tol,
            "chetaev": outcome_json(&p.chetaev),
            "hairer": outcome_json(&p.hairer),
            "time_chetaev_s": p.timing.as_ref().map(|t| t.a),
            "time_hairer_s": p.timing.as_ref().map(|t| t.b),
            "ratio_at_tol": p.timing.as_ref().map(|t| t.ratio),
            "ratio_at_tol_iqr": p.timing.as_ref().map(|t| t.ratio_iqr),
            "ratio_at_chetaev_error": r,
            "ratio_at_hairer_error": r2,
            "batch_chetaev": p.timing.as_ref().map(|t| t.batch_a),
            "batch_hairer": p.timing.as_ref().map(|t| t.batch_b),
            "rounds": p.timing.as_ref().map(|t| t.rounds),
            "samples_chetaev_s": p.timing.as_ref().map(|t| &t.samples_a),
            "samples_hairer_s": p.timing.as_ref().map(|t| &t.samples_b),
        })).collect::<Vec<_>>(),
    })
}
