//! A loop of whole solves of the paper's scene for a profiler: Dopri5 (or Dop853, with a third
//! argument `dop853`) at `rtol = atol = 1e-12` to
//! the closed-form impact time, output at the end only, through chetaev or through the
//! hand-written full system and the same driver (`solve_ode`).
//!
//! ```sh
//! cargo build --release -p chetaev-bench --example solve_loop
//! valgrind --tool=callgrind target/release/examples/solve_loop chetaev 2000
//! valgrind --tool=callgrind target/release/examples/solve_loop hand 2000
//! ```
//!
//! Prints the right-hand sides of one solve, so that instruction counts can be read per solve and
//! per right-hand side.

use std::hint::black_box;
use std::process::ExitCode;

use chetaev::integrate::driver::{solve_ode, OdeOptions};
use chetaev::prelude::*;
use chetaev_bench::handwritten::Full;
use chetaev_bench::scenes::uniform_scene;

const TOL: f64 = 1e-12;

fn main() -> ExitCode {
    let mut args = std::env::args().skip(1);
    let (which, count) = (args.next(), args.next().map(|s| s.parse::<usize>()));
    let (hand, count) = match (which.as_deref(), count) {
        (Some(w @ ("chetaev" | "hand")), Some(Ok(count))) if count > 0 => (w == "hand", count),
        _ => return usage(),
    };
    match args.next().as_deref() {
        None | Some("dopri5") => run(hand, count, Dopri5::default()),
        Some("dop853") => run(hand, count, Dop853::default()),
        Some(_) => usage(),
    }
}

fn usage() -> ExitCode {
    eprintln!("usage: solve_loop chetaev|hand <number of solves, at least 1> [dopri5|dop853]");
    ExitCode::from(2)
}

/// `count` solves by `method`, through chetaev or by hand.
fn run(hand: bool, count: usize, method: impl Method + Copy) -> ExitCode {
    let scene = match uniform_scene() {
        Ok(scene) => scene,
        Err(e) => {
            eprintln!("the paper's scene: {e}");
            return ExitCode::FAILURE;
        }
    };
    let (q0, qd0) = (scene.problem.q0(), scene.problem.qd0());
    let y0 = [q0[0], q0[1], qd0[0], qd0[1]];
    let options = (scene.options)(TOL).output_final().record(Record::State);
    let mut ode_options = OdeOptions::until(scene.t_end).tolerances(TOL, TOL);
    ode_options.output = Output::Final;
    let mut rhs = 0;
    for _ in 0..count {
        let result = if hand {
            let mut sys = Full::new(uniform_projectile::closed_form::Params::PAPER.g);
            let sol = solve_ode(&mut sys, method, 0.0, &y0, &ode_options);
            rhs = sys.counts.rhs;
            match sol {
                Ok(s) => match s.error {
                    None => Ok(black_box(s.t.len())),
                    Some(e) => Err(e.to_string()),
                },
                Err(e) => Err(e.to_string()),
            }
        } else {
            let sol = solve(&scene.problem, method, &options);
            match sol {
                Ok(s) if s.is_success() => {
                    rhs = s.stats.rhs_evaluations;
                    Ok(black_box(s.len()))
                }
                Ok(s) => Err(format!("{:?}", s.status)),
                Err(e) => Err(e.to_string()),
            }
        };
        if let Err(e) = result {
            eprintln!("solve failed: {e}");
            return ExitCode::FAILURE;
        }
    }
    println!("{count} solves, {rhs} right-hand sides each");
    ExitCode::SUCCESS
}
