//! The pictures a scene asks for: units in the axis labels (and after the summary's values), one
//! panel per unit, the trajectory's pairs of coordinates, and the located errors of the keys that
//! choose them.

use std::path::PathBuf;

use chetaev_scene::{output, Scene};

/// A particle in (x, y, z) under gravity along -z, held at constant speed, with an event at the
/// top of its flight and one that fires every π/10.
const BASE: &str = r#"
[parameters]
g = 10.0
[model]
coordinates = ["x", "y", "z"]
lagrangian = "0.5*(x_dot^2 + y_dot^2 + z_dot^2) - g*z"
constraints = ["x_dot^2 + y_dot^2 + z_dot^2 - 25"]
UNITS
[initial]
q = [0.0, 0.0, 5.0]
q_dot = [3.0, 0.0, 4.0]
[solve]
t_end = 1.0
rtol = 1e-9
atol = 1e-9
[[events]]
name = "top"
expression = "z_dot"
[[events]]
name = "tick"
expression = "sin(10*t)"
[output]
times = { count = 41 }
"#;

fn scene(units: &str, output: &str) -> Result<Scene, chetaev_scene::Error> {
    let text = format!("{}{output}\n", BASE.replace("UNITS", units));
    Scene::parse(&text, "pictures.toml")
}

/// Runs the scene and returns the SVG text of each picture, by file name.
fn pictures(units: &str, output: &str, tag: &str) -> Vec<(String, String)> {
    let s = scene(units, output).unwrap_or_else(|e| panic!("{e}\n{}", e.snippet().unwrap_or("")));
    let outcome = s.solve().expect("solves");
    assert!(outcome.is_success(), "{:?}", outcome.status);
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("pictures")
        .join(tag);
    let _ = std::fs::remove_dir_all(&dir);
    let written = output::write(&s, &outcome, &dir).expect("writes");
    written
        .iter()
        .filter(|f| f.extension().is_some_and(|x| x == "svg"))
        .map(|f| {
            let name = f.file_name().expect("name").to_string_lossy().into_owned();
            (name, std::fs::read_to_string(f).expect("readable"))
        })
        .collect()
}

fn picture<'a>(all: &'a [(String, String)], name: &str) -> &'a str {
    all.iter()
        .find(|(n, _)| n == name)
        .map(|(_, s)| s.as_str())
        .unwrap_or_else(|| panic!("no {name}"))
}

/// The texts of the elements of class `class` (axis labels: `x-label`, `y-label`).
fn texts(svg: &str, class: &str) -> Vec<String> {
    let marker = format!("class=\"{class}\"");
    svg.lines()
        .filter(|l| l.contains(&marker))
        .filter_map(|l| {
            let start = l.find('>')? + 1;
            let end = l.rfind("</")?;
            Some(l[start..end].to_string())
        })
        .collect()
}

fn frames(svg: &str) -> usize {
    svg.matches("class=\"frame\"").count()
}

#[test]
fn declared_units_appear_in_the_axis_labels() {
    let all = pictures(
        r#"units = { t = "s", coordinates = "m", mu = "kg/s", energy = "J" }"#,
        r#"pictures = ["state", "velocity", "acceleration", "multipliers", "force", "energy"]"#,
        "units",
    );
    let state = picture(&all, "state.svg");
    assert_eq!(texts(state, "x-label"), ["t [s]"]);
    assert_eq!(texts(state, "y-label"), ["x, y, z [m]"]);
    // Velocities and accelerations: a dot over the name, the unit per second.
    assert_eq!(
        texts(picture(&all, "velocity.svg"), "y-label"),
        ["x\u{307}, y\u{307}, z\u{307} [m/s]"]
    );
    assert_eq!(
        texts(picture(&all, "acceleration.svg"), "y-label"),
        ["x\u{308}, y\u{308}, z\u{308} [m/s²]"]
    );
    assert_eq!(
        texts(picture(&all, "multipliers.svg"), "y-label"),
        ["μ [kg/s]"]
    );
    assert_eq!(
        texts(picture(&all, "force.svg"), "y-label"),
        ["Φ_x, Φ_y, Φ_z [N]"]
    );
    // The energy's terms and its balance, each on its own axis, in joules.
    let energy = picture(&all, "energy.svg");
    assert_eq!(texts(energy, "y-label"), ["energy [J]", "balance [J]"]);
    assert_eq!(frames(energy), 2);
    assert_eq!(
        texts(energy, "x-label"),
        ["t [s]"],
        "one time axis, at the bottom"
    );

    // Nothing declared: names alone, no brackets; μ is unitless unless declared.
    let all = pictures(
        "",
        r#"pictures = ["state", "velocity", "multipliers"]"#,
        "no-units",
    );
    assert_eq!(texts(picture(&all, "state.svg"), "x-label"), ["t"]);
    assert_eq!(texts(picture(&all, "state.svg"), "y-label"), ["x, y, z"]);
    assert_eq!(
        texts(picture(&all, "velocity.svg"), "y-label"),
        ["x\u{307}, y\u{307}, z\u{307}"]
    );
    assert_eq!(texts(picture(&all, "multipliers.svg"), "y-label"), ["μ"]);
    // Units of the coordinates but not of time: no unit can be written for the velocities.
    let all = pictures(
        r#"units = { coordinates = "m" }"#,
        r#"pictures = ["velocity"]"#,
        "no-time-unit",
    );
    assert_eq!(
        texts(picture(&all, "velocity.svg"), "y-label"),
        ["x\u{307}, y\u{307}, z\u{307}"]
    );
}

#[test]
fn declared_units_follow_the_values_in_the_summary() {
    let printed = |units: &str| {
        let s = scene(units, r#"tables = ["state", "energy"]"#).expect("parses");
        let outcome = s.solve().expect("solves");
        output::summary(&s, &outcome)
    };
    let plain = printed("");
    let line = |text: &str, label: &str| {
        text.lines()
            .find(|l| l.trim_start().starts_with(label))
            .unwrap_or_else(|| panic!("no {label} line in\n{text}"))
            .to_string()
    };
    // Time in seconds, x and y in metres, z in kilometres (its own name wins), the energy in J.
    let with = printed(r#"units = { t = "s", coordinates = "m", z = "km", energy = "J" }"#);
    let status = line(&with, "status");
    assert!(status.ends_with(" s"), "{status}");
    let events = line(&with, "events");
    for unit in [" s,", " m,", " km,", " m/s,", " km/s"] {
        assert!(events.contains(unit), "{unit} in {events}");
    }
    assert!(line(&with, "energy").ends_with(" J"), "{with}");
    assert!(line(&with, "method").ends_with("to 1 s"), "{with}");
    // Without units, the same values alone: each line is the one with units, units taken out.
    let events_plain = line(&plain, "events");
    assert_eq!(
        events
            .replace(" km/s", "")
            .replace(" m/s", "")
            .replace(" km", "")
            .replace(" m", "")
            .replace(" s,", ","),
        events_plain
    );
    assert!(!events_plain.contains(" m"), "{events_plain}");
    // A unit declared empty shows nothing.
    let empty = printed(r#"units = { t = "", coordinates = "" }"#);
    assert_eq!(line(&empty, "events"), events_plain);
    assert!(!line(&plain, "energy").ends_with(" J"), "{plain}");
}

#[test]
fn different_units_never_share_an_axis() {
    // A coordinate with its own unit gets its own panel; the others share one.
    let all = pictures(
        r#"units = { t = "s", coordinates = "m", z = "km" }"#,
        r#"pictures = ["state", "velocity"]"#,
        "split",
    );
    let state = picture(&all, "state.svg");
    assert_eq!(frames(state), 2);
    assert_eq!(texts(state, "y-label"), ["x, y [m]", "z [km]"]);
    assert_eq!(texts(state, "x-label"), ["t [s]"]);
    assert_eq!(
        texts(picture(&all, "velocity.svg"), "y-label"),
        ["x\u{307}, y\u{307} [m/s]", "z\u{307} [km/s]"]
    );

    // Quantities: one panel per declared unit; one each for those without.
    let all = pictures(
        r#"units = { t = "s" }"#,
        r#"pictures = ["quantities"]
[output.quantities]
speed = "sqrt(x_dot^2 + y_dot^2 + z_dot^2)"
climb = "atan2(z_dot, x_dot)"
heading = "atan2(y_dot, x_dot)"
height = "z"
energy_ratio = "(0.5*z_dot^2)/12.5"
[output.units]
speed = "m/s"
climb = "rad"
heading = "rad""#,
        "quantities",
    );
    let q = picture(&all, "quantities.svg");
    assert_eq!(frames(q), 4);
    assert_eq!(
        texts(q, "y-label"),
        [
            "speed [m/s]",
            "climb, heading [rad]",
            "height",
            "energy_ratio"
        ]
    );
    assert_eq!(texts(q, "x-label"), ["t [s]"]);
}

#[test]
fn the_trajectory_draws_the_pairs_asked_for() {
    let units = r#"units = { t = "s", coordinates = "m" }"#;
    // One pair: one plot, z against x.
    let all = pictures(
        units,
        "pictures = [\"trajectory\"]\ntrajectory = [[\"x\", \"z\"]]",
        "pair",
    );
    let t = picture(&all, "trajectory.svg");
    assert_eq!(frames(t), 1);
    assert_eq!(texts(t, "x-label"), ["x [m]"]);
    assert_eq!(texts(t, "y-label"), ["z [m]"]);
    // Each event is one legend entry and one marker series, however often it fires.
    assert_eq!(t.matches(">top</text>").count(), 1);
    assert_eq!(t.matches(">tick</text>").count(), 1);
    let circles: Vec<usize> = t
        .split("class=\"markers\"")
        .skip(1)
        .map(|g| {
            g.split("</g>")
                .next()
                .unwrap_or("")
                .matches("<circle")
                .count()
        })
        .collect();
    // In the order they first fire: tick (at π/10, 2π/10, 3π/10; zero at the start, where it
    // is not reported), then top.
    assert_eq!(circles, [3, 1]);

    // By default with three coordinates: every pair, a panel each.
    let all = pictures(units, "pictures = [\"trajectory\"]", "default");
    let t = picture(&all, "trajectory.svg");
    assert_eq!(frames(t), 3);
    assert_eq!(texts(t, "x-label"), ["x [m]", "x [m]", "y [m]"]);
    assert_eq!(texts(t, "y-label"), ["y [m]", "z [m]", "z [m]"]);

    // Several pairs in one panel: one axis each way, a legend naming the curves.
    let all = pictures(
        units,
        "pictures = [\"trajectory\"]\ntrajectory = [[[\"x\", \"z\"], [\"y\", \"z\"]], [\"x\", \"y\"]]",
        "together",
    );
    let t = picture(&all, "trajectory.svg");
    assert_eq!(frames(t), 2);
    assert_eq!(texts(t, "x-label"), ["x, y [m]", "x [m]"]);
    assert_eq!(texts(t, "y-label"), ["z [m]", "y [m]"]);
    assert!(t.contains(">(x, z)</text>") && t.contains(">(y, z)</text>"));

    // Axes of different units are not drawn to equal scales, and show each unit.
    let all = pictures(
        r#"units = { coordinates = "m", z = "km" }"#,
        "pictures = [\"trajectory\"]\ntrajectory = [[\"x\", \"z\"]]",
        "mixed",
    );
    let t = picture(&all, "trajectory.svg");
    assert_eq!(texts(t, "y-label"), ["z [km]"]);
    assert!(t.contains("width=\"720\" height=\"450\""), "the full size");
}

#[test]
fn many_coordinates_default_to_the_first_two_with_a_note() {
    let text = r#"
[model]
coordinates = ["a", "b", "c", "d"]
lagrangian = "0.5*(a_dot^2 + b_dot^2 + c_dot^2 + d_dot^2) - b"
[initial]
q = [0.0, 0.0, 0.0, 0.0]
q_dot = [1.0, 1.0, 0.0, 0.0]
[solve]
t_end = 1.0
[output]
pictures = ["trajectory"]
"#;
    let s = Scene::parse(text, "four.toml").expect("valid");
    let outcome = s.solve().expect("solves");
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("pictures/four");
    let _ = std::fs::remove_dir_all(&dir);
    output::write(&s, &outcome, &dir).expect("writes");
    let t = std::fs::read_to_string(dir.join("trajectory.svg")).expect("written");
    assert_eq!(frames(&t), 1);
    assert_eq!(texts(&t, "x-label"), ["a"]);
    assert_eq!(texts(&t, "y-label"), ["b"]);
    let note = texts(&t, "note");
    assert_eq!(note.len(), 1);
    assert!(
        note[0].contains("first two of 4 coordinates") && note[0].contains("output.trajectory"),
        "{note:?}"
    );
}

/// The error of a scene that must not load: its message and the text at its position.
fn error(units: &str, output: &str) -> (String, String) {
    let text = format!("{}{output}\n", BASE.replace("UNITS", units));
    let e = Scene::parse(&text, "bad.toml").expect_err("invalid");
    let (line, column) = e.position().expect("located");
    let at: String = text
        .lines()
        .nth(line - 1)
        .expect("line")
        .chars()
        .skip(column - 1)
        .collect();
    (e.message(), at)
}

#[test]
fn trajectory_mistakes_are_located() {
    let (m, at) = error(
        "",
        "pictures = [\"trajectory\"]\ntrajectory = [[\"x\", \"w\"]]",
    );
    assert!(
        m.contains("'w' is not a coordinate") && m.contains("x, y, z"),
        "{m}"
    );
    assert!(at.starts_with("w\""), "{at}");

    let (m, at) = error(
        "",
        "pictures = [\"trajectory\"]\ntrajectory = [[\"t\", \"x\"]]",
    );
    assert!(m.contains("t is time"), "{m}");
    assert!(at.starts_with("t\""), "{at}");

    let (m, _) = error(
        "",
        "pictures = [\"trajectory\"]\ntrajectory = [[\"x\", \"y\", \"z\"]]",
    );
    assert!(
        m.contains("names two coordinates") && m.contains("names 3"),
        "{m}"
    );

    let (m, at) = error(
        "",
        "pictures = [\"trajectory\"]\ntrajectory = [[\"y\", \"y\"]]",
    );
    assert!(m.contains("against itself"), "{m}");
    assert!(at.starts_with("y\""), "{at}");

    // A pair not inside a list of panels.
    let (m, _) = error(
        "",
        "pictures = [\"trajectory\"]\ntrajectory = [\"x\", \"y\"]",
    );
    assert!(m.contains("alone is not a panel"), "{m}");

    let (m, _) = error("", "pictures = [\"trajectory\"]\ntrajectory = []");
    assert!(m.contains("no panel"), "{m}");

    // Pairs for a picture not asked for.
    let (m, at) = error("", "pictures = [\"state\"]\ntrajectory = [[\"x\", \"y\"]]");
    assert!(m.contains("does not ask for"), "{m}");
    assert!(at.starts_with("[[\"x\""), "{at}");
}

#[test]
fn unit_mistakes_are_located() {
    let (m, at) = error(r#"units = { t = "s", q = "m" }"#, "");
    assert!(
        m.contains("no unit can be given to 'q'") && m.contains("x, y, z"),
        "{m}"
    );
    assert!(at.starts_with("q ="), "{at}");

    let (m, at) = error(r#"units = { mu_2 = "kg/s" }"#, "");
    assert!(m.contains("'mu_2'") && m.contains("mu or mu_1"), "{m}");
    assert!(at.starts_with("mu_2"), "{at}");

    let (m, _) = error(r#"units = { t = "s\nm" }"#, "");
    assert!(m.contains("one line of text"), "{m}");

    let (m, at) = error(
        "",
        "[output.quantities]\nspeed = \"sqrt(x_dot^2)\"\n[output.units]\nsped = \"m/s\"",
    );
    assert!(
        m.contains("'sped' is not an output quantity") && m.contains("speed"),
        "{m}"
    );
    assert!(at.starts_with("sped"), "{at}");

    // No constraints, no multipliers to give a unit to.
    let text = BASE
        .replace("UNITS", r#"units = { mu = "kg/s" }"#)
        .replace("constraints = [\"x_dot^2 + y_dot^2 + z_dot^2 - 25\"]\n", "");
    let e = Scene::parse(&text, "free.toml").expect_err("no multipliers");
    assert!(e.message().contains("no constraints"), "{e}");
}

#[test]
fn units_given_reach_the_scene() {
    let s = scene(
        r#"units = { t = "s", coordinates = "m", z = "km", mu_1 = "kg/s", energy = "J" }"#,
        "[output.quantities]\nspeed = \"sqrt(x_dot^2)\"\nheight = \"z\"\n[output.units]\nspeed = \" m/s \"",
    )
    .expect("valid");
    let u = &s.units;
    assert_eq!(u.time.as_deref(), Some("s"));
    assert_eq!(
        u.coordinates,
        [Some("m".into()), Some("m".into()), Some("km".into())]
    );
    assert_eq!(u.multipliers, [Some("kg/s".to_string())]);
    assert_eq!(u.energy.as_deref(), Some("J"));
    assert_eq!(u.quantities, [Some("m/s".to_string()), None]);
}

/// The trajectory of a scene of one coordinate is the coordinate against t with its events marked,
/// not the state picture under another name.
#[test]
fn the_trajectory_of_one_coordinate_marks_its_events() {
    let text = r#"
[model]
coordinates = ["x"]
lagrangian = "0.5*x_dot^2 - 0.5*x^2"
[initial]
q = [0.0]
q_dot = [1.0]
[solve]
t_end = 10.0
[[events]]
name = "zero up"
expression = "x"
direction = "rising"
[output]
pictures = ["trajectory", "state"]
"#;
    let s = Scene::parse(text, "one.toml").unwrap_or_else(|e| panic!("{e}"));
    let outcome = s.solve().expect("solves");
    // x = sin t rises through 0 at 2π (zero at the start, where it is not reported).
    assert_eq!(outcome.events.len(), 1);
    assert!((outcome.events[0].t - 2.0 * std::f64::consts::PI).abs() < 1e-6);
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("pictures")
        .join("one-coordinate");
    let _ = std::fs::remove_dir_all(&dir);
    output::write(&s, &outcome, &dir).expect("writes");
    let read = |name: &str| std::fs::read_to_string(dir.join(name)).expect("written");
    let (trajectory, state) = (read("trajectory.svg"), read("state.svg"));
    assert!(trajectory.contains("zero up"), "the event is marked");
    assert!(!state.contains("zero up"));
    assert!(
        trajectory.contains(": trajectory"),
        "titled as the trajectory"
    );
}

#[test]
fn a_residual_that_is_zero_everywhere_says_so_over_the_whole_run() {
    // `ẋ = 1` holds exactly: every residual is 0, which a log axis cannot show. The picture used
    // to show an empty frame over t from 0 to 1, for a run to t = 2, with no word of why.
    let text = r#"
[model]
coordinates = ["x", "y"]
lagrangian = "0.5*(x_dot^2 + y_dot^2) - y"
constraints = ["x_dot - 1"]
[initial]
q = [0.0, 0.0]
q_dot = [1.0, 0.0]
[solve]
t_end = 2.0
[output]
times = { count = 5 }
pictures = ["residual"]
"#;
    let s = Scene::parse(text, "zero.toml").expect("parses");
    let outcome = s.solve().expect("solves");
    assert!(outcome.residual.iter().all(|f| f[0] == 0.0));
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("pictures")
        .join("zero-residual");
    let _ = std::fs::remove_dir_all(&dir);
    output::write(&s, &outcome, &dir).expect("writes");
    let svg = std::fs::read_to_string(dir.join("residual.svg")).expect("drawn");
    assert_eq!(
        texts(&svg, "note"),
        ["zero at every recorded point: nothing to draw on a log axis"]
    );
    assert!(svg.contains(">2.0</text>"), "{svg}");
}
