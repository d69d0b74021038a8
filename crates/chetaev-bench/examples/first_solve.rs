//! A fresh problem's first solve against a warm solve of the same problem, for scene files.
//!
//! For each scene, rounds of four runs, timed interleaved (A, B, C, D, A, B, C, D, ...):
//!
//! - **first**: a fresh problem made from the scene (`Scene::problem`) and solved once: the
//!   recording of its equations, the interpreted right-hand sides and whatever machine code the
//!   solve makes (`MachineCode::Auto`), all included;
//! - **warm**: a solve of one problem kept across the rounds whose right-hand side already runs as
//!   machine code;
//! - **interpreted**: a fresh problem on the interpreted route (`MachineCode::Never`) whose
//!   equations were recorded before the clock, solved once: the route a first solve starts on,
//!   without the recording;
//! - **first, never compiled**: as *first*, on the interpreted route throughout
//!   (`MachineCode::Never`), which is what a first solve of fewer than `10⁴` right-hand sides did
//!   before machine code was made when it pays.
//!
//! Each solve integrates the scene's `[solve]` (method, end, tolerances, events) and keeps the
//! state at the steps. The three take the same steps up to rounding, so they are at equal error.
//! Then a breakdown of one fresh problem: making it, recording its equations, compiling its
//! right-hand side to machine code, and the right-hand sides of a solve.
//!
//! ```sh
//! cargo run --release -p chetaev-bench --example first_solve -- \
//!     scenes/uniform-projectile.toml scenes/rolling-disc.toml scenes/snakeboard.toml
//! ```

use std::process::ExitCode;
use std::time::Instant;

use chetaev::prelude::*;
use chetaev_bench::measure::median;
use chetaev_scene::Scene;

const ROUNDS: usize = 21;

fn main() -> ExitCode {
    let paths: Vec<String> = std::env::args().skip(1).collect();
    if paths.is_empty() {
        eprintln!("usage: first_solve SCENE.toml [SCENE.toml ...]");
        return ExitCode::from(2);
    }
    println!("{}", machine());
    for path in &paths {
        if let Err(e) = run(path) {
            eprintln!("{path}: {e}");
            return ExitCode::FAILURE;
        }
    }
    ExitCode::SUCCESS
}

fn seconds(f: impl FnOnce()) -> f64 {
    let t0 = Instant::now();
    f();
    t0.elapsed().as_secs_f64()
}

fn run(path: &str) -> Result<(), String> {
    let scene = Scene::load(path).map_err(|e| e.to_string())?;
    let options = scene.options(scene.solve.t_end).record(Record::State);
    let method = scene.solve.method;
    let fresh = || scene.problem().map_err(|e| e.to_string());
    let solve_once = |p: &Problem<_>| -> Result<Solution, String> {
        let s = solve(p, method, &options).map_err(|e| e.to_string())?;
        if s.is_success() {
            Ok(s)
        } else {
            Err(format!("the solve stopped: {:?}", s.status))
        }
    };
    let warm = fresh()?;
    let operations = warm.compiled().and_then(|c| c.native_operations());
    let tape = warm.compiled().map_or(0, |c| c.operations().0);
    let reference = solve_once(&warm)?;
    let rhs = reference.stats.rhs_evaluations;
    let mut times = [Vec::new(), Vec::new(), Vec::new(), Vec::new()];
    for _ in 0..ROUNDS {
        let mut err = None;
        times[0].push(seconds(|| {
            if let Err(e) = fresh().and_then(|p| solve_once(&p)) {
                err = Some(e);
            }
        }));
        times[1].push(seconds(|| {
            if let Err(e) = solve_once(&warm) {
                err = Some(e);
            }
        }));
        let recorded = fresh()?.with_machine_code(MachineCode::Never);
        recorded.compiled();
        times[2].push(seconds(|| {
            if let Err(e) = solve_once(&recorded) {
                err = Some(e);
            }
        }));
        times[3].push(seconds(|| {
            let never = fresh().map(|p| p.with_machine_code(MachineCode::Never));
            if let Err(e) = never.and_then(|p| solve_once(&p)) {
                err = Some(e);
            }
        }));
        if let Some(e) = err {
            return Err(e);
        }
    }
    let [first, warm_t, interp, never] = times.map(|mut t| median(&mut t));
    // The breakdown of one fresh problem.
    let mut phases = [Vec::new(), Vec::new(), Vec::new(), Vec::new()];
    for _ in 0..ROUNDS {
        let mut p = None;
        phases[0].push(seconds(|| p = fresh().ok()));
        let p = p.ok_or("the scene's problem")?;
        phases[1].push(seconds(|| {
            p.compiled();
        }));
        phases[2].push(seconds(|| {
            p.compiled().and_then(|c| c.native_operations());
        }));
        let q = fresh()?;
        q.compiled();
        phases[3].push(seconds(|| {
            q.compiled().and_then(|c| c.quick_native_operations());
        }));
    }
    let [make, record, compile, quick] = phases.map(|mut t| median(&mut t));
    println!(
        "{path}: {} right-hand sides, {} operations on the tape, {} as machine code",
        rhs,
        tape,
        operations.map_or("no".to_string(), |o| o.to_string())
    );
    println!(
        "  first {:.3} ms, warm {:.3} ms, interpreted {:.3} ms, first never compiled {:.3} ms: first/warm {:.2}, never compiled/warm {:.2}, interpreted/warm {:.2}",
        first * 1e3,
        warm_t * 1e3,
        interp * 1e3,
        never * 1e3,
        first / warm_t,
        never / warm_t,
        interp / warm_t
    );
    println!(
        "  a fresh problem: made {:.3} ms, recorded {:.3} ms, compiled {:.3} ms quickly and {:.3} ms with full effort; right-hand side {:.2} µs interpreted, {:.2} µs as machine code (whole solve / right-hand sides)",
        make * 1e3,
        record * 1e3,
        quick * 1e3,
        compile * 1e3,
        interp / rhs as f64 * 1e6,
        warm_t / rhs as f64 * 1e6,
    );
    Ok(())
}

/// The processor and the load, for the report.
fn machine() -> String {
    let cpu = chetaev_bench::measure::cpu_model();
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    let cores = std::thread::available_parallelism().map_or(0, |n| n.get());
    format!(
        "{cores} cores, {cpu}; load average {}",
        load.split_whitespace()
            .take(3)
            .collect::<Vec<_>>()
            .join(" ")
    )
}
