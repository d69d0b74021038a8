//! `chetaev sweep` and `chetaev merge`: a scene over a grid or a random sample of its parameters
//! and initial values, in parallel, whole or one shard at a time (docs/sweeps.md).

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

use chetaev_parts::Shard;
use chetaev_scene::output::count;
use chetaev_scene::sweep::table::{self, Table};
use chetaev_scene::sweep::{Axis, Sweep, SweepArgs};
use chetaev_scene::Error;
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};

use crate::{eprint, fail, report, Stdout};

/// The exit codes of `chetaev sweep` and `chetaev merge`.
pub const SWEEP_EXIT_CODES: &str = "\
Exit codes:
  0  every run reached its end time or a terminal event
  1  some runs failed or were refused; every run is still a row of the table, with its status
     and reason
  2  the scene or the sweep cannot be run as written (nothing is run), the part files do not
     make one sweep, an output file cannot be written, or the command line is wrong";

/// What `chetaev sweep` is given.
#[derive(Args)]
pub struct SweepCommand {
    /// The scene file (TOML); its `[sweep]` table, if any, says what varies and what is collected.
    scene: PathBuf,
    /// A variable and its values, added to the scene's [sweep] (or replacing its entry):
    /// NAME=FROM:TO:COUNT (a grid; :log for a logarithmic one), NAME=A,B,C (a list), NAME=FROM:TO
    /// (sampled at random, with --samples). NAME is a parameter, initial.x or initial.x_dot.
    #[arg(long, value_name = "NAME=SPEC")]
    vary: Vec<String>,
    /// Random samples per grid point, of the variables given as FROM:TO.
    #[arg(long, value_name = "N")]
    samples: Option<usize>,
    /// The seed of the random samples (default 0): the same seed gives the same points everywhere.
    #[arg(long, value_name = "S")]
    seed: Option<u64>,
    /// How the random samples are drawn: uniform (independent) or latin (a Latin hypercube).
    #[arg(long, value_name = "DESIGN")]
    design: Option<String>,
    /// The quantities to collect, comma-separated (replacing the scene's `collect`): impact.t,
    /// impact.x, impact.count, end.y, x@1.5, max.y, max_abs.mu_1, max.residual, max_abs.balance,
    /// d(impact.t)/d(v0). Default: every event's time and state, the end's, and the extremes of
    /// the multipliers, the residual and the energy balance.
    #[arg(long, value_name = "LIST", value_delimiter = ',')]
    collect: Option<Vec<String>>,
    /// Write into this directory (default: the scene's output.directory with `-sweep`).
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    /// Run only shard K of N (K from 1 to N, as Slurm's --array=1-N): the points i, counted from
    /// 0, with i mod N = K − 1; writes sweep.part-K-of-N.json for `chetaev merge`.
    #[arg(long, value_name = "K/N")]
    shard: Option<Shard>,
    /// Threads to run on (default: every core).
    #[arg(long, value_name = "N")]
    jobs: Option<usize>,
    /// Run more than a million points.
    #[arg(long)]
    yes: bool,
    /// Print nothing but errors (no summary, no progress bar).
    #[arg(long)]
    quiet: bool,
}

/// What `chetaev merge` is given.
#[derive(Args)]
pub struct MergeCommand {
    /// The part files of every shard (sweep.part-K-of-N.json); a merged sweep.json counts as all
    /// of its shards.
    #[arg(required = true)]
    parts: Vec<PathBuf>,
    /// Write the whole sweep's files into this directory.
    #[arg(long, value_name = "DIR", default_value = ".")]
    out: PathBuf,
    /// Print nothing but errors.
    #[arg(long)]
    quiet: bool,
}

/// Runs `chetaev sweep`.
pub fn sweep(c: SweepCommand) -> ExitCode {
    let args = SweepArgs {
        vary: c.vary,
        samples: c.samples,
        seed: c.seed,
        design: c.design,
        collect: c.collect,
        yes: c.yes,
    };
    let sweep = match Sweep::load(&c.scene, &args) {
        Ok(s) => s,
        Err(e) => return fail(&e),
    };
    let shard = c.shard.unwrap_or(Shard::WHOLE);
    let items: Vec<usize> = shard.items(sweep.len()).collect();
    let out = c.out.unwrap_or_else(|| {
        let mut dir = sweep.scene.output.directory.clone().into_os_string();
        dir.push("-sweep");
        PathBuf::from(dir)
    });
    if let Err(e) = std::fs::create_dir_all(&out) {
        return fail(&Error::Write {
            path: out.display().to_string(),
            reason: e.to_string(),
        });
    }
    let pool = match rayon::ThreadPoolBuilder::new()
        .num_threads(c.jobs.unwrap_or(0))
        .build()
    {
        Ok(p) => p,
        Err(e) => {
            eprint(&format!("error: cannot start the threads: {e}\n"));
            return ExitCode::from(2);
        }
    };
    let bar = if c.quiet {
        ProgressBar::hidden()
    } else {
        ProgressBar::new(items.len() as u64)
    };
    bar.set_style(
        ProgressStyle::with_template(
            "{bar:40} {pos}/{len} runs, {elapsed} elapsed, about {eta} left",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let done = AtomicUsize::new(0);
    let start = Instant::now();
    let ran = pool.install(|| {
        sweep.run_part(shard, &|| {
            // Drawing is rate-limited by the bar itself; counting is cheap.
            let d = done.fetch_add(1, Ordering::Relaxed) + 1;
            bar.set_position(d as u64);
        })
    });
    bar.finish_and_clear();
    let seconds = start.elapsed().as_secs_f64();
    let (part, table) = match ran {
        Ok(x) => x,
        Err(e) => return fail(&e),
    };
    let mut stdout = Stdout::new();
    if !c.quiet {
        stdout.print(&format!(
            "{}: {} of {} in {:.3} s ({:.0} runs/s on {})\n  varied   {}\n",
            c.scene.display(),
            if shard == Shard::WHOLE {
                count(items.len(), "run", "runs")
            } else {
                format!("shard {shard}, {}", count(items.len(), "run", "runs"))
            },
            count(sweep.len(), "point", "points"),
            seconds,
            items.len() as f64 / seconds.max(1e-9),
            count(pool.current_num_threads(), "thread", "threads"),
            describe_varied(&sweep),
        ));
    }
    if shard.n() > 1 {
        if let Err(e) = part.write_into(&out) {
            eprint(&format!("error: {e}\n"));
            return stdout.finish(2);
        }
        if !c.quiet {
            stdout.print(&outcome_lines(&table));
            stdout.print(&format!(
                "  wrote    {} into {}; join the shards with `chetaev merge --out DIR {}/sweep.part-*-of-{}.json`\n",
                part.file_name(),
                out.display(),
                out.display(),
                shard.n()
            ));
        }
        return stdout.finish(exit_code(&table));
    }
    finish(stdout, &out, &part, &table, c.quiet)
}

/// Runs `chetaev merge`.
pub fn merge(c: MergeCommand) -> ExitCode {
    let (whole, table) = match table::merge(&c.parts) {
        Ok(x) => x,
        Err(e) => return fail(&e),
    };
    let mut stdout = Stdout::new();
    if !c.quiet {
        stdout.print(&format!(
            "merged {} ({}) of {}\n",
            count(whole.runs.len(), "shard", "shards"),
            count(table.rows.len(), "run", "runs"),
            table.title
        ));
    }
    finish(stdout, &c.out, &whole, &table, c.quiet)
}

fn finish(
    mut stdout: Stdout,
    out: &Path,
    whole: &chetaev_parts::Part,
    table: &Table,
    quiet: bool,
) -> ExitCode {
    match table::write_whole(out, whole, table) {
        Ok(written) => {
            if !quiet {
                stdout.print(&outcome_lines(table));
                let names: Vec<String> = written
                    .iter()
                    .filter_map(|f| f.file_name())
                    .map(|n| n.to_string_lossy().into_owned())
                    .collect();
                stdout.print(&format!(
                    "  wrote    {} into {}\n",
                    names.join(", "),
                    out.display()
                ));
            }
        }
        Err(e) => {
            report(&e);
            return stdout.finish(2);
        }
    }
    stdout.finish(exit_code(table))
}

fn exit_code(table: &Table) -> u8 {
    let (_, failed, refused) = table.counts();
    if failed + refused > 0 {
        // Why, on standard error too.
        eprint(&format!(
            "error: {} failed and {} refused (see the status and reason columns)\n",
            count(failed, "run", "runs"),
            refused
        ));
        1
    } else {
        0
    }
}

/// The counts of runs by outcome, and the first few failures with their reasons.
fn outcome_lines(table: &Table) -> String {
    let (ok, failed, refused) = table.counts();
    let mut s = format!(
        "  outcome  {ok} reached the end or a terminal event, {failed} failed, {refused} refused\n"
    );
    let bad: Vec<&table::Row> = table
        .rows
        .iter()
        .filter(|r| !r.status.is_success())
        .collect();
    for r in bad.iter().take(5) {
        let at: Vec<String> = table
            .variables
            .iter()
            .zip(&r.values)
            .map(|(n, v)| format!("{n} = {v}"))
            .collect();
        s.push_str(&format!(
            "  {:<8} run {} ({}): {}\n",
            r.status.text(),
            r.index,
            at.join(", "),
            r.reason
        ));
    }
    if bad.len() > 5 {
        s.push_str(&format!(
            "  ...      and {} more in sweep.csv\n",
            bad.len() - 5
        ));
    }
    s
}

fn describe_varied(sweep: &Sweep) -> String {
    let parts: Vec<String> = sweep
        .varied
        .iter()
        .map(|v| match &v.axis {
            Axis::Values(values) => format!(
                "{} ({})",
                v.variable.name(),
                count(values.len(), "value", "values")
            ),
            Axis::Random { from, to, .. } => format!(
                "{} (random in [{from}, {to}], {} {})",
                v.variable.name(),
                sweep.samples,
                sweep.design.name()
            ),
        })
        .collect();
    parts.join(", ")
}
