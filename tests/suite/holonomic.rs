//! Holonomic constraints `h(t, q) = 0`, alone and mixed with velocity constraints, against
//! references:
//!
//! 1. The pendulum in Cartesian coordinates, `x² + y² = ℓ²`: its period is
//!    `T = 4 sqrt(ℓ/g) K(sin(θ0/2))` with `K` the complete elliptic integral of the first kind
//!    (computed by the arithmetic–geometric mean, `K(k) = π / (2 AGM(1, sqrt(1 − k²)))`), and its
//!    multiplier follows from the rod's tension `m g (3 cos θ − 2 cos θ0)`: with `h = x² + y² − ℓ²`
//!    and `H = 2q`, the force `2λ q` pulls inward, `λ = −m g (3 cos θ − 2 cos θ0) / (2ℓ)`.
//! 2. A sled on an inclined plane `z = h0 − y tan α` (holonomic) whose speed is prescribed,
//!    `|q̇| = v0 + a t` (nonlinear in the velocities): the closed forms of the guide
//!    (`crates/chetaev-scene/tests/scene/guide.rs`, docs/scenes.md), the heading
//!    `2 atan((v0/(v0 + a t))^k)`, `k = g sin α / a`, and the plane's multiplier `m g cos² α`.

use std::f64::consts::PI;

use chetaev::prelude::*;

#[derive(Debug)]
struct Pendulum {
    m: f64,
    g: f64,
    l: f64,
}

impl Lagrangian<2> for Pendulum {
    fn lagrangian<R: Real>(&self, _t: R, q: &SVector<R, 2>, qd: &SVector<R, 2>) -> R {
        qd.dot(qd) * (0.5 * self.m) - q[1] * (self.m * self.g)
    }
}

impl Constraints<2, 0> for Pendulum {
    fn holonomic_count(&self) -> usize {
        1
    }
    fn holonomic<R: Real>(&self, _t: R, q: &SVector<R, 2>, h: &mut [R]) {
        h[0] = q.dot(q) - self.l * self.l;
    }
}

/// The complete elliptic integral of the first kind, `K(k)`, by the arithmetic–geometric mean.
fn elliptic_k(k: f64) -> f64 {
    let (mut a, mut b) = (1.0f64, (1.0 - k * k).sqrt());
    for _ in 0..40 {
        let (an, bn) = (0.5 * (a + b), (a * b).sqrt());
        (a, b) = (an, bn);
    }
    PI / (2.0 * a)
}

fn pendulum_problem(theta0: f64) -> Problem<chetaev::model::Fixed<Pendulum, 2, 0>> {
    let p = Pendulum {
        m: 1.5,
        g: 9.81,
        l: 2.0,
    };
    let q0 = SVector::from([p.l * theta0.sin(), -p.l * theta0.cos()]);
    Problem::new(p, 0.0, q0, SVector::zeros()).expect("consistent")
}

#[test]
fn the_cartesian_pendulum_has_the_elliptic_period_and_the_tension_of_the_rod() -> Result<(), Error>
{
    let (m, g, l) = (1.5f64, 9.81f64, 2.0f64);
    for theta0 in [0.3, 1.5, 2.8] {
        let problem = pendulum_problem(theta0);
        let period = 4.0 * (l / g).sqrt() * elliptic_k((theta0 / 2.0).sin());
        // Released at rest with x > 0: x falls through zero at T/4, 5T/4, ...
        let crossing = Event::new("x = 0 falling", |_t, q, _qd| q[0]).falling();
        let o = Options::until(2.1 * period)
            .tolerances(1e-12, 1e-12)
            .event(crossing);
        let sol = solve(&problem, Dop853::default(), &o)?.ok()?;
        assert_eq!(sol.events.len(), 2, "θ0 = {theta0}");
        let measured = sol.events[1].t - sol.events[0].t;
        assert!(
            ((measured - period) / period).abs() < 1e-10,
            "θ0 = {theta0}: period {measured} vs {period}"
        );
        assert!((sol.events[0].t - period / 4.0).abs() < 1e-10 * period);
        // The multiplier is the rod's tension, and both residuals stay small.
        for i in 0..sol.len() {
            let cos_theta = -sol.q[i][1] / l;
            let lambda = -m * g * (3.0 * cos_theta - 2.0 * theta0.cos()) / (2.0 * l);
            assert!(
                (sol.mu[i][0] - lambda).abs() < 1e-8 * m * g,
                "λ at t = {}",
                sol.t[i]
            );
            assert!(sol.position_residual[i][0].abs() < 1e-9 * l * l);
            assert!(sol.residual[i][0].abs() < 1e-9 * l * (g * l).sqrt());
        }
        // Energy is conserved: the rod's force does no work.
        assert!(sol
            .energy_balance()
            .iter()
            .all(|b| b.abs() < 1e-9 * m * g * l));
        assert!(sol.work.iter().all(|w| w.abs() < 1e-9 * m * g * l));
    }
    Ok(())
}

#[test]
fn projection_holds_the_rod_at_round_off_over_a_long_run() -> Result<(), Error> {
    let problem = pendulum_problem(1.0);
    let l = 2.0;
    let long = Options::until(200.0).tolerances(1e-8, 1e-8).output_final();
    let free = solve(&problem, Dopri5::default(), &long)?.ok()?;
    let projected = solve(
        &problem,
        Dopri5::default(),
        // A relative residual of 1e-14: round-off for the rod's |H|·|q| = 2ℓ².
        &long.clone().project(Projection {
            tol: 1e-14,
            max_iterations: 10,
        }),
    )?
    .ok()?;
    let h_end = |s: &Solution| s.position_residual.last().map_or(f64::NAN, |h| h[0].abs());
    let hd_end = |s: &Solution| s.residual.last().map_or(f64::NAN, |f| f[0].abs());
    eprintln!(
        "after 200 s: |h| = {:e} free, {:e} projected; |ḣ| = {:e} free, {:e} projected",
        h_end(&free),
        h_end(&projected),
        hd_end(&free),
        hd_end(&projected)
    );
    assert!(h_end(&projected) < 1e-13 * l * l);
    assert!(hd_end(&projected) < 1e-12 * l * 5.0);
    assert!(h_end(&free) > 100.0 * h_end(&projected));
    assert!(projected.stats.projections > 0);
    Ok(())
}

#[test]
fn an_inconsistent_initial_position_is_refused_or_projected_on_request() -> Result<(), Error> {
    let p = || Pendulum {
        m: 1.0,
        g: 9.81,
        l: 1.0,
    };
    let (q0, qd0) = (SVector::from([0.6, -0.9]), SVector::from([0.0, 0.0]));
    let err = Problem::new(p(), 0.0, q0, qd0).expect_err("|q0| ≠ ℓ");
    assert!(
        matches!(err, Error::InconsistentInitialPosition { index: 1, .. }),
        "{err}"
    );
    let problem = Problem::with_projected_state(p(), 0.0, q0, qd0)?;
    let q = problem.q0();
    assert!((q[0].hypot(q[1]) - 1.0).abs() < 1e-14, "{q:?}");
    // The older name is the same projection.
    let older = Problem::with_projected_velocity(p(), 0.0, q0, qd0)?;
    assert_eq!((older.q0(), older.qd0()), (problem.q0(), problem.qd0()));
    // A velocity along the rod is projected away too (ḣ = 2 q·q̇ = 0).
    let problem = Problem::with_projected_velocity(
        p(),
        0.0,
        SVector::from([0.6, -0.8]),
        SVector::from([0.6, -0.8]),
    )?;
    let (q, qd) = (problem.q0(), problem.qd0());
    assert!((q[0] * qd[0] + q[1] * qd[1]).abs() < 1e-14);
    Ok(())
}

/// `q̇0` off a velocity constraint and off the rate `ḣ` of a holonomic one are told apart, and a
/// model with too many constraints counts each kind.
#[test]
fn refusals_name_the_kind_of_constraint_they_are_about() {
    let sled = || Sled::GUIDE;
    let q0 = SVector::from([0.0, 0.0, 3.0]);
    // At the prescribed speed but straight up, off the plane: ḣ = ż + ẏ tan α = 2.
    let err = Problem::new(sled(), 0.0, q0, SVector::from([0.0, 0.0, 2.0])).expect_err("ḣ ≠ 0");
    assert!(
        matches!(
            err,
            Error::InconsistentInitialState {
                index: 2,
                holonomic: Some(1),
                ..
            }
        ),
        "{err}"
    );
    let text = err.to_string();
    assert!(
        text.contains("holonomic constraint 1") && text.contains("ḣ = ∂h/∂q·q̇ + ∂h/∂t = 2e0"),
        "{text}"
    );
    // Along the plane at half the speed: f = 1 − 4.
    let err = Problem::new(sled(), 0.0, q0, SVector::from([1.0, 0.0, 0.0])).expect_err("f ≠ 0");
    assert!(
        matches!(
            err,
            Error::InconsistentInitialState {
                index: 1,
                holonomic: None,
                ..
            }
        ),
        "{err}"
    );
    assert!(err
        .to_string()
        .contains("velocity constraint 1 (numbered from 1): f = -3e0"));

    /// One velocity and two holonomic constraints on two coordinates.
    #[derive(Debug)]
    struct Crowded;
    impl DynModel for Crowded {
        fn sizes(&self) -> (usize, usize) {
            (2, 1)
        }
        fn lagrangian<R: Real>(&self, _t: R, _q: &[R], qd: &[R]) -> R {
            (qd[0] * qd[0] + qd[1] * qd[1]) * 0.5
        }
        fn constraints<R: Real>(&self, _t: R, _q: &[R], qd: &[R], f: &mut [R]) {
            f[0] = qd[0] - 1.0;
        }
        fn holonomic_count(&self) -> usize {
            2
        }
        fn holonomic<R: Real>(&self, _t: R, q: &[R], h: &mut [R]) {
            h[0] = q[1];
            h[1] = q[0] + q[1] * 2.0;
        }
    }
    let err = Problem::dynamic(Crowded, 0.0, vec![0.0; 2], vec![1.0, 0.0]).expect_err("3 > 2");
    assert!(
        err.to_string()
            .contains("1 velocity and 2 holonomic constraints (3 in all) on 2 coordinates"),
        "{err}"
    );
}

/// The sled on an inclined plane with a prescribed speed (docs/scenes.md), the plane given as
/// a holonomic constraint.
#[derive(Debug)]
struct Sled {
    m: f64,
    g: f64,
    alpha: f64,
    v0: f64,
    a: f64,
    h0: f64,
}

impl Sled {
    /// The guide's sled: 1 kg on a 20° slope from 3 m, at `2 + 0.5 t` m/s.
    const GUIDE: Sled = Sled {
        m: 1.0,
        g: 9.81,
        alpha: PI / 9.0,
        v0: 2.0,
        a: 0.5,
        h0: 3.0,
    };
}

impl Lagrangian<3> for Sled {
    fn lagrangian<R: Real>(&self, _t: R, q: &SVector<R, 3>, qd: &SVector<R, 3>) -> R {
        qd.dot(qd) * (0.5 * self.m) - q[2] * (self.m * self.g)
    }
}

impl Constraints<3, 1> for Sled {
    fn constraints<R: Real>(&self, t: R, _q: &SVector<R, 3>, qd: &SVector<R, 3>) -> SVector<R, 1> {
        let v = t * self.a + self.v0;
        SVector::from([qd.dot(qd) - v * v])
    }
    fn holonomic_count(&self) -> usize {
        1
    }
    fn holonomic<R: Real>(&self, _t: R, q: &SVector<R, 3>, h: &mut [R]) {
        h[0] = q[2] + q[1] * self.alpha.tan() - self.h0;
    }
}

#[test]
fn a_sled_on_a_holonomic_plane_at_a_prescribed_speed_follows_the_guides_closed_forms(
) -> Result<(), Error> {
    let s = Sled::GUIDE;
    let (m, g, alpha, v0, a, h0) = (s.m, s.g, s.alpha, s.v0, s.a, s.h0);
    let k = g * alpha.sin() / a;
    let problem = Problem::new(
        s,
        0.0,
        SVector::from([0.0, 0.0, h0]),
        SVector::from([v0, 0.0, 0.0]),
    )?;
    assert_eq!(problem.sizes(), (3, 2));
    let bottom = Event::new("bottom", |_t, q, _qd| q[2]).falling().terminal();
    let o = Options::until(20.0)
        .tolerances(1e-10, 1e-10)
        .event(bottom)
        .output_grid(0.0, 201);
    for method in [
        AnyMethod::Dop853(Dop853::default()),
        AnyMethod::Rodas4(Rodas4),
    ] {
        let sol = solve(&problem, method, &o)?;
        assert_eq!(
            sol.status,
            Status::Terminated { event: 0 },
            "{}",
            method.name()
        );
        assert!(sol.len() > 20);
        for i in 0..sol.len() {
            let (t, q, qd) = (sol.t[i], &sol.q[i], &sol.qd[i]);
            let speed = (qd[0] * qd[0] + qd[1] * qd[1] + qd[2] * qd[2]).sqrt();
            assert!(
                (speed - (v0 + a * t)).abs() < 1e-8,
                "{}: speed",
                method.name()
            );
            assert!((q[2] - (h0 - q[1] * alpha.tan())).abs() < 1e-9, "plane");
            let heading = qd[0].atan2(qd[1] * alpha.cos() - qd[2] * alpha.sin());
            let exact = 2.0 * (v0 / (v0 + a * t)).powf(k).atan();
            assert!(
                (heading - exact).abs() < 1e-7,
                "{}: heading at t = {t}",
                method.name()
            );
            // μ: the speed constraint's multiplier, then the plane's (holonomic) one.
            assert!(
                (sol.mu[i][1] - m * g * alpha.cos().powi(2)).abs() < 1e-7,
                "{}: plane force at t = {t}",
                method.name()
            );
        }
        assert!((sol.mu[0][0] - m * a / (2.0 * v0)).abs() < 1e-10);
    }
    Ok(())
}

/// A curve `y = b c cos x − a` with `a = b c`: next to the coordinates' origin `h` is the
/// difference of terms of size 0.3 while `|∂h/∂q|·|q|` vanishes.
#[derive(Debug)]
struct Cancelling;

impl Lagrangian<2> for Cancelling {
    fn lagrangian<R: Real>(&self, _t: R, _q: &SVector<R, 2>, qd: &SVector<R, 2>) -> R {
        qd.dot(qd) * 0.5
    }
}

impl Constraints<2, 0> for Cancelling {
    fn holonomic_count(&self) -> usize {
        1
    }
    fn holonomic<R: Real>(&self, _t: R, q: &SVector<R, 2>, h: &mut [R]) {
        h[0] = q[1] + 0.3 - q[0].cos() * 0.1 * 3.0;
    }
}

#[test]
fn a_position_on_the_constraint_to_rounding_next_to_the_origin_is_accepted() -> Result<(), Error> {
    // h(1e-12, 0) = 0.3 − 0.3 cos(1e-12) = −5.6e-17 in floating point, zero exactly; the relative
    // tolerance alone allowed 1e-10 · |∂h/∂q| · |q0| = 1e-22.
    let q0 = SVector::from([1e-12, 0.0]);
    let problem = Problem::new(Cancelling, 0.0, q0, SVector::zeros())?;
    assert_eq!(problem.q0(), &[1e-12, 0.0]);
    // The projection on request accepts it as it is, where its relative residual cannot shrink.
    let projected = Problem::with_projected_velocity(Cancelling, 0.0, q0, SVector::zeros())?;
    assert!((projected.q0()[1] - problem.q0()[1]).abs() < 1e-15);
    // A position truly off the curve there is still refused: 1e-9 is no rounding of 0.3.
    let off = Problem::new(
        Cancelling,
        0.0,
        SVector::from([1e-12, 1e-9]),
        SVector::zeros(),
    );
    assert!(
        matches!(
            off,
            Err(Error::InconsistentInitialPosition { index: 1, .. })
        ),
        "{off:?}"
    );
    Ok(())
}

/// Released at rest, the pendulum's velocity is zero at the start: an event on `ẋ` (the turning
/// points) is not reported there, in either direction, and is armed as `ẋ` leaves zero; its next
/// zero, the far turning point, comes after half a period.
#[test]
fn a_turning_point_event_zero_at_the_release_first_fires_half_a_period_later() -> Result<(), Error>
{
    let (g, l) = (9.81f64, 2.0f64);
    let theta0 = 1.5;
    let problem = pendulum_problem(theta0);
    let period = 4.0 * (l / g).sqrt() * elliptic_k((theta0 / 2.0).sin());
    let turning = Event::new("x_dot = 0", |_t, _q, qd| qd[0]).terminal();
    let o = Options::until(period)
        .tolerances(1e-12, 1e-12)
        .event(turning);
    let sol = solve(&problem, Dop853::default(), &o)?;
    assert_eq!(sol.status, Status::Terminated { event: 0 });
    assert_eq!(sol.events.len(), 1);
    assert!(
        (sol.events[0].t - period / 2.0).abs() < 1e-9 * period,
        "{} against T/2 = {}",
        sol.events[0].t,
        period / 2.0
    );
    // At the far turning point, mirrored.
    assert!((sol.events[0].q[0] + l * theta0.sin()).abs() < 1e-8 * l);
    assert!(
        matches!(
            sol.warnings.as_slice(),
            [Warning::EventZeroAtStart { index: 0, value, armed_by: Some(t), .. }]
                if *value == 0.0 && *t < period / 2.0
        ),
        "{:?}",
        sol.warnings
    );
    Ok(())
}

/// A particle in space with holonomic constraints chosen at run time, for the redundancy checks.
#[derive(Debug)]
struct Redundant {
    /// Which set of constraints.
    case: usize,
}

impl DynModel for Redundant {
    fn sizes(&self) -> (usize, usize) {
        (3, 0)
    }
    fn lagrangian<R: Real>(&self, _t: R, q: &[R], qd: &[R]) -> R {
        (qd[0] * qd[0] + qd[1] * qd[1] + qd[2] * qd[2]) * 0.5 - q[1] * 9.81
    }
    fn holonomic_count(&self) -> usize {
        match self.case {
            0 | 1 | 3 => 2,
            _ => 3,
        }
    }
    fn holonomic<R: Real>(&self, _t: R, q: &[R], h: &mut [R]) {
        let rod = q[0] * q[0] + q[1] * q[1] + q[2] * q[2] - 4.0;
        match self.case {
            // The rod given twice.
            0 => (h[0], h[1]) = (rod, rod),
            // The rod and twice the rod.
            1 => (h[0], h[1]) = (rod, rod * 2.0),
            // A plane z = 0, a plane x = y, and a third plane through their line.
            2 => (h[0], h[1], h[2]) = (q[2], q[0] - q[1], q[0] - q[1] + q[2] * 3.0),
            // The rod and the plane z = 0: independent.
            _ => (h[0], h[1]) = (rod, q[2]),
        }
    }
}

#[test]
fn a_redundant_holonomic_constraint_is_named_not_blamed_on_the_lagrangian() {
    let start = || (vec![2.0f64.sqrt(), -(2.0f64.sqrt()), 0.0], vec![0.0; 3]);
    for (case, index, on) in [(0, 2, vec![1]), (1, 2, vec![1])] {
        let (q0, qd0) = start();
        let err = Problem::dynamic(Redundant { case }, 0.0, q0, qd0).expect_err("redundant");
        let text = err.to_string();
        assert!(
            matches!(&err, Error::RedundantHolonomic { index: i, dependent_on, .. } if *i == index && *dependent_on == on),
            "case {case}: {err:?}"
        );
        assert!(
            text.contains("holonomic constraints 1 and 2")
                && text.contains("remove constraint 2")
                && !text.contains("∂²L/∂q̇²"),
            "{text}"
        );
    }
    // Three planes through one line: the third is 1·(z) + 1·(x − y) of the first two.
    let err = Problem::dynamic(
        Redundant { case: 2 },
        0.0,
        vec![1.0, 1.0, 0.0],
        vec![0.0; 3],
    )
    .expect_err("redundant");
    assert!(
        matches!(&err, Error::RedundantHolonomic { index: 3, dependent_on, .. } if *dependent_on == [1, 2]),
        "{err:?}"
    );
    assert!(
        err.to_string().contains("holonomic constraints 1, 2 and 3"),
        "{err}"
    );
    // Independent constraints are accepted.
    let (q0, qd0) = start();
    assert!(Problem::dynamic(Redundant { case: 3 }, 0.0, q0, qd0).is_ok());
}

/// `K` counts the velocity constraints, `H` the holonomic ones, and `k = K + H` the multipliers,
/// wherever a count is given.
#[test]
fn the_counts_of_constraints_say_which_kind_they_count() -> Result<(), Error> {
    // The sled: one velocity constraint (the speed) and one holonomic (the plane).
    let problem = Problem::new(
        Sled::GUIDE,
        0.0,
        SVector::from([0.0, 0.0, 3.0]),
        SVector::from([Sled::GUIDE.v0, 0.0, 0.0]),
    )?;
    assert_eq!(problem.sizes(), (3, 2));
    assert_eq!(problem.multiplier_count(), 2);
    assert_eq!(problem.velocity_constraint_count(), 1);
    assert_eq!(problem.holonomic_count(), 1);
    let sol = solve(&problem, Dop853::default(), &Options::until(0.1))?;
    assert_eq!((sol.k(), sol.multiplier_count()), (2, 2));
    assert_eq!(sol.mu.width(), 2);
    // A run-time-sized model gives K alone in its own sizes; its problem counts k = K + H.
    let model = Redundant { case: 3 };
    assert_eq!(DynModel::sizes(&model), (3, 0));
    let q0 = vec![2.0f64.sqrt(), -(2.0f64.sqrt()), 0.0];
    let problem = Problem::dynamic(model, 0.0, q0, vec![0.0; 3])?;
    assert_eq!(problem.sizes(), (3, 2));
    assert_eq!(
        (
            problem.velocity_constraint_count(),
            problem.holonomic_count()
        ),
        (0, 2)
    );
    Ok(())
}
