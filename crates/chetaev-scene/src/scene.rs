//! The scene file: its TOML schema, and its validation into a [`Scene`] ready to solve.
//!
//! The schema is described in `docs/scenes.md`. Every table rejects unknown keys, every value
//! keeps its place in the file, and every mistake is reported at that place.

use std::collections::{BTreeMap, HashSet};
use std::fmt;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use chetaev::prelude::{Atol, Direction, Record};
use serde::de::{self, Deserializer, MapAccess, SeqAccess, Visitor};
use serde::Deserialize;
use toml::Spanned;

use crate::error::{Error, SourceFile};
use crate::expr::{is_function, parse as expr_parse, Expr, Symbols, RESERVED};
use crate::source::string_offset;

/// The most times an output grid may have.
pub const MAX_OUTPUT_TIMES: i64 = 10_000_000;

// ---------------------------------------------------------------------------------------------
// The file as written.

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawScene {
    scene: Option<RawMeta>,
    #[serde(default)]
    parameters: BTreeMap<Spanned<String>, Spanned<Number>>,
    model: Spanned<RawModel>,
    initial: Spanned<RawInitial>,
    solve: Spanned<RawSolve>,
    #[serde(default)]
    events: Vec<Spanned<RawEvent>>,
    output: Option<RawOutput>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawMeta {
    name: Option<String>,
    description: Option<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawModel {
    coordinates: Spanned<Vec<Spanned<String>>>,
    lagrangian: Spanned<String>,
    constraints: Option<Spanned<Vec<Spanned<String>>>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawInitial {
    t: Option<Spanned<Number>>,
    q: Spanned<Vec<Spanned<Number>>>,
    q_dot: Spanned<Vec<Spanned<Number>>>,
    #[serde(default)]
    project_velocity: bool,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSolve {
    method: Option<Spanned<MethodName>>,
    t_end: Spanned<Number>,
    rtol: Option<Spanned<f64>>,
    atol: Option<Spanned<RawAtol>>,
    step: Option<Spanned<Number>>,
    initial_step: Option<Spanned<Number>>,
    max_step: Option<Spanned<Number>>,
    max_steps: Option<Spanned<i64>>,
    #[serde(default)]
    projection: bool,
    stiffness_detection: Option<Spanned<bool>>,
}

#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
enum MethodName {
    Dopri5,
    Dop853,
    Rk4,
    Rodas4,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawEvent {
    name: Spanned<String>,
    expression: Spanned<String>,
    direction: Option<RawDirection>,
    #[serde(default)]
    terminal: bool,
}

#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(rename_all = "lowercase")]
enum RawDirection {
    Either,
    Rising,
    Falling,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawOutput {
    directory: Option<String>,
    times: Option<Spanned<RawTimes>>,
    #[serde(default)]
    tables: Vec<Spanned<Table>>,
    #[serde(default)]
    pictures: Vec<Spanned<Picture>>,
    #[serde(default)]
    quantities: BTreeMap<Spanned<String>, Spanned<String>>,
}

/// A number, or an expression of the parameters in quotes.
#[derive(Clone, Debug)]
enum Number {
    Value(f64),
    Expr(String),
}

impl<'de> Deserialize<'de> for Number {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl Visitor<'_> for V {
            type Value = Number;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a number or an expression in quotes, such as 5.0 or \"2*h0\"")
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<Number, E> {
                Ok(Number::Value(v))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<Number, E> {
                Ok(Number::Value(v as f64))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<Number, E> {
                Ok(Number::Value(v as f64))
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<Number, E> {
                Ok(Number::Expr(v.to_string()))
            }
        }
        d.deserialize_any(V)
    }
}

/// `atol`: one number, or one per component of `(q, q̇)`.
enum RawAtol {
    Scalar(f64),
    List(Vec<f64>),
}

impl<'de> Deserialize<'de> for RawAtol {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = RawAtol;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str(
                    "a number, or a list of 2N numbers (the coordinates' absolute tolerances, then the velocities')",
                )
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<RawAtol, E> {
                Ok(RawAtol::Scalar(v))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<RawAtol, E> {
                Ok(RawAtol::Scalar(v as f64))
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<RawAtol, A::Error> {
                let mut v = Vec::new();
                while let Some(x) = seq.next_element::<f64>()? {
                    v.push(x);
                }
                Ok(RawAtol::List(v))
            }
        }
        d.deserialize_any(V)
    }
}

/// `output.times`.
enum RawTimes {
    Steps,
    List(Vec<f64>),
    Grid {
        from: Option<Number>,
        to: Option<Number>,
        count: i64,
    },
}

impl<'de> Deserialize<'de> for RawTimes {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = RawTimes;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str(
                    "\"steps\", a list of times, or a grid { from = 0.0, to = \"end\", count = 101 }",
                )
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<RawTimes, E> {
                match v {
                    "steps" => Ok(RawTimes::Steps),
                    other => Err(E::custom(format!(
                        "unknown output times \"{other}\": expected \"steps\", a list of times, or a grid \
                         {{ from = 0.0, to = \"end\", count = 101 }}"
                    ))),
                }
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<RawTimes, A::Error> {
                let mut v = Vec::new();
                while let Some(x) = seq.next_element::<f64>()? {
                    v.push(x);
                }
                Ok(RawTimes::List(v))
            }
            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<RawTimes, A::Error> {
                let (mut from, mut to, mut count) = (None, None, None);
                while let Some(key) = map.next_key::<String>()? {
                    match key.as_str() {
                        "from" => from = Some(map.next_value::<Number>()?),
                        "to" => to = Some(map.next_value::<Number>()?),
                        "count" => count = Some(map.next_value::<i64>()?),
                        other => {
                            return Err(de::Error::custom(format!(
                                "unknown key `{other}` in the output grid: expected `from`, `to`, `count`"
                            )))
                        }
                    }
                }
                let count = count.ok_or_else(|| {
                    de::Error::custom(
                        "the output grid needs `count`, the number of times (at least 2), as in \
                         { from = 0.0, to = \"end\", count = 101 }",
                    )
                })?;
                Ok(RawTimes::Grid { from, to, count })
            }
        }
        d.deserialize_any(V)
    }
}

// ---------------------------------------------------------------------------------------------
// The scene as validated.

/// A validated scene: every expression parsed and resolved, every number checked.
#[derive(Clone, Debug)]
pub struct Scene {
    /// The scene's name (`[scene] name`, or the file name).
    pub name: String,
    /// Its description, if any.
    pub description: Option<String>,
    /// The file, for locating errors found later (at the initial state).
    pub file: SourceFile,
    /// Parameters and their values, in the order of the file.
    pub parameters: Vec<(String, f64)>,
    /// Coordinate names.
    pub coordinates: Vec<String>,
    /// `L(t, q, q̇)`.
    pub lagrangian: Expr,
    /// `f_a(t, q, q̇)`, `a = 1..K`.
    pub constraints: Vec<Expr>,
    /// Initial time.
    pub t0: f64,
    /// Initial coordinates.
    pub q0: Vec<f64>,
    /// Initial velocities.
    pub qd0: Vec<f64>,
    /// Whether the initial velocity is projected onto `f = 0` first.
    pub project_velocity: bool,
    /// Method, end time, tolerances.
    pub solve: SolveSpec,
    /// Events, in the order of the file.
    pub events: Vec<EventSpec>,
    /// What to write.
    pub output: OutputSpec,
    pub(crate) spans: Spans,
}

/// Places in the file that errors found after validation point at.
#[derive(Clone, Debug, Default)]
pub(crate) struct Spans {
    pub initial: Range<usize>,
    pub q_dot: Range<usize>,
    pub constraints: Vec<Range<usize>>,
    pub lagrangian: Range<usize>,
    pub solve: Range<usize>,
    pub options: BTreeMap<&'static str, Range<usize>>,
    pub events: Vec<Range<usize>>,
    pub quantities: Vec<Range<usize>>,
}

/// The integration method and its options.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MethodSpec {
    /// Dormand–Prince 5(4).
    Dopri5 {
        /// Stop with a stiffness error when the test fires.
        stiffness_detection: bool,
    },
    /// Dormand–Prince 8(5,3).
    Dop853 {
        /// Stop with a stiffness error when the test fires.
        stiffness_detection: bool,
    },
    /// Classical Runge–Kutta with a fixed step.
    Rk4 {
        /// The step size.
        step: f64,
    },
    /// Hairer and Wanner's Rosenbrock method RODAS (implicit, for stiff problems).
    Rodas4,
}

impl MethodSpec {
    /// The method's name as in the literature.
    pub fn name(&self) -> &'static str {
        match self {
            MethodSpec::Dopri5 { .. } => "Dopri5",
            MethodSpec::Dop853 { .. } => "Dop853",
            MethodSpec::Rk4 { .. } => "Rk4",
            MethodSpec::Rodas4 => "Rodas4",
        }
    }
}

/// `[solve]`.
#[derive(Clone, Debug, PartialEq)]
pub struct SolveSpec {
    /// The method.
    pub method: MethodSpec,
    /// The end time.
    pub t_end: f64,
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance.
    pub atol: Atol,
    /// First step size.
    pub initial_step: Option<f64>,
    /// Largest step size.
    pub max_step: Option<f64>,
    /// Step limit.
    pub max_steps: Option<usize>,
    /// Projection onto `f = 0` after each step.
    pub projection: bool,
}

/// One `[[events]]` entry.
#[derive(Clone, Debug)]
pub struct EventSpec {
    /// Its name.
    pub name: String,
    /// `g(t, q, q̇)`, whose zeros are located.
    pub expr: Expr,
    /// Which crossings count.
    pub direction: Direction,
    /// Whether the first crossing stops the integration.
    pub terminal: bool,
}

/// A CSV table a scene can ask for.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq, PartialOrd, Ord)]
#[serde(rename_all = "lowercase")]
pub enum Table {
    /// `t`, the coordinates and the velocities.
    State,
    /// `t` and the accelerations `q̈`.
    Acceleration,
    /// `t` and the multipliers `μ_a`.
    Multipliers,
    /// `t` and the Chetaev force `Φ = Jᵀμ`, one column per coordinate.
    Force,
    /// `t` and the constraint residuals `f_a`.
    Residual,
    /// `t`, the energy `E`, the work `W_Φ`, `∫∂L/∂t dt` and the balance.
    Energy,
    /// One row per located event: its name, `t`, the coordinates and the velocities.
    Events,
    /// `t` and the scene's `[output.quantities]`.
    Quantities,
}

/// An SVG picture a scene can ask for.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq, PartialOrd, Ord)]
#[serde(rename_all = "lowercase")]
pub enum Picture {
    /// The second coordinate against the first (equal scales); the coordinate against `t` if `N = 1`.
    Trajectory,
    /// Every coordinate against `t`.
    State,
    /// Every velocity against `t`.
    Velocity,
    /// Every acceleration against `t`.
    Acceleration,
    /// Every multiplier against `t`.
    Multipliers,
    /// Every component of the Chetaev force against `t`.
    Force,
    /// `|f_a|` against `t`, logarithmic.
    Residual,
    /// `E − E(t0)`, `W_Φ`, `∫∂L/∂t dt` and the balance against `t`.
    Energy,
    /// Every output quantity against `t`.
    Quantities,
}

impl Table {
    /// Every table, in the order of the documentation.
    pub const ALL: [Table; 8] = [
        Table::State,
        Table::Acceleration,
        Table::Multipliers,
        Table::Force,
        Table::Residual,
        Table::Energy,
        Table::Events,
        Table::Quantities,
    ];

    /// The file name without extension.
    pub fn name(self) -> &'static str {
        match self {
            Table::State => "state",
            Table::Acceleration => "acceleration",
            Table::Multipliers => "multipliers",
            Table::Force => "force",
            Table::Residual => "residual",
            Table::Energy => "energy",
            Table::Events => "events",
            Table::Quantities => "quantities",
        }
    }

    /// What has to be recorded along the motion for it.
    pub fn record(self) -> Record {
        match self {
            Table::State | Table::Events | Table::Quantities => Record::State,
            Table::Acceleration | Table::Multipliers | Table::Force | Table::Residual => {
                Record::Dynamics
            }
            Table::Energy => Record::Energy,
        }
    }

    fn needs_constraints(self) -> bool {
        matches!(self, Table::Multipliers | Table::Force | Table::Residual)
    }
}

impl Picture {
    /// The file name without extension.
    pub fn name(self) -> &'static str {
        match self {
            Picture::Trajectory => "trajectory",
            Picture::State => "state",
            Picture::Velocity => "velocity",
            Picture::Acceleration => "acceleration",
            Picture::Multipliers => "multipliers",
            Picture::Force => "force",
            Picture::Residual => "residual",
            Picture::Energy => "energy",
            Picture::Quantities => "quantities",
        }
    }

    /// What has to be recorded along the motion for it.
    pub fn record(self) -> Record {
        match self {
            Picture::Trajectory | Picture::State | Picture::Velocity | Picture::Quantities => {
                Record::State
            }
            Picture::Acceleration | Picture::Multipliers | Picture::Force | Picture::Residual => {
                Record::Dynamics
            }
            Picture::Energy => Record::Energy,
        }
    }

    fn needs_constraints(self) -> bool {
        matches!(
            self,
            Picture::Multipliers | Picture::Force | Picture::Residual
        )
    }
}

/// Where along the motion the tables and pictures are sampled.
#[derive(Clone, Debug, PartialEq)]
pub enum Times {
    /// At every accepted step.
    Steps,
    /// At these times (by dense output), plus the start and the end.
    List(Vec<f64>),
    /// `count` equally spaced times from `from` to `to`.
    Grid {
        /// First time.
        from: f64,
        /// Last time.
        to: GridEnd,
        /// Number of times, at least 2.
        count: usize,
    },
}

/// The last time of an output grid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum GridEnd {
    /// A given time.
    Time(f64),
    /// Where the motion stops: at a terminal event, or at `t_end`.
    End,
}

/// `[output]`.
#[derive(Clone, Debug)]
pub struct OutputSpec {
    /// Where the files go.
    pub directory: PathBuf,
    /// Where the motion is sampled.
    pub times: Times,
    /// CSV tables, without repetitions, in the order asked.
    pub tables: Vec<Table>,
    /// SVG pictures, without repetitions, in the order asked.
    pub pictures: Vec<Picture>,
    /// Named expressions of `t`, the coordinates and the velocities, in the order of the file.
    pub quantities: Vec<(String, Expr)>,
}

impl Scene {
    /// Reads and validates the scene file at `path`.
    pub fn load(path: impl AsRef<Path>) -> Result<Self, Error> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|source| Error::Read {
            path: path.display().to_string(),
            source,
        })?;
        Self::parse(&text, &path.display().to_string())
    }

    /// Validates a scene given as text; `path` names it in messages and gives the default output
    /// directory `out/<file stem>`.
    pub fn parse(text: &str, path: &str) -> Result<Self, Error> {
        let file = SourceFile {
            path: path.to_string(),
            text: Arc::from(text),
        };
        let raw: RawScene = toml::from_str(text).map_err(|e| {
            let span = e.span().unwrap_or(0..0);
            file.error(span, toml_message(e.message()))
        })?;
        Builder { file }.build(raw)
    }

    /// `N`, the number of coordinates.
    pub fn n(&self) -> usize {
        self.coordinates.len()
    }

    /// `K`, the number of constraints.
    pub fn k(&self) -> usize {
        self.constraints.len()
    }

    /// What has to be recorded along the motion for the tables and pictures asked for.
    pub fn record(&self) -> Record {
        let tables = self.output.tables.iter().map(|t| t.record());
        let pictures = self.output.pictures.iter().map(|p| p.record());
        tables.chain(pictures).max().unwrap_or(Record::State)
    }

    /// Whether anything is sampled along the motion (a table or a picture other than the events
    /// table). When nothing is, only the start, the end and the events are recorded.
    pub fn samples_motion(&self) -> bool {
        !self.output.pictures.is_empty() || self.output.tables.iter().any(|t| *t != Table::Events)
    }

    pub(crate) fn error_at(&self, range: Range<usize>, message: impl Into<String>) -> Error {
        self.file.error(range, message)
    }
}

/// toml's messages, with a hint for the commonest mistakes.
fn toml_message(message: &str) -> String {
    let m = message.trim_end().to_string();
    if m.contains("missing field") {
        format!("{m}; see docs/scenes.md for the keys of each table")
    } else {
        m
    }
}

struct Builder {
    file: SourceFile,
}

fn is_identifier(s: &str) -> bool {
    let mut c = s.chars();
    c.next()
        .is_some_and(|f| f.is_ascii_alphabetic() || f == '_')
        && c.all(|x| x.is_ascii_alphanumeric() || x == '_')
}

impl Builder {
    fn err(&self, range: Range<usize>, message: impl Into<String>) -> Error {
        self.file.error(range, message)
    }

    /// Parses an expression given as a TOML string; errors point into the string.
    fn expr(&self, s: &Spanned<String>, symbols: &Symbols) -> Result<Expr, Error> {
        Expr::parse(s.get_ref(), symbols).map_err(|e| self.expr_error(s, e))
    }

    fn expr_error(&self, s: &Spanned<String>, e: crate::expr::ExprError) -> Error {
        let span = s.span();
        let start = string_offset(&self.file.text, &span, s.get_ref(), e.start);
        let end = string_offset(&self.file.text, &span, s.get_ref(), e.end).max(start + 1);
        self.err(start..end, e.message)
    }

    /// A constant: a number, or an expression of the parameters.
    fn number(&self, n: &Spanned<Number>, symbols: &Symbols, what: &str) -> Result<f64, Error> {
        let v = match n.get_ref() {
            Number::Value(v) => *v,
            Number::Expr(s) => {
                let s = Spanned::new(n.span(), s.clone());
                let e = self.expr(&s, symbols)?;
                e.constant().ok_or_else(|| {
                    self.err(
                        n.span(),
                        format!("{what} must be a constant: use only numbers and parameters"),
                    )
                })?
            }
        };
        if !v.is_finite() {
            return Err(self.err(n.span(), format!("{what} is {v}; give a finite number")));
        }
        Ok(v)
    }

    fn name_check(&self, name: &Spanned<String>, what: &str) -> Result<(), Error> {
        let n = name.get_ref();
        if !is_identifier(n) {
            return Err(self.err(
                name.span(),
                format!(
                    "'{n}' is not a valid {what} name: use ASCII letters, digits and '_', starting with a letter"
                ),
            ));
        }
        if RESERVED.contains(&n.as_str()) {
            return Err(self.err(
                name.span(),
                format!("'{n}' is reserved (t is time, pi and e are constants); choose another {what} name"),
            ));
        }
        if is_function(n) {
            return Err(self.err(
                name.span(),
                format!(
                    "'{n}' is a function of the expression language; choose another {what} name"
                ),
            ));
        }
        if n.ends_with("_dot") {
            return Err(self.err(
                name.span(),
                format!("'{n}' ends in _dot, which names velocities; choose another {what} name"),
            ));
        }
        Ok(())
    }

    fn build(&self, raw: RawScene) -> Result<Scene, Error> {
        let parameters = self.parameters(&raw.parameters)?;
        let param_map: BTreeMap<String, f64> = parameters.iter().cloned().collect();
        let constants = Symbols::constants(&param_map);

        // [model]
        let model = raw.model.get_ref();
        let coords = model.coordinates.get_ref();
        let n = coords.len();
        if n == 0 {
            return Err(self.err(
                model.coordinates.span(),
                "no coordinates: list at least one, as in coordinates = [\"x\", \"y\"]",
            ));
        }
        let mut seen = HashSet::new();
        for c in coords {
            self.name_check(c, "coordinate")?;
            if param_map.contains_key(c.get_ref()) {
                return Err(self.err(
                    c.span(),
                    format!(
                        "'{}' is both a parameter and a coordinate; rename one",
                        c.get_ref()
                    ),
                ));
            }
            if !seen.insert(c.get_ref().clone()) {
                return Err(self.err(
                    c.span(),
                    format!("the coordinate '{}' is listed twice", c.get_ref()),
                ));
            }
        }
        let coordinates: Vec<String> = coords.iter().map(|c| c.get_ref().clone()).collect();
        let motion = Symbols {
            parameters: param_map.clone(),
            coordinates: coordinates.clone(),
            motion: true,
        };
        let lagrangian = self.expr(&model.lagrangian, &motion)?;
        let mut constraints = Vec::new();
        let mut constraint_spans = Vec::new();
        if let Some(list) = &model.constraints {
            let k = list.get_ref().len();
            if k > n {
                return Err(self.err(
                    list.span(),
                    format!(
                        "{k} constraints on {n} coordinates: at most {n} independent velocity constraints \
                         can hold at once (K ≤ N; see 'Sizes' in docs/scenes.md)"
                    ),
                ));
            }
            for c in list.get_ref() {
                constraints.push(self.expr(c, &motion)?);
                constraint_spans.push(c.span());
            }
        }

        // [initial]
        let initial = raw.initial.get_ref();
        let t0 = match &initial.t {
            Some(t) => self.number(t, &constants, "initial.t")?,
            None => 0.0,
        };
        let q0 = self.vector(&initial.q, &coordinates, "q", &constants)?;
        let qd0 = self.vector(&initial.q_dot, &coordinates, "q_dot", &constants)?;

        // [solve]
        let (solve, options) = self.solve(raw.solve.get_ref(), n, &constants)?;
        if solve.t_end == t0 {
            return Err(self.err(
                raw.solve.get_ref().t_end.span(),
                format!(
                    "t_end = {} equals the initial time: nothing to integrate",
                    solve.t_end
                ),
            ));
        }

        // [[events]]
        let mut events = Vec::new();
        let mut event_spans = Vec::new();
        let mut names = HashSet::new();
        for e in &raw.events {
            let e = e.get_ref();
            if !names.insert(e.name.get_ref().clone()) {
                return Err(self.err(
                    e.name.span(),
                    format!(
                        "two events are named '{}'; names must differ",
                        e.name.get_ref()
                    ),
                ));
            }
            if e.name.get_ref().trim().is_empty() {
                return Err(self.err(e.name.span(), "an event needs a non-empty name"));
            }
            events.push(EventSpec {
                name: e.name.get_ref().clone(),
                expr: self.expr(&e.expression, &motion)?,
                direction: match e.direction {
                    None | Some(RawDirection::Either) => Direction::Either,
                    Some(RawDirection::Rising) => Direction::Rising,
                    Some(RawDirection::Falling) => Direction::Falling,
                },
                terminal: e.terminal,
            });
            event_spans.push(e.expression.span());
        }

        // [output]
        let stem = Path::new(&self.file.path)
            .file_stem()
            .map_or_else(|| "scene".to_string(), |s| s.to_string_lossy().into_owned());
        let (output, quantity_spans) = self.output(
            raw.output.as_ref(),
            &stem,
            constraints.len(),
            &motion,
            &constants,
            t0,
            solve.t_end,
        )?;

        let meta = raw.scene.as_ref();
        Ok(Scene {
            name: meta
                .and_then(|m| m.name.clone())
                .unwrap_or_else(|| stem.clone()),
            description: meta.and_then(|m| m.description.clone()),
            file: self.file.clone(),
            parameters,
            coordinates,
            lagrangian,
            constraints,
            t0,
            q0,
            qd0,
            project_velocity: initial.project_velocity,
            solve,
            events,
            output,
            spans: Spans {
                initial: raw.initial.span(),
                q_dot: initial.q_dot.span(),
                constraints: constraint_spans,
                lagrangian: model.lagrangian.span(),
                solve: raw.solve.span(),
                options,
                events: event_spans,
                quantities: quantity_spans,
            },
        })
    }

    /// The parameters in the order of the file; a value may be an expression of other parameters.
    fn parameters(
        &self,
        raw: &BTreeMap<Spanned<String>, Spanned<Number>>,
    ) -> Result<Vec<(String, f64)>, Error> {
        let mut entries: Vec<(&Spanned<String>, &Spanned<Number>)> = raw.iter().collect();
        entries.sort_by_key(|(k, _)| k.span().start);
        let all: HashSet<&str> = entries.iter().map(|(k, _)| k.get_ref().as_str()).collect();
        let mut values: BTreeMap<String, f64> = BTreeMap::new();
        let mut pending = Vec::new();
        for (k, v) in &entries {
            self.name_check(k, "parameter")?;
            match v.get_ref() {
                Number::Value(x) => {
                    if !x.is_finite() {
                        return Err(self.err(
                            v.span(),
                            format!("parameter '{}' is {x}; give a finite number", k.get_ref()),
                        ));
                    }
                    values.insert(k.get_ref().clone(), *x);
                }
                Number::Expr(s) => {
                    let spanned = Spanned::new(v.span(), s.clone());
                    let ast = expr_parse::parse(s).map_err(|e| self.expr_error(&spanned, e))?;
                    pending.push((k, spanned, ast));
                }
            }
        }
        // Resolve expressions once everything they name is known.
        while !pending.is_empty() {
            let mut progress = false;
            let mut i = 0;
            while i < pending.len() {
                let (k, s, ast) = &pending[i];
                let mut used = Vec::new();
                ast.names(&mut used);
                let waiting = used
                    .iter()
                    .any(|(n, _)| all.contains(n.as_str()) && !values.contains_key(n));
                if waiting {
                    i += 1;
                    continue;
                }
                let e = Expr::from_ast(s.get_ref(), ast, &Symbols::constants(&values))
                    .map_err(|e| self.expr_error(s, e))?;
                let value = e.constant().ok_or_else(|| {
                    self.err(s.span(), "a parameter must be a constant expression")
                })?;
                values.insert(k.get_ref().clone(), value);
                pending.remove(i);
                progress = true;
            }
            if !progress {
                let names: Vec<&str> = pending
                    .iter()
                    .map(|(k, _, _)| k.get_ref().as_str())
                    .collect();
                return Err(self.err(
                    pending[0].1.span(),
                    format!(
                        "the parameters {} are defined in terms of each other in a cycle; give one of them a number",
                        names.join(", ")
                    ),
                ));
            }
        }
        Ok(entries
            .iter()
            .map(|(k, _)| {
                let name = k.get_ref().clone();
                let v = values.get(&name).copied().unwrap_or(f64::NAN);
                (name, v)
            })
            .collect())
    }

    fn vector(
        &self,
        list: &Spanned<Vec<Spanned<Number>>>,
        coordinates: &[String],
        what: &str,
        constants: &Symbols,
    ) -> Result<Vec<f64>, Error> {
        let n = coordinates.len();
        if list.get_ref().len() != n {
            let names: Vec<String> = coordinates
                .iter()
                .map(|c| {
                    if what == "q" {
                        c.clone()
                    } else {
                        format!("{c}_dot")
                    }
                })
                .collect();
            return Err(self.err(
                list.span(),
                format!(
                    "initial.{what} has {} values; expected {n}, one for each of {}",
                    list.get_ref().len(),
                    names.join(", ")
                ),
            ));
        }
        list.get_ref()
            .iter()
            .enumerate()
            .map(|(i, v)| {
                let name = if what == "q" {
                    coordinates[i].clone()
                } else {
                    format!("{}_dot", coordinates[i])
                };
                self.number(v, constants, &format!("the initial value of {name}"))
            })
            .collect()
    }

    #[allow(clippy::type_complexity)]
    fn solve(
        &self,
        raw: &RawSolve,
        n: usize,
        constants: &Symbols,
    ) -> Result<(SolveSpec, BTreeMap<&'static str, Range<usize>>), Error> {
        let mut spans = BTreeMap::new();
        let method_name = raw
            .method
            .as_ref()
            .map_or(MethodName::Dop853, |m| *m.get_ref());
        let stiffness = raw.stiffness_detection.as_ref().map(|s| *s.get_ref());
        if let (Some(s), MethodName::Rk4 | MethodName::Rodas4) =
            (&raw.stiffness_detection, method_name)
        {
            return Err(self.err(
                s.span(),
                "stiffness_detection applies to dopri5 and dop853 only; remove it",
            ));
        }
        let step = match (&raw.step, method_name) {
            (Some(s), MethodName::Rk4) => {
                spans.insert("step", s.span());
                let h = self.number(s, constants, "solve.step")?;
                if h <= 0.0 {
                    return Err(self.err(
                        s.span(),
                        format!("solve.step = {h}: the step of rk4 must be positive"),
                    ));
                }
                h
            }
            (None, MethodName::Rk4) => {
                let span = raw.method.as_ref().map_or(0..0, |m| m.span());
                return Err(self.err(
                    span,
                    "rk4 takes a fixed step: add `step = ...` under [solve] (or choose an adaptive method: dopri5, dop853, rodas4)",
                ));
            }
            (Some(s), _) => {
                return Err(self.err(
                    s.span(),
                    "`step` is the fixed step of rk4; the adaptive methods choose their own steps \
                     (use initial_step or max_step to guide them)",
                ));
            }
            (None, _) => 0.0,
        };
        let method = match method_name {
            MethodName::Dopri5 => MethodSpec::Dopri5 {
                stiffness_detection: stiffness.unwrap_or(true),
            },
            MethodName::Dop853 => MethodSpec::Dop853 {
                stiffness_detection: stiffness.unwrap_or(true),
            },
            MethodName::Rk4 => MethodSpec::Rk4 { step },
            MethodName::Rodas4 => MethodSpec::Rodas4,
        };
        let t_end = self.number(&raw.t_end, constants, "solve.t_end")?;
        spans.insert("t_end", raw.t_end.span());
        let defaults = chetaev::prelude::Options::<1>::until(0.0);
        let rtol = match &raw.rtol {
            Some(r) => {
                spans.insert("rtol", r.span());
                *r.get_ref()
            }
            None => defaults.rtol,
        };
        let atol = match &raw.atol {
            Some(a) => {
                spans.insert("atol", a.span());
                spans.insert("atol (length)", a.span());
                match a.get_ref() {
                    RawAtol::Scalar(x) => Atol::Scalar(*x),
                    RawAtol::List(v) => {
                        if v.len() != 2 * n {
                            return Err(self.err(
                                a.span(),
                                format!(
                                    "atol has {} values; a list needs {} (one per coordinate, then one per velocity), or give one number",
                                    v.len(),
                                    2 * n
                                ),
                            ));
                        }
                        Atol::PerComponent(v.clone())
                    }
                }
            }
            None => defaults.atol.clone(),
        };
        let optional = |s: &Option<Spanned<Number>>,
                        name: &'static str,
                        spans: &mut BTreeMap<&'static str, Range<usize>>|
         -> Result<Option<f64>, Error> {
            s.as_ref()
                .map(|s| {
                    spans.insert(name, s.span());
                    self.number(s, constants, &format!("solve.{name}"))
                })
                .transpose()
        };
        let initial_step = optional(&raw.initial_step, "initial_step", &mut spans)?;
        let max_step = optional(&raw.max_step, "max_step", &mut spans)?;
        let max_steps = match &raw.max_steps {
            Some(m) => {
                spans.insert("max_steps", m.span());
                let v = *m.get_ref();
                if v < 1 {
                    return Err(self.err(
                        m.span(),
                        format!("max_steps = {v}: allow at least one step"),
                    ));
                }
                Some(usize::try_from(v).unwrap_or(usize::MAX))
            }
            None => None,
        };
        Ok((
            SolveSpec {
                method,
                t_end,
                rtol,
                atol,
                initial_step,
                max_step,
                max_steps,
                projection: raw.projection,
            },
            spans,
        ))
    }

    #[allow(clippy::too_many_arguments)]
    fn output(
        &self,
        raw: Option<&RawOutput>,
        stem: &str,
        k: usize,
        motion: &Symbols,
        constants: &Symbols,
        t0: f64,
        t_end: f64,
    ) -> Result<(OutputSpec, Vec<Range<usize>>), Error> {
        let default_dir = PathBuf::from("out").join(stem);
        let Some(raw) = raw else {
            return Ok((
                OutputSpec {
                    directory: default_dir,
                    times: Times::Steps,
                    tables: Vec::new(),
                    pictures: Vec::new(),
                    quantities: Vec::new(),
                },
                Vec::new(),
            ));
        };
        let no_constraints = |what: &str, span: Range<usize>| {
            self.err(
                span,
                format!(
                    "the model has no constraints, so there is no {what}; remove it from the list"
                ),
            )
        };
        let mut tables = Vec::new();
        for t in &raw.tables {
            if t.get_ref().needs_constraints() && k == 0 {
                return Err(no_constraints(
                    &format!("'{}' table", t.get_ref().name()),
                    t.span(),
                ));
            }
            if !tables.contains(t.get_ref()) {
                tables.push(*t.get_ref());
            }
        }
        let mut pictures = Vec::new();
        for p in &raw.pictures {
            if p.get_ref().needs_constraints() && k == 0 {
                return Err(no_constraints(
                    &format!("'{}' picture", p.get_ref().name()),
                    p.span(),
                ));
            }
            if !pictures.contains(p.get_ref()) {
                pictures.push(*p.get_ref());
            }
        }
        let mut entries: Vec<(&Spanned<String>, &Spanned<String>)> =
            raw.quantities.iter().collect();
        entries.sort_by_key(|(k, _)| k.span().start);
        let mut quantities = Vec::new();
        let mut spans = Vec::new();
        for (name, value) in entries {
            if !is_identifier(name.get_ref()) {
                return Err(self.err(
                    name.span(),
                    format!(
                        "'{}' is not a valid quantity name: use ASCII letters, digits and '_'",
                        name.get_ref()
                    ),
                ));
            }
            quantities.push((name.get_ref().clone(), self.expr(value, motion)?));
            spans.push(value.span());
        }
        let wants_quantities =
            tables.contains(&Table::Quantities) || pictures.contains(&Picture::Quantities);
        if wants_quantities && quantities.is_empty() {
            let span = raw
                .tables
                .iter()
                .map(|t| (t.get_ref() == &Table::Quantities, t.span()))
                .chain(
                    raw.pictures
                        .iter()
                        .map(|p| (p.get_ref() == &Picture::Quantities, p.span())),
                )
                .find(|(hit, _)| *hit)
                .map_or(0..0, |(_, s)| s);
            return Err(self.err(
                span,
                "'quantities' asks for the [output.quantities] table, which is empty; add one, as in \
                 speed = \"sqrt(x_dot^2 + y_dot^2)\"",
            ));
        }
        let times = match &raw.times {
            None => Times::Steps,
            Some(t) => self.times(t, constants, t0, t_end)?,
        };
        Ok((
            OutputSpec {
                directory: raw.directory.as_ref().map_or(default_dir, PathBuf::from),
                times,
                tables,
                pictures,
                quantities,
            },
            spans,
        ))
    }

    fn times(
        &self,
        t: &Spanned<RawTimes>,
        constants: &Symbols,
        t0: f64,
        t_end: f64,
    ) -> Result<Times, Error> {
        let inside = |s: f64| {
            let (lo, hi) = if t0 <= t_end {
                (t0, t_end)
            } else {
                (t_end, t0)
            };
            s.is_finite() && s >= lo && s <= hi
        };
        let outside = |s: f64| {
            self.err(
                t.span(),
                format!(
                    "output time {s} lies outside the integration from t = {t0} to t_end = {t_end}"
                ),
            )
        };
        Ok(match t.get_ref() {
            RawTimes::Steps => Times::Steps,
            RawTimes::List(v) => {
                if let Some(s) = v.iter().find(|s| !inside(**s)) {
                    return Err(outside(*s));
                }
                Times::List(v.clone())
            }
            RawTimes::Grid { from, to, count } => {
                if *count > MAX_OUTPUT_TIMES {
                    return Err(self.err(
                        t.span(),
                        format!(
                            "the output grid has count = {count}; at most {MAX_OUTPUT_TIMES} times are written"
                        ),
                    ));
                }
                if *count < 2 {
                    return Err(self.err(
                        t.span(),
                        format!("the output grid has count = {count}; it needs at least 2 times"),
                    ));
                }
                let constant = |n: &Number, what: &str| -> Result<f64, Error> {
                    self.number(&Spanned::new(t.span(), n.clone()), constants, what)
                };
                let from = match from {
                    Some(n) => constant(n, "output.times.from")?,
                    None => t0,
                };
                let to = match to {
                    None => GridEnd::End,
                    Some(Number::Expr(s)) if s.trim() == "end" => GridEnd::End,
                    Some(Number::Expr(s)) => {
                        let e = Expr::parse(s, constants).map_err(|_| {
                            self.err(
                                t.span(),
                                format!(
                                    "output.times.to = \"{s}\" is not a time: give a number, an expression of the \
                                     parameters, or \"end\" (where the motion stops: at a terminal event, or at t_end)"
                                ),
                            )
                        })?;
                        GridEnd::Time(constant(
                            &Number::Value(e.constant().unwrap_or(f64::NAN)),
                            "output.times.to",
                        )?)
                    }
                    Some(n) => GridEnd::Time(constant(n, "output.times.to")?),
                };
                if !inside(from) {
                    return Err(outside(from));
                }
                if let GridEnd::Time(x) = to {
                    if !inside(x) {
                        return Err(outside(x));
                    }
                }
                Times::Grid {
                    from,
                    to,
                    count: usize::try_from(*count).unwrap_or(2),
                }
            }
        })
    }
}
