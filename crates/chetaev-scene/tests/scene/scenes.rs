//! Every scene in `scenes/` runs; only what a scene asks for is computed; any number of
//! coordinates runs, and more constraints than coordinates is a located error.

use std::path::PathBuf;

use chetaev::prelude::{Record, Status};
use chetaev_scene::{output, Scene};

fn scenes_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
}

#[test]
fn every_scene_file_checks_runs_and_writes_what_it_asks_for() {
    let mut files: Vec<PathBuf> = std::fs::read_dir(scenes_dir())
        .expect("scenes/")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    files.sort();
    assert!(files.len() >= 3, "{files:?}");
    for path in files {
        let scene =
            Scene::load(&path).unwrap_or_else(|e| panic!("{e}\n{}", e.snippet().unwrap_or("")));
        scene.check().unwrap_or_else(|e| panic!("{e}"));
        let outcome = scene.solve().unwrap_or_else(|e| panic!("{e}"));
        assert!(
            outcome.is_success(),
            "{}: {:?}",
            path.display(),
            outcome.status
        );
        let stem = path
            .file_stem()
            .expect("stem")
            .to_string_lossy()
            .into_owned();
        let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
            .join("scenes")
            .join(&stem);
        let _ = std::fs::remove_dir_all(&dir);
        let written = output::write(&scene, &outcome, &dir).expect("writes");
        assert_eq!(
            written.len(),
            scene.output.tables.len() + scene.output.pictures.len(),
            "{stem}"
        );
        for f in &written {
            let text = std::fs::read_to_string(f).expect("readable");
            assert!(!text.contains("NaN"), "{}", f.display());
            if f.extension().is_some_and(|x| x == "csv") {
                let mut lines = text.lines();
                let width = lines.next().expect("header").split(',').count();
                assert!(
                    lines.all(|l| l.split(',').count() == width),
                    "{}",
                    f.display()
                );
            } else {
                assert!(text.contains("<svg"), "{}", f.display());
            }
        }
        let summary = output::summary(&scene, &outcome);
        assert!(summary.contains("status"), "{summary}");
    }
}

const BASE: &str = r#"
[parameters]
g = 10.0
v0 = 10.0
[model]
coordinates = ["x", "y"]
lagrangian = "0.5*(x_dot^2 + y_dot^2) - g*y"
constraints = ["x_dot^2 + y_dot^2 - v0^2"]
[initial]
q = [0.0, 5.0]
q_dot = ["v0", 0.0]
[solve]
t_end = 0.5
rtol = 1e-9
atol = 1e-9
"#;

/// The line number (from 1) of the first line of `text` that starts with `prefix`, where an
/// error about that key should point.
fn line_of(text: &str, prefix: &str) -> usize {
    text.lines()
        .position(|l| l.starts_with(prefix))
        .unwrap_or_else(|| panic!("no line starts with {prefix}"))
        + 1
}

fn with_output(output: &str) -> Scene {
    Scene::parse(&format!("{BASE}\n[output]\n{output}\n"), "base.toml")
        .unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn only_what_is_asked_for_is_recorded() {
    // Nothing asked: the start and the end only, no diagnostics, no output evaluations.
    let o = Scene::parse(BASE, "base.toml")
        .expect("parses")
        .solve()
        .expect("solves");
    assert_eq!(o.t.len(), 2);
    assert_eq!(o.record, Record::State);
    assert!(o.mu.is_empty() && o.energy.is_empty() && o.work.is_empty());
    assert_eq!(o.stats.output_evaluations, 0);

    let s = with_output("tables = [\"state\", \"events\"]");
    assert_eq!(s.record(), Record::State);
    let o = s.solve().expect("solves");
    assert!(o.t.len() > 2 && o.mu.is_empty() && o.qdd.is_empty());
    assert_eq!(o.stats.output_evaluations, 0);

    let s = with_output("tables = [\"multipliers\"]");
    assert_eq!(s.record(), Record::Dynamics);
    let o = s.solve().expect("solves");
    assert_eq!(o.mu.len(), o.t.len());
    assert!(o.work.is_empty());

    let s = with_output("pictures = [\"energy\"]\ntimes = [0.1, 0.2, 0.3]");
    assert_eq!(s.record(), Record::Energy);
    let o = s.solve().expect("solves");
    assert_eq!(o.t, vec![0.0, 0.1, 0.2, 0.3, 0.5]);
    assert_eq!(o.work.len(), 5);

    // Listed times may be constant expressions of the parameters, as the grid's ends may.
    let o = with_output("tables = [\"state\"]\ntimes = [\"1/g\", 0.2, \"3*v0/100\"]")
        .solve()
        .expect("solves");
    assert_eq!(o.t, vec![0.0, 0.1, 0.2, 0.3, 0.5]);
    let e = Scene::parse(
        &format!("{BASE}\n[output]\ntimes = [\"x/g\"]\n"),
        "base.toml",
    )
    .expect_err("not a constant");
    assert!(
        e.to_string()
            .contains("'x' is a coordinate, which has no value here"),
        "{e}"
    );

    // An explicit grid to a time: one integration.
    let o = with_output("tables = [\"state\"]\ntimes = { from = 0.0, to = 0.4, count = 5 }")
        .solve()
        .expect("solves");
    assert_eq!(o.passes, 1);
    assert_eq!(o.t, vec![0.0, 0.1, 0.2, 0.30000000000000004, 0.4, 0.5]);
}

#[test]
fn tables_about_constraints_need_constraints() {
    let text = format!(
        "{}\n[output]\ntables = [\"state\", \"multipliers\"]\n",
        BASE.replace("constraints = [\"x_dot^2 + y_dot^2 - v0^2\"]\n", "",)
    );
    let e = Scene::parse(&text, "free.toml").expect_err("no multipliers");
    assert!(e.to_string().contains("no constraints"), "{e}");
    let e = Scene::parse(
        &format!("{BASE}\n[output]\npictures = [\"quantities\"]\n"),
        "q.toml",
    )
    .expect_err("no quantities");
    assert!(e.to_string().contains("[output.quantities]"), "{e}");
}

/// A scene with `n` coordinates `q1..qn` and `k` constraints `qa_dot = 1`.
fn sized(n: usize, k: usize) -> String {
    let names: Vec<String> = (1..=n).map(|i| format!("\"q{i}\"")).collect();
    let kinetic: Vec<String> = (1..=n).map(|i| format!("q{i}_dot^2")).collect();
    let constraints: Vec<String> = (1..=k).map(|a| format!("\"q{a}_dot - 1\"")).collect();
    let ones = vec!["1.0"; n].join(", ");
    let zeros = vec!["0.0"; n].join(", ");
    format!(
        "[model]\ncoordinates = [{}]\nlagrangian = \"0.5*({}) - q{n}\"\nconstraints = [{}]\n\
         [initial]\nq = [{zeros}]\nq_dot = [{ones}]\n[solve]\nt_end = 1.0\n",
        names.join(", "),
        kinetic.join(" + "),
        constraints.join(", ")
    )
}

#[test]
fn any_size_runs() {
    // Every K for N up to 8, and a few larger N: sizes are read from the scene, not compiled in.
    let sizes =
        (1..=8)
            .flat_map(|n| (0..=n).map(move |k| (n, k)))
            .chain([(12, 0), (12, 5), (20, 1)]);
    for (n, k) in sizes {
        let scene =
            Scene::parse(&sized(n, k), "sized.toml").unwrap_or_else(|e| panic!("{n} {k}: {e}"));
        assert_eq!((scene.n(), scene.k()), (n, k));
        scene.check().unwrap_or_else(|e| panic!("{n} {k}: {e}"));
        let o = scene.solve().unwrap_or_else(|e| panic!("{n} {k}: {e}"));
        assert!(o.is_success(), "{n} {k}: {:?}", o.status);
        // q_n falls freely unless held: q_n(1) = 1 - 1/2 when unconstrained, 1 when held.
        let q = &o.q[1];
        let want = if k >= n { 1.0 } else { 0.5 };
        assert!((q[n - 1] - want).abs() < 1e-9, "{n} {k}: {q:?}");
    }
}

#[test]
fn impossible_sizes_are_located_errors() {
    let e = Scene::parse(&sized(2, 3), "over.toml").expect_err("K > N");
    assert_eq!(e.position().map(|p| p.0), Some(4), "{e}");
    assert!(
        e.to_string().contains("3 constraints on 2 coordinates"),
        "{e}"
    );
    assert!(e.to_string().contains("K ≤ N"), "{e}");
    let none = "[model]\ncoordinates = []\nlagrangian = \"1\"\n[initial]\nq = []\nq_dot = []\n\
                [solve]\nt_end = 1.0\n";
    let e = Scene::parse(none, "none.toml").expect_err("N = 0");
    assert_eq!(e.position(), Some((2, 15)), "{e}");
    assert!(e.to_string().contains("at least one"), "{e}");
}

#[test]
fn an_inconsistent_initial_velocity_points_at_q_dot_and_says_what_to_try() {
    let text = BASE.replace("q_dot = [\"v0\", 0.0]", "q_dot = [\"v0\", 1.0]");
    let scene = Scene::parse(&text, "bad.toml").expect("parses");
    let e = scene.check().expect_err("inconsistent");
    let line = line_of(&text, "q_dot");
    assert_eq!(e.position().map(|p| p.0), Some(line), "{e}");
    assert!(e.to_string().contains("project_velocity = true"), "{e}");
    // Opting in projects the velocity and runs.
    let text = text.replace("[solve]", "project_velocity = true\n[solve]");
    let o = Scene::parse(&text, "fixed.toml")
        .expect("parses")
        .solve()
        .expect("solves");
    assert!(o.is_success());
    assert!((o.qd[0][0].hypot(o.qd[0][1]) - 10.0).abs() < 1e-12);
    // The summary says from what to what.
    let scene = Scene::parse(&text, "fixed.toml").expect("parses");
    let summary = output::summary(&scene, &o);
    let n = output::summary_number;
    let want = format!(
        "  initial  q_dot projected onto f = 0 (project_velocity = true): x_dot 10 → {} ({}), y_dot 1 → {} ({})\n",
        n(o.qd[0][0]),
        n(o.qd[0][0] - 10.0),
        n(o.qd[0][1]),
        n(o.qd[0][1] - 1.0)
    );
    assert!(summary.contains(&want), "{summary}");
    // A consistent velocity is left as it is, and the summary says so.
    let consistent = BASE.replace("[solve]", "project_velocity = true\n[solve]");
    let scene = Scene::parse(&consistent, "kept.toml").expect("parses");
    let o = scene.solve().expect("solves");
    assert!(output::summary(&scene, &o).contains("changed nothing"));
}

#[test]
fn a_failed_integration_keeps_the_motion_computed() {
    // Two steps do not reach t_end = 0.5 at this tolerance.
    let text = BASE.replace("atol = 1e-9", "atol = 1e-9\nmax_steps = 2");
    let scene = Scene::parse(
        &format!("{text}\n[output]\ntables = [\"state\"]\n"),
        "short.toml",
    )
    .expect("parses");
    let o = scene.solve().expect("setup is fine");
    assert!(!o.is_success());
    assert_eq!(o.t.len(), 3, "{:?}", o.t);
    let summary = output::summary(&scene, &o);
    let Status::Failed(chetaev::Error::MaxSteps { t, .. }) = &o.status else {
        panic!("{:?}", o.status)
    };
    assert!(
        summary.contains(&format!(
            "  status   FAILED at t = {}: the step limit of 2 steps was reached\n",
            output::summary_number(*t)
        )),
        "{summary}"
    );
    assert!(
        summary.contains("  advice   raise max_steps under [solve] (now 2)"),
        "{summary}"
    );

    // A fixed-step method has no tolerances to loosen: the advice is its step.
    let fixed = BASE.replace(
        "rtol = 1e-9\natol = 1e-9",
        "method = \"rk4\"\nstep = 0.01\nmax_steps = 2",
    );
    let fixed = Scene::parse(&fixed, "fixed.toml").expect("parses");
    let o = fixed.solve().expect("setup is fine");
    let summary = output::summary(&fixed, &o);
    assert!(
        summary.contains(
            "  advice   raise max_steps under [solve] (now 2), or take a larger step (now step = \
             0.01)"
        ),
        "{summary}"
    );
    assert!(!summary.contains("rtol"), "{summary}");

    // Stiffness is told as the method key to write.
    let stiff = output::failure(
        &scene,
        &chetaev::Error::Stiff {
            t: 0.25,
            h_lambda: 3.3,
            suggestion: "Rodas4",
        },
    );
    assert_eq!(stiff.t, Some(0.25));
    assert!(
        stiff
            .advice
            .starts_with("set method = \"rodas4\" under [solve]"),
        "{stiff:?}"
    );
    assert!(
        stiff
            .advice
            .contains("method = \"dop853\" with stiffness_detection = false"),
        "{stiff:?}"
    );
}

#[test]
fn every_method_solves_the_paper_scene() {
    let uniform =
        std::fs::read_to_string(scenes_dir().join("uniform-projectile.toml")).expect("scene");
    let t_exact = 0.5f64.exp().acosh(); // (42.38), v0 = g

    // Every method the library offers, by its name, so that a new method is covered here too.
    for m in chetaev::integrate::AnyMethod::all(0.001) {
        let info = chetaev::integrate::Method::info(&m);
        let method = info.name.to_lowercase();
        let extra = if info.fixed_step.is_some() {
            "step = 0.001"
        } else {
            ""
        };
        let tol = if info.needs_jacobian { 1e-8 } else { 1e-10 };
        // A fixed-step method has no error control, and refuses tolerances.
        let tolerances = if info.fixed_step.is_some() {
            ""
        } else {
            "rtol = 1e-10\natol = 1e-12"
        };
        let text = uniform
            .replace(
                "method = \"dop853\"",
                &format!("method = \"{method}\"\n{extra}"),
            )
            .replace("rtol = 1e-12\natol = 1e-12", tolerances);
        let scene = Scene::parse(&text, "methods.toml").unwrap_or_else(|e| panic!("{method}: {e}"));
        let o = scene.solve().unwrap_or_else(|e| panic!("{method}: {e}"));
        assert!(o.is_success(), "{method}: {:?}", o.status);
        assert_eq!(o.method.to_lowercase(), method);
        assert!(
            (o.events[0].t - t_exact).abs() < tol,
            "{method}: {}",
            o.events[0].t
        );
        assert_eq!(
            o.stats.jacobian_evaluations > 0,
            info.needs_jacobian,
            "{method}"
        );
    }
    let text = uniform.replace("method = \"dop853\"", "method = \"rk4\"");
    let e = Scene::parse(&text, "rk4.toml").expect_err("no step");
    assert!(e.to_string().contains("add `step = ...`"), "{e}");
    let text = uniform.replace("method = \"dop853\"", "method = \"dopri5\"\nstep = 0.1");
    let e = Scene::parse(&text, "step.toml").expect_err("step with dopri5");
    assert!(e.to_string().contains("fixed step of rk4"), "{e}");
}

#[test]
fn stiffness_detection_sets_the_test_of_the_methods_that_have_one() {
    use chetaev::prelude::{AnyMethod, Dop853, Dopri5, StiffnessDetection, Tsit5};
    let method = |m: &str, extra: &str| {
        let text = BASE.replace(
            "t_end = 0.5",
            &format!("t_end = 0.5\nmethod = \"{m}\"\n{extra}"),
        );
        Scene::parse(&text, "stiff.toml").map(|s| s.solve.method)
    };
    assert_eq!(
        method("dop853", "stiffness_detection = false").expect("valid"),
        AnyMethod::Dop853(Dop853 {
            stiffness: StiffnessDetection::OFF
        })
    );
    assert_eq!(
        method("dopri5", "stiffness_detection = false").expect("valid"),
        AnyMethod::Dopri5(Dopri5 {
            stiffness: StiffnessDetection::OFF
        })
    );
    assert_eq!(
        method("dopri5", "").expect("valid"),
        AnyMethod::Dopri5(Dopri5::default())
    );
    assert_eq!(
        method("tsit5", "stiffness_detection = false").expect("valid"),
        AnyMethod::Tsit5(Tsit5 {
            stiffness: StiffnessDetection::OFF
        })
    );
    for m in ["rodas4", "rodas5p"] {
        let e = method(m, "stiffness_detection = false").expect_err("no stiffness test");
        assert!(
            e.to_string()
                .contains("applies to dopri5, dop853, tsit5 only"),
            "{m}: {e}"
        );
    }
}

#[test]
fn the_longest_expression_allowed_evaluates_with_every_dual_type() {
    // 100,000 tokens less one in one sum, differentiated by the implicit method's nested dual
    // numbers, on a test thread's stack: a long sum is one node of the tree, so its length costs
    // no depth.
    let kinetic: Vec<String> = (1..=6).map(|i| format!("0.5*q{i}_dot^2")).collect();
    // 6 terms of 5 tokens, 5 pluses, then 24,991 terms of 4 tokens: 99,999 tokens.
    let terms = 24_991;
    let l = format!("{}{}", kinetic.join(" + "), " - 0.001*q6".repeat(terms));
    let names: Vec<String> = (1..=6).map(|i| format!("\"q{i}\"")).collect();
    let text = format!(
        "[model]\ncoordinates = [{}]\nlagrangian = \"{l}\"\nconstraints = [\"q1_dot - 1\", \"q2_dot^2 + q3_dot^2 - 1\"]\n\
         [initial]\nq = [0, 0, 0, 0, 0, 0]\nq_dot = [1, 1, 0, 0, 0, 0]\n[solve]\nmethod = \"rodas4\"\nt_end = 1.0\n",
        names.join(", ")
    );
    let scene = Scene::parse(&text, "long.toml").unwrap_or_else(|e| panic!("{e}"));
    let o = scene.solve().expect("solves");
    assert!(o.is_success(), "{:?}", o.status);
    // A constant force −0.001 · terms along q6: q6(1) = −0.0005 · terms.
    let q6 = o.q.last().expect("points")[5];
    assert!((q6 + 0.0005 * terms as f64).abs() < 1e-12, "{q6}");
    // One more term is too long.
    let longer = text.replace(" - 0.001*q6\"", " - 0.001*q6 - 0.001*q6\"");
    match Scene::parse(&longer, "longer.toml") {
        Ok(_) => panic!("100,003 tokens accepted"),
        Err(e) => assert!(
            e.to_string()
                .contains("100003 numbers, names and operators"),
            "{e}"
        ),
    }
}

#[test]
fn a_fixed_step_method_refuses_the_options_it_would_ignore() {
    // rk4 takes every step of size `step` and has no error control: tolerances and a first step
    // would be ignored, so they are refused at their place, saying what to use instead.
    let rk4 = BASE.replace("rtol = 1e-9\natol = 1e-9", "method = \"rk4\"\nstep = 0.01");
    assert!(
        rk4.contains("step = 0.01") && !rk4.contains("rtol"),
        "{rk4}"
    );
    Scene::parse(&rk4, "rk4.toml").expect("rk4 with its step alone");
    for (key, line) in [
        ("rtol", "rtol = 1e-9"),
        ("atol", "atol = 1e-9"),
        ("initial_step", "initial_step = 0.1"),
    ] {
        let text = rk4.replace("step = 0.01", &format!("step = 0.01\n{line}"));
        let e = Scene::parse(&text, "rk4.toml").expect_err(key);
        let at = line_of(&text, line);
        assert_eq!(e.position().map(|p| p.0), Some(at), "{key}: {e}");
        let m = e.to_string();
        assert!(m.contains(&format!("`{key}`")), "{m}");
        assert!(
            m.contains("would be ignored") && m.contains("`step`"),
            "{m}"
        );
    }
    // max_step is used: it caps the fixed step.
    let capped = rk4.replace("step = 0.01", "step = 0.01\nmax_step = 0.005");
    let o = Scene::parse(&capped, "rk4.toml")
        .expect("max_step is not ignored")
        .solve()
        .expect("solves");
    assert_eq!(o.stats.accepted_steps, 100);
    // And the summary gives the step taken.
    let capped = Scene::parse(&capped, "rk4.toml").expect("parses");
    let summary = output::summary(&capped, &o);
    assert!(
        summary.contains("  method   Rk4, max_step = 0.005, below step = 0.01;"),
        "{summary}"
    );
    // So are the sensitivities' error control: rk4 has none.
    let control = format!("{rk4}\n[sensitivities]\nparameters = [\"g\"]\ncontrol = true\n");
    let e = Scene::parse(&control, "rk4.toml").expect_err("control with rk4");
    assert!(e.to_string().contains("would be ignored"), "{e}");
    Scene::parse(
        &control.replace("control = true", "control = false"),
        "rk4.toml",
    )
    .expect("control = false is the default");
}

#[test]
fn a_model_not_finite_at_the_start_names_the_expression() {
    // (text to replace, replacement, the line pointed at starts with, what the message names)
    let cases = [
        (
            "constraints = [\"x_dot^2 + y_dot^2 - v0^2\"]",
            "constraints = [\"x_dot^2 + y_dot^2 - v0^2/x\"]",
            "constraints",
            "constraint 1 (x_dot^2 + y_dot^2 - v0^2/x) is -inf",
        ),
        (
            "lagrangian = \"0.5*(x_dot^2 + y_dot^2) - g*y\"",
            "lagrangian = \"0.5*(x_dot^2 + y_dot^2) - g*y + ln(x)\"",
            "lagrangian",
            "the Lagrangian L (0.5*(x_dot^2 + y_dot^2) - g*y + ln(x)) is -inf",
        ),
        (
            // Finite, but its derivative by y is not.
            "lagrangian = \"0.5*(x_dot^2 + y_dot^2) - g*y\"",
            "lagrangian = \"0.5*(x_dot^2 + y_dot^2) - g*y + acos(y/5)\"",
            "lagrangian",
            "the derivative ∂L/∂y of the Lagrangian L (0.5*(x_dot^2 + y_dot^2) - g*y + acos(y/5)) is -inf",
        ),
        (
            // Finite, but sqrt's derivative at 0 is NaN, which makes every derivative NaN: which
            // variable cannot be told, the expression can.
            "lagrangian = \"0.5*(x_dot^2 + y_dot^2) - g*y\"",
            "lagrangian = \"0.5*(x_dot^2 + y_dot^2) - g*y + sqrt(x)\"",
            "lagrangian",
            "the first derivatives of the Lagrangian L (0.5*(x_dot^2 + y_dot^2) - g*y + sqrt(x)) are not finite",
        ),
        (
            "constraints = [",
            "forces = [\"1/x\", \"0\"]\nconstraints = [",
            "forces",
            "the force Q_x (1/x) is inf",
        ),
        (
            "constraints = [",
            "dissipation = \"x_dot^2/x\"\nconstraints = [",
            "dissipation",
            "the dissipation function D (x_dot^2/x) is inf",
        ),
    ];
    for (from, to, line, names) in cases {
        assert!(BASE.contains(from), "{from}");
        let text = BASE.replace(from, to);
        let scene = Scene::parse(&text, "domain.toml").unwrap_or_else(|e| panic!("{e}"));
        let e = scene.check().expect_err("not finite at x = 0");
        let at = line_of(&text, line);
        assert_eq!(e.position().map(|p| p.0), Some(at), "{e}");
        let m = e.to_string();
        assert!(m.contains(names), "{m}");
        assert!(
            m.contains("at the initial state (t = 0, x = 0, y = 5"),
            "{m}"
        );
        // solve says the same.
        assert_eq!(scene.solve().expect_err("solve").to_string(), m);
    }
}

#[test]
fn the_energy_line_names_the_terms_of_the_balance() {
    let energy = "[output]\ntables = [\"energy\"]\n";
    let line = |text: &str| {
        let scene = Scene::parse(text, "energy.toml").unwrap_or_else(|e| panic!("{e}"));
        let o = scene.solve().expect("solves");
        let summary = output::summary(&scene, &o);
        let line = summary
            .lines()
            .find(|l| l.starts_with("  energy"))
            .unwrap_or_else(|| panic!("{summary}"))
            .to_string();
        let max = o.balance.iter().fold(0.0f64, |m, b| m.max(b.abs()));
        assert!(
            line.ends_with(&format!("| = {}", output::summary_number(max))),
            "{line}"
        );
        line
    };
    let base = format!("{BASE}{energy}");
    assert!(line(&base).contains("max |E − E(t0) − W_Φ| = "));
    let drag = base.replace(
        "constraints = [",
        "dissipation = \"0.1*x_dot^2\"\nconstraints = [",
    );
    assert!(line(&drag).contains("max |E − E(t0) − W_Φ − W_Q| = "));
    let forced = base.replace(
        "constraints = [",
        "forces = [\"0\", \"-0.1*y_dot\"]\nconstraints = [",
    );
    assert!(line(&forced).contains("max |E − E(t0) − W_Φ − W_Q| = "));
    let timed = base.replace("- g*y\"", "- g*y*(1 + 0.01*t)\"");
    assert!(line(&timed).contains("max |E − E(t0) − W_Φ + ∫∂L/∂t dt| = "));
    let free = base.replace("constraints = [\"x_dot^2 + y_dot^2 - v0^2\"]\n", "");
    assert!(line(&free).contains("max |E − E(t0)| = "));
}

/// The paper's motion written out in 300 coordinates: gravity along a unit vector `c` of R³⁰⁰.
/// Its Lagrangian alone has about 2,700 numbers, names and operators.
#[test]
fn a_scene_of_300_coordinates_is_written_out_and_solved() {
    let n = 300;
    let norm = (0..n)
        .map(|i| (i as f64 + 1.0).sin().powi(2))
        .sum::<f64>()
        .sqrt();
    let c: Vec<f64> = (0..n).map(|i| (i as f64 + 1.0).sin() / norm).collect();
    let names: Vec<String> = (0..n).map(|i| format!("x{i}")).collect();
    let height = |scale: f64| {
        names
            .iter()
            .zip(&c)
            .map(|(x, ci)| format!("{:e}*{x}", ci * scale))
            .collect::<Vec<_>>()
            .join(" + ")
    };
    let speeds = names
        .iter()
        .map(|x| format!("{x}_dot^2"))
        .collect::<Vec<_>>()
        .join(" + ");
    // Start at height h0 = 5 along c with the speed v0 = 10 along x0 − (c·e0) c, orthogonal to c.
    let e = {
        let mut e = vec![0.0; n];
        e[0] = 1.0;
        let d = c[0];
        let v: Vec<f64> = e.iter().zip(&c).map(|(ei, ci)| ei - d * ci).collect();
        let len = v.iter().map(|x| x * x).sum::<f64>().sqrt();
        v.into_iter().map(|x| 10.0 * x / len).collect::<Vec<_>>()
    };
    let list = |v: &[f64]| {
        v.iter()
            .map(|x| format!("{x:e}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let q0: Vec<f64> = c.iter().map(|ci| 5.0 * ci).collect();
    let text = format!(
        "[parameters]\ng = 10.0\nv0 = 10.0\n[model]\ncoordinates = [{}]\nlagrangian = \"0.5*({speeds}) - \
         g*({})\"\nconstraints = [\"{speeds} - v0^2\"]\n[initial]\nq = [{}]\nq_dot = [{}]\n[solve]\n\
         method = \"dop853\"\nt_end = 3.0\nrtol = 1e-11\natol = 1e-11\n[[events]]\nname = \"impact\"\n\
         expression = \"{}\"\ndirection = \"falling\"\nterminal = true\n",
        names
            .iter()
            .map(|x| format!("\"{x}\""))
            .collect::<Vec<_>>()
            .join(", "),
        height(1.0),
        list(&q0),
        list(&e),
        height(1.0)
    );
    let scene = Scene::parse(&text, "big.toml").unwrap_or_else(|e| panic!("{e}"));
    let o = scene.solve().expect("solves");
    assert_eq!(o.solution.status, Status::Terminated { event: 0 });
    // The paper's impact time for g = 10, v0 = 10, h0 = 5 (Table 42.1).
    let t = o.solution.events[0].t;
    assert!((t - 1.085038501948).abs() < 1e-9, "{t}");
}

#[test]
fn an_empty_span_or_a_grid_of_one_time_is_refused_saying_what_to_write() {
    let e = Scene::parse(&BASE.replace("t_end = 0.5", "t_end = 0.0"), "span.toml")
        .expect_err("t_end = t0");
    let m = e.to_string();
    assert!(
        m.contains("equals the initial time") && m.contains("integrate backwards"),
        "{m}"
    );
    let grid = format!("{BASE}\n[output]\ntimes = {{ from = 0.0, to = \"end\", count = 1 }}\n");
    let e = Scene::parse(&grid, "grid.toml").expect_err("count = 1");
    let m = e.to_string();
    assert!(
        m.contains("count = 1") && m.contains("count = 2 writes the start and the end"),
        "{m}"
    );
    // What the messages advise is accepted.
    Scene::parse(&grid.replace("count = 1", "count = 2"), "grid.toml").expect("count = 2");
    Scene::parse(&BASE.replace("t_end = 0.5", "t_end = -0.5"), "back.toml").expect("backwards");
}

#[test]
fn steps_stalled_at_a_kink_are_reported_as_such() {
    // The apex of the velocity cone ż = k|(ẋ, ẏ)| is reached at t* = s0 (1 + k²)/(g k) = 0.5097.
    let text = r#"
[parameters]
k = 0.5
[model]
coordinates = ["x", "y", "z"]
lagrangian = "0.5*(x_dot^2 + y_dot^2 + z_dot^2) - 9.81*z"
constraints = ["z_dot - k*sqrt(x_dot^2 + y_dot^2)"]
[initial]
q = [0.0, 0.0, 0.0]
q_dot = [2.0, 0.0, 1.0]
[solve]
method = "dop853"
t_end = 0.75
rtol = 1e-10
atol = 1e-10
max_steps = 20000
"#;
    let scene = Scene::parse(text, "cone.toml").expect("parses");
    let outcome = scene.solve().expect("solves");
    let Status::Failed(e) = &outcome.status else {
        panic!("{:?}", outcome.status)
    };
    assert!(
        matches!(e, chetaev::Error::MaxSteps { stalled: true, .. }),
        "{e}"
    );
    let f = output::failure(&scene, e);
    assert!(
        f.what.contains("less than a thousandth") && f.advice.contains("kink"),
        "{f:?}"
    );
    assert!(!f.advice.contains("loosen rtol"), "{f:?}");
}

#[test]
fn the_residual_table_names_each_row_and_shows_the_holonomic_position_residual() {
    let scene = Scene::load(scenes_dir().join("cartesian-pendulum.toml")).expect("loads");
    assert_eq!(
        (scene.constraints.len(), scene.holonomic.len()),
        (0, 1),
        "the scene changed"
    );
    let outcome = scene.solve().expect("solves");
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("residual-table");
    let _ = std::fs::remove_dir_all(&dir);
    output::write(&scene, &outcome, &dir).expect("writes");
    // The summary gives the holonomic residual h beside f, and no relative measure of velocity
    // constraints the scene does not have.
    let summary = output::summary(&scene, &outcome);
    assert!(
        summary.contains("; max |h| = ") && !summary.contains("velocity terms"),
        "{summary}"
    );
    let text = std::fs::read_to_string(dir.join("residual.csv")).expect("written");
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("t,hdot_1,h_1"));
    // h is the rod's x² + y² − l², as recorded in the solution.
    for (i, line) in lines.enumerate() {
        let h: f64 = line.split(',').nth(2).expect("h").parse().expect("number");
        assert_eq!(h, outcome.position_residual[i][0], "row {i}");
    }
}

#[test]
fn option_values_in_messages_are_written_as_numbers_are() {
    // A tiny or huge value is shown in scientific notation, not as hundreds of digits.
    for (line, shown) in [
        ("rtol = 1e-30", "rtol = 1e-30 under [solve]"),
        ("max_step = 1e-300", "max_step = 1e-300 under [solve]"),
    ] {
        let text = BASE.replace("rtol = 1e-9", line);
        let e = Scene::parse(&text, "base.toml")
            .and_then(|s| s.solve().map(|_| ()))
            .expect_err(line);
        let m = e.to_string();
        assert!(m.contains(shown) && m.len() < 400, "{m}");
    }
}

#[test]
fn a_terminal_event_zero_at_the_start_does_not_stop_the_run_and_is_named() {
    // A projectile launched upward from y = 0: `y` leaves zero rising, which is not a crossing;
    // in either direction, the landing at 2 v_y / g = 0.8 is.
    let launch = |direction: &str| {
        let text = BASE
            .replace("lagrangian = \"0.5*(x_dot^2 + y_dot^2) - g*y\"\nconstraints = [\"x_dot^2 + y_dot^2 - v0^2\"]",
                "lagrangian = \"0.5*(x_dot^2 + y_dot^2) - g*y\"")
            .replace("q = [0.0, 5.0]\nq_dot = [\"v0\", 0.0]", "q = [0.0, 0.0]\nq_dot = [3.0, 4.0]")
            .replace("t_end = 0.5", "t_end = 2.0")
            + &format!(
                "[[events]]\nname = \"land\"\nexpression = \"y\"\nterminal = true\n{direction}\n"
            );
        let scene = Scene::parse(&text, "launch.toml").unwrap_or_else(|e| panic!("{e}"));
        let warnings = scene.check_with_warnings().expect("checks");
        assert!(
            matches!(warnings.as_slice(), [chetaev::Warning::EventZeroAtStart { name, .. }] if name == "land"),
            "{warnings:?}"
        );
        let outcome = scene.solve().expect("solves");
        (output::summary(&scene, &outcome), outcome)
    };
    for direction in ["", "direction = \"falling\""] {
        let (summary, outcome) = launch(direction);
        let t = *outcome.t.last().expect("recorded");
        assert!((t - 0.8).abs() < 1e-9, "{summary}");
        assert!(
            summary.contains("warning")
                && summary.contains("\"land\" (index 0) is zero at the start"),
            "{summary}"
        );
        assert!(!summary.contains("advice"), "{summary}");
    }
}

#[test]
fn output_times_out_of_order_repeated_or_reversed_are_refused_at_their_place() {
    for (times, says) in [
        ("[0.3, 0.1]", "0.1 follows 0.3"),
        ("[0.1, 0.2, 0.2]", "0.2 follows 0.2"),
        (
            "{ from = 0.4, to = 0.1, count = 5 }",
            "against the direction",
        ),
        ("{ from = 0.2, to = 0.2, count = 3 }", "no interval"),
    ] {
        let text = format!("{BASE}\n[output]\ntimes = {times}\n");
        let e = Scene::parse(&text, "base.toml").expect_err(times);
        let at = line_of(&text, "times");
        assert_eq!(e.position().map(|p| p.0), Some(at), "{times}: {e}");
        assert!(e.to_string().contains(says), "{times}: {e}");
    }
    // Backward, the list decreases.
    let backward = BASE.replace("t_end = 0.5", "t_end = -0.5");
    Scene::parse(
        &format!("{backward}\n[output]\ntimes = [-0.1, -0.3]\n"),
        "base.toml",
    )
    .expect("decreasing times going backward");
    let e = Scene::parse(
        &format!("{backward}\n[output]\ntimes = [-0.3, -0.1]\n"),
        "base.toml",
    )
    .expect_err("increasing times going backward");
    assert!(e.to_string().contains("decreasing"), "{e}");
}

#[test]
fn the_rolling_disc_and_the_snakeboard_conserve_their_energy_and_roll_without_slipping() {
    // Constraints linear and homogeneous in the velocities do no work (q̇·Φ = μ·J q̇ = μ·f = 0),
    // and neither Lagrangian depends on time: E stays at E(t0), and f at zero.
    for name in ["rolling-disc", "snakeboard"] {
        let scene = Scene::load(scenes_dir().join(format!("{name}.toml"))).expect("loads");
        let outcome = scene.solve().expect("solves");
        assert!(
            matches!(outcome.status, Status::Success),
            "{name}: {:?}",
            outcome.status
        );
        let e0 = outcome.energy[0];
        let drift = outcome
            .energy
            .iter()
            .fold(0.0f64, |m, e| m.max((e - e0).abs()));
        assert!(
            drift < 1e-8 * (1.0 + e0.abs()),
            "{name}: E drifts by {drift:e}"
        );
        let work = outcome.work.iter().fold(0.0f64, |m, w| m.max(w.abs()));
        assert!(work < 1e-8, "{name}: W_Φ = {work:e}");
        let residual = outcome
            .residual
            .iter()
            .flatten()
            .fold(0.0f64, |m, f| m.max(f.abs()));
        assert!(residual < 1e-8, "{name}: |f| = {residual:e}");
        assert!(
            outcome.mu.iter().flatten().any(|m| m.abs() > 1e-3),
            "{name}: forces act"
        );
    }
}
