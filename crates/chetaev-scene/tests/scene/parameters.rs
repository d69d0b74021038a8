//! `[parameters]`: expressions of other parameters in any order, resolved in dependency order in
//! time linear in their number; cycles named; suggestions for unknown names bounded.

use chetaev_scene::Scene;
use proptest::prelude::*;

/// A scene whose parameters are `lines`, in that order, and whose Lagrangian uses `last`.
fn scene(lines: &[String], last: &str) -> String {
    format!(
        "[parameters]\n{}\n[model]\ncoordinates = [\"x\"]\nlagrangian = \"0.5*x_dot^2 - {last}*x\"\n\
         [initial]\nq = [0.0]\nq_dot = [0.0]\n[solve]\nt_end = 1.0\n",
        lines.join("\n")
    )
}

fn value(s: &Scene, name: &str) -> f64 {
    s.parameters
        .iter()
        .find(|(n, _)| n == name)
        .map(|(_, v)| *v)
        .unwrap_or_else(|| panic!("no parameter {name}"))
}

fn chain(n: usize) -> Vec<String> {
    std::iter::once("p1 = 1.0".to_string())
        .chain((2..=n).map(|i| format!("p{i} = \"p{} + 1\"", i - 1)))
        .collect()
}

#[test]
fn twenty_thousand_chained_parameters_resolve_in_either_order() {
    let n = 20_000;
    let mut lines = chain(n);
    let s = Scene::parse(&scene(&lines, &format!("p{n}")), "chain.toml")
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(s.parameters.len(), n);
    assert_eq!(value(&s, &format!("p{n}")), n as f64);
    // Written last to first: every parameter waits for the one after it in the file.
    lines.reverse();
    let s = Scene::parse(&scene(&lines, &format!("p{n}")), "reversed.toml")
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(value(&s, &format!("p{n}")), n as f64);
    assert_eq!(
        s.parameters[0].0,
        format!("p{n}"),
        "the order of the file is kept"
    );
}

#[test]
fn a_cycle_is_named_in_order_at_its_first_member() {
    let lines = [
        "g = 9.81".to_string(),
        "a = \"b + 1\"".to_string(),
        "b = \"2*c\"".to_string(),
        "c = \"a - g\"".to_string(),
    ];
    let e = Scene::parse(&scene(&lines, "g"), "cycle.toml").expect_err("cycle");
    assert_eq!(e.position().map(|p| p.0), Some(3), "{e}");
    assert!(e.to_string().contains("a cycle of 3"), "{e}");
    assert!(e.to_string().contains("a → b → c → a"), "{e}");

    let e = Scene::parse(&scene(&["k = \"k/2\"".to_string()], "k"), "self.toml").expect_err("self");
    assert!(
        e.to_string().contains("'k' is defined in terms of itself"),
        "{e}"
    );

    // A long cycle is listed in part.
    let n = 5000;
    let mut lines: Vec<String> = (1..n)
        .map(|i| format!("p{i} = \"p{} + 1\"", i + 1))
        .collect();
    lines.push(format!("p{n} = \"p1\""));
    let e = Scene::parse(&scene(&lines, "p1"), "long.toml").expect_err("cycle");
    let m = e.to_string();
    assert!(m.contains(&format!("a cycle of {n}")), "{m}");
    assert!(m.contains("p1 → p2 → p3"), "{m}");
    assert!(m.contains("→ … → p1"), "{m}");
    assert!(m.len() < 600, "{m}");
}

#[test]
fn an_unknown_name_suggests_any_parameter_of_the_file() {
    // The parameter meant is written after the one that misspells it.
    let lines = [
        "w = \"sqrt(stifness/mass)\"".to_string(),
        "mass = 2.0".to_string(),
        "stiffness = 8.0".to_string(),
    ];
    let e = Scene::parse(&scene(&lines, "w"), "typo.toml").expect_err("typo");
    assert!(e.to_string().contains("did you mean 'stiffness'?"), "{e}");
    assert_eq!(e.position(), Some((2, 11)), "{e}");
    // pi and e are constants, not mistakes.
    let s = Scene::parse(&scene(&["w = \"pi*e\"".to_string()], "w"), "pie.toml")
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(value(&s, "w"), std::f64::consts::PI * std::f64::consts::E);
}

#[test]
fn suggestions_among_many_long_names_stay_bounded() {
    let n = 20_000;
    let stem = "a_rather_long_parameter_name_that_goes_on_and_on_".repeat(2);
    let mut lines: Vec<String> = (0..n).map(|i| format!("{stem}{i} = {i}.0")).collect();
    lines.push(format!("w = \"{stem}1999x\""));
    let e = Scene::parse(&scene(&lines, "w"), "many.toml").expect_err("unknown");
    let m = e.to_string();
    // Names over 64 characters get no suggestion, and the list of names is cut short.
    assert!(!m.contains("did you mean"), "{}", &m[..m.len().min(400)]);
    // The n + 1 parameters, pi and e, of which 20 are listed.
    assert!(
        m.contains(&format!("and {} more", n + 3 - 20)),
        "{}",
        &m[..m.len().min(400)]
    );
    assert!(m.len() < 4000, "{}", m.len());

    let lines: Vec<String> = (0..n)
        .map(|i| format!("q{i} = {i}.0"))
        .chain(["w = \"q1999x\"".to_string()])
        .collect();
    let e = Scene::parse(&scene(&lines, "w"), "short.toml").expect_err("unknown");
    assert!(e.to_string().contains("did you mean '"), "{e}");
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Random acyclic dependencies, written in a random order: every value as computed directly.
    #[test]
    fn random_dependencies_in_any_order_resolve(
        n in 1usize..60,
        seed in any::<u64>(),
        order in any::<u64>(),
    ) {
        let mut rng = seed | 1;
        let mut next = move || {
            rng ^= rng << 13;
            rng ^= rng >> 7;
            rng ^= rng << 17;
            rng
        };
        // p_i = i + the sum of up to three p_j with j < i.
        let mut want = vec![0.0f64; n];
        let mut lines = Vec::with_capacity(n);
        for i in 0..n {
            let mut terms = vec![format!("{i}")];
            want[i] = i as f64;
            if i > 0 {
                for _ in 0..(next() % 4) {
                    let j = (next() % i as u64) as usize;
                    terms.push(format!("p{j}"));
                    want[i] += want[j];
                }
            }
            lines.push(if terms.len() == 1 { format!("p{i} = {i}") } else { format!("p{i} = \"{}\"", terms.join(" + ")) });
        }
        let mut shuffle = order | 1;
        for i in (1..n).rev() {
            shuffle ^= shuffle << 13;
            shuffle ^= shuffle >> 7;
            shuffle ^= shuffle << 17;
            lines.swap(i, (shuffle % (i as u64 + 1)) as usize);
        }
        let s = Scene::parse(&scene(&lines, &format!("p{}", n - 1)), "random.toml")
            .map_err(|e| TestCaseError::fail(e.to_string()))?;
        for (i, w) in want.iter().enumerate() {
            prop_assert_eq!(value(&s, &format!("p{i}")), *w);
        }
    }
}

/// A charge `q` of mass `m` in the plane, in a uniform magnetic field `B` along `z`, from the
/// origin with velocity `(v, 0)`. The force `e (ẏ B, −ẋ B)` is given either as `forces` or through
/// the vector potential `A = (−B y/2, B x/2)` in `L = ½ m |v|² + e A·v`.
fn charge_in_a_field(parameters: &str, force: &str) -> String {
    let model = match force {
        "forces" => {
            "lagrangian = \"0.5*m*(x_dot^2 + y_dot^2)\"\nforces = [\"e*B*y_dot\", \"-e*B*x_dot\"]"
        }
        _ => "lagrangian = \"0.5*m*(x_dot^2 + y_dot^2) + e*B/2*(x*y_dot - y*x_dot)\"",
    };
    format!(
        "[parameters]\n{parameters}\nm = 1.0\nB = 1.0\nv = 1.0\n[model]\ncoordinates = [\"x\", \"y\"]\n\
         {model}\n[initial]\nq = [0.0, 0.0]\nq_dot = [\"v\", 0.0]\n[solve]\nt_end = 1.0\n\
         rtol = 1e-12\natol = 1e-12\n"
    )
}

/// The circle of the charge: `x = (v/ω) sin ωt`, `y = −(v/ω)(1 − cos ωt)`, `ω = e B / m`.
fn gyration(e: f64, t: f64) -> [f64; 2] {
    let w = e; // B = m = v = 1
    [(w * t).sin() / w, -(1.0 - (w * t).cos()) / w]
}

#[test]
fn a_parameter_named_e_is_the_charge_and_not_eulers_number() {
    for force in ["forces", "potential"] {
        let s = Scene::parse(&charge_in_a_field("e = 2.0", force), "charge.toml")
            .unwrap_or_else(|err| panic!("{force}: {err}"));
        assert!(s.warnings.is_empty(), "{force}: {:?}", s.warnings);
        let o = s.solve().unwrap_or_else(|err| panic!("{force}: {err}"));
        assert!(o.is_success(), "{force}: {:?}", o.status);
        let (t, q) = (o.t[o.len() - 1], &o.q[o.len() - 1]);
        assert_eq!(t, 1.0);
        let want = gyration(2.0, t);
        for i in 0..2 {
            assert!(
                (q[i] - want[i]).abs() < 1e-9,
                "{force}: q = {q:?}, want {want:?}"
            );
        }
    }
    // Computed from the declared e, and shadowing pi too.
    let lines = [
        "e = 1.5".to_string(),
        "pi = 3.0".to_string(),
        "w = \"e*pi\"".to_string(),
    ];
    let s = Scene::parse(&scene(&lines, "w"), "shadow.toml").unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(value(&s, "w"), 4.5);
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
}

#[test]
fn an_undeclared_e_is_eulers_number_with_a_warning_at_each_place() {
    let s = Scene::parse(&charge_in_a_field("", "forces"), "euler.toml")
        .unwrap_or_else(|err| panic!("{err}"));
    let o = s.solve().unwrap_or_else(|err| panic!("{err}"));
    let q = &o.q[o.len() - 1];
    let want = gyration(std::f64::consts::E, 1.0);
    for i in 0..2 {
        assert!((q[i] - want[i]).abs() < 1e-9, "q = {q:?}, want {want:?}");
    }
    // One warning per use, at the e in each force.
    let text = charge_in_a_field("", "forces");
    let line = text
        .lines()
        .position(|l| l.starts_with("forces"))
        .expect("forces")
        + 1;
    let places: Vec<(usize, usize)> = s.warnings.iter().map(|w| (w.line, w.column)).collect();
    assert_eq!(places, [(line, 12), (line, 26)], "{:?}", s.warnings);
    for w in &s.warnings {
        assert!(w.message.contains("Euler's number"), "{w}");
        assert!(w.message.contains("exp(1)"), "{w}");
        assert!(w.message.contains("[parameters]"), "{w}");
        assert!(w.snippet.contains('^'), "{}", w.snippet);
    }
    // In a parameter's expression too; exp(1) and pi say what they mean and are not warned of.
    let lines = ["w = \"e*pi\"".to_string(), "u = \"exp(1)*pi\"".to_string()];
    let s = Scene::parse(&scene(&lines, "w + u"), "pie.toml").unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(s.warnings.len(), 1, "{:?}", s.warnings);
    assert_eq!((s.warnings[0].line, s.warnings[0].column), (2, 6));
}

#[test]
fn a_coordinate_may_be_named_e_and_t_stays_reserved() {
    let text = "[model]\ncoordinates = [\"e\"]\nlagrangian = \"0.5*e_dot^2 - 0.5*e^2\"\n\
                [initial]\nq = [1.0]\nq_dot = [0.0]\n[solve]\nt_end = 1.0\nrtol = 1e-12\natol = 1e-12\n";
    let s = Scene::parse(text, "oscillator.toml").unwrap_or_else(|e| panic!("{e}"));
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    let o = s.solve().unwrap_or_else(|e| panic!("{e}"));
    assert!((o.q[o.len() - 1][0] - 1f64.cos()).abs() < 1e-9);
    let e = Scene::parse(&scene(&["t = 1.0".to_string()], "t"), "time.toml").expect_err("t");
    assert!(e.to_string().contains("'t' is reserved for time"), "{e}");
}
