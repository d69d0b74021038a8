//! Sweeps of a scene: the same scene run over a grid or a random sample of its parameters and
//! initial values, with chosen quantities collected from every run (`chetaev sweep`,
//! docs/sweeps.md).
//!
//! | step | where | what |
//! |---|---|---|
//! | what varies | [`Sweep::parse`], `[sweep]` and [`SweepArgs`] | parameters and initial values: lists, linear and logarithmic grids, random samples (uniform or Latin hypercube) from a seed |
//! | what is collected | [`Quantity`] | event times and states, the end state, values at given times, extremes over the steps, sensitivities |
//! | the runs | [`Sweep::run`] | each point's scene validated and solved on its own, in parallel over the cores; a point that fails is a row with its status and reason |
//! | the table | [`table`] | rows as CSV and as the JSON part files of `--shard k/n`, joined by [`table::merge`] |
//!
//! The points are numbered `0..len`: the grid's axes in the order written (the last varies
//! fastest), and within each grid point the random samples. A point's values are a function of
//! the specification and its index alone, so a shard computes exactly the rows the whole sweep
//! would ([`chetaev_parts::Shard`]).
//!
//! ```
//! use chetaev_scene::sweep::{Sweep, SweepArgs};
//!
//! let text = r#"
//!     [parameters]
//!     g = 10.0
//!     v0 = 10.0
//!     h0 = 5.0
//!     [model]
//!     coordinates = ["x", "y"]
//!     lagrangian = "0.5*(x_dot^2 + y_dot^2) - g*y"
//!     constraints = ["x_dot^2 + y_dot^2 - v0^2"]
//!     [initial]
//!     q = [0.0, "h0"]
//!     q_dot = ["v0", 0.0]
//!     [solve]
//!     t_end = 10.0
//!     rtol = 1e-10
//!     atol = 1e-10
//!     [[events]]
//!     name = "impact"
//!     expression = "y"
//!     direction = "falling"
//!     terminal = true
//!     [sweep]
//!     vary = { h0 = [1.0, 5.0, 20.0] }
//!     collect = ["impact.t"]
//! "#;
//! let sweep = Sweep::parse(text, "projectile.toml", &SweepArgs::default())?;
//! let rows = sweep.run(&[0, 1, 2], &|| {});
//! for row in &rows {
//!     // T = (v0/g) arccosh e^(g h0/v0²), (42.32)
//!     let h0 = row.values[0];
//!     let exact = (10.0f64 * h0 / 100.0).exp().acosh();
//!     assert!((row.quantities[0] - exact).abs() < 1e-8);
//! }
//! # Ok::<(), chetaev_scene::Error>(())
//! ```

pub mod collect;
mod design;
#[cfg(feature = "parquet")]
pub mod parquet;
pub mod picture;
pub mod table;

use std::ops::Range;
use std::path::Path;

use rayon::prelude::*;
use toml::Spanned;

use crate::error::{Error, SourceFile};
use crate::scene::{Number, RawScene, RawSweep};
use crate::Scene;

pub use collect::{Extreme, Of, Part, Quantity};
pub use design::{Axis, Design, Scale};
pub use table::{Row, RunStatus};

/// Runs a sweep may have without being confirmed (`--yes`, [`SweepArgs::yes`]).
pub const MAX_RUNS_UNCONFIRMED: usize = 1_000_000;

/// What a sweep varies: a parameter, or an initial coordinate or velocity.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Variable {
    /// A parameter of `[parameters]`, by name; the parameters computed from it follow it.
    Parameter(String),
    /// The initial value of coordinate `index` (`initial.x`).
    Position {
        /// The coordinate, from 0.
        index: usize,
        /// Its name.
        name: String,
    },
    /// The initial velocity of coordinate `index` (`initial.x_dot`).
    Velocity {
        /// The coordinate, from 0.
        index: usize,
        /// Its name.
        name: String,
    },
}

impl Variable {
    /// The variable's name as written: `v0`, `initial.y`, `initial.y_dot`.
    pub fn name(&self) -> String {
        match self {
            Variable::Parameter(p) => p.clone(),
            Variable::Position { name, .. } => format!("initial.{name}"),
            Variable::Velocity { name, .. } => format!("initial.{name}_dot"),
        }
    }
}

/// A variable and how it varies.
#[derive(Clone, Debug, PartialEq)]
pub struct Varied {
    /// What varies.
    pub variable: Variable,
    /// Its values: a list or grid, or a range sampled at random.
    pub axis: Axis,
}

/// A sweep given on the command line, added to (or replacing) the scene file's `[sweep]`.
#[derive(Clone, Debug, Default)]
pub struct SweepArgs {
    /// `NAME=SPEC`: `v0=5:20:4` (4 values from 5 to 20), `v0=1:100:5:log`, `v0=1,2,5` (a list),
    /// `v0=5:20` or `v0=1:100:log` (a range sampled at random). A name also in the file replaces
    /// the file's entry.
    pub vary: Vec<String>,
    /// Random samples per grid point.
    pub samples: Option<usize>,
    /// The seed of the random samples.
    pub seed: Option<u64>,
    /// `uniform` or `latin`.
    pub design: Option<String>,
    /// The quantities to collect, replacing the file's `collect`.
    pub collect: Option<Vec<String>>,
    /// Allows more than [`MAX_RUNS_UNCONFIRMED`] runs.
    pub yes: bool,
}

/// A scene and the sweep over it, checked: every variable known, every range valid, every
/// quantity readable from a run. Run it with [`Sweep::run`].
#[derive(Clone)]
pub struct Sweep {
    file: SourceFile,
    raw: RawScene,
    /// The scene as written (the sweep's base point).
    pub scene: Scene,
    /// What varies, in order: the grid's axes (the last varies fastest), then the random ranges.
    pub varied: Vec<Varied>,
    /// Random samples per grid point (0 without random ranges).
    pub samples: usize,
    /// The seed of the random samples.
    pub seed: u64,
    /// How the random ranges are sampled.
    pub design: Design,
    /// What is collected from each run.
    pub collect: Vec<Quantity>,
    /// The random samples, `samples × (number of random ranges)`, in `[0, 1)`.
    unit_samples: Vec<f64>,
    len: usize,
}

impl Sweep {
    /// Reads the scene file at `path` and its sweep ([`Sweep::parse`]).
    pub fn load(path: impl AsRef<Path>, args: &SweepArgs) -> Result<Self, Error> {
        let path = path.as_ref();
        let text = crate::scene::read_text(path)?;
        Self::parse(&text, &path.display().to_string(), args)
    }

    /// Whether the scene's file has a `[sweep]` table.
    pub fn declared_in(scene: &Scene) -> bool {
        Scene::read_raw(&scene.file.text, &scene.file.path)
            .is_ok_and(|(_, raw)| raw.sweep.is_some())
    }

    /// The sweep over a scene already read ([`Sweep::parse`] of its text).
    pub fn of_scene(scene: &Scene, args: &SweepArgs) -> Result<Self, Error> {
        Self::parse(&scene.file.text, &scene.file.path, args)
    }

    /// Validates a scene given as text and the sweep over it: the file's `[sweep]` with `args`
    /// added. Nothing is run; every mistake in the specification is an error here.
    pub fn parse(text: &str, path: &str, args: &SweepArgs) -> Result<Self, Error> {
        // The TOML read once: validated as the scene, kept raw for the points.
        let (file, raw) = Scene::read_raw(text, path)?;
        let scene = Scene::build(file.clone(), raw.clone())?;
        let raw_sweep = raw.sweep.as_ref().map(|s| s.get_ref().clone());
        let spec = Spec::read(&file, &scene, raw_sweep.as_ref(), args)?;
        let random = spec.varied.iter().filter(|v| v.axis.is_random()).count();
        let samples = match (random, spec.samples) {
            (0, None) => 0,
            (0, Some(_)) => {
                return Err(spec.error(
                    &file,
                    Where::Samples,
                    "`samples` is given but no variable has a range to sample: give a range \
                     without `count`, as in v0 = { from = 5.0, to = 20.0 }, or leave `samples` out",
                ))
            }
            (_, None) => {
                return Err(spec.error(
                    &file,
                    Where::Vary,
                    "a range without `count` is sampled at random: give `samples` (how many \
                     samples), or a `count` to make it a grid",
                ))
            }
            (_, Some(0)) => {
                return Err(spec.error(&file, Where::Samples, "`samples` is 0: give at least 1"))
            }
            (_, Some(s)) => s,
        };
        let grid = spec
            .varied
            .iter()
            .filter(|v| !v.axis.is_random())
            .try_fold(1usize, |acc, v| acc.checked_mul(v.axis.count()));
        let len = grid.and_then(|g| g.checked_mul(samples.max(1)));
        let len = match len {
            Some(l) if spec.varied.is_empty() => l.min(1),
            Some(l) => l,
            None => usize::MAX,
        };
        if spec.varied.is_empty() {
            return Err(Error::Sweep {
                message: "nothing varies: give the variables under [sweep] vary = { ... } in \
                          the scene, or --vary NAME=SPEC (v0=5:20:4 for 4 values from 5 to 20)"
                    .to_string(),
            });
        }
        if len > MAX_RUNS_UNCONFIRMED && !args.yes {
            return Err(Error::Sweep {
                message: format!(
                    "{} runs (more than {MAX_RUNS_UNCONFIRMED}): check the counts and samples, or \
                     pass --yes to run them all",
                    if len == usize::MAX {
                        "more than 2^64".to_string()
                    } else {
                        len.to_string()
                    }
                ),
            });
        }
        if len == usize::MAX {
            return Err(Error::Sweep {
                message: "the grid has more points than can be counted: use fewer values"
                    .to_string(),
            });
        }
        let unit_samples = design::unit_samples(spec.design, samples, random, spec.seed);
        Ok(Self {
            file,
            raw,
            scene,
            varied: spec.varied,
            samples,
            seed: spec.seed,
            design: spec.design,
            collect: spec.collect,
            unit_samples,
            len,
        })
    }

    /// The number of runs.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether the sweep has no runs (never: a sweep varies something).
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The names of the variables, in the order of [`Row::values`].
    pub fn variables(&self) -> Vec<String> {
        self.varied.iter().map(|v| v.variable.name()).collect()
    }

    /// The names of the quantities collected, in the order of [`Row::quantities`].
    pub fn columns(&self) -> Vec<String> {
        self.collect.iter().map(|q| q.name(&self.scene)).collect()
    }

    /// The variables' names with their units where the scene declares them (`initial.x [m]`),
    /// for axis labels.
    pub fn variable_labels(&self) -> Vec<String> {
        self.varied
            .iter()
            .map(|v| {
                let unit = match &v.variable {
                    Variable::Parameter(_) => None,
                    Variable::Position { index, .. } => collect::state_units(&self.scene, *index).0,
                    Variable::Velocity { index, .. } => collect::state_units(&self.scene, *index).1,
                };
                crate::output::labelled(&v.variable.name(), unit.as_deref())
            })
            .collect()
    }

    /// The quantities' names with their units where the scene declares them (`impact.t [s]`).
    pub fn column_labels(&self) -> Vec<String> {
        self.collect
            .iter()
            .map(|q| crate::output::labelled(&q.name(&self.scene), q.unit(&self.scene).as_deref()))
            .collect()
    }

    /// The values of the variables at point `index` (`< len`), in the order of
    /// [`Sweep::variables`].
    pub fn values(&self, index: usize) -> Vec<f64> {
        let per = self.samples.max(1);
        let (mut grid, sample) = (index / per, index % per);
        let random = self.varied.iter().filter(|v| v.axis.is_random()).count();
        let mut out = vec![0.0; self.varied.len()];
        // The grid's axes, the last fastest.
        for (i, v) in self.varied.iter().enumerate().rev() {
            if let Axis::Values(values) = &v.axis {
                out[i] = values[grid % values.len()];
                grid /= values.len();
            }
        }
        let mut r = 0;
        for (i, v) in self.varied.iter().enumerate() {
            if let Axis::Random { from, to, scale } = v.axis {
                let u = self.unit_samples[sample * random + r];
                out[i] = scale.at(from, to, u);
                r += 1;
            }
        }
        out
    }

    /// The scene at point `index`: the scene file with the variables set to their values and
    /// validated again, so that a parameter computed from a varied one, and an initial value
    /// written as an expression of it, follow it.
    pub fn scene_at(&self, index: usize) -> Result<Scene, Error> {
        self.scene_with(&self.values(index))
    }

    fn scene_with(&self, values: &[f64]) -> Result<Scene, Error> {
        let mut raw = self.raw.clone();
        for (v, &x) in self.varied.iter().zip(values) {
            match &v.variable {
                Variable::Parameter(name) => {
                    let key = raw.parameters.keys().find(|k| k.get_ref() == name).cloned();
                    if let Some(key) = key {
                        let span = raw.parameters[&key].span();
                        raw.parameters
                            .insert(key, Spanned::new(span, Number::Value(x)));
                    }
                }
                Variable::Position { index, .. } => {
                    let q = &mut raw.initial.get_mut().q;
                    let span = q.span();
                    if let Some(slot) = q.get_mut().get_mut(*index) {
                        *slot = Spanned::new(span, Number::Value(x));
                    }
                }
                Variable::Velocity { index, .. } => {
                    let qd = &mut raw.initial.get_mut().q_dot;
                    let span = qd.span();
                    if let Some(slot) = qd.get_mut().get_mut(*index) {
                        *slot = Spanned::new(span, Number::Value(x));
                    }
                }
            }
        }
        Scene::build(self.file.clone(), raw)
    }

    /// Runs point `index` and collects its row. A point whose scene is refused (an initial state
    /// off the constraints, a parameter out of its domain) is a row with status
    /// [`RunStatus::Refused`] and the reason.
    pub fn run_one(&self, index: usize) -> Row {
        let values = self.values(index);
        let scene = match self.scene_with(&values) {
            Ok(s) => s,
            Err(e) => return Row::refused(index, values, self.collect.len(), &e),
        };
        collect::run(&scene, &self.collect, index, values)
    }

    /// Runs the points `items` in parallel over the machine's cores (rayon's pool) and returns
    /// their rows in the order given; `progress` is called once as each run ends. No run's
    /// failure stops the others.
    pub fn run(&self, items: &[usize], progress: &(dyn Fn() + Sync)) -> Vec<Row> {
        items
            .par_iter()
            .map(|&i| {
                let row = self.run_one(i);
                progress();
                row
            })
            .collect()
    }

    /// Runs shard `shard` of the sweep ([`Shard::WHOLE`](chetaev_parts::Shard::WHOLE) for all of
    /// it) on the current rayon pool, and returns its part (for `--shard` files and
    /// [`table::merge`]) and its table; `progress` is called as each run ends.
    pub fn run_part(
        &self,
        shard: chetaev_parts::Shard,
        progress: &(dyn Fn() + Sync),
    ) -> Result<(chetaev_parts::Part, table::Table), Error> {
        let items: Vec<usize> = shard.items(self.len).collect();
        let start = std::time::Instant::now();
        let rows = self.run(&items, progress);
        let about = serde_json::json!({
            "seconds": start.elapsed().as_secs_f64(),
            "threads": rayon::current_num_threads(),
        });
        let part = table::part(self, shard, &rows, about);
        let table = table::Table::from_part(&part)?;
        Ok((part, table))
    }

    /// What defines the sweep's rows, for its part files: two parts merge only when these are
    /// equal. The scene's text is identified by a hash of it.
    pub fn settings(&self) -> serde_json::Value {
        let varied: Vec<serde_json::Value> = self
            .varied
            .iter()
            .map(
                |v| serde_json::json!({ "variable": v.variable.name(), "axis": v.axis.describe() }),
            )
            .collect();
        serde_json::json!({
            "scene": self.scene.name,
            "scene_file": self.file.path,
            "scene_hash": format!("{:016x}", fnv1a(self.file.text.as_bytes())),
            "varied": varied,
            "samples": self.samples,
            "seed": self.seed,
            "design": self.design.name(),
            "variables": self.variables(),
            "columns": self.columns(),
            "labels": table::labels(self),
            "parameters": self
                .scene
                .parameters
                .iter()
                .map(|(p, v)| (p.clone(), chetaev_parts::number(*v)))
                .collect::<serde_json::Map<_, _>>(),
            "version": env!("CARGO_PKG_VERSION"),
        })
    }
}

impl std::fmt::Debug for Sweep {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Sweep")
            .field("scene", &self.scene.name)
            .field("varied", &self.varied)
            .field("samples", &self.samples)
            .field("seed", &self.seed)
            .field("design", &self.design)
            .field("collect", &self.collect)
            .field("len", &self.len)
            .finish_non_exhaustive()
    }
}

/// The 64-bit FNV-1a hash: a fingerprint of the scene's text in the part files (not a
/// cryptographic one: it tells runs of different scenes apart, it does not guard against forgery).
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}

/// Where in the specification a mistake is.
enum Where {
    Vary,
    Samples,
}

/// The sweep as specified, checked.
struct Spec {
    varied: Vec<Varied>,
    samples: Option<usize>,
    seed: u64,
    design: Design,
    collect: Vec<Quantity>,
    spans: SpecSpans,
}

#[derive(Default)]
struct SpecSpans {
    vary: Option<Range<usize>>,
    samples: Option<Range<usize>>,
}

impl Spec {
    fn error(&self, file: &SourceFile, at: Where, message: &str) -> Error {
        let span = match at {
            Where::Vary => self.spans.vary.clone(),
            Where::Samples => self.spans.samples.clone().or(self.spans.vary.clone()),
        };
        match span {
            Some(s) => file.error(s, message),
            None => Error::Sweep {
                message: message.to_string(),
            },
        }
    }

    fn read(
        file: &SourceFile,
        scene: &Scene,
        raw: Option<&RawSweep>,
        args: &SweepArgs,
    ) -> Result<Self, Error> {
        let mut spans = SpecSpans::default();
        // The file's variables, in the order written.
        let mut varied: Vec<(Varied, Option<Range<usize>>)> = Vec::new();
        if let Some(raw) = raw {
            let mut entries: Vec<(&Spanned<String>, &Spanned<toml::Value>)> =
                raw.vary.iter().collect();
            entries.sort_by_key(|(k, _)| k.span().start);
            for (key, value) in entries {
                spans.vary.get_or_insert(key.span());
                let located = |m: String| file.error(value.span(), m);
                // `initial.x = ...` unquoted is a table `initial = { x = ... }`.
                if key.get_ref() == "initial" {
                    if let toml::Value::Table(t) = value.get_ref() {
                        if !design::looks_like_range(t) {
                            for (name, v) in t {
                                let variable = variable(scene, &format!("initial.{name}"))
                                    .map_err(|m| file.error(key.span(), m))?;
                                let axis = design::axis_from_toml(v).map_err(|m| {
                                    file.error(value.span(), format!("initial.{name}: {m}"))
                                })?;
                                varied.push((Varied { variable, axis }, Some(value.span())));
                            }
                            continue;
                        }
                    }
                }
                let variable =
                    variable(scene, key.get_ref()).map_err(|m| file.error(key.span(), m))?;
                let axis = design::axis_from_toml(value.get_ref())
                    .map_err(|m| located(format!("{}: {m}", key.get_ref())))?;
                varied.push((Varied { variable, axis }, Some(value.span())));
            }
        }
        for given in &args.vary {
            let (name, spec) = given.split_once('=').ok_or_else(|| Error::Sweep {
                message: format!(
                    "--vary {given}: write NAME=SPEC, as in v0=5:20:4 (4 values from 5 to 20), \
                     v0=1:100:5:log, v0=1,2,5 or v0=5:20 (sampled at random)"
                ),
            })?;
            let name = name.trim();
            let variable = variable(scene, name).map_err(|m| Error::Sweep {
                message: format!("--vary {given}: {m}"),
            })?;
            let axis = design::axis_from_text(spec).map_err(|m| Error::Sweep {
                message: format!("--vary {given}: {m}"),
            })?;
            let entry = Varied { variable, axis };
            match varied
                .iter()
                .position(|(v, _)| v.variable == entry.variable)
            {
                Some(i) => varied[i] = (entry, None),
                None => varied.push((entry, None)),
            }
        }
        let mut seen: Vec<&Variable> = Vec::new();
        for (v, span) in &varied {
            if seen.contains(&&v.variable) {
                let m = format!("{} is varied twice: give it once", v.variable.name());
                return Err(match span {
                    Some(s) => file.error(s.clone(), m),
                    None => Error::Sweep { message: m },
                });
            }
            seen.push(&v.variable);
        }
        // Grid axes first (in order), then the random ranges (in order).
        let (mut grid, random): (Vec<Varied>, Vec<Varied>) = varied
            .into_iter()
            .map(|(v, _)| v)
            .partition(|v| !v.axis.is_random());
        grid.extend(random);

        let samples = match (args.samples, raw.and_then(|r| r.samples.as_ref())) {
            (Some(s), _) => Some(s),
            (None, Some(s)) => {
                spans.samples = Some(s.span());
                Some(usize::try_from(*s.get_ref()).map_err(|_| {
                    file.error(
                        s.span(),
                        "`samples` is negative: give how many samples to draw",
                    )
                })?)
            }
            (None, None) => None,
        };
        let seed = match (args.seed, raw.and_then(|r| r.seed.as_ref())) {
            (Some(s), _) => s,
            (None, Some(s)) => u64::try_from(*s.get_ref()).map_err(|_| {
                file.error(s.span(), "`seed` is negative: give a whole number from 0")
            })?,
            (None, None) => 0,
        };
        let design = match (&args.design, raw.and_then(|r| r.design.as_ref())) {
            (Some(d), _) => Design::from_name(d).map_err(|m| Error::Sweep {
                message: format!("--design {d}: {m}"),
            })?,
            (None, Some(d)) => {
                Design::from_name(d.get_ref()).map_err(|m| file.error(d.span(), m))?
            }
            (None, None) => Design::Uniform,
        };
        let collect = match (&args.collect, raw.and_then(|r| r.collect.as_ref())) {
            (Some(list), _) => list
                .iter()
                .map(|q| {
                    Quantity::parse(q.trim(), scene).map_err(|m| Error::Sweep {
                        message: format!("--collect {q}: {m}"),
                    })
                })
                .collect::<Result<Vec<_>, _>>()?,
            (None, Some(list)) => list
                .get_ref()
                .iter()
                .map(|q| Quantity::parse(q.get_ref(), scene).map_err(|m| file.error(q.span(), m)))
                .collect::<Result<Vec<_>, _>>()?,
            (None, None) => Quantity::defaults(scene),
        };
        if collect.is_empty() {
            let m = "nothing to collect: name the quantities, as in collect = [\"impact.t\", \
                     \"max_abs.mu_1\"] (docs/sweeps.md lists them)";
            return Err(match raw.and_then(|r| r.collect.as_ref()) {
                Some(c) if args.collect.is_none() => file.error(c.span(), m),
                _ => Error::Sweep {
                    message: m.to_string(),
                },
            });
        }
        Ok(Self {
            varied: grid,
            samples,
            seed,
            design,
            collect,
            spans,
        })
    }
}

/// The variable named `name`: a parameter, `initial.x` or `initial.x_dot`.
fn variable(scene: &Scene, name: &str) -> Result<Variable, String> {
    if let Some(c) = name.strip_prefix("initial.") {
        let coordinates = &scene.coordinates;
        if let Some(i) = coordinates.iter().position(|x| x == c) {
            return Ok(Variable::Position {
                index: i,
                name: c.to_string(),
            });
        }
        if let Some(base) = c.strip_suffix("_dot") {
            if let Some(i) = coordinates.iter().position(|x| x == base) {
                return Ok(Variable::Velocity {
                    index: i,
                    name: base.to_string(),
                });
            }
        }
        let known = collect::names(scene);
        let hint = match crate::expr::closest(c, &known) {
            Some(k) => format!(" (did you mean initial.{k}?)"),
            None => format!(
                "; the initial values are initial.<coordinate> and initial.<coordinate>_dot, for \
                 the coordinates {}",
                coordinates.join(", ")
            ),
        };
        return Err(format!(
            "`{name}` is not an initial value of this scene{hint}"
        ));
    }
    if scene.parameters.iter().any(|(p, _)| p == name) {
        return Ok(Variable::Parameter(name.to_string()));
    }
    let known: Vec<String> = scene.parameters.iter().map(|(p, _)| p.clone()).collect();
    let hint = match crate::expr::closest(name, &known) {
        Some(k) => format!(" (did you mean {k}?)"),
        None if known.is_empty() => {
            "; the scene has no parameters: vary an initial value (initial.x, initial.x_dot), or \
             declare the quantity under [parameters]"
                .to_string()
        }
        None => format!(
            "; its parameters are {}, and the initial values are initial.<coordinate> and \
             initial.<coordinate>_dot",
            known.join(", ")
        ),
    };
    Err(format!("`{name}` is not a parameter of this scene{hint}"))
}
