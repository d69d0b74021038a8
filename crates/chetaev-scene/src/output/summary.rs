//! The summary a run prints, a failure told in the scene's terms, and the values that are not
//! finite.

use std::fmt::Write as _;

use chetaev::prelude::{Atol, Status};
use chetaev::Singularity;

use super::picture::per_time;
use super::{balance_text, quantity_values, summary_number as num, writes_quantities};
use crate::run::Outcome;
use chetaev::integrate::Method;

use crate::scene::{Scene, Table};

/// `n` and the noun in the number that goes with it: `count(1, "step", "steps")` is "1 step".
pub fn count(n: usize, one: &str, many: &str) -> String {
    format!("{n} {}", if n == 1 { one } else { many })
}

/// A failed integration told in the scene's terms: where, what, and what to change in the file.
#[derive(Clone, Debug, PartialEq)]
pub struct Failure {
    /// The time of the failure, as the error reports it (not the last output time).
    pub t: Option<f64>,
    /// What happened.
    pub what: String,
    /// What to change in the scene file, by its keys.
    pub advice: String,
}

/// `x = 1, y = 2, x_dot = 3, y_dot = 4`, or as much of it as the vectors hold.
/// Each value carries the unit the scene declares for it (`x = 1 m, x_dot = 3 m/s`).
pub(crate) fn state_text(scene: &Scene, q: &[f64], qd: &[f64]) -> String {
    let c = &scene.coordinates;
    let units = &scene.units;
    let unit = |i: usize| units.coordinates.get(i).cloned().flatten();
    c.iter()
        .zip(q)
        .enumerate()
        .map(|(i, (c, v))| format!("{c} = {}", with_unit(*v, unit(i).as_deref())))
        .chain(c.iter().zip(qd).enumerate().map(|(i, (c, v))| {
            let rate = per_time(unit(i).as_deref(), units.time.as_deref(), 1);
            format!("{c}_dot = {}", with_unit(*v, rate.as_deref()))
        }))
        .collect::<Vec<_>>()
        .join(", ")
}

/// A value as the summary writes it, followed by its unit where one is declared and not empty.
fn with_unit(v: f64, unit: Option<&str>) -> String {
    match unit {
        Some(u) if !u.is_empty() => format!("{} {u}", num(v)),
        _ => num(v),
    }
}

/// A time as the summary writes it, with the scene's unit of time.
fn time(scene: &Scene, t: f64) -> String {
    with_unit(t, scene.units.time.as_deref())
}

/// The step a fixed-step method takes, `step = 0.01`, or `max_step = 0.005, below step = 0.01`
/// where `max_step` caps it; `None` for an adaptive method.
fn fixed_step_text(scene: &Scene) -> Option<String> {
    let h = scene.solve.method.info().fixed_step?;
    Some(match scene.solve.max_step.filter(|&m| m < h) {
        Some(m) => format!("max_step = {}, below step = {}", num(m), num(h)),
        None => format!("step = {}", num(h)),
    })
}

/// The method key for the advice: `method = "dop853"`.
fn method_key(scene: &Scene) -> String {
    format!("method = \"{}\"", scene.solve.method.name().to_lowercase())
}

/// The failure `e` of a scene's integration, with its own time and advice by the scene's keys.
pub fn failure(scene: &Scene, e: &chetaev::Error) -> Failure {
    use chetaev::Error as E;
    let stiff =
        "if the steps shrank because the problem is stiff, set method = \"rodas4\" under [solve]";
    match e {
        E::MaxSteps {
            t,
            max_steps,
            stalled: true,
            ..
        } => Failure {
            t: Some(*t),
            what: format!(
                "the step limit of {max_steps} steps was reached, the second half of them \
                 advancing t by less than a thousandth of what the first half did"
            ),
            advice: format!(
                "the motion changes ever faster here. At a kink of an expression (abs or sqrt at \
                 zero), a singular point or a blow-up the steps shrink to nothing and more steps \
                 will not pass it: check the expressions near this state. In a fast but regular \
                 phase (a close passage of an orbit) raise max_steps under [solve] (now \
                 {max_steps})"
            ),
        },
        E::MaxSteps { t, max_steps, .. } => Failure {
            t: Some(*t),
            what: format!("the step limit of {max_steps} steps was reached"),
            advice: match fixed_step_text(scene) {
                Some(step) => format!(
                    "raise max_steps under [solve] (now {max_steps}), or take a larger step (now \
                     {step}); or choose an adaptive method ({}), which takes the steps the \
                     tolerances need",
                    crate::scene::adaptive_methods()
                ),
                None => format!(
                    "raise max_steps under [solve] (now {max_steps}), or loosen rtol and atol; {stiff}"
                ),
            },
        },
        E::Stiff { t, h_lambda, .. } => Failure {
            t: Some(*t),
            what: format!(
                "the problem became stiff: {} holds h·|λ| ≈ {h_lambda:.2} at its stability boundary, step after step",
                scene.solve.method.name()
            ),
            advice: format!(
                "set method = \"rodas4\" under [solve] (implicit, made for stiff problems); or keep \
                 {} with stiffness_detection = false, which goes on with many small steps",
                method_key(scene)
            ),
        },
        E::StepSizeTooSmall { t, h, .. } => Failure {
            t: Some(*t),
            what: format!(
                "the step size fell to {h:.2e}, below what floating point resolves: the motion changes \
                 faster than rtol and atol allow"
            ),
            advice: format!(
                "check the expressions near this time for a singularity (a division by a vanishing \
                 coordinate, a speed constraint at zero speed); {stiff}; or loosen rtol and atol"
            ),
        },
        E::NonFiniteEvaluation { t, q, qd } => Failure {
            t: Some(*t),
            what: match scene.non_finite_part(*t, q, qd) {
                Some(part) => format!("{} at {}", part.what, state_text(scene, q, qd)),
                None => format!(
                    "the lagrangian or a constraint, or a derivative of one, is not finite at {}",
                    state_text(scene, q, qd)
                ),
            },
            advice: "an expression left its domain there (sqrt or ln of a negative number, a \
                     division by zero, an overflow): check the expressions at this state, or stop \
                     the motion before it with a terminal [[events]] entry"
                .to_string(),
        },
        E::Singular {
            t, pivot_ratio, q, qd,
        } => Failure {
            t: Some(*t),
            what: format!(
                "the equations for the accelerations and multipliers are singular (pivot ratio \
                 {pivot_ratio:e}) at {}",
                state_text(scene, q, qd)
            ),
            advice: "two constraints have become dependent, a constraint on a speed has met a zero \
                     velocity, or a coordinate has no kinetic term in the lagrangian there: check the \
                     constraints and the lagrangian at this state"
                .to_string(),
        },
        E::DegenerateConstraint { t, index, q, qd } => Failure {
            t: Some(*t),
            what: format!(
                "{} no longer restricts the velocity at {}: {}",
                scene.constraint_name(*index),
                state_text(scene, q, qd),
                scene.why_degenerate(*index)
            ),
            advice: "check that constraint at this state".to_string(),
        },
        E::SingularPoint {
            t,
            cause,
            ratio,
            q,
            qd,
        } => Failure {
            t: Some(*t),
            what: format!(
                "singular point: {} (the last state checked, at or after t: {})",
                match cause {
                    Singularity::Gradient(a) => format!(
                        "the derivative by the velocities of {} passes through zero, down to \
                         {ratio:e} times its size at the ends of the step",
                        scene.constraint_name(*a)
                    ),
                    Singularity::DependentGradients => format!(
                        "the derivatives by the velocities of the constraints become linearly \
                         dependent (the frame they span reverses its orientation within one step, \
                         each of them leaving that span by at most {ratio:e} of its size)"
                    ),
                    Singularity::Metric => format!(
                        "the kinetic metric ∂²L/∂q̇² of the lagrangian changed size by a factor \
                         {ratio:e} within one step"
                    ),
                    Singularity::BlockSystem => format!(
                        "the kinetic metric ∂²L/∂q̇² of the lagrangian, on the constraints' \
                         tangent space, passed through zero within one step (the determinant of \
                         the block system changed sign; the metric's size changed by a factor \
                         {ratio:e})"
                    ),
                    Singularity::Unbounded(a) => format!(
                        "the derivative of {} grew without bound after the motion met the edge \
                         of the expressions' domain, and the velocity left the constraint there, \
                         missing it by {ratio:.2} of its terms: the constraint ends there, as \
                         the curve y = -sqrt(1 - x^2) does at x = ±1",
                        scene.constraint_name(*a)
                    ),
                    other => format!("{other:?}, ratio {ratio:e}"),
                },
                state_text(scene, q, qd)
            ),
            advice: "the equations do not determine the motion there (a rank loss, such as the \
                     speed passing through zero under a constraint on its magnitude, or a pole of \
                     the model; or a computed state drifted off the constraints, which tighter \
                     tolerances or `projection = true` under [solve] prevent); the motion up to \
                     the last step before t is kept: check the expressions near this state, or \
                     stop the motion before it with a terminal [[events]] entry"
                .to_string(),
        },
        E::ProjectionFailed {
            t,
            residual,
            iterations,
        } => Failure {
            t: Some(*t),
            what: format!(
                "the projection onto f = 0 (projection = true) did not converge: residual \
                 {residual:e} after {}",
                count(*iterations, "iteration", "iterations")
            ),
            advice: "tighten rtol and atol under [solve] so that the steps stay near the \
                     constraints, or set projection = false"
                .to_string(),
        },
        E::NonFiniteEvent {
            index, t, value, ..
        } => Failure {
            t: Some(*t),
            what: format!(
                "the event '{}' is {value}",
                scene.events.get(*index).map_or("?", |e| e.name.as_str())
            ),
            advice: "check the event's expression for its domain along the motion".to_string(),
        },
        other => Failure {
            t: None,
            what: other.to_string(),
            advice: String::new(),
        },
    }
}

/// How the integration ended, in one line: "reached t_end = 10", "stopped by the terminal event
/// 'impact' at t = 1.08", "FAILED at t = 0.3: ...".
pub fn status_text(scene: &Scene, out: &Outcome) -> String {
    let end = out.t.last().copied().unwrap_or(scene.t0);
    match &out.status {
        Status::Success => format!("reached t_end = {}", time(scene, end)),
        Status::Terminated { event } => format!(
            "stopped by the terminal event '{}' at t = {}",
            scene.events.get(*event).map_or("?", |e| e.name.as_str()),
            time(scene, end)
        ),
        Status::Failed(e) => {
            let f = failure(scene, e);
            match f.t {
                Some(t) => format!("FAILED at t = {}: {}", time(scene, t), f.what),
                None => format!(
                    "FAILED after the last output time t = {}: {}",
                    time(scene, end),
                    f.what
                ),
            }
        }
    }
}

/// Values of a run that are not finite: what, at how many output points (or events), of how many.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct NonFinite {
    /// What holds them: "the state", "the quantity 'speed'", ...
    pub what: String,
    /// At how many output points.
    pub count: usize,
    /// Of how many.
    pub of: usize,
}

/// Every recorded value that is NaN or infinite, and every output quantity written that is: rows
/// the tables and pictures would hold as `NaN` or `inf`. Empty for a clean run.
pub fn non_finite(scene: &Scene, out: &Outcome) -> Vec<NonFinite> {
    let mut found = Vec::new();
    let total = out.t.len();
    let mut check = |what: String, bad: usize, of: usize| {
        if bad > 0 {
            found.push(NonFinite {
                what,
                count: bad,
                of,
            });
        }
    };
    let rows = |r: &chetaev::solution::Series| {
        r.iter()
            .filter(|r| r.iter().any(|v| !v.is_finite()))
            .count()
    };
    let state_rows = (0..total)
        .filter(|&i| {
            !out.t[i].is_finite()
                || out
                    .q
                    .get(i)
                    .is_some_and(|r| r.iter().any(|v| !v.is_finite()))
                || out
                    .qd
                    .get(i)
                    .is_some_and(|r| r.iter().any(|v| !v.is_finite()))
        })
        .count();
    check("the time or state (t, q, q_dot)".into(), state_rows, total);
    check("the accelerations".into(), rows(&out.qdd), out.qdd.len());
    check("the multipliers".into(), rows(&out.mu), out.mu.len());
    check("the Chetaev force".into(), rows(&out.phi), out.phi.len());
    check(
        "the constraint residual".into(),
        rows(&out.residual),
        out.residual.len(),
    );
    let energy_rows = (0..out.energy.len())
        .filter(|&i| {
            [&out.energy, &out.work, &out.dl_dt_integral, &out.balance]
                .iter()
                .any(|c| c.get(i).is_some_and(|v| !v.is_finite()))
        })
        .count();
    check("the energy balance".into(), energy_rows, out.energy.len());
    let events = out
        .events
        .iter()
        .filter(|e| !e.t.is_finite() || e.q.iter().chain(&e.qd).any(|v| !v.is_finite()))
        .count();
    check("the located events".into(), events, out.events.len());
    if let Some(sens) = &out.sensitivities {
        let bad = rows(&sens.values);
        check("the sensitivities".into(), bad, sens.values.len());
        let moved = sens
            .events
            .iter()
            .flatten()
            .filter(|e| {
                e.t.iter()
                    .chain(e.q.iter().flatten())
                    .chain(e.qd.iter().flatten())
                    .any(|v| !v.is_finite())
            })
            .count();
        check(
            "the sensitivities of the events".into(),
            moved,
            out.events.len(),
        );
    }
    if writes_quantities(scene) {
        for (name, e) in &scene.output.quantities {
            let bad = quantity_values(e, out).filter(|v| !v.is_finite()).count();
            check(format!("the quantity '{name}'"), bad, total);
        }
    }
    found
}

/// The largest `|v|`, NaN if any `v` is NaN: a summary never hides a NaN.
fn max_abs<'a>(values: impl IntoIterator<Item = &'a f64>) -> Option<f64> {
    values.into_iter().fold(None, |m, v| {
        let a = v.abs();
        Some(match m {
            None => a,
            Some(m) if m.is_nan() || a.is_nan() => f64::NAN,
            Some(m) => m.max(a),
        })
    })
}

/// `K` as the summary states it: "0 (unconstrained)", "2 constraints" when all are velocity
/// constraints, "1 constraint (holonomic)", "3 constraints (2 velocity, 1 holonomic)".
fn constraint_count(velocity: usize, holonomic: usize) -> String {
    let k = velocity + holonomic;
    match (velocity, holonomic) {
        (0, 0) => "0 (unconstrained)".to_string(),
        (_, 0) => count(k, "constraint", "constraints"),
        (0, _) => format!("{} (holonomic)", count(k, "constraint", "constraints")),
        _ => format!(
            "{} ({velocity} velocity, {holonomic} holonomic)",
            count(k, "constraint", "constraints")
        ),
    }
}

/// The summary a run prints: the scene, the method, the initial velocity if it was projected, why
/// it stopped (and what to change if it failed), the events with their state, the work done, the
/// largest residual and energy balance, and every value that is not finite.
pub fn summary(scene: &Scene, out: &Outcome) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "{} ({})", scene.name, scene.file.path);
    let k = scene.k();
    let _ = writeln!(
        s,
        "  model    N = {} ({}), K = {}",
        scene.n(),
        scene.coordinates.join(", "),
        constraint_count(scene.constraints.len(), scene.holonomic.len())
    );
    let tol = match &scene.solve.atol {
        Atol::Scalar(a) => format!("atol = {a:e}"),
        Atol::PerComponent(_) => "atol per component".to_string(),
    };
    let info = scene.solve.method.info();
    let method = match fixed_step_text(scene) {
        Some(step) => format!("{}, {step}", info.name),
        None => format!("{}, rtol = {:e}, {tol}", info.name, scene.solve.rtol),
    };
    let _ = writeln!(
        s,
        "  method   {method}; t from {} to {}",
        num(scene.t0),
        time(scene, scene.solve.t_end)
    );
    if scene.project_velocity && k > 0 {
        let _ = writeln!(s, "  initial  {}", projection_text(scene, out));
    }
    let _ = writeln!(s, "  status   {}", status_text(scene, out));
    if let Status::Failed(e) = &out.status {
        let f = failure(scene, e);
        if !f.advice.is_empty() {
            let _ = writeln!(s, "  advice   {}", f.advice);
        }
    }
    for w in &out.warnings {
        let _ = writeln!(s, "  warning  {w}");
    }
    for line in event_lines(scene, out) {
        let _ = writeln!(s, "{line}");
    }
    if let Some(lines) = sensitivity_text(scene, out) {
        for (i, l) in lines.iter().enumerate() {
            let label = if i == 0 { "d/dp" } else { "" };
            let _ = writeln!(s, "  {label:<8} {l}");
        }
    }
    let st = &out.stats;
    let mut work = format!(
        "{} and {}, {}",
        count(st.accepted_steps, "accepted step", "accepted steps"),
        count(st.rejected_steps, "rejected step", "rejected steps"),
        count(st.rhs_evaluations, "right-hand side", "right-hand sides")
    );
    if st.jacobian_evaluations > 0 {
        let _ = write!(
            work,
            ", {}, {}",
            count(st.jacobian_evaluations, "Jacobian", "Jacobians"),
            count(
                st.lu_decompositions,
                "LU decomposition",
                "LU decompositions"
            )
        );
    }
    if st.event_evaluations > 0 {
        let _ = write!(
            work,
            ", {}",
            count(
                st.event_evaluations,
                "event evaluation",
                "event evaluations"
            )
        );
    }
    if st.projections > 0 {
        let _ = write!(
            work,
            ", {} ({})",
            count(st.projections, "projection", "projections"),
            count(st.projection_iterations, "iteration", "iterations")
        );
    }
    if out.passes > 1 {
        let _ = write!(
            work,
            "; {} integrations (the first finds where the motion ends)",
            out.passes
        );
    }
    let _ = writeln!(s, "  stats    {work}");
    if k > 0 {
        if let Some(max) = max_abs(out.residual.iter().flatten()) {
            let _ = write!(
                s,
                "  residual max |f| = {} over {}",
                num(max),
                count(out.residual.len(), "output point", "output points")
            );
            // |f| against the velocity terms of each velocity constraint
            // (Solution::relative_residual), and the holonomic constraints' own residual h.
            if !scene.constraints.is_empty() {
                if let Some(r) = out.max_relative_residual() {
                    let _ = write!(s, "; against their velocity terms at most {}", num(r));
                }
            }
            if let Some(h) = max_abs(out.position_residual.iter().flatten()) {
                let _ = write!(s, "; max |h| = {}", num(h));
            }
            let _ = writeln!(s);
        }
    }
    if let Some(b) = max_abs(&out.balance) {
        let _ = writeln!(
            s,
            "  energy   max |{}| = {}",
            balance_text(scene),
            with_unit(b, scene.units.energy.as_deref())
        );
    }
    for bad in non_finite(scene, out) {
        let _ = writeln!(
            s,
            "  error    {} is NaN or infinite at {} of {} (written as NaN or inf); check the \
             expressions' domains",
            bad.what,
            bad.count,
            count(bad.of, "output point", "output points")
        );
    }
    s
}

/// The most located events the summary lists one by one; past it, each event is summarised by
/// how often it was located and its first and last occurrence, at most this many events.
pub const EVENTS_LISTED: usize = 10;

/// The indices into `out.events` the summary shows: all of them up to [`EVENTS_LISTED`]; past it,
/// the first and the last occurrence of each event (of the first [`EVENTS_LISTED`] events
/// located), by event in the order of the scene, with how many times it was located.
fn shown_events(scene: &Scene, out: &Outcome) -> Option<Vec<(usize, usize, Option<usize>)>> {
    if out.events.len() <= EVENTS_LISTED {
        return None;
    }
    // (count, first, last) per event of the scene.
    let mut per: Vec<(usize, usize, usize)> = vec![(0, 0, 0); scene.events.len()];
    for (i, e) in out.events.iter().enumerate() {
        if let Some(p) = per.get_mut(e.index) {
            if p.0 == 0 {
                p.1 = i;
            }
            p.0 += 1;
            p.2 = i;
        }
    }
    Some(
        per.into_iter()
            .filter(|p| p.0 > 0)
            .map(|(n, first, last)| (n, first, (n > 1).then_some(last)))
            .collect(),
    )
}

/// The summary's lines on the located events: each one, or past [`EVENTS_LISTED`] of them, per
/// event how many and the first and last, and where they are all written.
fn event_lines(scene: &Scene, out: &Outcome) -> Vec<String> {
    if out.events.is_empty() {
        return if scene.events.is_empty() {
            Vec::new()
        } else {
            vec!["  events   none located".to_string()]
        };
    }
    let width = out.event_name_width();
    let state = |i: usize| {
        let e = &out.events[i];
        format!(
            "t = {}, {}",
            time(scene, e.t),
            state_text(scene, &e.q, &e.qd)
        )
    };
    let Some(shown) = shown_events(scene, out) else {
        return out
            .events
            .iter()
            .enumerate()
            .map(|(i, e)| {
                let label = if i == 0 { "events" } else { "" };
                format!(
                    "  {label:<8} {:<width$}  {}",
                    out.event_name(e.index),
                    state(i)
                )
            })
            .collect();
    };
    let name = Table::Events.name();
    let table = if scene.output.tables.contains(&Table::Events) {
        format!("all of them are in {name}.csv")
    } else {
        format!("add \"{name}\" to tables under [output] to write them all to {name}.csv")
    };
    let mut lines = vec![format!(
        "  events   {} located; of each event, how many, the first and the last ({table}):",
        out.events.len()
    )];
    for &(n, first, last) in shown.iter().take(EVENTS_LISTED) {
        let name = out.event_name(out.events[first].index);
        let times = count(n, "time", "times");
        lines.push(format!("           {name:<width$}  {times}"));
        match last {
            Some(last) => {
                lines.push(format!(
                    "           {:<width$}    first {}",
                    "",
                    state(first)
                ));
                lines.push(format!(
                    "           {:<width$}    last  {}",
                    "",
                    state(last)
                ));
            }
            None => lines.push(format!("           {:<width$}    at {}", "", state(first))),
        }
    }
    if shown.len() > EVENTS_LISTED {
        let rest = &shown[EVENTS_LISTED..];
        let located: usize = rest.iter().map(|s| s.0).sum();
        lines.push(format!(
            "           and {} more, located {}",
            count(rest.len(), "event", "events"),
            count(located, "time", "times")
        ));
    }
    lines
}

/// The summary's lines on the sensitivities: for each located event, how its time moves with each
/// parameter (`impact  dT/dv0 = 0.108, dT/dg = -0.054`); without events, the parameters and the
/// number of output points. `None` without `[sensitivities]`.
fn sensitivity_text(scene: &Scene, out: &Outcome) -> Option<Vec<String>> {
    let spec = scene.sensitivities.as_ref()?;
    let sens = out.sensitivities.as_ref()?;
    if out.events.is_empty() {
        return Some(vec![format!(
            "with respect to {} at {}{}",
            spec.parameters.join(", "),
            count(sens.values.len(), "output point", "output points"),
            if spec.control {
                ", under error control"
            } else {
                ""
            }
        )]);
    }
    // Past EVENTS_LISTED, the first and the last occurrence of each event, as the events lines.
    let listed: Vec<(usize, &str)> = match shown_events(scene, out) {
        None => (0..out.events.len()).map(|i| (i, "")).collect(),
        Some(shown) => shown
            .iter()
            .take(EVENTS_LISTED)
            .flat_map(|&(_, first, last)| match last {
                Some(last) => vec![(first, " (first)"), (last, " (last)")],
                None => vec![(first, "")],
            })
            .collect(),
    };
    let label = |i: usize, which: &str| format!("{}{which}", out.event_name(out.events[i].index));
    let width = listed
        .iter()
        .map(|&(i, which)| label(i, which).chars().count())
        .max()
        .unwrap_or(0);
    let lines = listed
        .iter()
        .map(|&(i, which)| {
            let text = match sens.events.get(i).and_then(Option::as_ref) {
                Some(d) => spec
                    .parameters
                    .iter()
                    .zip(&d.t)
                    .map(|(p, dt)| format!("dT/d{p} = {}", num(*dt)))
                    .collect::<Vec<_>>()
                    .join(", "),
                None => {
                    "T is not differentiable here (the event is crossed tangentially)".to_string()
                }
            };
            format!("{:<width$}  {text}", label(i, which))
        })
        .collect();
    Some(lines)
}

/// What `project_velocity = true` changed in the initial state, coordinate by coordinate, by how
/// much: "q_dot projected onto f = 0 (project_velocity = true): x_dot 10 → 9.95 (-0.0496), ...";
/// with holonomic constraints, "q projected onto h = 0 and q_dot onto ḣ = 0 (...): y 0.1 → 0
/// (-0.1), ..."; or that it changed nothing.
fn projection_text(scene: &Scene, out: &Outcome) -> String {
    let holonomic = !scene.holonomic.is_empty();
    let velocity = match (scene.constraints.is_empty(), holonomic) {
        (false, true) => "f = 0 and ḣ = 0",
        (true, true) => "ḣ = 0",
        _ => "f = 0",
    };
    let at_start = out.t.first() == Some(&scene.t0);
    let (Some(q), Some(qd)) = (
        out.q.first().filter(|_| at_start),
        out.qd.first().filter(|_| at_start),
    ) else {
        return if holonomic {
            format!("q projected onto h = 0 and q_dot onto {velocity} (project_velocity = true)")
        } else {
            format!("q_dot projected onto {velocity} (project_velocity = true)")
        };
    };
    let change = |name: String, a: f64, b: f64| {
        let d = b - a;
        let sign = if d > 0.0 { "+" } else { "" };
        format!("{name} {} → {} ({sign}{})", num(a), num(b), num(d))
    };
    let c = &scene.coordinates;
    let moved: Vec<String> = c
        .iter()
        .zip(scene.q0.iter().zip(q))
        .filter(|(_, (a, b))| a != b)
        .map(|(c, (a, b))| change(c.clone(), *a, *b))
        .collect();
    let turned: Vec<String> = c
        .iter()
        .zip(scene.qd0.iter().zip(qd))
        .filter(|(_, (a, b))| a != b)
        .map(|(c, (a, b))| change(format!("{c}_dot"), *a, *b))
        .collect();
    let what = match (moved.is_empty(), turned.is_empty()) {
        (true, true) if holonomic => {
            return "q and q_dot satisfy the constraints as given; project_velocity = true \
                    changed nothing"
                .to_string()
        }
        (true, true) => {
            return format!(
                "q_dot satisfies {velocity} as given; project_velocity = true changed nothing"
            )
        }
        (false, false) => {
            format!("q projected onto h = 0 and q_dot onto {velocity} (project_velocity = true)")
        }
        (false, true) => format!(
            "q projected onto h = 0 (project_velocity = true; q_dot satisfies {velocity} as given)"
        ),
        (true, false) => format!("q_dot projected onto {velocity} (project_velocity = true)"),
    };
    format!(
        "{what}: {}",
        moved
            .into_iter()
            .chain(turned)
            .collect::<Vec<_>>()
            .join(", ")
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_maximum_over_a_nan_is_nan() {
        assert_eq!(max_abs(&[1.0, -3.0, 2.0]), Some(3.0));
        assert!(max_abs(&[1.0, f64::NAN, 2.0]).is_some_and(f64::is_nan));
        assert!(max_abs(&[f64::NAN, 1.0]).is_some_and(f64::is_nan));
        assert_eq!(max_abs(&[]), None);
    }

    #[test]
    fn counts_agree_with_their_nouns() {
        assert_eq!(count(1, "constraint", "constraints"), "1 constraint");
        assert_eq!(count(0, "constraint", "constraints"), "0 constraints");
        assert_eq!(constraint_count(0, 0), "0 (unconstrained)");
        assert_eq!(constraint_count(2, 0), "2 constraints");
        assert_eq!(constraint_count(0, 1), "1 constraint (holonomic)");
        assert_eq!(
            constraint_count(2, 1),
            "3 constraints (2 velocity, 1 holonomic)"
        );
        assert_eq!(
            count(2, "right-hand side", "right-hand sides"),
            "2 right-hand sides"
        );
    }
}
