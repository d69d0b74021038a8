//! chetaev's Rodas4 (or another method, `--method`) on the stiff uniform projectile (v0 = 1e-3, g = 9.81, h0 = 1, m = 1), the
//! counterpart of `bench/scipy/lsoda.py`: same problem, end time, tolerances and error measure.
//!
//! Prints CSV to stdout, one row per tolerance:
//! `solver,tol,error,abs_error,median_s,runs,batch,rhs,jac,steps,rejected`.
//!
//! Usage: `rodas4 [--method rodas4,rodas5p] [--t-end T] [--runs N] [--min-batch-ms MS]
//! [--tols 1e-4,1e-5,...]`. The `solver` column is the method's name in lower case; with several
//! methods, each tolerance's timed solves alternate between them (A B A B ...).
//!
//! Time: the median over `--runs` (default 201) timed batches, after one untimed solve that gives
//! the error and the counters; a batch is as many solves as last `--min-batch-ms` (default 0: one
//! solve per batch, each solve timed on its own, as `lsoda.py` does), and its time is divided by
//! that number.

use std::hint::black_box;
use std::time::Instant;

use chetaev::prelude::*;
use uniform_projectile::closed_form::{uniform, Params};
use uniform_projectile::model::uniform_problem;

const P: Params = Params {
    v0: 1e-3,
    g: 9.81,
    h0: 1.0,
    m: 1.0,
};

struct Args {
    methods: Vec<AnyMethod>,
    t_end: f64,
    runs: usize,
    min_batch_s: f64,
    tols: Vec<f64>,
}

fn parse_args() -> Result<Args, String> {
    let mut a = Args {
        methods: vec![AnyMethod::Rodas4(Rodas4)],
        t_end: 999.9,
        runs: 201,
        min_batch_s: 0.0,
        tols: (4..=10).map(|k| 10f64.powi(-k)).collect(),
    };
    let mut it = std::env::args().skip(1);
    while let Some(flag) = it.next() {
        let mut value = || it.next().ok_or_else(|| format!("{flag} needs a value"));
        match flag.as_str() {
            "--method" => {
                a.methods = value()?
                    .split(',')
                    .map(|m| AnyMethod::from_name(m.trim(), None))
                    .collect::<Result<_, _>>()
                    .map_err(|e| format!("--method: {e}"))?;
            }
            "--t-end" => a.t_end = value()?.parse().map_err(|e| format!("--t-end: {e}"))?,
            "--runs" => a.runs = value()?.parse().map_err(|e| format!("--runs: {e}"))?,
            "--min-batch-ms" => {
                let ms: f64 = value()?
                    .parse()
                    .map_err(|e| format!("--min-batch-ms: {e}"))?;
                a.min_batch_s = ms * 1e-3;
            }
            "--tols" => {
                a.tols = value()?
                    .split(',')
                    .map(|s| s.trim().parse::<f64>().map_err(|e| format!("--tols: {e}")))
                    .collect::<Result<_, _>>()?;
            }
            _ => return Err(format!("unknown argument {flag}")),
        }
    }
    if a.runs == 0 {
        return Err("--runs must be at least 1".into());
    }
    Ok(a)
}

/// The error measure shared with lsoda.py: each component of `(x, y, ẋ, ẏ)(t_end)` minus the closed
/// form (42.29)–(42.30), divided by its scale (x: v0²/g, y: h0, velocities: v0); the largest
/// magnitude. Also returns the unscaled largest magnitude.
fn errors(t_end: f64, q: &[f64], qd: &[f64]) -> (f64, f64) {
    let pos = uniform::position(&P, t_end);
    let vel = uniform::velocity(&P, t_end);
    let scales = [P.v0 * P.v0 / P.g, P.h0, P.v0, P.v0];
    let diff = [q[0] - pos[0], q[1] - pos[1], qd[0] - vel[0], qd[1] - vel[1]];
    let scaled = diff
        .iter()
        .zip(scales)
        .map(|(d, s)| (d / s).abs())
        .fold(0.0, f64::max);
    let plain = diff.iter().map(|d| d.abs()).fold(0.0, f64::max);
    (scaled, plain)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

fn main() {
    let args = match parse_args() {
        Ok(a) => a,
        Err(e) => {
            eprintln!("rodas4: {e}");
            std::process::exit(2);
        }
    };
    let problem = match uniform_problem(&P) {
        Ok(p) => p,
        Err(e) => {
            eprintln!("rodas4: problem: {e}");
            std::process::exit(1);
        }
    };
    println!("solver,tol,error,abs_error,median_s,runs,batch,rhs,jac,steps,rejected");
    for &tol in &args.tols {
        let opts = Options::until(args.t_end)
            .tolerances(tol, tol)
            .record(Record::State)
            .output_final();
        let solve_once = |method| chetaev::solve(black_box(&problem), method, black_box(&opts));
        // Per method: the untimed solve's row, and the batch size.
        let mut timed = Vec::new();
        for &method in &args.methods {
            let name = method.info().name.to_ascii_lowercase();
            let sol = match solve_once(method) {
                Ok(s) if s.is_success() => s,
                Ok(s) => {
                    eprintln!("rodas4: {name} tol {tol:e}: {:?}", s.error());
                    continue;
                }
                Err(e) => {
                    eprintln!("rodas4: {name} tol {tol:e}: {e}");
                    continue;
                }
            };
            let Some((t, q, qd)) = sol.last() else {
                eprintln!("rodas4: {name} tol {tol:e}: no final state");
                continue;
            };
            if t != args.t_end {
                eprintln!("rodas4: {name} tol {tol:e}: stopped at t = {t}");
                continue;
            }
            let (err, abs_err) = errors(t, q, qd);
            // Batch size: enough solves that one timed batch lasts at least min_batch_s.
            let start = Instant::now();
            black_box(solve_once(method).ok());
            let one = start.elapsed().as_secs_f64().max(1e-9);
            let batch = ((args.min_batch_s / one).ceil() as usize).max(1);
            timed.push((method, name, err, abs_err, sol.stats, batch, Vec::new()));
        }
        // The methods timed in turn, A B A B ..., so that a change of load falls on all alike.
        for _ in 0..args.runs {
            for (method, _, _, _, _, batch, times) in &mut timed {
                let start = Instant::now();
                for _ in 0..*batch {
                    black_box(solve_once(*method).ok());
                }
                times.push(start.elapsed().as_secs_f64() / *batch as f64);
            }
        }
        for (_, name, err, abs_err, s, batch, times) in timed {
            println!(
                "{name},{tol:e},{err:.6e},{abs_err:.6e},{:.6e},{},{batch},{},{},{},{}",
                median(times),
                args.runs,
                s.rhs_evaluations,
                s.jacobian_evaluations,
                s.accepted_steps,
                s.rejected_steps
            );
        }
    }
}
