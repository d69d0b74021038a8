//! The `chetaev` command: output, files, and exit codes 0 (success), 1 (integration failed),
//! 2 (bad scene).

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

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
    // Advice in the scene's keys, not the library's names.
    assert!(
        stdout.contains("raise max_steps under [solve] (now 4)"),
        "{stdout}"
    );
    assert!(!stdout.contains("Options::"), "{stdout}");
    let state = std::fs::read_to_string(out.join("state.csv")).expect("written");
    assert!(state.lines().count() > 2, "{state}");
    // The time printed is where the step limit was met: the last row written, to the 13
    // significant digits printed.
    let last = state
        .lines()
        .last()
        .expect("row")
        .split(',')
        .next()
        .expect("t");
    // The scene declares t in seconds: `FAILED at t = 0.4 s: ...`.
    let printed = stdout
        .split("FAILED at t = ")
        .nth(1)
        .and_then(|r| r.split(':').next())
        .and_then(|t| t.strip_suffix(" s"))
        .expect("t in s");
    let (last, printed): (f64, f64) = (
        last.parse().expect("number"),
        printed.parse().expect("number"),
    );
    assert!(
        (printed - last).abs() <= 1e-12 * last.abs(),
        "failure at {printed}, last row at {last}"
    );

    // Quiet: the same, on standard error only.
    let o = chetaev(&[
        "run",
        "--quiet",
        &path,
        "--out",
        out.to_str().expect("utf-8"),
    ]);
    let stderr = text(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{stderr}");
    assert!(o.stdout.is_empty());
    assert!(
        stderr.starts_with("error: the integration failed at t = ")
            && stderr.contains("the step limit of 4 steps was reached\n  advice: raise max_steps"),
        "{stderr}"
    );
}

/// Runs the command with standard output a pipe that is closed before anything is printed.
fn with_stdout_closed(args: &[&str], dir: &Path) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_chetaev"))
        .args(args)
        .current_dir(dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the binary runs");
    drop(child.stdout.take());
    child.wait_with_output().expect("it ends")
}

#[test]
fn a_closed_standard_output_ends_the_printing_quietly() {
    let dir = tmp("pipe");
    let scene = scene_path("uniform-projectile.toml");
    for args in [
        vec!["run", scene.as_str(), "--out", "out"],
        vec!["check", scene.as_str(), "--out", "out"],
    ] {
        let o = with_stdout_closed(&args, &dir);
        let stderr = text(&o.stderr);
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
        assert_eq!(o.status.code(), Some(0), "{args:?}: {stderr}");
    }
    // The run still wrote its files.
    assert!(dir.join("out/state.csv").is_file());
    assert!(dir.join("out/manifest.toml").is_file());
}

/// Standard output that refuses every write (`/dev/full`): the text is lost, and the command
/// says so with status 2 instead of reporting success.
#[cfg(target_os = "linux")]
#[test]
fn a_standard_output_that_cannot_be_written_is_an_error() {
    let dir = tmp("full");
    let scene = scene_path("uniform-projectile.toml");
    for args in [
        vec!["describe", scene.as_str()],
        vec!["describe", "--latex", scene.as_str()],
        vec!["check", scene.as_str(), "--out", "out"],
    ] {
        let full = std::fs::OpenOptions::new()
            .write(true)
            .open("/dev/full")
            .expect("/dev/full");
        let o = Command::new(env!("CARGO_BIN_EXE_chetaev"))
            .args(&args)
            .current_dir(&dir)
            .stdout(full)
            .output()
            .expect("the binary runs");
        let stderr = text(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(
            stderr.contains("error: cannot write to standard output"),
            "{args:?}: {stderr}"
        );
    }
}

fn short_scene(dir: &Path) -> String {
    let uniform = std::fs::read_to_string(scene_path("uniform-projectile.toml")).expect("scene");
    write_scene(
        dir,
        "short.toml",
        &uniform.replace("atol = 1e-12", "atol = 1e-12\nmax_steps = 4"),
    )
}

#[test]
fn an_output_directory_that_cannot_be_made_is_refused_before_integrating() {
    let dir = tmp("unwritable");
    let path = short_scene(&dir);
    std::fs::write(dir.join("a-file"), "not a directory").expect("write");
    for (out, says) in [
        ("a-file", "it is a file"),
        ("a-file/sub", "a-file is a file"),
    ] {
        let out = dir.join(out);
        for command in ["run", "check"] {
            let o = chetaev(&[command, &path, "--out", out.to_str().expect("utf-8")]);
            let stderr = text(&o.stderr);
            // 2, not the 1 of the integration that would have failed: nothing was integrated.
            assert_eq!(o.status.code(), Some(2), "{command} {out:?}: {stderr}");
            assert!(o.stdout.is_empty(), "{command}: {}", text(&o.stdout));
            assert!(stderr.contains("output directory"), "{stderr}");
            assert!(stderr.contains(says), "{stderr}");
        }
    }
    // `check` leaves nothing behind, not even the directory it would create.
    let fresh = dir.join("fresh/deeper");
    let o = chetaev(&["check", &path, "--out", fresh.to_str().expect("utf-8")]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    assert!(text(&o.stdout).contains(&format!("into {}", fresh.display())));
    assert!(!dir.join("fresh").exists());
    assert_eq!(std::fs::read_dir(&dir).expect("dir").count(), 2);
}

fn manifest_files(dir: &Path) -> Vec<String> {
    let m = std::fs::read_to_string(dir.join("manifest.toml")).expect("manifest");
    let line = m
        .lines()
        .find(|l| l.starts_with("files = "))
        .expect("files");
    line.trim_start_matches("files = [")
        .trim_end_matches(']')
        .split(", ")
        .map(|f| f.trim_matches('"').to_string())
        .collect()
}

#[test]
fn a_run_lists_its_files_and_refuses_to_mix_them_with_another_runs() {
    let dir = tmp("manifest");
    let out = dir.join("out");
    let out_s = out.to_str().expect("utf-8");
    std::fs::create_dir_all(&out).expect("dir");
    std::fs::write(out.join("notes.txt"), "mine").expect("write");
    let uniform = scene_path("uniform-projectile.toml");
    let classical = scene_path("classical-projectile.toml");

    let o = chetaev(&["run", &uniform, "--out", out_s]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let first = manifest_files(&out);
    assert_eq!(first.len(), 7, "{first:?}");
    assert!(first.contains(&"multipliers.csv".to_string()));
    // The same scene again: it replaces its own files, no flag needed.
    let o = chetaev(&["run", &uniform, "--out", out_s]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));

    // Another scene writes no multipliers: the earlier ones would be left beside its files.
    let o = chetaev(&["run", &classical, "--out", out_s]);
    let stderr = text(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{stderr}");
    assert!(o.stdout.is_empty(), "refused before integrating");
    assert!(
        stderr.contains("multipliers.csv, multipliers.svg"),
        "{stderr}"
    );
    assert!(stderr.contains("--force"), "{stderr}");
    let o = chetaev(&["check", &classical, "--out", out_s]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o.stderr));

    let o = chetaev(&["run", &classical, "--out", out_s, "--force"]);
    let stdout = text(&o.stdout);
    assert_eq!(o.status.code(), Some(0), "{stdout}{}", text(&o.stderr));
    assert!(
        stdout.contains("removed  multipliers.csv, multipliers.svg"),
        "{stdout}"
    );
    assert!(!out.join("multipliers.csv").exists());
    assert_eq!(manifest_files(&out).len(), 5);
    assert_eq!(
        std::fs::read_to_string(out.join("notes.txt"))
            .ok()
            .as_deref(),
        Some("mine")
    );

    // A file no run wrote is not overwritten without --force.
    let other = dir.join("other");
    std::fs::create_dir_all(&other).expect("dir");
    std::fs::write(other.join("state.csv"), "precious").expect("write");
    let o = chetaev(&["run", &classical, "--out", other.to_str().expect("utf-8")]);
    let stderr = text(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("would overwrite 1 file"), "{stderr}");
    // One file that no run wrote: "it", and --force overwrites it (no earlier run is implied).
    assert!(
        stderr.contains("remove it, or pass --force to overwrite it"),
        "{stderr}"
    );
    assert_eq!(
        std::fs::read_to_string(other.join("state.csv"))
            .ok()
            .as_deref(),
        Some("precious")
    );
    let o = chetaev(&[
        "run",
        &classical,
        "--out",
        other.to_str().expect("utf-8"),
        "--overwrite",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    assert!(std::fs::read_to_string(other.join("state.csv"))
        .expect("csv")
        .starts_with("t,x,y"));
}

#[test]
fn the_output_directory_is_relative_to_the_working_directory_and_printed_resolved() {
    let dir = tmp("relative");
    let work = dir.join("work");
    std::fs::create_dir_all(&work).expect("dir");
    let classical =
        std::fs::read_to_string(scene_path("classical-projectile.toml")).expect("scene");
    let scenes = dir.join("scenes");
    std::fs::create_dir_all(&scenes).expect("dir");
    let path = write_scene(
        &scenes,
        "up.toml",
        &classical.replace(
            "directory = \"out/classical-projectile\"",
            "directory = \"../elsewhere/./out\"",
        ),
    );
    let o = Command::new(env!("CARGO_BIN_EXE_chetaev"))
        .args(["run", &path])
        .current_dir(&work)
        .output()
        .expect("runs");
    let stdout = text(&o.stdout);
    assert_eq!(o.status.code(), Some(0), "{stdout}{}", text(&o.stderr));
    let want = std::fs::canonicalize(dir.join("elsewhere/out")).expect("written");
    assert!(want.join("state.csv").is_file());
    assert!(
        stdout.contains(&format!("into {}\n", want.display())),
        "{stdout}"
    );
    assert!(!scenes.join("../elsewhere/out").join("x").exists());
}

#[test]
fn an_endless_or_huge_scene_file_is_refused() {
    let o = chetaev(&["check", "/dev/zero"]);
    let stderr = text(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("larger than 16777216 bytes"), "{stderr}");
    let dir = tmp("huge");
    let path = dir.join("huge.toml");
    let mut text_ = String::from("# ");
    text_.push_str(&"x".repeat(17 << 20));
    std::fs::write(&path, text_).expect("write");
    let o = chetaev(&["run", path.to_str().expect("utf-8")]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        text(&o.stderr).contains("larger than"),
        "{}",
        text(&o.stderr)
    );
    std::fs::write(&path, [b'#', 0xff, b'\n']).expect("write");
    let o = chetaev(&["check", path.to_str().expect("utf-8")]);
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o.stderr).contains("not UTF-8"), "{}", text(&o.stderr));
}

#[test]
fn a_nan_written_makes_the_exit_code_1_and_the_summary_says_where() {
    let dir = tmp("nan");
    let classical =
        std::fs::read_to_string(scene_path("classical-projectile.toml")).expect("scene");
    // sqrt(y - 2) is NaN once the projectile is below y = 2: y = 5 − 5t², so for t > √0.6 ≈ 0.775,
    // at 23 of the 101 output times from 0 to the impact at t = 1.
    let path = write_scene(
        &dir,
        "nan.toml",
        &format!(
            "{}\n[output.quantities]\nroot = \"sqrt(y - 2)\"\n",
            classical.replace(
                "tables = [\"state\", \"energy\", \"events\"]",
                "tables = [\"state\", \"quantities\"]",
            )
        ),
    );
    let out = dir.join("out");
    for quiet in [false, true] {
        let mut args = vec!["run", &path, "--out", out.to_str().expect("utf-8")];
        if quiet {
            args.push("--quiet");
        }
        let o = chetaev(&args);
        let (stdout, stderr) = (text(&o.stdout), text(&o.stderr));
        assert_eq!(o.status.code(), Some(1), "{stdout}{stderr}");
        let said = if quiet { &stderr } else { &stdout };
        assert!(
            said.contains("the quantity 'root' is NaN or infinite at 23 of 101 output points"),
            "{said}"
        );
    }
    assert!(std::fs::read_to_string(out.join("quantities.csv"))
        .expect("csv")
        .contains("NaN"));
}

#[test]
fn check_counts_agree_with_their_nouns() {
    let dir = tmp("nouns");
    let classical =
        std::fs::read_to_string(scene_path("classical-projectile.toml")).expect("scene");
    let path = write_scene(
        &dir,
        "one.toml",
        &classical
            .replace(
                "tables = [\"state\", \"energy\", \"events\"]",
                "tables = [\"state\"]",
            )
            .replace(
                "pictures = [\"trajectory\", \"energy\"]",
                "pictures = [\"trajectory\"]",
            ),
    );
    let o = chetaev(&[
        "check",
        &path,
        "--out",
        dir.join("o").to_str().expect("utf-8"),
    ]);
    let stdout = text(&o.stdout);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    assert!(
        stdout.contains(
            ": ok (2 coordinates, 0 constraints, 1 event, method Dop853, 1 table, 1 picture)"
        ),
        "{stdout}"
    );
}

#[test]
fn describe_shows_the_proved_structure_and_the_derived_equations_in_text_and_latex() {
    let scene = scene_path("uniform-projectile.toml");
    let o = chetaev(&["describe", &scene]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        text.contains("structure  (proved from the recorded expressions)"),
        "{text}"
    );
    assert!(text.contains("J[1,1]     = 2·x_dot"), "{text}");
    let o = chetaev(&["describe", "--latex", &scene]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let latex = String::from_utf8_lossy(&o.stdout);
    assert!(
        latex.contains("\\begin{align*}") && latex.contains("\\end{align*}"),
        "{latex}"
    );
    assert!(latex.contains("J_{1,1} &= 2 \\dot{x}"), "{latex}");
}

#[test]
fn help_gives_each_command_its_own_description() {
    let o = chetaev(&["--help"]);
    assert_eq!(o.status.code(), Some(0));
    let help = text(&o.stdout);
    let line = |command: &str| {
        help.lines()
            .find(|l| l.trim_start().starts_with(&format!("{command} ")))
            .unwrap_or_else(|| panic!("{help}"))
            .to_string()
    };
    assert!(line("run").contains("Solve a scene"), "{help}");
    assert!(
        line("check").contains("Parse and validate a scene"),
        "{help}"
    );
    let describe = line("describe");
    assert!(describe.contains("Show the equations"), "{help}");
    assert!(!describe.contains("Parse and validate"), "{help}");
}

#[test]
fn a_grid_that_starts_after_a_terminal_event_stops_the_motion_is_refused() {
    // y = 1 − g t²/2 reaches the ground at t = √(2/9.81) ≈ 0.4515, before the grid's start.
    let dir = tmp("grid-after-stop");
    let scene = |from: f64| {
        format!(
            "[model]\ncoordinates = [\"y\"]\nlagrangian = \"0.5*y_dot^2 - 9.81*y\"\n\
             [initial]\nq = [1.0]\nq_dot = [0.0]\n[solve]\nt_end = 3.0\n\
             [[events]]\nname = \"ground\"\nexpression = \"y\"\ndirection = \"falling\"\n\
             terminal = true\n[output]\ntimes = {{ from = {from:?}, count = 3 }}\n\
             tables = [\"state\"]\n"
        )
    };
    let path = write_scene(&dir, "late.toml", &scene(1.0));
    let out = dir.join("out");
    let o = chetaev(&["run", &path, "--out", out.to_str().expect("utf-8")]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o.stdout));
    assert!(
        text(&o.stderr).contains("stops the motion earlier, at t = 0.45"),
        "{}",
        text(&o.stderr)
    );
    // Starting before the stop, the grid runs to it: three rows, the last at the event.
    let path = write_scene(&dir, "early.toml", &scene(0.1));
    let o = chetaev(&["run", &path, "--out", out.to_str().expect("utf-8")]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let csv = std::fs::read_to_string(out.join("state.csv")).expect("state.csv");
    let last: f64 = csv
        .lines()
        .last()
        .and_then(|l| l.split(',').next())
        .expect("a row")
        .parse()
        .expect("t");
    assert!((last - (2.0 / 9.81f64).sqrt()).abs() < 1e-9, "{csv}");
}

#[test]
fn a_scene_that_is_not_utf8_is_refused_at_its_line_and_column() {
    let dir = tmp("latin1");
    let path = dir.join("latin1.toml");
    // "é" in Latin-1, one byte 0xE9, in a comment on line 2.
    let mut bytes = b"[model]\n# caf".to_vec();
    bytes.push(0xE9);
    bytes.extend_from_slice(b"\ncoordinates = [\"x\"]\n");
    std::fs::write(&path, bytes).expect("writable");
    let o = chetaev(&["check", path.to_str().expect("utf-8")]);
    assert_eq!(o.status.code(), Some(2));
    let err = text(&o.stderr);
    assert!(
        err.contains("latin1.toml:2:6: this byte is not UTF-8"),
        "{err}"
    );
    assert!(err.contains("save it as UTF-8"), "{err}");
}

/// `x = cos t` to `t_end`, with an event at each zero of `x` going down and one going up: 64 of
/// them to t = 200. `tables` is the `[output] tables` line, or empty.
fn oscillator(dir: &Path, tables: &str) -> String {
    write_scene(
        dir,
        "oscillator.toml",
        &format!(
            "[model]\ncoordinates = [\"x\"]\nlagrangian = \"0.5*x_dot^2 - 0.5*x^2\"\n\
             [initial]\nq = [1.0]\nq_dot = [0.0]\n[solve]\nt_end = 200.0\nrtol = 1e-12\n\
             atol = 1e-12\n[[events]]\nname = \"down\"\nexpression = \"x\"\n\
             direction = \"falling\"\n[[events]]\nname = \"up\"\nexpression = \"x\"\n\
             direction = \"rising\"\n[output]\n{tables}\n"
        ),
    )
}

/// The time printed after `label t = ` on the line that holds it.
fn time_after(line: &str, label: &str) -> f64 {
    line.split(&format!("{label} t = "))
        .nth(1)
        .and_then(|r| r.split(',').next())
        .and_then(|t| t.trim().parse().ok())
        .unwrap_or_else(|| panic!("no time after '{label}' in {line}"))
}

#[test]
fn many_events_are_summarised_per_event_with_their_first_and_last() {
    let dir = tmp("many-events");
    let path = oscillator(&dir, "");
    let out = dir.join("out");
    let o = chetaev(&["run", &path, "--out", out.to_str().expect("utf-8")]);
    let stdout = text(&o.stdout);
    assert_eq!(o.status.code(), Some(0), "{stdout}{}", text(&o.stderr));
    let lines: Vec<&str> = stdout.lines().collect();
    // Two events: a heading, and per event its count, first and last; the whole summary is short.
    assert!(lines.len() <= 16, "{stdout}");
    let heading = lines
        .iter()
        .position(|l| l.starts_with("  events   64 located"))
        .unwrap_or_else(|| panic!("{stdout}"));
    assert!(
        lines[heading].contains("add \"events\" to tables under [output]"),
        "{stdout}"
    );
    let pi = std::f64::consts::PI;
    // x = cos t goes down through 0 at π/2 + 2kπ, up at 3π/2 + 2kπ: 32 of each before 200.
    let expected = [
        ("down", pi / 2.0, pi / 2.0 + 62.0 * pi),
        ("up", 1.5 * pi, 1.5 * pi + 62.0 * pi),
    ];
    for (k, (name, first, last)) in expected.iter().enumerate() {
        let at = heading + 1 + 3 * k;
        assert!(
            lines[at].trim_start().starts_with(name) && lines[at].ends_with("32 times"),
            "{stdout}"
        );
        let (f, l) = (
            time_after(lines[at + 1], "first"),
            time_after(lines[at + 2], "last "),
        );
        assert!(
            (f - first).abs() < 1e-8,
            "first {name} at {f}, want {first}"
        );
        assert!((l - last).abs() < 1e-8, "last {name} at {l}, want {last}");
    }

    // With the events table asked for, the summary points at it, and it holds every event.
    let path = oscillator(&dir, "tables = [\"events\"]");
    let o = chetaev(&[
        "run",
        &path,
        "--out",
        out.to_str().expect("utf-8"),
        "--force",
    ]);
    let stdout = text(&o.stdout);
    assert_eq!(o.status.code(), Some(0), "{stdout}{}", text(&o.stderr));
    assert!(
        stdout.contains("64 located; of each event, how many, the first and the last (all of them are in events.csv)"),
        "{stdout}"
    );
    let events = std::fs::read_to_string(out.join("events.csv")).expect("events.csv");
    assert_eq!(events.lines().count(), 1 + 64, "{events}");
    assert_eq!(
        events.lines().filter(|l| l.starts_with("down,")).count(),
        32
    );
}

#[test]
fn a_few_events_are_listed_one_by_one() {
    let dir = tmp("few-events");
    let path = oscillator(&dir, "");
    let short = std::fs::read_to_string(&path)
        .expect("scene")
        .replace("t_end = 200.0", "t_end = 10.0");
    let path = write_scene(&dir, "short.toml", &short);
    let o = chetaev(&[
        "run",
        &path,
        "--out",
        dir.join("out").to_str().expect("utf-8"),
    ]);
    let stdout = text(&o.stdout);
    assert_eq!(o.status.code(), Some(0), "{stdout}{}", text(&o.stderr));
    // Zeros at π/2, 3π/2, 5π/2: three lines, each with its state.
    let events: Vec<&str> = stdout
        .lines()
        .skip_while(|l| !l.starts_with("  events"))
        .take_while(|l| l.starts_with("  events") || l.starts_with("           "))
        .collect();
    assert_eq!(events.len(), 3, "{stdout}");
    assert!(!stdout.contains("located"), "{stdout}");
    assert!(
        events[1].contains("up") && events[1].contains("x_dot = 1"),
        "{stdout}"
    );
}

#[test]
fn a_failed_run_says_why_on_standard_error_too() {
    let dir = tmp("failed-stderr");
    let path = short_scene(&dir);
    let o = chetaev(&[
        "run",
        &path,
        "--out",
        dir.join("out").to_str().expect("utf-8"),
    ]);
    let (stdout, stderr) = (text(&o.stdout), text(&o.stderr));
    assert_eq!(o.status.code(), Some(1), "{stdout}{stderr}");
    // The summary keeps its status and advice lines; standard error has the same reason.
    assert!(stdout.contains("  status   FAILED at t = "), "{stdout}");
    assert!(stdout.contains("  advice   raise max_steps"), "{stdout}");
    assert!(
        stderr.starts_with("error: the integration failed at t = ")
            && stderr.contains("the step limit of 4 steps was reached\n  advice: raise max_steps"),
        "{stderr}"
    );
}

#[test]
fn the_help_lists_the_exit_codes() {
    for args in [vec!["run", "--help"], vec!["--help"]] {
        let o = chetaev(&args);
        let help = text(&o.stdout);
        assert_eq!(o.status.code(), Some(0), "{args:?}: {}", text(&o.stderr));
        assert!(help.contains("Exit codes:"), "{args:?}: {help}");
        for says in [
            "0  ",
            "1  ",
            "the integration failed, or a value written is NaN or infinite",
            "2  the scene cannot be run as written",
            "the output directory cannot be used",
            "standard output cannot be written",
        ] {
            assert!(help.contains(says), "{args:?}: '{says}' in {help}");
        }
    }
    let help = text(&chetaev(&["run", "--help"]).stdout);
    assert!(
        help.contains(
            "0  the end time or a terminal event was reached, and every value written is finite"
        ),
        "{help}"
    );
    let help = text(&chetaev(&["check", "--help"]).stdout);
    assert!(help.contains("Exit codes: 0 the scene is valid"), "{help}");
}

#[test]
fn an_e_read_as_eulers_number_is_warned_of_by_check_and_run() {
    let dir = tmp("euler");
    let body = "[parameters]\nB = 1.0\n[model]\ncoordinates = [\"x\", \"y\"]\n\
                lagrangian = \"0.5*(x_dot^2 + y_dot^2)\"\nforces = [\"e*B*y_dot\", \"-e*B*x_dot\"]\n\
                [initial]\nq = [0.0, 0.0]\nq_dot = [1.0, 0.0]\n[solve]\nt_end = 1.0\n";
    let path = write_scene(&dir, "euler.toml", body);
    let out = dir.join("out");
    let out = out.to_str().expect("utf-8");
    for args in [
        vec!["check", &path, "--out", out],
        vec!["run", &path, "--out", out],
    ] {
        let o = chetaev(&args);
        let stderr = text(&o.stderr);
        assert_eq!(o.status.code(), Some(0), "{args:?}: {stderr}");
        assert_eq!(stderr.matches("warning: ").count(), 2, "{args:?}: {stderr}");
        assert!(
            stderr.contains("euler.toml:6:12: 'e' is Euler's number"),
            "{args:?}: {stderr}"
        );
        assert!(stderr.contains("exp(1)"), "{args:?}: {stderr}");
        assert!(stderr.contains("6 | forces"), "{args:?}: {stderr}");
    }
    // Quiet prints nothing but errors; a declared e is no warning.
    let o = chetaev(&["run", "--quiet", &path, "--out", out]);
    assert!(o.stderr.is_empty(), "{}", text(&o.stderr));
    let path = write_scene(
        &dir,
        "charge.toml",
        &body.replace("B = 1.0", "B = 1.0\ne = 2.0"),
    );
    let o = chetaev(&["check", &path, "--out", out]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    assert!(o.stderr.is_empty(), "{}", text(&o.stderr));
}
