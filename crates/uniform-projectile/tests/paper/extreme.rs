//! The paper's scene over extreme parameters: the dimensionless number z = g h0 / v0² from 1e-8
//! (a nearly straight fall) to 1e6 (a nearly vertical one), and v0, h0 each over 1e-6 … 1e6 (z up
//! to 1e19). A user's strategy: an explicit method first; where it reports stiffness, the implicit
//! method it names. The impact must agree with the closed forms to 1e-8 relative, or the run must
//! fail with a status that says why.

use chetaev::prelude::*;
use uniform_projectile::closed_form::{classical, table, uniform, Params};
use uniform_projectile::model::{impact, scaled_atol, uniform_problem};

const RTOL: f64 = 1e-11;

/// Relative difference `|a − b| / max(|b|, tiny)`.
fn rel_err(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(f64::MIN_POSITIVE)
}

/// Euclidean distance `|a − b|`.
fn distance(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len(), "vectors of different lengths");
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y) * (x - y))
        .sum::<f64>()
        .sqrt()
}

fn options(p: &Params) -> Options {
    let t_max = 20.0 * table(p).uniform.t_impact;
    let (aq, av) = scaled_atol(p, RTOL);
    Options::until(t_max)
        .tolerances(RTOL, 0.0)
        .atol_per_component(&aq, &av)
        .event(impact())
        .record(Record::State)
        .output_final()
}

/// Solves to the impact; returns the method that succeeded and the relative errors of T and R.
fn impact_errors(p: &Params) -> (&'static str, f64, f64) {
    let k = table(p).uniform;
    let problem = uniform_problem(p).expect("valid");
    let explicit = solve(&problem, Dop853::default(), &options(p)).expect("valid options");
    let sol = match explicit.error() {
        None => explicit,
        Some(Error::Stiff { suggestion, .. }) => {
            assert_eq!(*suggestion, "Rodas4");
            solve(&problem, Rodas4, &options(p)).expect("valid options")
        }
        Some(e) => panic!(
            "z = {:e}: Dop853 failed without saying it is stiff: {e}",
            p.z()
        ),
    };
    assert_eq!(
        sol.status,
        Status::Terminated { event: 0 },
        "z = {:e}",
        p.z()
    );
    let hit = &sol.events[0];
    (
        sol.method,
        rel_err(hit.t, k.t_impact),
        rel_err(hit.q[0], k.range),
    )
}

#[test]
fn closed_forms_stay_finite_over_the_whole_grid() {
    for e in -6..=6 {
        for f in -6..=6 {
            let p = Params {
                v0: 10f64.powi(e),
                g: 9.81,
                h0: 10f64.powi(f),
                m: 1.0,
            };
            let t = table(&p);
            for k in [t.classical, t.uniform] {
                for v in [
                    k.t_impact,
                    k.range,
                    k.impact_speed,
                    k.impact_angle,
                    k.length,
                ] {
                    assert!(
                        v.is_finite() && v > 0.0,
                        "v0 = {:e}, h0 = {:e}: {k:?}",
                        p.v0,
                        p.h0
                    );
                }
            }
            for s in [0.0, 0.5, 1.0, 2.0] {
                let tt = s * t.uniform.t_impact;
                let all = [
                    uniform::position(&p, tt),
                    uniform::velocity(&p, tt),
                    classical::position(&p, tt),
                ];
                assert!(all.iter().flatten().all(|v| v.is_finite()));
            }
        }
    }
}

#[test]
fn impact_to_1e_8_over_z_from_1e_minus_8_to_1e6() {
    let g = 9.81;
    for e in -8..=6 {
        let z = 10f64.powi(e);
        let p = Params {
            v0: 1.0,
            g,
            h0: z / g,
            m: 1.0,
        };
        let (method, et, er) = impact_errors(&p);
        assert!(
            et <= 1e-8 && er <= 1e-8,
            "z = {z:e} ({method}): T {et:e}, R {er:e}"
        );
    }
}

#[test]
fn impact_to_1e_8_over_v0_and_h0_from_1e_minus_6_to_1e6() {
    for ev in [-6, -3, 0, 3, 6] {
        for eh in [-6, -3, 0, 3, 6] {
            let p = Params {
                v0: 10f64.powi(ev),
                g: 9.81,
                h0: 10f64.powi(eh),
                m: 1.0,
            };
            let (method, et, er) = impact_errors(&p);
            assert!(
                et <= 1e-8 && er <= 1e-8,
                "v0 = {:e}, h0 = {:e} ({method}): T {et:e}, R {er:e}",
                p.v0,
                p.h0
            );
        }
    }
}

#[test]
fn an_end_time_a_few_ulps_after_the_start() {
    let p = uniform_problem(&Params::PAPER).expect("valid");
    for (t0, ulps) in [(0.0, 1.0), (0.0, 4.0), (1.0, 3.0)] {
        let t_end = if t0 == 0.0 {
            ulps * f64::MIN_POSITIVE
        } else {
            t0 + ulps * f64::EPSILON
        };
        let problem = if t0 == 0.0 {
            p.clone()
        } else {
            let q = SVector::from(uniform::position(&Params::PAPER, t0));
            let qd = SVector::from(uniform::velocity(&Params::PAPER, t0));
            Problem::new(**p.model(), t0, q, qd).expect("consistent")
        };
        for sol in [
            solve(&problem, Dopri5::default(), &Options::until(t_end)).expect("valid"),
            solve(&problem, Rodas4, &Options::until(t_end)).expect("valid"),
            solve(&problem, Rk4::new(0.1), &Options::until(t_end)).expect("valid"),
        ] {
            assert!(sol.is_success(), "{}: {:?}", sol.method, sol.status);
            let (t, q, _) = sol.last().expect("points");
            assert_eq!(t, t_end);
            assert!(distance(q, problem.q0()) <= 1e-12, "{}", sol.method);
        }
    }
}

#[test]
fn a_long_horizon_with_projection_keeps_the_constraint() {
    // 10^4 time units: the fall continues below y = 0 (nothing stops it) and turns vertical, where
    // the reduced equations become stiff (eigenvalue −g/v0), so the explicit Dop853 stops with
    // Error::Stiff; fixed-step Rk4 (h = 0.05, inside its stability region) and Rodas4 go on.
    let params = Params::PAPER;
    let p = uniform_problem(&params).expect("valid");
    let scale = params.v0 * params.v0;
    // Tighter than the default 1e-12: this well-conditioned constraint reaches rounding level.
    let strict = Projection {
        tol: 1e-14,
        ..Projection::default()
    };
    let opts = Options::until(1e4)
        .record(Record::Dynamics)
        .output_times((1..=10).map(|k| 1e3 * k as f64).collect());

    let dop = solve(
        &p,
        Dop853::default(),
        &opts.clone().tolerances(1e-10, 1e-10),
    )
    .expect("valid");
    assert!(
        matches!(
            dop.error(),
            Some(Error::Stiff {
                suggestion: "Rodas4",
                ..
            })
        ),
        "{:?}",
        dop.status
    );

    for (name, free, projected) in [
        (
            "Rk4",
            solve(&p, Rk4::new(0.05), &opts).expect("valid"),
            solve(&p, Rk4::new(0.05), &opts.clone().project(strict)).expect("valid"),
        ),
        (
            "Rodas4",
            solve(&p, Rodas4, &opts.clone().tolerances(1e-10, 1e-10)).expect("valid"),
            solve(
                &p,
                Rodas4,
                &opts.clone().tolerances(1e-10, 1e-10).project(strict),
            )
            .expect("valid"),
        ),
    ] {
        assert!(
            free.is_success() && projected.is_success(),
            "{name}: {:?} {:?}",
            free.status,
            projected.status
        );
        eprintln!(
            "{name}: max |f|/v0² over 10^4 time units: {:.1e} without projection, {:.1e} with ({} projections, {} Newton iterations)",
            free.max_residual().expect("recorded") / scale,
            projected.max_residual().expect("recorded") / scale,
            projected.stats.projections,
            projected.stats.projection_iterations
        );
        // With projection every recorded point satisfies the projection's bound,
        // |f| ≤ tol·|J|·|q̇| = 1e-14 · 2 v0² (or the rounding floor, 1e3·tol, where it stagnates).
        assert!(
            projected.max_residual().expect("recorded") <= 2e-14 * scale,
            "{name}: {:e}",
            projected.max_residual().expect("recorded")
        );
        // Far below the start the motion is a vertical fall at speed v0: ẏ = −v0.
        let (_, _, qd) = projected.last().expect("points");
        assert!(
            (qd[1] + params.v0).abs() <= 1e-10 * params.v0,
            "{name}: {qd:?}"
        );
    }
}
