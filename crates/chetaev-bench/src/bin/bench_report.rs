//! `bench-report`: turns the results of `cargo bench -p chetaev-bench` into the tables of the
//! performance report: the cost of one right-hand side against `n` and `k` with the fitted growth
//! exponent, where the time of one right-hand side of the paper's model goes, and the cost of an
//! unused constraint per right-hand side.
//!
//! Reads criterion's results where criterion writes them (`$CRITERION_HOME`, else
//! `$CARGO_TARGET_DIR/criterion`, else the workspace's `target/criterion` when run by cargo, else
//! `./target/criterion`) and writes `benchmarks.md`, `rhs-cost.csv` and `rhs-cost.svg` into
//! `--out` (default `./chetaev-bench-out/bench-report`).
//!
//! ```sh
//! cargo bench -p chetaev-bench
//! cargo run --release -p chetaev-bench --bin bench-report -- --out docs/performance
//! ```

use std::error::Error;
use std::fmt::Write as _;
use std::io::Write as _;
use std::path::PathBuf;
use std::process::ExitCode;

use chetaev_bench::cli::{exit, output_dir};
use chetaev_bench::criterion_results::{default_criterion_dir, parse_size, read_group, Estimate};
use chetaev_bench::measure::log_slope;
use chetaev_bench::report::format_seconds;
use chetaev_plot::{Figure, Style};
use clap::Parser;

/// Tables from criterion's results.
#[derive(Parser, Debug)]
#[command(name = "bench-report", version)]
struct Args {
    /// criterion's output directory [default: $CRITERION_HOME, else $CARGO_TARGET_DIR/criterion,
    /// else cargo's target/criterion].
    #[arg(long)]
    criterion: Option<PathBuf>,
    /// Output directory [default: ./chetaev-bench-out/bench-report].
    #[arg(long)]
    out: Option<PathBuf>,
}

fn main() -> ExitCode {
    exit("bench-report", run())
}

/// The number of constraints of a size class as a function of `n`.
type KOfN = fn(usize) -> usize;

/// Text for a Markdown table cell.
fn cell(s: &str) -> String {
    s.replace('|', "\\|")
}

fn ns(e: &Estimate) -> String {
    format_seconds(e.median_ns * 1e-9)
}

fn run() -> Result<(), Box<dyn Error>> {
    let args = Args::parse();
    let criterion = args.criterion.unwrap_or_else(default_criterion_dir);
    let stat = read_group(&criterion, "rhs_cost")?;
    if stat.is_empty() {
        return Err(format!(
            "no results under {}: run `cargo bench -p chetaev-bench` first (with the same \
             CARGO_TARGET_DIR), or pass --criterion DIR",
            criterion.display()
        )
        .into());
    }
    // Made only once there is something to write into it.
    let out = output_dir(args.out, "bench-report")?;
    let mut md = String::new();
    let dynamic = read_group(&criterion, "rhs_cost_dyn")?;
    let groups = [("static", &stat), ("run-time", &dynamic)];
    let sized = |group: &[Estimate]| -> Vec<(usize, usize, Estimate)> {
        group
            .iter()
            .filter_map(|e| parse_size(&e.function).map(|(n, k)| (n, k, e.clone())))
            .collect()
    };
    let sizes: Vec<Vec<(usize, usize, Estimate)>> = groups.iter().map(|(_, g)| sized(g)).collect();
    let mut ns_values: Vec<usize> = sizes.iter().flatten().map(|s| s.0).collect();
    ns_values.sort_unstable();
    ns_values.dedup();
    let classes: [(&str, KOfN); 3] = [("k = 0", |_| 0), ("k = 1", |_| 1), ("k = n/2", |n| n / 2)];
    let find =
        |g: usize, n: usize, k: usize| sizes[g].iter().find(|s| s.0 == n && s.1 == k).map(|s| &s.2);
    let _ = writeln!(
        md,
        "## Cost of one right-hand side\n\nOne evaluation of the reduced equations with `f64` on a chain of `n` \
         unit masses with anharmonic springs and `k` pair-speed constraints \
         (`chetaev::equations::evaluate`): static sizes (`Chain<N, K>`) and sizes known at run time \
         (`DynChain`, a `DynModel`), both from `chetaev_catalogue::benchmarks`. Median of \
         criterion's samples (95 % intervals in `rhs-cost.csv`).\n\n| n | static, k = 0 | static, k = 1 | static, k = n/2 | run-time, k = 0 | \
         run-time, k = 1 | run-time, k = n/2 |\n|---|---|---|---|---|---|---|"
    );
    let mut csv = String::from("sizes,n,k,median_ns,ci_low_ns,ci_high_ns\n");
    for (g, (label, _)) in groups.iter().enumerate() {
        for (n, k, e) in &sizes[g] {
            let _ = writeln!(
                csv,
                "{label},{n},{k},{},{},{}",
                e.median_ns, e.median_ci_ns.0, e.median_ci_ns.1
            );
        }
    }
    for &n in &ns_values {
        let cells: Vec<String> = (0..groups.len())
            .flat_map(|g| classes.iter().map(move |(_, k)| (g, k(n))))
            .map(|(g, k)| find(g, n, k).map_or("–".to_string(), ns))
            .collect();
        let _ = writeln!(md, "| {n} | {} |", cells.join(" | "));
    }
    let _ = writeln!(
        md,
        "\nGrowth exponent `p` of time ∝ n^p (least-squares fit of log time against log n):\n\n\
         | sizes | k | all n | n ≥ 6 |\n|---|---|---|---|"
    );
    let mut fig = Figure::new("One right-hand side against the number of coordinates")
        .x_label("n (coordinates)")
        .y_label("time per right-hand side [s]")
        .log_x()
        .log_y();
    let mut exponents = Vec::new();
    for (g, (label, _)) in groups.iter().enumerate() {
        for (c, (name, k)) in classes.iter().enumerate() {
            let pts: Vec<(f64, f64)> = ns_values
                .iter()
                .filter_map(|&n| find(g, n, k(n)).map(|e| (n as f64, e.median_ns * 1e-9)))
                .collect();
            if pts.len() < 2 {
                continue;
            }
            let large: Vec<(f64, f64)> = pts.iter().copied().filter(|p| p.0 >= 6.0).collect();
            // "–" where too few sizes were measured for a fit (a filtered `cargo bench`).
            let slope = |p: &[(f64, f64)]| {
                let s = log_slope(p);
                if s.is_finite() {
                    format!("{s:.2}")
                } else {
                    "–".to_string()
                }
            };
            let (all, big) = (slope(&pts), slope(&large));
            let _ = writeln!(md, "| {label} | {name} | {all} | {big} |");
            exponents.push((format!("{label}, {name}"), all, big));
            fig = fig.line_styled(
                &format!("{label}, {name}"),
                &pts,
                Style {
                    markers: true,
                    dashed: g == 1,
                    color: Some(chetaev_plot::PALETTE[c]),
                    ..Style::default()
                },
            );
        }
    }
    fig.save(out.join("rhs-cost.svg"))?;
    std::fs::write(out.join("rhs-cost.csv"), csv)?;
    md.push_str("\n![cost of one right-hand side](rhs-cost.svg)\n");

    let profile = read_group(&criterion, "profile")?;
    if !profile.is_empty() {
        let total = profile
            .iter()
            .find(|e| e.function == "dynamics")
            .map(|e| e.median_ns);
        let _ = writeln!(
            md,
            "\n## Where one right-hand side of the paper's model goes\n\n`(N, K) = (2, 1)` at the state of `t = 0.5 s`; \
             criterion medians; `dynamics` is the whole right-hand side \
             (`chetaev::equations::evaluate`).\n\n| part | time | share of `dynamics` |\n|---|---|---|"
        );
        let order = [
            "dynamics",
            "lagrangian_derivatives (passes A, B, C)",
            "velocity_hessian (pass A)",
            "constraint_derivatives (two passes)",
            "saddle::solve (3 × 3)",
            "dynamics over Dual64 (one Jacobian column)",
            "hand-written full rhs",
            "hand-written (42.28) rhs",
            "hand-written full jacobian",
        ];
        let rank = |e: &Estimate| {
            order
                .iter()
                .position(|o| *o == e.function)
                .unwrap_or(order.len())
        };
        let mut profile = profile.clone();
        profile.sort_by_key(|e| rank(e));
        for e in &profile {
            let share = total.map_or("–".to_string(), |t| {
                format!("{:.0} %", 100.0 * e.median_ns / t)
            });
            let _ = writeln!(md, "| {} | {} | {share} |", cell(&e.function), ns(e));
        }
    }

    let overhead = read_group(&criterion, "overhead")?;
    if !overhead.is_empty() {
        let base = overhead
            .iter()
            .find(|e| e.function.starts_with("K = 0"))
            .map(|e| e.median_ns);
        let _ = writeln!(
            md,
            "\n## An unused constraint, per right-hand side\n\nThe paper's particle, one evaluation of \
             the reduced equations (`chetaev::equations::evaluate`); ratio to `K = 0`.\n\n| model | time | ratio |\n|---|---|---|"
        );
        for e in &overhead {
            let r = base.map_or("–".to_string(), |b| format!("{:.2}", e.median_ns / b));
            let _ = writeln!(md, "| {} | {} | {r} |", cell(&e.function), ns(e));
        }
    }
    std::fs::write(out.join("benchmarks.md"), &md)?;
    // The files are written; a reader that leaves early only shortens this summary.
    let mut stdout = std::io::stdout().lock();
    for (name, all, big) in exponents {
        writeln!(
            stdout,
            "growth exponent, {name}: {all} (all n), {big} (n ≥ 6)"
        )?;
    }
    writeln!(stdout, "written to {}", out.join("benchmarks.md").display())?;
    stdout.flush()?;
    Ok(())
}
