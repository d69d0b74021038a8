//! Fresh problems from one scene file in a loop, and nothing else: a target for an instruction
//! counter (`valgrind --tool=callgrind`) or a profiler, which count the parts of a first solve
//! reproducibly on a machine too noisy for small timing differences.
//!
//! ```sh
//! cargo build --release -p chetaev-bench --example fresh_loop
//! valgrind --tool=callgrind target/release/examples/fresh_loop scenes/rolling-disc.toml 200 record
//! #                                                            SCENE  N  record|never|auto
//! ```
//!
//! Each of the `N` rounds makes the scene's problem afresh, then with `record` records its
//! equations (`Problem::compiled`) and stops there; with `never` solves it by the interpreted
//! route throughout (`MachineCode::Never`); with `auto` solves it as a first solve does
//! (`MachineCode::Auto`). A solve integrates the scene's `[solve]` and keeps the state at the steps.

use std::process::ExitCode;

use chetaev::prelude::*;
use chetaev_scene::Scene;

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [path, rounds, mode] = args.as_slice() else {
        eprintln!("usage: fresh_loop SCENE.toml N record|never|auto");
        return ExitCode::from(2);
    };
    let (Ok(rounds), true) = (
        rounds.parse::<usize>(),
        matches!(mode.as_str(), "record" | "never" | "auto"),
    ) else {
        eprintln!("usage: fresh_loop SCENE.toml N record|never|auto");
        return ExitCode::from(2);
    };
    match run(path, rounds, mode) {
        Ok(steps) => {
            println!("{rounds} fresh problems of {path} ({mode}): {steps} steps in all");
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("{path}: {e}");
            ExitCode::FAILURE
        }
    }
}

/// The rounds; the steps taken by all solves.
fn run(path: &str, rounds: usize, mode: &str) -> Result<usize, String> {
    let scene = Scene::load(path).map_err(|e| e.to_string())?;
    let options = scene.options(scene.solve.t_end).record(Record::State);
    let mut steps = 0;
    for _ in 0..rounds {
        let problem = scene.problem().map_err(|e| e.to_string())?;
        let problem = match mode {
            "never" => problem.with_machine_code(MachineCode::Never),
            _ => problem,
        };
        if mode == "record" {
            problem.compiled();
            continue;
        }
        let solution = solve(&problem, scene.solve.method, &options).map_err(|e| e.to_string())?;
        steps += solution.stats.accepted_steps;
    }
    Ok(steps)
}
