//! `scenes/isokinetic-gas.toml`: ten coordinates under one Gaussian isokinetic constraint keep
//! their kinetic energy and the energy balance, and follow the closed form of the motion.
//!
//! With `m a_i = −m g ŷ + μ m v_i` and `Σ ½ m |v_i|² = K0`, the vertical momentum `s = m Σ ẏ_i`
//! obeys `ṡ = (g / 2K0)(s² − M² u²)`, `M = 5m`, `u = √(2K0/M)`. With `φ = g t/u + φ0`,
//! `tanh φ0 = −s0/(M u)`:
//!
//! ```text
//! μ = −(g/u) tanh φ,   ẋ_i = ẋ_i0 cosh φ0 / cosh φ,   ẏ_i cosh φ = ẏ_i0 cosh φ0 − u (sinh φ − sinh φ0),
//! x_i = x_i0 + ẋ_i0 cosh φ0 (u/g)(gd φ − gd φ0),
//! y_i = y_i0 + (u/g) [(ẏ_i0 cosh φ0 + u sinh φ0)(gd φ − gd φ0) − u ln(cosh φ / cosh φ0)],
//! ```
//!
//! `gd φ = atan(sinh φ)`. With one particle this is the paper's uniform projectile.

use std::collections::HashMap;

use chetaev::prelude::Status;
use chetaev_scene::{Outcome, Scene};

const SCENE: &str = include_str!("../../../../scenes/isokinetic-gas.toml");

fn solved() -> (Scene, Outcome, HashMap<String, f64>) {
    let scene = Scene::parse(SCENE, "isokinetic-gas.toml").unwrap_or_else(|e| panic!("{e}"));
    scene.check().unwrap_or_else(|e| panic!("{e}"));
    let outcome = scene.solve().unwrap_or_else(|e| panic!("{e}"));
    let p = scene.parameters.iter().cloned().collect();
    (scene, outcome, p)
}

/// The closed form at `t` for the initial state `(q0, qd0)`: `(q, q̇, μ)`.
fn exact(p: &HashMap<String, f64>, q0: &[f64], qd0: &[f64], t: f64) -> (Vec<f64>, Vec<f64>, f64) {
    let (g, u, phi0) = (p["g"], p["u"], p["phi0"]);
    let phi = g * t / u + phi0;
    let gd = |x: f64| x.sinh().atan();
    let (c0, s0, c, s) = (phi0.cosh(), phi0.sinh(), phi.cosh(), phi.sinh());
    let mut q = Vec::new();
    let mut qd = Vec::new();
    for i in 0..q0.len() / 2 {
        let (x0, y0, vx0, vy0) = (q0[2 * i], q0[2 * i + 1], qd0[2 * i], qd0[2 * i + 1]);
        q.push(x0 + vx0 * c0 * (u / g) * (gd(phi) - gd(phi0)));
        q.push(y0 + (u / g) * ((vy0 * c0 + u * s0) * (gd(phi) - gd(phi0)) - u * (c / c0).ln()));
        qd.push(vx0 * c0 / c);
        qd.push((vy0 * c0 - u * (s - s0)) / c);
    }
    (q, qd, -(g / u) * phi.tanh())
}

#[test]
fn ten_coordinates_keep_the_kinetic_energy_and_the_energy_balance() {
    let (scene, o, p) = solved();
    assert_eq!((scene.n(), scene.k()), (10, 1));
    assert_eq!(o.status, Status::Success);
    assert_eq!(o.t.len(), 151);
    let (m, k0) = (p["m"], p["K0"]);
    // At rtol = atol = 1e-10 over 3 s the constraint drifts by a few 1e-10 of K0; so does the
    // energy balance, since the work of the thermostat accounts for the rest exactly.
    let tol = 2e-9 * k0;
    let residual = o
        .residual
        .iter()
        .flatten()
        .fold(0.0f64, |a, f| a.max(f.abs()));
    assert!(residual <= tol, "max |f| = {residual:e}");
    let balance = o.balance.iter().fold(0.0f64, |a, b| a.max(b.abs()));
    assert!(balance <= tol, "max balance = {balance:e}");
    for (i, qd) in o.qd.iter().enumerate() {
        let kinetic = 0.5 * m * qd.iter().map(|v| v * v).sum::<f64>();
        assert!((kinetic - k0).abs() <= tol, "t = {}: K = {kinetic}", o.t[i]);
    }
    // The work of the thermostat is the change of potential energy.
    let last = o.t.len() - 1;
    let fall: f64 = (0..5).map(|i| o.q[last][2 * i + 1] - p["h0"]).sum();
    assert!((o.work[last] - m * p["g"] * fall).abs() <= tol);
}

#[test]
fn the_thermostat_force_is_mu_m_v_and_the_motion_follows_the_closed_form() {
    let (scene, o, p) = solved();
    let (m, u) = (p["m"], p["u"]);
    for i in 0..o.t.len() {
        let (t, mu) = (o.t[i], o.mu[i][0]);
        // Φ = Jᵀμ with J = m q̇: the Gaussian isokinetic force, along each particle's momentum.
        for (phi, v) in o.phi[i].iter().zip(&o.qd[i]) {
            assert!((phi - mu * m * v).abs() <= 1e-14 * (mu * m * u).abs().max(1.0));
        }
        let (q, qd, mu_exact) = exact(&p, &scene.q0, &scene.qd0, t);
        assert!((mu - mu_exact).abs() <= 1e-9 * p["g"] / u, "μ at t = {t}");
        for c in 0..10 {
            assert!(
                (o.q[i][c] - q[c]).abs() <= 1e-9 * p["h0"],
                "q{c} at t = {t}"
            );
            assert!((o.qd[i][c] - qd[c]).abs() <= 1e-9 * u, "q̇{c} at t = {t}");
        }
    }
    // The scene's own `mu_exact` column is the same closed form.
    let (_, e) = &scene.output.quantities[2];
    for i in [0, 75, 150] {
        let env = chetaev_scene::expr::Env {
            t: o.t[i],
            q: &o.q[i],
            qd: &o.qd[i],
        };
        let (_, _, mu_exact) = exact(&p, &scene.q0, &scene.qd0, o.t[i]);
        assert!((e.eval(&env) - mu_exact).abs() <= 1e-14);
    }
    // The net vertical momentum, and with it μ, changes sign at t = −φ0 u / g.
    let hit = &o.events[0];
    assert_eq!(o.event_name(hit.index), "net vertical momentum zero");
    let t_zero = -p["phi0"] * u / p["g"];
    assert!((hit.t - t_zero).abs() <= 1e-9, "{} vs {t_zero}", hit.t);
    // At the end (g t/u ≈ 6) every particle falls nearly straight down at the common terminal
    // speed u: the velocities' differences decay as 1/cosh φ.
    let last = o.qd.last().expect("points");
    for i in 0..5 {
        assert!(last[2 * i].abs() < 0.02 * u && (last[2 * i + 1] + u).abs() < 0.02 * u);
    }
}
