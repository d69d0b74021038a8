//! The cost of one reduced right-hand side, `chetaev::equations::evaluate` with `f64`, on a chain
//! of `n` unit masses with `k` pair-speed constraints, for `n = 2, 3, 6, 12, 24` and
//! `k = 0, 1, n/2`. The group `rhs_cost` runs `Chain<N, K>` (sizes known when compiling, every
//! size its own type); the group `rhs_cost_dyn` runs the same chain as `DynChain`, whose sizes
//! are known only at run time (both from `chetaev_catalogue::benchmarks`).
//!
//! `cargo bench -p chetaev-bench --bench rhs_cost`; `cargo run -p chetaev-bench --bin bench-report`
//! then fits the growth in `n`.

use std::hint::black_box;
use std::time::Duration;

use chetaev::equations::{evaluate, Workspace};
use chetaev_catalogue::benchmarks::{Chain, DynChain};
use criterion::Criterion;

fn bench_one<const N: usize, const K: usize>(c: &mut Criterion) {
    let problem = Chain::<N, K>::problem().expect("the benchmark chain is consistent");
    let model = problem.model();
    let (q, qd) = (problem.q0(), problem.qd0());
    let mut ws = Workspace::for_model(model);
    let id = format!("n{N:02}_k{K:02}");
    let mut group = c.benchmark_group("rhs_cost");
    group
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2))
        .sample_size(50);
    group.bench_function(id, |b| {
        b.iter(|| {
            evaluate(black_box(model), &mut ws, 0.0, black_box(q), black_box(qd)).map(|d| d.qdd[0])
        })
    });
    group.finish();
}

/// The same chain with its sizes known at run time.
fn bench_dyn(c: &mut Criterion, n: usize, k: usize) {
    let problem = DynChain::problem(n, k).expect("the benchmark chain is consistent");
    let model = problem.model();
    let (q, qd) = (problem.q0(), problem.qd0());
    let mut ws = Workspace::for_model(model);
    let mut group = c.benchmark_group("rhs_cost_dyn");
    group
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2))
        .sample_size(50);
    group.bench_function(format!("n{n:02}_k{k:02}"), |b| {
        b.iter(|| {
            evaluate(black_box(model), &mut ws, 0.0, black_box(q), black_box(qd)).map(|d| d.qdd[0])
        })
    });
    group.finish();
}

fn rhs_cost(c: &mut Criterion) {
    bench_one::<2, 0>(c);
    bench_one::<2, 1>(c);
    bench_one::<3, 0>(c);
    bench_one::<3, 1>(c);
    bench_one::<6, 0>(c);
    bench_one::<6, 1>(c);
    bench_one::<6, 3>(c);
    bench_one::<12, 0>(c);
    bench_one::<12, 1>(c);
    bench_one::<12, 6>(c);
    bench_one::<24, 0>(c);
    bench_one::<24, 1>(c);
    bench_one::<24, 12>(c);
    for n in [2, 3, 6, 12, 24] {
        let mut ks = vec![0, 1, n / 2];
        ks.dedup();
        for k in ks {
            bench_dyn(c, n, k);
        }
    }
}

fn main() {
    let mut c = Criterion::default().configure_from_args();
    rhs_cost(&mut c);
    c.final_summary();
}
