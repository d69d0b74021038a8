//! From a validated scene to `chetaev`'s const-generic problem, and back to runtime-sized results.
//!
//! `chetaev` fixes the number of coordinates `N` and of constraints `K` at compile time. A scene
//! states them at run time, so [`Scene::solve`] dispatches to one compiled instance per supported
//! pair `(N, K)`: `1 ≤ N ≤ 6`, `0 ≤ K ≤ min(N, 3)` (21 pairs), each with the four methods.

use chetaev::integrate::system::Stats;
use chetaev::prelude::*;

use crate::error::Error;
use crate::expr::Env;
use crate::model::ExprModel;
use crate::scene::{GridEnd, MethodSpec, Scene, Times};

/// Calls `$f::<N, K>($args)` for the runtime sizes `($n, $k)`; every supported pair is listed once.
macro_rules! dispatch {
    ($n:expr, $k:expr, $f:ident $args:tt, $unsupported:expr) => {
        dispatch!(@pairs $n, $k, $f $args, $unsupported;
            (1, 0) (1, 1)
            (2, 0) (2, 1) (2, 2)
            (3, 0) (3, 1) (3, 2) (3, 3)
            (4, 0) (4, 1) (4, 2) (4, 3)
            (5, 0) (5, 1) (5, 2) (5, 3)
            (6, 0) (6, 1) (6, 2) (6, 3))
    };
    (@pairs $n:expr, $k:expr, $f:ident $args:tt, $unsupported:expr; $(($N:literal, $K:literal))*) => {
        match ($n, $k) {
            $(($N, $K) => $f::<$N, $K> $args,)*
            _ => $unsupported,
        }
    };
}

/// Whether `(n, k)` is one of the compiled sizes.
pub fn is_supported(n: usize, k: usize) -> bool {
    fn yes<const N: usize, const K: usize>() -> bool {
        true
    }
    dispatch!(n, k, yes(), false)
}

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

/// What an integration of a scene produced, sized at run time. Vectors of diagnostics are empty
/// unless a table or picture asked for them.
#[derive(Clone, Debug)]
#[must_use = "an outcome carries a status that says whether the integration succeeded"]
pub struct Outcome {
    /// The method's name.
    pub method: &'static str,
    /// What was recorded at each output point.
    pub record: Record,
    /// Output times.
    pub t: Vec<f64>,
    /// Coordinates at the output times.
    pub q: Vec<Vec<f64>>,
    /// Velocities.
    pub qd: Vec<Vec<f64>>,
    /// Accelerations ([`Record::Dynamics`]).
    pub qdd: Vec<Vec<f64>>,
    /// Multipliers `μ` ([`Record::Dynamics`]).
    pub mu: Vec<Vec<f64>>,
    /// The Chetaev force `Φ = Jᵀμ` ([`Record::Dynamics`]).
    pub phi: Vec<Vec<f64>>,
    /// Constraint residuals `f` ([`Record::Dynamics`]).
    pub residual: Vec<Vec<f64>>,
    /// Energy `E = q̇·∂L/∂q̇ − L` ([`Record::Dynamics`]).
    pub energy: Vec<f64>,
    /// Work of the Chetaev force since the start ([`Record::Energy`]).
    pub work: Vec<f64>,
    /// `∫∂L/∂t dt` since the start ([`Record::Energy`]).
    pub dl_dt_integral: Vec<f64>,
    /// `E − E(t0) − W_Φ + ∫∂L/∂t dt`, zero along an exact motion ([`Record::Energy`]).
    pub balance: Vec<f64>,
    /// Located events in the order they occurred.
    pub events: Vec<EventRecord>,
    /// Work counters of the integration that recorded the motion.
    pub stats: Stats,
    /// Integrations run: 2 when an output grid ends at a terminal event (the first finds where).
    pub passes: usize,
    /// Why it stopped.
    pub status: Status,
}

impl Outcome {
    /// Whether the end time or a terminal event was reached.
    pub fn is_success(&self) -> bool {
        !matches!(self.status, Status::Failed(_))
    }
}

impl Scene {
    /// Builds the problem and checks it as the integration would, without integrating: the sizes,
    /// the initial state against the constraints, the block system at the start, the options, and
    /// the events and output quantities at the initial state.
    pub fn check(&self) -> Result<(), Error> {
        dispatch!(
            self.n(),
            self.k(),
            check_sized(self),
            Err(self.unsupported())
        )
    }

    /// Integrates the scene, recording only what its tables and pictures need. A problem found
    /// before the integration starts is an `Err`; a failure during it is the outcome's status.
    pub fn solve(&self) -> Result<Outcome, Error> {
        dispatch!(
            self.n(),
            self.k(),
            solve_sized(self),
            Err(self.unsupported())
        )
    }

    fn unsupported(&self) -> Error {
        self.error_at(
            self.spans.initial.clone(),
            format!(
                "N = {} coordinates with K = {} constraints is not a supported size: scenes support \
                 1 ≤ N ≤ 6 and 0 ≤ K ≤ min(N, 3)",
                self.n(),
                self.k()
            ),
        )
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
            E::InvalidOption { name, .. } => {
                let key = if name == "Rk4::h" { "step" } else { name };
                let span = s.options.get(key).cloned().unwrap_or(s.solve.clone());
                self.error_at(span, e.to_string())
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

    fn problem<const N: usize, const K: usize>(&self) -> Result<Problem<ExprModel, N, K>, Error> {
        let model = ExprModel {
            lagrangian: self.lagrangian.clone(),
            constraints: self.constraints.clone(),
        };
        let q0 = SVector::<f64, N>::from_iterator(self.q0.iter().copied());
        let qd0 = SVector::<f64, N>::from_iterator(self.qd0.iter().copied());
        let built = if self.project_velocity && K > 0 {
            Problem::with_projected_velocity(model, self.t0, q0, qd0)
        } else {
            Problem::new(model, self.t0, q0, qd0)
        };
        built.map_err(|e| self.setup_error(e))
    }

    /// The options every integration of the scene shares: end, tolerances, step bounds, events,
    /// projection.
    fn options<const N: usize>(&self, t_end: f64) -> Options<N> {
        let s = &self.solve;
        let mut o = Options::until(t_end);
        o.rtol = s.rtol;
        o.atol = s.atol.clone();
        o.initial_step = s.initial_step;
        o.max_step = s.max_step;
        if let Some(m) = s.max_steps {
            o.max_steps = m;
        }
        if s.projection {
            o = o.project(Projection::default());
        }
        for e in &self.events {
            let expr = e.expr.clone();
            let mut ev = Event::new(
                e.name.clone(),
                move |t, q: &SVector<f64, N>, qd: &SVector<f64, N>| {
                    expr.eval(&Env {
                        t,
                        q: q.as_slice(),
                        qd: qd.as_slice(),
                    })
                },
            );
            ev.direction = e.direction;
            ev.terminal = e.terminal;
            o = o.event(ev);
        }
        o
    }
}

fn check_sized<const N: usize, const K: usize>(scene: &Scene) -> Result<(), Error> {
    let problem = scene.problem::<N, K>()?;
    scene.check_at_start()?;
    // An integration over no time validates the options and evaluates the block system at the
    // start, exactly as a run would.
    let options = scene
        .options::<N>(scene.t0)
        .record(Record::Dynamics)
        .output_final();
    let sol = match scene.solve.method {
        MethodSpec::Dopri5 {
            stiffness_detection,
        } => solve(
            &problem,
            Dopri5 {
                stiffness_detection,
            },
            &options,
        ),
        MethodSpec::Dop853 {
            stiffness_detection,
        } => solve(
            &problem,
            Dop853 {
                stiffness_detection,
            },
            &options,
        ),
        MethodSpec::Rk4 { step } => solve(&problem, Rk4::new(step), &options),
        MethodSpec::Rodas4 => solve(&problem, Rodas4, &options),
    }
    .map_err(|e| scene.setup_error(e))?;
    match sol.status {
        Status::Failed(e) => Err(scene.setup_error(e)),
        _ => Ok(()),
    }
}

fn solve_sized<const N: usize, const K: usize>(scene: &Scene) -> Result<Outcome, Error> {
    let problem = scene.problem::<N, K>()?;
    scene.check_at_start()?;
    match scene.solve.method {
        MethodSpec::Dopri5 {
            stiffness_detection,
        } => integrate(
            scene,
            &problem,
            Dopri5 {
                stiffness_detection,
            },
        ),
        MethodSpec::Dop853 {
            stiffness_detection,
        } => integrate(
            scene,
            &problem,
            Dop853 {
                stiffness_detection,
            },
        ),
        MethodSpec::Rk4 { step } => integrate(scene, &problem, Rk4::new(step)),
        MethodSpec::Rodas4 => integrate(scene, &problem, Rodas4),
    }
}

fn integrate<const N: usize, const K: usize, Me: Method + Copy>(
    scene: &Scene,
    problem: &Problem<ExprModel, N, K>,
    method: Me,
) -> Result<Outcome, Error> {
    let t_end = scene.solve.t_end;
    let base = scene.options::<N>(t_end);
    let mut passes = 1;
    let options = if !scene.samples_motion() {
        base.output_final().record(Record::State)
    } else {
        let record = scene.record();
        match &scene.output.times {
            Times::Steps => base.record(record),
            Times::List(times) => base.output_times(times.clone()).record(record),
            Times::Grid { from, to, count } => {
                let to = match to {
                    GridEnd::Time(x) => *x,
                    GridEnd::End if scene.events.iter().any(|e| e.terminal) => {
                        // Where does the motion stop? One cheap integration finds out.
                        passes = 2;
                        let first = solve(
                            problem,
                            method,
                            &base.clone().output_final().record(Record::State),
                        )
                        .map_err(|e| scene.setup_error(e))?;
                        // If it fails, the recording pass fails at the same place and records
                        // the grid up to there.
                        match first.status {
                            Status::Terminated { .. } => first.t.last().copied().unwrap_or(t_end),
                            _ => t_end,
                        }
                    }
                    GridEnd::End => t_end,
                };
                base.output_times(grid(*from, to, *count)).record(record)
            }
        }
    };
    let sol = solve(problem, method, &options).map_err(|e| scene.setup_error(e))?;
    Ok(outcome(scene, sol, passes))
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

fn outcome<const N: usize, const K: usize>(
    scene: &Scene,
    sol: Solution<N, K>,
    passes: usize,
) -> Outcome {
    let vecs = |v: &[SVector<f64, N>]| v.iter().map(|x| x.as_slice().to_vec()).collect();
    let vecs_k = |v: &[SVector<f64, K>]| v.iter().map(|x| x.as_slice().to_vec()).collect();
    Outcome {
        method: sol.method,
        record: sol.record,
        t: sol.t.clone(),
        q: vecs(&sol.q),
        qd: vecs(&sol.qd),
        qdd: vecs(&sol.qdd),
        mu: vecs_k(&sol.mu),
        phi: vecs(&sol.phi),
        residual: vecs_k(&sol.residual),
        energy: sol.energy.clone(),
        work: sol.work.clone(),
        dl_dt_integral: sol.dl_dt_integral.clone(),
        balance: sol.energy_balance(),
        events: sol
            .events
            .iter()
            .map(|h| EventRecord {
                name: scene
                    .events
                    .get(h.index)
                    .map_or_else(|| format!("event {}", h.index), |e| e.name.clone()),
                index: h.index,
                t: h.t,
                q: h.q.as_slice().to_vec(),
                qd: h.qd.as_slice().to_vec(),
            })
            .collect(),
        stats: sol.stats,
        passes,
        status: sol.status,
    }
}
