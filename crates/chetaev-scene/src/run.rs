//! From a validated scene to `chetaev`'s problem, and back to the outcome.
//!
//! A scene states the number of coordinates `N` and of constraints `K` when it is read, so its
//! model is a run-time-sized [`DynModel`] ([`Problem::dynamic`]): the same `Problem`, `Options`,
//! `Event`, `Solution` and `solve` as a model written in Rust with `N` and `K` fixed when
//! compiling, for any `N ≥ 1` and `0 ≤ K ≤ N`.

use chetaev::prelude::*;
use chetaev::Warning;

use std::ops::Range;

use crate::error::Error;
use crate::expr::{Env, Expr};
use crate::model::ExprModel;
use crate::output::{state_text, summary_number};
use crate::scene::{GridEnd, LoadSpec, Scene, Times};

/// What an integration of a scene produced: the library's [`Solution`] (whose fields it
/// dereferences to: `t`, `q`, `qd`, `qdd`, `mu`, `phi`, `residual`, `energy`, `work`, `events`,
/// `stats`, `status`, ...), with the energy balance computed and the events' names. Series of
/// diagnostics are empty unless a table or picture asked for them.
#[derive(Clone, Debug)]
#[must_use = "an outcome carries a status that says whether the integration succeeded"]
pub struct Outcome {
    /// The motion and its diagnostics.
    pub solution: Solution,
    /// `E − E(t0) − W_Φ − W_Q + ∫∂L/∂t dt`, zero along an exact motion ([`Record::Energy`]).
    pub balance: Vec<f64>,
    /// The names of the scene's events, by index (`solution.events[i].index`).
    pub event_names: Vec<String>,
    /// Integrations run: 2 when an output grid ends at a terminal event (the first finds where).
    pub passes: usize,
}

impl std::ops::Deref for Outcome {
    type Target = Solution;
    fn deref(&self) -> &Solution {
        &self.solution
    }
}

impl Outcome {
    /// Whether the end time or a terminal event was reached.
    pub fn is_success(&self) -> bool {
        !matches!(self.status, Status::Failed(_))
    }

    /// The name of event `index` of the scene.
    pub fn event_name(&self, index: usize) -> &str {
        self.event_names.get(index).map_or("?", String::as_str)
    }

    /// The width of the longest name among the located events, for aligned lines.
    pub(crate) fn event_name_width(&self) -> usize {
        self.events
            .iter()
            .map(|e| self.event_name(e.index).chars().count())
            .max()
            .unwrap_or(0)
    }
}

impl Scene {
    /// Builds the problem and checks it as the integration would, without integrating: the initial
    /// state against the constraints, the block system at the start, the options, and the events
    /// and output quantities at the initial state.
    pub fn check(&self) -> Result<(), Error> {
        self.check_with_warnings().map(|_| ())
    }

    /// [`Scene::check`], with what a run would warn of at the start (an event zero there).
    pub fn check_with_warnings(&self) -> Result<Vec<Warning>, Error> {
        let problem = self.problem()?;
        self.check_at_start()?;
        // An integration over no time validates the options and evaluates the block system at the
        // start, exactly as a run would.
        let options = self
            .options(self.t0)
            .record(Record::Dynamics)
            .output_final();
        let sol = solve(&problem, self.solve.method, &options).map_err(|e| self.setup_error(e))?;
        match sol.status {
            Status::Failed(e) => Err(self.setup_error(e)),
            _ => Ok(sol.warnings),
        }
    }

    /// The equations the library derived for the scene, described at its initial state
    /// ([`chetaev::Problem::describe_named`]), as plain text: the coordinates by their names
    /// (`x`, `x_dot`) and the parameters as symbols.
    pub fn describe(&self) -> Result<String, Error> {
        let d = self.description()?;
        let names = self.coordinates.join(", ");
        Ok(format!("coordinates q = ({names})\n{d}"))
    }

    /// The equations the library derived for the scene, as one LaTeX `align*` environment, with
    /// the coordinates and parameters by their names (`theta` as `\theta`, `v0` as `v_{0}`); an
    /// explanation where the scene's model cannot be recorded.
    pub fn describe_latex(&self) -> Result<String, Error> {
        let d = self.description()?;
        let names = self.coordinates.join(", ");
        let latex = d.latex();
        if latex.is_empty() {
            return Ok("% the model could not be recorded as expressions".to_string());
        }
        Ok(format!(
            "% coordinates q = ({names}); r = dL/dq - g + Q (Q with -dD/dqdot), the right side of W qdd - J^T mu = r\n{latex}"
        ))
    }

    /// The description at the initial state, of the model with every parameter a symbol
    /// ([`Scene::symbolic_model`]) where it can be made, else of the scene's own.
    fn description(&self) -> Result<chetaev::equations::structure::Description, Error> {
        let problem = self.problem()?;
        let names = chetaev::equations::structure::Names::coordinates(&self.coordinates);
        let (t0, q0, qd0) = (self.t0, problem.q0().to_vec(), problem.qd0().to_vec());
        let symbolic = self
            .symbolic_model()
            .and_then(|m| Problem::dynamic(m, t0, q0.clone(), qd0.clone()).ok());
        match &symbolic {
            Some(p) => p.describe_named(t0, &q0, &qd0, &names),
            None => problem.describe_named(t0, &q0, &qd0, &names),
        }
        .map_err(|e| self.setup_error(e))
    }

    /// The scene's model with every parameter read by its name
    /// ([`Real::parameter`](chetaev::prelude::Real::parameter)), so that a description shows
    /// `tan(alpha)` where the model would fold it to its value; its values are the scene's.
    /// `None` where an expression does not resolve so.
    fn symbolic_model(&self) -> Option<ExprModel> {
        let symbols = crate::expr::Symbols {
            parameters: self.parameters.iter().cloned().collect(),
            varying: self
                .parameters
                .iter()
                .enumerate()
                .map(|(i, (name, _))| (name.clone(), i))
                .collect(),
            coordinates: self.coordinates.clone(),
            motion: true,
            recorded: Vec::new(),
        };
        let again = |e: &Expr| Expr::parse(e.source(), &symbols).ok();
        let all = |list: &[Expr]| list.iter().map(again).collect::<Option<Vec<Expr>>>();
        Some(ExprModel {
            n: self.n(),
            lagrangian: again(&self.lagrangian)?,
            constraints: all(&self.constraints)?,
            holonomic: all(&self.holonomic)?,
            forces: all(&self.forces)?,
            dissipation: match &self.dissipation {
                Some(d) => Some(again(d)?),
                None => None,
            },
            loads: self
                .loads
                .iter()
                .map(|load| {
                    Some(match load {
                        LoadSpec::Force { point, force } => LoadSpec::Force {
                            point: all(point)?,
                            force: all(force)?,
                        },
                        LoadSpec::Torque {
                            angular_velocity,
                            torque,
                        } => LoadSpec::Torque {
                            angular_velocity: all(angular_velocity)?,
                            torque: all(torque)?,
                        },
                    })
                })
                .collect::<Option<Vec<_>>>()?,
        })
    }

    /// Integrates the scene, recording only what its tables and pictures need. A problem found
    /// before the integration starts is an `Err`; a failure during it is the outcome's status.
    pub fn solve(&self) -> Result<Outcome, Error> {
        let problem = self.problem()?;
        self.check_at_start()?;
        self.integrate(&problem, self.solve.method)
    }

    /// Constraint `index` as `chetaev` numbers the constraints (from 1: the velocity constraints,
    /// then one per holonomic constraint, its time derivative `ḣ = 0`): the velocity constraint
    /// `Ok(a)` or the holonomic constraint `Err(b)`, both from 0; `None` past the end.
    fn constraint_at(&self, index: usize) -> Option<Result<usize, usize>> {
        let a = index.checked_sub(1)?;
        match a.checked_sub(self.constraints.len()) {
            None => Some(Ok(a)),
            Some(b) => (b < self.holonomic.len()).then_some(Err(b)),
        }
    }

    /// Constraint `index` (numbered as in [`Scene::constraint_at`]) named by its source in the
    /// file: "constraint 1 (x_dot^2 + y_dot^2 - v0^2)", "holonomic constraint 1 (x^2 + y^2 - l^2)".
    pub(crate) fn constraint_name(&self, index: usize) -> String {
        match self.constraint_at(index) {
            Some(Ok(a)) => format!("constraint {index} ({})", self.constraints[a].source()),
            Some(Err(b)) => format!(
                "holonomic constraint {} ({})",
                b + 1,
                self.holonomic[b].source()
            ),
            None => format!("constraint {index}"),
        }
    }

    /// Why constraint `index` (numbered as in [`Scene::constraint_at`]) can stop restricting the
    /// velocity, in the terms of its kind.
    pub(crate) fn why_degenerate(&self, index: usize) -> &'static str {
        match self.constraint_at(index) {
            Some(Err(_)) => {
                "its derivative by the coordinates vanishes there (write it so that its gradient \
                 does not vanish where it holds: x^2 + y^2 - l^2, not its square)"
            }
            _ => {
                "its derivative by the velocities vanishes there (a constraint on the speed, such \
                 as x_dot^2 + y_dot^2 - v0^2, needs a speed that is not zero)"
            }
        }
    }

    /// Where constraint `index` (numbered as in [`Scene::constraint_at`]) is written.
    pub(crate) fn constraint_span(&self, index: usize) -> Option<Range<usize>> {
        match self.constraint_at(index)? {
            Ok(a) => self.spans.constraints.get(a).cloned(),
            Err(b) => self.spans.holonomic.get(b).cloned(),
        }
    }

    /// A located error for a setup failure reported by `chetaev`, told by the scene's keys (the
    /// library's own messages name its Rust API).
    pub(crate) fn setup_error(&self, e: chetaev::Error) -> Error {
        use chetaev::Error as E;
        let s = &self.spans;
        let v = self.constraints.len();
        match e {
            E::InconsistentInitialState {
                t,
                index,
                holonomic: Some(_),
                residual,
                tolerance,
            } => self.error_at(
                // A holonomic constraint, through its time derivative ḣ = ∂h/∂q q̇ + ∂h/∂t.
                s.q_dot.clone(),
                format!(
                    "the initial velocity violates {} differentiated in time: ḣ = ∂h/∂q·q̇ + ∂h/∂t \
                     = {residual:.3e} at t = {t} (allowed {tolerance:.2e}), so the motion would leave \
                     h = 0 at once; give a q_dot along the constraint (ḣ = 0), or set \
                     project_velocity = true under [initial] to project it onto ḣ = 0",
                    self.constraint_name(index)
                ),
            ),
            E::InconsistentInitialState {
                t,
                index,
                holonomic: None,
                residual,
                tolerance,
            } => self.error_at(
                s.q_dot.clone(),
                format!(
                    "the initial velocity violates {}: f = {residual:.3e} at t = {t} \
                     (allowed {tolerance:.2e}); give a consistent q_dot, or set project_velocity = true \
                     under [initial] to project it onto f = 0",
                    self.constraint_name(index)
                ),
            ),
            E::InconsistentInitialPosition {
                t,
                index,
                residual,
                tolerance,
            } => self.error_at(
                s.q.clone(),
                format!(
                    "the initial position violates {}: h = {residual:.3e} at t = {t} (allowed \
                     {tolerance:.2e}); give a q on the constraint, or set project_velocity = true \
                     under [initial] to project q onto h = 0 (and then q_dot onto the velocity \
                     constraints; the summary says what changed)",
                    // The library numbers the holonomic constraints from 1 among themselves.
                    self.constraint_name(v + index)
                ),
            ),
            E::InvalidOption { name, value, hint } => {
                // The option by its key in the scene file.
                let key = if name == "Rk4::h" { "step" } else { name };
                let span = s.options.get(key).cloned().unwrap_or(s.solve.clone());
                self.error_at(
                    span,
                    format!(
                        "invalid {key} = {} under [solve]: {hint}",
                        summary_number(value)
                    ),
                )
            }
            E::DegenerateConstraint { index, ref q, ref qd, t } => {
                let span = self.constraint_span(index).unwrap_or(s.initial.clone());
                self.error_at(
                    span,
                    format!(
                        "at the initial state (t = {}, {}), {} does not restrict the velocity: {}",
                        summary_number(t),
                        state_text(self, q, qd),
                        self.constraint_name(index),
                        self.why_degenerate(index)
                    ),
                )
            }
            E::NonFiniteEvaluation { t, ref q, ref qd } => {
                let state = format!("t = {}, {}", summary_number(t), state_text(self, q, qd));
                match self.non_finite_part(t, q, qd) {
                    Some(part) => self.error_at(
                        part.span,
                        format!(
                            "at the initial state ({state}), {}: the expression leaves its domain \
                             there (a square root or logarithm of a negative number, a division by \
                             zero, or an overflow); check it, or give another initial state under \
                             [initial]",
                            part.what
                        ),
                    ),
                    None => self.error_at(s.initial.clone(), format!("at the initial state, {e}")),
                }
            }
            e @ E::Completion { .. } => self.error_at(
                s.independent.clone(),
                format!(
                    "{e} (coordinates and constraints are numbered from 1 in the order of the file)"
                ),
            ),
            E::InitialProjectionFailed {
                residual,
                iterations,
                ..
            } => self.error_at(
                s.initial.clone(),
                format!(
                    "project_velocity = true could not make the initial state consistent: the \
                     projection onto the constraints left a residual of {residual:.3e} after \
                     {iterations} iterations; give a q and q_dot closer to the constraints, and \
                     check that they can be met there with a nonzero gradient (a speed \
                     constraint whose prescribed speed is 0 at t0 cannot)"
                ),
            ),
            E::InconsistentSeed {
                seed,
                constraint,
                holonomic,
                residual,
                ..
            } => {
                // A velocity constraint ties q_dot to the parameter, a holonomic one q and q_dot.
                let span = if holonomic.is_none() {
                    s.q_dot.clone()
                } else {
                    s.initial.clone()
                };
                self.error_at(
                    span,
                    format!(
                        "moving '{seed}' moves the initial state off {} to first order (residual \
                         {residual:.3e}): the initial values that the constraint ties to '{seed}' must \
                         move with it; write them under [initial] as expressions of '{seed}' (for \
                         x_dot^2 + y_dot^2 - v0^2, q_dot = [\"v0\", 0.0])",
                        self.constraint_name(constraint)
                    ),
                )
            }
            E::Sensitivity { what } => self.error_at(
                s.sensitivities.clone(),
                format!("the sensitivities asked for cannot be taken: {what}"),
            ),
            E::Singular { .. } => {
                let span = s.constraints.first().cloned().unwrap_or(s.lagrangian.clone());
                self.error_at(span, format!("at the initial state, {e}"))
            }
            other => self.error_at(s.initial.clone(), format!("at the initial state, {other}")),
        }
    }

    /// Evaluates the events and output quantities at the initial state: a NaN there is a mistake
    /// in the scene, found before integrating.
    pub(crate) fn check_at_start(&self) -> Result<(), Error> {
        let env = Env {
            t: self.t0,
            q: &self.q0,
            qd: &self.qd0,
        };
        let state = format!("t = {}, q = {:?}, q_dot = {:?}", self.t0, self.q0, self.qd0);
        for (i, e) in self.events.iter().enumerate() {
            let v = e.expr.eval(&env);
            if !v.is_finite() {
                return Err(self.error_at(
                    self.spans.events[i].clone(),
                    format!(
                        "the event '{}' is {v} at the initial state ({state}); check its domain",
                        e.name
                    ),
                ));
            }
        }
        // Those that read μ or Φ are evaluated where these are recorded.
        let along = self.output.quantities.iter().enumerate();
        for (i, (name, q)) in along.filter(|(_, (_, q))| !q.reads_recorded()) {
            let v = q.eval(&env);
            if !v.is_finite() {
                return Err(self.error_at(
                    self.spans.quantities[i].clone(),
                    format!("the quantity '{name}' is {v} at the initial state ({state}); check its domain"),
                ));
            }
        }
        Ok(())
    }

    /// The scene's problem: its expressions as a [`DynModel`](chetaev::model::DynModel), with its
    /// initial state (made consistent where the scene asks for it). A scene's equations take the
    /// library's routes as any model does: recorded and compiled, then machine code.
    pub fn problem(&self) -> Result<Problem<ExprModel>, Error> {
        let model = ExprModel {
            n: self.n(),
            lagrangian: self.lagrangian.clone(),
            constraints: self.constraints.clone(),
            holonomic: self.holonomic.clone(),
            forces: self.forces.clone(),
            dissipation: self.dissipation.clone(),
            loads: self.loads.clone(),
        };
        let (mut q0, mut qd0) = (self.q0.clone(), self.qd0.clone());
        if let Some(independent) = &self.independent {
            let done = chetaev::manifold::complete(&model, self.t0, &q0, &qd0, independent)
                .map_err(|e| self.setup_error(e))?;
            (q0, qd0) = (done.q, done.qd);
        }
        if self.project_velocity && self.k() > 0 {
            Problem::dynamic_with_projected_velocity(model, self.t0, q0, qd0)
        } else {
            Problem::dynamic(model, self.t0, q0, qd0)
        }
        .map_err(|e| self.setup_error(e))
    }

    /// The options every integration of the scene shares: end, tolerances, step bounds, events,
    /// projection.
    pub fn options(&self, t_end: f64) -> Options {
        let s = &self.solve;
        let mut o = Options::until(t_end);
        o.rtol = s.rtol;
        o.atol = s.atol.clone();
        if let Some(h) = s.initial_step {
            o = o.initial_step(h);
        }
        if let Some(h) = s.max_step {
            o = o.max_step(h);
        }
        if let Some(m) = s.max_steps {
            o = o.max_steps(m);
        }
        if s.projection {
            o = o.project(Projection::default());
        }
        for e in &self.events {
            let mut event = Event::smooth(e.name.clone(), EventExpr(e.expr.clone()));
            event.direction = e.direction;
            event.terminal = e.terminal;
            o = o.event(event);
        }
        if let Some(sens) = &self.sensitivities {
            for seed in &sens.seeds {
                o = o.sensitivity(seed.clone());
            }
            o = o.sensitivity_control(sens.control);
        }
        o
    }

    fn integrate(&self, problem: &Problem<ExprModel>, method: AnyMethod) -> Result<Outcome, Error> {
        let t_end = self.solve.t_end;
        let base = self.options(t_end);
        let mut passes = 1;
        let options = if !self.samples_motion() {
            base.output_final().record(Record::State)
        } else {
            let record = self.record();
            match &self.output.times {
                Times::Steps => base.record(record),
                Times::List(times) => base.output_times(times.clone()).record(record),
                Times::Grid { from, to, count } => {
                    let to = match to {
                        GridEnd::Time(x) => *x,
                        GridEnd::End if self.events.iter().any(|e| e.terminal) => {
                            // Where does the motion stop? One cheap integration finds out. It
                            // carries the sensitivities only where they are under error control,
                            // which changes the steps (and so, in the last digits, where the
                            // motion stops); else the steps are those of the motion alone.
                            passes = 2;
                            let mut first = base.clone().output_final().record(Record::State);
                            if !first.sensitivity_control {
                                first.sensitivities.clear();
                            }
                            let first =
                                solve(problem, method, &first).map_err(|e| self.setup_error(e))?;
                            // If it fails, the recording pass fails at the same place and records
                            // the grid up to there.
                            match first.status {
                                Status::Terminated { event } => {
                                    let stop = first.t.last().copied().unwrap_or(t_end);
                                    // A grid that would begin after the motion has stopped has
                                    // no time to record.
                                    let dir = (t_end - self.t0).signum();
                                    if dir * (*from - stop) > 0.0 {
                                        let span = self.spans.events.get(event).cloned();
                                        return Err(self.error_at(
                                            span.unwrap_or_else(|| self.spans.solve.clone()),
                                            format!(
                                                "the output grid starts at t = {from}, but this \
                                                 terminal event stops the motion earlier, at \
                                                 t = {stop}: start [output] times at or before \
                                                 it, or give a list of times"
                                            ),
                                        ));
                                    }
                                    stop
                                }
                                _ => t_end,
                            }
                        }
                        GridEnd::End => t_end,
                    };
                    base.output_times(grid(*from, to, *count)).record(record)
                }
            }
        };
        let sol = solve(problem, method, &options).map_err(|e| self.setup_error(e))?;
        Ok(self.outcome(sol, passes))
    }

    fn outcome(&self, sol: Solution, passes: usize) -> Outcome {
        Outcome {
            balance: sol.energy_balance(),
            solution: sol,
            event_names: self.events.iter().map(|e| e.name.clone()).collect(),
            passes,
        }
    }
}

/// An event function given as an expression: written for any scalar, so the event's time and
/// state have exact derivatives with respect to the parameters ([`Event::smooth`]). Located
/// with `f64`, it is the expression's value as before.
struct EventExpr(Expr);

impl EventFunction for EventExpr {
    #[inline]
    fn value<R: Real>(&self, t: R, q: &[R], qd: &[R]) -> R {
        self.0.eval(&Env { t, q, qd })
    }
}

/// `count` equally spaced times from `from` to `to`, both included exactly.
pub(crate) fn grid(from: f64, to: f64, count: usize) -> Vec<f64> {
    let n = count.max(2) - 1;
    (0..=n)
        .map(|i| {
            if i == n {
                to
            } else {
                from + (to - from) * (i as f64 / n as f64)
            }
        })
        .collect()
}
