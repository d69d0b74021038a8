//! The paper's two motions as scene files reproduce the Rust versions and the closed forms.

use chetaev::integrate::system::Stats;
use chetaev::prelude::*;
use chetaev_scene::{Outcome, Scene};
use uniform_projectile::closed_form::{table, uniform, Kinematics, Params};
use uniform_projectile::model::{classical_problem, impact, uniform_problem};

fn scene(name: &str) -> (Scene, Outcome) {
    let path = format!("{}/../../scenes/{name}", env!("CARGO_MANIFEST_DIR"));
    let scene = Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
    let outcome = scene.solve().unwrap_or_else(|e| panic!("{e}"));
    assert!(
        matches!(outcome.status, Status::Terminated { event: 0 }),
        "{:?}",
        outcome.status
    );
    (scene, outcome)
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

/// T, R, v_R and the impact angle from the scene's impact event.
fn impact_row(o: &Outcome) -> [f64; 4] {
    let e = &o.events[0];
    assert_eq!(o.event_name(e.index), "impact");
    let (vx, vy) = (e.qd[0], e.qd[1]);
    [e.t, e.q[0], vx.hypot(vy), (-vy).atan2(vx).to_degrees()]
}

/// The scene takes the steps the Rust model takes, with as many evaluations of the equations.
fn same_steps(o: &Outcome, rust: &Stats) {
    let s = &o.stats;
    assert_eq!(
        (s.accepted_steps, s.rejected_steps, s.rhs_evaluations),
        (
            rust.accepted_steps,
            rust.rejected_steps,
            rust.rhs_evaluations
        )
    );
}

/// Asserts that the rows agree column by column to `tol`, relative to `want`.
fn assert_row(got: [f64; 4], want: [f64; 4], tol: f64) {
    for i in 0..4 {
        assert!(
            rel(got[i], want[i]) < tol,
            "column {i}: {} vs {}",
            got[i],
            want[i]
        );
    }
}

/// The Rust model solved as the scene files solve it: Dop853, `rtol = atol = 1e-12`, to the impact.
fn solve_to_impact<M: Model>(problem: &Problem<M>) -> Solution {
    let options = Options::until(10.0)
        .tolerances(1e-12, 1e-12)
        .event(impact());
    solve(problem, Dop853::default(), &options).expect("solves")
}

fn closed_row(k: &Kinematics) -> [f64; 4] {
    [k.t_impact, k.range, k.impact_speed, k.impact_angle_deg()]
}

fn rust_row(sol: &Solution) -> [f64; 4] {
    let e = &sol.events[0];
    [
        e.t,
        e.q[0],
        e.qd[0].hypot(e.qd[1]),
        (-e.qd[1]).atan2(e.qd[0]).to_degrees(),
    ]
}

#[test]
fn uniform_scene_reproduces_table_42_1_and_the_rust_model() {
    let (_, o) = scene("uniform-projectile.toml");
    let p = Params::PAPER;
    let got = impact_row(&o);
    assert_row(got, closed_row(&table(&p).uniform), 1e-10);
    // The Rust model with the same method, tolerances and event.
    let rust = solve_to_impact(&uniform_problem(&p).expect("problem"));
    assert_row(got, rust_row(&rust), 1e-13);
    same_steps(&o, &rust.stats);
    // The multiplier along the motion against (42.40), μ = −(m g / 2 v0) tanh(g t / v0).
    assert_eq!(o.mu.len(), o.t.len());
    for (t, mu) in o.t.iter().zip(&o.mu) {
        let exact = uniform::multiplier(&p, *t);
        assert!(
            (mu[0] - exact).abs() < 1e-10 * (p.m * p.g / (2.0 * p.v0)),
            "t = {t}"
        );
    }
    // The work of the Chetaev force is the change of potential energy, m g (y − h0).
    let last = o.t.len() - 1;
    assert!((o.work[last] - p.m * p.g * (o.q[last][1] - p.h0)).abs() < 1e-9);
}

#[test]
fn classical_scene_reproduces_table_42_1_and_the_rust_model() {
    let (scene, o) = scene("classical-projectile.toml");
    assert_eq!(scene.k(), 0);
    let p = Params::PAPER;
    let got = impact_row(&o);
    assert_row(got, closed_row(&table(&p).classical), 1e-10);
    let rust = solve_to_impact(&classical_problem(&p).expect("problem"));
    assert_row(got, rust_row(&rust), 1e-13);
    same_steps(&o, &rust.stats);
}

#[test]
fn the_output_grid_ends_exactly_at_the_impact() {
    let (_, o) = scene("uniform-projectile.toml");
    assert_eq!(o.t.len(), 101);
    assert_eq!(o.passes, 2);
    assert_eq!(o.t[0], 0.0);
    assert_eq!(*o.t.last().expect("points"), o.events[0].t);
    assert!(o.t.windows(2).all(|w| w[1] > w[0]));
}

#[test]
fn a_scenes_right_hand_side_becomes_machine_code_equal_to_the_dual_number_one() {
    use chetaev::integrate::system::{OdeSystem, ReducedOde};
    for name in ["uniform-projectile.toml", "cartesian-pendulum.toml"] {
        let path = format!("{}/../../scenes/{name}", env!("CARGO_MANIFEST_DIR"));
        let scene = Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
        let problem = scene.problem().unwrap_or_else(|e| panic!("{e}"));
        let ops = problem.compiled().and_then(|c| c.native_operations());
        if cfg!(any(target_arch = "x86_64", target_arch = "aarch64")) {
            assert!(ops.is_some(), "{name}: this host has machine code");
        }
        let dual = problem.clone().with_route(Route::Dual);
        let (mut a, mut b) = (
            ReducedOde::for_problem(&problem, false),
            ReducedOde::for_problem(&dual, false),
        );
        let y: Vec<f64> = problem.q0().iter().chain(problem.qd0()).copied().collect();
        let (mut dya, mut dyb) = (vec![f64::NAN; y.len()], vec![f64::NAN; y.len()]);
        a.rhs(0.1, &y, &mut dya).expect("regular");
        b.rhs(0.1, &y, &mut dyb).expect("regular");
        for (u, v) in dya.iter().zip(&dyb) {
            assert!(
                (u - v).abs() <= 1e-12 * v.abs().max(1.0),
                "{name}: {dya:?} {dyb:?}"
            );
        }
    }
}
