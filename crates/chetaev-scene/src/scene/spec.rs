//! The scene as validated: every expression parsed and resolved, every number checked.

use std::collections::BTreeMap;
use std::ops::Range;
use std::path::PathBuf;

use chetaev::prelude::{Atol, Direction, Record};
use chetaev::Seed;
use serde::Deserialize;

use crate::error::SourceFile;
use crate::expr::Expr;

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
    /// Holonomic constraints `h_b(t, q) = 0` (empty for none); their multipliers follow the
    /// velocity constraints' in `μ`.
    pub holonomic: Vec<Expr>,
    /// Generalised forces `Q_i(t, q, q̇)` not derivable from `L`, one per coordinate (empty for none).
    pub forces: Vec<Expr>,
    /// A Rayleigh dissipation function `D(t, q, q̇)`, whose force is `−∂D/∂q̇`.
    pub dissipation: Option<Expr>,
    /// `[[loads]]`: forces on points and torques on bodies, in the order of the file; their
    /// generalised forces add to `forces`.
    pub loads: Vec<LoadSpec>,
    /// Initial time.
    pub t0: f64,
    /// Initial coordinates.
    pub q0: Vec<f64>,
    /// Initial velocities.
    pub qd0: Vec<f64>,
    /// Whether the initial velocity is projected onto `f = 0` first.
    pub project_velocity: bool,
    /// The independent coordinates and speeds of `[initial]`, if named: the dependent ones are
    /// solved from the constraints ([`chetaev::manifold::complete`]) before the solve.
    pub independent: Option<chetaev::manifold::Independent>,
    /// Method, end time, tolerances.
    pub solve: SolveSpec,
    /// Events, in the order of the file.
    pub events: Vec<EventSpec>,
    /// The sensitivities asked for by `[sensitivities]`, if any.
    pub sensitivities: Option<SensitivitySpec>,
    /// What to write.
    pub output: OutputSpec,
    /// Units of time, the coordinates, the multipliers, the energy and the output quantities,
    /// for the pictures' axis labels.
    pub units: Units,
    /// What in the file is valid but may not be what was meant, in the order of the file: each
    /// `e` read as Euler's number where no parameter `e` is declared.
    pub warnings: Vec<crate::error::Warning>,
    pub(crate) spans: Spans,
}

/// Units as declared by `[model] units` and `[output.units]`: text shown in the pictures' axis
/// labels (`"x [m]"`) and after the summary's values (`x = 9.19 m`), and from which the units of
/// derivatives are written (`"ẋ [m/s]"`). `None`
/// where nothing is declared; `Some("")` for a quantity declared without unit.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Units {
    /// The unit of `t`.
    pub time: Option<String>,
    /// The unit of each coordinate, in the order of `coordinates`.
    pub coordinates: Vec<Option<String>>,
    /// The unit of each multiplier `μ_a`, `a = 1..K`.
    pub multipliers: Vec<Option<String>>,
    /// The unit of the energy (and of `L`, the works and the balance).
    pub energy: Option<String>,
    /// The unit of each output quantity, in the order of `output.quantities`.
    pub quantities: Vec<Option<String>>,
}

/// `[sensitivities]`: derivatives of the motion and of the events with respect to parameters.
///
/// Each parameter asked for is one [`Seed`] (named after it) that moves the parameter at rate 1,
/// every parameter computed from it at its rate `dp_i/dp` (by dual numbers through the
/// definitions), and the initial values written as expressions of it at their rates (by dual
/// numbers through those expressions). Only the parameters the model and the events read are
/// named in a seed.
#[derive(Clone, Debug, PartialEq)]
pub struct SensitivitySpec {
    /// The parameters asked for, in the order written.
    pub parameters: Vec<String>,
    /// Whether the sensitivities are under error control (`control = true`).
    pub control: bool,
    /// One seed per parameter asked for, in the same order.
    pub seeds: Vec<Seed>,
}

/// Of one load, the places of the components of its point (or angular velocity), then of its
/// force (or torque).
pub(crate) type LoadSpans = (Vec<Range<usize>>, Vec<Range<usize>>);

/// Places in the file that errors found after validation point at.
#[derive(Clone, Debug, Default)]
pub(crate) struct Spans {
    pub initial: Range<usize>,
    /// `independent_speeds` (or `independent_coordinates`), or `[initial]`.
    pub independent: Range<usize>,
    pub q: Range<usize>,
    pub q_dot: Range<usize>,
    pub constraints: Vec<Range<usize>>,
    pub holonomic: Vec<Range<usize>>,
    pub forces: Vec<Range<usize>>,
    pub dissipation: Option<Range<usize>>,
    /// Of each load, the places of the components of its point (or angular velocity), then of
    /// its force (or torque).
    pub loads: Vec<LoadSpans>,
    pub lagrangian: Range<usize>,
    pub solve: Range<usize>,
    pub options: BTreeMap<&'static str, Range<usize>>,
    pub events: Vec<Range<usize>>,
    pub quantities: Vec<Range<usize>>,
    /// `[sensitivities] parameters`, or the start of the file.
    pub sensitivities: Range<usize>,
}

/// `[solve]`.
#[derive(Clone, Debug, PartialEq)]
pub struct SolveSpec {
    /// The method.
    pub method: chetaev::integrate::AnyMethod,
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

/// One `[[loads]]` entry: a load stated where it acts, whose generalised force `Q` is taken by
/// dual numbers ([`chetaev::loads`]) and added to the scene's `forces`.
#[derive(Clone, Debug)]
pub enum LoadSpec {
    /// A force `F(t, q, q̇)` on the point at `r(t, q)`, both of 2 (plane) or 3 (space) components:
    /// `Q_i = F · ∂r/∂q_i`.
    Force {
        /// `r(t, q)`.
        point: Vec<Expr>,
        /// `F(t, q, q̇)`, one component per component of `point`.
        force: Vec<Expr>,
    },
    /// A torque `T(t, q, q̇)` on a body turning at `ω(t, q, q̇)`, both of 1 (plane: about the
    /// normal) or 3 (space) components: `Q_i = T · ∂ω/∂q̇_i`.
    Torque {
        /// `ω(t, q, q̇)`.
        angular_velocity: Vec<Expr>,
        /// `T(t, q, q̇)`, one component per component of `angular_velocity`.
        torque: Vec<Expr>,
    },
}

impl LoadSpec {
    /// Where it acts (`r` or `ω`), then what acts (`F` or `T`).
    pub fn parts(&self) -> (&[Expr], &[Expr]) {
        match self {
            LoadSpec::Force { point, force } => (point, force),
            LoadSpec::Torque {
                angular_velocity,
                torque,
            } => (angular_velocity, torque),
        }
    }
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
    /// `t`, the energy `E`, the works `W_Φ` and `W_Q`, `∫∂L/∂t dt` and the balance.
    Energy,
    /// One row per located event: its name, `t`, the coordinates and the velocities.
    Events,
    /// `t` and the scene's `[output.quantities]`.
    Quantities,
    /// `t` and, for each parameter of `[sensitivities]`, `∂q/∂p` and `∂q̇/∂p`.
    Sensitivities,
}

/// An SVG picture a scene can ask for.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq, PartialOrd, Ord)]
#[serde(rename_all = "lowercase")]
pub enum Picture {
    /// Coordinates against each other, in the panels of `output.trajectory` (by default the
    /// second coordinate against the first; with `N = 3`, each pair); the coordinate against `t`
    /// if `N = 1`.
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
    /// `E − E(t0)`, `W_Φ`, `W_Q`, `∫∂L/∂t dt` (those the model has) and the balance against `t`.
    Energy,
    /// Every output quantity against `t`, one panel per unit.
    Quantities,
}

impl Table {
    /// Every table, in the order of the documentation.
    pub const ALL: [Table; 9] = [
        Table::State,
        Table::Acceleration,
        Table::Multipliers,
        Table::Force,
        Table::Residual,
        Table::Energy,
        Table::Events,
        Table::Quantities,
        Table::Sensitivities,
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
            Table::Sensitivities => "sensitivities",
        }
    }

    /// What has to be recorded along the motion for it.
    pub fn record(self) -> Record {
        match self {
            Table::State | Table::Events | Table::Quantities | Table::Sensitivities => {
                Record::State
            }
            Table::Acceleration | Table::Multipliers | Table::Force | Table::Residual => {
                Record::Dynamics
            }
            Table::Energy => Record::Energy,
        }
    }

    pub(crate) fn needs_constraints(self) -> bool {
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

    pub(crate) fn needs_constraints(self) -> bool {
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
    /// The panels of the trajectory picture, each a list of pairs of coordinate indices `(i, j)`
    /// (`q_j` against `q_i`) drawn together; `None` for the default.
    pub trajectory: Option<Vec<Vec<(usize, usize)>>>,
}
