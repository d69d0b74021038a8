//! The stiff scene of the uniform projectile: `v0 = 1e-3 m/s`, `g = 9.81 m/s²`, `h0 = 1 m`,
//! `m = 1 kg`. The speed is held at 1 mm/s, so the fall lasts about `h0/v0 = 1000 s`; the velocity
//! turns downwards within a few `v0/g ≈ 1e-4 s` and is held there by a reduced equation whose
//! eigenvalue is about `−g/v0 ≈ −1e4`. An explicit method is limited by stability to steps of some
//! `3e-4 s`; `Rodas4` is limited only by accuracy.

use std::time::Instant;

use chetaev::prelude::*;
use chetaev_suite::rel_err;
use uniform_projectile::closed_form::{table, Params};
use uniform_projectile::model::{impact, scaled_atol, uniform_problem};

const STIFF: Params = Params {
    v0: 1e-3,
    g: 9.81,
    h0: 1.0,
    m: 1.0,
};

/// Options for the scene: per-component absolute tolerances scaled to the motion, the terminal
/// impact, output at the end only.
fn options(rtol: f64) -> Options {
    let (atol_q, atol_qd) = scaled_atol(&STIFF, rtol);
    let mut o = Options::until(2.0 * STIFF.h0 / STIFF.v0)
        .output_final()
        .event(impact())
        .atol_per_component(&atol_q, &atol_qd);
    o.rtol = rtol;
    o
}

#[test]
fn rodas4_reaches_the_impact_of_the_stiff_scene_to_1e_8() {
    let exact = table(&STIFF).uniform;
    let problem = uniform_problem(&STIFF).expect("valid");
    let rtol = 1e-10;
    let start = Instant::now();
    let sol = solve(&problem, Rodas4, &options(rtol)).expect("valid");
    let elapsed = start.elapsed();
    assert_eq!(
        sol.status,
        Status::Terminated { event: 0 },
        "{:?}",
        sol.status
    );
    let hit = &sol.events[0];
    let (e_t, e_r) = (
        rel_err(hit.t, exact.t_impact),
        rel_err(hit.q[0], exact.range),
    );
    let s = sol.stats;
    eprintln!(
        "Rodas4, rtol {rtol:e}: T = {} (error {e_t:.2e}), R = {:e} (error {e_r:.2e}); \
         {} accepted + {} rejected steps, {} rhs, {} jacobians, {} LU, {elapsed:.2?}",
        hit.t,
        hit.q[0],
        s.accepted_steps,
        s.rejected_steps,
        s.rhs_evaluations,
        s.jacobian_evaluations,
        s.lu_decompositions
    );
    assert!(e_t <= 1e-8, "T: {e_t:e}");
    assert!(e_r <= 1e-8, "R: {e_r:e}");
    assert!(
        s.accepted_steps + s.rejected_steps <= 3000,
        "{} steps",
        s.accepted_steps + s.rejected_steps
    );
    assert!(s.jacobian_evaluations <= s.accepted_steps + s.rejected_steps + 1);
    assert_eq!(
        s.lu_decompositions,
        s.accepted_steps + s.rejected_steps + 1,
        "one LU per trial step, and one for the step onto the impact"
    );
}

#[test]
fn the_explicit_methods_detect_the_stiffness_and_suggest_rodas4() {
    let problem = uniform_problem(&STIFF).expect("valid");
    for method in AnyMethod::all(1e-3) {
        let name = method.info().name;
        let start = Instant::now();
        let sol = solve(&problem, method, &options(1e-10)).expect("valid");
        let elapsed = start.elapsed();
        let s = sol.stats;
        eprintln!(
            "{name}: {:?} after {} accepted + {} rejected steps, {} rhs, t = {}, {elapsed:.2?}",
            sol.status,
            s.accepted_steps,
            s.rejected_steps,
            s.rhs_evaluations,
            sol.t.last().copied().unwrap_or(f64::NAN)
        );
        // Every explicit method with error control has the stiffness test; the Rosenbrock
        // methods reach the impact, and Rk4 has no test (see `rk4_beyond_its_stability_…`).
        let has_test = method.clone().stiffness_detection_mut().is_some();
        if has_test {
            assert!(
                matches!(
                    sol.status,
                    Status::Failed(Error::Stiff {
                        suggestion: "Rodas4",
                        ..
                    })
                ),
                "{name}: {:?}",
                sol.status
            );
        }
        let info = method.info();
        if info.fixed_step.is_none() && !info.needs_jacobian {
            assert!(has_test, "{name} has error control but no stiffness test");
        }
    }
}

#[test]
fn the_step_that_finds_the_stiffness_keeps_its_events_and_output_times() {
    // The run ends after the step whose stiffness test fires; a crossing or an output time inside
    // that step was dropped, and a terminal event there became `Failed(Stiff)` with the motion
    // recorded past it.
    let problem = uniform_problem(&STIFF).expect("valid");
    let (v0, g, h0) = (STIFF.v0, STIFF.g, STIFF.h0);
    for method in AnyMethod::all(1e-3) {
        let name = method.info().name;
        if method.clone().stiffness_detection_mut().is_none() {
            continue;
        }
        let o = Options::until(2.0 * h0 / v0);
        let plain = solve(&problem, method, &o).expect("valid");
        assert!(
            matches!(plain.error(), Some(Error::Stiff { .. })),
            "{name}: {:?}",
            plain.status
        );
        let n = plain.len();
        let (ta, tb) = (plain.t[n - 2], plain.t[n - 1]);
        let level = 0.5 * (plain.q[n - 2][1] + plain.q[n - 1][1]);
        // y = h0 − (v0²/g) ln cosh(g t/v0), where ln cosh u = u − ln 2 to rounding (u ≈ 3000).
        let crossing = ((h0 - level) * g / (v0 * v0) + std::f64::consts::LN_2) * v0 / g;
        assert!(
            ta < crossing && crossing < tb,
            "{name}: {ta} {crossing} {tb}"
        );
        let event = move || Event::new("level", move |_t, q, _qd| q[1] - level).falling();
        let mid = 0.5 * (ta + tb);
        let o2 = o.clone().event(event()).output_times(vec![ta, mid]);
        let sol = solve(&problem, method, &o2).expect("valid");
        assert!(
            matches!(sol.error(), Some(Error::Stiff { .. })),
            "{name}: {:?}",
            sol.status
        );
        assert_eq!(sol.events.len(), 1, "{name}");
        let hit = sol.events[0].t;
        // Within 10 atol in height, at the falling speed v0.
        assert!(
            (hit - crossing).abs() * v0 < 1e-8,
            "{name}: {hit} against {crossing}"
        );
        assert!(sol.t.contains(&mid), "{name}: {:?}", sol.t);
        // Terminal: the run ends at the crossing, not past it.
        let sol = solve(&problem, method, &o.clone().event(event().terminal())).expect("valid");
        assert_eq!(sol.status, Status::Terminated { event: 0 }, "{name}");
        let (t, q, _) = sol.last().expect("kept");
        assert_eq!(t, hit, "{name}");
        assert!((q[1] - level).abs() < 1e-12, "{name}: {}", q[1] - level);
    }
}

/// The explicit method run to the end with its stiffness test off: the step count that the
/// stiffness test saves (a few million steps; run with `--ignored`, preferably `--release`).
#[test]
#[ignore = "a few million explicit steps"]
fn dopri5_without_stiffness_detection_needs_millions_of_steps() {
    let exact = table(&STIFF).uniform;
    let problem = uniform_problem(&STIFF).expect("valid");
    let method = Dopri5 {
        stiffness: StiffnessDetection::OFF,
    };
    let start = Instant::now();
    let sol = solve(&problem, method, &options(1e-10).max_steps(100_000_000)).expect("valid");
    let elapsed = start.elapsed();
    let s = sol.stats;
    let hit = sol.events.first().map_or(f64::NAN, |e| e.t);
    eprintln!(
        "Dopri5 without stiffness test: {:?}, T error {:.2e}, {} accepted + {} rejected steps, \
         {} rhs, {elapsed:.2?}",
        sol.status,
        rel_err(hit, exact.t_impact),
        s.accepted_steps,
        s.rejected_steps,
        s.rhs_evaluations
    );
    assert_eq!(sol.status, Status::Terminated { event: 0 });
    assert!(s.accepted_steps > 1_000_000);
}

/// Rk4's fixed step beyond its stability boundary (`h·|λ| ≈ 20` here): no error, a wrong motion
/// off the constraint, and the recorded residual that says so.
#[test]
fn rk4_beyond_its_stability_boundary_leaves_the_constraint_and_the_residual_shows_it() {
    let problem = uniform_problem(&STIFF).expect("valid");
    let sol = solve(&problem, Rk4::new(1e-3), &options(1e-10)).expect("valid");
    assert_eq!(
        sol.status,
        Status::Terminated { event: 0 },
        "{:?}",
        sol.status
    );
    let exact = table(&STIFF).uniform;
    assert!(
        sol.events[0].t < 0.5 * exact.t_impact,
        "{}",
        sol.events[0].t
    );
    let v0_squared = STIFF.v0 * STIFF.v0;
    let residual = sol
        .residual
        .as_flat()
        .iter()
        .fold(0.0f64, |m, f| m.max(f.abs()));
    let (_, _, qd) = sol.last().expect("recorded");
    eprintln!(
        "Rk4 beyond its stability boundary: impact at t = {}, max |f| = {:.1} v0², ẏ = {:.2} v0 \
         at the end",
        sol.events[0].t,
        residual / v0_squared,
        qd[1] / STIFF.v0
    );
    assert!(
        residual > v0_squared,
        "|f| ≤ {residual:e} against v0² = {v0_squared:e}"
    );
}
