//! Sensitivities against the closed forms' own derivatives (taken by dual numbers of the closed
//! forms), on the paper's uniform projectile and on models with holonomic constraints, forces and
//! branches.

use chetaev::num_dual::{Dual64, DualNum};
use chetaev::prelude::*;
use chetaev::SeedPart;

/// The paper's model (42.2), (42.23), with `g` and `v0` read as parameters.
struct Uniform {
    m: f64,
    g: f64,
    v0: f64,
}

impl Lagrangian<2> for Uniform {
    fn lagrangian<R: Real>(&self, _t: R, q: &SVector<R, 2>, qd: &SVector<R, 2>) -> R {
        qd.dot(qd) * (0.5 * self.m) - q[1] * (R::parameter("g", self.g) * self.m)
    }
}

impl Constraints<2, 1> for Uniform {
    fn constraints<R: Real>(&self, _t: R, _q: &SVector<R, 2>, qd: &SVector<R, 2>) -> SVector<R, 1> {
        let v0 = R::parameter("v0", self.v0);
        SVector::from([qd.dot(qd) - v0 * v0])
    }
}

struct Ground;
impl EventFunction for Ground {
    fn value<R: Real>(&self, _t: R, q: &[R], _qd: &[R]) -> R {
        q[1]
    }
}

/// `T = (v0/g) arccosh e^z`, `R = (v0²/g) arccos e^(−z)`, `z = g h0 / v0²` (42.38), for any scalar.
fn impact<D: DualNum<f64> + Copy>(v0: D, g: D, h0: D) -> (D, D) {
    let z = g * h0 / (v0 * v0);
    let t = v0 / g * z.exp().acosh();
    let r = v0 * v0 / g * (-z).exp().acos();
    (t, r)
}

/// `(∂T/∂θ, ∂R/∂θ)` for θ = v0, g, h0 by dual numbers of the closed form.
fn closed_form_derivatives(v0: f64, g: f64, h0: f64) -> [(f64, f64); 3] {
    let d = |i: usize| {
        let s = |j: usize, x: f64| Dual64::new(x, if i == j { 1.0 } else { 0.0 });
        let (t, r) = impact(s(0, v0), s(1, g), s(2, h0));
        (t.eps, r.eps)
    };
    [d(0), d(1), d(2)]
}

/// The paper's problem: `v0 = g = 10`, `h0 = 5`.
fn paper_problem() -> Result<Problem<chetaev::model::Fixed<Uniform, 2, 1>>, Error> {
    Problem::new(
        Uniform {
            m: 1.0,
            g: 10.0,
            v0: 10.0,
        },
        0.0,
        SVector::from([0.0, 5.0]),
        SVector::from([10.0, 0.0]),
    )
}

/// To the impact at 1e-12, with the seeds `v0` (and the initial speed), `g`, `h0`.
fn paper_options(control: bool) -> Options {
    Options::until(10.0)
        .tolerances(1e-12, 1e-12)
        .event(Event::smooth("impact", Ground).falling().terminal())
        .sensitivity(Seed::parameter("v0").with_velocity(0, 1.0))
        .sensitivity(Seed::parameter("g"))
        .sensitivity(Seed::new("h0").with_position(1, 1.0))
        .sensitivity_control(control)
}

fn paper_solution(method: impl Method, control: bool) -> Result<Solution, Error> {
    solve(&paper_problem()?, method, &paper_options(control))
}

fn check_paper(sol: &Solution, tol: f64) {
    assert!(sol.is_success(), "{:?}", sol.status);
    let s = sol.sensitivities.as_ref().expect("sensitivities recorded");
    let hit = s.events[0].as_ref().expect("the impact moves smoothly");
    let expected = closed_form_derivatives(10.0, 10.0, 5.0);
    for (j, name) in ["v0", "g", "h0"].iter().enumerate() {
        let i = s.seed(name).expect("seed by name");
        let (dt, dr) = expected[j];
        let (et, er) = ((hit.t[i] - dt) / dt, (hit.q[i][0] - dr) / dr);
        println!(
            "∂T/∂{name} = {:.15e} ({et:.1e}), ∂R/∂{name} = {:.15e} ({er:.1e})",
            hit.t[i], hit.q[i][0]
        );
        assert!(et.abs() < tol && er.abs() < tol, "{name}: {et:e} {er:e}");
        // y(T) = 0 for every parameter: the event's state moves along the ground.
        assert!(hit.q[i][1].abs() < tol * (1.0 + dr.abs()));
    }
}

#[test]
fn paper_impact_derivatives_match_the_closed_form() -> Result<(), Error> {
    check_paper(&paper_solution(Dop853::default(), true)?, 1e-8);
    check_paper(&paper_solution(Dopri5::default(), true)?, 1e-8);
    check_paper(&paper_solution(Rodas4, true)?, 1e-7);
    Ok(())
}

#[test]
fn without_error_control_the_derivatives_follow_the_motions_steps() -> Result<(), Error> {
    // Steps chosen for the motion alone still carry the derivatives to about the tolerance.
    check_paper(&paper_solution(Dop853::default(), false)?, 1e-9);
    Ok(())
}

/// The Cartesian pendulum `h = x² + y² − ℓ²` with `ℓ` and `g` as parameters.
struct Pendulum {
    g: f64,
    l: f64,
}

impl Lagrangian<2> for Pendulum {
    fn lagrangian<R: Real>(&self, _t: R, q: &SVector<R, 2>, qd: &SVector<R, 2>) -> R {
        qd.dot(qd) * 0.5 - q[1] * R::parameter("g", self.g)
    }
}

impl Constraints<2, 0> for Pendulum {
    fn holonomic_count(&self) -> usize {
        1
    }
    fn holonomic<R: Real>(&self, _t: R, q: &SVector<R, 2>, h: &mut [R]) {
        let l = R::parameter("l", self.l);
        h[0] = q.dot(q) - l * l;
    }
}

/// A pendulum with holonomic constraint only: `K = 0` velocity constraints.
struct Rod {
    g: f64,
    l: f64,
}

impl DynModel for Rod {
    fn sizes(&self) -> (usize, usize) {
        (2, 0)
    }
    fn lagrangian<R: Real>(&self, _t: R, q: &[R], qd: &[R]) -> R {
        (qd[0] * qd[0] + qd[1] * qd[1]) * 0.5 - q[1] * R::parameter("g", self.g)
    }
    fn holonomic_count(&self) -> usize {
        1
    }
    fn holonomic<R: Real>(&self, _t: R, q: &[R], h: &mut [R]) {
        let l = R::parameter("l", self.l);
        h[0] = q[0] * q[0] + q[1] * q[1] - l * l;
    }
}

struct Vertical;
impl EventFunction for Vertical {
    fn value<R: Real>(&self, _t: R, q: &[R], _qd: &[R]) -> R {
        q[0]
    }
}

#[test]
fn a_holonomic_pendulums_quarter_period_moves_as_the_square_root_of_l_over_g() -> Result<(), Error>
{
    // Released at rest at θ0 from the vertical: it reaches x = 0 after T/4, T = 4 √(ℓ/g) K(sin θ0/2),
    // so d(T/4)/dℓ = T/(8ℓ) and d(T/4)/dg = −T/(8g) whatever K is. The initial position moves
    // with ℓ: (x0, y0) = ℓ (sin θ0, −cos θ0).
    let (g, l, th0) = (9.81, 1.5, 1.2);
    let q0 = [l * th0.sin(), -l * th0.cos()];
    let options = Options::until(10.0)
        .tolerances(1e-12, 1e-12)
        .event(Event::smooth("vertical", Vertical).falling().terminal())
        .sensitivity(
            Seed::parameter("l")
                .with_position(0, th0.sin())
                .with_position(1, -th0.cos()),
        )
        .sensitivity(Seed::parameter("g"))
        .sensitivity_control(true);
    let check = |sol: &Solution| {
        assert!(sol.is_success(), "{:?}", sol.status);
        let quarter = sol.events[0].t;
        let s = sol.sensitivities.as_ref().expect("recorded");
        let hit = s.events[0].as_ref().expect("smooth event");
        let (dl, dg) = (quarter / (2.0 * l), -quarter / (2.0 * g));
        assert!(
            (hit.t[0] - dl).abs() < 1e-8 * dl.abs(),
            "{} vs {dl}",
            hit.t[0]
        );
        assert!(
            (hit.t[1] - dg).abs() < 1e-8 * dg.abs(),
            "{} vs {dg}",
            hit.t[1]
        );
        // At the bottom, y = −ℓ: dy/dℓ = −1, dy/dg = 0; the velocity scales as √(gℓ).
        assert!((hit.q[0][1] + 1.0).abs() < 1e-8);
        assert!(hit.q[1][1].abs() < 1e-8);
        let v = sol.events[0].qd[0];
        assert!((hit.qd[0][0] - v / (2.0 * l)).abs() < 1e-8 * v.abs());
        assert!((hit.qd[1][0] - v / (2.0 * g)).abs() < 1e-8 * v.abs());
    };
    let fixed = Problem::new(
        Pendulum { g, l },
        0.0,
        SVector::from(q0),
        SVector::from([0.0, 0.0]),
    )?;
    check(&solve(&fixed, Dop853::default(), &options)?);
    let dynamic = Problem::dynamic(Rod { g, l }, 0.0, q0.to_vec(), vec![0.0, 0.0])?;
    check(&solve(&dynamic, Dop853::default(), &options)?);
    check(&solve(&dynamic, Rodas4, &options)?);
    // A velocity seed across the rod moves q̇0 off ḣ = 2 q·q̇ = 0: the refusal names the holonomic
    // constraint (the model has no velocity constraint) and the seeds that keep ḣ = 0.
    let e = solve(
        &fixed,
        Dop853::default(),
        &Options::until(1.0).sensitivity(Seed::velocity(0)),
    )
    .expect_err("δḣ = 2 x0 ≠ 0");
    assert!(
        matches!(
            e,
            Error::InconsistentSeed {
                constraint: 1,
                holonomic: Some(1),
                ..
            }
        ),
        "{e}"
    );
    let text = e.to_string();
    assert!(text.contains("off holonomic constraint 1"), "{text}");
    assert!(text.contains("through its rate ḣ"), "{text}");
    assert!(!text.contains("|q̇|² − v0²"), "{text}");
    // The pendulum at rest has no parameter moved and no constraint moving in time: the hint is
    // about the velocity the seed moves, not about ω of a time-dependent constraint.
    assert!(
        matches!(
            e,
            Error::InconsistentSeed {
                moved_by: SeedPart::Velocity,
                ..
            }
        ),
        "{e}"
    );
    assert!(
        text.contains("through the initial velocity it moves") && text.contains("x δẋ + y δẏ = 0"),
        "{text}"
    );
    assert!(
        !text.contains('ω') && !text.contains("with the parameter"),
        "{text}"
    );
    // ℓ moved without the position that keeps h = x² + y² − ℓ² = 0 (δh = −2ℓ), or x0 moved alone
    // (δh = 2 x0): refused in position, for static and run-time sizes, where the derivatives
    // would otherwise be those of a rod whose length does not change.
    for seed in [Seed::parameter("l"), Seed::position(0)] {
        let options = Options::until(1.0).sensitivity(seed.clone());
        for e in [
            solve(&fixed, Dop853::default(), &options).expect_err("δh ≠ 0"),
            solve(&dynamic, Dop853::default(), &options).expect_err("δh ≠ 0"),
        ] {
            let Error::InconsistentSeed {
                constraint: 1,
                holonomic: Some(1),
                position: true,
                residual,
                ..
            } = e
            else {
                panic!("{seed:?}: {e}")
            };
            let expected = if seed.name == "l" {
                -2.0 * l
            } else {
                2.0 * q0[0]
            };
            assert!(
                (residual - expected).abs() < 1e-12,
                "{residual} vs {expected}"
            );
            assert!(e.to_string().contains("in position (h itself)"), "{e}");
            // Named by what the seed moves: ℓ, a parameter; x0, a position.
            let (part, says) = if seed.name == "l" {
                (SeedPart::Parameter, "through the parameter it moves")
            } else {
                (SeedPart::Position, "through the initial position it moves")
            };
            assert!(
                matches!(&e, Error::InconsistentSeed { moved_by, .. } if *moved_by == part),
                "{e}"
            );
            assert!(e.to_string().contains(says), "{e}");
        }
    }
    Ok(())
}

/// `L = ½ ẋ² − ½ k x²` with `k = k1` for `x > 0` and `k2` below: a branch in the model's code.
struct Kinked {
    k1: f64,
    k2: f64,
    c: f64,
}

impl DynModel for Kinked {
    fn sizes(&self) -> (usize, usize) {
        (1, 0)
    }
    fn lagrangian<R: Real>(&self, _t: R, q: &[R], qd: &[R]) -> R {
        let k = if q[0] > 0.0 {
            R::parameter("k1", self.k1)
        } else {
            R::parameter("k2", self.k2)
        };
        (qd[0] * qd[0] - k * q[0] * q[0]) * 0.5
    }
    fn dissipation<R: Real>(&self, _t: R, _q: &[R], qd: &[R]) -> Option<R> {
        (self.c != 0.0).then(|| qd[0] * qd[0] * R::parameter("c", self.c) * 0.5)
    }
}

#[test]
fn sensitivities_follow_a_branch_of_the_models_code_and_a_rayleigh_function() -> Result<(), Error> {
    // From x0 > 0 at rest: x = x0 cos(w1 t) until t1 = π/(2 w1), then x = −x0 (w1/w2) sin(w2 (t − t1)).
    let (k1, k2, x0) = (4.0, 9.0, 0.7);
    fn x<D: DualNum<f64> + Copy>(k1: D, k2: D, x0: D, t: f64) -> D {
        let (w1, w2) = (k1.sqrt(), k2.sqrt());
        let t1 = w1.recip() * std::f64::consts::FRAC_PI_2;
        -x0 * (w1 / w2) * (w2 * (t1 * -1.0 + t)).sin()
    }
    let t = 1.0; // past t1 = π/4, before the next switch at t1 + π/3
    let problem = Problem::dynamic(Kinked { k1, k2, c: 0.0 }, 0.0, vec![x0], vec![0.0])?;
    let options = Options::until(t)
        .tolerances(1e-12, 1e-12)
        .sensitivity(Seed::parameter("k1"))
        .sensitivity(Seed::parameter("k2"))
        .sensitivity(Seed::position(0))
        .sensitivity_control(true);
    let sol = solve(&problem, Dop853::default(), &options)?;
    assert!(sol.is_success(), "{:?}", sol.status);
    let s = sol.sensitivities.as_ref().expect("recorded");
    let last = sol.len() - 1;
    let d = |i: usize| {
        x(
            Dual64::new(k1, f64::from(u8::from(i == 0))),
            Dual64::new(k2, f64::from(u8::from(i == 1))),
            Dual64::new(x0, f64::from(u8::from(i == 2))),
            t,
        )
    };
    assert!((sol.q[last][0] - d(0).re).abs() < 1e-10);
    for i in 0..3 {
        let expected = d(i).eps;
        let got = s.q(last, i)[0];
        assert!(
            (got - expected).abs() < 1e-8 * (1.0 + expected.abs()),
            "{i}: {got} vs {expected}"
        );
    }
    assert!(
        sol.stats.graph_fallbacks > 0,
        "the branch flipped and was recorded again"
    );

    // A damped oscillator, D = ½ c ẋ² (x > 0 throughout the short run): x = x0 e^(−ct/2)(cos ωt +
    // c/(2ω) sin ωt), ω = √(k1 − c²/4).
    let c = 0.3;
    fn damped<D: DualNum<f64> + Copy>(k: D, c: D, x0: D, t: f64) -> D {
        let w = (k - c * c * 0.25).sqrt();
        x0 * (c * (-0.5 * t)).exp() * ((w * t).cos() + c / (w * 2.0) * (w * t).sin())
    }
    let t = 0.5;
    let problem = Problem::dynamic(Kinked { k1, k2, c }, 0.0, vec![x0], vec![0.0])?;
    let options = Options::until(t)
        .tolerances(1e-12, 1e-12)
        .sensitivity(Seed::parameter("c"))
        .sensitivity(Seed::parameter("k1"))
        .sensitivity_control(true);
    let sol = solve(&problem, Dop853::default(), &options)?;
    let s = sol.sensitivities.as_ref().expect("recorded");
    let last = sol.len() - 1;
    let dc = damped(Dual64::from(k1), Dual64::new(c, 1.0), Dual64::from(x0), t).eps;
    let dk = damped(Dual64::new(k1, 1.0), Dual64::from(c), Dual64::from(x0), t).eps;
    assert!(
        (s.q(last, 0)[0] - dc).abs() < 1e-9,
        "{} vs {dc}",
        s.q(last, 0)[0]
    );
    assert!(
        (s.q(last, 1)[0] - dk).abs() < 1e-9,
        "{} vs {dk}",
        s.q(last, 1)[0]
    );
    Ok(())
}

#[test]
fn bad_seeds_are_typed_errors() -> Result<(), Error> {
    let problem = paper_problem()?;
    let base = Options::until(1.0);
    // A parameter nobody reads (a typo).
    let e = solve(
        &problem,
        Dop853::default(),
        &base.clone().sensitivity(Seed::parameter("v_0")),
    )
    .expect_err("unknown parameter");
    assert!(matches!(e, Error::Sensitivity { .. }), "{e}");
    assert!(e.to_string().contains("g, v0"), "{e}");
    // v0 moved without the initial speed: off the constraint to first order.
    let e = solve(
        &problem,
        Dop853::default(),
        &base.clone().sensitivity(Seed::parameter("v0")),
    )
    .expect_err("inconsistent seed");
    assert!(
        matches!(
            e,
            Error::InconsistentSeed {
                constraint: 1,
                holonomic: None,
                ..
            }
        ),
        "{e}"
    );
    assert!(e.to_string().contains("off velocity constraint 1"), "{e}");
    assert!(
        matches!(
            e,
            Error::InconsistentSeed {
                moved_by: SeedPart::Parameter,
                ..
            }
        ),
        "{e}"
    );
    assert!(e.to_string().contains("Seed::parameter(\"v0\")"), "{e}");
    // Out-of-range coordinate, duplicate names, projection.
    let e = solve(
        &problem,
        Dop853::default(),
        &base.clone().sensitivity(Seed::position(2)),
    )
    .expect_err("index");
    assert!(e.to_string().contains("2 coordinates"), "{e}");
    for seed in [Seed::position(usize::MAX), Seed::velocity(usize::MAX)] {
        let e =
            solve(&problem, Dop853::default(), &base.clone().sensitivity(seed)).expect_err("index");
        assert!(e.to_string().contains("2 coordinates"), "{e}");
    }
    let twice = base
        .clone()
        .sensitivity(Seed::parameter("g"))
        .sensitivity(Seed::parameter("g"));
    assert!(matches!(
        solve(&problem, Dop853::default(), &twice),
        Err(Error::Sensitivity { .. })
    ));
    let projected = base
        .clone()
        .sensitivity(Seed::parameter("g"))
        .project(Projection::default());
    assert!(matches!(
        solve(&problem, Dop853::default(), &projected),
        Err(Error::Sensitivity { .. })
    ));
    // Error control asked of a method that has none; without seeds there is nothing to control.
    let controlled = base.clone().sensitivity_control(true);
    let e = solve(
        &problem,
        Rk4::new(1e-2),
        &controlled.clone().sensitivity(Seed::parameter("g")),
    )
    .expect_err("no error control");
    assert!(matches!(e, Error::Sensitivity { .. }), "{e}");
    assert!(
        e.to_string().contains(
            "Rk4 takes fixed steps (h = 0.01) and has no error control to put the sensitivities \
             under: leave Options::sensitivity_control off"
        ),
        "{e}"
    );
    assert!(solve(&problem, Rk4::new(1e-2), &controlled)?.is_success());
    // An event written as a closure is located, but its motion cannot be differentiated.
    let closure = Options::until(10.0)
        .sensitivity(Seed::parameter("g"))
        .event(Event::new("ground", |_t, q, _qd| q[1]).falling().terminal());
    let sol = solve(&problem, Dop853::default(), &closure)?;
    let s = sol.sensitivities.as_ref().expect("recorded");
    assert_eq!(sol.events.len(), 1);
    assert_eq!(s.events, vec![None]);
    Ok(())
}

#[test]
fn sensitivities_leave_the_motion_as_it_is() -> Result<(), Error> {
    // Without error control the steps are the motion's: the same numbers bit for bit.
    let problem = paper_problem()?;
    let options = Options::until(1.0).tolerances(1e-10, 1e-10);
    let plain = solve(&problem, Dop853::default(), &options)?;
    let with = solve(
        &problem,
        Dop853::default(),
        &options.clone().sensitivity(Seed::parameter("g")),
    )?;
    assert_eq!(plain.t, with.t);
    assert_eq!(plain.q, with.q);
    assert_eq!(plain.mu, with.mu);
    assert_eq!(plain.work, with.work);
    assert!(plain.sensitivities.is_none());
    assert_eq!(
        with.sensitivities.as_ref().map(|s| s.values.len()),
        Some(with.len())
    );
    Ok(())
}

#[test]
fn more_seeds_than_one_pass_carries_give_the_same_derivatives() -> Result<(), Error> {
    // Five seeds take two passes of the equations: the first three must not change, x0 moves the
    // impact's place by 1 and not its time, and a doubled seed gives doubled derivatives.
    let problem = paper_problem()?;
    let options = paper_options(true)
        .sensitivity(Seed::position(0))
        .sensitivity(Seed::new("2 h0").with_position(1, 2.0));
    let sol = solve(&problem, Dop853::default(), &options)?;
    check_paper(&sol, 1e-8);
    let s = sol.sensitivities.as_ref().expect("recorded");
    let hit = s.events[0].as_ref().expect("smooth");
    assert!(hit.t[3].abs() < 1e-12 && (hit.q[3][0] - 1.0).abs() < 1e-12);
    assert!((hit.t[4] - 2.0 * hit.t[2]).abs() < 1e-10 * hit.t[2].abs());
    assert!((hit.q[4][0] - 2.0 * hit.q[2][0]).abs() < 1e-10 * hit.q[2][0].abs());
    assert_eq!(s.names[3], "q1(t0)");
    Ok(())
}

/// `L = ½ ẋ² − ½ k x²`.
struct Spring {
    k: f64,
}

impl DynModel for Spring {
    fn sizes(&self) -> (usize, usize) {
        (1, 0)
    }
    fn lagrangian<R: Real>(&self, _t: R, q: &[R], qd: &[R]) -> R {
        (qd[0] * qd[0] - R::parameter("k", self.k) * q[0] * q[0]) * 0.5
    }
}

struct Rest;
impl EventFunction for Rest {
    fn value<R: Real>(&self, _t: R, q: &[R], _qd: &[R]) -> R {
        q[0]
    }
}

#[test]
fn backward_at_output_times_and_at_every_crossing_of_a_non_terminal_event() -> Result<(), Error> {
    // x = x0 cos ωt + (v0/ω) sin ωt, ω = √k, integrated backward from 0 to −4: the series at the
    // output times and every zero of x (a non-terminal event) against the closed form's duals.
    let (k, x0, v0) = (2.5, 0.8, -0.3);
    fn x<D: DualNum<f64> + Copy>(k: D, x0: D, v0: D, t: f64) -> D {
        let w = k.sqrt();
        x0 * (w * t).cos() + v0 / w * (w * t).sin()
    }
    let times: Vec<f64> = (0..=8).map(|i| -0.5 * f64::from(i)).collect();
    let problem = Problem::dynamic(Spring { k }, 0.0, vec![x0], vec![v0])?;
    let options = Options::until(-4.0)
        .tolerances(1e-12, 1e-12)
        .output_times(times.clone())
        .event(Event::smooth("rest", Rest))
        .sensitivity(Seed::parameter("k"))
        .sensitivity(Seed::position(0))
        .sensitivity(Seed::velocity(0))
        .sensitivity_control(true);
    for method in [
        AnyMethod::Dop853(Dop853::default()),
        AnyMethod::Rodas4(Rodas4),
    ] {
        let sol = solve(&problem, method, &options)?;
        assert!(sol.is_success(), "{:?}", sol.status);
        let s = sol.sensitivities.as_ref().expect("recorded");
        let seeded = |j: usize, t: f64| {
            let d = |i: usize, v: f64| Dual64::new(v, f64::from(u8::from(i == j)));
            x(d(0, k), d(1, x0), d(2, v0), t).eps
        };
        assert_eq!(sol.len(), times.len());
        for (p, &t) in sol.t.iter().enumerate() {
            for j in 0..3 {
                let (got, want) = (s.q(p, j)[0], seeded(j, t));
                assert!(
                    (got - want).abs() < 1e-8 * (1.0 + want.abs()),
                    "t = {t}, seed {j}: {got} vs {want}"
                );
            }
        }
        // Zeros of x: T(θ) with x(T(θ), θ) = 0, so dT/dθ = −(∂x/∂θ)/ẋ at T.
        assert!(sol.events.len() >= 2, "{} crossings", sol.events.len());
        for (hit, moved) in sol.events.iter().zip(&s.events) {
            let moved = moved.as_ref().expect("transversal crossings");
            let xd = hit.qd[0];
            for j in 0..3 {
                let want = -seeded(j, hit.t) / xd;
                assert!(
                    (moved.t[j] - want).abs() < 1e-8 * (1.0 + want.abs()),
                    "{} vs {want}",
                    moved.t[j]
                );
                // The event's place stays at x = 0.
                assert!(moved.q[j][0].abs() < 1e-8);
            }
        }
    }
    Ok(())
}

#[test]
fn the_csv_carries_the_sensitivities_by_seed_name() -> Result<(), Error> {
    let sol = solve(
        &paper_problem()?,
        Dop853::default(),
        &paper_options(false)
            .output_grid(0.0, 5)
            .record(Record::State),
    )?;
    let mut out = Vec::new();
    sol.write_csv(&mut out).expect("written");
    let text = String::from_utf8(out).expect("utf-8");
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().expect("header").split(',').collect();
    assert_eq!(header.len(), 1 + 4 + 3 * 4, "{header:?}");
    assert_eq!(header[5], "d(q_1)/d(v0)");
    assert_eq!(header[16], "d(qd_2)/d(h0)");
    let s = sol.sensitivities.as_ref().expect("recorded");
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().expect("a number")).collect())
        .collect();
    assert_eq!(rows.len(), sol.len());
    for (p, row) in rows.iter().enumerate() {
        assert_eq!(&row[5..], &s.values[p]);
    }
    Ok(())
}

/// Reads the name `g` for two different numbers.
struct TwoValues;

impl DynModel for TwoValues {
    fn sizes(&self) -> (usize, usize) {
        (1, 0)
    }
    fn lagrangian<R: Real>(&self, _t: R, q: &[R], qd: &[R]) -> R {
        qd[0] * qd[0] * 0.5 - q[0] * R::parameter("g", 9.81) - q[0] * q[0] * R::parameter("g", 1.0)
    }
}

#[test]
fn a_name_read_with_two_values_is_a_typed_error() -> Result<(), Error> {
    let problem = Problem::dynamic(TwoValues, 0.0, vec![1.0], vec![0.0])?;
    let seeded = Options::until(1.0).sensitivity(Seed::parameter("g"));
    let e = solve(&problem, Dop853::default(), &seeded).expect_err("ambiguous parameter");
    assert!(matches!(e, Error::Sensitivity { .. }), "{e}");
    assert!(e.to_string().contains("two values, 9.81 and 1"), "{e}");
    // Without sensitivities the parameters are the plain numbers, and the model solves.
    assert!(solve(&problem, Dop853::default(), &Options::until(1.0))?.is_success());
    Ok(())
}

/// An event that reads the spring's parameter `k`, with its own value of it: `g = x − k/10`.
struct ReadsK {
    k: f64,
}
impl EventFunction for ReadsK {
    fn value<R: Real>(&self, _t: R, q: &[R], _qd: &[R]) -> R {
        q[0] - R::parameter("k", self.k) * 0.1
    }
}

#[test]
fn one_parameter_name_read_with_two_values_by_the_model_and_an_event_is_refused(
) -> Result<(), Error> {
    let problem = Problem::dynamic(Spring { k: 1.0 }, 0.0, vec![0.0], vec![1.0])?;
    let options = |event_k: f64| {
        Options::until(2.0)
            .tolerances(1e-10, 1e-10)
            .event(Event::smooth("at k/10", ReadsK { k: event_k }))
            .sensitivity(Seed::parameter("k"))
    };
    match solve(&problem, Dop853::default(), &options(0.3)) {
        Err(Error::Sensitivity { what }) => {
            assert!(
                what.contains("\"k\"") && what.contains("the model") && what.contains("at k/10"),
                "{what}"
            );
        }
        other => panic!("expected a refusal, got {:?}", other.map(|s| s.status)),
    }
    // The same value in both places is one parameter: x = sin t reaches k/10 = 0.1 at
    // T = asin 0.1, and ∂T/∂k = (1/10 − ∂x/∂k)/ẋ with ∂x/∂k(t) = (t cos t − sin t)/2 at k = 1.
    let sol = solve(&problem, Dop853::default(), &options(1.0))?;
    assert!(sol.is_success(), "{:?}", sol.status);
    let t = 0.1f64.asin();
    assert!((sol.events[0].t - t).abs() < 1e-9);
    let s = sol.sensitivities.as_ref().expect("recorded");
    let hit = s.events[0].as_ref().expect("smooth event");
    let dx_dk = (t * t.cos() - t.sin()) / 2.0;
    let expected = (0.1 - dx_dk) / t.cos();
    assert!(
        (hit.t[0] - expected).abs() < 1e-8 * expected.abs(),
        "{} against {expected}",
        hit.t[0]
    );
    Ok(())
}

/// The paper's model with the mass read as a parameter too.
struct UniformMass {
    m: f64,
    g: f64,
    v0: f64,
}

impl Lagrangian<2> for UniformMass {
    fn lagrangian<R: Real>(&self, _t: R, q: &SVector<R, 2>, qd: &SVector<R, 2>) -> R {
        let m = R::parameter("m", self.m);
        qd.dot(qd) * m * 0.5 - q[1] * R::parameter("g", self.g) * m
    }
}

impl Constraints<2, 1> for UniformMass {
    fn constraints<R: Real>(&self, _t: R, _q: &SVector<R, 2>, qd: &SVector<R, 2>) -> SVector<R, 1> {
        let v0 = R::parameter("v0", self.v0);
        SVector::from([qd.dot(qd) - v0 * v0])
    }
}

/// `μ(t) = −(m g / 2 v0) tanh(g t / v0)` (42.40) and `Φ = 2μ q̇` with `q̇` of (42.30), for any
/// scalar: `(μ, Φ_x, Φ_y)`.
fn multiplier<D: DualNum<f64> + Copy>(t: f64, m: D, g: D, v0: D) -> (D, D, D) {
    let s = g * t / v0;
    let mu = -(m * g / (v0 * 2.0)) * s.tanh();
    (mu, mu * v0 * 2.0 / s.cosh(), -(mu * v0 * 2.0) * s.tanh())
}

#[test]
fn the_multipliers_and_the_chetaev_force_move_with_the_parameters_as_the_closed_form_says(
) -> Result<(), Error> {
    let (m, g, v0, h0) = (2.0, 9.81, 7.0, 5.0);
    let problem = Problem::new(
        UniformMass { m, g, v0 },
        0.0,
        SVector::from([0.0, h0]),
        SVector::from([v0, 0.0]),
    )?;
    let options = Options::until(10.0)
        .tolerances(1e-12, 1e-12)
        .record(Record::Dynamics)
        .event(Event::smooth("impact", Ground).falling().terminal())
        .sensitivity(Seed::parameter("v0").with_velocity(0, 1.0))
        .sensitivity(Seed::parameter("g"))
        .sensitivity(Seed::parameter("m"))
        .sensitivity(Seed::new("h0").with_position(1, 1.0))
        .sensitivity_control(true);
    for sol in [
        solve(&problem, Dop853::default(), &options)?,
        solve(&problem, Rodas4, &options)?,
    ] {
        assert!(sol.is_success(), "{:?}", sol.status);
        let s = sol.sensitivities.as_ref().expect("sensitivities recorded");
        assert_eq!(s.mu.len(), sol.len());
        assert_eq!(s.phi.len(), sol.len());
        // Per seed: the largest error of dμ/dθ, dΦ/dθ and the largest closed-form value.
        for (j, name) in ["v0", "g", "m", "h0"].iter().enumerate() {
            let seed = s.seed(name).expect("seed by name");
            let (mut error, mut size) = (0.0f64, 0.0f64);
            for (i, &t) in sol.t.iter().enumerate() {
                let d = |k: usize, x: f64| Dual64::new(x, if j == k { 1.0 } else { 0.0 });
                let (mu, px, py) = multiplier(t, d(2, m), d(1, g), d(0, v0));
                let dmu = s.mu(i, seed).expect("recorded with μ");
                let dphi = s.phi(i, seed).expect("recorded with Φ");
                error = error
                    .max((dmu[0] - mu.eps).abs())
                    .max((dphi[0] - px.eps).abs())
                    .max((dphi[1] - py.eps).abs());
                size = size.max(mu.eps.abs()).max(px.eps.abs()).max(py.eps.abs());
                // The value part is the motion's own μ and Φ.
                assert!((sol.mu[i][0] - mu.re).abs() < 1e-9 * m * g);
            }
            println!("dμ/d{name}, dΦ/d{name}: largest error {error:.1e} of {size:.3e}");
            if *name == "h0" {
                // Before the impact μ does not depend on the height.
                assert!(error < 1e-12, "{name}: {error:e}");
            } else {
                assert!(
                    size > 0.1 && error < 1e-10 * size,
                    "{name}: {error:e} of {size:e}"
                );
            }
        }
    }
    Ok(())
}

#[test]
fn without_the_multipliers_recorded_their_sensitivities_are_absent() -> Result<(), Error> {
    let sol = solve(
        &paper_problem()?,
        Dop853::default(),
        &paper_options(false).record(Record::State),
    )?;
    let s = sol.sensitivities.as_ref().expect("sensitivities recorded");
    assert!(s.mu.is_empty() && s.phi.is_empty());
    assert_eq!(s.mu(0, 0), None);
    assert!(!s.values.is_empty());
    Ok(())
}
