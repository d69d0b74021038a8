//! The quantities a sweep collects from each run, and the run that records just what they need.
//!
//! | written | what |
//! |---|---|
//! | `impact.t`, `impact.x`, `impact.x_dot` | the time and state of the first hit of the event `impact` (NaN if none) |
//! | `impact.count` | how often the event was hit |
//! | `end.t`, `end.x`, `end.x_dot` | the last point reached: the end time, a terminal event, or where a failed run stopped |
//! | `x@1.5`, `x_dot@1.5` | the value at `t = 1.5`, by dense output (NaN if the run stopped before) |
//! | `max.x`, `min.x_dot`, `max_abs.x` | extremes of a coordinate or velocity over the accepted steps |
//! | `max_abs.mu_1`, `max.mu_1`, `min.mu_1` | extremes of a multiplier (Newton form) over the accepted steps |
//! | `max.residual` | the largest `|f_a|` of any constraint over the accepted steps |
//! | `max_abs.balance` | the largest `|E − E0 − W_Φ − W_Q + ∫∂L/∂t dt|` over the accepted steps |
//! | `d(impact.t)/d(v0)`, `d(end.x)/d(v0)` | the derivative of an event or end quantity with respect to a parameter of `[sensitivities]` |
//!
//! Extremes are taken over the points the integration accepted (and its start, end and events),
//! not between them.

use chetaev::prelude::*;

use super::table::{Row, RunStatus};
use crate::Scene;

/// Which part of a state.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Part {
    /// The time.
    Time,
    /// Coordinate `i`.
    Position(usize),
    /// Velocity `i`.
    Velocity(usize),
}

/// An extreme over the steps.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Extreme {
    /// The largest value.
    Max,
    /// The smallest value.
    Min,
    /// The largest magnitude.
    MaxAbs,
}

/// A series along the motion whose extremes are taken.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Of {
    /// Coordinate `i`.
    Position(usize),
    /// Velocity `i`.
    Velocity(usize),
    /// Multiplier `a` (from 0).
    Multiplier(usize),
    /// `max_a |f_a|`.
    Residual,
    /// The energy balance.
    Balance,
}

/// A quantity collected from each run ([module docs](self) list how each is written).
#[derive(Clone, Debug, PartialEq)]
pub enum Quantity {
    /// A part of the first hit of an event.
    Event {
        /// The event, by index.
        event: usize,
        /// Which part.
        part: Part,
    },
    /// How often an event was hit.
    EventCount {
        /// The event, by index.
        event: usize,
    },
    /// A part of the last point reached.
    End(Part),
    /// A coordinate or velocity at a time.
    At {
        /// The time.
        t: f64,
        /// Which part (not the time).
        part: Part,
    },
    /// An extreme over the steps.
    Extreme {
        /// Which extreme.
        kind: Extreme,
        /// Of what.
        of: Of,
    },
    /// The derivative of an event or end quantity with respect to a parameter.
    Derivative {
        /// The quantity ([`Quantity::Event`] or [`Quantity::End`]).
        of: Box<Quantity>,
        /// The seed, by index in the scene's `[sensitivities]`.
        seed: usize,
    },
}

impl Quantity {
    /// What is collected when nothing is named: each event's time and state, the end's, and
    /// (with constraints) the extremes of the multipliers and the residual, and the energy
    /// balance's worst.
    pub fn defaults(scene: &Scene) -> Vec<Quantity> {
        let n = scene.n();
        let state = |make: &dyn Fn(Part) -> Quantity| {
            let mut v = vec![make(Part::Time)];
            v.extend((0..n).map(|i| make(Part::Position(i))));
            v.extend((0..n).map(|i| make(Part::Velocity(i))));
            v
        };
        let mut out = Vec::new();
        for e in 0..scene.events.len() {
            out.extend(state(&|part| Quantity::Event { event: e, part }));
        }
        out.extend(state(&Quantity::End));
        for a in 0..scene.k() {
            out.push(Quantity::Extreme {
                kind: Extreme::MaxAbs,
                of: Of::Multiplier(a),
            });
        }
        if scene.k() > 0 {
            out.push(Quantity::Extreme {
                kind: Extreme::Max,
                of: Of::Residual,
            });
        }
        out.push(Quantity::Extreme {
            kind: Extreme::MaxAbs,
            of: Of::Balance,
        });
        out
    }

    /// Reads a quantity as written (see the [module docs](self)); the error says what can be
    /// written instead.
    pub fn parse(text: &str, scene: &Scene) -> Result<Quantity, String> {
        let text = text.trim();
        if let Some(inner) = text.strip_prefix("d(") {
            let (of, param) = inner
                .split_once(")/d(")
                .ok_or_else(|| format!("`{text}`: write a derivative as d(impact.t)/d(v0)"))?;
            let param = param
                .strip_suffix(')')
                .ok_or_else(|| format!("`{text}`: write a derivative as d(impact.t)/d(v0)"))?;
            let of = Quantity::parse(of, scene)?;
            if !matches!(of, Quantity::Event { .. } | Quantity::End(_)) {
                return Err(format!(
                    "`{text}`: derivatives are taken of an event's or the end's time and state \
                     (d(impact.t)/d(v0), d(end.x)/d(v0))"
                ));
            }
            let seed = scene
                .sensitivities
                .as_ref()
                .and_then(|s| s.parameters.iter().position(|p| p == param))
                .ok_or_else(|| {
                    format!(
                        "`{text}`: the scene takes no sensitivity with respect to `{param}`: add \
                         it under [sensitivities] parameters = [\"{param}\"]"
                    )
                })?;
            return Ok(Quantity::Derivative {
                of: Box::new(of),
                seed,
            });
        }
        if let Some((what, t)) = text.split_once('@') {
            let t: f64 = t
                .trim()
                .parse()
                .ok()
                .filter(|t: &f64| t.is_finite())
                .ok_or_else(|| format!("`{text}`: the time after @ is not a finite number"))?;
            let part = state_part(what.trim(), scene)
                .filter(|p| *p != Part::Time)
                .ok_or_else(|| {
                    format!(
                        "`{text}`: before @ goes a coordinate or velocity ({})",
                        names(scene).join(", ")
                    )
                })?;
            return Ok(Quantity::At { t, part });
        }
        let (head, tail) = text.split_once('.').ok_or_else(|| unknown(text, scene))?;
        match head {
            "end" => state_part(tail, scene)
                .map(Quantity::End)
                .ok_or_else(|| unknown(text, scene)),
            "max" | "min" | "max_abs" => {
                let kind = match head {
                    "max" => Extreme::Max,
                    "min" => Extreme::Min,
                    _ => Extreme::MaxAbs,
                };
                let of = match tail {
                    "residual" if scene.k() > 0 => Of::Residual,
                    "residual" => {
                        return Err(format!(
                            "`{text}`: the scene has no constraints, so no residual"
                        ))
                    }
                    "balance" => Of::Balance,
                    _ => match tail
                        .strip_prefix("mu_")
                        .and_then(|a| a.parse::<usize>().ok())
                    {
                        Some(a) if (1..=scene.k()).contains(&a) => Of::Multiplier(a - 1),
                        Some(a) => {
                            return Err(format!(
                                "`{text}`: the scene has {} multiplier(s), mu_1 … mu_{0}, not \
                                 mu_{a}",
                                scene.k()
                            ))
                        }
                        None => match state_part(tail, scene) {
                            Some(Part::Position(i)) => Of::Position(i),
                            Some(Part::Velocity(i)) => Of::Velocity(i),
                            _ => return Err(unknown(text, scene)),
                        },
                    },
                };
                Ok(Quantity::Extreme { kind, of })
            }
            event => {
                let e = scene
                    .events
                    .iter()
                    .position(|s| s.name == event)
                    .ok_or_else(|| unknown(text, scene))?;
                if tail == "count" {
                    return Ok(Quantity::EventCount { event: e });
                }
                state_part(tail, scene)
                    .map(|part| Quantity::Event { event: e, part })
                    .ok_or_else(|| unknown(text, scene))
            }
        }
    }

    /// The quantity as [`Quantity::parse`] reads it.
    pub fn name(&self, scene: &Scene) -> String {
        let part = |p: &Part| match p {
            Part::Time => "t".to_string(),
            Part::Position(i) => scene.coordinates[*i].clone(),
            Part::Velocity(i) => format!("{}_dot", scene.coordinates[*i]),
        };
        match self {
            Quantity::Event { event, part: p } => {
                format!("{}.{}", scene.events[*event].name, part(p))
            }
            Quantity::EventCount { event } => format!("{}.count", scene.events[*event].name),
            Quantity::End(p) => format!("end.{}", part(p)),
            Quantity::At { t, part: p } => format!("{}@{t}", part(p)),
            Quantity::Extreme { kind, of } => {
                let kind = match kind {
                    Extreme::Max => "max",
                    Extreme::Min => "min",
                    Extreme::MaxAbs => "max_abs",
                };
                let of = match of {
                    Of::Position(i) => part(&Part::Position(*i)),
                    Of::Velocity(i) => part(&Part::Velocity(*i)),
                    Of::Multiplier(a) => format!("mu_{}", a + 1),
                    Of::Residual => "residual".to_string(),
                    Of::Balance => "balance".to_string(),
                };
                format!("{kind}.{of}")
            }
            Quantity::Derivative { of, seed } => {
                let param = scene
                    .sensitivities
                    .as_ref()
                    .and_then(|s| s.parameters.get(*seed))
                    .map_or("?", String::as_str);
                format!("d({})/d({param})", of.name(scene))
            }
        }
    }
}

/// The unit of coordinate `i` and of its velocity, as the scene declares them (`[model] units`).
pub(super) fn state_units(scene: &Scene, i: usize) -> (Option<String>, Option<String>) {
    let u = &scene.units;
    let position = u.coordinates.get(i).cloned().flatten();
    let velocity = crate::output::per_time(position.as_deref(), u.time.as_deref(), 1);
    (position, velocity)
}

impl Quantity {
    /// The quantity's unit, from the scene's declared units (`[model] units`): a time's, a
    /// coordinate's, a velocity's (the coordinate's per the time's), a multiplier's, the energy's;
    /// `None` where none is declared, and for counts, residuals and derivatives.
    pub fn unit(&self, scene: &Scene) -> Option<String> {
        let u = &scene.units;
        let part = |p: &Part| match p {
            Part::Time => u.time.clone(),
            Part::Position(i) => state_units(scene, *i).0,
            Part::Velocity(i) => state_units(scene, *i).1,
        };
        match self {
            Quantity::Event { part: p, .. } | Quantity::End(p) | Quantity::At { part: p, .. } => {
                part(p)
            }
            Quantity::Extreme { of, .. } => match of {
                Of::Position(i) => part(&Part::Position(*i)),
                Of::Velocity(i) => part(&Part::Velocity(*i)),
                Of::Multiplier(a) => u.multipliers.get(*a).cloned().flatten(),
                Of::Balance => u.energy.clone(),
                Of::Residual => None,
            },
            Quantity::EventCount { .. } | Quantity::Derivative { .. } => None,
        }
    }
}

/// The names of the coordinates and their velocities: `x`, `x_dot`, `y`, `y_dot`, ...
pub(super) fn names(scene: &Scene) -> Vec<String> {
    scene
        .coordinates
        .iter()
        .flat_map(|c| [c.clone(), format!("{c}_dot")])
        .collect()
}

fn unknown(text: &str, scene: &Scene) -> String {
    let events: Vec<&str> = scene.events.iter().map(|e| e.name.as_str()).collect();
    format!(
        "`{text}` is not a quantity of this scene: write <event>.t, <event>.<coordinate>, \
         <event>.count (events: {}), end.t, end.<coordinate>, <coordinate>@<time>, \
         max.<coordinate>, min.<coordinate>, max_abs.mu_<a>, max.residual, max_abs.balance or \
         d(<event or end quantity>)/d(<parameter>); the coordinates and velocities are {}",
        if events.is_empty() {
            "none".to_string()
        } else {
            events.join(", ")
        },
        names(scene).join(", ")
    )
}

fn state_part(s: &str, scene: &Scene) -> Option<Part> {
    if s == "t" {
        return Some(Part::Time);
    }
    if let Some(i) = scene.coordinates.iter().position(|c| c == s) {
        return Some(Part::Position(i));
    }
    let base = s.strip_suffix("_dot")?;
    scene
        .coordinates
        .iter()
        .position(|c| c == base)
        .map(Part::Velocity)
}

/// What the quantities need recorded.
struct Needs {
    steps: bool,
    times: Vec<f64>,
    record: Record,
    sensitivities: bool,
}

fn needs(quantities: &[Quantity]) -> Needs {
    let mut n = Needs {
        steps: false,
        times: Vec::new(),
        record: Record::State,
        sensitivities: false,
    };
    for q in quantities {
        match q {
            Quantity::At { t, .. } => n.times.push(*t),
            Quantity::Extreme { of, .. } => {
                n.steps = true;
                let level = match of {
                    Of::Position(_) | Of::Velocity(_) => Record::State,
                    Of::Multiplier(_) | Of::Residual => Record::Dynamics,
                    Of::Balance => Record::Energy,
                };
                n.record = n.record.max(level);
            }
            Quantity::Derivative { .. } => n.sensitivities = true,
            _ => {}
        }
    }
    n
}

/// Solves `scene` recording only what `quantities` need, and collects them into row `index`.
pub(super) fn run(scene: &Scene, quantities: &[Quantity], index: usize, values: Vec<f64>) -> Row {
    let problem = match scene
        .problem()
        .and_then(|p| scene.check_at_start().map(|()| p))
    {
        Ok(p) => p,
        Err(e) => return Row::refused(index, values, quantities.len(), &e),
    };
    let need = needs(quantities);
    let mut base = scene.options(scene.solve.t_end);
    if !need.sensitivities {
        base.sensitivities.clear();
    }
    let method = scene.solve.method;
    let main = if need.steps {
        base.clone().record(need.record)
    } else if !need.times.is_empty() {
        base.clone()
            .output_times(need.times.clone())
            .record(Record::State)
    } else {
        base.clone().output_final().record(Record::State)
    };
    let sol = match solve(&problem, method, &main) {
        Ok(s) => s,
        Err(e) => return Row::refused(index, values, quantities.len(), &scene.setup_error(e)),
    };
    // Values at given times come from a second run with dense output there, when the first
    // recorded every step for the extremes.
    let at = if need.steps && !need.times.is_empty() {
        let mut o = base.output_times(need.times.clone()).record(Record::State);
        o.sensitivities.clear();
        solve(&problem, method, &o).ok()
    } else {
        None
    };
    let at_sol = at.as_ref().unwrap_or(&sol);
    let balance = if need.record == Record::Energy {
        sol.energy_balance()
    } else {
        Vec::new()
    };
    let out = quantities
        .iter()
        .map(|q| value(q, &sol, at_sol, &balance))
        .collect();
    let (status, reason) = match &sol.status {
        Status::Success => (RunStatus::Completed, String::new()),
        Status::Terminated { event } => (
            RunStatus::Terminated(
                scene
                    .events
                    .get(*event)
                    .map_or_else(|| format!("event {event}"), |e| e.name.clone()),
            ),
            String::new(),
        ),
        Status::Failed(e) => (RunStatus::Failed, scene.setup_error(e.clone()).message()),
    };
    Row {
        index,
        values,
        status,
        reason,
        quantities: out,
        steps: sol.stats.accepted_steps,
        rhs_evaluations: sol.stats.rhs_evaluations,
    }
}

fn part_of(part: Part, t: f64, q: &[f64], qd: &[f64]) -> f64 {
    match part {
        Part::Time => t,
        Part::Position(i) => q.get(i).copied().unwrap_or(f64::NAN),
        Part::Velocity(i) => qd.get(i).copied().unwrap_or(f64::NAN),
    }
}

fn value(q: &Quantity, sol: &Solution, at: &Solution, balance: &[f64]) -> f64 {
    match q {
        Quantity::Event { event, part } => sol
            .events
            .iter()
            .find(|h| h.index == *event)
            .map_or(f64::NAN, |h| part_of(*part, h.t, &h.q, &h.qd)),
        Quantity::EventCount { event } => {
            sol.events.iter().filter(|h| h.index == *event).count() as f64
        }
        Quantity::End(part) => sol
            .last()
            .map_or(f64::NAN, |(t, q, qd)| part_of(*part, t, q, qd)),
        Quantity::At { t, part } => {
            at.t.iter()
                .position(|x| x == t)
                .map_or(f64::NAN, |i| part_of(*part, at.t[i], &at.q[i], &at.qd[i]))
        }
        Quantity::Extreme { kind, of } => {
            let series: Vec<f64> = match of {
                Of::Position(i) => sol.q.component(*i).collect(),
                Of::Velocity(i) => sol.qd.component(*i).collect(),
                Of::Multiplier(a) => sol.mu.component(*a).collect(),
                Of::Residual => sol
                    .residual
                    .iter()
                    .map(|r| r.iter().fold(0.0f64, |m, x| m.max(x.abs())))
                    .collect(),
                Of::Balance => balance.to_vec(),
            };
            extreme(*kind, &series)
        }
        Quantity::Derivative { of, seed } => {
            let Some(s) = &sol.sensitivities else {
                return f64::NAN;
            };
            match of.as_ref() {
                Quantity::Event { event, part } => {
                    let Some(hit) = sol.events.iter().position(|h| h.index == *event) else {
                        return f64::NAN;
                    };
                    match s.events.get(hit) {
                        Some(Some(e)) => event_part(e, *part, *seed),
                        _ => f64::NAN,
                    }
                }
                Quantity::End(part) => {
                    // A run ended by a terminal event ends where the event is: its end moves as
                    // the event does (the total derivative d q(T)/dθ).
                    if let (Status::Terminated { event }, Some(hit)) =
                        (&sol.status, sol.events.last())
                    {
                        if hit.index == *event {
                            return match s.events.last() {
                                Some(Some(e)) => event_part(e, *part, *seed),
                                _ => f64::NAN,
                            };
                        }
                    }
                    let Some(last) = sol.t.len().checked_sub(1) else {
                        return f64::NAN;
                    };
                    match part {
                        // A fixed end time does not move.
                        Part::Time => 0.0,
                        Part::Position(i) => s.q(last, *seed).get(*i).copied().unwrap_or(f64::NAN),
                        Part::Velocity(i) => s.qd(last, *seed).get(*i).copied().unwrap_or(f64::NAN),
                    }
                }
                _ => f64::NAN,
            }
        }
    }
}

/// A part of an event's sensitivity for one seed.
fn event_part(e: &chetaev::EventSensitivity, part: Part, seed: usize) -> f64 {
    let of = |v: &[Vec<f64>], i: usize| v.get(seed).and_then(|x| x.get(i)).copied();
    match part {
        Part::Time => e.t.get(seed).copied(),
        Part::Position(i) => of(&e.q, i),
        Part::Velocity(i) => of(&e.qd, i),
    }
    .unwrap_or(f64::NAN)
}

fn extreme(kind: Extreme, series: &[f64]) -> f64 {
    if series.is_empty() {
        return f64::NAN;
    }
    match kind {
        Extreme::Max => series.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        Extreme::Min => series.iter().copied().fold(f64::INFINITY, f64::min),
        Extreme::MaxAbs => series.iter().fold(0.0f64, |m, x| m.max(x.abs())),
    }
}
