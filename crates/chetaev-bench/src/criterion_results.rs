//! Reading criterion's results (`target/criterion/<group>/<bench>/new/`) back, for the tables of
//! the performance report.

use std::ffi::OsString;
use std::path::{Path, PathBuf};

/// One benchmark's result.
#[derive(Clone, Debug, PartialEq)]
pub struct Estimate {
    /// The group (`rhs_cost`, `profile`, `overhead`).
    pub group: String,
    /// The benchmark's name within its group.
    pub function: String,
    /// Median time per iteration, nanoseconds.
    pub median_ns: f64,
    /// 95 % confidence interval of the median, nanoseconds.
    pub median_ci_ns: (f64, f64),
}

/// Everything that can go wrong reading criterion's files.
#[derive(Debug)]
pub struct ReadError(pub String);

impl std::fmt::Display for ReadError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for ReadError {}

fn read_json(path: &Path) -> Result<serde_json::Value, ReadError> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| ReadError(format!("cannot read {}: {e}", path.display())))?;
    serde_json::from_str(&text)
        .map_err(|e| ReadError(format!("cannot parse {}: {e}", path.display())))
}

/// The estimates of every benchmark of `group` under the criterion directory `root`, in the order
/// of their directory names. An absent group gives an empty list.
pub fn read_group(root: &Path, group: &str) -> Result<Vec<Estimate>, ReadError> {
    let dir = root.join(group);
    let Ok(entries) = std::fs::read_dir(&dir) else {
        return Ok(Vec::new());
    };
    let mut dirs: Vec<_> = entries
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| p.join("new/estimates.json").is_file())
        .collect();
    dirs.sort();
    let mut out = Vec::new();
    for d in dirs {
        let bench = read_json(&d.join("new/benchmark.json"))?;
        let est = read_json(&d.join("new/estimates.json"))?;
        let number = |v: &serde_json::Value| {
            v.as_f64()
                .ok_or_else(|| ReadError(format!("missing number in {}", d.display())))
        };
        let median = &est["median"];
        out.push(Estimate {
            group: bench["group_id"].as_str().unwrap_or(group).to_string(),
            function: bench["function_id"]
                .as_str()
                .unwrap_or_default()
                .to_string(),
            median_ns: number(&median["point_estimate"])?,
            median_ci_ns: (
                number(&median["confidence_interval"]["lower_bound"])?,
                number(&median["confidence_interval"]["upper_bound"])?,
            ),
        });
    }
    Ok(out)
}

/// Where criterion writes its results, looked up as criterion 0.7 does: `$CRITERION_HOME`, else
/// `$CARGO_TARGET_DIR/criterion`, else the target directory that `cargo_metadata` reports (when
/// run by cargo), else `./target/criterion`.
pub fn criterion_dir(
    criterion_home: Option<OsString>,
    cargo_target_dir: Option<OsString>,
    cargo_metadata: impl FnOnce() -> Option<PathBuf>,
) -> PathBuf {
    if let Some(home) = criterion_home.filter(|h| !h.is_empty()) {
        return PathBuf::from(home);
    }
    cargo_target_dir
        .filter(|d| !d.is_empty())
        .map(PathBuf::from)
        .or_else(cargo_metadata)
        .unwrap_or_else(|| PathBuf::from("target"))
        .join("criterion")
}

/// [`criterion_dir`] from this process's environment; `cargo metadata` is asked only when cargo
/// started the process (`$CARGO` set), as criterion does.
pub fn default_criterion_dir() -> PathBuf {
    criterion_dir(
        std::env::var_os("CRITERION_HOME"),
        std::env::var_os("CARGO_TARGET_DIR"),
        || {
            let output = std::process::Command::new(std::env::var_os("CARGO")?)
                .args(["metadata", "--format-version", "1", "--no-deps"])
                .output()
                .ok()?;
            let v: serde_json::Value = serde_json::from_slice(&output.stdout).ok()?;
            v["target_directory"].as_str().map(PathBuf::from)
        },
    )
}

/// `(n, k)` from a right-hand-side benchmark name `nNN_kKK`.
pub fn parse_size(name: &str) -> Option<(usize, usize)> {
    let (n, k) = name.strip_prefix('n')?.split_once("_k")?;
    Some((n.parse().ok()?, k.parse().ok()?))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse_from_names() {
        assert_eq!(parse_size("n06_k03"), Some((6, 3)));
        assert_eq!(parse_size("n24_k12"), Some((24, 12)));
        assert_eq!(parse_size("dynamics"), None);
    }

    #[test]
    fn criterion_is_looked_for_where_it_writes() {
        let never = || -> Option<PathBuf> { panic!("cargo metadata asked needlessly") };
        assert_eq!(
            criterion_dir(Some("/c".into()), Some("/t".into()), never),
            PathBuf::from("/c")
        );
        assert_eq!(
            criterion_dir(None, Some("/shared/target".into()), never),
            PathBuf::from("/shared/target/criterion")
        );
        assert_eq!(
            criterion_dir(None, None, || Some(PathBuf::from("/ws/target"))),
            PathBuf::from("/ws/target/criterion")
        );
        assert_eq!(
            criterion_dir(Some("".into()), Some("".into()), || None),
            PathBuf::from("target/criterion")
        );
    }

    #[test]
    fn an_absent_group_is_empty() {
        let r = read_group(Path::new("/nonexistent/criterion"), "rhs_cost").expect("no error");
        assert!(r.is_empty());
    }
}
