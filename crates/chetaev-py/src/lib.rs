//! The Python package's native module, `chetaev._chetaev`: a thin layer over the Rust API.
//!
//! It converts arguments, releases the GIL, calls [`chetaev::solve`] and converts the result;
//! every feature is written once, in Rust. The Python side (`python/chetaev`) adds only what is
//! Pythonic: the conversion of sympy expressions into operations of a
//! [`chetaev_scene::graph::Graph`] (each distinct subexpression once), numpy arrays, exceptions.
//!
//! | Python | Rust |
//! |---|---|
//! | `Model(n, ops, lagrangian, ...)`, `Model.from_sympy(...)` | [`GraphModel`] |
//! | `Problem(model, q0, qd0, t0)` | [`chetaev::Problem::dynamic`] |
//! | `Scene.load(path)`, `Scene.parse(text)` | [`chetaev_scene::Scene`] |
//! | `solve(problem, t_end, method=..., ...)` | [`chetaev::solve`] with [`Options`] |
//! | `Solution` | [`chetaev::Solution`], its series as numpy arrays |
//! | `Scene.sweep(...)`, `SweepTable`, `merge_sweeps` | [`chetaev_scene::sweep`] |

// The documentation is Python's (the docstrings of the module's classes and functions), and its
// indented blocks are Python or mathematics, not Rust: no doc tests, even under `cargo test --doc`
// (which does not heed the manifest's `doctest = false`).
#![cfg(not(doctest))]

mod sweep;

use std::sync::{Arc, OnceLock};

use chetaev::equations::structure::Names;
use chetaev::integrate::events::{Direction, Event};
use chetaev::prelude::{AnyMethod, Atol, Options, Output, Projection, Record};
use chetaev::{Problem as RustProblem, Seed as RustSeed, Solution as RustSolution, Status};
use chetaev_scene::graph::{Graph, GraphError, GraphModel, Parts};
use chetaev_scene::{ExprModel, Scene as RustScene};
use numpy::{PyArray1, PyArrayMethods};
use pyo3::create_exception;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

create_exception!(
    _chetaev,
    ChetaevError,
    PyValueError,
    "Bad input to chetaev: a model, problem or option it cannot use. The message is the library's: what was wrong and what to try."
);
create_exception!(
    _chetaev,
    SceneError,
    ChetaevError,
    "A scene file or text that cannot be read: the message gives the line and column."
);

fn chetaev_error(e: chetaev::Error) -> PyErr {
    ChetaevError::new_err(pythonic(&e.to_string()))
}

/// The library's message with the Rust names of options spelled as Python calls them:
/// `Options::max_steps` is `solve(..., max_steps=...)`, `Problem::with_projected_velocity` is
/// `Problem(..., project_velocity=True)`.
fn pythonic(message: &str) -> String {
    let mut out = message
        .replace(
            "Problem::with_projected_velocity",
            "Problem(..., project_velocity=True)",
        )
        .replace(
            "Problem::with_projected_state",
            "Problem(..., project_velocity=True)",
        )
        .replace(
            "with Seed::with_position and Seed::with_velocity",
            "with Seed(name, parameters={...}, positions=[(i, rate)], velocities=[(i, rate)])",
        )
        .replace("Seed::with_position", "Seed(..., positions=[(i, rate)])")
        .replace("Seed::with_velocity", "Seed(..., velocities=[(i, rate)])")
        .replace("Seed::with_parameter", "Seed(..., parameters={...})");
    // `Seed::parameter("l").with_position(i, rate)` is `Seed("l", parameters={l: 1}, positions=[(i, rate)])`.
    while let Some(at) = out.find("Seed::parameter(\"") {
        let rest = &out[at + "Seed::parameter(\"".len()..];
        let Some(name_end) = rest.find('"') else {
            break;
        };
        let name = rest[..name_end].to_string();
        let after = &rest[name_end..];
        let (kind, tail) = if let Some(t) = after.strip_prefix("\").with_position(") {
            ("positions", t)
        } else if let Some(t) = after.strip_prefix("\").with_velocity(") {
            ("velocities", t)
        } else {
            ("", after.strip_prefix("\")").unwrap_or(after))
        };
        let (args, tail) = match tail.find(')') {
            Some(close) if !kind.is_empty() => (&tail[..close], &tail[close + 1..]),
            _ => ("", tail),
        };
        let python = if kind.is_empty() {
            format!("Seed.parameter({name:?})")
        } else {
            format!("Seed({name:?}, parameters={{{name}: 1}}, {kind}=[({args})])")
        };
        let end = out.len() - tail.len();
        out.replace_range(at..end, &python);
    }
    // A parameter the model does not read: in Python, a symbol given a value in `parameters`.
    if let Some(at) = out.find("; read it as R::parameter(") {
        out.truncate(at);
        out.push_str(
            "; name a parameter given in from_sympy(..., parameters={...}) and used by the model",
        );
    }
    while let Some(at) = out.find("Options::") {
        let rest = &out[at + "Options::".len()..];
        let len = rest
            .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
            .unwrap_or(rest.len());
        let name = &rest[..len];
        let python = match name {
            "project" => "solve(..., project=True)".to_string(),
            _ => format!("solve(..., {name}=...)"),
        };
        out.replace_range(at..at + "Options::".len() + len, &python);
    }
    out
}

fn graph_error(e: GraphError) -> PyErr {
    ChetaevError::new_err(e.message)
}

fn scene_error(e: chetaev_scene::Error) -> PyErr {
    match e.snippet() {
        Some(snippet) => SceneError::new_err(format!("{e}\n{snippet}")),
        None => SceneError::new_err(e.to_string()),
    }
}

/// One operation as Python gives it: `(name, operands, value)`.
type OpSpec = (String, Vec<u32>, f64);

fn build_graph(n: usize, parameters: Vec<(String, f64)>, ops: &[OpSpec]) -> PyResult<Graph> {
    let mut g = Graph::new(n, parameters).map_err(graph_error)?;
    for (name, args, value) in ops {
        g.push(name, args, *value).map_err(graph_error)?;
    }
    Ok(g)
}

/// A model: a Lagrangian `L(t, q, q̇)`, velocity constraints `f(t, q, q̇) = 0`, holonomic
/// constraints `h(t, q) = 0`, generalised forces `Q(t, q, q̇)` and a Rayleigh function `D`, as one
/// expression graph with shared subexpressions.
///
/// Made by `Model.from_sympy(...)` (see `chetaev.from_sympy`) or from operations directly.
#[pyclass(module = "chetaev._chetaev", frozen)]
struct Model {
    inner: Arc<GraphModel>,
    /// The operations and parts it was made from, for pickling (a process pool sends a model
    /// to its workers so).
    made_from: Arc<(Vec<OpSpec>, Parts)>,
    coordinates: Vec<String>,
    /// The coordinates' names in LaTeX (sympy's), for `describe`.
    latex: Option<Vec<String>>,
    /// The sympy symbols the model was converted with (for events and outputs), or None.
    symbols: Option<Py<PyAny>>,
}

#[pymethods]
impl Model {
    /// A model on `n` coordinates from operations `ops` (`(name, operands, value)` each, see
    /// `chetaev_scene::graph`), with the indices of `L`, `f`, `h`, `Q` and `D` among them.
    #[new]
    #[pyo3(signature = (n, ops, lagrangian, constraints=vec![], holonomic=vec![], forces=vec![], dissipation=None, parameters=vec![], coordinates=None, symbols=None, latex=None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        n: usize,
        ops: Vec<OpSpec>,
        lagrangian: u32,
        constraints: Vec<u32>,
        holonomic: Vec<u32>,
        forces: Vec<u32>,
        dissipation: Option<u32>,
        parameters: Vec<(String, f64)>,
        coordinates: Option<Vec<String>>,
        symbols: Option<Py<PyAny>>,
        latex: Option<Vec<String>>,
    ) -> PyResult<Self> {
        let coordinates = coordinates.unwrap_or_else(|| (1..=n).map(|i| format!("q{i}")).collect());
        if coordinates.len() != n {
            return Err(ChetaevError::new_err(format!(
                "{} coordinate names for {n} coordinates",
                coordinates.len()
            )));
        }
        let graph = build_graph(n, parameters, &ops)?;
        let parts = Parts {
            lagrangian,
            constraints,
            holonomic,
            forces,
            dissipation,
        };
        let made_from = Arc::new((ops, parts.clone()));
        if latex.as_ref().is_some_and(|l| l.len() != n) {
            return Err(ChetaevError::new_err(format!(
                "{} LaTeX names for {n} coordinates",
                latex.as_ref().map_or(0, Vec::len)
            )));
        }
        Ok(Self {
            inner: Arc::new(GraphModel::new(graph, parts).map_err(graph_error)?),
            made_from,
            coordinates,
            latex,
            symbols,
        })
    }

    /// Pickling: the model is made again from its operations, with its current parameter
    /// values (`with_parameters` included).
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyAny>> {
        let py = slf.py();
        let m = slf.get();
        let (ops, parts) = &*m.made_from;
        let kwargs = PyDict::new(py);
        kwargs.set_item("constraints", parts.constraints.clone())?;
        kwargs.set_item("holonomic", parts.holonomic.clone())?;
        kwargs.set_item("forces", parts.forces.clone())?;
        kwargs.set_item("dissipation", parts.dissipation)?;
        let parameters: Vec<(String, f64)> = m
            .inner
            .graph()
            .parameters()
            .map(|(n, v)| (n.to_string(), v))
            .collect();
        kwargs.set_item("parameters", parameters)?;
        kwargs.set_item("coordinates", m.coordinates.clone())?;
        kwargs.set_item("symbols", m.symbols.as_ref().map(|s| s.clone_ref(py)))?;
        kwargs.set_item("latex", m.latex.clone())?;
        let args = (m.inner.graph().n(), ops.clone(), parts.lagrangian);
        // `Model(*args, **kwargs)`, through functools.partial, which pickles by reference.
        let partial = py
            .import("functools")?
            .getattr("partial")?
            .call((slf.get_type(), args.0, args.1, args.2), Some(&kwargs))?;
        (partial, ()).into_pyobject(py).map(|t| t.into_any())
    }

    /// The model of a sympy Lagrangian (or of `sympy.physics.mechanics` bodies); see
    /// `chetaev.from_sympy` for the arguments.
    #[classmethod]
    #[pyo3(signature = (*args, **kwargs))]
    fn from_sympy<'py>(
        cls: &Bound<'py, pyo3::types::PyType>,
        args: &Bound<'py, pyo3::types::PyTuple>,
        kwargs: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let module = cls.py().import("chetaev._sympy")?;
        module.getattr("from_sympy")?.call(args, kwargs)
    }

    /// The number of coordinates `n`.
    #[getter]
    fn n(&self) -> usize {
        self.inner.graph().n()
    }

    /// The number of velocity constraints.
    #[getter]
    fn k(&self) -> usize {
        use chetaev::model::DynModel;
        self.inner.sizes().1
    }

    /// The number of holonomic constraints.
    #[getter]
    fn holonomic_count(&self) -> usize {
        use chetaev::model::DynModel;
        self.inner.holonomic_count()
    }

    /// The coordinates' names.
    #[getter]
    fn coordinates(&self) -> Vec<String> {
        self.coordinates.clone()
    }

    /// The parameters and their values.
    #[getter]
    fn parameters(&self) -> Vec<(String, f64)> {
        self.inner
            .graph()
            .parameters()
            .map(|(n, v)| (n.to_string(), v))
            .collect()
    }

    /// The number of operations of the graph (shared subexpressions counted once).
    #[getter]
    fn operations(&self) -> usize {
        self.inner.graph().len()
    }

    /// The sympy symbols the model was converted with, or None.
    #[getter]
    fn symbols(&self, py: Python<'_>) -> Option<Py<PyAny>> {
        self.symbols.as_ref().map(|s| s.clone_ref(py))
    }

    /// The same model with new parameter values, `{name: value}` (names as strings or sympy
    /// symbols); the graph is shared, not converted again.
    fn with_parameters(&self, py: Python<'_>, values: &Bound<'_, PyDict>) -> PyResult<Self> {
        let mut m = (*self.inner).clone();
        for (k, v) in values.iter() {
            let name = k.str()?.to_string();
            let value: f64 = v.extract()?;
            m = m.with_parameter(&name, value).map_err(graph_error)?;
        }
        Ok(Self {
            inner: Arc::new(m),
            made_from: Arc::clone(&self.made_from),
            coordinates: self.coordinates.clone(),
            latex: self.latex.clone(),
            symbols: self.symbols.as_ref().map(|s| s.clone_ref(py)),
        })
    }

    fn __repr__(&self) -> String {
        use chetaev::model::DynModel;
        let params: Vec<String> = self
            .inner
            .graph()
            .parameters()
            .map(|(n, v)| format!("{n}={v}"))
            .collect();
        format!(
            "Model(coordinates=[{}], velocity_constraints={}, holonomic={}, parameters={{{}}}, operations={})",
            self.coordinates.join(", "),
            self.inner.sizes().1,
            self.inner.holonomic_count(),
            params.join(", "),
            self.inner.graph().len()
        )
    }
}

/// The independent coordinates and speeds as Python names them (indices, names, dynamicsymbols
/// or their derivatives), `None` for automatic.
fn independent(
    py: Python<'_>,
    model: &Py<Model>,
    coordinates: Option<&Bound<'_, PyAny>>,
    speeds: Option<&Bound<'_, PyAny>>,
) -> PyResult<chetaev::manifold::Independent> {
    let convert = py.import("chetaev._sympy")?.getattr("indices")?;
    let pick = |items: Option<&Bound<'_, PyAny>>, what: &str| -> PyResult<Option<Vec<usize>>> {
        match items {
            None => Ok(None),
            Some(items) => convert.call1((model.bind(py), items, what))?.extract(),
        }
    };
    Ok(chetaev::manifold::Independent {
        coordinates: pick(coordinates, "independent_coordinates")?,
        speeds: pick(speeds, "independent_speeds")?,
    })
}

/// An initial position or velocity: a sequence of `n` numbers in the model's order, or a dict
/// `{coordinate: value}` (names, dynamicsymbols or, for velocities, their derivatives).
fn state(
    py: Python<'_>,
    model: &Py<Model>,
    values: &Bound<'_, PyAny>,
    what: &str,
) -> PyResult<Vec<f64>> {
    if values.is_instance_of::<PyDict>() {
        return py
            .import("chetaev._sympy")?
            .getattr("state_vector")?
            .call1((model.bind(py), values, what))?
            .extract();
    }
    values.extract().map_err(|_| {
        ChetaevError::new_err(format!(
            "{what} must be a sequence of numbers, one per coordinate ({}), or a dict {{coordinate: value}}",
            model.get().coordinates.join(", ")
        ))
    })
}

/// A problem of either kind the package makes.
#[derive(Clone)]
enum Inner {
    Graph(Arc<RustProblem<GraphModel>>),
    Scene(Arc<RustProblem<ExprModel>>),
}

macro_rules! with_problem {
    ($inner:expr, $p:ident => $body:expr) => {
        match $inner {
            Inner::Graph($p) => $body,
            Inner::Scene($p) => $body,
        }
    };
}

/// A model with its initial state `(t0, q0, q̇0)`, checked: finite, the holonomic constraints and
/// the velocity constraints satisfied, the block system regular. With `project_velocity=True` the
/// state is made consistent first (`Problem::with_projected_state` in Rust): the position projected
/// onto the holonomic constraints `h = 0`, then the velocity onto the velocity constraints and
/// `ḣ = 0`, each the smallest change in the metric `∂²L/∂q̇²`.
#[pyclass(module = "chetaev._chetaev", frozen)]
struct Problem {
    inner: Inner,
    model: Option<Py<Model>>,
    coordinates: Vec<String>,
    /// The route's name, for pickling.
    route: &'static str,
    /// When the right-hand side runs as machine code, by name, for pickling.
    machine_code: &'static str,
}

fn machine_code(name: &str) -> PyResult<(chetaev::MachineCode, &'static str)> {
    match name {
        "auto" => Ok((chetaev::MachineCode::Auto, "auto")),
        "never" => Ok((chetaev::MachineCode::Never, "never")),
        "at_once" => Ok((chetaev::MachineCode::AtOnce, "at_once")),
        other => Err(ChetaevError::new_err(format!(
            "unknown machine_code '{other}'; it is 'auto' (compiled when the right-hand sides still expected pay for it, the default), 'never' (interpreted always) or 'at_once' (compiled before the first solve: every solve the same to the bit)"
        ))),
    }
}

fn route_name(route: chetaev::Route) -> &'static str {
    match route {
        chetaev::Route::Dual => "dual",
        _ => "graph",
    }
}

fn route(name: &str) -> PyResult<chetaev::Route> {
    match name {
        "graph" => Ok(chetaev::Route::Graph),
        "dual" => Ok(chetaev::Route::Dual),
        other => Err(ChetaevError::new_err(format!(
            "unknown route '{other}'; the routes are 'graph' (the recorded and compiled equations, the default) and 'dual' (dual numbers, the reference)"
        ))),
    }
}

#[pymethods]
impl Problem {
    #[new]
    #[pyo3(signature = (model, q0, qd0, t0=0.0, project_velocity=false, route="graph", independent_coordinates=None, independent_speeds=None, complete=false, machine_code="auto"))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        model: Py<Model>,
        q0: &Bound<'_, PyAny>,
        qd0: &Bound<'_, PyAny>,
        t0: f64,
        project_velocity: bool,
        route: &str,
        independent_coordinates: Option<&Bound<'_, PyAny>>,
        independent_speeds: Option<&Bound<'_, PyAny>>,
        complete: bool,
        machine_code: &str,
    ) -> PyResult<Self> {
        let route = self::route(route)?;
        let (machine_code, machine_code_name) = self::machine_code(machine_code)?;
        let mut q0 = state(py, &model, q0, "q0")?;
        let mut qd0 = state(py, &model, qd0, "qd0")?;
        if complete || independent_coordinates.is_some() || independent_speeds.is_some() {
            let independent =
                self::independent(py, &model, independent_coordinates, independent_speeds)?;
            let m = (*model.get().inner).clone();
            let done = py
                .detach(|| chetaev::manifold::complete(&m, t0, &q0, &qd0, &independent))
                .map_err(chetaev_error)?;
            (q0, qd0) = (done.q, done.qd);
        }
        let m = model.get();
        let graph_model = (*m.inner).clone();
        let coordinates = m.coordinates.clone();
        let problem = py
            .detach(|| {
                if project_velocity {
                    RustProblem::dynamic_with_projected_state(graph_model, t0, q0, qd0)
                } else {
                    RustProblem::dynamic(graph_model, t0, q0, qd0)
                }
            })
            .map_err(chetaev_error)?
            .with_route(route)
            .with_machine_code(machine_code);
        Ok(Self {
            inner: Inner::Graph(Arc::new(problem)),
            model: Some(model),
            coordinates,
            route: route_name(route),
            machine_code: machine_code_name,
        })
    }

    /// Pickling: the model and the (completed) initial state; a scene's problem is pickled as
    /// its scene is not, so it is refused.
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyAny>> {
        let py = slf.py();
        let p = slf.get();
        let Some(model) = &p.model else {
            return Err(ChetaevError::new_err(
                "a scene's problem cannot be pickled: send the scene's text and make the problem with Scene.parse(text).problem() where it is needed",
            ));
        };
        let (t0, q0, qd0) =
            with_problem!(&p.inner, x => (x.t0(), x.q0().to_vec(), x.qd0().to_vec()));
        let args = (
            model.clone_ref(py),
            q0,
            qd0,
            t0,
            false,
            p.route,
            py.None(),
            py.None(),
            false,
            p.machine_code,
        );
        (slf.get_type(), args)
            .into_pyobject(py)
            .map(|t| t.into_any())
    }

    /// The model (None for a scene's problem).
    #[getter]
    fn model(&self, py: Python<'_>) -> Option<Py<Model>> {
        self.model.as_ref().map(|m| m.clone_ref(py))
    }

    /// The coordinates' names.
    #[getter]
    fn coordinates(&self) -> Vec<String> {
        self.coordinates.clone()
    }

    /// The initial time.
    #[getter]
    fn t0(&self) -> f64 {
        with_problem!(&self.inner, p => p.t0())
    }

    /// The initial position (after projection, if asked for).
    #[getter]
    fn q0<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        with_problem!(&self.inner, p => PyArray1::from_slice(py, p.q0()))
    }

    /// The initial velocity (after projection, if asked for).
    #[getter]
    fn qd0<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        with_problem!(&self.inner, p => PyArray1::from_slice(py, p.qd0()))
    }

    /// `(n, k)`: coordinates, and multipliers (velocity plus holonomic constraints).
    #[getter]
    fn sizes(&self) -> (usize, usize) {
        with_problem!(&self.inner, p => p.sizes())
    }

    /// The Chetaev equations solved at a state: a dict of `qdd`, `mu`, `phi` (the Chetaev force
    /// `Φ = Jᵀμ`), `f` (the residual), `energy`, `pivot_ratio` and `j` (`∂f/∂q̇`, `k × n`).
    fn equations_at<'py>(
        &self,
        py: Python<'py>,
        t: f64,
        q: Vec<f64>,
        qd: Vec<f64>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let inner = self.inner.clone();
        let d = py
            .detach(|| with_problem!(&inner, p => p.equations_at(t, &q, &qd)))
            .map_err(chetaev_error)?;
        let out = PyDict::new(py);
        out.set_item("qdd", PyArray1::from_vec(py, d.qdd))?;
        out.set_item("mu", PyArray1::from_vec(py, d.mu))?;
        out.set_item("phi", PyArray1::from_vec(py, d.phi))?;
        out.set_item("f", PyArray1::from_vec(py, d.f))?;
        out.set_item("forces", PyArray1::from_vec(py, d.forces))?;
        out.set_item("energy", d.energy)?;
        out.set_item("lagrangian", d.l)?;
        out.set_item("pivot_ratio", d.pivot_ratio)?;
        let n = q.len();
        let k = d.j.len() / n.max(1);
        out.set_item("j", PyArray1::from_vec(py, d.j).reshape([k, n])?)?;
        Ok(out)
    }

    /// What the library derived for the model, at a state (the initial one by default): the
    /// structure of the blocks, the derived expressions (text and LaTeX), the numbers there.
    #[pyo3(signature = (t=None, q=None, qd=None))]
    fn describe(
        &self,
        py: Python<'_>,
        t: Option<f64>,
        q: Option<Vec<f64>>,
        qd: Option<Vec<f64>>,
    ) -> PyResult<Description> {
        let inner = self.inner.clone();
        let names = self.coordinates.join(", ");
        let latex_names = self
            .model
            .as_ref()
            .and_then(|m| m.get().latex.clone())
            .unwrap_or_else(|| self.coordinates.clone());
        let symbols = Names::with_latex(&self.coordinates, &latex_names);
        let d = py
            .detach(|| {
                with_problem!(&inner, p => {
                    let t = t.unwrap_or(p.t0());
                    let q = q.unwrap_or_else(|| p.q0().to_vec());
                    let qd = qd.unwrap_or_else(|| p.qd0().to_vec());
                    p.describe_named(t, &q, &qd, &symbols)
                })
            })
            .map_err(chetaev_error)?;
        Ok(Description {
            text: format!("coordinates q = ({names})\n{d}"),
            latex: d.latex(),
            coordinates: latex_names,
        })
    }

    /// The reduced equations linearised on the constraint manifold at a state (the initial one
    /// by default), in independent coordinates and speeds (chosen by pivoting where None):
    /// `δż = A δz`, with its eigenvalues and eigenvectors. See `Linearization`.
    #[pyo3(signature = (t=None, q=None, qd=None, coordinates=None, speeds=None))]
    fn linearize(
        &self,
        py: Python<'_>,
        t: Option<f64>,
        q: Option<Vec<f64>>,
        qd: Option<Vec<f64>>,
        coordinates: Option<&Bound<'_, PyAny>>,
        speeds: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Linearization> {
        let independent = match &self.model {
            Some(m) => independent(py, m, coordinates, speeds)?,
            None => chetaev::manifold::Independent {
                coordinates: coordinates.map(|c| c.extract()).transpose()?,
                speeds: speeds.map(|c| c.extract()).transpose()?,
            },
        };
        let inner = self.inner.clone();
        let lin = py
            .detach(|| {
                with_problem!(&inner, p => {
                    let t = t.unwrap_or(p.t0());
                    let q = q.unwrap_or_else(|| p.q0().to_vec());
                    let qd = qd.unwrap_or_else(|| p.qd0().to_vec());
                    p.linearize(t, &q, &qd, &independent)
                })
            })
            .map_err(chetaev_error)?;
        Ok(Linearization {
            inner: lin,
            coordinates: self.coordinates.clone(),
        })
    }

    fn __repr__(&self) -> String {
        let (n, k) = self.sizes();
        format!(
            "Problem(coordinates=[{}], n={n}, multipliers={k}, t0={})",
            self.coordinates.join(", "),
            self.t0()
        )
    }
}

/// The reduced equations linearised on the constraint manifold: `δż = A δz` in the independent
/// coordinates and speeds `z` (`states` names them), with the eigenvalues of `A` (sorted by real
/// part) and their eigenvectors (columns). A cyclic coordinate (on which nothing depends) gives a
/// zero column and an eigenvalue 0: `cyclic` lists them.
#[pyclass(module = "chetaev._chetaev", frozen)]
struct Linearization {
    inner: chetaev::manifold::Linearization,
    coordinates: Vec<String>,
}

#[pymethods]
impl Linearization {
    /// `A`, shape `(p, p)`.
    #[getter]
    fn a<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let p = self.inner.dim();
        Ok(PyArray1::from_slice(py, &self.inner.a)
            .reshape([p, p])?
            .into_any())
    }

    /// The eigenvalues of `A`, complex, shape `(p,)`.
    #[getter]
    fn eigenvalues<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let v: Vec<numpy::Complex64> = self
            .inner
            .eigenvalues
            .iter()
            .map(|c| numpy::Complex64::new(c.re, c.im))
            .collect();
        Ok(PyArray1::from_vec(py, v).into_any())
    }

    /// The eigenvectors, one column per eigenvalue, shape `(p, p)`, each of unit length.
    #[getter]
    fn eigenvectors<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let p = self.inner.dim();
        let mut flat = vec![numpy::Complex64::new(0.0, 0.0); p * p];
        for (j, v) in self.inner.eigenvectors.iter().enumerate() {
            for (i, c) in v.iter().enumerate() {
                flat[i * p + j] = numpy::Complex64::new(c.re, c.im);
            }
        }
        Ok(PyArray1::from_vec(py, flat).reshape([p, p])?.into_any())
    }

    /// The names of `z`: the independent coordinates, then their speeds (`<name>_dot`).
    #[getter]
    fn states(&self) -> Vec<String> {
        let name = |i: usize| {
            self.coordinates
                .get(i)
                .cloned()
                .unwrap_or_else(|| format!("q{}", i + 1))
        };
        self.inner
            .coordinates
            .iter()
            .map(|&i| name(i))
            .chain(
                self.inner
                    .speeds
                    .iter()
                    .map(|&i| format!("{}_dot", name(i))),
            )
            .collect()
    }

    /// The independent coordinates (indices from 0).
    #[getter]
    fn coordinates(&self) -> Vec<usize> {
        self.inner.coordinates.clone()
    }

    /// The independent speeds (indices from 0).
    #[getter]
    fn speeds(&self) -> Vec<usize> {
        self.inner.speeds.clone()
    }

    /// The cyclic coordinates' names: each gives an eigenvalue exactly 0.
    #[getter]
    fn cyclic(&self) -> Vec<String> {
        self.inner
            .cyclic
            .iter()
            .map(|&i| self.coordinates.get(i).cloned().unwrap_or_default())
            .collect()
    }

    /// The full Jacobian `∂F/∂(q, q̇)` of the reduced equations, shape `(2n, 2n)`.
    #[getter]
    fn full<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let d = 2 * self.inner.q.len();
        Ok(PyArray1::from_slice(py, &self.inner.full)
            .reshape([d, d])?
            .into_any())
    }

    /// The tangent basis `T`: `δ(q, q̇) = T δz`, shape `(2n, p)`.
    #[getter]
    fn basis<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let (d, p) = (2 * self.inner.q.len(), self.inner.dim());
        Ok(PyArray1::from_slice(py, &self.inner.basis)
            .reshape([d, p])?
            .into_any())
    }

    fn __repr__(&self) -> String {
        let values: Vec<String> = self
            .inner
            .eigenvalues
            .iter()
            .map(|c| format!("{:.6}{:+.6}j", c.re, c.im))
            .collect();
        format!(
            "Linearization(states=[{}], eigenvalues=[{}])",
            self.states().join(", "),
            values.join(", ")
        )
    }
}

/// Completes a state on the constraints: the dependent coordinates from `h = 0`, then the
/// dependent speeds from `f = 0` and `ḣ = 0`, by Newton's method from the values given (which
/// serve as the guess), the independent ones held. Returns `(q, qd)` as numpy arrays; with
/// `info=True`, `(q, qd, info)` where `info` holds the dependent coordinates and speeds (indices
/// from 0) and the Newton iterations of each stage.
#[pyfunction]
#[pyo3(signature = (model, q, qd, t=0.0, coordinates=None, speeds=None, info=false))]
#[allow(clippy::too_many_arguments)]
fn complete<'py>(
    py: Python<'py>,
    model: Py<Model>,
    q: &Bound<'py, PyAny>,
    qd: &Bound<'py, PyAny>,
    t: f64,
    coordinates: Option<&Bound<'py, PyAny>>,
    speeds: Option<&Bound<'py, PyAny>>,
    info: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let q = state(py, &model, q, "q")?;
    let qd = state(py, &model, qd, "qd")?;
    let independent = independent(py, &model, coordinates, speeds)?;
    let m = (*model.get().inner).clone();
    let done = py
        .detach(|| chetaev::manifold::complete(&m, t, &q, &qd, &independent))
        .map_err(chetaev_error)?;
    let (q, qd) = (
        PyArray1::from_vec(py, done.q),
        PyArray1::from_vec(py, done.qd),
    );
    if !info {
        return Ok((q, qd).into_pyobject(py)?.into_any());
    }
    let details = PyDict::new(py);
    details.set_item("dependent_coordinates", done.dependent_coordinates)?;
    details.set_item("dependent_speeds", done.dependent_speeds)?;
    details.set_item("coordinate_iterations", done.iterations.0)?;
    details.set_item("speed_iterations", done.iterations.1)?;
    Ok((q, qd, details).into_pyobject(py)?.into_any())
}

/// What the library derived for a model: `str()` gives the text; in Jupyter it renders as LaTeX.
#[pyclass(module = "chetaev._chetaev", frozen)]
struct Description {
    text: String,
    latex: String,
    coordinates: Vec<String>,
}

#[pymethods]
impl Description {
    /// The derived equations as one LaTeX `align*` environment (empty where the model could not
    /// be recorded as expressions).
    #[getter]
    fn latex(&self) -> String {
        self.latex.clone()
    }

    fn __str__(&self) -> String {
        self.text.clone()
    }

    fn __repr__(&self) -> String {
        self.text.clone()
    }

    fn _repr_latex_(&self) -> Option<String> {
        if self.latex.is_empty() {
            return None;
        }
        // Jupyter's MathJax renders one display block.
        let body = self
            .latex
            .trim()
            .trim_start_matches("\\begin{align*}")
            .trim_end_matches("\\end{align*}");
        Some(format!(
            "$$q = ({})$$\n$$\\begin{{aligned}}{body}\\end{{aligned}}$$",
            self.coordinates.join(", ")
        ))
    }
}

/// An event: the zeros of `g(t, q, q̇)` are located; `direction` is 'either', 'rising' or
/// 'falling'; a terminal event ends the run. The expression is converted with the model's
/// symbols when the problem is solved.
#[pyclass(module = "chetaev._chetaev", name = "Event", frozen)]
struct EventSpec {
    #[pyo3(get)]
    name: String,
    #[pyo3(get)]
    expression: Py<PyAny>,
    #[pyo3(get)]
    direction: String,
    #[pyo3(get)]
    terminal: bool,
    /// The expression converted for the last model it was solved with (held, so that its
    /// address identifies it), so that a solve repeated on one model converts it once.
    converted: std::sync::Mutex<Option<(Arc<GraphModel>, Event)>>,
}

#[pymethods]
impl EventSpec {
    #[new]
    #[pyo3(signature = (name, expression, direction="either", terminal=false))]
    fn new(name: String, expression: Py<PyAny>, direction: &str, terminal: bool) -> PyResult<Self> {
        parse_direction(direction)?;
        Ok(Self {
            name,
            expression,
            direction: direction.to_string(),
            terminal,
            converted: std::sync::Mutex::new(None),
        })
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        Ok(format!(
            "Event({:?}, {}, direction={:?}, terminal={})",
            self.name,
            self.expression.bind(py).str()?,
            self.direction,
            if self.terminal { "True" } else { "False" }
        ))
    }
}

fn parse_direction(d: &str) -> PyResult<Direction> {
    match d {
        "either" => Ok(Direction::Either),
        "rising" => Ok(Direction::Rising),
        "falling" => Ok(Direction::Falling),
        other => Err(ChetaevError::new_err(format!(
            "unknown event direction '{other}'; write 'either', 'rising' or 'falling'"
        ))),
    }
}

/// A scene: a model, its initial state and its solve options as a TOML text (docs/scenes.md).
#[pyclass(module = "chetaev._chetaev", frozen)]
struct Scene {
    inner: Arc<RustScene>,
}

#[pymethods]
impl Scene {
    /// Reads a scene file.
    #[staticmethod]
    fn load(py: Python<'_>, path: std::path::PathBuf) -> PyResult<Self> {
        let scene = py.detach(|| RustScene::load(&path)).map_err(scene_error)?;
        Ok(Self {
            inner: Arc::new(scene),
        })
    }

    /// Reads a scene from its text; `name` is used in error messages.
    #[staticmethod]
    #[pyo3(signature = (text, name="<scene>"))]
    fn parse(text: &str, name: &str) -> PyResult<Self> {
        Ok(Self {
            inner: Arc::new(RustScene::parse(text, name).map_err(scene_error)?),
        })
    }

    /// Solves the scene with its own options; the solution's `event_names` are the scene's.
    fn solve(&self, py: Python<'_>) -> PyResult<Solution> {
        let scene = Arc::clone(&self.inner);
        let outcome = py.detach(|| scene.solve()).map_err(scene_error)?;
        let names = outcome.event_names.clone();
        Solution::new(py, outcome.solution, names)
    }

    /// The scene's problem, to solve with other options.
    fn problem(&self, py: Python<'_>) -> PyResult<Problem> {
        let scene = Arc::clone(&self.inner);
        let p = py.detach(|| scene.problem()).map_err(scene_error)?;
        Ok(Problem {
            inner: Inner::Scene(Arc::new(p)),
            model: None,
            coordinates: self.inner.coordinates.clone(),
            route: "graph",
            machine_code: "auto",
        })
    }

    /// What the library derived for the scene's model, as text (`latex=True`: LaTeX).
    #[pyo3(signature = (latex=false))]
    fn describe(&self, py: Python<'_>, latex: bool) -> PyResult<String> {
        let scene = Arc::clone(&self.inner);
        py.detach(|| {
            if latex {
                scene.describe_latex()
            } else {
                scene.describe()
            }
        })
        .map_err(scene_error)
    }

    /// The coordinates' names.
    #[getter]
    fn coordinates(&self) -> Vec<String> {
        self.inner.coordinates.clone()
    }

    /// Runs the scene over a grid or a random sample of its parameters and initial values
    /// (docs/sweeps.md), in parallel over `jobs` threads (default: every core), and returns the
    /// table of runs. `vary` adds to (or replaces entries of) the scene's `[sweep]`: a name (a
    /// parameter, `initial.x`, `initial.x_dot`) with a list of values, a dict `{'from', 'to',
    /// 'count', 'scale'}` (without `count`: sampled at random, `samples` times), or the command
    /// line's string (`'1:100:5:log'`). `shard='k/n'` runs only that shard (write it, then
    /// `merge_sweeps`).
    #[pyo3(signature = (vary=None, *, samples=None, seed=None, design=None, collect=None, shard=None, jobs=None, yes=false))]
    #[allow(clippy::too_many_arguments)]
    fn sweep(
        &self,
        py: Python<'_>,
        vary: Option<&Bound<'_, PyDict>>,
        samples: Option<usize>,
        seed: Option<u64>,
        design: Option<String>,
        collect: Option<Vec<String>>,
        shard: Option<String>,
        jobs: Option<usize>,
        yes: bool,
    ) -> PyResult<sweep::SweepTable> {
        sweep::run(
            py,
            &self.inner,
            vary,
            samples,
            seed,
            design,
            collect,
            shard,
            jobs,
            yes,
        )
    }

    /// What in the scene is valid but may not be what was meant (an `e` read as Euler's number),
    /// each as `path:line:column: message`, in the order of the file; empty for most scenes.
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.inner
            .warnings
            .iter()
            .map(ToString::to_string)
            .collect()
    }
}

/// A seed for sensitivities: the derivative of the motion with respect to a direction in the
/// parameters and initial values.
#[pyclass(module = "chetaev._chetaev", frozen)]
#[derive(Clone)]
struct Seed {
    inner: RustSeed,
}

#[pymethods]
impl Seed {
    /// A seed named `name`: `parameters={name: rate}`, `positions={i: rate}` and
    /// `velocities={i: rate}` (coordinate indices from 0) give its direction.
    #[new]
    #[pyo3(signature = (name, parameters=None, positions=None, velocities=None))]
    fn new(
        name: String,
        parameters: Option<&Bound<'_, PyDict>>,
        positions: Option<Vec<(usize, f64)>>,
        velocities: Option<Vec<(usize, f64)>>,
    ) -> PyResult<Self> {
        let mut s = RustSeed::new(name);
        if let Some(p) = parameters {
            for (k, v) in p.iter() {
                s = s.with_parameter(&k.str()?.to_string(), v.extract()?);
            }
        }
        for (i, r) in positions.unwrap_or_default() {
            s = s.with_position(i, r);
        }
        for (i, r) in velocities.unwrap_or_default() {
            s = s.with_velocity(i, r);
        }
        Ok(Self { inner: s })
    }

    /// The derivative with respect to one parameter (a name or a sympy symbol).
    #[staticmethod]
    fn parameter(name: &Bound<'_, PyAny>) -> PyResult<Self> {
        Ok(Self {
            inner: RustSeed::parameter(&name.str()?.to_string()),
        })
    }

    /// The derivative with respect to the initial position `q0[i]`.
    #[staticmethod]
    fn position(i: usize) -> Self {
        Self {
            inner: RustSeed::position(i),
        }
    }

    /// The derivative with respect to the initial velocity `q̇0[i]`.
    #[staticmethod]
    fn velocity(i: usize) -> Self {
        Self {
            inner: RustSeed::velocity(i),
        }
    }

    #[getter]
    fn name(&self) -> String {
        self.inner.name.clone()
    }

    fn __repr__(&self) -> String {
        format!(
            "Seed('{}')",
            self.inner.name.replace('\\', "\\\\").replace('\'', "\\'")
        )
    }
}

fn record(name: &str) -> PyResult<Record> {
    match name {
        "state" => Ok(Record::State),
        "dynamics" => Ok(Record::Dynamics),
        "energy" => Ok(Record::Energy),
        other => Err(ChetaevError::new_err(format!(
            "unknown record level '{other}'; write 'state' (t, q, q̇), 'dynamics' (also q̈, μ, Φ, f) or 'energy' (also E and the work, the default)"
        ))),
    }
}

/// The options, from the keyword arguments of `solve`.
struct Asked<'py> {
    t_end: f64,
    rtol: Option<f64>,
    atol: Option<Bound<'py, PyAny>>,
    output: Option<Bound<'py, PyAny>>,
    record: &'py str,
    events: Vec<Py<EventSpec>>,
    project: Option<Bound<'py, PyAny>>,
    max_step: Option<f64>,
    initial_step: Option<f64>,
    max_steps: Option<usize>,
    event_samples: Option<usize>,
    sensitivities: Vec<Bound<'py, PyAny>>,
    sensitivity_control: bool,
}

fn options(py: Python<'_>, problem: &Problem, a: Asked<'_>) -> PyResult<(Options, Vec<String>)> {
    let mut o = Options::until(a.t_end);
    if let Some(r) = a.rtol {
        o.rtol = r;
    }
    if let Some(atol) = a.atol {
        o.atol = match atol.extract::<f64>() {
            Ok(x) => Atol::Scalar(x),
            Err(_) => Atol::PerComponent(atol.extract::<Vec<f64>>().map_err(|_| {
                ChetaevError::new_err(
                    "atol must be a number or a sequence of 2n numbers (the n positions, then the n velocities)",
                )
            })?),
        };
    }
    if let Some(out) = a.output {
        o.output = if let Ok(s) = out.extract::<String>() {
            match s.as_str() {
                "steps" => Output::Steps,
                "final" => Output::Final,
                other => {
                    return Err(ChetaevError::new_err(format!(
                        "unknown output '{other}'; write 'steps' (every accepted step, the default), 'final', or give the times as a sequence"
                    )))
                }
            }
        } else {
            Output::Times(out.extract::<Vec<f64>>().map_err(|_| {
                ChetaevError::new_err(
                    "output must be 'steps', 'final' or a sequence of times (a numpy array will do)",
                )
            })?)
        };
    }
    o.record = record(a.record)?;
    if let Some(h) = a.max_step {
        o.max_step = Some(h);
    }
    if let Some(h) = a.initial_step {
        o.initial_step = Some(h);
    }
    if let Some(m) = a.max_steps {
        o.max_steps = m;
    }
    if let Some(s) = a.event_samples {
        o.event_samples = s;
    }
    if let Some(p) = a.project {
        if let Ok(on) = p.extract::<bool>() {
            if on {
                o.projection = Some(Projection::default());
            }
        } else if let Ok(tol) = p.extract::<f64>() {
            o.projection = Some(Projection {
                tol,
                ..Projection::default()
            });
        } else {
            return Err(ChetaevError::new_err(
                "project must be True, False or the relative residual to hold (a number such as 1e-12)",
            ));
        }
    }
    for s in a.sensitivities {
        let seed = if let Ok(seed) = s.cast::<Seed>() {
            seed.get().inner.clone()
        } else {
            RustSeed::parameter(&s.str()?.to_string())
        };
        o.sensitivities.push(seed);
    }
    o.sensitivity_control = a.sensitivity_control;
    let mut names = Vec::new();
    for e in a.events {
        let e = e.get();
        let model = problem.model.as_ref().ok_or_else(|| {
            ChetaevError::new_err(
                "events on a scene's problem are declared in the scene file ([[events]]); solve it with scene.solve(), or build the model with Model.from_sympy",
            )
        })?;
        names.push(e.name.clone());
        o.events.push(event_for(py, model, e)?);
    }
    Ok((o, names))
}

/// The event for `model`: its expression as operations on the model's graph, converted by the
/// Python side, made once per model (a solve repeated on one model reuses it).
fn event_for(py: Python<'_>, model: &Py<Model>, e: &EventSpec) -> PyResult<Event> {
    let m = model.get();
    if let Ok(cache) = e.converted.lock() {
        if let Some((held, event)) = cache.as_ref() {
            if Arc::ptr_eq(held, &m.inner) {
                return Ok(event.clone());
            }
        }
    }
    let converted = py
        .import("chetaev._sympy")?
        .getattr("expression_ops")?
        .call1((model.bind(py), e.expression.bind(py)))?;
    let (ops, root): (Vec<OpSpec>, u32) = converted.extract()?;
    let g = m
        .inner
        .expression(|g| {
            for (name, args, value) in &ops {
                g.push(name, args, *value)?;
            }
            Ok(root)
        })
        .map_err(|err| ChetaevError::new_err(format!("event '{}': {}", e.name, err.message)))?;
    let mut event = Event::smooth(e.name.clone(), g);
    event.direction = parse_direction(&e.direction)?;
    event.terminal = e.terminal;
    if let Ok(mut cache) = e.converted.lock() {
        *cache = Some((Arc::clone(&m.inner), event.clone()));
    }
    Ok(event)
}

/// Solves a problem from its initial state to `t_end`: Chetaev's equations in Newton form,
///
///     d/dt ∂L/∂q̇ − ∂L/∂q = Σ_a μ_a ∂f_a/∂q̇ + Q,   f(t, q, q̇) = 0,   h(t, q) = 0,
///
/// reduced by eliminating the multipliers μ (a pivoted block solve) and integrated.
///
/// Arguments:
///     problem: a `Problem` (or `scene.problem()`).
///     t_end: the end time (earlier than t0 integrates backward).
///     method: 'dop853' (default), 'dopri5', 'tsit5', 'rk4' (fixed `step`), 'rodas4' or
///         'rodas5p' (implicit, for stiff problems); `chetaev.methods()` lists them.
///     rtol, atol: tolerances (default 1e-6 and 1e-9); `atol` may be 2n numbers (positions,
///         then velocities).
///     step: the fixed step of 'rk4'.
///     output: 'steps' (every accepted step, default), 'final', or a sequence of times.
///     record: 'state' (t, q, q̇), 'dynamics' (also q̈, μ, Φ, f) or 'energy' (also E, the work
///         of Φ and the energy balance; the default).
///     events: `Event`s (sympy expressions or strings on the coordinates, `x_dot` for ẋ).
///     project: True (or a relative residual such as 1e-12) to project the state back onto
///         the constraints after each step.
///     max_step, initial_step, max_steps, event_samples: step control.
///     sensitivities: parameter symbols or names, or `Seed`s: the derivatives of the motion and
///         of the events with respect to them; `sensitivity_control` puts them under error
///         control.
///     stiffness_detection: False switches off the explicit methods' stiffness test (on by
///         default: a stiff problem stops with advice to use 'rodas4').
///     controller: the step-size controller, `{"safety", "fac_min", "fac_max", "beta"}` (each
///         method's own by default).
///     rank_tolerance: the block solve's rank threshold (1e-8).
///
/// Returns a `Solution`. A run that fails returns the motion up to the failure, with
/// `status == 'failed'` and the reason in `message`; input that cannot be used raises
/// `ChetaevError`. The GIL is released while the problem is solved.
#[pyfunction]
#[pyo3(signature = (problem, t_end, method="dop853", rtol=None, atol=None, step=None, output=None, record="energy", events=vec![], project=None, max_step=None, initial_step=None, max_steps=None, event_samples=None, sensitivities=vec![], sensitivity_control=false, stiffness_detection=None, controller=None, rank_tolerance=None))]
#[allow(clippy::too_many_arguments)]
fn solve<'py>(
    py: Python<'py>,
    problem: &Problem,
    t_end: f64,
    method: &str,
    rtol: Option<f64>,
    atol: Option<Bound<'py, PyAny>>,
    step: Option<f64>,
    output: Option<Bound<'py, PyAny>>,
    record: &'py str,
    events: Vec<Py<EventSpec>>,
    project: Option<Bound<'py, PyAny>>,
    max_step: Option<f64>,
    initial_step: Option<f64>,
    max_steps: Option<usize>,
    event_samples: Option<usize>,
    sensitivities: Vec<Bound<'py, PyAny>>,
    sensitivity_control: bool,
    stiffness_detection: Option<bool>,
    controller: Option<&Bound<'py, PyDict>>,
    rank_tolerance: Option<f64>,
) -> PyResult<Solution> {
    let fixed = method.eq_ignore_ascii_case("rk4");
    if step.is_some() && !fixed {
        return Err(ChetaevError::new_err(format!(
            "step= is the fixed step of 'rk4'; '{method}' chooses its own steps by rtol and atol (bound them with max_step= or initial_step=)"
        )));
    }
    if fixed && (rtol.is_some() || atol.is_some()) {
        return Err(ChetaevError::new_err(
            "'rk4' takes fixed steps (step=) and has no error control, so rtol and atol would be ignored; leave them out, or choose an adaptive method such as 'dop853'",
        ));
    }
    let mut method = AnyMethod::from_name(method, step).map_err(chetaev_error)?;
    if let Some(on) = stiffness_detection {
        let test = match &mut method {
            AnyMethod::Dopri5(m) => &mut m.stiffness,
            AnyMethod::Dop853(m) => &mut m.stiffness,
            AnyMethod::Tsit5(m) => &mut m.stiffness,
            _ => {
                return Err(ChetaevError::new_err(
                    "stiffness_detection= applies to the explicit methods with error control ('dopri5', 'dop853', 'tsit5'); the implicit ones are made for stiff problems and 'rk4' has no error estimate",
                ))
            }
        };
        test.enabled = on;
    }
    let controller = controller.map(step_controller).transpose()?;
    let asked = Asked {
        t_end,
        rtol,
        atol,
        output,
        record,
        events,
        project,
        max_step,
        initial_step,
        max_steps,
        event_samples,
        sensitivities,
        sensitivity_control,
    };
    let (mut options, names) = options(py, problem, asked)?;
    options.controller = controller;
    if let Some(r) = rank_tolerance {
        options.rank_tolerance = r;
    }
    let inner = problem.inner.clone();
    let solution = py
        .detach(|| with_problem!(&inner, p => chetaev::solve(&**p, method, &options)))
        .map_err(chetaev_error)?;
    Solution::new(py, solution, names)
}

/// The seconds each of `repeats` solves takes inside Rust, timed there: the same problem, method
/// and options as `solve` with these arguments, without the Python call and the conversion of the
/// solution. For the benchmark of the bindings' overhead (bench/python/overhead.py).
#[pyfunction]
#[pyo3(signature = (problem, t_end, repeats, method="dop853", rtol=None, atol=None, output=None, record="energy", events=vec![]))]
#[allow(clippy::too_many_arguments)]
fn _solve_seconds<'py>(
    py: Python<'py>,
    problem: &Problem,
    t_end: f64,
    repeats: usize,
    method: &str,
    rtol: Option<f64>,
    atol: Option<Bound<'py, PyAny>>,
    output: Option<Bound<'py, PyAny>>,
    record: &'py str,
    events: Vec<Py<EventSpec>>,
) -> PyResult<Vec<f64>> {
    let method = AnyMethod::from_name(method, None).map_err(chetaev_error)?;
    let asked = Asked {
        t_end,
        rtol,
        atol,
        output,
        record,
        events,
        project: None,
        max_step: None,
        initial_step: None,
        max_steps: None,
        event_samples: None,
        sensitivities: Vec::new(),
        sensitivity_control: false,
    };
    let (options, _) = options(py, problem, asked)?;
    let inner = problem.inner.clone();
    py.detach(|| {
        (0..repeats)
            .map(|_| {
                // The solution is dropped inside the timing, as a caller's would be.
                let start = std::time::Instant::now();
                let s = with_problem!(&inner, p => chetaev::solve(&**p, method, &options))?;
                drop(std::hint::black_box(s));
                Ok(start.elapsed().as_secs_f64())
            })
            .collect::<Result<Vec<f64>, chetaev::Error>>()
    })
    .map_err(chetaev_error)
}

/// A step-size controller from `{"safety": .., "fac_min": .., "fac_max": .., "beta": ..}` (missing
/// keys: the I controller's 0.9, 0.2, 10, 0).
fn step_controller(d: &Bound<'_, PyDict>) -> PyResult<chetaev::prelude::Controller> {
    let mut c = chetaev::prelude::Controller::i(0.2, 10.0);
    for (k, v) in d.iter() {
        let key = k.str()?.to_string();
        let value: f64 = v.extract()?;
        match key.as_str() {
            "safety" => c.safety = value,
            "fac_min" => c.fac_min = value,
            "fac_max" => c.fac_max = value,
            "beta" => c.beta = value,
            other => {
                return Err(ChetaevError::new_err(format!(
                    "unknown controller key '{other}'; the keys are safety, fac_min, fac_max and beta (the PI controller's β; 0 is the I controller)"
                )))
            }
        }
    }
    Ok(c)
}

/// The located crossing of an event.
#[pyclass(module = "chetaev._chetaev", frozen)]
struct EventHit {
    index: usize,
    name: String,
    t: f64,
    q: Vec<f64>,
    qd: Vec<f64>,
    dt: Vec<(String, f64)>,
}

#[pymethods]
impl EventHit {
    /// The event's index in `events`.
    #[getter]
    fn index(&self) -> usize {
        self.index
    }

    /// Its name.
    #[getter]
    fn name(&self) -> &str {
        &self.name
    }

    /// The time of the crossing.
    #[getter]
    fn t(&self) -> f64 {
        self.t
    }

    /// `q` there.
    #[getter]
    fn q<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.q)
    }

    /// `q̇` there.
    #[getter]
    fn qd<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.qd)
    }

    /// `∂t/∂θ` for each seed (empty without sensitivities, or where the crossing is tangential).
    #[getter]
    fn dt<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (k, v) in &self.dt {
            d.set_item(k, v)?;
        }
        Ok(d)
    }

    fn __repr__(&self) -> String {
        format!("EventHit({:?}, t={})", self.name, self.t)
    }
}

/// The motion and everything recorded along it: numpy arrays with one row per recorded point,
/// made from the Rust solution on first access (and kept).
#[pyclass(module = "chetaev._chetaev", frozen)]
struct Solution {
    inner: RustSolution,
    names: Vec<String>,
    cache: Cache,
}

/// The arrays made so far, one cell per attribute.
#[derive(Default)]
struct Cache {
    t: OnceLock<Py<PyAny>>,
    q: OnceLock<Py<PyAny>>,
    qd: OnceLock<Py<PyAny>>,
    qdd: OnceLock<Py<PyAny>>,
    mu: OnceLock<Py<PyAny>>,
    phi: OnceLock<Py<PyAny>>,
    residual: OnceLock<Py<PyAny>>,
    relative_residual: OnceLock<Py<PyAny>>,
    position_residual: OnceLock<Py<PyAny>>,
    energy: OnceLock<Py<PyAny>>,
    work: OnceLock<Py<PyAny>>,
    dl_dt_integral: OnceLock<Py<PyAny>>,
    work_forces: OnceLock<Py<PyAny>>,
    energy_balance: OnceLock<Py<PyAny>>,
    events: OnceLock<Py<PyAny>>,
    sensitivities: OnceLock<Py<PyAny>>,
    stats: OnceLock<Py<PyAny>>,
}

/// The value in `cell`, made by `make` on first use.
fn cached(
    py: Python<'_>,
    cell: &OnceLock<Py<PyAny>>,
    make: impl FnOnce() -> PyResult<Py<PyAny>>,
) -> PyResult<Py<PyAny>> {
    if let Some(v) = cell.get() {
        return Ok(v.clone_ref(py));
    }
    let v = make()?;
    // Another thread may have made it meanwhile: either value is the same array.
    let _ = cell.set(v.clone_ref(py));
    Ok(v)
}

/// A series as an `(m, width)` array; a series of width 0 (no constraints of its kind) has one
/// empty row per recorded point, `rows`.
fn series(py: Python<'_>, s: &chetaev::prelude::Series, rows: usize) -> PyResult<Py<PyAny>> {
    let rows = if s.width() == 0 { rows } else { s.len() };
    Ok(PyArray1::from_slice(py, s.as_flat())
        .reshape([rows, s.width()])?
        .into_any()
        .unbind())
}

fn vector(py: Python<'_>, v: &[f64]) -> Py<PyAny> {
    PyArray1::from_slice(py, v).into_any().unbind()
}

impl Solution {
    fn new(_py: Python<'_>, inner: RustSolution, names: Vec<String>) -> PyResult<Self> {
        Ok(Self {
            inner,
            names,
            cache: Cache::default(),
        })
    }

    /// The series `s` as an `(m, width)` array, kept in `cell`.
    fn series(
        &self,
        py: Python<'_>,
        cell: &OnceLock<Py<PyAny>>,
        s: &chetaev::prelude::Series,
    ) -> PyResult<Py<PyAny>> {
        cached(py, cell, || series(py, s, self.inner.t.len()))
    }

    /// The values `v` as an `(m,)` array, kept in `cell`.
    fn vector(&self, py: Python<'_>, cell: &OnceLock<Py<PyAny>>, v: &[f64]) -> PyResult<Py<PyAny>> {
        cached(py, cell, || Ok(vector(py, v)))
    }
}

#[pymethods]
impl Solution {
    /// `q`, shape `(m, n)`.
    #[getter]
    fn q(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        self.series(py, &self.cache.q, &self.inner.q)
    }

    /// `q̇`, shape `(m, n)`.
    #[getter]
    fn qd(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        self.series(py, &self.cache.qd, &self.inner.qd)
    }

    /// `q̈`, shape `(m, n)` (no columns below record='dynamics').
    #[getter]
    fn qdd(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        self.series(py, &self.cache.qdd, &self.inner.qdd)
    }

    /// The multipliers `μ`, shape `(m, k)`, Newton form: `d/dt ∂L/∂q̇ − ∂L/∂q = Jᵀμ + Q`.
    #[getter]
    fn mu(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        self.series(py, &self.cache.mu, &self.inner.mu)
    }

    /// The Chetaev force `Φ = Σ_a μ_a ∂f_a/∂q̇`, shape `(m, n)`.
    #[getter]
    fn phi(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        self.series(py, &self.cache.phi, &self.inner.phi)
    }

    /// The residual `f` of the velocity constraints (and `ḣ` of the holonomic ones), shape `(m, k)`.
    #[getter]
    fn residual(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        self.series(py, &self.cache.residual, &self.inner.residual)
    }

    /// `h(t, q)` of the holonomic constraints, shape `(m, kh)`.
    #[getter]
    fn position_residual(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        self.series(
            py,
            &self.cache.position_residual,
            &self.inner.position_residual,
        )
    }

    /// `t`, shape `(m,)`.
    #[getter]
    fn t(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        self.vector(py, &self.cache.t, &self.inner.t)
    }

    /// `max_a |f_a| / (|J_a|·|q̇|)` at each point, shape `(m,)`.
    #[getter]
    fn relative_residual(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        self.vector(
            py,
            &self.cache.relative_residual,
            &self.inner.relative_residual,
        )
    }

    /// The energy `E = q̇·∂L/∂q̇ − L`, shape `(m,)`.
    #[getter]
    fn energy(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        self.vector(py, &self.cache.energy, &self.inner.energy)
    }

    /// The work of the Chetaev force, `W_Φ = ∫ q̇·Φ dt`, shape `(m,)`.
    #[getter]
    fn work(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        self.vector(py, &self.cache.work, &self.inner.work)
    }

    /// `∫ ∂L/∂t dt`, shape `(m,)`.
    #[getter]
    fn dl_dt_integral(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        self.vector(py, &self.cache.dl_dt_integral, &self.inner.dl_dt_integral)
    }

    /// The work of the forces not derivable from `L`, shape `(m,)`.
    #[getter]
    fn work_forces(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        self.vector(py, &self.cache.work_forces, &self.inner.work_forces)
    }

    /// `E − E(t0) − W_Φ − W_Q + ∫∂L/∂t dt`: zero along an exact motion, shape `(m,)`.
    #[getter]
    fn energy_balance(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        cached(py, &self.cache.energy_balance, || {
            Ok(vector(py, &self.inner.energy_balance()))
        })
    }

    /// The located events, in order (`EventHit`s).
    #[getter]
    fn events(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        cached(py, &self.cache.events, || {
            let s = &self.inner;
            let events = PyList::empty(py);
            for (i, e) in s.events.iter().enumerate() {
                let dt = match &s.sensitivities {
                    Some(sens) => match sens.events.get(i) {
                        Some(Some(es)) => sens
                            .names
                            .iter()
                            .cloned()
                            .zip(es.t.iter().copied())
                            .collect(),
                        _ => Vec::new(),
                    },
                    None => Vec::new(),
                };
                events.append(EventHit {
                    index: e.index,
                    name: self.names.get(e.index).cloned().unwrap_or_default(),
                    t: e.t,
                    q: e.q.clone(),
                    qd: e.qd.clone(),
                    dt,
                })?;
            }
            Ok(events.into_any().unbind())
        })
    }

    /// The sensitivities: `{seed name: {"q": (m, n), "qd": (m, n), "mu": (m, k), "phi": (m, n)}}`
    /// (`mu`, `phi`: the total derivatives of the multipliers and the Chetaev force, present where
    /// they are recorded, `record="dynamics"` and above), or None without seeds.
    #[getter]
    fn sensitivities(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        cached(py, &self.cache.sensitivities, || {
            let s = &self.inner;
            let Some(sens) = &s.sensitivities else {
                return Ok(py.None());
            };
            let d = PyDict::new(py);
            let n = s.n();
            let rows = sens.values.len();
            for (j, name) in sens.names.iter().enumerate() {
                let (mut dq, mut dqd) =
                    (Vec::with_capacity(rows * n), Vec::with_capacity(rows * n));
                for i in 0..rows {
                    dq.extend_from_slice(sens.q(i, j));
                    dqd.extend_from_slice(sens.qd(i, j));
                }
                let entry = PyDict::new(py);
                entry.set_item("q", PyArray1::from_vec(py, dq).reshape([rows, n])?)?;
                entry.set_item("qd", PyArray1::from_vec(py, dqd).reshape([rows, n])?)?;
                // dμ/dθ and dΦ/dθ where the multipliers are recorded.
                if sens.mu.len() == rows {
                    let k = s.k();
                    let (mut dmu, mut dphi) =
                        (Vec::with_capacity(rows * k), Vec::with_capacity(rows * n));
                    for i in 0..rows {
                        dmu.extend_from_slice(sens.mu(i, j).unwrap_or_default());
                        dphi.extend_from_slice(sens.phi(i, j).unwrap_or_default());
                    }
                    entry.set_item("mu", PyArray1::from_vec(py, dmu).reshape([rows, k])?)?;
                    entry.set_item("phi", PyArray1::from_vec(py, dphi).reshape([rows, n])?)?;
                }
                d.set_item(name, entry)?;
            }
            Ok(d.into_any().unbind())
        })
    }

    /// Counts: right-hand sides, steps, Jacobians, projections, event evaluations, ...
    #[getter]
    fn stats(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        cached(py, &self.cache.stats, || {
            let st = &self.inner.stats;
            let stats = PyDict::new(py);
            for (k, v) in [
                ("rhs_evaluations", st.rhs_evaluations),
                ("jacobian_evaluations", st.jacobian_evaluations),
                ("lu_decompositions", st.lu_decompositions),
                ("output_evaluations", st.output_evaluations),
                ("accepted_steps", st.accepted_steps),
                ("rejected_steps", st.rejected_steps),
                ("projections", st.projections),
                ("projection_iterations", st.projection_iterations),
                ("event_evaluations", st.event_evaluations),
                ("graph_fallbacks", st.graph_fallbacks),
            ] {
                stats.set_item(k, v)?;
            }
            Ok(stats.into_any().unbind())
        })
    }

    /// The method's name.
    #[getter]
    fn method(&self) -> &'static str {
        self.inner.method
    }

    /// 'success' (the end time), 'terminated' (a terminal event) or 'failed'.
    #[getter]
    fn status(&self) -> &'static str {
        match self.inner.status {
            Status::Success => "success",
            Status::Terminated { .. } => "terminated",
            Status::Failed(_) => "failed",
        }
    }

    /// What the run did that one may not expect, though nothing failed, as sentences (an event
    /// zero at the start, armed only once it left zero); empty for an ordinary run.
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.inner.warnings.iter().map(|w| w.to_string()).collect()
    }

    /// The index of the terminal event that ended the run, or None.
    #[getter]
    fn terminated_by(&self) -> Option<usize> {
        match self.inner.status {
            Status::Terminated { event } => Some(event),
            _ => None,
        }
    }

    /// Why the run failed (the library's message, with advice), or None.
    #[getter]
    fn message(&self) -> Option<String> {
        match &self.inner.status {
            Status::Failed(e) => Some(pythonic(&e.to_string())),
            _ => None,
        }
    }

    /// Whether the end time or a terminal event was reached.
    #[getter]
    fn success(&self) -> bool {
        !matches!(self.inner.status, Status::Failed(_))
    }

    /// The number of coordinates `n`.
    #[getter]
    fn n(&self) -> usize {
        self.inner.n()
    }

    /// The number of multipliers `k`.
    #[getter]
    fn k(&self) -> usize {
        self.inner.k()
    }

    fn __len__(&self) -> usize {
        self.inner.len()
    }

    fn __repr__(&self) -> String {
        let tail = match self.message() {
            Some(m) => format!(", message={m:?}"),
            None => String::new(),
        };
        format!(
            "Solution(method={:?}, status={:?}, points={}{tail})",
            self.inner.method,
            self.status(),
            self.inner.len()
        )
    }
}

/// The names of the methods, for `solve(method=...)`.
#[pyfunction]
fn methods() -> Vec<String> {
    AnyMethod::NAMES.iter().map(|n| n.to_lowercase()).collect()
}

#[pymodule]
fn _chetaev(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Model>()?;
    m.add_class::<Problem>()?;
    m.add_class::<Description>()?;
    m.add_class::<EventSpec>()?;
    m.add_class::<EventHit>()?;
    m.add_class::<Scene>()?;
    m.add_class::<Seed>()?;
    m.add_class::<Solution>()?;
    sweep::register(m)?;
    m.add_function(wrap_pyfunction!(solve, m)?)?;
    m.add_function(wrap_pyfunction!(methods, m)?)?;
    m.add_function(wrap_pyfunction!(complete, m)?)?;
    m.add_class::<Linearization>()?;
    m.add_function(wrap_pyfunction!(_solve_seconds, m)?)?;
    // Raised and pickled as `chetaev.ChetaevError` (a process pool sends them back by name).
    for t in [
        m.py().get_type::<ChetaevError>(),
        m.py().get_type::<SceneError>(),
    ] {
        t.setattr("__module__", "chetaev")?;
    }
    m.add("ChetaevError", m.py().get_type::<ChetaevError>())?;
    m.add("SceneError", m.py().get_type::<SceneError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
