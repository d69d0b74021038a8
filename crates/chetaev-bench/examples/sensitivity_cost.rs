//! What the sensitivities cost against central finite differences, at equal accuracy, on the
//! paper's scene: the six derivatives `∂T/∂θ`, `∂R/∂θ` of the impact for `θ = v0, g, h0`.
//!
//! - **Sensitivities**: one solve carrying three seeds, under error control (Dop853 at `tol`);
//!   and the same on the steps of the motion alone ("free": no error control on the seeds).
//! - **Central differences**: six solves, `θ ± δ` for each `θ` (Dop853 at `tol`), with `δ` the
//!   best of `θ · 10^-2 … θ · 10^-8` *for that tolerance* (chosen against the closed form, which a
//!   user would not have: this favours finite differences).
//!
//! Errors are the largest relative error of the six derivatives against the closed form (42.38)
//! differentiated by dual numbers. Times are medians of batches run interleaved (sensitivities,
//! differences, sensitivities, ...) in one process. The last table compares at equal error: for
//! each finite-difference point, the cheapest sensitivity run that is at least as accurate.
//!
//! ```sh
//! cargo run --release -p chetaev-bench --example sensitivity_cost
//! ```

use std::hint::black_box;
use std::time::Instant;

use chetaev::num_dual::Dual64;
use chetaev::prelude::*;
use chetaev_bench::measure::median;
use uniform_projectile::closed_form::{uniform, Params};
use uniform_projectile::model::{impact, seeds, uniform_problem};

const TOLERANCES: [f64; 5] = [1e-6, 1e-8, 1e-10, 1e-12, 1e-13];
const ROUNDS: usize = 21;
const MIN_BATCH_SECONDS: f64 = 5e-3;
const NAMES: [&str; 3] = ["v0", "g", "h0"];

fn paper() -> Params {
    Params {
        v0: 10.0,
        g: 10.0,
        h0: 5.0,
        m: 1.0,
    }
}

/// `[∂T/∂v0, ∂R/∂v0, ∂T/∂g, ∂R/∂g, ∂T/∂h0, ∂R/∂h0]` from the closed form.
fn exact(p: &Params) -> [f64; 6] {
    let mut out = [0.0; 6];
    for j in 0..3 {
        let s = |i: usize, x: f64| Dual64::new(x, if i == j { 1.0 } else { 0.0 });
        let (t, r) = uniform::impact(s(0, p.v0), s(1, p.g), s(2, p.h0));
        out[2 * j] = t.eps;
        out[2 * j + 1] = r.eps;
    }
    out
}

fn largest_error(d: &[f64; 6], e: &[f64; 6]) -> f64 {
    d.iter()
        .zip(e)
        .map(|(a, b)| ((a - b) / b).abs())
        .fold(0.0, f64::max)
}

fn options(tol: f64) -> Options {
    Options::until(10.0)
        .tolerances(tol, tol)
        .output_final()
        .record(Record::State)
        .event(impact())
}

/// The six derivatives from one solve with sensitivities (under error control with `control`).
fn by_sensitivities(p: &Params, tol: f64, control: bool) -> Result<[f64; 6], Error> {
    let problem = uniform_problem(p)?;
    let mut o = options(tol).sensitivity_control(control);
    for s in seeds() {
        o = o.sensitivity(s);
    }
    let sol = solve(&problem, Dop853::default(), &o)?;
    let hit = sol
        .sensitivities
        .and_then(|s| s.events.into_iter().next().flatten())
        .ok_or(Error::Sensitivity {
            what: "no impact".into(),
        })?;
    let mut out = [0.0; 6];
    for j in 0..3 {
        out[2 * j] = hit.t[j];
        out[2 * j + 1] = hit.q[j][0];
    }
    Ok(out)
}

/// `(T, R)` of one plain solve.
fn impact_of(p: &Params, tol: f64) -> Result<(f64, f64), Error> {
    let sol = solve(&uniform_problem(p)?, Dop853::default(), &options(tol))?;
    let hit = sol.events.first().ok_or(Error::Sensitivity {
        what: "no impact".into(),
    })?;
    Ok((hit.t, hit.q[0]))
}

/// The six derivatives by central differences with relative step `rel`.
fn by_differences(p: &Params, tol: f64, rel: f64) -> Result<[f64; 6], Error> {
    let mut out = [0.0; 6];
    for j in 0..3 {
        let moved = |sign: f64| {
            let mut q = *p;
            let x = match j {
                0 => &mut q.v0,
                1 => &mut q.g,
                _ => &mut q.h0,
            };
            let d = rel * *x;
            *x += sign * d;
            (q, d)
        };
        let ((plus, d), (minus, _)) = (moved(1.0), moved(-1.0));
        let (tp, rp) = impact_of(&plus, tol)?;
        let (tm, rm) = impact_of(&minus, tol)?;
        out[2 * j] = (tp - tm) / (2.0 * d);
        out[2 * j + 1] = (rp - rm) / (2.0 * d);
    }
    Ok(out)
}

/// Seconds per call of `f`, one batch.
fn batch(f: &mut dyn FnMut() -> Result<(), Error>) -> Result<f64, Error> {
    let mut calls = 0u32;
    let start = Instant::now();
    loop {
        f()?;
        calls += 1;
        let s = start.elapsed().as_secs_f64();
        if s >= MIN_BATCH_SECONDS {
            return Ok(s / f64::from(calls));
        }
    }
}

fn main() -> Result<(), Error> {
    let p = paper();
    let e = exact(&p);
    println!("Derivatives of the impact (T, R) in v0, g, h0 at the paper's data; Dop853.");
    println!(
        "{:>8} {:>12} {:>10} {:>12} {:>10} {:>9} {:>12} {:>10}",
        "tol",
        "sens. error",
        "sens. [µs]",
        "free error",
        "free [µs]",
        "best δ/θ",
        "c.d. error",
        "c.d. [µs]"
    );
    // (error, seconds, finite-difference error, finite-difference seconds); NaN for the free runs.
    let mut rows = Vec::new();
    for tol in TOLERANCES {
        let s_err = largest_error(&by_sensitivities(&p, tol, true)?, &e);
        let f_err = largest_error(&by_sensitivities(&p, tol, false)?, &e);
        let mut best = (f64::INFINITY, 0.0);
        for k in 2..=8 {
            let rel = 10f64.powi(-k);
            let err = largest_error(&by_differences(&p, tol, rel)?, &e);
            if err < best.0 {
                best = (err, rel);
            }
        }
        let (mut ts, mut tf, mut td) = (Vec::new(), Vec::new(), Vec::new());
        for _ in 0..ROUNDS {
            for (times, control) in [(&mut ts, true), (&mut tf, false)] {
                times.push(batch(&mut || {
                    by_sensitivities(&p, tol, control).map(|d| {
                        black_box(d);
                    })
                })?);
            }
            td.push(batch(&mut || {
                by_differences(&p, tol, best.1).map(|d| {
                    black_box(d);
                })
            })?);
        }
        let (ts, tf, td) = (median(&mut ts), median(&mut tf), median(&mut td));
        println!(
            "{tol:>8.0e} {s_err:>12.2e} {:>10.1} {f_err:>12.2e} {:>10.1} {:>9.0e} {:>12.2e} {:>10.1}",
            ts * 1e6,
            tf * 1e6,
            best.1,
            best.0,
            td * 1e6,
        );
        rows.push((s_err, ts, best.0, td));
        rows.push((f_err, tf, f64::NAN, f64::NAN));
    }
    println!("\nAt equal accuracy (each central-difference point against the cheapest sensitivity run at least as accurate):");
    for &(_, _, d_err, d_time) in rows.iter().filter(|r| !r.2.is_nan()) {
        if let Some(&(s_err, s_time, ..)) = rows
            .iter()
            .filter(|r| r.0 <= d_err)
            .min_by(|a, b| a.1.total_cmp(&b.1))
        {
            println!(
                "  c.d. error {d_err:.1e} in {:.1} µs; sensitivities {s_err:.1e} in {:.1} µs: c.d./sens. = {:.2}",
                d_time * 1e6,
                s_time * 1e6,
                d_time / s_time
            );
        } else {
            println!("  c.d. error {d_err:.1e}: no sensitivity run here is that accurate");
        }
    }
    println!(
        "\nSeeds: {}; free: the seeds on the motion's steps, without error control.",
        NAMES.join(", ")
    );
    Ok(())
}
