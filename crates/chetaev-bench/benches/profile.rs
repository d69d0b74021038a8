//! Where the time of one right-hand side of the paper's model goes: the three autodiff passes
//! over `L`, the two over `f`, the block solve, the whole right-hand side
//! (`chetaev::equations::evaluate`, named `dynamics` in the results), the integrator's right-hand
//! side as machine code and interpreted, one dual-number evaluation
//! (a Rodas4 Jacobian takes `2·dim + 1 = 5` of them), and the hand-written right-hand sides and
//! Jacobians for comparison.
//!
//! The one-time cost of a problem and of its compiled equations is timed too.
//!
//! `cargo bench -p chetaev-bench --bench profile`

use std::hint::black_box;
use std::time::Duration;

use chetaev::equations::derivatives::{
    constraint_derivatives, lagrangian_derivatives, velocity_hessian,
};
use chetaev::equations::{
    evaluate, evaluate_with, saddle, saddle::SaddleWorkspace, Need, Workspace,
};
use chetaev::integrate::system::{Jacobian, OdeSystem, ReducedOde};
use chetaev::prelude::*;
use chetaev_bench::handwritten::{Full, Reduced};
use criterion::Criterion;
use num_dual::Dual64;
use uniform_projectile::closed_form::{uniform, Params};
use uniform_projectile::model::uniform_problem;

fn profile(c: &mut Criterion) {
    let p = Params::PAPER;
    let problem = uniform_problem(&p).expect("the paper's problem is valid");
    let fixed = *problem.model();
    let model = fixed.0;
    let t = 0.5;
    let q = SVector::from(uniform::position(&p, t));
    let qd = SVector::from(uniform::velocity(&p, t));
    let mut g = c.benchmark_group("profile");
    g.warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2))
        .sample_size(50);

    let mut workspace = Workspace::for_model(&fixed);
    g.bench_function("dynamics", |b| {
        b.iter(|| {
            evaluate(
                black_box(&fixed),
                &mut workspace,
                t,
                black_box(q.as_slice()),
                black_box(qd.as_slice()),
            )
            .map(|d| d.qdd[0])
        })
    });
    // The one-time cost of the compiled equations: a problem built, and built then compiled
    // (recorded, differentiated, checked against the dual-number path).
    g.bench_function("Problem::new", |b| {
        b.iter(|| uniform_problem(black_box(&p)).map(|pr| pr.q0()[1]))
    });
    g.bench_function("Problem::new and its compiled equations", |b| {
        b.iter(|| uniform_problem(black_box(&p)).map(|pr| pr.compiled().is_some()))
    });
    let compiled = problem.compiled();
    for (name, need) in [
        ("compiled dynamics (right-hand side)", Need::Motion),
        (
            "compiled dynamics (with the rates of the energy balance)",
            Need::Rates,
        ),
        (
            "compiled dynamics (everything, as at an output point)",
            Need::All,
        ),
    ] {
        let mut workspace = Workspace::for_model(&fixed);
        g.bench_function(name, |b| {
            b.iter(|| {
                evaluate_with(
                    black_box(&fixed),
                    compiled,
                    &mut workspace,
                    t,
                    black_box(q.as_slice()),
                    black_box(qd.as_slice()),
                    need,
                )
                .map(|(d, _)| d.qdd[0])
            })
        });
    }
    // The integrator's right-hand side, `ReducedOde::rhs` on the state `(q, q̇)`, as machine code
    // where the host has it (made at once here, as after `NATIVE_AFTER` right-hand sides in a
    // run); before that it is `compiled dynamics (right-hand side)` above and a few ns of glue.
    if problem
        .compiled()
        .and_then(|c| c.native_operations())
        .is_some()
    {
        let y_state = [q[0], q[1], qd[0], qd[1]];
        let mut sys = ReducedOde::for_problem(&problem, false);
        let mut dy = [0.0; 4];
        g.bench_function("integrator's rhs (machine code)", |b| {
            b.iter(|| sys.rhs(t, black_box(&y_state), &mut dy).map(|()| dy[3]))
        });
    }
    g.bench_function("lagrangian_derivatives (passes A, B, C)", |b| {
        b.iter(|| lagrangian_derivatives(black_box(&model), t, black_box(&q), black_box(&qd)))
    });
    g.bench_function("velocity_hessian (pass A)", |b| {
        b.iter(|| velocity_hessian(black_box(&model), t, black_box(&q), black_box(&qd)))
    });
    g.bench_function("constraint_derivatives (two passes)", |b| {
        b.iter(|| {
            constraint_derivatives::<_, f64, 2, 1>(
                black_box(&model),
                t,
                black_box(&q),
                black_box(&qd),
            )
        })
    });
    let ld = lagrangian_derivatives(&model, t, &q, &qd);
    let cd = constraint_derivatives::<_, f64, 2, 1>(&model, t, &q, &qd);
    let r = ld.dl_dq - ld.g;
    let s = -cd.c;
    let mut ws = SaddleWorkspace::default();
    g.bench_function("saddle::solve (3 × 3)", |b| {
        b.iter(|| {
            saddle::solve(
                &mut ws,
                black_box(&ld.w),
                black_box(&cd.j),
                black_box(&r),
                black_box(&s),
            )
        })
    });

    let mut wsd = Workspace::<Dual64>::for_model(&fixed);
    let qd_dual = qd.map(Dual64::from_re);
    let mut q_dual = q.map(Dual64::from_re);
    q_dual[0].eps = 1.0;
    g.bench_function("dynamics over Dual64 (one Jacobian column)", |b| {
        b.iter(|| {
            evaluate(
                black_box(&fixed),
                &mut wsd,
                Dual64::from_re(t),
                black_box(q_dual.as_slice()),
                black_box(qd_dual.as_slice()),
            )
            .map(|d| d.qdd[0])
        })
    });

    let y_full = [q[0], q[1], qd[0], qd[1]];
    let mut full = Full::new(p.g);
    let mut dy = [0.0; 4];
    g.bench_function("hand-written full rhs", |b| {
        b.iter(|| full.rhs(t, black_box(&y_full), &mut dy))
    });
    let y_red = [q[0], q[1], qd[1]];
    let mut reduced = Reduced::new(p.g, p.v0);
    let mut dz = [0.0; 3];
    g.bench_function("hand-written (42.28) rhs", |b| {
        b.iter(|| reduced.rhs(t, black_box(&y_red), &mut dz))
    });
    let mut jac = Jacobian::new(4);
    g.bench_function("hand-written full jacobian", |b| {
        b.iter(|| full.jacobian(t, black_box(&y_full), &mut jac))
    });
    g.finish();
}

fn main() {
    let mut c = Criterion::default().configure_from_args();
    profile(&mut c);
    c.final_summary();
}
