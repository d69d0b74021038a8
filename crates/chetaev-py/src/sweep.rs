//! `Scene.sweep(...)` and `merge_sweeps(...)`: [`chetaev_scene::sweep`] from Python.

use std::path::PathBuf;

use chetaev_parts::{Part, Shard};
use chetaev_scene::sweep::table::{self, Table};
use chetaev_scene::sweep::{Sweep, SweepArgs};
use chetaev_scene::Scene as RustScene;
use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::{scene_error, ChetaevError};

/// One variable's values as Python gives them, in the command line's spelling: a string as it
/// is (`"1:100:5:log"`), a number, a list of numbers (`"1,2,5"`), or a dict with `from`, `to` and
/// optionally `count` and `scale`.
fn spec(name: &str, v: &Bound<'_, PyAny>) -> PyResult<String> {
    let bad = || {
        ChetaevError::new_err(format!(
            "vary['{name}']: give a list of numbers [1.0, 2.0, 5.0], a dict {{'from': 1.0, 'to': \
             10.0, 'count': 10, 'scale': 'log'}} (without 'count': sampled at random), or a \
             string '1:10:10:log'"
        ))
    };
    if let Ok(s) = v.extract::<String>() {
        return Ok(s);
    }
    if let Ok(x) = v.extract::<f64>() {
        return Ok(format!("{x:?}"));
    }
    if let Ok(d) = v.cast::<PyDict>() {
        let number = |key: &str| -> PyResult<Option<f64>> {
            d.get_item(key)?
                .map(|x| x.extract::<f64>().map_err(|_| bad()))
                .transpose()
        };
        for key in d.keys() {
            let key: String = key.extract().map_err(|_| bad())?;
            if !["from", "to", "count", "scale"].contains(&key.as_str()) {
                return Err(ChetaevError::new_err(format!(
                    "vary['{name}']: unknown key '{key}'; a range has 'from', 'to', 'count' (for \
                     a grid) and 'scale' ('linear' or 'log')"
                )));
            }
        }
        let (from, to) = (
            number("from")?.ok_or_else(bad)?,
            number("to")?.ok_or_else(bad)?,
        );
        let mut s = format!("{from:?}:{to:?}");
        if let Some(c) = d.get_item("count")? {
            let c: i64 = c.extract().map_err(|_| bad())?;
            s.push_str(&format!(":{c}"));
        }
        if let Some(scale) = d.get_item("scale")? {
            let scale: String = scale.extract().map_err(|_| bad())?;
            s.push_str(&format!(":{scale}"));
        }
        return Ok(s);
    }
    if let Ok(list) = v.extract::<Vec<f64>>() {
        let parts: Vec<String> = list.iter().map(|x| format!("{x:?}")).collect();
        return Ok(parts.join(","));
    }
    Err(bad())
}

/// Runs the sweep of `scene` (see `Scene.sweep`).
#[allow(clippy::too_many_arguments)]
pub(crate) fn run(
    py: Python<'_>,
    scene: &RustScene,
    vary: Option<&Bound<'_, PyDict>>,
    samples: Option<usize>,
    seed: Option<u64>,
    design: Option<String>,
    collect: Option<Vec<String>>,
    shard: Option<String>,
    jobs: Option<usize>,
    yes: bool,
) -> PyResult<SweepTable> {
    let mut args = SweepArgs {
        samples,
        seed,
        design,
        collect,
        yes,
        ..SweepArgs::default()
    };
    if let Some(vary) = vary {
        for (k, v) in vary.iter() {
            let name: String = k.str()?.extract()?;
            args.vary.push(format!("{name}={}", spec(&name, &v)?));
        }
    }
    let shard = match shard {
        Some(s) => s
            .parse::<Shard>()
            .map_err(|e| ChetaevError::new_err(e.to_string()))?,
        None => Shard::WHOLE,
    };
    let sweep = Sweep::of_scene(scene, &args).map_err(|e| match e {
        // Said in the command line's words; here they are keyword arguments.
        chetaev_scene::Error::Sweep { message } => ChetaevError::new_err(format!(
            "sweep: {}",
            message
                .replace("--vary NAME=SPEC", "vary={'v0': '5:20:4'}")
                .replace("--vary ", "vary: ")
                .replace("--collect ", "collect: ")
                .replace("--design ", "design: ")
                .replace("pass --yes", "pass yes=True")
        )),
        e => scene_error(e),
    })?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(jobs.unwrap_or(0))
        .build()
        .map_err(|e| ChetaevError::new_err(format!("cannot start the threads: {e}")))?;
    let (part, table) = py
        .detach(|| pool.install(|| sweep.run_part(shard, &|| {})))
        .map_err(scene_error)?;
    Ok(SweepTable { part, table })
}

/// The rows of a sweep: one per run, with the variables' values, the status, the quantities
/// collected and why a run failed. Columns are numpy arrays (`table["impact.t"]`); `write(dir)`
/// writes the files `chetaev sweep` writes.
#[pyclass(module = "chetaev._chetaev", frozen)]
pub(crate) struct SweepTable {
    part: Part,
    table: Table,
}

#[pymethods]
impl SweepTable {
    /// The names of the variables, in the order of `values`' columns.
    #[getter]
    fn variables(&self) -> Vec<String> {
        self.table.variables.clone()
    }

    /// The names of the quantities, in the order of `quantities`' columns.
    #[getter]
    fn columns(&self) -> Vec<String> {
        self.table.columns.clone()
    }

    /// The points' indices in the whole sweep.
    #[getter]
    fn index<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u64>> {
        let v: Vec<u64> = self.table.rows.iter().map(|r| r.index as u64).collect();
        PyArray1::from_vec(py, v)
    }

    /// The variables' values, an `(runs, variables)` array.
    #[getter]
    fn values<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let w = self.table.variables.len();
        let flat: Vec<f64> = self
            .table
            .rows
            .iter()
            .flat_map(|r| r.values.clone())
            .collect();
        Ok(PyArray1::from_vec(py, flat)
            .reshape([self.table.rows.len(), w])?
            .into_any())
    }

    /// The quantities collected, an `(runs, columns)` array; NaN where a run did not reach one.
    #[getter]
    fn quantities<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let w = self.table.columns.len();
        let flat: Vec<f64> = self
            .table
            .rows
            .iter()
            .flat_map(|r| r.quantities.clone())
            .collect();
        Ok(PyArray1::from_vec(py, flat)
            .reshape([self.table.rows.len(), w])?
            .into_any())
    }

    /// How each run ended: `completed`, `terminated:<event>`, `failed` or `refused`.
    #[getter]
    fn status(&self) -> Vec<String> {
        self.table.rows.iter().map(|r| r.status.text()).collect()
    }

    /// Why each run failed or was refused; empty for the others.
    #[getter]
    fn reason(&self) -> Vec<String> {
        self.table.rows.iter().map(|r| r.reason.clone()).collect()
    }

    /// The accepted steps of each run.
    #[getter]
    fn steps<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u64>> {
        let v: Vec<u64> = self.table.rows.iter().map(|r| r.steps as u64).collect();
        PyArray1::from_vec(py, v)
    }

    /// The runs' count of `(completed or terminated, failed, refused)`.
    fn counts(&self) -> (usize, usize, usize) {
        self.table.counts()
    }

    /// One column by name: a variable or a quantity, as an array.
    fn __getitem__<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let rows = &self.table.rows;
        if let Some(j) = self.table.variables.iter().position(|v| v == name) {
            return Ok(PyArray1::from_vec(
                py,
                rows.iter().map(|r| r.values[j]).collect(),
            ));
        }
        if let Some(j) = self.table.columns.iter().position(|v| v == name) {
            return Ok(PyArray1::from_vec(
                py,
                rows.iter().map(|r| r.quantities[j]).collect(),
            ));
        }
        Err(pyo3::exceptions::PyKeyError::new_err(format!(
            "'{name}' is neither a variable ({}) nor a quantity ({}) of this sweep",
            self.table.variables.join(", "),
            self.table.columns.join(", ")
        )))
    }

    fn __len__(&self) -> usize {
        self.table.rows.len()
    }

    /// The table as CSV text, as `chetaev sweep` writes it.
    fn to_csv(&self) -> String {
        self.table.to_csv()
    }

    /// Writes the files `chetaev sweep` writes into `directory`: for a whole sweep `sweep.csv`,
    /// `sweep.json` and the pictures; for one shard its part file `sweep.part-K-of-N.json`.
    /// Returns the files written.
    fn write(&self, directory: PathBuf) -> PyResult<Vec<PathBuf>> {
        let sharded = self.part.runs.len() == 1 && self.part.runs[0].shard.n() > 1;
        if sharded {
            std::fs::create_dir_all(&directory).map_err(|e| {
                ChetaevError::new_err(format!("cannot create {}: {e}", directory.display()))
            })?;
            self.part
                .write_into(&directory)
                .map_err(|e| ChetaevError::new_err(e.to_string()))?;
            return Ok(vec![directory.join(self.part.file_name())]);
        }
        table::write_whole(&directory, &self.part, &self.table).map_err(scene_error)
    }

    fn __repr__(&self) -> String {
        let (ok, failed, refused) = self.table.counts();
        format!(
            "<SweepTable of {}: {} runs over ({}), collecting ({}); {ok} ok, {failed} failed, {refused} refused>",
            self.table.title,
            self.table.rows.len(),
            self.table.variables.join(", "),
            self.table.columns.join(", ")
        )
    }
}

/// Joins the part files of a sharded sweep (`Scene.sweep(shard="k/n")` then `write`, or
/// `chetaev sweep --shard k/n`) into the whole sweep's table.
#[pyfunction]
pub(crate) fn merge_sweeps(files: Vec<PathBuf>) -> PyResult<SweepTable> {
    let (part, table) = table::merge(&files).map_err(scene_error)?;
    Ok(SweepTable { part, table })
}

/// Registers the sweep's classes and functions in the module.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<SweepTable>()?;
    m.add_function(wrap_pyfunction!(merge_sweeps, m)?)?;
    Ok(())
}
