//! The part files of the bench binaries' sweeps: the shared convention ([`chetaev_parts`]: shards,
//! parts, merging), and the bench's own results as JSON.

use serde_json::{json, Value};

pub use chetaev_parts::*;

use crate::ensemble::SweepPoint;
use crate::overhead::Comparison;
use crate::study::{Point, PointOutcome};

/// A point of the work-precision study as JSON.
pub fn point_to_json(p: &Point) -> Value {
    let (outcome, reason) = match &p.outcome {
        PointOutcome::Measured => ("measured", ""),
        PointOutcome::Skipped(r) => ("skipped", r.as_str()),
        PointOutcome::Failed(r) => ("failed", r.as_str()),
    };
    json!({
        "scene": p.scene,
        "method": p.method,
        "tolerance": number(p.tolerance),
        "step": number(p.step),
        "outcome": outcome,
        "reason": reason,
        "error": number(p.error),
        "seconds": number(p.seconds),
        "repeats": p.repeats,
        "rhs_evaluations": p.rhs_evaluations,
        "jacobian_evaluations": p.jacobian_evaluations,
        "output_evaluations": p.output_evaluations,
        "accepted_steps": p.accepted_steps,
        "rejected_steps": p.rejected_steps,
    })
}

/// A point written by [`point_to_json`].
pub fn point_from_json(v: &Value) -> Result<Point, PartError> {
    let f = Fields::of(v, "point")?;
    let reason = f.str("reason")?.to_string();
    let outcome = match f.str("outcome")? {
        "measured" => PointOutcome::Measured,
        "skipped" => PointOutcome::Skipped(reason),
        "failed" => PointOutcome::Failed(reason),
        other => return Err(malformed(format!("outcome `{other}`"))),
    };
    Ok(Point {
        scene: f.str("scene")?.to_string(),
        method: f.str("method")?.to_string(),
        tolerance: f.f64("tolerance")?,
        step: f.f64("step")?,
        outcome,
        error: f.f64("error")?,
        seconds: f.f64("seconds")?,
        repeats: f.usize("repeats")?,
        rhs_evaluations: f.usize("rhs_evaluations")?,
        jacobian_evaluations: f.usize("jacobian_evaluations")?,
        output_evaluations: f.usize("output_evaluations")?,
        accepted_steps: f.usize("accepted_steps")?,
        rejected_steps: f.usize("rejected_steps")?,
    })
}

/// A comparison of two ways to run a motion as JSON.
pub fn comparison_to_json(c: &Comparison) -> Value {
    json!({
        "what": c.what,
        "setting": c.setting,
        "lean_seconds": number(c.lean_seconds),
        "costly_seconds": number(c.costly_seconds),
        "lean_rhs": c.lean_rhs,
        "costly_rhs": c.costly_rhs,
        "lean_output": c.lean_output,
        "costly_output": c.costly_output,
        "end_difference": number(c.end_difference),
    })
}

/// A comparison written by [`comparison_to_json`].
pub fn comparison_from_json(v: &Value) -> Result<Comparison, PartError> {
    let f = Fields::of(v, "comparison")?;
    Ok(Comparison {
        what: f.str("what")?.to_string(),
        setting: f.str("setting")?.to_string(),
        lean_seconds: f.f64("lean_seconds")?,
        costly_seconds: f.f64("costly_seconds")?,
        lean_rhs: f.usize("lean_rhs")?,
        costly_rhs: f.usize("costly_rhs")?,
        lean_output: f.usize("lean_output")?,
        costly_output: f.usize("costly_output")?,
        end_difference: f.f64("end_difference")?,
    })
}

/// A solved point of the ensemble as JSON.
pub fn sweep_point_to_json(p: &SweepPoint) -> Value {
    json!({
        "v0": number(p.v0),
        "h0": number(p.h0),
        "z": number(p.z),
        "ratio": number(p.ratio),
        "closed_ratio": number(p.closed_ratio),
        "uniform_error": number(p.uniform_error),
        "classical_error": number(p.classical_error),
        "method": p.method,
        "steps": p.steps,
        "failure": p.failure,
    })
}

/// A point written by [`sweep_point_to_json`].
pub fn sweep_point_from_json(v: &Value) -> Result<SweepPoint, PartError> {
    let f = Fields::of(v, "ensemble point")?;
    let method = match f.str("method")? {
        "Dop853" => "Dop853",
        "Rodas4" => "Rodas4",
        other => return Err(malformed(format!("ensemble method `{other}`"))),
    };
    let failure = match f.get("failure")? {
        Value::Null => None,
        Value::String(s) => Some(s.clone()),
        _ => return Err(malformed("`failure` of an ensemble point")),
    };
    Ok(SweepPoint {
        v0: f.f64("v0")?,
        h0: f.f64("h0")?,
        z: f.f64("z")?,
        ratio: f.f64("ratio")?,
        closed_ratio: f.f64("closed_ratio")?,
        uniform_error: f.f64("uniform_error")?,
        classical_error: f.f64("classical_error")?,
        method,
        steps: f.usize("steps")?,
        failure,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(method: &str, outcome: PointOutcome) -> Point {
        Point {
            scene: "uniform".to_string(),
            method: method.to_string(),
            tolerance: 1e-8,
            step: f64::NAN,
            outcome,
            error: 3.0e-9,
            seconds: 1.2e-4,
            repeats: 7,
            rhs_evaluations: 100,
            jacobian_evaluations: 2,
            output_evaluations: 3,
            accepted_steps: 15,
            rejected_steps: 1,
        }
    }

    #[test]
    fn points_comparisons_and_sweep_points_read_back() {
        for p in [
            point("Dopri5", PointOutcome::Measured),
            point("Rk4", PointOutcome::Skipped("no, \"never\"".to_string())),
            point("Rodas4", PointOutcome::Failed("stiff at t = 1".to_string())),
        ] {
            // Debug, not ==: NaN fields print alike and compare unequal.
            let back = point_from_json(&point_to_json(&p)).expect("reads");
            assert_eq!(format!("{back:?}"), format!("{p:?}"));
        }
        let c = Comparison {
            what: "K = 0 → K = 1".to_string(),
            setting: "Dopri5 at 1e-8".to_string(),
            lean_seconds: 1e-5,
            costly_seconds: 1.3e-5,
            lean_rhs: 80,
            costly_rhs: 80,
            lean_output: 0,
            costly_output: 12,
            end_difference: 0.0,
        };
        assert_eq!(
            comparison_from_json(&comparison_to_json(&c)).expect("reads"),
            c
        );
        let s = SweepPoint {
            v0: 0.1,
            h0: 100.0,
            z: 98100.0,
            ratio: f64::NAN,
            closed_ratio: 0.005,
            uniform_error: f64::NAN,
            classical_error: f64::NAN,
            method: "Rodas4",
            steps: 42,
            failure: Some("no impact before t_max".to_string()),
        };
        let back = sweep_point_from_json(&sweep_point_to_json(&s)).expect("reads");
        assert_eq!(format!("{back:?}"), format!("{s:?}"));
    }
}
