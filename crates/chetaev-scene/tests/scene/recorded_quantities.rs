//! Output quantities that read the recorded multipliers `mu_a` and Chetaev force `Phi_x`, against
//! the paper's closed form (42.40), (42.41).

use chetaev_scene::Scene;

/// The paper's projectile (Table 42.1, with other numbers) with output quantities of its own.
fn projectile(tables: &str, quantities: &str) -> String {
    format!(
        r#"
[parameters]
m = 2.0
g = 9.81
v0 = 7.0
h0 = 5.0

[model]
coordinates = ["x", "y"]
lagrangian = "0.5*m*(x_dot^2 + y_dot^2) - m*g*y"
constraints = ["x_dot^2 + y_dot^2 - v0^2"]

[initial]
q = [0.0, "h0"]
q_dot = ["v0", 0.0]

[solve]
method = "dop853"
t_end = 10.0
rtol = 1e-12
atol = 1e-12

[[events]]
name = "impact"
expression = "y"
direction = "falling"
terminal = true

[output]
times = {{ from = 0.0, to = "end", count = 41 }}
tables = {tables}

[output.quantities]
{quantities}
"#
    )
}

/// The columns of `quantities.csv` written for `text`, by name.
fn quantities(text: &str, dir: &str) -> Vec<(String, Vec<f64>)> {
    let scene = Scene::parse(text, "recorded.toml").unwrap_or_else(|e| panic!("{e}"));
    let out = scene.solve().unwrap_or_else(|e| panic!("{e}"));
    assert!(out.is_success(), "{:?}", out.status);
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(dir);
    let _ = std::fs::remove_dir_all(&dir);
    chetaev_scene::output::write(&scene, &out, &dir).unwrap_or_else(|e| panic!("{e}"));
    let table = std::fs::read_to_string(dir.join("quantities.csv")).expect("written");
    let mut lines = table.lines();
    let header: Vec<String> = lines
        .next()
        .expect("a header")
        .split(',')
        .map(String::from)
        .collect();
    let rows: Vec<Vec<f64>> = lines
        .map(|l| {
            l.split(',')
                .map(|v| v.parse().unwrap_or(f64::NAN))
                .collect()
        })
        .collect();
    header
        .into_iter()
        .enumerate()
        .map(|(j, name)| (name, rows.iter().map(|r| r[j]).collect()))
        .collect()
}

#[test]
fn a_quantity_overlays_the_computed_multiplier_on_the_closed_form() {
    // Only the quantities are asked for: μ and Φ are recorded because a quantity reads them.
    let text = projectile(
        r#"["quantities"]"#,
        r#"mu = "mu_1"
error = "mu_1 - (-(m*g/(2*v0))*tanh(g*t/v0))"
force_x = "Phi_x - 2*mu_1*x_dot"
force_y = "Phi_y - m*g*tanh(g*t/v0)^2""#,
    );
    let columns = quantities(&text, "recorded-quantities");
    let names: Vec<&str> = columns.iter().map(|c| c.0.as_str()).collect();
    assert_eq!(names, ["t", "mu", "error", "force_x", "force_y"]);
    let (m, g) = (2.0, 9.81);
    let scale = m * g;
    let mu = &columns[1].1;
    assert_eq!(mu.len(), 41);
    // μ < 0 while falling (42.40), and it is not 0 along the way: the comparison is not empty.
    assert!(mu[1..].iter().all(|&v| v < -1e-3 * scale), "{mu:?}");
    for (name, values) in &columns[2..] {
        let worst = values.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        assert!(worst < 1e-10 * scale, "{name}: {worst:e}");
    }
}

#[test]
fn a_multiplier_name_written_without_its_underscore_is_named_back() {
    let text = projectile(r#"["quantities"]"#, r#"mu = "mu1""#);
    let e = Scene::parse(&text, "recorded.toml").expect_err("unknown name");
    assert!(e.to_string().contains("did you mean 'mu_1'"), "{e}");
}

#[test]
fn the_multipliers_have_no_value_in_the_model_or_an_event() {
    let text = projectile(r#"["state"]"#, r#"speed = "x_dot""#)
        .replace(r#"expression = "y""#, r#"expression = "mu_1 + 1""#);
    let e = Scene::parse(&text, "recorded.toml").expect_err("unknown name");
    assert!(e.to_string().contains("unknown name 'mu_1'"), "{e}");
}
