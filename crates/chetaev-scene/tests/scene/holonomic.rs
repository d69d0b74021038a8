//! Holonomic constraints in scene files: the Cartesian pendulum of
//! `scenes/cartesian-pendulum.toml` against its elliptic period and the rod's tension, and the
//! located error of a holonomic constraint that uses a velocity.

use std::f64::consts::PI;

use chetaev_scene::{output, Scene};

/// `K(k)` by the arithmetic–geometric mean.
fn elliptic_k(k: f64) -> f64 {
    let (mut a, mut b) = (1.0f64, (1.0 - k * k).sqrt());
    for _ in 0..40 {
        (a, b) = (0.5 * (a + b), (a * b).sqrt());
    }
    PI / (2.0 * a)
}

#[test]
fn the_cartesian_pendulum_scene_has_the_elliptic_period() {
    let text = include_str!("../../../../scenes/cartesian-pendulum.toml");
    let scene = Scene::parse(text, "scenes/cartesian-pendulum.toml").expect("parses");
    assert_eq!(scene.k(), 1);
    let o = scene.solve().expect("solves");
    assert!(o.is_success(), "{:?}", o.status);
    let (m, g, l, theta0) = (1.5, 9.81, 2.0, 80.0 * PI / 180.0);
    let period = 4.0 * f64::sqrt(l / g) * elliptic_k((theta0 / 2.0_f64).sin());
    assert_eq!(o.events.len(), 3); // at T/4, 5T/4 and 9T/4 before t_end = 8
    assert!((o.events[1].t - o.events[0].t - period).abs() < 1e-10 * period);
    for i in 0..o.len() {
        let cos_theta = -o.q[i][1] / l;
        let lambda = -m * g * (3.0 * cos_theta - 2.0 * theta0.cos()) / (2.0 * l);
        assert!((o.mu[i][0] - lambda).abs() < 1e-8, "λ at t = {}", o.t[i]);
        assert!(o.position_residual[i][0].abs() < 1e-9);
    }
}

#[test]
fn a_bead_that_reaches_the_rim_of_its_bowl_stops_there() {
    // The lower half of the unit circle ends at x = ±1, where its gradient becomes infinite. From
    // the bottom at speed 5 the bead reaches the rim at t = ∫₀^{π/2} dθ/v(θ), with
    // v² = 25 − 2g(1 − cos θ); the steps that stayed inside the domain of the square root crept
    // along x = 1 with the bead falling off the curve, and returned success.
    let text = r#"
[model]
coordinates = ["x", "y"]
lagrangian = "0.5*(x_dot^2 + y_dot^2) - 9.81*y"
holonomic = ["y + sqrt(1 - x^2)"]

[initial]
q = [0.0, -1.0]
q_dot = [5.0, 0.0]

[solve]
method = "dopri5"
t_end = 3.0

[output]
tables = ["residual"]
"#;
    let scene = Scene::parse(text, "bowl.toml").expect("parses");
    let o = scene.solve().expect("solves");
    let Some(chetaev::Error::SingularPoint {
        t,
        cause: chetaev::Singularity::Unbounded(1),
        ..
    }) = o.error()
    else {
        panic!("{:?}", o.status);
    };
    let steps = 20_000;
    let h = 0.5 * PI / steps as f64;
    let rim: f64 = (0..steps)
        .map(|i| {
            let theta = (i as f64 + 0.5) * h;
            h / (25.0 - 2.0 * 9.81 * (1.0 - theta.cos())).sqrt()
        })
        .sum();
    assert!((t - rim).abs() < 1e-4, "stopped at {t}, the rim at {rim}");
    let f = output::failure(&scene, o.error().expect("failed"));
    assert!(
        f.what
            .contains("holonomic constraint 1 (y + sqrt(1 - x^2)) grew without bound"),
        "{f:?}"
    );
    assert_eq!(o.position_residual.len(), o.len());
    for (h, t) in o.position_residual.iter().zip(&o.t) {
        assert!(h[0].abs() < 1e-4, "h = {} at t = {t}", h[0]);
    }
}

#[test]
fn a_holonomic_constraint_on_a_velocity_is_a_located_error() {
    let text = include_str!("../../../../scenes/cartesian-pendulum.toml").replace(
        "holonomic = [\"x^2 + y^2 - l^2\"]",
        "holonomic = [\"x*x_dot + y^2 - l^2\"]",
    );
    let err = Scene::parse(&text, "bad.toml").expect_err("uses x_dot");
    assert!(err.to_string().contains("uses x_dot"), "{err}");
}

/// The Cartesian pendulum with its initial position and velocity replaced.
fn pendulum(q: &str, q_dot: &str, extra: &str) -> String {
    include_str!("../../../../scenes/cartesian-pendulum.toml")
        .replace(
            "q = [\"l*sin(theta0)\", \"-l*cos(theta0)\"]",
            &format!("q = {q}"),
        )
        .replace("q_dot = [0.0, 0.0]", &format!("q_dot = {q_dot}{extra}"))
}

/// The line of `text` that starts with `start`, from 1.
fn line_of(text: &str, start: &str) -> usize {
    text.lines()
        .position(|l| l.starts_with(start))
        .expect("line")
        + 1
}

#[test]
fn project_velocity_reports_how_far_it_moved_the_position() {
    // Off the circle x² + y² = l² = 4 (radius 2.12), at rest: q is moved onto it, q_dot is kept.
    let text = pendulum("[1.5, -1.5]", "[0.0, 0.0]", "\nproject_velocity = true");
    let scene = Scene::parse(&text, "moved.toml").expect("parses");
    let o = scene.solve().expect("solves");
    assert!(o.is_success(), "{:?}", o.status);
    let q = &o.q[0];
    assert!((q[0].hypot(q[1]) - 2.0).abs() < 1e-12, "{q:?}");
    let summary = output::summary(&scene, &o);
    let n = output::summary_number;
    let want = format!(
        "  initial  q projected onto h = 0 (project_velocity = true; q_dot satisfies ḣ = 0 as \
         given): x 1.5 → {} ({}), y -1.5 → {} (+{})\n",
        n(q[0]),
        n(q[0] - 1.5),
        n(q[1]),
        n(q[1] + 1.5)
    );
    assert!(summary.contains(&want), "{summary}");
    assert!(!summary.contains("changed nothing"), "{summary}");

    // Off the circle and moving across it: both change, each by how much.
    let text = pendulum("[1.5, -1.5]", "[1.0, 0.0]", "\nproject_velocity = true");
    let scene = Scene::parse(&text, "both.toml").expect("parses");
    let o = scene.solve().expect("solves");
    let summary = output::summary(&scene, &o);
    let (q, qd) = (&o.q[0], &o.qd[0]);
    assert!((q[0] * qd[0] + q[1] * qd[1]).abs() < 1e-12, "{qd:?}"); // ḣ = 2 q·q̇ = 0
    assert!(
        summary.contains(&format!(
            "  initial  q projected onto h = 0 and q_dot onto ḣ = 0 (project_velocity = true): \
             x 1.5 → {}",
            n(q[0])
        )),
        "{summary}"
    );
    assert!(
        summary.contains(&format!("x_dot 1 → {} ({})", n(qd[0]), n(qd[0] - 1.0))),
        "{summary}"
    );

    // On the circle and along it: nothing changes, and the summary says so.
    let text = pendulum("[0.0, -2.0]", "[1.0, 0.0]", "\nproject_velocity = true");
    let scene = Scene::parse(&text, "kept.toml").expect("parses");
    let o = scene.solve().expect("solves");
    assert!(output::summary(&scene, &o).contains(
        "  initial  q and q_dot satisfy the constraints as given; project_velocity = true changed \
         nothing\n"
    ));
}

#[test]
fn an_inconsistent_holonomic_position_points_at_q_with_the_scene_key_to_set() {
    let text = pendulum("[1.5, -1.5]", "[0.0, 0.0]", "");
    let e = Scene::parse(&text, "off.toml")
        .expect("parses")
        .check()
        .expect_err("off the circle");
    assert_eq!(e.position(), Some((line_of(&text, "q = "), 5)), "{e}");
    let m = e.to_string();
    assert!(
        m.contains("the initial position violates holonomic constraint 1 (x^2 + y^2 - l^2): h = "),
        "{m}"
    );
    assert!(
        m.contains("set project_velocity = true under [initial]"),
        "{m}"
    );
    assert!(!m.contains("Problem::"), "{m}");
}

#[test]
fn a_holonomic_constraint_whose_gradient_vanishes_says_so_in_its_own_terms() {
    // (x² + y² − l²)² holds on the circle, but its gradient vanishes all along it: exactly at
    // (l, 0), where the set-up fails, and to rounding elsewhere, where the run stops.
    let square = |text: String| {
        text.replace(
            "holonomic = [\"x^2 + y^2 - l^2\"]",
            "holonomic = [\"(x^2 + y^2 - l^2)^2\"]",
        )
    };
    let text = square(pendulum("[\"l\", 0.0]", "[0.0, 0.0]", ""));
    let e = Scene::parse(&text, "flat.toml")
        .expect("parses")
        .check()
        .expect_err("degenerate");
    let m = e.to_string();
    assert!(
        m.contains("holonomic constraint 1 ((x^2 + y^2 - l^2)^2) does not restrict the velocity"),
        "{m}"
    );
    let text = square(include_str!("../../../../scenes/cartesian-pendulum.toml").to_string());
    let scene = Scene::parse(&text, "flat.toml").expect("parses");
    let o = scene.solve().expect("regular to rounding at the start");
    assert!(!o.is_success());
    let m = output::summary(&scene, &o);
    for m in [e.to_string(), m] {
        assert!(m.contains("derivative by the coordinates vanishes"), "{m}");
        assert!(!m.contains("speed"), "{m}");
    }
}

#[test]
fn an_inconsistent_velocity_names_the_holonomic_constraint_it_leaves() {
    // On the circle at 80°, moving along x: ḣ = 2 x ẋ ≠ 0.
    let text = pendulum("[\"l*sin(theta0)\", \"-l*cos(theta0)\"]", "[1.0, 0.0]", "");
    let e = Scene::parse(&text, "across.toml")
        .expect("parses")
        .check()
        .expect_err("across the circle");
    assert_eq!(
        e.position().map(|p| p.0),
        Some(line_of(&text, "q_dot")),
        "{e}"
    );
    let m = e.to_string();
    assert!(
        m.contains("violates holonomic constraint 1 (x^2 + y^2 - l^2) differentiated in time"),
        "{m}"
    );
    assert!(m.contains("project_velocity = true"), "{m}");
    assert!(!m.contains("(?)"), "{m}");
}

#[test]
fn a_failure_names_the_constraint_as_the_scene_writes_it() {
    // A velocity constraint, then a holonomic one: chetaev numbers them 1 and 2.
    let text = include_str!("../../../../scenes/cartesian-pendulum.toml").replace(
        "holonomic = [",
        "constraints = [\"x_dot*y - y_dot*x - 1\"]\nholonomic = [",
    );
    let scene = Scene::parse(&text, "two.toml").expect("parses");
    let (q, qd) = (vec![0.0, -2.0], vec![0.0, 0.0]);
    let degenerate = |index| {
        let e = chetaev::Error::DegenerateConstraint {
            t: 0.5,
            index,
            q: q.clone(),
            qd: qd.clone(),
        };
        output::failure(&scene, &e).what
    };
    let first = degenerate(1);
    assert!(
        first.starts_with("constraint 1 (x_dot*y - y_dot*x - 1) no longer"),
        "{first}"
    );
    let second = degenerate(2);
    assert!(
        second.starts_with("holonomic constraint 1 (x^2 + y^2 - l^2) no longer"),
        "{second}"
    );
    let e = chetaev::Error::SingularPoint {
        t: 0.5,
        cause: chetaev::Singularity::Gradient(2),
        ratio: 1e-9,
        q: q.clone(),
        qd: qd.clone(),
    };
    let f = output::failure(&scene, &e);
    assert!(
        f.what.contains("holonomic constraint 1 (x^2 + y^2 - l^2)"),
        "{f:?}"
    );
    assert!(!f.advice.contains("Options::"), "{f:?}");
    // A model that is not finite there is named too: the Lagrangian divides by x.
    let text = text.replace("- m*g*y\"", "- m*g*y/x\"");
    let scene = Scene::parse(&text, "pole.toml").expect("parses");
    let e = chetaev::Error::NonFiniteEvaluation { t: 0.5, q, qd };
    let f = output::failure(&scene, &e);
    assert!(
        f.what
            .starts_with("the Lagrangian L (0.5*m*(x_dot^2 + y_dot^2) - m*g*y/x) is inf at x = 0"),
        "{f:?}"
    );
}

#[test]
fn an_initial_projection_that_cannot_converge_points_at_the_initial_state() {
    // The prescribed speed a·t is 0 at t0 = 0, where the gradient 2q̇ of the constraint vanishes:
    // no Newton step can reach it.
    let text = include_str!("../../../../scenes/uniform-projectile.toml")
        .replace(
            "constraints = [\"x_dot^2 + y_dot^2 - v0^2\"]",
            "constraints = [\"x_dot^2 + y_dot^2 - (v0*t)^2\"]",
        )
        .replace(
            "q_dot = [\"v0\", 0.0]",
            "q_dot = [0.3, 0.0]\nproject_velocity = true",
        );
    let e = Scene::parse(&text, "ramp.toml")
        .expect("parses")
        .check()
        .expect_err("no consistent velocity can be reached");
    assert_eq!(
        e.position().map(|p| p.0),
        Some(line_of(&text, "[initial]")),
        "{e}"
    );
    let m = e.to_string();
    assert!(
        m.contains("project_velocity = true could not make the initial state consistent"),
        "{m}"
    );
    assert!(m.contains("prescribed speed is 0 at t0"), "{m}");
}

/// A pendulum of length 2 whose `y` and `y_dot` are left to the constraint.
fn pendulum_with(initial: &str) -> String {
    format!(
        r#"
[model]
coordinates = ["x", "y"]
lagrangian = "0.5*(x_dot^2 + y_dot^2) - 9.81*y"
holonomic = ["x^2 + y^2 - 4"]

[initial]
{initial}

[solve]
t_end = 1.0
"#
    )
}

#[test]
fn named_independent_coordinates_and_speeds_complete_the_dependent_ones() {
    // x = 1.2 held: y = −1.6 (the guess −1.76 is 10 % off); ẋ = 0.8: ẏ = −x ẋ / y = 0.6.
    let text = pendulum_with(
        "q = [1.2, -1.76]\nq_dot = [0.8, 0.0]\nindependent_coordinates = [\"x\"]\nindependent_speeds = [\"x_dot\"]",
    );
    let scene = Scene::parse(&text, "pendulum.toml").expect("parses");
    let problem = scene.problem().expect("completed");
    assert!((problem.q0()[1] + 1.6).abs() < 1e-14, "{:?}", problem.q0());
    assert!(
        (problem.qd0()[1] - 0.6).abs() < 1e-14,
        "{:?}",
        problem.qd0()
    );
    let o = scene.solve().expect("solves");
    assert!(o.is_success() && o.position_residual.iter().all(|h| h[0].abs() < 1e-8));
}

#[test]
fn independent_lists_are_checked_where_they_are_written() {
    let cases = [
        (
            "q = [1.2, -1.76]\nq_dot = [0.8, 0.0]\nindependent_speeds = [\"z_dot\"]",
            "'z_dot' is not a coordinate",
        ),
        (
            "q = [1.2, -1.76]\nq_dot = [0.8, 0.0]\nindependent_speeds = [\"x\"]\nproject_velocity = true",
            "choose one",
        ),
        (
            // Both coordinates held: no coordinate is left for the holonomic constraint.
            "q = [1.2, -1.76]\nq_dot = [0.8, 0.0]\nindependent_coordinates = [\"x\", \"y\"]",
            "have 1",
        ),
    ];
    for (initial, says) in cases {
        let text = pendulum_with(initial);
        let e = Scene::parse(&text, "pendulum.toml")
            .and_then(|s| s.problem().map(|_| ()))
            .expect_err(says);
        let message = e.to_string();
        assert!(message.contains(says), "{message}");
        assert!(e.position().is_some(), "{message}");
    }
}

#[test]
fn a_position_constraint_under_constraints_is_told_to_go_under_holonomic() {
    let text = pendulum_with("q = [0.0, -2.0]\nq_dot = [1.0, 0.0]").replace(
        "holonomic = [\"x^2 + y^2 - 4\"]",
        "constraints = [\"x^2 + y^2 - l^2\"]",
    );
    let text = format!("[parameters]\nl = 2.0\n{text}");
    let e = Scene::parse(&text, "pendulum.toml").expect_err("a position constraint");
    let message = e.to_string();
    assert!(
        message.contains("this constraint has no velocity in it"),
        "{message}"
    );
    assert!(
        message.contains("a position constraint goes under `holonomic = [...]`"),
        "{message}"
    );
    assert!(
        message.contains("holonomic = [\"x^2 + y^2 - l^2\"]"),
        "{message}"
    );
    assert!(!message.contains("speed"), "{message}");
    // At the constraint itself.
    let line = text
        .lines()
        .position(|l| l.starts_with("constraints"))
        .expect("line")
        + 1;
    assert_eq!(e.position(), Some((line, 16)), "{message}");
    // The same constraint under holonomic runs.
    let fixed = text.replace("constraints = [", "holonomic = [");
    Scene::parse(&fixed, "pendulum.toml")
        .and_then(|s| s.check())
        .unwrap_or_else(|e| panic!("{e}"));
}
