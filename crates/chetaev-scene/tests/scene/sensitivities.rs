//! `[sensitivities]`: derivatives of the motion and of the events with respect to a scene's
//! parameters, against the paper's closed forms differentiated by dual numbers and against the
//! Rust model's sensitivities.

use chetaev::num_dual::{Dual64, DualNum};
use chetaev::prelude::*;
use chetaev::EventSensitivity;
use chetaev_scene::{Outcome, Scene};
use uniform_projectile::closed_form::{uniform, Params};
use uniform_projectile::model::{impact, seeds, uniform_problem};

fn load(name: &str) -> Scene {
    let path = format!("{}/../../scenes/{name}", env!("CARGO_MANIFEST_DIR"));
    Scene::load(&path).unwrap_or_else(|e| panic!("{e}"))
}

fn solved(scene: &Scene) -> Outcome {
    let o = scene.solve().unwrap_or_else(|e| panic!("{e}"));
    assert!(
        matches!(o.status, Status::Terminated { event: 0 }),
        "{:?}",
        o.status
    );
    o
}

/// How the first event moved with each seed.
fn first_event(o: &Outcome) -> &EventSensitivity {
    let s = o.sensitivities.as_ref().expect("asked for");
    s.events[0]
        .as_ref()
        .expect("a smooth event, crossed transversally")
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

/// `dT/dθ` and `dR/dθ` of (42.38), `T = (v0/g) arccosh e^z`, `R = (v0²/g) arccos e^(−z)`,
/// `z = g h0/v0²`, for `θ` moving `(v0, g, h0)` at the rates `d`.
fn closed_form(p: &Params, d: [f64; 3]) -> (f64, f64) {
    let (t, r) = uniform::impact(
        Dual64::new(p.v0, d[0]),
        Dual64::new(p.g, d[1]),
        Dual64::new(p.h0, d[2]),
    );
    (t.eps, r.eps)
}

#[test]
fn impact_derivatives_match_the_closed_form_and_the_rust_model() {
    let scene = load("uniform-projectile-sensitivities.toml");
    let o = solved(&scene);
    let hit = first_event(&o);
    let p = Params::PAPER;

    // The Rust model with the same method, tolerances, event and seeds.
    let mut options = Options::until(10.0)
        .tolerances(1e-12, 1e-12)
        .event(impact())
        .sensitivity_control(true);
    for seed in seeds() {
        options = options.sensitivity(seed);
    }
    let rust = solve(
        &uniform_problem(&p).expect("problem"),
        Dop853::default(),
        &options,
    )
    .expect("solves");
    let rust_hit = rust
        .sensitivities
        .as_ref()
        .and_then(|s| s.events[0].clone())
        .expect("moved");

    let names = ["v0", "g", "h0"];
    assert_eq!(
        o.sensitivities.as_ref().map(|s| &s.names[..]),
        Some(&names.map(String::from)[..])
    );
    let (mut worst_closed, mut worst_rust) = (0.0f64, 0.0f64);
    for (j, theta) in names.iter().enumerate() {
        let mut d = [0.0; 3];
        d[j] = 1.0;
        let (dt, dr) = closed_form(&p, d);
        for (what, got, exact, rust) in [
            ("T", hit.t[j], dt, rust_hit.t[j]),
            ("R", hit.q[j][0], dr, rust_hit.q[j][0]),
        ] {
            let e = rel(got, exact);
            let r = rel(got, rust);
            eprintln!(
                "d{what}/d{theta}: scene {got:.15e}, closed form {exact:.15e} (rel {e:.1e}), Rust model rel {r:.1e}"
            );
            assert!(e < 1e-8, "d{what}/d{theta}: {got} vs {exact}, rel {e:e}");
            assert!(
                r < 1e-11,
                "d{what}/d{theta}: {got} vs Rust {rust}, rel {r:e}"
            );
            worst_closed = worst_closed.max(e);
            worst_rust = worst_rust.max(r);
        }
    }
    eprintln!("largest relative error: {worst_closed:.1e} against the closed form, {worst_rust:.1e} against the Rust model");
}

#[test]
fn initial_values_written_with_a_parameter_move_with_it() {
    let scene = load("uniform-projectile-sensitivities.toml");
    let spec = scene.sensitivities.as_ref().expect("asked for");
    assert!(spec.control);
    // q_dot = ["v0", 0.0]: ẋ(0) moves with v0, which the constraint reads.
    assert_eq!(
        spec.seeds[0],
        Seed::new("v0")
            .with_parameter("v0", 1.0)
            .with_velocity(0, 1.0)
    );
    assert_eq!(spec.seeds[1], Seed::new("g").with_parameter("g", 1.0));
    // q = [0.0, "h0"]: y(0) moves with h0, which nothing else reads.
    assert_eq!(spec.seeds[2], Seed::new("h0").with_position(1, 1.0));
    // Along the motion, ∂y/∂h0 = 1: the motion is shifted up with y(0).
    let o = solved(&scene);
    let s = o.sensitivities.as_ref().expect("asked for");
    assert_eq!(s.values.len(), o.t.len());
    for i in 0..o.t.len() {
        assert!((s.q(i, 2)[1] - 1.0).abs() < 1e-12, "{:?}", s.q(i, 2));
    }
}

/// The paper's scene with its data given through other parameters: `g = 2 gh`, `h0 = H/2`,
/// `v0 = sqrt(s)`.
const DERIVED: &str = r#"
[parameters]
m = 1.0
gh = 5.0
g = "2*gh"
H = 10.0
h0 = "H/2"
s = 100.0
v0 = "sqrt(s)"

[model]
coordinates = ["x", "y"]
lagrangian = "0.5*m*(x_dot^2 + y_dot^2) - m*g*y"
constraints = ["x_dot^2 + y_dot^2 - v0^2"]

[initial]
q = [0.0, "h0"]
q_dot = ["v0", 0.0]

[solve]
t_end = 10.0
rtol = 1e-12
atol = 1e-12

[[events]]
name = "impact"
expression = "y"
direction = "falling"
terminal = true

[sensitivities]
parameters = ["gh", "H", "s", "g"]
control = true
"#;

#[test]
fn parameters_computed_from_others_move_with_them() {
    let scene = Scene::parse(DERIVED, "derived.toml").unwrap_or_else(|e| panic!("{e}"));
    let spec = scene.sensitivities.as_ref().expect("asked for");
    // gh moves g at dg/dgh = 2; H moves y(0) at 1/2; s moves v0 and ẋ(0) at 1/(2 sqrt(s)).
    assert_eq!(spec.seeds[0], Seed::new("gh").with_parameter("g", 2.0));
    assert_eq!(spec.seeds[1], Seed::new("H").with_position(1, 0.5));
    assert_eq!(
        spec.seeds[2],
        Seed::new("s")
            .with_parameter("v0", 0.05)
            .with_velocity(0, 0.05)
    );
    // g asked for itself: moved with gh held.
    assert_eq!(spec.seeds[3], Seed::new("g").with_parameter("g", 1.0));

    let o = solved(&scene);
    let hit = first_event(&o);
    let p = Params::PAPER;
    let expected = [
        closed_form(&p, [0.0, 2.0, 0.0]),
        closed_form(&p, [0.0, 0.0, 0.5]),
        closed_form(&p, [0.05, 0.0, 0.0]),
        closed_form(&p, [0.0, 1.0, 0.0]),
    ];
    for (j, (dt, dr)) in expected.iter().enumerate() {
        let name = &spec.parameters[j];
        assert!(
            rel(hit.t[j], *dt) < 1e-8,
            "dT/d{name}: {} vs {dt}",
            hit.t[j]
        );
        assert!(
            rel(hit.q[j][0], *dr) < 1e-8,
            "dR/d{name}: {} vs {dr}",
            hit.q[j][0]
        );
    }
}

/// `DERIVED` with `from` replaced by `to`.
fn edited(from: &str, to: &str) -> String {
    assert!(DERIVED.contains(from), "{from}");
    DERIVED.replacen(from, to, 1)
}

fn error_of(text: &str) -> chetaev_scene::Error {
    match Scene::parse(text, "bad.toml") {
        Ok(scene) => scene.check().expect_err("refused"),
        Err(e) => e,
    }
}

/// The line of `text` that holds `needle`, counted from 1.
fn line_of(text: &str, needle: &str) -> usize {
    text.lines()
        .position(|l| l.contains(needle))
        .map(|i| i + 1)
        .expect("present")
}

#[test]
fn a_name_that_is_not_a_parameter_is_refused_at_its_place() {
    let text = edited(
        r#"parameters = ["gh", "H", "s", "g"]"#,
        r#"parameters = ["gh", "HH", "s"]"#,
    );
    let e = error_of(&text);
    let line = line_of(&text, r#"parameters = ["gh""#);
    let column = text
        .lines()
        .nth(line - 1)
        .and_then(|l| l.find("HH"))
        .expect("there")
        + 1;
    assert_eq!(e.position(), Some((line, column)), "{e}");
    assert!(e.message().contains("'HH' is not a parameter"), "{e}");
    assert!(e.message().contains("did you mean 'H'?"), "{e}");
    assert!(e.snippet().is_some_and(|s| s.contains("^^")), "{e}");

    // A coordinate: told how to differentiate with respect to an initial value.
    let e = error_of(&edited(r#""gh", "H", "s", "g""#, r#""x""#));
    assert!(e.message().contains("make it a parameter"), "{e}");
}

#[test]
fn other_mistakes_under_sensitivities_are_located_and_explained() {
    let cases: [(String, &str, &str); 7] = [
        (
            edited("control = true", "contol = true"),
            "contol",
            "unknown field `contol`",
        ),
        (
            edited(r#""gh", "H", "s", "g""#, r#""gh", "gh""#),
            "parameters = [",
            "listed twice",
        ),
        (
            edited(r#""gh", "H", "s", "g""#, ""),
            "parameters = [",
            "lists no parameter",
        ),
        (
            // m enters the Lagrangian as a factor of both terms, but is read; a parameter that
            // nothing uses is refused.
            edited("m = 1.0", "m = 1.0\nunused = 2.0").replacen(
                r#""gh", "H""#,
                r#""unused", "H""#,
                1,
            ),
            "parameters = [",
            "does not depend on 'unused'",
        ),
        (
            edited(
                "q_dot = [\"v0\", 0.0]",
                "q_dot = [\"v0\", 0.0]\nproject_velocity = true",
            ),
            "parameters = [",
            "project_velocity",
        ),
        (
            edited("atol = 1e-12", "atol = 1e-12\nprojection = true"),
            "parameters = [",
            "projection = true",
        ),
        (
            // ẋ(0) written as a number: moving s (and so v0) leaves it off the constraint.
            edited("q_dot = [\"v0\", 0.0]", "q_dot = [10.0, 0.0]"),
            "q_dot = [10.0",
            "moves the initial state off constraint 1",
        ),
    ];
    for (text, at, says) in cases {
        let e = error_of(&text);
        assert_eq!(
            e.position().map(|p| p.0),
            Some(line_of(&text, at)),
            "{says}: {e}"
        );
        assert!(e.message().contains(says), "{says}: {e}");
    }
    // The table without [sensitivities].
    let text = load_text("uniform-projectile.toml").replacen(
        r#""events"]"#,
        r#""events", "sensitivities"]"#,
        1,
    );
    let e = error_of(&text);
    assert!(e.message().contains("needs the parameters"), "{e}");
    assert_eq!(
        e.position().map(|p| p.0),
        Some(line_of(&text, "\"sensitivities\""))
    );
}

fn load_text(name: &str) -> String {
    let path = format!("{}/../../scenes/{name}", env!("CARGO_MANIFEST_DIR"));
    std::fs::read_to_string(path).expect("scene")
}

#[test]
fn without_sensitivities_nothing_is_carried() {
    let scene = load("uniform-projectile.toml");
    assert!(scene.sensitivities.is_none());
    let o = solved(&scene);
    assert!(o.sensitivities.is_none());
}

#[test]
fn uncontrolled_sensitivities_leave_the_motion_as_it_was() {
    // With control = false the steps are the motion's alone, and the parameters kept for the
    // derivatives evaluate to the same numbers as the folded ones.
    let plain = solved(&load("uniform-projectile.toml"));
    let text = load_text("uniform-projectile-sensitivities.toml").replacen(
        "control = true",
        "control = false",
        1,
    );
    let with = solved(&Scene::parse(&text, "uncontrolled.toml").unwrap_or_else(|e| panic!("{e}")));
    assert_eq!(plain.events[0].t, with.events[0].t);
    assert_eq!(plain.events[0].q, with.events[0].q);
    assert_eq!(plain.stats.accepted_steps, with.stats.accepted_steps);
    // Still exact to the method's accuracy.
    let hit = first_event(&with);
    let (dt, _) = closed_form(&Params::PAPER, [1.0, 0.0, 0.0]);
    assert!(rel(hit.t[0], dt) < 1e-8, "{} vs {dt}", hit.t[0]);
}

#[test]
fn an_event_that_reads_a_parameter_moves_with_it() {
    // The sled of docs/scenes.md: two constraints, one of them time-dependent, and the event
    // 'heading 45 degrees' reads alpha. Its time has a closed form,
    // T45 = (v0/a) (tan(π/8)^(−a/(g sin α)) − 1), differentiated here by dual numbers.
    let text = load_text("your-own-constraint.toml")
        + "\n[sensitivities]\nparameters = [\"alpha\", \"a\", \"g\", \"v0\"]\ncontrol = true\n";
    let scene = Scene::parse(&text, "sled.toml").unwrap_or_else(|e| panic!("{e}"));
    let o = scene.solve().unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(o.event_name(o.events[0].index), "heading 45 degrees");
    let hit = first_event(&o);
    let value = |name: &str| {
        scene
            .parameters
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| *v)
            .expect("a parameter")
    };
    for (j, name) in ["alpha", "a", "g", "v0"].iter().enumerate() {
        let d = |n: &str| Dual64::new(value(n), if n == *name { 1.0 } else { 0.0 });
        let (alpha, a, g, v0) = (d("alpha"), d("a"), d("g"), d("v0"));
        let base = Dual64::from(std::f64::consts::FRAC_PI_8.tan());
        let t45 = v0 / a * ((-a / (g * alpha.sin()) * base.ln()).exp() - 1.0);
        let e = rel(hit.t[j], t45.eps);
        assert!(
            e < 1e-7,
            "dT45/d{name}: {} vs {}, rel {e:e}",
            hit.t[j],
            t45.eps
        );
    }
}

#[test]
fn the_command_writes_the_sensitivities_and_lists_them() {
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("sensitivities-cli");
    let _ = std::fs::remove_dir_all(&dir);
    let scene = format!(
        "{}/../../scenes/uniform-projectile-sensitivities.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_chetaev"))
        .args(["run", &scene, "--out"])
        .arg(&dir)
        .output()
        .expect("the binary runs");
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert_eq!(o.status.code(), Some(0), "{stdout}");
    assert!(
        stdout.contains("  d/dp     impact  dT/dv0 = -0.01727280530"),
        "{stdout}"
    );
    let read = |name: &str| std::fs::read_to_string(dir.join(name)).expect(name);
    let table = read("sensitivities.csv");
    let header = table.lines().next().expect("a header");
    assert!(header.starts_with("t,d(x)/d(v0),d(y)/d(v0),d(x_dot)/d(v0),d(y_dot)/d(v0),d(x)/d(g)"));
    // Then those of the multiplier and of the Chetaev force, for each parameter in turn.
    assert!(header.ends_with(
        ",d(mu_1)/d(v0),d(mu_1)/d(g),d(mu_1)/d(h0),d(Phi_x)/d(v0),d(Phi_y)/d(v0),d(Phi_x)/d(g),\
         d(Phi_y)/d(g),d(Phi_x)/d(h0),d(Phi_y)/d(h0)"
    ));
    assert_eq!(header.split(',').count(), 1 + 3 * 4 + 3 * (1 + 2));
    assert_eq!(table.lines().count(), 1 + 101);
    // The first row: y(0) = h0 moves with h0, x_dot(0) = v0 with v0; μ(0) = 0 for every v0, g,
    // h0 (42.40), and so Φ(0) = 2μ(0)q̇(0).
    assert_eq!(
        table.lines().nth(1),
        Some("0,0,0,1,0,0,0,0,0,0,1,0,0,0,0,0,0,0,0,0,0,0")
    );
    let events = read("events.csv");
    let header = events.lines().next().expect("a header");
    assert!(header.contains(",d(t)/d(v0),d(x)/d(v0),"), "{header}");
    assert_eq!(header.split(',').count(), 6 + 3 * 5);
    let row: Vec<&str> = events
        .lines()
        .nth(1)
        .expect("the impact")
        .split(',')
        .collect();
    assert_eq!(row.len(), 6 + 3 * 5);
    let dt_dv0: f64 = row[6].parse().expect("a number");
    assert!(
        (dt_dv0 + 0.017_272_805_304_873_35).abs() < 1e-12,
        "{dt_dv0}"
    );
    assert!(read("manifest.toml").contains("\"sensitivities.csv\""));
}

#[test]
fn a_long_chain_of_parameters_carries_its_rate_in_linear_time() {
    // p1 = 1, p_i = 1.5 p_(i−1) − 0.5 p_(i−1) (= p_(i−1)): the rate of p_n with respect to p1 is 1,
    // found in one pass; the expressions stay as written, whatever the length of the chain.
    let n = 20_000;
    let mut text = String::from("[parameters]\np1 = 1.0\n");
    for i in 2..=n {
        text.push_str(&format!("p{i} = \"1.5*p{j} - 0.5*p{j}\"\n", j = i - 1));
    }
    text.push_str(&format!(
        "[model]\ncoordinates = [\"x\"]\nlagrangian = \"0.5*x_dot^2 - p{n}*x\"\n[initial]\n\
         q = [0.0]\nq_dot = [0.0]\n[solve]\nt_end = 1.0\n[sensitivities]\nparameters = [\"p1\"]\n"
    ));
    let scene = Scene::parse(&text, "chain.toml").unwrap_or_else(|e| panic!("{e}"));
    let spec = scene.sensitivities.as_ref().expect("asked for");
    assert_eq!(
        spec.seeds[0],
        Seed::new("p1").with_parameter(&format!("p{n}"), 1.0)
    );
}

#[test]
fn a_holonomic_constraint_moves_with_its_parameter_when_the_initial_position_does() {
    // The pendulum on a rod x² + y² = l², from the angle theta0: the time to the lowest point is
    // a quarter period, proportional to sqrt(l/g) at a fixed amplitude, so
    // dT/dl = T/(2l) and dT/dg = −T/(2g).
    let text = load_text("cartesian-pendulum.toml")
        + "\n[sensitivities]\nparameters = [\"l\", \"g\"]\ncontrol = true\n";
    let scene = Scene::parse(&text, "pendulum.toml").unwrap_or_else(|e| panic!("{e}"));
    let o = scene.solve().unwrap_or_else(|e| panic!("{e}"));
    let t = o.events[0].t;
    let hit = first_event(&o);
    let (l, g) = (2.0, 9.81);
    assert!(
        rel(hit.t[0], t / (2.0 * l)) < 1e-7,
        "{} vs {}",
        hit.t[0],
        t / (2.0 * l)
    );
    assert!(
        rel(hit.t[1], -t / (2.0 * g)) < 1e-7,
        "{} vs {}",
        hit.t[1],
        -t / (2.0 * g)
    );

    // The initial position written as numbers does not move with l: refused at initial.q.
    let fixed = text.replacen(
        r#"q = ["l*sin(theta0)", "-l*cos(theta0)"]"#,
        r#"q = ["2*sin(theta0)", "-2*cos(theta0)"]"#,
        1,
    );
    assert_ne!(fixed, text);
    let e = Scene::parse(&fixed, "pendulum.toml").expect_err("refused");
    assert_eq!(
        e.position().map(|p| p.0),
        Some(line_of(&fixed, "q = [\"2*sin")),
        "{e}"
    );
    assert!(
        e.message().contains("off the holonomic constraint 1"),
        "{e}"
    );
}
