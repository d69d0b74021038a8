//! How the cost of one right-hand side grows with the number of coordinates `n`, on both routes
//! (`Route::Graph`, the compiled tape of a run-time-size model, and `Route::Dual`, scalar dual
//! numbers), for two run-time-size models ([`DynModel`]):
//!
//! - `gas`: `p` particles in 3D (`n = 3p`), unit masses, each in its own harmonic well, with
//!   the kinetic energy held fixed by one constraint (`k = 1`):
//!
//!   ```text
//!   L = ½ |q̇|² − ½ |q|²,      f = |q̇|² − 2K = 0.
//!   ```
//!
//!   Newton form: `W = I`, `J = 2 q̇ᵀ`, `c = 0`, so `q̈ = F + 2μ q̇` with `F = −q`, and `J q̈ = 0`
//!   gives `μ = −F·q̇ / (2 q̇·q̇)`, hence the hand-written right-hand side (group `growth_gas`,
//!   function `hand`)
//!
//!   ```text
//!   q̈ = F − (F·q̇ / q̇·q̇) q̇.
//!   ```
//!
//! - `pendulums`: a chain of `n` planar pendulum links (angles `θ_i` from the downward vertical,
//!   unit masses and lengths, link 0 at the pivot) at constant `Σ θ̇_i²`:
//!
//!   ```text
//!   L = ½ Σ_ij M_ij(θ) θ̇_i θ̇_j + g Σ_i (n − i) cos θ_i,   M_ij = (n − max(i, j)) cos(θ_i − θ_j),
//!   f = Σ θ̇_i² − v² = 0,
//!   ```
//!
//!   so `W = M(θ)` is dense and varies with the configuration (no hand-written version).
//!
//! Before the timed groups, the one-time costs are printed (`compile ...` lines, wall clock by
//! `std::time::Instant`, best of a few repetitions): `Problem::dynamic` followed by the first
//! `Problem::compiled` (checking the initial state, recording, symbolic differentiation,
//! compiling the tape, and the dual-number evaluation that checks the compiled equations),
//! `Compiled::new` alone, and one evaluation on the dual route. The dual route is
//! timed only where one evaluation takes less than `DUAL_LIMIT`.
//!
//! `nice -n 10 cargo bench -p chetaev-bench --bench growth -- --warm-up-time 0.3
//! --measurement-time 1 --sample-size 20`; `docs/performance/growth.md` has the results.

use std::hint::black_box;
use std::time::{Duration, Instant};

use chetaev::equations::compiled::Compiled;
use chetaev::equations::{evaluate_with, Need, Workspace};
use chetaev::prelude::*;
use chetaev_catalogue::benchmarks::Gas;
use criterion::{BenchmarkGroup, Criterion, SamplingMode};

/// Sizes of the gas, `n = 3p` for `p = 10, 33, 100, 333, 1000` particles (30, 100, 300, 1000,
/// 3000 rounded to multiples of 3).
const GAS_N: [usize; 5] = [30, 99, 300, 999, 3000];
/// Sizes of the pendulum chain.
const PENDULUM_N: [usize; 4] = [6, 12, 24, 48];
/// The dual route is timed only where one evaluation takes less than this.
const DUAL_LIMIT: Duration = Duration::from_secs(1);
/// The dual route's reference evaluation inside `Problem::dynamic` is repeated only below this.
const REPEAT_LIMIT: Duration = Duration::from_secs(2);

/// The gas with `n` coordinates (`n` a multiple of 3) and a fixed, irregular state.
fn gas(n: usize) -> (Gas, Vec<f64>, Vec<f64>) {
    Gas::standard(n).expect("the gas has three coordinates per particle")
}

/// The hand-written right-hand side of the gas: `q̈ = F − (F·q̇ / q̇·q̇) q̇` with `F = −q`, into
/// `qdd` (length `n`); returns `μ = −F·q̇ / (2 q̇·q̇)`.
fn gas_rhs(q: &[f64], qd: &[f64], qdd: &mut [f64]) -> f64 {
    let (mut fv, mut vv) = (0.0, 0.0);
    for (x, v) in q.iter().zip(qd) {
        fv -= x * v;
        vv += v * v;
    }
    let alpha = fv / vv;
    for ((a, x), v) in qdd.iter_mut().zip(q).zip(qd) {
        *a = -x - alpha * v;
    }
    -0.5 * alpha
}

/// A chain of `n` unit planar pendulum links at constant `Σ θ̇_i² = v²`.
#[derive(Clone, Debug)]
struct Pendulums {
    n: usize,
    g: f64,
    /// `v² = Σ θ̇0_i²`.
    v2: f64,
}

impl DynModel for Pendulums {
    fn sizes(&self) -> (usize, usize) {
        (self.n, 1)
    }

    /// `L = ½ Σ_ij (n − max(i, j)) cos(θ_i − θ_j) θ̇_i θ̇_j + g Σ_i (n − i) cos θ_i`, the double sum
    /// taken over `i ≤ j` (the off-diagonal terms twice).
    fn lagrangian<R: Real>(&self, _t: R, q: &[R], qd: &[R]) -> R {
        let n = self.n;
        let mut kinetic = R::zero();
        for j in 0..n {
            let weight = (n - j) as f64;
            kinetic += qd[j] * qd[j] * (0.5 * weight);
            for i in 0..j {
                kinetic += (q[i] - q[j]).cos() * qd[i] * qd[j] * weight;
            }
        }
        let potential = (0..n).fold(R::zero(), |acc, i| {
            acc + q[i].cos() * (self.g * (n - i) as f64)
        });
        kinetic + potential
    }

    /// `f = Σ θ̇_i² − v²`.
    fn constraints<R: Real>(&self, _t: R, _q: &[R], qd: &[R], f: &mut [R]) {
        f[0] = qd.iter().fold(R::zero(), |acc, v| acc + *v * *v) - self.v2;
    }
}

/// The pendulum chain with `n` links and a fixed, irregular state.
fn pendulums(n: usize) -> (Pendulums, Vec<f64>, Vec<f64>) {
    let q: Vec<f64> = (0..n).map(|i| 0.3 * (0.9 * i as f64).sin()).collect();
    let qd: Vec<f64> = (0..n).map(|i| 0.5 * (1.7 * i as f64).cos()).collect();
    let v2 = qd.iter().map(|v| v * v).sum();
    (Pendulums { n, g: 9.81, v2 }, q, qd)
}

/// The best of `reps` timings of `f`.
fn best_of<T>(reps: usize, mut f: impl FnMut() -> T) -> (Duration, T) {
    let mut best = Duration::MAX;
    let mut out = None;
    for _ in 0..reps {
        let start = Instant::now();
        let value = f();
        best = best.min(start.elapsed());
        out = Some(value);
    }
    (best, out.expect("at least one repetition"))
}

/// The operation counts of the compiled tapes, `(core, full)`, out of their debug form.
fn operations(compiled: &Compiled) -> String {
    let text = format!("{compiled:?}");
    text.find("operations: ")
        .and_then(|at| text[at..].split_once(')').map(|(ops, _)| format!("{ops})")))
        .unwrap_or_default()
}

/// Milliseconds, for the `compile` lines.
fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

/// Flat sampling (each sample the same number of iterations) where one iteration is slow, so
/// that 20 samples need 20 iterations rather than 210.
fn sampling(group: &mut BenchmarkGroup<'_, criterion::measurement::WallTime>, one: Duration) {
    if one > Duration::from_millis(5) {
        group.sampling_mode(SamplingMode::Flat);
    } else {
        group.sampling_mode(SamplingMode::Auto);
    }
}

/// Times the one-time costs of `model` and, in `group`, one right-hand side on both routes;
/// returns the graph route's `q̈` for the caller to check.
fn bench_model<M: DynModel + Clone>(
    group: &mut BenchmarkGroup<'_, criterion::measurement::WallTime>,
    name: &str,
    (model, q, qd): (M, Vec<f64>, Vec<f64>),
) -> Vec<f64> {
    let (n, _) = model.sizes();
    let (compile, _) = best_of(3, || {
        Compiled::new(&model, 0.0, &q, &qd).expect("the model can be recorded")
    });
    let mut dual_ws = Workspace::for_model(&model);
    let (dual_one, reference) = best_of(1, || {
        evaluate_with(&model, None, &mut dual_ws, 0.0, &q, &qd, Need::Motion)
            .expect("the dual route solves the block system")
            .0
            .qdd
            .clone()
    });
    let reps = if dual_one < REPEAT_LIMIT { 3 } else { 1 };
    // The problem and its compiled equations, whether they are made at construction or on the
    // first call of `compiled`.
    let (build, problem) = best_of(reps, || {
        let problem = Problem::dynamic(model.clone(), 0.0, q.clone(), qd.clone())
            .expect("the state is consistent");
        black_box(problem.compiled().is_some());
        problem
    });
    let plan = problem.compiled();
    println!(
        "compile {name} n={n}: Problem::dynamic + compiled() {:.3} ms (best of {reps}), Compiled::new {:.3} ms, \
         one dual evaluation {:.3} ms, tape {}",
        ms(build),
        ms(compile),
        ms(dual_one),
        plan.map_or_else(|| "none".to_string(), operations),
    );
    let plan = plan.expect("the compiled equations agree with the dual route");

    let mut ws = Workspace::for_model(&model);
    let (graph_one, (qdd, fell_back)) = best_of(3, || {
        let (d, fell_back) = evaluate_with(&model, Some(plan), &mut ws, 0.0, &q, &qd, Need::Motion)
            .expect("the graph route solves the block system");
        (d.qdd.clone(), fell_back)
    });
    assert!(!fell_back, "{name} n={n}: the tape's guards held");
    let scale = reference.iter().fold(1.0f64, |m, v| m.max(v.abs()));
    let gap = qdd
        .iter()
        .zip(&reference)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(
        gap <= 1e-9 * scale,
        "{name} n={n}: the routes differ by {gap:e}"
    );

    sampling(group, graph_one);
    group.bench_function(format!("graph/{n:05}"), |b| {
        b.iter(|| {
            evaluate_with(
                black_box(&model),
                Some(plan),
                &mut ws,
                0.0,
                black_box(&q),
                black_box(&qd),
                Need::Motion,
            )
            .map(|(d, _)| d.qdd[0])
        })
    });
    if dual_one < DUAL_LIMIT {
        sampling(group, dual_one);
        group.bench_function(format!("dual/{n:05}"), |b| {
            b.iter(|| {
                evaluate_with(
                    black_box(&model),
                    None,
                    &mut dual_ws,
                    0.0,
                    black_box(&q),
                    black_box(&qd),
                    Need::Motion,
                )
                .map(|(d, _)| d.qdd[0])
            })
        });
    } else {
        println!(
            "skip {name} n={n}: one dual evaluation takes {:.1} s",
            dual_one.as_secs_f64()
        );
    }
    qdd
}

fn growth(c: &mut Criterion) {
    let mut group = c.benchmark_group("growth_gas");
    group
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(1))
        .sample_size(20);
    for n in GAS_N {
        let (model, q, qd) = gas(n);
        let from_graph = bench_model(&mut group, "gas", (model, q.clone(), qd.clone()));
        let mut qdd = vec![0.0; n];
        gas_rhs(&q, &qd, &mut qdd);
        let gap = qdd
            .iter()
            .zip(&from_graph)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(
            gap <= 1e-12,
            "gas n={n}: the hand-written q̈ differs by {gap:e}"
        );
        sampling(&mut group, Duration::ZERO);
        group.bench_function(format!("hand/{n:05}"), |b| {
            b.iter(|| gas_rhs(black_box(&q), black_box(&qd), &mut qdd))
        });
    }
    group.finish();

    let mut group = c.benchmark_group("growth_pendulums");
    group
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(1))
        .sample_size(20);
    for n in PENDULUM_N {
        bench_model(&mut group, "pendulums", pendulums(n));
    }
    group.finish();
}

fn main() {
    let mut c = Criterion::default().configure_from_args();
    growth(&mut c);
    c.final_summary();
}
