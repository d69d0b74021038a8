//! The stiff scene against its hand-written limit: `chetaev` solving the uniform projectile with
//! `v0 = 1e-3`, `g = 9.81`, `h0 = 1` ([`stiff_scene`]) by `Rodas4` and `Rodas5P`, and the same
//! equations written out by hand with their Jacobian written out too
//! ([`Full`](chetaev_bench::handwritten::Full)), integrated by the same methods and driver
//! ([`solve_ode`]) with the same options, timed interleaved in one process.
//!
//! The hand-written right-hand side, on the state `y = (x, y, ẋ, ẏ)`, is gravity minus its
//! component along the velocity (the Chetaev equation (42.26) with the multiplier (42.27)
//! eliminated), and its Jacobian (`s = ẋ² + ẏ²`, all other entries zero, `∂F/∂t = 0`):
//!
//! ```text
//! ẍ = g ẏ ẋ / s,   ÿ = −g + g ẏ² / s,
//! ∂ẍ/∂ẋ = g ẏ (s − 2ẋ²) / s²,   ∂ẍ/∂ẏ = g ẋ (s − 2ẏ²) / s²,
//! ∂ÿ/∂ẋ = −2 g ẋ ẏ² / s²,       ∂ÿ/∂ẏ = 2 g ẋ² ẏ / s²,   ∂x'/∂ẋ = ∂y'/∂ẏ = 1.
//! ```
//!
//! Along the motion `ẋ = v0 sech(g t / v0)` decays at the rate `g / v0 ≈ 9.8e3 /s`: the stiffness.
//!
//! Both sides run to the closed-form impact time `T` with the scene's options (`rtol = tol`,
//! per-component absolute tolerances `scaled_atol`), output at the end only and the state only
//! recorded (`Record::State`, as the work-precision study runs chetaev's adaptive methods). The
//! error is the scene's: the end state against the closed form (42.29)–(42.30) at `T`, each
//! component relative to its scale in `scaled_atol`, the largest.
//!
//! Before anything is timed: the hand-written `q̈` is checked against `Problem::equations_at`, its
//! Jacobian against chetaev's (by dual numbers and as machine code, through
//! [`ReducedOde`]), and at every tolerance the end states of both sides against each other.
//!
//! chetaev evaluates a problem's right-hand side by an interpreted program until its tiering finds
//! that machine code pays (`MachineCode::Auto`: from the right-hand sides the problem has run and
//! those its solve still expects), and then as machine code, with the Jacobian as machine code too
//! (before that by dual numbers). Three chetaev timings are therefore taken, each against the same
//! hand-written one:
//!
//! - **first solve**: a fresh problem (built before the clock) solved once, which includes
//!   recording its equations and whatever machine code the solve makes;
//! - **interpreted**: a fresh problem on the interpreted route (`MachineCode::Never`) whose
//!   equations were compiled before the clock (`Problem::compiled`), solved once: the interpreted
//!   right-hand side and the dual-number Jacobian, without the one-time recording;
//! - **steady**: repeated solves of one problem whose right-hand side was made machine code
//!   (`Compiled::native_operations`): machine code for both.
//!
//! Both sides take the same steps (the counts are printed) and reach the same errors, to 1e-4
//! relative or better (printed as "errors agree to"): the ratios are therefore taken at equal
//! tolerance, which is equal error here, with no interpolation.
//!
//! A part-by-part timing follows (one right-hand side, one Jacobian, at a state of the motion; the
//! recording of a fresh problem's equations) with the work counted in a solve, to say where the
//! extra time of each goes.
//!
//! ```sh
//! cargo run --release -p chetaev-bench --example stiff_limit
//! ```

use std::hint::black_box;
use std::time::Instant;

use chetaev::integrate::driver::solve_ode;
use chetaev::integrate::system::{Jacobian, OdeSystem, ReducedOde, Stats};
use chetaev::prelude::*;
use chetaev_bench::handwritten::Full;
use chetaev_bench::measure::{batch_size, interleaved_batches, median, Batch};
use chetaev_bench::scenes::{stiff_scene, STIFF};
use uniform_projectile::closed_form::uniform;
use uniform_projectile::model::{scaled_atol, uniform_problem, UniformProblem};

const TOLERANCES: [f64; 7] = [1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10];
const ROUNDS: usize = 31;
/// Each timed sample is a batch of solves (or calls) lasting at least this long.
const MIN_BATCH_SECONDS: f64 = 5e-3;
/// Right-hand sides per fresh problem when one interpreted right-hand side is timed.
const INTERPRETED_CALLS: usize = 5_000;

/// The names of the four timings, in the order of a round.
const NAMES: [&str; 4] = ["first solve", "interpreted", "steady", "hand-written"];

/// A fresh problem of the stiff scene.
fn fresh() -> UniformProblem {
    uniform_problem(&STIFF).expect("the stiff scene is a valid problem")
}

/// A fresh problem of the stiff scene on the interpreted route with its equations compiled.
fn fresh_compiled() -> UniformProblem {
    let pb = fresh().with_machine_code(MachineCode::Never);
    assert!(pb.compiled().is_some(), "the stiff scene's model records");
    pb
}

/// The end state `(q, q̇)` of a chetaev solve.
fn end_state(sol: &Solution) -> Vec<f64> {
    assert!(sol.is_success(), "chetaev failed: {:?}", sol.status);
    let (_, q, qd) = sol.last().expect("recorded");
    q.iter().chain(qd).copied().collect()
}

/// The largest of `|a_i − b_i| / scale_i`; NaN if any is NaN.
fn scaled_diff(a: &[f64], b: &[f64], scale: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .zip(scale)
        .map(|((x, y), s)| (x - y).abs() / s)
        .fold(0.0, |m, d| {
            if m.is_nan() || d.is_nan() {
                f64::NAN
            } else {
                m.max(d)
            }
        })
}

/// Median seconds per item of each of `batches`, timed interleaved ([`ROUNDS`] rounds, batches
/// of at least [`MIN_BATCH_SECONDS`]).
fn interleaved(batches: &mut [Batch<'_>]) -> Vec<f64> {
    interleaved_batches(ROUNDS, MIN_BATCH_SECONDS, batches)
}

/// What one method at one tolerance gave.
struct Row {
    tol: f64,
    /// Errors against the closed form: chetaev's first solve, chetaev steady, hand-written.
    err: [f64; 3],
    /// Scaled differences of chetaev's end states (first solve, steady) from the hand-written one.
    diff: [f64; 2],
    /// Median seconds per solve, in the order of [`NAMES`].
    time: [f64; 4],
    /// chetaev's counts: first solve, steady.
    stats: [Stats; 2],
    /// The hand-written counts: right-hand sides, Jacobians, LU decompositions, accepted and
    /// rejected steps.
    hand: [usize; 5],
}

/// The scene's options at `tol`, as the work-precision study runs them.
fn options_at(options: &dyn Fn(f64) -> Options, tol: f64) -> Options {
    options(tol).output_final().record(Record::State)
}

/// `method` over [`TOLERANCES`]: the checks of the end states, then the four timings interleaved.
fn measure<Me: Method + Copy>(
    options: &dyn Fn(f64) -> Options,
    error: &dyn Fn(&[f64], &[f64]) -> f64,
    steady: &UniformProblem,
    y0: &[f64],
    scale: &[f64],
    method: Me,
) -> Result<Vec<Row>, String> {
    let mut rows = Vec::new();
    for &tol in &TOLERANCES {
        let o = options_at(options, tol);

        // The work and the end states, untimed.
        let cold = solve(&fresh(), method, &o).map_err(|e| e.to_string())?;
        let warm = solve(steady, method, &o).map_err(|e| e.to_string())?;
        let mut counted = Full::new(STIFF.g);
        let hand = solve_ode(&mut counted, method, 0.0, y0, &o).map_err(|e| e.to_string())?;
        if let Some(e) = &hand.error {
            return Err(format!("hand-written failed at tol {tol:e}: {e}"));
        }
        let (yc, yw) = (end_state(&cold), end_state(&warm));
        let yh = hand.y.last().ok_or("nothing recorded")?;
        let err = [
            error(&yc[..2], &yc[2..]),
            error(&yw[..2], &yw[2..]),
            error(&yh[..2], &yh[2..]),
        ];
        let diff = [scaled_diff(&yc, yh, scale), scaled_diff(&yw, yh, scale)];
        if diff.iter().any(|d| d.is_nan() || *d > tol) {
            return Err(format!(
                "at tol {tol:e} chetaev's end state differs from the hand-written one by \
                 {diff:?} (scaled), more than the tolerance"
            ));
        }

        // The four timings.
        // One fresh problem at a time, made and dropped outside the clock: a batch of problems
        // made in advance would time the first touch of their memory as well (page faults),
        // which a program that solves one problem after another does not pay.
        let once = |make: fn() -> UniformProblem, n: usize| {
            let mut elapsed = 0.0;
            for _ in 0..n {
                let pb = make();
                let start = Instant::now();
                let _sol = black_box(solve(&pb, method, &o).expect("valid options"));
                elapsed += start.elapsed().as_secs_f64();
            }
            elapsed / n as f64
        };
        let mut first = |n: usize| once(fresh, n);
        let mut interpreted = |n: usize| once(fresh_compiled, n);
        let mut repeated = |n: usize| {
            let start = Instant::now();
            for _ in 0..n {
                let _sol = black_box(solve(steady, method, &o).expect("valid options"));
            }
            start.elapsed().as_secs_f64() / n as f64
        };
        let mut by_hand = |n: usize| {
            let start = Instant::now();
            for _ in 0..n {
                let mut sys = Full::new(STIFF.g);
                let _sol =
                    black_box(solve_ode(&mut sys, method, 0.0, y0, &o).expect("valid options"));
            }
            start.elapsed().as_secs_f64() / n as f64
        };
        let t = interleaved(&mut [&mut first, &mut interpreted, &mut repeated, &mut by_hand]);
        rows.push(Row {
            tol,
            err,
            diff,
            time: [t[0], t[1], t[2], t[3]],
            stats: [cold.stats, warm.stats],
            hand: [
                counted.counts.rhs,
                counted.counts.jacobians,
                counted.counts.lu,
                hand.stats.accepted_steps,
                hand.stats.rejected_steps,
            ],
        });
    }
    Ok(rows)
}

/// The tables of one method.
fn report(name: &str, rows: &[Row]) {
    println!("\n### {name}\n");
    println!(
        "| tol | error first solve | error steady | error hand | end state vs hand (first, steady) | \
         steps chetaev | steps hand | RHS chetaev | RHS hand | Jacobians chetaev / hand | LU chetaev / hand |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    for r in rows {
        let [c, w] = &r.stats;
        let counts = |s: &Stats| (s.accepted_steps, s.rejected_steps, s.rhs_evaluations);
        let (same_c, same_w) = (counts(c), counts(w));
        assert_eq!(
            same_c, same_w,
            "the first solve and the steady one did different work"
        );
        println!(
            "| {:.0e} | {:.2e} | {:.2e} | {:.2e} | {:.1e}, {:.1e} | {}+{} | {}+{} | {} | {} | {} / {} | {} / {} |",
            r.tol,
            r.err[0],
            r.err[1],
            r.err[2],
            r.diff[0],
            r.diff[1],
            c.accepted_steps,
            c.rejected_steps,
            r.hand[3],
            r.hand[4],
            c.rhs_evaluations,
            r.hand[0],
            c.jacobian_evaluations,
            r.hand[1],
            c.lu_decompositions,
            r.hand[2],
        );
    }

    println!(
        "\n| tol | errors agree to (relative) | first solve (µs) | interpreted (µs) | steady (µs) | \
         hand (µs) | first / hand | interpreted / hand | steady / hand |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    for r in rows {
        let spread = r.err[..2]
            .iter()
            .map(|e| (e - r.err[2]).abs() / r.err[2])
            .fold(0.0f64, f64::max);
        println!(
            "| {:.0e} | {:.1e} | {:.1} | {:.1} | {:.1} | {:.1} | {:.2} | {:.2} | {:.2} |",
            r.tol,
            spread,
            r.time[0] * 1e6,
            r.time[1] * 1e6,
            r.time[2] * 1e6,
            r.time[3] * 1e6,
            r.time[0] / r.time[3],
            r.time[1] / r.time[3],
            r.time[2] / r.time[3],
        );
    }
}

/// Seconds per call of `f`, the median of [`ROUNDS`] batches.
fn per_call(f: &mut dyn FnMut()) -> f64 {
    let mut batch = |n: usize| {
        let start = Instant::now();
        for _ in 0..n {
            f();
        }
        start.elapsed().as_secs_f64() / n as f64
    };
    interleaved(&mut [&mut batch])[0]
}

/// Seconds per interpreted right-hand side of chetaev at `y`: [`INTERPRETED_CALLS`] calls on each
/// of a batch of fresh problems on the interpreted route.
fn interpreted_rhs(y: &[f64]) -> f64 {
    let mut dy = [0.0; 4];
    let mut batch = |problems: usize| {
        let pbs: Vec<UniformProblem> = (0..problems).map(|_| fresh_compiled()).collect();
        let mut systems: Vec<_> = pbs
            .iter()
            .map(|pb| ReducedOde::for_problem(pb, false))
            .collect();
        let start = Instant::now();
        for sys in &mut systems {
            for _ in 0..INTERPRETED_CALLS {
                sys.rhs(0.0, black_box(y), &mut dy).expect("regular");
                black_box(&dy);
            }
        }
        let s = start.elapsed().as_secs_f64() / (problems * INTERPRETED_CALLS) as f64;
        drop(systems);
        s
    };
    let n = batch_size(MIN_BATCH_SECONDS, &mut |k| {
        batch(k) * INTERPRETED_CALLS as f64
    });
    median(&mut (0..ROUNDS).map(|_| batch(n)).collect::<Vec<_>>())
}

/// Seconds per `Problem::compiled` on a fresh problem: recording the model and compiling its
/// equations, which a problem's first solve does.
fn recording() -> f64 {
    let mut batch = |n: usize| {
        let problems: Vec<UniformProblem> = (0..n).map(|_| fresh()).collect();
        let start = Instant::now();
        for pb in &problems {
            black_box(pb.compiled());
        }
        start.elapsed().as_secs_f64() / n as f64
    };
    interleaved(&mut [&mut batch])[0]
}

/// Seconds per right-hand side and per Jacobian at `y`: chetaev interpreted (and its Jacobian by
/// dual numbers), chetaev as machine code (`steady`, past `NATIVE_AFTER`), hand-written.
fn parts(steady: &UniformProblem, y: &[f64]) -> [[f64; 2]; 3] {
    let (mut dy, mut jac) = ([0.0; 4], Jacobian::new(4));
    let rhs_i = interpreted_rhs(y);
    let fresh = fresh_compiled();
    let mut dual = ReducedOde::for_problem(&fresh, false);
    let jac_i = per_call(&mut || {
        dual.jacobian(0.0, black_box(y), &mut jac).expect("regular");
        black_box(&jac);
    });
    let mut native = ReducedOde::for_problem(steady, false);
    let rhs_n = per_call(&mut || {
        native.rhs(0.0, black_box(y), &mut dy).expect("regular");
        black_box(&dy);
    });
    let jac_n = per_call(&mut || {
        native
            .jacobian(0.0, black_box(y), &mut jac)
            .expect("regular");
        black_box(&jac);
    });
    let mut full = Full::new(STIFF.g);
    let rhs_h = per_call(&mut || {
        full.rhs(0.0, black_box(y), &mut dy).expect("finite");
        black_box(&dy);
    });
    let jac_h = per_call(&mut || {
        full.jacobian(0.0, black_box(y), &mut jac).expect("finite");
        black_box(&jac);
    });
    [[rhs_i, jac_i], [rhs_n, jac_n], [rhs_h, jac_h]]
}

/// The largest difference of two Jacobians relative to `1 + max |entry|` of the second.
fn jacobian_diff(a: &[f64], b: &[f64]) -> f64 {
    let scale = 1.0 + b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    scaled_diff(a, b, &vec![scale; a.len()])
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let p = STIFF;
    let scene = stiff_scene(1_000_000)?;
    let t_end = scene.t_end;
    let (q0, qd0) = (scene.problem.q0().to_vec(), scene.problem.qd0().to_vec());
    let y0: Vec<f64> = q0.iter().chain(&qd0).copied().collect();
    let (aq, av) = scaled_atol(&p, 1.0);
    let scale = [aq[0], aq[1], av[0], av[1]];
    println!("{}: {}", scene.title, scene.reference);

    // The hand-written right-hand side against chetaev's at states on the constraint |q̇| = v0,
    // and its Jacobian against chetaev's by dual numbers (a fresh problem) and, below, as machine
    // code.
    let pb = fresh_compiled();
    let mut dual = ReducedOde::for_problem(&pb, false);
    let mut full = Full::new(p.g);
    let (mut worst_rhs, mut worst_dual): (f64, f64) = (0.0, 0.0);
    let angles = [0.0, 1e-3, 0.3, 0.9, 1.4, 1.57];
    let states: Vec<[f64; 4]> = angles
        .iter()
        .map(|&a: &f64| [0.7 * a, 1.0 - 0.5 * a, p.v0 * a.cos(), -p.v0 * a.sin()])
        .collect();
    let (mut jh, mut jc) = (Jacobian::new(4), Jacobian::new(4));
    for y in &states {
        let eq = pb.equations_at(0.0, &y[..2], &y[2..])?;
        let mut dy = [0.0; 4];
        full.rhs(0.0, y, &mut dy)?;
        let d = scaled_diff(&dy[2..], &eq.qdd, &[p.g; 2]);
        worst_rhs = worst_rhs.max(d);
        full.jacobian(0.0, y, &mut jh)?;
        dual.jacobian(0.0, y, &mut jc)?;
        let dj =
            jacobian_diff(&jc.dy, &jh.dy).max(jc.dt.iter().fold(0.0f64, |m, v| m.max(v.abs())));
        worst_dual = worst_dual.max(dj);
        if d.is_nan() || d > 1e-13 || dj.is_nan() || dj > 1e-12 {
            return Err(format!(
                "hand-written and chetaev disagree at y = {y:?}: q̈ {:?} vs {:?} (relative {d:e}), \
                 Jacobian {:?} vs {:?} (relative {dj:e})",
                &dy[2..],
                eq.qdd,
                jh.dy,
                jc.dy
            )
            .into());
        }
    }
    drop(dual);
    println!(
        "hand-written q̈ agrees with Problem::equations_at to {worst_rhs:.1e} (relative to g); its \
         Jacobian with chetaev's by dual numbers to {worst_dual:.1e} (relative to 1 + max entry)"
    );

    // The problem of the steady state: machine code at once.
    let steady = scene.problem;
    let operations = steady.compiled().and_then(|c| c.native_operations());
    println!(
        "steady problem: its right-hand side as machine code: {}",
        operations.map_or("none (host not supported)".to_string(), |k| format!(
            "{k} operations"
        ))
    );
    let mut native = ReducedOde::for_problem(&steady, false);
    let mut worst_native: f64 = 0.0;
    for y in &states {
        full.jacobian(0.0, y, &mut jh)?;
        // The Jacobian as machine code follows the right-hand side.
        native.rhs(0.0, y, &mut [0.0; 4])?;
        native.jacobian(0.0, y, &mut jc)?;
        let dj =
            jacobian_diff(&jc.dy, &jh.dy).max(jc.dt.iter().fold(0.0f64, |m, v| m.max(v.abs())));
        worst_native = worst_native.max(dj);
        if dj.is_nan() || dj > 1e-12 {
            return Err(format!(
                "hand-written Jacobian {:?} and chetaev's as machine code {:?} disagree at \
                 y = {y:?} (relative {dj:e})",
                jh.dy, jc.dy
            )
            .into());
        }
    }
    drop(native);
    println!(
        "hand-written Jacobian agrees with chetaev's as machine code to {worst_native:.1e} (relative)"
    );
    println!(
        "T = {t_end:.6} s; {ROUNDS} interleaved rounds ({}), batches >= {} ms; \
         end states checked against the hand-written one to within tol (scaled as the error)",
        NAMES.join(", "),
        MIN_BATCH_SECONDS * 1e3
    );

    let rodas4 = measure(&*scene.options, &*scene.error, &steady, &y0, &scale, Rodas4)?;
    let rodas5p = measure(
        &*scene.options,
        &*scene.error,
        &steady,
        &y0,
        &scale,
        Rodas5P,
    )?;
    report("Rodas4", &rodas4);
    report("Rodas5P", &rodas5p);

    // One right-hand side and one Jacobian, at the exact state at T/2.
    let (x, v) = (
        uniform::position(&p, 0.5 * t_end),
        uniform::velocity(&p, 0.5 * t_end),
    );
    let y_mid = [x[0], x[1], v[0], v[1]];
    let [[rhs_i, jac_i], [rhs_n, jac_n], [rhs_h, jac_h]] = parts(&steady, &y_mid);
    println!("\n### Parts (ns per call, at the exact state at T/2)\n");
    println!("| | right-hand side | Jacobian |");
    println!("|---|---|---|");
    for (name, r, j) in [
        ("chetaev interpreted / dual numbers", rhs_i, jac_i),
        ("chetaev machine code", rhs_n, jac_n),
        ("hand-written", rhs_h, jac_h),
    ] {
        println!("| {name} | {:.1} | {:.1} |", r * 1e9, j * 1e9);
    }
    let record = recording();
    println!(
        "\nrecording and compiling the equations of a fresh problem (Problem::compiled, which the \
         first solve does): {:.1} µs",
        record * 1e6
    );
    println!(
        "\nThe time a solve spends beyond the hand-written one, against what its evaluations \
         explain ((RHS_chetaev − RHS_hand per call) × RHS + (Jacobian_chetaev − Jacobian_hand) × \
         Jacobians, with the counts above):\n"
    );
    println!(
        "| method | tol | interpreted − hand (µs) | explained by RHS, Jacobian (µs) | \
         steady − hand (µs) | explained by RHS, Jacobian (µs) | first solve − interpreted (µs) | \
         recording (µs) |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    for (name, rows) in [("Rodas4", &rodas4), ("Rodas5P", &rodas5p)] {
        for r in rows {
            let s = &r.stats[1];
            let (nr, nj) = (s.rhs_evaluations as f64, s.jacobian_evaluations as f64);
            let ex = |rc: f64, jc: f64| ((rc - rhs_h) * nr * 1e6, (jc - jac_h) * nj * 1e6);
            let (ri, ji) = ex(rhs_i, jac_i);
            let (rn, jn) = ex(rhs_n, jac_n);
            println!(
                "| {name} | {:.0e} | {:.1} | {:.1}, {:.1} | {:.1} | {:.1}, {:.1} | {:.1} | {:.1} |",
                r.tol,
                (r.time[1] - r.time[3]) * 1e6,
                ri,
                ji,
                (r.time[2] - r.time[3]) * 1e6,
                rn,
                jn,
                (r.time[0] - r.time[1]) * 1e6,
                record * 1e6,
            );
        }
    }
    Ok(())
}
