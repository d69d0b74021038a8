//! The `chetaev` command: output, files, and exit codes 0 (success), 1 (integration failed),
//! 2 (bad scene).

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn chetaev(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_chetaev"))
        .args(args)
        .output()
        .expect("the binary runs")
}

fn scene_path(name: &str) -> String {
    format!("{}/../../scenes/{name}", env!("CARGO_MANIFEST_DIR"))
}

fn tmp(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("cli")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temporary directory");
    dir
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

#[test]
fn run_prints_the_summary_and_writes_the_files() {
    let out = tmp("uniform");
    let o = chetaev(&[
        "run",
        &scene_path("uniform-projectile.toml"),
        "--out",
        out.to_str().expect("utf-8"),
    ]);
    let stdout = text(&o.stdout);
    assert_eq!(o.status.code(), Some(0), "{stdout}{}", text(&o.stderr));
    assert!(
        stdout.contains("stopped by the terminal event 'impact' at t = 1.085038501948"),
        "{stdout}"
    );
    assert!(stdout.contains("x = 9.191066572934"), "{stdout}");
    assert!(stdout.contains("accepted"), "{stdout}");
    for f in [
        "state.csv",
        "multipliers.csv",
        "energy.csv",
        "events.csv",
        "trajectory.svg",
        "multipliers.svg",
        "energy.svg",
    ] {
        assert!(out.join(f).is_file(), "{f}");
    }
    let events = std::fs::read_to_string(out.join("events.csv")).expect("events");
    assert!(
        events.starts_with("event,t,x,y,x_dot,y_dot\nimpact,1.08503850194"),
        "{events}"
    );
}

#[test]
fn quiet_prints_nothing_and_check_does_not_write() {
    let out = tmp("quiet");
    let o = chetaev(&[
        "run",
        "--quiet",
        &scene_path("classical-projectile.toml"),
        "--out",
        out.to_str().expect("utf-8"),
    ]);
    assert_eq!(o.status.code(), Some(0));
    assert!(o.stdout.is_empty() && o.stderr.is_empty());
    assert!(out.join("state.csv").is_file());

    let o = chetaev(&["check", &scene_path("your-own-constraint.toml")]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    assert!(text(&o.stdout).contains(": ok (3 coordinates, 2 constraints"));
}

fn write_scene(dir: &Path, name: &str, body: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, body).expect("write");
    p.to_str().expect("utf-8").to_string()
}

#[test]
fn a_malformed_scene_exits_with_2_and_points_at_the_line_and_column() {
    let dir = tmp("malformed");
    let uniform = std::fs::read_to_string(scene_path("uniform-projectile.toml")).expect("scene");
    let typo = uniform.replace("x_dot^2 + y_dot^2 - v0^2", "x_dot^^2 + y_dot^2 - v0^2");
    let line = typo
        .lines()
        .position(|l| l.contains("x_dot^^2"))
        .expect("line")
        + 1;
    let col = typo
        .lines()
        .nth(line - 1)
        .expect("line")
        .find("^^")
        .expect("^^")
        + 2; // second '^'
    let path = write_scene(&dir, "typo.toml", &typo);
    for command in ["run", "check"] {
        let o = chetaev(&[command, &path]);
        let stderr = text(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{command}: {stderr}");
        assert!(
            stderr.contains(&format!("typo.toml:{line}:{col}: expected")),
            "{stderr}"
        );
        assert!(stderr.contains("x_dot^^2"), "{stderr}");
        assert!(o.stdout.is_empty());
    }

    // Not TOML at all.
    let path = write_scene(&dir, "broken.toml", "[model\ncoordinates = [\"x\"]\n");
    let o = chetaev(&["run", &path]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        text(&o.stderr).contains("broken.toml:1:"),
        "{}",
        text(&o.stderr)
    );

    // An initial velocity that violates the constraint.
    let bad = uniform.replace("q_dot = [\"v0\", 0.0]", "q_dot = [\"v0\", 1.0]");
    let line = bad
        .lines()
        .position(|l| l.starts_with("q_dot"))
        .expect("line")
        + 1;
    let path = write_scene(&dir, "inconsistent.toml", &bad);
    let o = chetaev(&["check", &path]);
    assert_eq!(o.status.code(), Some(2));
    let stderr = text(&o.stderr);
    assert!(
        stderr.contains(&format!("inconsistent.toml:{line}:")),
        "{stderr}"
    );
    assert!(stderr.contains("project_velocity = true"), "{stderr}");

    // A missing file.
    let o = chetaev(&["run", &dir.join("absent.toml").to_string_lossy()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o.stderr).contains("cannot read the scene file"));
}

#[test]
fn a_failed_integration_exits_with_1_and_still_writes() {
    let dir = tmp("failed");
    let uniform = std::fs::read_to_string(scene_path("uniform-projectile.toml")).expect("scene");
    let short = uniform.replace("atol = 1e-12", "atol = 1e-12\nmax_steps = 4");
    let path = write_scene(&dir, "short.toml", &short);
    let out = dir.join("out");
    let o = chetaev(&["run", &path, "--out", out.to_str().expect("utf-8")]);
    let stdout = text(&o.stdout);
    assert_eq!(o.status.code(), Some(1), "{stdout}");
    assert!(stdout.contains("FAILED at t = "), "{stdout}");
    assert!(stdout.contains("step limit of 4"), "{stdout}");
    let state = std::fs::read_to_string(out.join("state.csv")).expect("written");
    assert!(state.lines().count() > 2, "{state}");
}
