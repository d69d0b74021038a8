//! The binaries as a user runs them: a sweep split into three shards and merged writes what the
//! whole sweep writes (measurements of time aside), output goes under the current directory,
//! `bench-report` finds criterion under `$CARGO_TARGET_DIR`, and a reader that leaves early ends
//! a binary quietly.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use serde_json::Value;

const ENSEMBLE: &str = env!("CARGO_BIN_EXE_ensemble");
const WORK_PRECISION: &str = env!("CARGO_BIN_EXE_work-precision");
const BENCH_REPORT: &str = env!("CARGO_BIN_EXE_bench-report");

/// The work-precision study cut down to seconds: two tolerances, two step counts of Rk4, one
/// timed run each, 1000 steps at most.
const TINY_STUDY: [&str; 7] = [
    "--quick",
    "--tolerances",
    "1e-3,1e-5",
    "--rk4-steps",
    "8,32",
    "--max-steps",
    "1000",
];

/// An empty directory for one test.
fn scratch(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch directory");
    dir
}

/// Runs `bin` with `args` in `cwd`; its stdout, after checking that it succeeded.
fn run(bin: &str, args: &[&str], cwd: &Path) -> String {
    let out = Command::new(bin)
        .args(args)
        .current_dir(cwd)
        .output()
        .expect("the binary starts");
    assert!(
        out.status.success(),
        "{bin} {args:?} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// Every file of a directory by name.
fn files(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    std::fs::read_dir(dir)
        .expect("output directory")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.is_file())
        .map(|p| {
            let name = p.file_name().expect("name").to_string_lossy().into_owned();
            (name, std::fs::read(&p).expect("readable"))
        })
        .collect()
}

fn read_json(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).expect("readable")).expect("JSON")
}

/// A measurement of time, or what it depends on: each shard's record, and the run times and
/// repeat counts of the items.
fn is_measurement(key: &str) -> bool {
    key == "shards" || key == "repeats" || key.ends_with("seconds")
}

/// `merged` with every measurement replaced by the one at the same place in `whole`.
fn with_measurements_of(merged: &Value, whole: &Value) -> Value {
    match (merged, whole) {
        (Value::Object(m), Value::Object(w)) => Value::Object(
            m.iter()
                .map(|(k, v)| {
                    let v = match w.get(k) {
                        Some(wv) if is_measurement(k) => wv.clone(),
                        Some(wv) => with_measurements_of(v, wv),
                        None => v.clone(),
                    };
                    (k.clone(), v)
                })
                .collect(),
        ),
        (Value::Array(m), Value::Array(w)) if m.len() == w.len() => Value::Array(
            m.iter()
                .zip(w)
                .map(|(a, b)| with_measurements_of(a, b))
                .collect(),
        ),
        _ => merged.clone(),
    }
}

fn strs(v: &[String]) -> Vec<&str> {
    v.iter().map(String::as_str).collect()
}

/// Runs `bin` on the whole sweep and as three shards merged, in `dir`, and checks that the merge
/// writes what the whole run writes: the same files; with the measurements of the whole run put
/// into the merged data, `merge` writes every file of the whole run byte for byte. Returns the
/// directories of the whole and of the merged run.
fn shards_merge_to_the_whole(
    bin: &str,
    sweep: &str,
    args: &[&str],
    dir: &Path,
) -> (PathBuf, PathBuf) {
    let with = |extra: &[&str]| -> Vec<String> {
        args.iter().chain(extra).map(ToString::to_string).collect()
    };
    run(bin, &strs(&with(&["--out", "whole"])), dir);
    for k in 1..=3 {
        let shard = format!("{k}/3");
        run(
            bin,
            &strs(&with(&["--shard", &shard, "--out", "parts"])),
            dir,
        );
    }
    // In no particular order.
    let parts: Vec<String> = [3, 1, 2]
        .iter()
        .map(|k| format!("parts/{sweep}.part-{k}-of-3.json"))
        .collect();
    let mut merge = vec!["merge", "--out", "merged"];
    merge.extend(strs(&parts));
    run(bin, &merge, dir);

    let (whole, merged) = (files(&dir.join("whole")), files(&dir.join("merged")));
    assert_eq!(
        whole.keys().collect::<Vec<_>>(),
        merged.keys().collect::<Vec<_>>(),
        "the merge writes other files than the whole run"
    );
    let data = format!("{sweep}.json");
    let transplanted = with_measurements_of(
        &read_json(&dir.join("merged").join(&data)),
        &read_json(&dir.join("whole").join(&data)),
    );
    std::fs::create_dir_all(dir.join("check")).expect("directory");
    std::fs::write(
        dir.join("check").join(&data),
        serde_json::to_string(&transplanted).expect("serialises"),
    )
    .expect("writable");
    let check = format!("check/{data}");
    run(bin, &["merge", "--out", "again", &check], dir);
    let again = files(&dir.join("again"));
    for (name, bytes) in &whole {
        assert!(
            again.get(name) == Some(bytes),
            "{name} of the merged shards differs from the whole run's beyond its measurements"
        );
    }
    (dir.join("whole"), dir.join("merged"))
}

#[test]
fn an_ensemble_in_three_shards_merges_into_the_whole_run() {
    let dir = scratch("ensemble-shards");
    let (whole, merged) =
        shards_merge_to_the_whole(ENSEMBLE, "ensemble", &["--n", "4", "--threads", "2"], &dir);
    // What holds no time at all is equal as written.
    for name in ["ensemble.csv", "ensemble-ratio.svg", "ensemble-error.svg"] {
        assert_eq!(
            std::fs::read(whole.join(name)).expect("written"),
            std::fs::read(merged.join(name)).expect("written"),
            "{name}"
        );
    }
    let csv = std::fs::read_to_string(merged.join("ensemble.csv")).expect("written");
    assert_eq!(csv.lines().count(), 1 + 16, "a header and 4 × 4 points");
    // The error diagram marks the largest error of the CSV, with its value.
    let largest = csv
        .lines()
        .skip(1)
        .filter(|l| l.ends_with(','))
        .map(|l| {
            l.split(',')
                .nth(4)
                .expect("ratio_error")
                .parse::<f64>()
                .expect("a number")
        })
        .fold(0.0f64, f64::max);
    let error_svg = std::fs::read_to_string(merged.join("ensemble-error.svg")).expect("written");
    let mark = format!("largest: {:.1e} at z = ", largest.max(1e-17));
    assert!(error_svg.contains(&mark), "{mark} in {error_svg}");
    assert!(error_svg.contains("all 16 points"), "{error_svg}");
    // The speed-up with the range of its rounds: three interleaved pairs per run, so nine over
    // three shards; each run records the seconds of every round.
    let md = |dir: &Path| std::fs::read_to_string(dir.join("ensemble.md")).expect("written");
    assert!(
        md(&whole).contains("over 3 interleaved pairs"),
        "{}",
        md(&whole)
    );
    assert!(
        md(&merged).contains("over 9 interleaved pairs"),
        "{}",
        md(&merged)
    );
    let part = read_json(&dir.join("parts/ensemble.part-2-of-3.json"));
    let text = part.to_string();
    for key in ["serial_rounds_seconds", "parallel_rounds_seconds"] {
        assert!(text.contains(key), "{key} in {text}");
    }
}

#[test]
fn a_work_precision_study_in_three_shards_merges_into_the_whole_run() {
    let dir = scratch("work-precision-shards");
    // The whole of `--quick` (about a second): its tightest tolerances take enough right-hand
    // sides for a problem to switch to machine code part way, which gave a shard another last bit
    // of an error than the whole run until the study made the machine code first.
    let (whole, merged) =
        shards_merge_to_the_whole(WORK_PRECISION, "work-precision", &["--quick"], &dir);
    // The CSV files without their columns of time are equal as written.
    let untimed = |path: &Path| -> Vec<Vec<String>> {
        let text = std::fs::read_to_string(path).expect("written");
        let mut lines = text.lines();
        let header: Vec<&str> = lines.next().expect("a header").split(',').collect();
        let timed: Vec<usize> = ["seconds", "repeats"]
            .iter()
            .map(|c| header.iter().position(|h| h == c).expect("column"))
            .collect();
        // No field of these CSV files holds a quoted comma before the columns of time.
        text.lines()
            .map(|l| {
                l.split(',')
                    .enumerate()
                    .filter(|(i, _)| !timed.contains(i))
                    .map(|(_, f)| f.to_string())
                    .collect()
            })
            .collect()
    };
    // Every work-precision diagram says which error it plots.
    for name in [
        "uniform.svg",
        "classical.svg",
        "stiff.svg",
        "particle3d.svg",
        "two-runners.svg",
        "limit-full.svg",
        "limit-reduced.svg",
    ] {
        let svg = std::fs::read_to_string(whole.join(name)).expect("written");
        assert!(
            svg.contains("Error of the end state (q, q̇)") && svg.contains("end-state error: max_i"),
            "{name} defines its error"
        );
    }
    for scene in [
        "uniform",
        "classical",
        "stiff",
        "particle3d",
        "two-runners",
        "limit",
    ] {
        let name = format!("{scene}.csv");
        assert_eq!(
            untimed(&whole.join(&name)),
            untimed(&merged.join(&name)),
            "{name}"
        );
    }
}

#[test]
fn parts_that_miss_a_shard_are_refused_with_the_shard_named() {
    let dir = scratch("ensemble-missing");
    for k in [1, 3] {
        let shard = format!("{k}/3");
        run(
            ENSEMBLE,
            &["--n", "2", "--shard", &shard, "--out", "parts"],
            &dir,
        );
    }
    let out = Command::new(ENSEMBLE)
        .args([
            "merge",
            "--out",
            "merged",
            "parts/ensemble.part-1-of-3.json",
            "parts/ensemble.part-3-of-3.json",
        ])
        .current_dir(&dir)
        .output()
        .expect("starts");
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("shard(s) 2 of 3 missing"), "{err}");
    assert!(!dir.join("merged/ensemble.md").exists());
    // Shards count from 1.
    let out = Command::new(ENSEMBLE)
        .args(["--n", "2", "--shard", "0/3"])
        .current_dir(&dir)
        .output()
        .expect("starts");
    assert!(!out.status.success());
}

#[test]
fn output_goes_under_the_current_directory_by_default() {
    let dir = scratch("default-out");
    run(ENSEMBLE, &["--n", "2"], &dir);
    let out = dir.join("chetaev-bench-out/ensemble");
    for name in ["ensemble.md", "ensemble.csv", "ensemble.json"] {
        assert!(out.join(name).is_file(), "{name} not in {}", out.display());
    }
}

#[test]
fn a_reader_that_leaves_early_ends_the_binaries_quietly() {
    let dir = scratch("closed-pipe");
    for (bin, args) in [
        (ENSEMBLE, vec!["--n", "2"]),
        (
            WORK_PRECISION,
            TINY_STUDY
                .iter()
                .copied()
                .chain(["--shard", "1/29"])
                .collect(),
        ),
    ] {
        let mut child = Command::new(bin)
            .args(&args)
            .current_dir(&dir)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("starts");
        // The reader leaves before the binary has written anything.
        drop(child.stdout.take());
        let out = child.wait_with_output().expect("ends");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{bin}: {:?}, {err}", out.status);
        assert!(!err.contains("panicked"), "{bin}: {err}");
    }
}

#[test]
fn bench_report_reads_criterion_under_cargo_target_dir() {
    let dir = scratch("bench-report");
    let target = dir.join("elsewhere");
    for (name, ns) in [("n02_k00", 100.0), ("n04_k00", 400.0)] {
        let new = target.join("criterion/rhs_cost").join(name).join("new");
        std::fs::create_dir_all(&new).expect("directory");
        let benchmark = format!(r#"{{"group_id": "rhs_cost", "function_id": "{name}"}}"#);
        let estimates = format!(
            r#"{{"median": {{"point_estimate": {ns}, "confidence_interval": {{"lower_bound": {ns}, "upper_bound": {ns}}}}}}}"#
        );
        std::fs::write(new.join("benchmark.json"), benchmark).expect("writable");
        std::fs::write(new.join("estimates.json"), estimates).expect("writable");
    }
    let out = Command::new(BENCH_REPORT)
        .current_dir(&dir)
        .env("CARGO_TARGET_DIR", &target)
        .env_remove("CRITERION_HOME")
        .output()
        .expect("starts");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let md = std::fs::read_to_string(dir.join("chetaev-bench-out/bench-report/benchmarks.md"))
        .expect("benchmarks.md under the current directory");
    assert!(md.contains("| 4 |"), "{md}");
    let rhs = std::fs::read_to_string(dir.join("chetaev-bench-out/bench-report/rhs-cost.csv"))
        .expect("rhs-cost.csv");
    assert!(rhs.contains("static,4,0,400,400,400"), "{rhs}");
    // Two sizes below 6: the fit over n ≥ 6 has no points, and says so rather than NaN.
    let summary = String::from_utf8_lossy(&out.stdout);
    assert!(
        !md.contains("NaN") && !summary.contains("NaN"),
        "{md}\n{summary}"
    );
    assert!(md.contains("| static | k = 0 | 2.00 | – |"), "{md}");
    // Without results nothing is written, not even the output folder.
    let out = Command::new(BENCH_REPORT)
        .args(["--criterion", "nowhere", "--out", "empty"])
        .current_dir(&dir)
        .output()
        .expect("starts");
    assert!(!out.status.success());
    assert!(!dir.join("empty").exists());
}

#[test]
fn an_argument_that_makes_no_sense_is_refused_with_status_2_before_any_output() {
    let dir = scratch("bad-arguments");
    for (bin, args, names) in [
        (ENSEMBLE, vec!["--hi", "inf"], "--hi inf"),
        (ENSEMBLE, vec!["--lo", "5", "--hi", "1"], "--lo 5 --hi 1"),
        (ENSEMBLE, vec!["--n", "1"], "--n 1"),
        (ENSEMBLE, vec!["--threads", "0"], "--threads 0"),
        (ENSEMBLE, vec!["--g", "nan"], "--g NaN"),
        (ENSEMBLE, vec!["--tol", "0"], "--tol 0e0"),
        (ENSEMBLE, vec!["--tol", "10"], "--tol 1e1"),
        (ENSEMBLE, vec!["--threads", "1"], "--threads 1"),
        (ENSEMBLE, vec!["--g", "-9.81"], "--g -9.81"),
        (
            WORK_PRECISION,
            vec!["--tolerances", "-1e-3"],
            "between 0 and 1",
        ),
        (WORK_PRECISION, vec!["--tolerances", "10"], "--tolerances"),
        (
            WORK_PRECISION,
            vec!["--tolerances", "1e-4,nan"],
            "--tolerances",
        ),
        (WORK_PRECISION, vec!["--rk4-steps", "0"], "--rk4-steps"),
        (
            WORK_PRECISION,
            vec!["--rk4-steps", "16,1000000000"],
            "--rk4-steps",
        ),
        (WORK_PRECISION, vec!["--max-steps", "0"], "--max-steps"),
        // Cannot be read at all: refused by the parser, with the same status.
        (ENSEMBLE, vec!["--n", "two"], "--n"),
    ] {
        let out = Command::new(bin)
            .args(&args)
            .args(["--out", "out"])
            .current_dir(&dir)
            .output()
            .expect("starts");
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{bin} {args:?}: {err}");
        assert!(err.contains(names), "{bin} {args:?}: {err}");
        assert!(out.stdout.is_empty(), "{bin} {args:?}");
        assert!(
            !dir.join("out").exists(),
            "{bin} {args:?} made its output folder"
        );
    }
}
