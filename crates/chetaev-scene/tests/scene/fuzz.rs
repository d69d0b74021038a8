//! Bounded fuzzing: random expression strings and randomly damaged scene files never panic. An
//! expression either parses or is a located error inside its text; a scene either loads, and then
//! checks or fails with an error, or is an error at a line and column of the file.

use chetaev_scene::expr::{Env, Expr, Symbols};
use chetaev_scene::Scene;
use num_dual::{Dual64, HyperDual};
use proptest::prelude::*;

/// Pieces an expression is made of, right and wrong.
const PIECES: &[&str] = &[
    "x",
    "y",
    "x_dot",
    "y_dot",
    "t",
    "g",
    "m",
    "pi",
    "e",
    "z",
    "xdot",
    "0",
    "1",
    "2.5",
    ".5",
    "1e-3",
    "1e400",
    "46342",
    "4503599627370497",
    "-",
    "+",
    "*",
    "/",
    "^",
    "^^",
    "**",
    "(",
    ")",
    "((",
    "))",
    ",",
    " ",
    "sqrt(",
    "ln(",
    "atan2(",
    "abs(",
    "log(",
    "sinh(",
    "acosh(",
    "exp(",
    "é",
    "\t",
    "\"",
    "#",
    "1.",
    "e5",
    "_",
    "x_",
    "sin",
    "2x",
];

fn expression() -> impl Strategy<Value = String> {
    prop::collection::vec(prop::sample::select(PIECES), 0..40).prop_map(|p| p.concat())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(3000))]

    #[test]
    fn random_expressions_parse_or_point_inside_their_text(src in expression()) {
        let symbols = Symbols::motion(&[("g", 9.81), ("m", 0.0)], &["x", "y"]);
        match Expr::parse(&src, &symbols) {
            Ok(e) => {
                let v = e.eval(&Env { t: 0.3, q: &[0.7, -1.2], qd: &[2.0, 0.1] });
                let _ = v;
                type J = HyperDual<Dual64, f64>;
                let q = [J::from_re(Dual64::new(0.7, 1.0)), J::from_re(Dual64::from(-1.2))];
                let qd = [J::new(Dual64::from(2.0), Dual64::from(1.0), Dual64::from(1.0), Dual64::from(0.0)), J::from_re(Dual64::from(0.1))];
                let _ = e.eval(&Env { t: J::from_re(Dual64::from(0.3)), q: &q, qd: &qd });
            }
            Err(e) => {
                prop_assert!(e.start <= e.end && e.end <= src.len().max(e.start + 1), "{e:?} in {src:?}");
                prop_assert!(!e.message.is_empty());
            }
        }
    }

    #[test]
    fn random_text_never_panics_the_parser(src in "\\PC{0,60}") {
        let _ = Expr::parse(&src, &Symbols::motion(&[], &["x"]));
    }
}

/// The shipped scenes, to be damaged.
fn scenes() -> Vec<String> {
    let dir = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let mut files: Vec<_> = std::fs::read_dir(dir)
        .expect("scenes/")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    files.sort();
    files
        .iter()
        .map(|p| std::fs::read_to_string(p).expect("readable"))
        .collect()
}

/// One damage to a scene: a cut, a repeated line, an inserted piece, a replaced character.
#[derive(Clone, Debug)]
enum Damage {
    Cut(usize, usize),
    RepeatLine(usize),
    Insert(usize, &'static str),
    Replace(usize, char),
}

fn damage() -> impl Strategy<Value = Damage> {
    let inserted = prop::sample::select(vec![
        "[",
        "]",
        "\"",
        "'",
        "=",
        "\n",
        "\\",
        "\\u00e9",
        "x^^2",
        "\"\"\"",
        "#",
        "1e309",
        "-1",
        "[[events]]\n",
        "nan",
        "inf",
        "project_velocity = true\n",
        "é",
        "\u{0}",
        "count = 0",
        "t_end = 0.0\n",
    ]);
    prop_oneof![
        (any::<usize>(), 1usize..40).prop_map(|(a, n)| Damage::Cut(a, n)),
        any::<usize>().prop_map(Damage::RepeatLine),
        (any::<usize>(), inserted).prop_map(|(a, s)| Damage::Insert(a, s)),
        (
            any::<usize>(),
            prop::sample::select(vec!['"', '[', ']', '=', '0', 'x', '\n', ' ', '^', ','])
        )
            .prop_map(|(a, c)| Damage::Replace(a, c)),
    ]
}

fn floor_boundary(s: &str, mut i: usize) -> usize {
    i = i.min(s.len());
    while !s.is_char_boundary(i) {
        i -= 1;
    }
    i
}

fn apply(text: &str, d: &Damage) -> String {
    let at = |a: usize| floor_boundary(text, a % (text.len() + 1));
    match d {
        Damage::Cut(a, n) => {
            let start = at(*a);
            let end = floor_boundary(text, start + n);
            format!("{}{}", &text[..start], &text[end..])
        }
        Damage::RepeatLine(a) => {
            let lines: Vec<&str> = text.lines().collect();
            let i = a % lines.len().max(1);
            let mut out: Vec<&str> = lines.clone();
            if let Some(l) = lines.get(i) {
                out.insert(i, l);
            }
            out.join("\n")
        }
        Damage::Insert(a, s) => {
            let i = at(*a);
            format!("{}{s}{}", &text[..i], &text[i..])
        }
        Damage::Replace(a, c) => {
            let i = at(*a);
            let mut out = text[..i].to_string();
            out.push(*c);
            let rest = &text[i..];
            out.push_str(
                rest.get(rest.chars().next().map_or(0, char::len_utf8)..)
                    .unwrap_or(""),
            );
            out
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(600))]

    #[test]
    fn damaged_scene_files_load_and_check_or_fail_at_a_place(
        which in any::<usize>(),
        damages in prop::collection::vec(damage(), 1..4),
    ) {
        let all = scenes();
        let mut text = all[which % all.len()].clone();
        for d in &damages {
            text = apply(&text, d);
        }
        match Scene::parse(&text, "damaged.toml") {
            Ok(scene) => {
                // Setup errors are errors; nothing panics.
                let _ = scene.check();
            }
            Err(e) => {
                let lines = text.lines().count().max(1) + 1;
                if let Some((line, column)) = e.position() {
                    prop_assert!(line >= 1 && line <= lines, "{e}");
                    prop_assert!(column >= 1, "{e}");
                    prop_assert!(e.snippet().is_some_and(|s| s.contains('^')), "{e}");
                }
                prop_assert!(!e.to_string().is_empty());
            }
        }
    }
}
