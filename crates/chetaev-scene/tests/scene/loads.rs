//! `[[loads]]`: forces on points and torques on bodies, stated where they act, against the same
//! scenes with their generalised forces written by hand, and the located errors of a wrong table.

use chetaev::model::DynModel;
use chetaev_scene::Scene;

/// A pendulum of mass `m` on a rod of length `l`, angle `theta` from the downward vertical,
/// damped by `D = ½ c θ̇²`, with `extra` added to `[model]` (forces) and after it (loads).
fn pendulum(model: &str, loads: &str) -> String {
    format!(
        r#"
[parameters]
m = 1.5
g = 9.81
l = 2.0
c = 6.0
F = 4.0

[model]
coordinates = ["theta"]
lagrangian = "0.5*m*l^2*theta_dot^2 + m*g*l*cos(theta)"
dissipation = "0.5*c*theta_dot^2"
{model}
{loads}
[initial]
q = [0.1]
q_dot = [0.5]

[solve]
method = "dop853"
t_end = 80.0
rtol = 1e-11
atol = 1e-12

[output]
tables = ["state", "energy"]
times = "steps"
"#
    )
}

/// The scene's motion: its times, coordinates and velocities at every step.
fn motion(text: &str) -> (Vec<f64>, Vec<Vec<f64>>, Vec<Vec<f64>>) {
    let scene = Scene::parse(text, "loads.toml").unwrap_or_else(|e| panic!("{e}"));
    let o = scene.solve().unwrap_or_else(|e| panic!("{e}"));
    assert!(o.is_success(), "{:?}", o.status);
    let rows = |s: &chetaev::prelude::Series| s.into_iter().map(<[f64]>::to_vec).collect();
    (o.t.clone(), rows(&o.q), rows(&o.qd))
}

/// Two motions take the same steps and agree to `tol` in every component.
fn same_motion(a: &str, b: &str, tol: f64) {
    let (ta, qa, qda) = motion(a);
    let (tb, qb, qdb) = motion(b);
    assert_eq!(ta.len(), tb.len(), "the same number of steps");
    assert!(ta.len() > 20);
    for i in 0..ta.len() {
        assert!(
            (ta[i] - tb[i]).abs() <= tol * ta[i].abs().max(1.0),
            "t[{i}]"
        );
        for (x, y) in qa[i].iter().zip(&qb[i]).chain(qda[i].iter().zip(&qdb[i])) {
            assert!((x - y).abs() <= tol, "step {i}: {x} against {y}");
        }
    }
}

const PUSH: &str = r#"
[[loads]]
point = ["l*sin(theta)", "-l*cos(theta)"]
force = ["F", "0"]
"#;

#[test]
fn a_horizontal_force_at_the_bob_moves_the_pendulum_as_its_generalised_force_does() {
    let by_load = pendulum("", PUSH);
    let by_hand = pendulum("forces = [\"F*l*cos(theta)\"]", "");
    same_motion(&by_load, &by_hand, 1e-14);
    // The same force in space, with the plane's normal as the third axis.
    let in_space = pendulum(
        "",
        "[[loads]]\npoint = [\"l*sin(theta)\", \"-l*cos(theta)\", \"0\"]\nforce = [\"F\", \"0\", \"0\"]\n",
    );
    same_motion(&in_space, &by_hand, 1e-14);
}

#[test]
fn a_pendulum_pushed_sideways_settles_where_tan_theta_is_f_over_m_g() {
    let (t, q, qd) = motion(&pendulum("", PUSH));
    let last = t.len() - 1;
    assert!((t[last] - 80.0).abs() < 1e-12);
    let (m, g, f): (f64, f64, f64) = (1.5, 9.81, 4.0);
    let expected = (f / (m * g)).atan();
    // Damped at 1/(2·m·l²/c) = 0.5 per second, the swing has decayed by e^-40 at t = 80.
    assert!(
        (q[last][0] - expected).abs() < 1e-9,
        "{} against {expected}",
        q[last][0]
    );
    assert!(qd[last][0].abs() < 1e-9, "{}", qd[last][0]);
}

#[test]
fn loads_add_to_the_forces_written_by_hand() {
    let both = pendulum(
        "forces = [\"0.5*F*l*cos(theta)\"]",
        &PUSH.replace("\"F\"", "\"0.5*F\""),
    );
    let by_hand = pendulum("forces = [\"F*l*cos(theta)\"]", "");
    same_motion(&both, &by_hand, 1e-14);
}

#[test]
fn a_torque_on_the_rod_moves_the_pendulum_as_its_generalised_force_does() {
    let torque = "[[loads]]\nangular_velocity = [\"theta_dot\"]\ntorque = [\"2 - 0.5*theta_dot*cos(theta)\"]\n";
    let by_load = pendulum("", torque);
    let by_hand = pendulum("forces = [\"2 - 0.5*theta_dot*cos(theta)\"]", "");
    same_motion(&by_load, &by_hand, 1e-14);
}

/// A body whose axes turn with two angles, `ω = (θ̇ cos φ, θ̇ sin φ, φ̇ + ψ θ̇)`, under a torque
/// `T = (a, b, k)`: `Q_φ = T · ∂ω/∂φ̇ = k`, `Q_θ = T · ∂ω/∂θ̇ = a cos φ + b sin φ + k ψ`.
const TOP: &str = r#"
[parameters]
psi = 0.3

[model]
coordinates = ["phi", "theta"]
lagrangian = "0.5*(2*phi_dot^2 + theta_dot^2) - cos(theta)"
{model}
{loads}
[initial]
q = [0.2, 0.4]
q_dot = [1.0, -0.5]

[solve]
t_end = 5.0
rtol = 1e-11
atol = 1e-12

[output]
tables = ["state"]
times = "steps"
"#;

fn top(model: &str, loads: &str) -> String {
    TOP.replace("{model}", model).replace("{loads}", loads)
}

const SPIN: &str = r#"
[[loads]]
angular_velocity = ["theta_dot*cos(phi)", "theta_dot*sin(phi)", "phi_dot + psi*theta_dot"]
torque = ["-theta_dot", "0.5*t", "1 - phi_dot"]
"#;

#[test]
fn a_torque_in_space_is_the_torque_dotted_with_the_partial_angular_velocities() {
    let scene = Scene::parse(&top("", SPIN), "top.toml").unwrap_or_else(|e| panic!("{e}"));
    let problem = scene.problem().unwrap_or_else(|e| panic!("{e}"));
    let (t, q, qd) = (1.25, [0.7, -0.3], [0.4, 2.0]);
    let mut out = [f64::NAN; 2];
    assert!(problem.model().forces(t, &q, &qd, &mut out));
    let (a, b, k) = (-qd[1], 0.5 * t, 1.0 - qd[0]);
    let expected = [k, a * q[0].cos() + b * q[0].sin() + k * 0.3];
    for (x, y) in out.iter().zip(expected) {
        assert!((x - y).abs() < 1e-15, "{out:?} against {expected:?}");
    }
    let by_hand = top(
        "forces = [\"1 - phi_dot\", \"-theta_dot*cos(phi) + 0.5*t*sin(phi) + (1 - phi_dot)*psi\"]",
        "",
    );
    same_motion(&top("", SPIN), &by_hand, 1e-14);
}

#[test]
fn loads_count_in_the_work_of_the_forces_and_close_the_energy_balance() {
    let text = pendulum("", PUSH);
    let scene = Scene::parse(&text, "loads.toml").unwrap_or_else(|e| panic!("{e}"));
    let o = scene.solve().unwrap_or_else(|e| panic!("{e}"));
    let last = o.t.len() - 1;
    // E = ½ m l² θ̇² − m g l cos θ; the push and the damping do its change.
    let energy = |i: usize| 0.5 * 6.0 * o.qd[i][0].powi(2) - 1.5 * 9.81 * 2.0 * o.q[i][0].cos();
    let change = energy(last) - energy(0);
    assert!(change.abs() > 0.1, "{change}");
    assert!(
        (o.work_forces[last] - change).abs() < 1e-8,
        "{} against {change}",
        o.work_forces[last]
    );
    for (i, b) in o.balance.iter().enumerate() {
        assert!(b.abs() < 1e-8, "balance {b} at t = {}", o.t[i]);
    }
}

#[test]
fn describe_shows_a_scene_with_loads() {
    let scene = Scene::parse(&pendulum("", PUSH), "loads.toml").unwrap_or_else(|e| panic!("{e}"));
    let text = scene.describe().unwrap_or_else(|e| panic!("{e}"));
    assert!(text.contains("coordinates q = (theta)"), "{text}");
    assert!(text.contains('F'), "the force's parameter is shown: {text}");
    assert!(!scene
        .describe_latex()
        .unwrap_or_else(|e| panic!("{e}"))
        .is_empty());
}

/// The line and column of the first occurrence of `needle` in `text` from its `[[loads]]` on.
fn line_col(text: &str, needle: &str) -> (usize, usize) {
    let from = text.find("[[loads]]").unwrap_or(0);
    let at = from
        + text[from..]
            .find(needle)
            .unwrap_or_else(|| panic!("{needle} not in {text}"));
    let line = text[..at].matches('\n').count() + 1;
    let col = text[..at].rfind('\n').map_or(at, |nl| at - nl - 1) + 1;
    (line, col)
}

#[test]
fn a_wrong_loads_table_is_a_located_error_that_says_what_to_write() {
    let cases = [
        (
            "[[loads]]\npoint = [\"l*sin(theta)\", \"-l*cos(theta)\"]\nforce = [\"F\"]\n",
            "[\"F\"]",
            "the force has 1 component and the point 2 components",
        ),
        (
            "[[loads]]\npoint = [\"l*sin(theta)\"]\nforce = [\"F\"]\n",
            "[\"l*sin(theta)\"]",
            "give 2 components in the plane or 3 in space",
        ),
        (
            "[[loads]]\npoint = [\"l*sin(theta)\", \"-l*cos(theta)*theta_dot\"]\nforce = [\"F\", \"0\"]\n",
            "\"-l*cos(theta)*theta_dot\"",
            "depends on the coordinates and time only",
        ),
        (
            "[[loads]]\nforce = [\"F\", \"0\"]\n",
            "[\"F\", \"0\"]",
            "a force needs the point it acts on: add point = [...]",
        ),
        (
            "[[loads]]\npoint = [\"l*sin(theta)\", \"-l*cos(theta)\"]\n",
            "[\"l*sin(theta)\", \"-l*cos(theta)\"]",
            "add force = [...]",
        ),
        (
            "[[loads]]\npoint = [\"l*sin(theta)\", \"-l*cos(theta)\"]\nforce = [\"F\", \"0\"]\nangular_velocity = [\"theta_dot\"]\ntorque = [\"1\"]\n",
            "[\"theta_dot\"]",
            "not both; put each in its own [[loads]] table",
        ),
        (
            "[[loads]]\ntorque = [\"1\"]\n",
            "[\"1\"]",
            "add angular_velocity = [...]",
        ),
        (
            "[[loads]]\npoint = [\"l*sin(theta)\", \"-l*cos(theta)\"]\ntorque = [\"1\"]\n",
            "[\"1\"]",
            "a torque acts on a body, not on a point",
        ),
        (
            "[[loads]]\nangular_velocity = [\"theta_dot\", \"0\"]\ntorque = [\"1\", \"0\"]\n",
            "[\"theta_dot\", \"0\"]",
            "the angular velocity has 2 components: give 1 component in the plane or 3 in space",
        ),
        (
            "[[loads]]\nangular_velocity = [\"theta\"]\ntorque = [\"1\"]\n",
            "[\"theta\"]",
            "no component of this angular velocity uses a velocity",
        ),
        (
            "[[loads]]\npoint = [\"l*sin(theta)\", \"-l*cos(thet)\"]\nforce = [\"F\", \"0\"]\n",
            "thet)",
            "did you mean",
        ),
    ];
    for (loads, at, says) in cases {
        let text = pendulum("", loads);
        let e = Scene::parse(&text, "bad.toml").expect_err(loads);
        let message = e.to_string();
        assert!(message.contains(says), "{loads}: {message}");
        assert_eq!(
            e.position(),
            Some(line_col(&text, at)),
            "{loads}: {message}"
        );
    }
    // An empty table, at the table.
    let text = pendulum("", "[[loads]]\n");
    let e = Scene::parse(&text, "bad.toml").expect_err("empty");
    assert!(e.to_string().contains("neither where nor what acts"), "{e}");
    assert_eq!(
        e.position().map(|p| p.0),
        Some(line_col(&text, "[[loads]]").0),
        "{e}"
    );
    // A key of neither kind, named by toml.
    let text = pendulum(
        "",
        "[[loads]]\npoint = [\"0\", \"0\"]\nforces = [\"1\", \"0\"]\n",
    );
    let e = Scene::parse(&text, "bad.toml").expect_err("unknown key");
    assert!(e.to_string().contains("forces"), "{e}");
}

#[test]
fn the_sensitivities_of_a_pushed_pendulum_see_the_parameters_of_the_point() {
    let asked = "[sensitivities]\nparameters = [\"l\", \"F\"]\n";
    let by_load = format!("{}{asked}", pendulum("", PUSH)).replace("t_end = 80.0", "t_end = 3.0");
    let by_hand = format!("{}{asked}", pendulum("forces = [\"F*l*cos(theta)\"]", ""))
        .replace("t_end = 80.0", "t_end = 3.0");
    let run = |text: &str| {
        let scene = Scene::parse(text, "loads.toml").unwrap_or_else(|e| panic!("{e}"));
        let o = scene.solve().unwrap_or_else(|e| panic!("{e}"));
        let s = o.sensitivities.clone().expect("asked for");
        s.values
            .into_iter()
            .map(<[f64]>::to_vec)
            .collect::<Vec<_>>()
    };
    let (a, b) = (run(&by_load), run(&by_hand));
    assert_eq!(a.len(), b.len());
    let last = a.len() - 1;
    // ∂θ/∂l at the end is far from zero, and the two agree on it and on the rest.
    assert!(a[last][0].abs() > 1e-3, "{:?}", a[last]);
    for (x, y) in a.iter().flatten().zip(b.iter().flatten()) {
        assert!((x - y).abs() < 1e-12, "{x} against {y}");
    }
}
