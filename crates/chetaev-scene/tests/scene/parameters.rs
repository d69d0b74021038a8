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
