//! Paying only for what is used, per right-hand side: the paper's particle without constraints
//! (`K = 0`, `Problem::unconstrained`) against the same Lagrangian with the constraint
//! `ẋ − v0 = 0`, which the classical motion satisfies anyway, and against the uniform motion's
//! nonlinear constraint.
//!
//! `cargo bench -p chetaev-bench --bench overhead`

use std::hint::black_box;
use std::time::Duration;

use chetaev::equations::{dynamics, saddle::SaddleWorkspace};
use chetaev::prelude::*;
use chetaev_bench::models::steady_horizontal_problem;
use criterion::Criterion;
use uniform_projectile::closed_form::Params;
use uniform_projectile::model::{classical_problem, uniform_problem};

fn overhead(c: &mut Criterion) {
    let p = Params::PAPER;
    let free = classical_problem(&p).expect("valid");
    let held = steady_horizontal_problem(&p).expect("valid");
    let uniform = uniform_problem(&p).expect("valid");
    let q = SVector::from([3.0, 4.0]);
    let qd = SVector::from([p.v0, -3.0]);
    let mut ws = SaddleWorkspace::default();
    let mut g = c.benchmark_group("overhead");
    g.warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2))
        .sample_size(50);
    g.bench_function("K = 0 (unconstrained)", |b| {
        b.iter(|| {
            dynamics::<_, f64, 2, 0>(
                black_box(free.model()),
                &mut ws,
                0.0,
                black_box(&q),
                black_box(&qd),
            )
        })
    });
    g.bench_function("K = 1 linear (xdot - v0)", |b| {
        b.iter(|| {
            dynamics::<_, f64, 2, 1>(
                black_box(held.model()),
                &mut ws,
                0.0,
                black_box(&q),
                black_box(&qd),
            )
        })
    });
    let qd_u = qd * (p.v0 / qd.norm());
    g.bench_function("K = 1 nonlinear (|qdot|^2 - v0^2)", |b| {
        b.iter(|| {
            dynamics::<_, f64, 2, 1>(
                black_box(uniform.model()),
                &mut ws,
                0.0,
                black_box(&q),
                black_box(&qd_u),
            )
        })
    });
    g.finish();
}

fn main() {
    let mut c = Criterion::default().configure_from_args();
    overhead(&mut c);
    c.final_summary();
}
