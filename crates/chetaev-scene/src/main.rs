//! `chetaev`: solve a scene file and write the tables and pictures it asks for.
//!
//! Exit codes: 0 success (the end time or a terminal event was reached), 1 the integration failed
//! (what was computed up to the failure is still written), 2 the scene cannot be run as written
//! (or its output cannot be written).

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

use chetaev_scene::{output, Error, Scene};

#[derive(Parser)]
#[command(
    name = "chetaev",
    version,
    about = "Solve constrained Lagrangian systems written as scene files (docs/scenes.md)"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Solve a scene, print a summary and write the tables and pictures it asks for.
    Run {
        /// The scene file (TOML).
        scene: PathBuf,
        /// Write into this directory instead of the scene's `output.directory`.
        #[arg(long, value_name = "DIR")]
        out: Option<PathBuf>,
        /// Print nothing but errors.
        #[arg(long)]
        quiet: bool,
    },
    /// Parse and validate a scene without integrating it.
    Check {
        /// The scene file (TOML).
        scene: PathBuf,
    },
}

fn report(e: &Error) {
    eprintln!("error: {e}");
    if let Some(snippet) = e.snippet() {
        eprintln!("{snippet}");
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Command::Check { scene } => {
            let checked = Scene::load(&scene).and_then(|s| s.check().map(|()| s));
            match checked {
                Ok(s) => {
                    println!(
                        "{}: ok ({} coordinates, {} constraints, {} events, method {}, {} tables, {} pictures)",
                        scene.display(),
                        s.n(),
                        s.k(),
                        s.events.len(),
                        s.solve.method.name(),
                        s.output.tables.len(),
                        s.output.pictures.len()
                    );
                    ExitCode::SUCCESS
                }
                Err(e) => {
                    report(&e);
                    ExitCode::from(2)
                }
            }
        }
        Command::Run { scene, out, quiet } => {
            let loaded = match Scene::load(&scene) {
                Ok(s) => s,
                Err(e) => {
                    report(&e);
                    return ExitCode::from(2);
                }
            };
            let outcome = match loaded.solve() {
                Ok(o) => o,
                Err(e) => {
                    report(&e);
                    return ExitCode::from(2);
                }
            };
            if !quiet {
                print!("{}", output::summary(&loaded, &outcome));
            }
            let dir = out.unwrap_or_else(|| loaded.output.directory.clone());
            match output::write(&loaded, &outcome, &dir) {
                Ok(files) => {
                    if !quiet && !files.is_empty() {
                        let names: Vec<String> = files
                            .iter()
                            .map(|f| {
                                f.file_name()
                                    .map_or_else(String::new, |n| n.to_string_lossy().into_owned())
                            })
                            .collect();
                        println!("  wrote    {} in {}", names.join(", "), dir.display());
                    }
                }
                Err(e) => {
                    report(&e);
                    return ExitCode::from(2);
                }
            }
            if outcome.is_success() {
                ExitCode::SUCCESS
            } else {
                if quiet {
                    if let chetaev::Status::Failed(e) = &outcome.status {
                        eprintln!("error: the integration failed: {e}");
                    }
                }
                ExitCode::from(1)
            }
        }
    }
}
