//! Holonomic constraints in scene files: the Cartesian pendulum of
//! `scenes/cartesian-pendulum.toml` against its elliptic period and the rod's tension, and the
//! located error of a holonomic constraint that uses a velocity.

use std::f64::consts::PI;

use chetaev_scene::Scene;

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
    let text = include_str!("../../../scenes/cartesian-pendulum.toml");
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
fn a_holonomic_constraint_on_a_velocity_is_a_located_error() {
    let text = include_str!("../../../scenes/cartesian-pendulum.toml").replace(
        "holonomic = [\"x^2 + y^2 - l^2\"]",
        "holonomic = [\"x*x_dot + y^2 - l^2\"]",
    );
    let err = Scene::parse(&text, "bad.toml").expect_err("uses x_dot");
    assert!(err.to_string().contains("uses x_dot"), "{err}");
}
