//! Bad input gets a typed error that says what was wrong; failures mid-run keep what was computed.

use chetaev::integrate::options::MAX_EVENT_SAMPLES;
use chetaev::prelude::*;
use chetaev_suite::{distance, norm};
use uniform_projectile::closed_form::Params;
use uniform_projectile::model::{impact, uniform_problem, Projectile, UniformProjectile};

fn model(v0: f64) -> UniformProjectile {
    UniformProjectile {
        particle: Projectile { m: 1.0, g: 10.0 },
        v0,
    }
}

#[test]
fn non_finite_initial_state_is_rejected() {
    let e = Problem::new(
        model(10.0),
        0.0,
        SVector::from([f64::NAN, 5.0]),
        SVector::from([10.0, 0.0]),
    )
    .unwrap_err();
    assert!(
        matches!(e, Error::NonFiniteInput { ref what, .. } if what == "q0[0]"),
        "{e}"
    );
    let e = Problem::new(
        model(10.0),
        f64::INFINITY,
        SVector::zeros(),
        SVector::from([10.0, 0.0]),
    )
    .unwrap_err();
    assert!(matches!(e, Error::NonFiniteInput { .. }), "{e}");
}

#[test]
fn zero_speed_under_the_constant_speed_constraint_is_degenerate() {
    let e = Problem::new(model(0.0), 0.0, SVector::from([0.0, 5.0]), SVector::zeros()).unwrap_err();
    assert!(
        matches!(e, Error::DegenerateConstraint { index: 1, .. }),
        "{e}"
    );
    assert!(e.to_string().contains("v0 must not be zero"), "{e}");
}

#[test]
fn inconsistent_initial_velocity_is_an_error_unless_projection_is_asked_for() {
    let qd0 = SVector::from([10.5, 0.0]);
    let e = Problem::new(model(10.0), 0.0, SVector::from([0.0, 5.0]), qd0).unwrap_err();
    assert!(
        matches!(e, Error::InconsistentInitialState { index: 1, .. }),
        "{e}"
    );
    assert!(e.to_string().contains("with_projected_velocity"));
    let p = Problem::with_projected_velocity(model(10.0), 0.0, SVector::from([0.0, 5.0]), qd0)
        .expect("projectable");
    assert!((norm(p.qd0()) - 10.0).abs() <= 1e-14 * 10.0);
    assert_eq!(
        p.qd0()[1],
        0.0,
        "the minimal correction in the metric W = m I keeps the direction"
    );
}

/// The same constraint twice: J has rank 1, not 2.
#[derive(Debug)]
struct Twice;
impl Lagrangian<2> for Twice {
    fn lagrangian<R: Real>(&self, _t: R, _q: &SVector<R, 2>, qd: &SVector<R, 2>) -> R {
        qd.dot(qd) * 0.5
    }
}
impl Constraints<2, 2> for Twice {
    fn constraints<R: Real>(&self, _t: R, _q: &SVector<R, 2>, qd: &SVector<R, 2>) -> SVector<R, 2> {
        let f = qd.dot(qd) - 1.0;
        SVector::from([f, f])
    }
}

#[test]
fn rank_deficient_constraints_are_singular() {
    let e = Problem::new(Twice, 0.0, SVector::zeros(), SVector::from([1.0, 0.0])).unwrap_err();
    assert!(matches!(e, Error::Singular { t: 0.0, .. }), "{e}");
}

/// y has no kinetic term: W is singular, and no constraint fixes ÿ.
#[derive(Debug)]
struct NoKinetic;
impl Lagrangian<2> for NoKinetic {
    fn lagrangian<R: Real>(&self, _t: R, q: &SVector<R, 2>, qd: &SVector<R, 2>) -> R {
        qd[0] * qd[0] * 0.5 - q[1] * q[1]
    }
}

#[test]
fn singular_mass_matrix_is_singular() {
    let e = Problem::unconstrained(NoKinetic, 0.0, SVector::zeros(), SVector::zeros()).unwrap_err();
    assert!(matches!(e, Error::Singular { .. }), "{e}");
}

/// A potential √(1 − t) y that stops existing at t = 1.
struct Expiring;
impl Lagrangian<2> for Expiring {
    fn lagrangian<R: Real>(&self, t: R, q: &SVector<R, 2>, qd: &SVector<R, 2>) -> R {
        qd.dot(qd) * 0.5 - (-t + 1.0).sqrt() * q[1]
    }
}

/// The paper's particle at speed 10 with the domain ending at `t = 1` elsewhere: in a term of `L`
/// in `t` alone, which the motion never differentiates into but the energy balance does (`∂L/∂t`),
/// and in a constraint whose value and gradient carry the factor `√(1 − t)`.
struct EndsAtOne {
    in_l: bool,
}

impl DynModel for EndsAtOne {
    fn sizes(&self) -> (usize, usize) {
        (2, 1)
    }
    fn lagrangian<R: Real>(&self, t: R, q: &[R], qd: &[R]) -> R {
        let l = (qd[0] * qd[0] + qd[1] * qd[1]) * 0.5 - q[1] * 10.0;
        if self.in_l {
            l + (-t + 1.0).sqrt()
        } else {
            l
        }
    }
    fn constraints<R: Real>(&self, t: R, _q: &[R], qd: &[R], f: &mut [R]) {
        let factor = if self.in_l {
            R::one()
        } else {
            (-t + 1.0).sqrt()
        };
        f[0] = (qd[0] * qd[0] + qd[1] * qd[1] - 100.0) * factor;
    }
}

/// Where the model stops existing, every route and method stops there as at a NaN (rejecting the
/// step, then `NonFiniteEvaluation` or `StepSizeTooSmall`), keeping the motion up to it: not a
/// singular block system past the end, nor a non-finite state.
#[test]
fn a_model_that_leaves_its_domain_mid_run_stops_there_on_every_route() {
    for in_l in [true, false] {
        for route in [Route::Graph, Route::Dual] {
            let problem =
                Problem::dynamic(EndsAtOne { in_l }, 0.0, vec![0.0, 5.0], vec![10.0, 0.0])
                    .expect("valid at t0")
                    .with_route(route);
            for method in [
                AnyMethod::Dopri5(Dopri5::default()),
                AnyMethod::Dop853(Dop853::default()),
                AnyMethod::Rodas4(Rodas4),
            ] {
                let options = Options::until(2.0).record(Record::Energy);
                let sol = solve(&problem, method, &options).expect("valid options");
                let case = format!("in_l {in_l}, {route:?}, {}", method.name());
                let t = match sol.error() {
                    Some(
                        Error::NonFiniteEvaluation { t, .. } | Error::StepSizeTooSmall { t, .. },
                    ) => *t,
                    other => panic!("{case}: expected a stop at a NaN, got {other:?}"),
                };
                assert!(t > 0.99 && t <= 1.0 + 1e-9, "{case}: t = {t}");
                let last = *sol.t.last().expect("points");
                assert!(last > 0.99, "{case}: the motion is kept to {last} only");
                assert!(
                    sol.work
                        .iter()
                        .chain(&sol.dl_dt_integral)
                        .all(|v| v.is_finite()),
                    "{case}: no NaN in the balance"
                );
            }
        }
    }
    // The limit docs/where-it-breaks.md states: by a static model's compiled equations a term of
    // `L` in `t` alone is evaluated only where `L` is recorded, so a run recording the state alone
    // goes on past the end of its domain; by dual numbers it stops there.
    struct Static;
    impl Lagrangian<2> for Static {
        fn lagrangian<R: Real>(&self, t: R, q: &SVector<R, 2>, qd: &SVector<R, 2>) -> R {
            EndsAtOne { in_l: true }.lagrangian(t, q.as_slice(), qd.as_slice())
        }
    }
    impl Constraints<2, 1> for Static {
        fn constraints<R: Real>(
            &self,
            t: R,
            q: &SVector<R, 2>,
            qd: &SVector<R, 2>,
        ) -> SVector<R, 1> {
            model(10.0).constraints(t, q, qd)
        }
    }
    let problem = Problem::new(
        Static,
        0.0,
        SVector::from([0.0, 5.0]),
        SVector::from([10.0, 0.0]),
    )
    .expect("valid at t0");
    let state = Options::until(2.0).record(Record::State);
    let sol = solve(&problem, Dop853::default(), &state).expect("valid options");
    assert_eq!(sol.status, Status::Success);
    let sol = solve(&problem.with_route(Route::Dual), Dop853::default(), &state).expect("valid");
    assert!(
        matches!(sol.error(), Some(Error::NonFiniteEvaluation { t, .. } | Error::StepSizeTooSmall { t, .. }) if *t <= 1.0 + 1e-9),
        "{:?}",
        sol.status
    );
}

#[test]
fn nan_mid_run_is_reported_with_time_and_the_trajectory_so_far() {
    let p = Problem::unconstrained(Expiring, 0.0, SVector::zeros(), SVector::from([1.0, 0.0]))
        .expect("valid at t0");
    let sol = solve(&p, Dopri5::default(), &Options::until(2.0)).expect("valid options");
    match sol.error() {
        Some(Error::NonFiniteEvaluation { t, q, .. }) => {
            assert!(*t > 0.99 && *t <= 1.01, "t = {t}");
            assert_eq!(q.len(), 2);
        }
        other => panic!("expected NonFiniteEvaluation, got {other:?}"),
    }
    assert!(
        sol.len() > 3 && *sol.t.last().expect("points") > 0.9,
        "the motion up to the failure is kept"
    );
    assert!(
        sol.q.iter().all(|q| q.iter().all(|v| v.is_finite())),
        "no NaN in the output"
    );
}

#[test]
fn bad_tolerances_are_rejected() {
    let p = uniform_problem(&Params::PAPER).expect("valid");
    for (rtol, atol) in [
        (0.0, 0.0),
        (-1e-6, 1e-9),
        (f64::NAN, 1e-9),
        (1e-6, f64::INFINITY),
        (1e-6, -1.0),
        (1e-17, 1e-9),
    ] {
        let e = solve(
            &p,
            Dopri5::default(),
            &Options::until(1.0).tolerances(rtol, atol),
        )
        .unwrap_err();
        assert!(
            matches!(e, Error::InvalidOption { .. }),
            "{rtol} {atol}: {e}"
        );
    }
    let e = solve(
        &p,
        Dopri5::default(),
        &Options::until(1.0).atol_per_component(&[1e-9, -1.0], &[1e-9, 1e-9]),
    )
    .unwrap_err();
    assert!(
        matches!(e, Error::InvalidOption { name: "atol", .. }),
        "{e}"
    );
    // With rtol = 0 the absolute tolerance alone sets the accuracy: a subnormal one cannot.
    let e = solve(
        &p,
        Dopri5::default(),
        &Options::until(1.0).tolerances(0.0, 1e-320),
    )
    .unwrap_err();
    assert!(
        matches!(e, Error::InvalidOption { name: "atol", value, .. } if value == 1e-320),
        "{e}"
    );
    let sol = solve(
        &p,
        Dopri5::default(),
        &Options::until(1.0).tolerances(0.0, 1e-10),
    )
    .expect("rtol = 0 with a usable atol is valid");
    assert!(sol.is_success(), "{:?}", sol.status);
    // A tolerance that never rejects holds an adaptive method to fixed steps.
    let sol = solve(
        &p,
        Dopri5::default(),
        &Options::until(1.0)
            .tolerances(1e3, 1e3)
            .initial_step(0.125)
            .max_step(0.125),
    )
    .expect("a loose tolerance is valid");
    assert!(sol.is_success(), "{:?}", sol.status);
    assert_eq!((sol.stats.accepted_steps, sol.stats.rejected_steps), (8, 0));
    let e = solve(&p, Rk4::new(0.0), &Options::until(1.0)).unwrap_err();
    assert!(
        matches!(e, Error::InvalidOption { name: "Rk4::h", .. }),
        "{e}"
    );
    let e = solve(&p, Dopri5::default(), &Options::until(f64::NAN)).unwrap_err();
    assert!(matches!(e, Error::NonFiniteInput { .. }), "{e}");
    // A projection that may not iterate is refused before the run, not failed in it.
    let e = solve(
        &p,
        Dopri5::default(),
        &Options::until(1.0).project(Projection {
            max_iterations: 0,
            ..Projection::default()
        }),
    )
    .unwrap_err();
    assert!(
        matches!(
            e,
            Error::InvalidOption {
                name: "projection max_iterations",
                ..
            }
        ),
        "{e}"
    );
    // So many event samples that counting them overflows: refused, the run never starts.
    for samples in [
        MAX_EVENT_SAMPLES + 1,
        usize::MAX / 32,
        usize::MAX - 1,
        usize::MAX,
    ] {
        let options = Options::until(1.0).event(impact()).event_samples(samples);
        let e = solve(&p, Dopri5::default(), &options).unwrap_err();
        assert!(
            matches!(
                e,
                Error::InvalidOption {
                    name: "event_samples",
                    ..
                }
            ),
            "{samples}: {e}"
        );
    }
    let options = Options::until(1.0)
        .event(impact())
        .event_samples(MAX_EVENT_SAMPLES);
    let sol = solve(&p, Dopri5::default(), &options).expect("valid");
    assert!(sol.is_success(), "{:?}", sol.status);
    // A projection tolerance below the rounding error of f can never be met.
    let tight = |tol| Projection {
        tol,
        ..Projection::default()
    };
    // So is one that a velocity as far off as its own size would meet.
    for tol in [1e-17, 1.0, 1e10] {
        let e = solve(
            &p,
            Dopri5::default(),
            &Options::until(1.0).project(tight(tol)),
        )
        .unwrap_err();
        assert!(
            matches!(e, Error::InvalidOption { name: "projection tol", value, .. } if value == tol),
            "{e}"
        );
    }
    let sol = solve(
        &p,
        Dopri5::default(),
        &Options::until(1.0).project(tight(1e-14)),
    );
    assert!(sol.expect("valid").is_success());
}

/// Steps too short to change `t` (below 4 ulps of it) are refused before the run, whether they are
/// a fixed step or the bound `max_step`; steps held at a bound that the step limit stops say so.
#[test]
fn steps_held_too_short_by_the_users_own_bound_are_named() {
    let late = |t0: f64| {
        Problem::new(
            model(10.0),
            t0,
            SVector::from([0.0, 5.0]),
            SVector::from([10.0, 0.0]),
        )
        .expect("valid")
    };
    let p = late(1e9);
    let until = Options::until(1e9 + 1.0);
    let e = solve(&p, Rk4::new(1e-10), &until).unwrap_err();
    assert!(
        matches!(e, Error::InvalidOption { name: "Rk4::h", .. }),
        "{e}"
    );
    assert!(e.to_string().contains("nearer origin"), "{e}");
    let e = solve(&p, Dopri5::default(), &until.clone().max_step(1e-10)).unwrap_err();
    assert!(
        matches!(
            e,
            Error::InvalidOption {
                name: "max_step",
                ..
            }
        ),
        "{e}"
    );
    // The same steps from t0 = 0 are valid.
    let p = late(0.0);
    let sol = solve(&p, Rk4::new(1e-10), &Options::until(1e-9)).expect("valid");
    assert!(sol.is_success(), "{:?}", sol.status);
    // The step limit reached with the steps at the bound names the bound, not the tolerances.
    let held = Options::until(1.0).max_step(1e-6).max_steps(1000);
    for method in [
        AnyMethod::Dopri5(Dopri5::default()),
        AnyMethod::Rodas4(Rodas4),
        AnyMethod::Rk4(Rk4::new(1e-3)),
    ] {
        let sol = solve(&p, method, &held).expect("valid");
        let e = sol.error().expect("1000 steps of 1e-6 do not reach t = 1");
        assert!(
            matches!(e, Error::MaxSteps { .. }) && e.to_string().contains("Options::max_step"),
            "{}: {e}",
            method.name()
        );
    }
    // Without a bound, or with one the steps stay well below, the hint is the usual one.
    let sol = solve(&p, Dopri5::default(), &Options::until(1.0).max_steps(3)).expect("valid");
    let e = sol.error().expect("3 steps");
    assert!(!e.to_string().contains("Options::max_step "), "{e}");
    assert!(e.to_string().contains("loosen the tolerances"), "{e}");
}

#[test]
fn step_limit_keeps_the_partial_solution() {
    let p = uniform_problem(&Params::PAPER).expect("valid");
    let sol = solve(
        &p,
        Dopri5::default(),
        &Options::until(1.0).tolerances(1e-12, 1e-12).max_steps(5),
    )
    .expect("valid");
    assert!(
        matches!(sol.error(), Some(Error::MaxSteps { max_steps: 5, .. })),
        "{:?}",
        sol.status
    );
    assert!(sol.len() >= 2);
}

#[test]
fn the_step_limit_of_a_fixed_step_advises_a_larger_step_and_prints_t_readably() {
    let p = uniform_problem(&Params::PAPER).expect("valid");
    // (Up to t = 1e-290: a step of 1e-300 would stop changing t before t = 1, which is refused.)
    let sol = solve(&p, Rk4::new(1e-300), &Options::until(1e-290).max_steps(10)).expect("valid");
    let e = sol.error().expect("the step limit").to_string();
    // Rk4 has no tolerances to loosen; and t, about 1e-299, is not three hundred digits long.
    assert!(e.contains("take a larger fixed step"), "{e}");
    assert!(!e.contains("tolerances"), "{e}");
    assert!(e.contains("reached at t = 1e-299;"), "{e}");
    // An adaptive method's advice is its tolerances.
    let sol = solve(&p, Dopri5::default(), &Options::until(1.0).max_steps(2)).expect("valid");
    let e = sol.error().expect("the step limit").to_string();
    assert!(e.contains("loosen the tolerances"), "{e}");
}

#[test]
fn numbers_in_messages_are_written_as_numbers() {
    // An integer option is printed as one; a tiny or huge number in scientific notation.
    let p = uniform_problem(&Params::PAPER).expect("valid");
    let e = solve(&p, Dopri5::default(), &Options::until(1.0).max_steps(0)).unwrap_err();
    assert!(
        e.to_string().starts_with("invalid option max_steps = 0: "),
        "{e}"
    );
    let e = solve(
        &p,
        Dopri5::default(),
        &Options::until(1e300).output_times(vec![-1e-300]),
    )
    .unwrap_err();
    assert!(
        e.to_string()
            .starts_with("output time -1e-300 lies outside the integration interval from t0 = 0 to t_end = 1e300;"),
        "{e}"
    );
}

/// A particle whose speed is prescribed as `a·t`: at `t0 = 0` the only consistent velocity is 0,
/// where the constraint's gradient `2q̇` vanishes.
#[derive(Debug)]
struct Ramp {
    a: f64,
}

impl Lagrangian<2> for Ramp {
    fn lagrangian<R: Real>(&self, _t: R, _q: &SVector<R, 2>, qd: &SVector<R, 2>) -> R {
        qd.dot(qd) * 0.5
    }
}

impl Constraints<2, 1> for Ramp {
    fn constraints<R: Real>(&self, t: R, _q: &SVector<R, 2>, qd: &SVector<R, 2>) -> SVector<R, 1> {
        let v = t * self.a;
        SVector::from([qd.dot(qd) - v * v])
    }
}

#[test]
fn an_initial_projection_that_cannot_converge_is_told_as_such() {
    let e = Problem::with_projected_velocity(
        Ramp { a: 1.0 },
        0.0,
        SVector::zeros(),
        SVector::from([0.3, 0.0]),
    )
    .unwrap_err();
    assert!(matches!(e, Error::InitialProjectionFailed { .. }), "{e}");
    let text = e.to_string();
    // Not the advice of a failure along the motion (there are no steps yet).
    assert!(!text.contains("tolerances"), "{text}");
    assert!(text.contains("at t0 = 0"), "{text}");
    assert!(text.contains("give q and q̇ that satisfy them"), "{text}");
}

#[test]
fn the_largest_residual_is_none_when_it_was_not_recorded() {
    // A check `max_residual() < tol` must not pass on a residual nobody recorded.
    let p = uniform_problem(&Params::PAPER).expect("valid");
    let state = Options::until(0.5).record(Record::State);
    let sol = solve(&p, Dopri5::default(), &state).expect("valid");
    assert_eq!(sol.max_residual(), None);
    let dynamics = Options::until(0.5).record(Record::Dynamics);
    let sol = solve(&p, Dopri5::default(), &dynamics).expect("valid");
    assert!(
        sol.max_residual().is_some_and(|r| r < 1e-6),
        "{:?}",
        sol.max_residual()
    );
    // Likewise the energy balance, recorded only with Record::Energy (the default).
    assert_eq!(sol.max_energy_balance(), None);
    assert!(sol.energy_balance().is_empty());
    let sol = solve(&p, Dopri5::default(), &Options::until(0.5)).expect("valid");
    assert!(
        sol.max_energy_balance().is_some_and(|b| b < 1e-6),
        "{:?}",
        sol.max_energy_balance()
    );
}

#[test]
fn a_terminal_event_zero_at_the_start_does_not_end_the_run() {
    // The apex ẏ = 0, falling, of a horizontal launch (ẏ0 = 0, then ẏ < 0 at once); and y − h0,
    // 0 at t0 and falling at once. Neither is reported at t0, and neither crosses later: the run
    // reaches its end.
    let p = uniform_problem(&Params::PAPER).expect("valid");
    assert_eq!(p.qd0()[1], 0.0, "a horizontal launch");
    let h0 = p.q0()[1];
    let apex = Event::new("apex", |_t, _q, qd| qd[1]).falling().terminal();
    let start = Event::new("start", move |_t, q, _| q[1] - h0)
        .falling()
        .terminal();
    for method in AnyMethod::all(1e-3) {
        for event in [&apex, &start] {
            let sol = solve(&p, method, &Options::until(0.5).event(event.clone())).expect("valid");
            assert_eq!(sol.status, Status::Success, "{method:?}, {}", event.name);
            assert_eq!(sol.t.last(), Some(&0.5), "{method:?}");
            assert!(sol.len() > 2, "{method:?}: {} points", sol.len());
            assert!(sol.events.is_empty(), "{method:?}: {:?}", sol.events);
            assert!(
                matches!(
                    sol.warnings.as_slice(),
                    [Warning::EventZeroAtStart { index: 0, armed_by: Some(t), .. }] if *t > 0.0 && *t < 0.5
                ),
                "{method:?}: {:?}",
                sol.warnings
            );
        }
    }
}

#[test]
fn an_event_zero_at_the_start_within_rounding_is_not_a_crossing() {
    // A launch at the angle π, computed: ẏ0 = v0 sin π = 1.2e-15, positive by rounding alone, and
    // ẏ < 0 at once. Counted from its computed sign, the fall would be a crossing at t ≈ 1e-16.
    let v0 = 10.0;
    let angle = std::f64::consts::PI;
    let qd0 = SVector::from([-v0 * angle.cos(), v0 * angle.sin()]);
    assert!(qd0[1] > 0.0 && qd0[1] < 1e-14);
    let p = Problem::new(model(v0), 0.0, SVector::from([0.0, 5.0]), qd0).expect("consistent");
    let apex = Event::new("apex", |_t, _q, qd| qd[1]).falling().terminal();
    let sol = solve(&p, Dopri5::default(), &Options::until(0.5).event(apex)).expect("valid");
    assert_eq!(sol.status, Status::Success);
    assert!(sol.events.is_empty(), "{:?}", sol.events);
    assert!(
        matches!(sol.warnings.as_slice(), [Warning::EventZeroAtStart { value, .. }] if *value == qd0[1]),
        "{:?}",
        sol.warnings
    );
    // A value the rounding of the state cannot reach is a sign of its own: from ẏ0 = 1e-6 the
    // fall crosses zero at t ≈ 1e-6 / g.
    let qd0 = SVector::from([(v0 * v0 - 1e-12f64).sqrt(), 1e-6]);
    let p = Problem::new(model(v0), 0.0, SVector::from([0.0, 5.0]), qd0).expect("consistent");
    let apex = Event::new("apex", |_t, _q, qd| qd[1]).falling().terminal();
    let o = Options::until(0.5).tolerances(1e-12, 1e-12).event(apex);
    let sol = solve(&p, Dopri5::default(), &o).expect("valid");
    assert_eq!(sol.status, Status::Terminated { event: 0 });
    assert!(sol.warnings.is_empty(), "{:?}", sol.warnings);
    assert!(
        (sol.events[0].t - 1e-7).abs() < 1e-12,
        "{}",
        sol.events[0].t
    );
}

#[test]
fn a_run_over_no_time_names_an_event_zero_at_the_start() {
    let p = uniform_problem(&Params::PAPER).expect("valid");
    let apex = Event::new("apex", |_t, _q, qd| qd[1]).falling().terminal();
    let sol = solve(&p, Dopri5::default(), &Options::until(0.0).event(apex)).expect("valid");
    assert_eq!(sol.status, Status::Success);
    assert!(
        matches!(
            sol.warnings.as_slice(),
            [Warning::EventZeroAtStart { index: 0, armed_by: None, name, .. }] if name == "apex"
        ),
        "{:?}",
        sol.warnings
    );
}

#[test]
fn a_seed_is_named_as_written_in_its_messages() {
    // The dot of q̇ is a combining character: the name is quoted, not escaped.
    let p = uniform_problem(&Params::PAPER).expect("valid");
    let options = Options::until(0.5).sensitivity(Seed::velocity(2));
    let e = solve(&p, Dopri5::default(), &options).unwrap_err();
    assert!(
        e.to_string()
            .contains("seed \"q̇3(t0)\" moves coordinate index 2"),
        "{e}"
    );
}

#[test]
fn zero_length_interval_returns_the_initial_point() {
    let p = uniform_problem(&Params::PAPER).expect("valid");
    let sol = solve(&p, Dopri5::default(), &Options::until(0.0)).expect("valid");
    assert!(sol.is_success());
    assert_eq!(sol.len(), 1);
    assert_eq!(&sol.q[0], p.q0());
}

#[test]
fn backward_from_the_impact_recovers_the_start() {
    let params = Params::PAPER;
    let p = uniform_problem(&params).expect("valid");
    let fwd = solve(
        &p,
        Dopri5::default(),
        &Options::until(5.0).tolerances(1e-12, 1e-12).event(impact()),
    )
    .expect("valid");
    let (t1, q1, qd1) = fwd.last().expect("points");
    let back = Problem::new(
        **p.model(),
        t1,
        SVector::from_column_slice(q1),
        SVector::from_column_slice(qd1),
    )
    .expect("consistent");
    let sol = solve(
        &back,
        Dopri5::default(),
        &Options::until(0.0).tolerances(1e-12, 1e-12),
    )
    .expect("valid");
    assert!(sol.is_success(), "{:?}", sol.status);
    let (t0, q0, qd0) = sol.last().expect("points");
    assert_eq!(t0, 0.0);
    assert!(distance(q0, p.q0()) <= 1e-10 * params.h0, "{q0:?}");
    assert!(distance(qd0, p.qd0()) <= 1e-10 * params.v0, "{qd0:?}");
}

#[test]
fn output_times_are_hit_exactly() {
    let p = uniform_problem(&Params::PAPER).expect("valid");
    let times = vec![0.1, 0.25, 0.5, 0.75];
    let sol = solve(
        &p,
        Dopri5::default(),
        &Options::until(0.75)
            .tolerances(1e-10, 1e-10)
            .output_times(times.clone()),
    )
    .expect("valid");
    assert_eq!(sol.t, vec![0.0, 0.1, 0.25, 0.5, 0.75]);
    for (i, t) in sol.t.iter().enumerate() {
        let v = uniform_projectile::closed_form::uniform::velocity(&Params::PAPER, *t);
        assert!(
            (sol.qd[i][1] - v[1]).abs() <= 1e-8,
            "dense output at t = {t}"
        );
    }
    // In the direction of integration whatever the order given; a time given twice, twice.
    let sol = solve(
        &p,
        Dopri5::default(),
        &Options::until(0.75).output_times(vec![0.5, 0.1, 0.5]),
    )
    .expect("valid");
    assert_eq!(sol.t, vec![0.0, 0.1, 0.5, 0.5, 0.75]);
}

#[test]
fn non_finite_model_parameter_is_reported_at_construction() {
    let e = Problem::new(
        model(f64::NAN),
        0.0,
        SVector::from([0.0, 5.0]),
        SVector::from([10.0, 0.0]),
    )
    .unwrap_err();
    assert!(
        matches!(e, Error::NonFiniteEvaluation { t: 0.0, .. }),
        "{e}"
    );
    let p = Params {
        g: f64::INFINITY,
        ..Params::PAPER
    };
    assert!(uniform_problem(&p).is_err());
}

#[test]
fn output_times_outside_the_interval_are_rejected() {
    let p = uniform_problem(&Params::PAPER).expect("valid");
    for (t_end, times, outside) in [
        (1.0, vec![0.5, 1.5], 1.5),
        (1.0, vec![-0.1, 0.5], -0.1),
        (1.0, vec![0.5, 1.0 + 1e-12], 1.0 + 1e-12),
        // Backward from t0 = 0 to −1: a positive time lies outside.
        (-1.0, vec![-0.5, 0.5], 0.5),
    ] {
        let e = solve(
            &p,
            Dopri5::default(),
            &Options::until(t_end).output_times(times.clone()),
        )
        .unwrap_err();
        assert!(
            matches!(
                e,
                Error::OutputTimeOutOfRange { time, t0, t_end: end }
                    if time == outside && t0 == 0.0 && end == t_end
            ),
            "{times:?} on [0, {t_end}]: {e}"
        );
        assert!(
            e.to_string().contains("between the start and the end"),
            "{e}"
        );
    }
    // The ends themselves are inside.
    let sol = solve(
        &p,
        Dopri5::default(),
        &Options::until(-1.0).output_times(vec![-0.5, -1.0]),
    )
    .expect("valid");
    assert_eq!(sol.t, vec![0.0, -0.5, -1.0]);
}

/// A Lagrangian on no coordinates at all.
#[derive(Debug)]
struct Empty;
impl Lagrangian<0> for Empty {
    fn lagrangian<R: Real>(&self, _t: R, _q: &SVector<R, 0>, _qd: &SVector<R, 0>) -> R {
        R::zero()
    }
}

/// Run-time sizes `(n, k)` with a free-particle Lagrangian and constraints `q̇_a = 0`.
#[derive(Debug)]
struct Sizes(usize, usize);
impl DynModel for Sizes {
    fn sizes(&self) -> (usize, usize) {
        (self.0, self.1)
    }
    fn lagrangian<R: Real>(&self, _t: R, _q: &[R], qd: &[R]) -> R {
        qd.iter().fold(R::zero(), |a, v| a + *v * *v * 0.5)
    }
    fn constraints<R: Real>(&self, _t: R, _q: &[R], qd: &[R], f: &mut [R]) {
        for (a, fa) in f.iter_mut().enumerate() {
            *fa = qd[a % qd.len()];
        }
    }
}

#[test]
fn a_model_without_coordinates_is_invalid() {
    let e = Problem::unconstrained(Empty, 0.0, SVector::zeros(), SVector::zeros()).unwrap_err();
    assert!(matches!(e, Error::InvalidModel { .. }), "{e}");
    assert!(e.to_string().contains("no coordinates"), "{e}");
    let e = Problem::dynamic(Sizes(0, 0), 0.0, vec![], vec![]).unwrap_err();
    assert!(matches!(e, Error::InvalidModel { .. }), "{e}");
    assert!(e.to_string().contains("no coordinates"), "{e}");
    // More constraints than coordinates cannot all hold independently.
    let e = Problem::dynamic(Sizes(1, 2), 0.0, vec![0.0], vec![0.0]).unwrap_err();
    assert!(matches!(e, Error::InvalidModel { .. }), "{e}");
}

/// A state the equations are asked at is named as such in the errors, not as the initial state.
#[test]
fn a_bad_state_for_equations_at_is_named_as_that_state() {
    let p = uniform_problem(&Params::PAPER).expect("valid");
    let e = p.equations_at(0.0, &[0.0], &[10.0, 0.0]).unwrap_err();
    assert!(
        matches!(&e, Error::InvalidModel { what } if what.starts_with("q has 1 entries")),
        "{e}"
    );
    let e = p
        .equations_at(f64::NAN, &[0.0, 5.0], &[10.0, 0.0])
        .unwrap_err();
    assert!(e.to_string().starts_with("t is not finite"), "{e}");
}

/// An event function that leaves its domain stops the run there, names the event, and keeps the
/// motion before it.
#[test]
fn a_non_finite_event_is_named_and_the_motion_before_it_kept() {
    let p = uniform_problem(&Params::PAPER).expect("valid");
    // √(0.5 − t): NaN from t = 0.5 on.
    let root = Event::new("root", |t, _q, _qd| (0.5 - t).sqrt() - 10.0);
    let sol = solve(
        &p,
        Dop853::default(),
        &Options::until(1.0)
            .event(Event::new("never", |_t, _q, _qd| 1.0))
            .event(root),
    )
    .expect("valid options");
    match sol.error() {
        Some(Error::NonFiniteEvent { index, name, t, .. }) => {
            assert_eq!((*index, name.as_str()), (1, "root"));
            assert!(*t >= 0.5, "{t}");
        }
        other => panic!("expected NonFiniteEvent, got {other:?}"),
    }
    assert!(sol
        .error()
        .is_some_and(|e| e.to_string().starts_with("event \"root\" (index 1")));
    let (t_last, q, _) = sol.last().expect("kept");
    assert!(t_last <= 0.5 && q.iter().all(|v| v.is_finite()), "{t_last}");
}
