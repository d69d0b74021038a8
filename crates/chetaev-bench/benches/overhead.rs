//! Paying only for what is used, per right-hand side: the paper's particle without constraints
//! (`K = 0`, `Problem::unconstrained`) against the same Lagrangian with the constraint
//! `ẋ − v0 = 0`, which the classical motion satisfies anyway, and against the uniform motion's
//! nonlinear constraint.
//!
//! `cargo bench -p chetaev-bench --bench overhead`

use std::hint::black_box;
use std::time::Duration;

use chetaev::equations::{evaluate, Workspace};
use chetaev_bench::overhead::steady_horizontal_problem;
use criterion::Criterion;
use uniform_projectile::closed_form::Params;
use uniform_projectile::model::{classical_problem, uniform_problem};

fn overhead(c: &mut Criterion) {
    let p = Params::PAPER;
    let free = classical_problem(&p).expect("valid");
    let held = steady_horizontal_problem(&p).expect("valid");
    let uniform = uniform_problem(&p).expect("valid");
    let q = [3.0, 4.0];
    let qd = [p.v0, -3.0];
    let mut g = c.benchmark_group("overhead");
    g.warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2))
        .sample_size(50);
    let mut ws = Workspace::for_model(free.model());
    g.bench_function("K = 0 (unconstrained)", |b| {
        b.iter(|| {
            evaluate(
                black_box(free.model()),
                &mut ws,
                0.0,
                black_box(&q),
                black_box(&qd),
            )
            .map(|d| d.qdd[0])
        })
    });
    let mut ws = Workspace::for_model(held.model());
    g.bench_function("K = 1 linear (xdot - v0)", |b| {
        b.iter(|| {
            evaluate(
                black_box(held.model()),
                &mut ws,
                0.0,
                black_box(&q),
                black_box(&qd),
            )
            .map(|d| d.qdd[0])
        })
    });
    let speed = (qd[0] * qd[0] + qd[1] * qd[1]).sqrt();
    let qd_u = [qd[0] * (p.v0 / speed), qd[1] * (p.v0 / speed)];
    let mut ws = Workspace::for_model(uniform.model());
    g.bench_function("K = 1 nonlinear (|qdot|^2 - v0^2)", |b| {
        b.iter(|| {
            evaluate(
                black_box(uniform.model()),
                &mut ws,
                0.0,
                black_box(&q),
                black_box(&qd_u),
            )
            .map(|d| d.qdd[0])
        })
    });
    g.finish();
}

fn main() {
    let mut c = Criterion::default().configure_from_args();
    overhead(&mut c);
    c.final_summary();
}
