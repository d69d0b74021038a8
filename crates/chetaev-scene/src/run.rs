//! From a validated scene to `chetaev`'s run-time-sized problem ([`chetaev::dynamic`]), and back
//! to the outcome.
//!
//! A scene states the number of coordinates `N` and of constraints `K` when it is read, so it is
//! solved through [`chetaev::dynamic`]: the same equations, block solve, methods, step control,
//! events and projection as a model written in Rust with `N` and `K` fixed when compiling, for any
//! `N ≥ 1` and `0 ≤ K ≤ N`.

use std::sync::Arc;

use chetaev::dynamic::{solve_dyn, DynEvent, DynOptions, DynProblem, DynSolution};
use chetaev::prelude::*;

use crate::error::Error;
use crate::expr::Env;
use crate::model::ExprModel;
use crate::scene::{GridEnd, MethodSpec, Scene, Times};

/// A located event, with the event's name.
#[derive(Clone, Debug, PartialEq)]
pub struct EventRecord {
    /// The event's name.
    pub name: String,
    /// Its index in the scene's events.
    pub index: usize,
    /// The time of the zero.
    pub t: f64,
    /// Coordinates there.
    pub q: Vec<f64>,
    /// Velocities there.
    pub qd: Vec<f64>,
}

/// What an integration of a scene produced: the library's [`DynSolution`] (whose fields it
/// dereferences to: `t`, `q`, `qd`, `qdd`, `mu`, `phi`, `residual`, `energy`, `work`, `stats`,
/// `status`, ...), with the events named and the energy balance computed. Vectors of diagnostics are
/// empty unless a table or picture asked for them.
#[derive(Clone, Debug)]
#[must_use = "an outcome carries a status that says whether the integration succeeded"]
pub struct Outcome {
    /// The motion and its diagnostics.
    pub solution: DynSolution,
    /// `E − E(t0) − W_Φ + ∫∂L/∂t dt`, zero along an exact motion ([`Record::Energy`]).
    pub balance: Vec<f64>,
    /// Located events in the order they occurred, with their names.
    pub events: Vec<EventRecord>,
    /// Integrations run: 2 when an output grid ends at a terminal event (the first finds where).
    pub passes: usize,
}

impl std::ops::Deref for Outcome {
    type Target = DynSolution;
    fn deref(&self) -> &DynSolution {
        &self.solution
    }
}

impl Outcome {
    /// Whether the end time or a terminal event was reached.
    pub fn is_success(&self) -> bool {
        !matches!(self.status, Status::Failed(_))
    }
}

impl Scene {
    /// Builds the problem and checks it as the integration would, without integrating: the initial
    /// state against the constraints, the block system at the start, the options, and the events
    /// and output quantities at the initial state.
    pub fn check(&self) -> Result<(), Error> {
        let problem = self.problem()?;
        self.check_at_start()?;
        // An integration over no time validates the options and evaluates the block system at the
        // start, exactly as a run would.
        let options = self
            .options(self.t0)
            .record(Record::Dynamics)
            .output_final();
        let sol = match self.solve.method {
            MethodSpec::Dopri5 {
                stiffness_detection,
            } => solve_dyn(
                &problem,
                Dopri5 {
                    stiffness_detection,
                },
                &options,
            ),
            MethodSpec::Dop853 {
                stiffness_detection,
            } => solve_dyn(
                &problem,
                Dop853 {
                    stiffness_detection,
                },
                &options,
            ),
            MethodSpec::Rk4 { step } => solve_dyn(&problem, Rk4::new(step), &options),
            MethodSpec::Rodas4 => solve_dyn(&problem, Rodas4, &options),
        }
        .map_err(|e| self.setup_error(e))?;
        match sol.status {
            Status::Failed(e) => Err(self.setup_error(e)),
            _ => Ok(()),
        }
    }

    /// Integrates the scene, recording only what its tables and pictures need. A problem found
    /// before the integration starts is an `Err`; a failure during it is the outcome's status.
    pub fn solve(&self) -> Result<Outcome, Error> {
        let problem = self.problem()?;
        self.check_at_start()?;
        match self.solve.method {
            MethodSpec::Dopri5 {
                stiffness_detection,
            } => self.integrate(
                &problem,
                Dopri5 {
                    stiffness_detection,
                },
            ),
            MethodSpec::Dop853 {
                stiffness_detection,
            } => self.integrate(
                &problem,
                Dop853 {
                    stiffness_detection,
                },
            ),
            MethodSpec::Rk4 { step } => self.integrate(&problem, Rk4::new(step)),
            MethodSpec::Rodas4 => self.integrate(&problem, Rodas4),
        }
    }

    /// A located error for a setup failure reported by `chetaev`.
    fn setup_error(&self, e: chetaev::Error) -> Error {
        use chetaev::Error as E;
        let s = &self.spans;
        match e {
            E::InconsistentInitialState {
                t,
                index,
                residual,
                tolerance,
            } => self.error_at(
                s.q_dot.clone(),
                format!(
                    "the initial velocity violates constraint {} ({}): f = {residual:e} at t = {t} \
                     (allowed {tolerance:e}); give a consistent q_dot, or set project_velocity = true \
                     under [initial] to project it onto f = 0",
                    index + 1,
                    self.constraints
                        .get(index)
                        .map_or("?", |c| c.source())
                ),
            ),
            E::InvalidOption { name, value, hint } => {
                // The option by its key in the scene file.
                let key = if name == "Rk4::h" { "step" } else { name };
                let span = s.options.get(key).cloned().unwrap_or(s.solve.clone());
                self.error_at(span, format!("invalid {key} = {value} under [solve]: {hint}"))
            }
            E::DegenerateConstraint { index, .. } => {
                let span = s.constraints.get(index).cloned().unwrap_or(s.initial.clone());
                self.error_at(span, format!("at the initial state, {e}"))
            }
            E::Singular { .. } => {
                let span = s.constraints.first().cloned().unwrap_or(s.lagrangian.clone());
                self.error_at(span, format!("at the initial state, {e}"))
            }
            other => self.error_at(s.initial.clone(), format!("at the initial state, {other}")),
        }
    }

    /// Evaluates the events and output quantities at the initial state: a NaN there is a mistake
    /// in the scene, found before integrating.
    fn check_at_start(&self) -> Result<(), Error> {
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
        for (i, (name, q)) in self.output.quantities.iter().enumerate() {
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

    fn problem(&self) -> Result<DynProblem<ExprModel>, Error> {
        let model = ExprModel {
            n: self.n(),
            lagrangian: self.lagrangian.clone(),
            constraints: self.constraints.clone(),
        };
        let (q0, qd0) = (self.q0.clone(), self.qd0.clone());
        if self.project_velocity && self.k() > 0 {
            DynProblem::with_projected_velocity(model, self.t0, q0, qd0)
        } else {
            DynProblem::new(model, self.t0, q0, qd0)
        }
        .map_err(|e| self.setup_error(e))
    }

    /// The options every integration of the scene shares: end, tolerances, step bounds, events,
    /// projection.
    fn options(&self, t_end: f64) -> DynOptions {
        let s = &self.solve;
        let mut o = DynOptions::until(t_end);
        o.common.rtol = s.rtol;
        o.common.atol = s.atol.clone();
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
            let expr = e.expr.clone();
            o = o.event(DynEvent {
                name: e.name.clone(),
                g: Arc::new(move |t, q: &[f64], qd: &[f64]| expr.eval(&Env { t, q, qd })),
                direction: e.direction,
                terminal: e.terminal,
            });
        }
        o
    }

    fn integrate<Me: Method + Copy>(
        &self,
        problem: &DynProblem<ExprModel>,
        method: Me,
    ) -> Result<Outcome, Error> {
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
                            // Where does the motion stop? One cheap integration finds out.
                            passes = 2;
                            let first = solve_dyn(
                                problem,
                                method,
                                &base.clone().output_final().record(Record::State),
                            )
                            .map_err(|e| self.setup_error(e))?;
                            // If it fails, the recording pass fails at the same place and records
                            // the grid up to there.
                            match first.status {
                                Status::Terminated { .. } => {
                                    first.t.last().copied().unwrap_or(t_end)
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
        let sol = solve_dyn(problem, method, &options).map_err(|e| self.setup_error(e))?;
        Ok(self.outcome(sol, passes))
    }

    fn outcome(&self, sol: DynSolution, passes: usize) -> Outcome {
        let balance = sol.energy_balance();
        let events = sol
            .events
            .iter()
            .map(|h| EventRecord {
                name: self
                    .events
                    .get(h.index)
                    .map_or_else(|| format!("event {}", h.index), |e| e.name.clone()),
                index: h.index,
                t: h.t,
                q: h.q.clone(),
                qd: h.qd.clone(),
            })
            .collect();
        Outcome {
            solution: sol,
            balance,
            events,
            passes,
        }
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
