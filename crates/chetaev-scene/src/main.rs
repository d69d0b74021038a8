//! `chetaev`: solve a scene file and write the tables and pictures it asks for.
//!
//! Exit codes: 0 success (the end time or a terminal event was reached, and every value written is
//! finite), 1 the integration failed or wrote a value that is not finite (what was computed is
//! still written, and why is printed to standard error), 2 the scene cannot be run as written, its
//! output cannot be written, or standard output cannot be written. `--help` lists them
//! ([`EXIT_CODES`], [`RUN_EXIT_CODES`]).
//!
//! Standard output closed early (`chetaev run scene.toml | head`) ends the printing quietly; the
//! run still writes its files and exits with its own code.

mod command_sweep;

use chetaev::integrate::Method;
use std::io::{self, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand};

use chetaev::prelude::{Status, Warning};
use chetaev_scene::output::{self, count, Plan, MANIFEST};
use chetaev_scene::{Error, Scene};

/// The exit codes of `chetaev run`, as [`run`] returns them.
const RUN_EXIT_CODES: &str = "\
Exit codes:
  0  the end time or a terminal event was reached, and every value written is finite
  1  the integration failed, or a value written is NaN or infinite; what was computed is
     still written, and the reason is printed to standard error (and in the summary)
  2  the scene cannot be run as written, the output directory cannot be used (checked before
     integrating), an output file cannot be written, standard output cannot be written (a
     closed pipe is not an error: the run goes on quietly), or the command line is wrong";

/// The exit codes of every command, as [`main`] returns them.
const EXIT_CODES: &str = "\
Exit codes:
  0  success: run reached the end time or a terminal event with every value written finite;
     check found the scene valid and its output directory usable; describe printed the equations
  1  run only: the integration failed, or a value written is NaN or infinite; what was computed
     is still written, and the reason is printed to standard error (and in the summary)
  2  the scene cannot be run as written, the output directory cannot be used, an output file
     cannot be written, standard output cannot be written (a closed pipe is not an error), or
     the command line is wrong";

#[derive(Parser)]
#[command(
    name = "chetaev",
    version,
    about = "Solve constrained Lagrangian systems written as scene files (docs/scenes.md)",
    after_help = EXIT_CODES
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Solve a scene, print a summary and write the tables and pictures it asks for.
    #[command(after_help = RUN_EXIT_CODES)]
    Run {
        /// The scene file (TOML).
        scene: PathBuf,
        /// Write into this directory instead of the scene's `output.directory` (both relative to
        /// the working directory).
        #[arg(long, value_name = "DIR")]
        out: Option<PathBuf>,
        /// Write even where an earlier run left files this run would not write (they are removed)
        /// or files no earlier run's manifest lists (they are overwritten).
        #[arg(long, visible_alias = "overwrite")]
        force: bool,
        /// Print nothing but errors (no summary, no warnings).
        #[arg(long)]
        quiet: bool,
    },
    /// Show the equations the library derived for a scene, at its initial state: which blocks
    /// vanish or are constant, what each depends on, the numbers, the multipliers.
    Describe {
        /// The scene file (TOML).
        scene: PathBuf,
        /// Print the derived equations as one LaTeX `align*` environment instead.
        #[arg(long)]
        latex: bool,
    },
    /// Parse and validate a scene, and check its output directory, without integrating it.
    #[command(
        after_help = "Exit codes: 0 the scene is valid and its output directory usable; 2 it \
        is not (the message says where and why), standard output cannot be written, or the \
        command line is wrong"
    )]
    Check {
        /// The scene file (TOML).
        scene: PathBuf,
        /// Check this directory instead of the scene's `output.directory`.
        #[arg(long, value_name = "DIR")]
        out: Option<PathBuf>,
        /// Check as `run --force` would.
        #[arg(long, visible_alias = "overwrite")]
        force: bool,
    },
    /// Run a scene over a grid or a random sample of its parameters and initial values, in
    /// parallel, and collect event times, end states, extremes and sensitivities into a table
    /// (docs/sweeps.md).
    #[command(after_help = command_sweep::SWEEP_EXIT_CODES)]
    Sweep(command_sweep::SweepCommand),
    /// Join the part files of `chetaev sweep --shard K/N` runs into the whole sweep's table.
    #[command(after_help = command_sweep::SWEEP_EXIT_CODES)]
    Merge(command_sweep::MergeCommand),
}

/// Standard output that stops quietly when it is closed (a broken pipe), and remembers any other
/// failure to write.
struct Stdout {
    closed: bool,
    failure: Option<io::Error>,
}

impl Stdout {
    fn new() -> Self {
        Self {
            closed: false,
            failure: None,
        }
    }

    fn print(&mut self, text: &str) {
        if self.closed {
            return;
        }
        let mut out = io::stdout().lock();
        if let Err(e) = out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
            self.closed = true;
            if e.kind() != io::ErrorKind::BrokenPipe {
                self.failure = Some(e);
            }
        }
    }

    /// `code`, or 2 if the summary could not be written for another reason than a closed pipe.
    fn finish(self, code: u8) -> ExitCode {
        match self.failure {
            Some(e) => {
                eprint(&format!("error: cannot write to standard output: {e}\n"));
                ExitCode::from(code.max(2))
            }
            None => ExitCode::from(code),
        }
    }
}

/// Writes to standard error; a closed standard error is not worth a panic.
fn eprint(text: &str) {
    let _ = io::stderr().lock().write_all(text.as_bytes());
}

fn report(e: &Error) {
    let mut text = format!("error: {e}\n");
    if let Some(snippet) = e.snippet() {
        text.push_str(snippet);
        text.push('\n');
    }
    eprint(&text);
}

/// The scene's warnings, on standard error, each with its place in the file as an error has.
fn warn(scene: &Scene) {
    for w in &scene.warnings {
        eprint(&format!("warning: {w}\n{}\n", w.snippet));
    }
}

fn fail(e: &Error) -> ExitCode {
    report(e);
    ExitCode::from(2)
}

/// The plan for the scene's output directory (or `out`), checked for writing.
fn plan(scene: &Scene, out: Option<PathBuf>, force: bool) -> Result<Plan, Error> {
    let dir = out.unwrap_or_else(|| scene.output.directory.clone());
    let plan = Plan::new(scene, &dir, force)?;
    plan.check_writable()?;
    Ok(plan)
}

fn check(scene: &Path, out: Option<PathBuf>, force: bool) -> ExitCode {
    let s = match Scene::load(scene) {
        Ok(s) => s,
        Err(e) => return fail(&e),
    };
    warn(&s);
    let warnings = match s.check_with_warnings() {
        Ok(w) => w,
        Err(e) => return fail(&e),
    };
    // A `[sweep]` table is checked as `chetaev sweep` would read it.
    let sweep = if chetaev_scene::sweep::Sweep::declared_in(&s) {
        match chetaev_scene::sweep::Sweep::of_scene(&s, &Default::default()) {
            Ok(sw) => Some(sw),
            Err(e) => return fail(&e),
        }
    } else {
        None
    };
    let plan = match plan(&s, out, force) {
        Ok(p) => p,
        Err(e) => return fail(&e),
    };
    let mut stdout = Stdout::new();
    stdout.print(&format!(
        "{}: ok ({}, {}, {}, method {}, {}, {})\n",
        scene.display(),
        count(s.n(), "coordinate", "coordinates"),
        count(s.k(), "constraint", "constraints"),
        count(s.events.len(), "event", "events"),
        s.solve.method.name(),
        count(s.output.tables.len(), "table", "tables"),
        count(s.output.pictures.len(), "picture", "pictures"),
    ));
    if let Some(sw) = &sweep {
        stdout.print(&format!(
            "  sweep    {} of {}, collecting {}\n",
            count(sw.len(), "run", "runs"),
            sw.variables().join(", "),
            sw.columns().join(", ")
        ));
    }
    for w in &warnings {
        let text = match w {
            Warning::EventZeroAtStart { name, .. } => format!(
                "event '{name}' is zero at the start: a run does not stop there; the event is \
                 armed once its expression leaves zero, and crossings after that count"
            ),
            other => other.to_string(),
        };
        stdout.print(&format!("  warning  {text}\n"));
    }
    if !plan.is_empty() {
        let mut line = format!(
            "  output   would write {} and {MANIFEST} into {}",
            plan.files.join(", "),
            plan.resolved.display()
        );
        if !plan.stale.is_empty() {
            line.push_str(&format!(
                "; would remove {} of an earlier run ({})",
                plan.stale.join(", "),
                count(plan.stale.len(), "file", "files")
            ));
        }
        if !plan.foreign.is_empty() {
            line.push_str(&format!("; would overwrite {}", plan.foreign.join(", ")));
        }
        line.push('\n');
        stdout.print(&line);
    }
    stdout.finish(0)
}

fn run(scene: &Path, out: Option<PathBuf>, force: bool, quiet: bool) -> ExitCode {
    let loaded = match Scene::load(scene) {
        Ok(s) => s,
        Err(e) => return fail(&e),
    };
    if !quiet {
        warn(&loaded);
    }
    // Before integrating: a run that cannot write its results should not take the time.
    let plan = match plan(&loaded, out, force) {
        Ok(p) => p,
        Err(e) => return fail(&e),
    };
    let outcome = match loaded.solve() {
        Ok(o) => o,
        Err(e) => return fail(&e),
    };
    let mut stdout = Stdout::new();
    if !quiet {
        stdout.print(&output::summary(&loaded, &outcome));
    }
    match plan.write(&loaded, &outcome) {
        Ok(written) => {
            if !quiet && !written.files.is_empty() {
                let names: Vec<String> = written
                    .files
                    .iter()
                    .filter_map(|f| f.file_name())
                    .map(|n| n.to_string_lossy().into_owned())
                    .collect();
                let mut text = format!(
                    "  wrote    {} and {MANIFEST} into {}\n",
                    names.join(", "),
                    written.dir.display()
                );
                if !written.removed.is_empty() {
                    text.push_str(&format!(
                        "  removed  {} of an earlier run, which this run does not write (--force)\n",
                        written.removed.join(", ")
                    ));
                }
                stdout.print(&text);
            }
        }
        Err(e) => {
            report(&e);
            return stdout.finish(2);
        }
    }
    // Why the exit code is 1 goes to standard error whether or not the summary is printed: the
    // summary on standard output stays whole for whoever reads it, and `2> log` or a terminal
    // with standard output redirected still sees the failure.
    let non_finite = output::non_finite(&loaded, &outcome);
    let code = if let Status::Failed(e) = &outcome.status {
        let f = output::failure(&loaded, e);
        let at = f.t.map_or_else(String::new, |t| {
            format!(" at t = {}", output::summary_number(t))
        });
        let mut text = format!("error: the integration failed{at}: {}\n", f.what);
        if !f.advice.is_empty() {
            text.push_str(&format!("  advice: {}\n", f.advice));
        }
        eprint(&text);
        1
    } else if !non_finite.is_empty() {
        for bad in &non_finite {
            eprint(&format!(
                "error: {} is NaN or infinite at {} of {}\n",
                bad.what,
                bad.count,
                count(bad.of, "output point", "output points")
            ));
        }
        1
    } else {
        0
    };
    stdout.finish(code)
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Command::Check { scene, out, force } => check(&scene, out, force),
        Command::Describe { scene, latex } => {
            let described = Scene::load(&scene).and_then(|s| {
                if latex {
                    s.describe_latex()
                } else {
                    s.describe()
                        .map(|text| format!("{}\n{text}", scene.display()))
                }
            });
            match described {
                Ok(text) => {
                    let mut stdout = Stdout::new();
                    stdout.print(&format!("{text}\n"));
                    stdout.finish(0)
                }
                Err(e) => fail(&e),
            }
        }
        Command::Run {
            scene,
            out,
            force,
            quiet,
        } => run(&scene, out, force, quiet),
        Command::Sweep(c) => command_sweep::sweep(c),
        Command::Merge(c) => command_sweep::merge(c),
    }
}
