//! One right-hand side of the paper's model against the hand-written one, timed interleaved.
//!
//! `chetaev`'s side is the integrator's right-hand side, `ReducedOde::rhs`, as the step loop calls
//! it once the problem's equations run as machine code (made at once here, as when the tiering
//! finds that it pays), and the same right-hand side before that, by the interpreted route (the
//! compiled tape; `MachineCode::Never`): fresh problems, their recording left out of the time. The hand-written side is `Full::rhs`, `ẍ = g ẏ ẋ/|v|²`, `ÿ = −g + g ẏ²/|v|²`,
//! the same function the hand-written limit of `work-precision` integrates, called in the same
//! way (a generic `OdeSystem`, inlined where the compiler sees fit).
//!
//! Each sample evaluates every state of a table of 64 states along the closed-form motion (42.29)
//! once per pass, for enough passes to last a few milliseconds; the result of each call is handed
//! to `black_box` and nothing chains one call to the next, so that the processor may overlap
//! successive calls as it does inside a step. The sides are timed one sample each in turn
//! (A, B, C, A, B, C, ...) so that they see the same background load. Before timing,
//! both sides are checked to give the same derivative at every state of the table.
//!
//! ```sh
//! cargo run --release -p chetaev-bench --example rhs_ratio
//! ```

use std::hint::black_box;
use std::time::Instant;

use chetaev::integrate::system::{OdeSystem, ReducedOde};
use chetaev::MachineCode;
use chetaev_bench::handwritten::Full;
use chetaev_bench::measure::median;
use uniform_projectile::closed_form::{uniform, Params};
use uniform_projectile::model::uniform_problem;

const STATES: usize = 64;
const ROUNDS: usize = 41;
/// Passes over the table per sample (64 × 40,000 ≈ 2.6 million calls, a few milliseconds).
const PASSES: usize = 40_000;

/// Nanoseconds per call of `rhs` over `PASSES` passes of `states`.
fn time<S: OdeSystem>(sys: &mut S, states: &[[f64; 4]]) -> Result<f64, chetaev::Error> {
    let mut dy = [0.0; 4];
    let start = Instant::now();
    for _ in 0..PASSES {
        for y in states {
            sys.rhs(0.0, black_box(y), &mut dy)?;
            black_box(&mut dy);
        }
    }
    let elapsed = start.elapsed().as_secs_f64();
    Ok(elapsed * 1e9 / (PASSES * states.len()) as f64)
}

/// Nanoseconds per call of the interpreted right-hand side: `PROBLEMS` fresh problems (recorded
/// before the clock) on the interpreted route, each evaluated over `PASSES_INTERPRETED` passes of
/// `states`.
fn time_interpreted(p: &Params, states: &[[f64; 4]]) -> Result<f64, chetaev::Error> {
    const PROBLEMS: usize = 24;
    const PASSES_INTERPRETED: usize = 150;
    let passes = PASSES_INTERPRETED;
    let problems = (0..PROBLEMS)
        .map(|_| {
            let problem = uniform_problem(p)?.with_machine_code(MachineCode::Never);
            problem.compiled();
            Ok(problem)
        })
        .collect::<Result<Vec<_>, chetaev::Error>>()?;
    let mut dy = [0.0; 4];
    let mut elapsed = 0.0;
    for problem in &problems {
        let mut sys = ReducedOde::for_problem(problem, false);
        let start = Instant::now();
        for _ in 0..passes {
            for y in states {
                sys.rhs(0.0, black_box(y), &mut dy)?;
                black_box(&mut dy);
            }
        }
        elapsed += start.elapsed().as_secs_f64();
    }
    Ok(elapsed * 1e9 / (PROBLEMS * passes * states.len()) as f64)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let p = Params::PAPER;
    let t_end = uniform::kinematics(&p).t_impact;
    let states: Vec<[f64; 4]> = (0..STATES)
        .map(|i| {
            let t = t_end * (i as f64 + 0.5) / STATES as f64;
            let (q, v) = (uniform::position(&p, t), uniform::velocity(&p, t));
            [q[0], q[1], v[0], v[1]]
        })
        .collect();

    let native_problem = uniform_problem(&p)?;
    let ops = native_problem
        .compiled()
        .and_then(|c| c.native_operations())
        .ok_or("no machine code on this host")?;
    let mut native = ReducedOde::for_problem(&native_problem, false);
    let mut hand = Full::new(p.g);

    // The same derivative from each side at every state.
    let mut worst = 0.0f64;
    for y in &states {
        let (mut a, mut c) = ([0.0; 4], [0.0; 4]);
        native.rhs(0.0, y, &mut a)?;
        hand.rhs(0.0, y, &mut c)?;
        for i in 0..4 {
            worst = worst.max((a[i] - c[i]).abs() / c[i].abs().max(p.g));
        }
    }
    println!("machine code: {ops} operations; largest difference from the hand-written derivative {worst:.1e} (relative to g)");
    if worst > 1e-13 {
        return Err("the two sides disagree".into());
    }

    let (mut tn, mut th, mut ti) = (Vec::new(), Vec::new(), Vec::new());
    for _ in 0..ROUNDS {
        tn.push(time(&mut native, &states)?);
        th.push(time(&mut hand, &states)?);
        ti.push(time_interpreted(&p, &states)?);
    }
    let ratios: Vec<f64> = tn.iter().zip(&th).map(|(a, b)| a / b).collect();
    let (lo, hi) = {
        let mut r = ratios.clone();
        r.sort_by(f64::total_cmp);
        (r[r.len() / 4], r[3 * r.len() / 4])
    };
    let (n, h, i) = (median(&mut tn), median(&mut th), median(&mut ti));
    println!("ns per right-hand side, medians of {ROUNDS} interleaved samples:");
    println!("  chetaev, machine code    {n:6.2}");
    println!("  chetaev, interpreted     {i:6.2}");
    println!("  hand-written             {h:6.2}");
    println!(
        "ratio machine code / hand-written: median {:.2} (quartiles {lo:.2}–{hi:.2}); interpreted / hand-written {:.2}",
        median(&mut ratios.clone()),
        i / h
    );
    Ok(())
}
