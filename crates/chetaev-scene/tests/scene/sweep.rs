//! `chetaev sweep`: the paper's scene over grids and random samples of its parameters and initial
//! values, against the closed forms; shards merged into the whole; bad specifications refused.

use std::path::PathBuf;
use std::process::{Command, Output};

use chetaev::num_dual::Dual64;
use chetaev_scene::sweep::{Axis, RunStatus, Sweep, SweepArgs};
use chetaev_scene::Error;
use uniform_projectile::closed_form::{uniform, Params};

/// The paper's scene with `extra` appended (a `[sweep]` table, `[sensitivities]`).
fn scene(extra: &str) -> String {
    format!(
        r#"
[parameters]
m = 1.0
g = 10.0
v0 = 10.0
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
t_end = 1000.0
rtol = 1e-12
atol = 1e-12

[[events]]
name = "impact"
expression = "y"
direction = "falling"
terminal = true
{extra}
"#
    )
}

fn args(vary: &[&str]) -> SweepArgs {
    SweepArgs {
        vary: vary.iter().map(|s| s.to_string()).collect(),
        ..SweepArgs::default()
    }
}

fn all(sweep: &Sweep) -> Vec<usize> {
    (0..sweep.len()).collect()
}

fn column(sweep: &Sweep, name: &str) -> usize {
    sweep
        .columns()
        .iter()
        .position(|c| c == name)
        .unwrap_or_else(|| panic!("no column {name} in {:?}", sweep.columns()))
}

fn params(v0: f64, h0: f64) -> Params {
    Params {
        v0,
        h0,
        ..Params::PAPER
    }
}

#[test]
fn a_grid_of_speeds_and_heights_gives_the_closed_form_impacts_and_multipliers() {
    let text = scene(
        r#"
[sweep]
vary = { v0 = { from = 1.0, to = 100.0, count = 5, scale = "log" }, h0 = [1.0, 5.0, 50.0] }
collect = ["impact.t", "impact.x", "impact.y_dot", "max_abs.mu_1", "max.residual", "max_abs.balance"]
"#,
    );
    let sweep = Sweep::parse(&text, "grid.toml", &SweepArgs::default()).expect("valid");
    assert_eq!(sweep.len(), 15);
    assert_eq!(sweep.variables(), ["v0", "h0"]);
    let rows = sweep.run(&all(&sweep), &|| {});
    let (t, x, yd, mu, res, bal) = (
        column(&sweep, "impact.t"),
        column(&sweep, "impact.x"),
        column(&sweep, "impact.y_dot"),
        column(&sweep, "max_abs.mu_1"),
        column(&sweep, "max.residual"),
        column(&sweep, "max_abs.balance"),
    );
    // The last axis varies fastest; a log grid over two decades hits 1, 10 and 100 exactly.
    let v0s = [1.0, 10f64.sqrt(), 10.0, 1000f64.sqrt(), 100.0];
    for (i, row) in rows.iter().enumerate() {
        let (v0, h0) = (row.values[0], row.values[1]);
        assert!((v0 - v0s[i / 3]).abs() <= 1e-14 * v0, "{v0}");
        assert_eq!(h0, [1.0, 5.0, 50.0][i % 3]);
        assert_eq!(row.status, RunStatus::Terminated("impact".to_string()));
        let p = params(v0, h0);
        let k = uniform::kinematics(&p);
        let q = &row.quantities;
        let scale = |v: f64| 1e-9 * (1.0 + v.abs());
        assert!(
            (q[t] - k.t_impact).abs() < scale(k.t_impact),
            "T {} vs {}",
            q[t],
            k.t_impact
        );
        assert!(
            (q[x] - k.range).abs() < scale(k.range),
            "R {} vs {}",
            q[x],
            k.range
        );
        let vy = uniform::velocity(&p, k.t_impact)[1];
        assert!((q[yd] - vy).abs() < scale(vy), "ẏ(T) {} vs {vy}", q[yd]);
        // |μ| grows monotonically, so its largest value over the steps is the one at the impact.
        let m = uniform::multiplier(&p, k.t_impact).abs();
        assert!((q[mu] - m).abs() < scale(m), "max |μ| {} vs {m}", q[mu]);
        assert!(q[res] < 1e-8 * v0 * v0, "residual {}", q[res]);
        assert!(q[bal] < 1e-8 * (1.0 + h0 * 10.0), "balance {}", q[bal]);
        assert!(row.steps > 0 && row.rhs_evaluations > row.steps);
    }
}

#[test]
fn initial_values_and_values_at_times_follow_the_closed_form() {
    // initial.y in place of h0 (the parameter stays 5, the state starts elsewhere), and the
    // height at t = 0.3 by dense output.
    let sweep = Sweep::parse(
        &scene(""),
        "initial.toml",
        &SweepArgs {
            collect: Some(vec![
                "y@0.3".into(),
                "x_dot@0.3".into(),
                "end.t".into(),
                "max.y".into(),
                "min.x_dot".into(),
            ]),
            ..args(&["initial.y=2,8,20"])
        },
    )
    .expect("valid");
    assert_eq!(sweep.variables(), ["initial.y"]);
    let rows = sweep.run(&all(&sweep), &|| {});
    for row in &rows {
        let p = params(10.0, row.values[0]);
        let [_, y] = uniform::position(&p, 0.3);
        let [xd, _] = uniform::velocity(&p, 0.3);
        let k = uniform::kinematics(&p);
        let q = &row.quantities;
        assert!((q[0] - y).abs() < 1e-10, "y(0.3) {} vs {y}", q[0]);
        assert!((q[1] - xd).abs() < 1e-10, "ẋ(0.3) {} vs {xd}", q[1]);
        assert!((q[2] - k.t_impact).abs() < 1e-9, "end at the impact");
        assert_eq!(q[3], row.values[0], "the highest point is the start");
        let xd_end = uniform::velocity(&p, k.t_impact)[0];
        assert!((q[4] - xd_end).abs() < 1e-9, "min ẋ at the impact");
    }
    // A time after the impact is not reached: NaN, not a made-up value.
    let late = Sweep::parse(
        &scene(""),
        "late.toml",
        &SweepArgs {
            collect: Some(vec!["y@5".into()]),
            ..args(&["h0=1"])
        },
    )
    .expect("valid");
    assert!(late.run(&[0], &|| {})[0].quantities[0].is_nan());
}

#[test]
fn sensitivities_of_the_impact_are_the_closed_forms_derivatives() {
    let text = scene(
        r#"
[sensitivities]
parameters = ["v0", "h0"]
[sweep]
vary = { v0 = [5.0, 10.0, 20.0] }
collect = ["d(impact.t)/d(v0)", "d(impact.t)/d(h0)", "d(impact.x)/d(v0)", "d(end.x)/d(h0)"]
"#,
    );
    let sweep = Sweep::parse(&text, "sens.toml", &SweepArgs::default()).expect("valid");
    for row in sweep.run(&all(&sweep), &|| {}) {
        let v0 = row.values[0];
        let d = |dv: f64, dh: f64| {
            uniform::impact(
                Dual64::new(v0, dv),
                Dual64::from(10.0),
                Dual64::new(5.0, dh),
            )
        };
        let (t_v, r_v) = d(1.0, 0.0);
        let (t_h, r_h) = d(0.0, 1.0);
        let q = &row.quantities;
        let close = |a: f64, b: f64| (a - b).abs() < 1e-7 * (1.0 + b.abs());
        assert!(close(q[0], t_v.eps), "dT/dv0 {} vs {}", q[0], t_v.eps);
        assert!(close(q[1], t_h.eps), "dT/dh0 {} vs {}", q[1], t_h.eps);
        assert!(close(q[2], r_v.eps), "dR/dv0 {} vs {}", q[2], r_v.eps);
        // The run ends at the impact: the end moves with it.
        assert!(close(q[3], r_h.eps), "dR/dh0 {} vs {}", q[3], r_h.eps);
        assert!(t_v.re > 0.0);
    }
}

#[test]
fn random_samples_are_reproducible_from_the_seed_and_stay_in_their_ranges() {
    let make = |seed: u64, design: &str| {
        Sweep::parse(
            &scene(""),
            "random.toml",
            &SweepArgs {
                samples: Some(40),
                seed: Some(seed),
                design: Some(design.to_string()),
                collect: Some(vec!["impact.t".into()]),
                ..args(&["v0=5:20", "h0=1:100:log", "m=1,2"])
            },
        )
        .expect("valid")
    };
    let s = make(3, "latin");
    // The grid (m: 2 values) times 40 samples; the grid's variables first.
    assert_eq!(s.len(), 80);
    assert_eq!(s.variables(), ["m", "v0", "h0"]);
    assert!(matches!(s.varied[1].axis, Axis::Random { .. }));
    let points: Vec<Vec<f64>> = (0..s.len()).map(|i| s.values(i)).collect();
    assert_eq!(
        points,
        (0..80)
            .map(|i| make(3, "latin").values(i))
            .collect::<Vec<_>>()
    );
    assert_ne!(
        points,
        (0..80)
            .map(|i| make(4, "latin").values(i))
            .collect::<Vec<_>>()
    );
    for (i, p) in points.iter().enumerate() {
        assert_eq!(p[0], if i < 40 { 1.0 } else { 2.0 });
        assert!(
            (5.0..20.0).contains(&p[1]) && (1.0..100.0).contains(&p[2]),
            "{p:?}"
        );
    }
    // A Latin hypercube: each of 40 strata of v0 holds one sample per grid point.
    let mut strata: Vec<usize> = points[..40]
        .iter()
        .map(|p| ((p[1] - 5.0) / 15.0 * 40.0) as usize)
        .collect();
    strata.sort_unstable();
    assert_eq!(strata, (0..40).collect::<Vec<_>>());
    // Each random point's impact is its own closed form.
    let rows = s.run(&[0, 17, 79], &|| {});
    for r in rows {
        let k = uniform::kinematics(&params(r.values[1], r.values[2]));
        assert!((r.quantities[0] - k.t_impact).abs() < 1e-9 * (1.0 + k.t_impact));
    }
    // Uniform samples differ from the hypercube's.
    assert_ne!(make(3, "uniform").values(5), points[5]);
}

#[test]
fn a_run_that_fails_or_is_refused_is_a_row_and_the_others_go_on() {
    // v0 = 0 makes the initial velocity (0, 0) and the constraint's gradient vanish: refused.
    // max_steps = 20 stops the tall drops early: failed, with what they reached.
    let text = scene("").replace("atol = 1e-12", "atol = 1e-12\nmax_steps = 20");
    let sweep = Sweep::parse(
        &text,
        "fails.toml",
        &SweepArgs {
            collect: Some(vec!["impact.t".into(), "end.t".into()]),
            ..args(&["v0=0,10", "h0=1,1000"])
        },
    )
    .expect("valid");
    let rows = sweep.run(&all(&sweep), &|| {});
    assert_eq!(rows.len(), 4);
    assert_eq!(rows[0].status, RunStatus::Refused);
    assert_eq!(rows[1].status, RunStatus::Refused);
    assert!(!rows[0].reason.is_empty(), "the reason is kept");
    assert!(rows[0].quantities.iter().all(|q| q.is_nan()));
    assert_eq!(rows[2].status, RunStatus::Terminated("impact".into()));
    assert_eq!(rows[3].status, RunStatus::Failed);
    assert!(rows[3].reason.contains("step"), "{}", rows[3].reason);
    assert!(rows[3].quantities[0].is_nan(), "no impact reached");
    assert!(
        rows[3].quantities[1] > 0.0,
        "the end reached is kept: {}",
        rows[3].quantities[1]
    );
}

fn refused(text: &str, a: SweepArgs) -> Error {
    Sweep::parse(text, "bad.toml", &a).expect_err("refused")
}

#[test]
fn bad_specifications_are_refused_before_anything_runs() {
    let cases: Vec<(String, SweepArgs, &str)> = vec![
        (scene(""), args(&[]), "nothing varies"),
        (scene(""), args(&["vo=1,2"]), "did you mean v0?"),
        (scene(""), args(&["initial.z=1"]), "not an initial value"),
        (
            scene(""),
            args(&["v0=0:10:5:log"]),
            "cannot reach or cross zero",
        ),
        (
            scene(""),
            args(&["v0=5:5:3"]),
            "has one value but count = 3",
        ),
        (scene(""), args(&["v0=1:2:0"]), "give at least 1 value"),
        (scene(""), args(&["v0"]), "write NAME=SPEC"),
        (scene(""), args(&["v0=5:20"]), "give `samples`"),
        (
            scene(""),
            SweepArgs {
                samples: Some(3),
                ..args(&["v0=1,2"])
            },
            "no variable has a range to sample",
        ),
        (
            scene(""),
            args(&["v0=1:2:1000", "h0=1:2:1000", "g=1:2:1000"]),
            "pass --yes",
        ),
        (
            scene(""),
            SweepArgs {
                collect: Some(vec!["impact.z".into()]),
                ..args(&["v0=1,2"])
            },
            "is not a quantity of this scene",
        ),
        (
            scene(""),
            SweepArgs {
                collect: Some(vec!["d(impact.t)/d(v0)".into()]),
                ..args(&["v0=1,2"])
            },
            "add it under [sensitivities]",
        ),
        (
            scene(""),
            SweepArgs {
                collect: Some(vec!["max_abs.mu_2".into()]),
                ..args(&["v0=1,2"])
            },
            "mu_1 … mu_1, not mu_2",
        ),
        (
            scene(""),
            SweepArgs {
                design: Some("sobol".into()),
                samples: Some(3),
                ..args(&["v0=1:2"])
            },
            "unknown design",
        ),
    ];
    for (text, a, says) in cases {
        let e = refused(&text, a).to_string();
        assert!(e.contains(says), "{e}\n should say: {says}");
    }
    // 10⁹ points, confirmed, are allowed to be specified (not run here).
    let big = Sweep::parse(
        &scene(""),
        "big.toml",
        &SweepArgs {
            yes: true,
            ..args(&["v0=1:2:1000", "h0=1:2:1000", "g=1:2:1000"])
        },
    )
    .expect("confirmed");
    assert_eq!(big.len(), 1_000_000_000);
}

#[test]
fn mistakes_in_the_sweep_table_are_located_in_the_file() {
    let text = scene(
        r#"
[sweep]
vary = { v0 = { from = 0.0, to = 10.0, count = 3, scale = "log" } }
"#,
    );
    let e = refused(&text, SweepArgs::default());
    let (line, _) = e.position().expect("located");
    assert_eq!(
        text.lines().nth(line - 1).map(str::trim_start),
        Some(r#"vary = { v0 = { from = 0.0, to = 10.0, count = 3, scale = "log" } }"#)
    );
    assert!(e.to_string().contains("cannot reach or cross zero"), "{e}");
    let text = scene("[sweep]\nvary = { v0 = [1.0] }\ncollect = [\"impact.t\", \"landing.t\"]\n");
    let e = refused(&text, SweepArgs::default());
    let (line, _) = e.position().expect("located");
    assert!(text
        .lines()
        .nth(line - 1)
        .is_some_and(|l| l.contains("landing.t")));
    let text = scene("[sweep]\nvary = { v0 = [1.0] }\nsamples = 5\n");
    assert!(refused(&text, SweepArgs::default())
        .to_string()
        .contains("no variable has a range"));
    let text = scene("[sweep]\nvary = { v0 = [1.0] }\nunknown = 5\n");
    assert!(refused(&text, SweepArgs::default()).position().is_some());
}

#[test]
fn a_parameter_computed_from_a_varied_one_follows_it() {
    // h0 written as an expression of a parameter `z`: varying z moves h0 and the initial height.
    let text = scene("").replace("h0 = 5.0", "z = 0.5\nh0 = \"z*v0^2/g\"");
    let sweep = Sweep::parse(
        &text,
        "derived.toml",
        &SweepArgs {
            collect: Some(vec!["impact.t".into()]),
            ..args(&["z=0.5,2"])
        },
    )
    .expect("valid");
    for row in sweep.run(&all(&sweep), &|| {}) {
        let h0 = row.values[0] * 100.0 / 10.0;
        let k = uniform::kinematics(&params(10.0, h0));
        assert!((row.quantities[0] - k.t_impact).abs() < 1e-9);
    }
}

fn chetaev(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_chetaev"))
        .args(args)
        .output()
        .expect("the binary runs")
}

fn tmp(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("sweep")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temporary directory");
    dir
}

fn read(p: PathBuf) -> String {
    std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

#[test]
fn shards_merged_give_the_table_of_the_whole_sweep() {
    let dir = tmp("shards");
    let file = dir.join("scene.toml");
    std::fs::write(
        &file,
        scene("[sweep]\nvary = { v0 = { from = 2.0, to = 20.0, count = 7 }, h0 = [1.0, 10.0] }\n"),
    )
    .expect("written");
    let scene = file.to_string_lossy().into_owned();
    let whole = dir.join("whole");
    let out = chetaev(&[
        "sweep",
        &scene,
        "--out",
        &whole.to_string_lossy(),
        "--jobs",
        "2",
    ]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let parts = dir.join("parts");
    for k in ["1/3", "2/3", "3/3"] {
        let out = chetaev(&[
            "sweep",
            &scene,
            "--shard",
            k,
            "--out",
            &parts.to_string_lossy(),
            "--quiet",
        ]);
        assert_eq!(
            out.status.code(),
            Some(0),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let merged = dir.join("merged");
    let files: Vec<String> = (1..=3)
        .map(|k| {
            parts
                .join(format!("sweep.part-{k}-of-3.json"))
                .to_string_lossy()
                .into_owned()
        })
        .collect();
    let mut a = vec!["merge", "--out"];
    let m = merged.to_string_lossy().into_owned();
    a.push(&m);
    a.extend(files.iter().map(String::as_str));
    let out = chetaev(&a);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let table = read(whole.join("sweep.csv"));
    assert_eq!(read(merged.join("sweep.csv")), table);
    assert_eq!(table.lines().count(), 15, "a header and 14 rows");
    assert!(table.starts_with("index,v0,h0,status,impact.t,"), "{table}");
    // One varied variable with a second of two values: lines, one per value of h0.
    let svg = read(whole.join("sweep.svg"));
    assert!(svg.contains("h0 = 10"), "a line per height");
    // A shard missing is named.
    let out = chetaev(&["merge", "--out", &m, &files[0], &files[2]]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("shard(s) 2 of 3 missing"));
}

#[test]
fn the_command_exits_one_with_every_row_when_some_runs_fail() {
    let dir = tmp("failing");
    let out = chetaev(&[
        "sweep",
        &format!(
            "{}/../../scenes/uniform-projectile.toml",
            env!("CARGO_MANIFEST_DIR")
        ),
        "--vary",
        "v0=0,10",
        "--collect",
        "impact.t",
        "--out",
        &dir.to_string_lossy(),
    ]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("1 refused"), "{err}");
    let table = read(dir.join("sweep.csv"));
    let rows: Vec<&str> = table.lines().collect();
    assert_eq!(rows.len(), 3);
    assert!(rows[1].starts_with("0,0,refused,NaN,"), "{}", rows[1]);
    assert!(
        rows[2].starts_with("1,10,terminated:impact,1.08"),
        "{}",
        rows[2]
    );
    // A bad specification runs nothing and writes nothing.
    let none = tmp("none");
    let out = chetaev(&[
        "sweep",
        "--vary",
        "v0=0:1:3:log",
        "--out",
        &none.to_string_lossy(),
        &format!(
            "{}/../../scenes/uniform-projectile.toml",
            env!("CARGO_MANIFEST_DIR")
        ),
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("cannot reach or cross zero"));
    assert!(std::fs::read_dir(&none).map(|d| d.count()).unwrap_or(0) == 0);
}

#[test]
fn a_large_grid_of_two_variables_is_drawn_as_heat_maps() {
    let dir = tmp("heat");
    let out = chetaev(&[
        "sweep",
        &format!(
            "{}/../../scenes/uniform-projectile.toml",
            env!("CARGO_MANIFEST_DIR")
        ),
        "--vary",
        "v0=2:20:10",
        "--vary",
        "h0=1:100:10:log",
        "--collect",
        "impact.t,impact.x",
        "--out",
        &dir.to_string_lossy(),
        "--quiet",
    ]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for (q, unit) in [("impact.t", "s"), ("impact.x", "m")] {
        let svg = read(dir.join(format!("sweep-{q}.svg")));
        assert!(svg.contains(q) && svg.contains("h0") && svg.contains("v0"));
        // The colour bar's label carries the scene's unit.
        assert!(svg.contains(&format!("{q} [{unit}]")), "{q} [{unit}]");
        // 100 cells, then the colour bar's 64 bands.
        assert!(svg.matches("<rect").count() >= 100 + 64);
    }
}

#[cfg(feature = "parquet")]
#[test]
fn the_parquet_table_holds_the_csv_values_and_the_settings() {
    use parquet::file::reader::{FileReader, SerializedFileReader};
    use parquet::record::RowAccessor;
    let dir = tmp("parquet");
    let out = chetaev(&[
        "sweep",
        &format!(
            "{}/../../scenes/uniform-projectile.toml",
            env!("CARGO_MANIFEST_DIR")
        ),
        "--vary",
        "v0=0,5,10",
        "--collect",
        "impact.t,max_abs.mu_1",
        "--out",
        &dir.to_string_lossy(),
        "--quiet",
    ]);
    assert_eq!(out.status.code(), Some(1), "v0 = 0 is refused");
    let file = std::fs::File::open(dir.join("sweep.parquet")).expect("written");
    let reader = SerializedFileReader::new(file).expect("a Parquet file");
    let meta = reader.metadata().file_metadata();
    assert_eq!(meta.num_rows(), 3);
    let names: Vec<&str> = meta
        .schema_descr()
        .columns()
        .iter()
        .map(|c| c.name())
        .collect();
    assert_eq!(
        names,
        [
            "index",
            "v0",
            "status",
            "impact.t",
            "max_abs.mu_1",
            "steps",
            "rhs_evaluations",
            "reason"
        ]
    );
    let kv = meta.key_value_metadata().expect("metadata");
    let settings = kv
        .iter()
        .find(|k| k.key == "chetaev.sweep")
        .and_then(|k| k.value.clone())
        .expect("the settings");
    let settings: serde_json::Value = serde_json::from_str(&settings).expect("JSON");
    assert_eq!(settings["parameters"]["h0"], 5.0);
    assert_eq!(settings["variables"][0], "v0");
    assert!(kv.iter().any(|k| k.key == "chetaev.version"));
    // The rows are the CSV's, to the bit.
    let csv = read(dir.join("sweep.csv"));
    let rows: Vec<parquet::record::Row> = reader
        .get_row_iter(None)
        .expect("rows")
        .collect::<Result<_, _>>()
        .expect("readable");
    for (row, line) in rows.iter().zip(csv.lines().skip(1)) {
        let fields: Vec<&str> = line.split(',').collect();
        assert_eq!(row.get_long(0).expect("index").to_string(), fields[0]);
        assert_eq!(
            row.get_double(1).expect("v0"),
            fields[1].parse::<f64>().expect("a number")
        );
        assert_eq!(row.get_string(2).expect("status"), fields[2]);
        let t = row.get_double(3).expect("impact.t");
        let t_csv: f64 = fields[3].parse().expect("a number");
        assert!(t.to_bits() == t_csv.to_bits() || (t.is_nan() && t_csv.is_nan()));
    }
    assert!(rows[0].get_string(7).expect("reason").len() > 10);
}

#[test]
fn check_reads_the_sweep_table_as_sweep_does() {
    let good = chetaev(&[
        "check",
        &format!(
            "{}/../../scenes/uniform-projectile-sweep.toml",
            env!("CARGO_MANIFEST_DIR")
        ),
        "--out",
        &tmp("check").to_string_lossy(),
    ]);
    assert_eq!(
        good.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&good.stderr)
    );
    let text = String::from_utf8_lossy(&good.stdout);
    assert!(
        text.contains("sweep    10000 runs of v0, h0, collecting impact.t, impact.x"),
        "{text}"
    );
    let dir = tmp("check-bad");
    let file = dir.join("bad.toml");
    std::fs::write(
        &file,
        scene("[sweep]\nvary = { v0 = { from = 0.0, to = 1.0, count = 3, scale = \"log\" } }\n"),
    )
    .expect("written");
    let bad = chetaev(&[
        "check",
        &file.to_string_lossy(),
        "--out",
        &dir.to_string_lossy(),
    ]);
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("cannot reach or cross zero"));
}
