//! `work-precision`: error against run time for every scene and method, the limit set by the
//! paper's model written out by hand, and the cost of constraints and diagnostics that a problem
//! does not use. Writes CSV, Markdown and SVG into an output directory (default
//! `docs/performance/`) and prints a summary.
//!
//! ```sh
//! cargo run --release -p chetaev-bench --bin work-precision
//! cargo run --release -p chetaev-bench --bin work-precision -- --quick --out /tmp/wp
//! ```

use std::error::Error;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use chetaev::prelude::*;
use chetaev_bench::measure::{ratio_at_error, Budget};
use chetaev_bench::overhead::{constraint_overhead, diagnostics_overhead, Comparison};
use chetaev_bench::report::{
    format_ratio, format_seconds, points_csv, points_markdown, ratio_at_tolerance_markdown,
    ratio_markdown,
};
use chetaev_bench::scenes;
use chetaev_bench::study::{curve, run_limit, run_scene, Outcome, Point, Scene, StudyConfig};
use chetaev_plot::{Figure, Style};
use clap::Parser;

/// Error against run time for chetaev's methods, ode_solvers and hand-written right-hand sides.
#[derive(Parser, Debug)]
#[command(version)]
struct Args {
    /// Output directory for CSV, Markdown and SVG (default: the workspace's docs/performance).
    #[arg(long)]
    out: Option<PathBuf>,
    /// A smoke run: four tolerances, four Rk4 step counts, one timed run each (seconds, not
    /// minutes; the numbers are not for publishing).
    #[arg(long)]
    quick: bool,
}

/// The error levels at which curves are compared.
const COMPARE_AT: [f64; 6] = [1e-6, 1e-8, 1e-10, 1e-11, 1e-12, 1e-13];

/// chetaev's methods in the order of the tables, with the colour of their lines.
const METHODS: [(&str, &str); 4] = [
    ("Dopri5", "#0072B2"),
    ("Dop853", "#D55E00"),
    ("Rodas4", "#009E73"),
    ("Rk4", "#CC79A7"),
];

fn default_out() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/performance")
}

fn main() -> ExitCode {
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("work-precision: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run() -> Result<(), Box<dyn Error>> {
    let args = Args::parse();
    let out = args.out.unwrap_or_else(default_out);
    std::fs::create_dir_all(&out)?;
    let out = out.canonicalize().unwrap_or(out);
    let mut config = StudyConfig::default();
    let mut rk4_steps = scenes::rk4_steps();
    if args.quick {
        config.tolerances = vec![1e-4, 1e-8, 1e-12, 1e-14];
        config.budget = Budget {
            min_repeats: 1,
            max_repeats: 1,
            min_seconds: 0.0,
        };
        rk4_steps = vec![16, 256, 4096, 16384];
    }
    let started = Instant::now();
    let mut results = String::new();
    let _ = writeln!(results, "# Work-precision results\n\n{}", machine());
    let _ = writeln!(
        results,
        "Tolerances {} (rtol = atol unless the scene says otherwise); median of at least {} timed runs \
         (more until {} s, at most {}) after one untimed run; step budget {} per run.\n",
        config
            .tolerances
            .iter()
            .map(|t| format!("{t:.0e}"))
            .collect::<Vec<_>>()
            .join(", "),
        config.budget.min_repeats,
        config.budget.min_seconds,
        config.budget.max_repeats,
        config.max_steps
    );

    let mut all = Vec::new();
    let mut uniform_scene = scenes::uniform_scene()?;
    let mut classical = scenes::classical_scene()?;
    let stiff = scenes::stiff_scene(config.max_steps)?;
    let mut particle3d = scenes::particle3d_scene()?;
    let mut two = scenes::two_runners_scene()?;
    if args.quick {
        uniform_scene.rk4_steps = Ok(rk4_steps.clone());
        classical.rk4_steps = Ok(rk4_steps.clone());
        particle3d.rk4_steps = Ok(rk4_steps.clone());
        two.rk4_steps = Ok(rk4_steps.clone());
    }
    all.extend(study(&uniform_scene, &config, &out, &mut results)?);
    all.extend(study(&classical, &config, &out, &mut results)?);
    all.extend(study(&stiff, &config, &out, &mut results)?);
    all.extend(study(&particle3d, &config, &out, &mut results)?);
    all.extend(study(&two, &config, &out, &mut results)?);

    limit(&uniform_scene, &config, &rk4_steps, &out, &mut results)?;
    overheads(&all, &config, &out, &mut results)?;

    let skipped = all
        .iter()
        .filter(|p| matches!(p.outcome, Outcome::Skipped(_)))
        .count();
    let failed = all
        .iter()
        .filter(|p| matches!(p.outcome, Outcome::Failed(_)))
        .count();
    let elapsed = started.elapsed().as_secs_f64();
    let _ = writeln!(
        results,
        "\n{} configurations: {} measured, {skipped} skipped, {failed} failed. Whole run {elapsed:.0} s.",
        all.len(),
        all.len() - skipped - failed
    );
    std::fs::write(out.join("results.md"), &results)?;
    println!(
        "{} configurations ({skipped} skipped, {failed} failed) in {elapsed:.0} s; written to {}",
        all.len(),
        out.display()
    );
    Ok(())
}

/// `nproc`, the processor and the compiler, for the report.
fn machine() -> String {
    let cores = std::thread::available_parallelism().map_or(0, |n| n.get());
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|m| m.trim().to_string())
        })
        .unwrap_or_else(|| "unknown".to_string());
    let rustc = std::process::Command::new("rustc")
        .arg("--version")
        .output()
        .ok()
        .and_then(|o| String::from_utf8(o.stdout).ok())
        .map_or("unknown".to_string(), |s| s.trim().to_string());
    format!("Machine: {cores} cores, {cpu}; {rustc}; release build, one thread.\n")
}

/// One line of a work-precision diagram: name, `(seconds, error)` points, style.
type PlotLine = (String, Vec<(f64, f64)>, Style);

fn svg_figure(title: &str, lines: &[PlotLine]) -> Figure {
    let mut fig = Figure::new(title)
        .x_label("median run time [s]")
        .y_label("error at the end time")
        .log_x()
        .log_y()
        .size(820.0, 520.0);
    for (name, pts, style) in lines {
        if !pts.is_empty() {
            fig = fig.line_styled(name, pts, *style);
        }
    }
    fig
}

/// `(seconds, error)` of a method's measured points, for plotting.
fn plot_curve(points: &[Point], method: &str) -> Vec<(f64, f64)> {
    curve(points, method)
        .into_iter()
        .map(|(e, s)| (s, e))
        .collect()
}

fn study<M, const N: usize, const K: usize>(
    scene: &Scene<M, N, K>,
    config: &StudyConfig,
    out: &Path,
    results: &mut String,
) -> Result<Vec<Point>, Box<dyn Error>>
where
    M: Model<N, K>,
{
    let start = Instant::now();
    let points = run_scene(scene, config, &mut |m| eprintln!("{}: {m}", scene.key));
    eprintln!("{}: {:.1} s", scene.key, start.elapsed().as_secs_f64());
    std::fs::write(out.join(format!("{}.csv", scene.key)), points_csv(&points))?;

    let mut lines = Vec::new();
    for (m, c) in METHODS {
        let style = Style {
            color: Some(c),
            markers: true,
            ..Style::default()
        };
        lines.push((m.to_string(), plot_curve(&points, m), style));
    }
    for (m, c) in [
        ("Dopri5 (ode_solvers)", "#0072B2"),
        ("Dop853 (ode_solvers)", "#D55E00"),
    ] {
        let style = Style {
            color: Some(c),
            dashed: true,
            markers: true,
            ..Style::default()
        };
        lines.push((m.to_string(), plot_curve(&points, m), style));
    }
    svg_figure(&scene.title, &lines).save(out.join(format!("{}.svg", scene.key)))?;

    let pairs = [
        ("Dopri5", "Dopri5 (ode_solvers)"),
        ("Dop853", "Dop853 (ode_solvers)"),
    ];
    let mut md = format!(
        "## {}\n\nError: {}.\n\n![{}]({}.svg)\n\n",
        scene.title, scene.reference, scene.title, scene.key
    );
    md.push_str(&ratio_markdown(&points, &pairs, &COMPARE_AT));
    md.push('\n');
    let by_tolerance = ratio_at_tolerance_markdown(&points, &pairs);
    if !by_tolerance.is_empty() {
        md.push_str(&by_tolerance);
        md.push('\n');
    }
    md.push_str(&points_markdown(&points));
    std::fs::write(out.join(format!("{}.md", scene.key)), &md)?;
    results.push_str(&md);
    results.push('\n');
    Ok(points)
}

/// chetaev against the hand-written right-hand sides of the paper's model, timed interleaved.
fn limit<M: Model<2, 1>>(
    scene: &Scene<M, 2, 1>,
    config: &StudyConfig,
    rk4_steps: &[usize],
    out: &Path,
    results: &mut String,
) -> Result<(), Box<dyn Error>> {
    let start = Instant::now();
    eprintln!("limit: chetaev, hand-written (42.28) and full, interleaved");
    let (reduced_hw, full_hw) = (scenes::reduced_handwritten(), scenes::full_handwritten());
    let points = run_limit(scene, &reduced_hw, &full_hw, config, rk4_steps);
    eprintln!("limit: {:.1} s", start.elapsed().as_secs_f64());
    let of = |suffix: &str| -> Vec<Point> {
        points
            .iter()
            .filter(|p| p.method.ends_with(suffix))
            .cloned()
            .collect()
    };
    let (reduced, full) = (of(reduced_hw.name), of(full_hw.name));
    std::fs::write(out.join("limit.csv"), points_csv(&points))?;

    for (form, suffix, title) in [
        (
            "reduced",
            "hand-written (42.28)",
            "chetaev against the reduced equation (42.28) by hand",
        ),
        (
            "full",
            "hand-written full",
            "chetaev against a = g − (g·v)v/|v|² by hand",
        ),
    ] {
        let mut lines = Vec::new();
        for (m, c) in METHODS {
            lines.push((
                format!("{m} (chetaev)"),
                plot_curve(&points, m),
                Style {
                    color: Some(c),
                    markers: true,
                    ..Style::default()
                },
            ));
            lines.push((
                format!("{m} {suffix}"),
                plot_curve(&points, &format!("{m} {suffix}")),
                Style {
                    color: Some(c),
                    dashed: true,
                    markers: true,
                    ..Style::default()
                },
            ));
        }
        svg_figure(title, &lines).save(out.join(format!("limit-{form}.svg")))?;
    }

    let mut md = String::from(
        "## The limit: the paper's model by hand\n\nchetaev's time over the hand-written system's time at \
         equal error (log time interpolated linearly in log error), same methods, same driver, same \
         end time and error measure as the uniform scene. At every setting the three are timed \
         interleaved (one run of each in turn), so that they see the same background load.\n\n![chetaev against (42.28)](limit-reduced.svg)\n\n\
         ![chetaev against the full form](limit-full.svg)\n\n",
    );
    let mut pairs_owned = Vec::new();
    for (m, _) in METHODS {
        pairs_owned.push((m.to_string(), format!("{m} hand-written (42.28)")));
        pairs_owned.push((m.to_string(), format!("{m} hand-written full")));
    }
    let pairs: Vec<(&str, &str)> = pairs_owned
        .iter()
        .map(|(a, b)| (a.as_str(), b.as_str()))
        .collect();
    md.push_str(&ratio_markdown(&points, &pairs, &COMPARE_AT));
    md.push_str("\nTime per right-hand side (median over the measured points of time / RHS evaluations; \
                 includes the driver's and the method's own work per stage):\n\n\
                 | method | chetaev | hand-written (42.28) | hand-written full |\n|---|---|---|---|\n");
    for (m, _) in METHODS {
        let per = |name: &str| {
            let mut v: Vec<f64> = points
                .iter()
                .filter(|p| p.method == name && p.is_measured() && p.rhs_evaluations > 0)
                .map(|p| p.seconds / p.rhs_evaluations as f64)
                .collect();
            chetaev_bench::measure::median(&mut v)
        };
        let _ = writeln!(
            md,
            "| {m} | {} | {} | {} |",
            format_seconds(per(m)),
            format_seconds(per(&format!("{m} hand-written (42.28)"))),
            format_seconds(per(&format!("{m} hand-written full")))
        );
    }
    md.push_str("\n### Hand-written points\n\n");
    md.push_str(&points_markdown(&reduced));
    md.push('\n');
    md.push_str(&points_markdown(&full));
    std::fs::write(out.join("limit.md"), &md)?;
    results.push_str(&md);
    results.push('\n');

    println!("chetaev / hand-written at equal error:");
    for (a, b) in &pairs {
        let ratios: Vec<String> = [1e-10, 1e-11, 1e-12, 1e-13]
            .iter()
            .map(|&e| {
                format!(
                    "{e:.0e}: {}",
                    format_ratio(ratio_at_error(&curve(&points, a), &curve(&points, b), e))
                )
            })
            .collect();
        println!("  {a} / {b}: {}", ratios.join(", "));
    }
    Ok(())
}

fn comparison_row(md: &mut String, c: &Comparison) {
    let _ = writeln!(
        md,
        "| {} | {} | {} | {} | {:.2} | {:.2} | {} / {} | {} / {} | {:.1e} |",
        c.what,
        c.setting,
        format_seconds(c.lean_seconds),
        format_seconds(c.costly_seconds),
        c.ratio(),
        c.ratio_per_rhs(),
        c.lean_rhs,
        c.costly_rhs,
        c.lean_output,
        c.costly_output,
        c.end_difference
    );
}

/// Constraints and diagnostics that a problem does not use, and the Jacobians of explicit methods.
fn overheads(
    all: &[Point],
    config: &StudyConfig,
    out: &Path,
    results: &mut String,
) -> Result<(), Box<dyn Error>> {
    eprintln!("overheads");
    let p = scenes::PAPER;
    let b = &config.budget;
    let rows = [
        constraint_overhead(&p, Dopri5::default(), 1e-8, b)?,
        constraint_overhead(&p, Dop853::default(), 1e-12, b)?,
        constraint_overhead(&p, Rodas4, 1e-10, b)?,
        diagnostics_overhead(&p, Dopri5::default(), 1e-8, b)?,
        diagnostics_overhead(&p, Dop853::default(), 1e-12, b)?,
        diagnostics_overhead(&p, Rodas4, 1e-10, b)?,
    ];
    let mut md = String::from(
        "## Paying only for what is used\n\nWhole solves of the paper's particle to its impact time \
         (Record::State and output at the end unless said otherwise). Ratio = costly / lean.\n\n\
         | comparison | setting | lean | costly | ratio | ratio per RHS | RHS lean / costly | output evaluations lean / costly | end-state difference |\n\
         |---|---|---|---|---|---|---|---|---|\n",
    );
    for c in &rows {
        comparison_row(&mut md, c);
        println!("{} ({}): ratio {:.2}", c.what, c.setting, c.ratio());
    }
    let explicit: Vec<&Point> = all
        .iter()
        .filter(|p| !p.method.starts_with("Rodas4") && !matches!(p.outcome, Outcome::Skipped(_)))
        .collect();
    let explicit_jac: usize = explicit.iter().map(|p| p.jacobian_evaluations).sum();
    let rodas: Vec<&Point> = all
        .iter()
        .filter(|p| p.method == "Rodas4" && !matches!(p.outcome, Outcome::Skipped(_)))
        .collect();
    let rodas_jac: usize = rodas.iter().map(|p| p.jacobian_evaluations).sum();
    let _ = writeln!(
        md,
        "\nJacobians: the {} runs of explicit methods above (Dopri5, Dop853, Rk4 and ode_solvers, \
         every scene, measured or failed) evaluated {explicit_jac} Jacobians in all \
         (`sol.stats.jacobian_evaluations`); the {} runs of Rodas4 evaluated {rodas_jac}.",
        explicit.len(),
        rodas.len()
    );
    println!(
        "Jacobian evaluations: explicit methods {explicit_jac} over {} runs, Rodas4 {rodas_jac} over {} runs",
        explicit.len(),
        rodas.len()
    );
    std::fs::write(out.join("overheads.md"), &md)?;
    results.push_str(&md);
    Ok(())
}
