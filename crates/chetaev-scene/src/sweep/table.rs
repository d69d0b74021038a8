//! A sweep's rows: as CSV, and as the part files of `--shard k/n` ([`chetaev_parts`]), joined
//! again by [`merge`] into the table the whole sweep writes.
//!
//! The CSV has one row per run, in the order of the points: `index`, the variables, `status`
//! (`completed`, `terminated:<event>`, `failed`, `refused`), the quantities, `steps`,
//! `rhs_evaluations` and `reason` (why a run failed or was refused, empty otherwise). Numbers are
//! written in the shortest form that reads back to the same `f64`; a quantity a run did not
//! reach is `NaN`.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use chetaev_parts::{number, read_number, Fields, Part, PartError, Shard};
use serde_json::{json, Value};

use super::Sweep;
use crate::error::Error;
use crate::output::{csv_number, csv_text};

/// The name of a sweep's part files: `sweep.json`, `sweep.part-<k>-of-<n>.json`.
pub const SWEEP: &str = "sweep";

/// How a run ended.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum RunStatus {
    /// The end time was reached.
    Completed,
    /// A terminal event ended it (its name).
    Terminated(String),
    /// The integration failed; the row keeps what it reached.
    Failed,
    /// The point's scene or initial state was refused before integrating.
    Refused,
}

impl RunStatus {
    /// As written in the table: `completed`, `terminated:<event>`, `failed`, `refused`.
    pub fn text(&self) -> String {
        match self {
            RunStatus::Completed => "completed".to_string(),
            RunStatus::Terminated(e) => format!("terminated:{e}"),
            RunStatus::Failed => "failed".to_string(),
            RunStatus::Refused => "refused".to_string(),
        }
    }

    fn from_text(s: &str) -> Option<Self> {
        match s {
            "completed" => Some(RunStatus::Completed),
            "failed" => Some(RunStatus::Failed),
            "refused" => Some(RunStatus::Refused),
            _ => s
                .strip_prefix("terminated:")
                .map(|e| RunStatus::Terminated(e.to_string())),
        }
    }

    /// Whether the run reached its end time or a terminal event.
    pub fn is_success(&self) -> bool {
        matches!(self, RunStatus::Completed | RunStatus::Terminated(_))
    }
}

/// One run of a sweep.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    /// The point, from 0.
    pub index: usize,
    /// The variables' values ([`Sweep::variables`]).
    pub values: Vec<f64>,
    /// How the run ended.
    pub status: RunStatus,
    /// Why it failed or was refused; empty otherwise.
    pub reason: String,
    /// The quantities ([`Sweep::columns`]); NaN where the run did not reach them.
    pub quantities: Vec<f64>,
    /// Accepted steps.
    pub steps: usize,
    /// Right-hand side evaluations.
    pub rhs_evaluations: usize,
}

impl Row {
    pub(super) fn refused(index: usize, values: Vec<f64>, columns: usize, e: &Error) -> Self {
        // A located error names the scene file's place, which is the same for every point; the
        // message is what differs.
        Row {
            index,
            values,
            status: RunStatus::Refused,
            reason: e.message(),
            quantities: vec![f64::NAN; columns],
            steps: 0,
            rhs_evaluations: 0,
        }
    }

    fn to_json(&self) -> Value {
        json!({
            "values": self.values.iter().map(|&x| number(x)).collect::<Vec<_>>(),
            "status": self.status.text(),
            "reason": self.reason,
            "quantities": self.quantities.iter().map(|&x| number(x)).collect::<Vec<_>>(),
            "steps": self.steps,
            "rhs_evaluations": self.rhs_evaluations,
        })
    }

    fn from_json(index: usize, v: &Value) -> Result<Self, PartError> {
        let f = Fields::of(v, "row")?;
        let numbers = |key: &str| -> Result<Vec<f64>, PartError> {
            f.array(key)?
                .iter()
                .map(|x| {
                    read_number(x).ok_or_else(|| {
                        chetaev_parts::malformed(format!("`{key}` holds a non-number"))
                    })
                })
                .collect()
        };
        let status = f.str("status")?;
        Ok(Row {
            index,
            values: numbers("values")?,
            status: RunStatus::from_text(status)
                .ok_or_else(|| chetaev_parts::malformed(format!("status `{status}`")))?,
            reason: f.str("reason")?.to_string(),
            quantities: numbers("quantities")?,
            steps: f.usize("steps")?,
            rhs_evaluations: f.usize("rhs_evaluations")?,
        })
    }
}

/// The labels of the variables and quantities for pictures: their names with the scene's units.
pub(super) fn labels(sweep: &Sweep) -> Value {
    json!({
        "variables": sweep.variable_labels(),
        "columns": sweep.column_labels(),
        "title": sweep.scene.name,
    })
}

/// The rows of shard `shard`, with the sweep's settings, as a part ([`chetaev_parts::Part`]);
/// `about` records the run (machine, time).
pub fn part(sweep: &Sweep, shard: Shard, rows: &[Row], about: Value) -> Part {
    Part::new(
        SWEEP,
        sweep.settings(),
        sweep.len(),
        shard,
        about,
        rows.iter().map(|r| (r.index, r.to_json())).collect(),
    )
}

/// A whole sweep as read back from its parts: the variables' and quantities' names and the rows.
#[derive(Clone, Debug, PartialEq)]
pub struct Table {
    /// The scene's name.
    pub title: String,
    /// The variables.
    pub variables: Vec<String>,
    /// The quantities.
    pub columns: Vec<String>,
    /// The variables' axis labels, with their units where the scene declares them.
    pub variable_labels: Vec<String>,
    /// The quantities' axis labels, with their units where the scene declares them.
    pub column_labels: Vec<String>,
    /// The rows, by index.
    pub rows: Vec<Row>,
    /// The settings the rows were made with.
    pub settings: Value,
}

impl Table {
    /// The table of a whole part (one holding every shard).
    pub fn from_part(part: &Part) -> Result<Self, Error> {
        let bad = |e: PartError| Error::Parts(e.to_string());
        let s = Fields::of(&part.settings, "settings").map_err(bad)?;
        let names = |key: &str| -> Result<Vec<String>, Error> {
            s.array(key)
                .map_err(bad)?
                .iter()
                .map(|v| {
                    v.as_str().map(str::to_string).ok_or_else(|| {
                        Error::Parts(format!("`{key}` of the settings holds a non-name"))
                    })
                })
                .collect()
        };
        let rows = part
            .items
            .iter()
            .map(|(i, v)| Row::from_json(*i, v).map_err(bad))
            .collect::<Result<Vec<Row>, Error>>()?;
        let variables = names("variables")?;
        let columns = names("columns")?;
        // The labels, where the settings have them; the names otherwise.
        let labels = |key: &str, or: &[String]| -> Vec<String> {
            s.get("labels")
                .ok()
                .and_then(|l| l.get(key))
                .and_then(|l| l.as_array())
                .map(|a| {
                    a.iter()
                        .filter_map(|v| v.as_str().map(str::to_string))
                        .collect::<Vec<_>>()
                })
                .filter(|l| l.len() == or.len())
                .unwrap_or_else(|| or.to_vec())
        };
        Ok(Table {
            title: s.str("scene").map_err(bad)?.to_string(),
            variable_labels: labels("variables", &variables),
            column_labels: labels("columns", &columns),
            variables,
            columns,
            rows,
            settings: part.settings.clone(),
        })
    }

    /// The table as CSV (see the [module docs](self)).
    pub fn to_csv(&self) -> String {
        let mut out = String::new();
        let mut header = vec!["index".to_string()];
        header.extend(self.variables.iter().cloned());
        header.push("status".to_string());
        header.extend(self.columns.iter().cloned());
        header.extend(["steps", "rhs_evaluations", "reason"].map(String::from));
        out.push_str(
            &header
                .iter()
                .map(|h| csv_text(h))
                .collect::<Vec<_>>()
                .join(","),
        );
        out.push('\n');
        for r in &self.rows {
            let _ = write!(out, "{}", r.index);
            for &x in &r.values {
                let _ = write!(out, ",{}", csv_number(x));
            }
            let _ = write!(out, ",{}", csv_text(&r.status.text()));
            for &x in &r.quantities {
                let _ = write!(out, ",{}", csv_number(x));
            }
            let _ = writeln!(
                out,
                ",{},{},{}",
                r.steps,
                r.rhs_evaluations,
                csv_text(&r.reason)
            );
        }
        out
    }

    /// How many runs ended each way: completed or terminated, failed, refused.
    pub fn counts(&self) -> (usize, usize, usize) {
        let ok = self.rows.iter().filter(|r| r.status.is_success()).count();
        let failed = self
            .rows
            .iter()
            .filter(|r| r.status == RunStatus::Failed)
            .count();
        (ok, failed, self.rows.len() - ok - failed)
    }
}

/// Reads the part files `files` and joins them into the whole sweep ([`chetaev_parts::merge`]).
pub fn merge(files: &[PathBuf]) -> Result<(Part, Table), Error> {
    let whole = Part::read_merged(files, SWEEP).map_err(|e| Error::Parts(e.to_string()))?;
    let table = Table::from_part(&whole)?;
    Ok((whole, table))
}

/// Writes the whole sweep's files into `dir`: `sweep.csv`, `sweep.parquet` (with the feature
/// `parquet`, on by default), `sweep.json` (the merged part) and the pictures
/// ([`super::picture`]); returns the files written.
pub fn write_whole(dir: &Path, whole: &Part, table: &Table) -> Result<Vec<PathBuf>, Error> {
    std::fs::create_dir_all(dir).map_err(|e| Error::Write {
        path: dir.display().to_string(),
        reason: e.to_string(),
    })?;
    let mut written = Vec::new();
    let csv = dir.join(format!("{SWEEP}.csv"));
    write(&csv, &table.to_csv())?;
    written.push(csv);
    #[cfg(feature = "parquet")]
    {
        let parquet = dir.join(format!("{SWEEP}.parquet"));
        super::parquet::write(&parquet, table)?;
        written.push(parquet);
    }
    let json = dir.join(whole.file_name());
    write(&json, &whole.to_json())?;
    written.push(json);
    for (name, svg) in super::picture::draw(table) {
        let path = dir.join(name);
        write(&path, &svg)?;
        written.push(path);
    }
    Ok(written)
}

/// Writes `text` to `path`.
pub(crate) fn write(path: &Path, text: &str) -> Result<(), Error> {
    std::fs::write(path, text).map_err(|e| Error::Write {
        path: path.display().to_string(),
        reason: e.to_string(),
    })
}
