//! CSV and Markdown for the study's points and comparisons.

use std::fmt::Write as _;

use crate::measure::ratio_at_error;
use crate::study::{curve, Point, PointOutcome};

/// One CSV field, quoted when it holds a comma, a quote or a line break.
pub fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// A number for CSV: shortest round-trip form, empty for NaN.
fn csv_number(x: f64) -> String {
    if x.is_nan() {
        String::new()
    } else {
        format!("{x:e}")
    }
}

/// The CSV header of [`points_csv`].
pub const CSV_HEADER: &str = "scene,method,tolerance,step,outcome,reason,error,seconds,repeats,\
rhs_evaluations,jacobian_evaluations,output_evaluations,accepted_steps,rejected_steps";

/// The points as CSV, one line each, with [`CSV_HEADER`].
pub fn points_csv(points: &[Point]) -> String {
    let mut out = String::from(CSV_HEADER);
    out.push('\n');
    for p in points {
        let (outcome, reason) = match &p.outcome {
            PointOutcome::Measured => ("measured", ""),
            PointOutcome::Skipped(r) => ("skipped", r.as_str()),
            PointOutcome::Failed(r) => ("failed", r.as_str()),
        };
        let fields = [
            csv_field(&p.scene),
            csv_field(&p.method),
            csv_number(p.tolerance),
            csv_number(p.step),
            outcome.to_string(),
            csv_field(reason),
            csv_number(p.error),
            csv_number(p.seconds),
            p.repeats.to_string(),
            p.rhs_evaluations.to_string(),
            p.jacobian_evaluations.to_string(),
            p.output_evaluations.to_string(),
            p.accepted_steps.to_string(),
            p.rejected_steps.to_string(),
        ];
        out.push_str(&fields.join(","));
        out.push('\n');
    }
    out
}

/// A duration in the unit that suits it: `850 ns`, `12.3 µs`, `4.56 ms`, `1.23 s`.
pub fn format_seconds(s: f64) -> String {
    if !s.is_finite() {
        return "–".to_string();
    }
    let (v, unit) = if s < 1e-6 {
        (s * 1e9, "ns")
    } else if s < 1e-3 {
        (s * 1e6, "µs")
    } else if s < 1.0 {
        (s * 1e3, "ms")
    } else {
        (s, "s")
    };
    if v >= 100.0 {
        format!("{v:.0} {unit}")
    } else if v >= 10.0 {
        format!("{v:.1} {unit}")
    } else {
        format!("{v:.2} {unit}")
    }
}

/// A number in short scientific notation, `–` for NaN.
pub fn format_sci(x: f64) -> String {
    if x.is_nan() {
        "–".to_string()
    } else {
        format!("{x:.1e}")
    }
}

/// A ratio with two decimals, `–` when missing.
pub fn format_ratio(r: Option<f64>) -> String {
    r.map_or("–".to_string(), |r| format!("{r:.2}"))
}

/// The points as a Markdown table: method, tolerance or step, outcome, error, median time, runs,
/// right-hand sides, Jacobians, steps (accepted + rejected), time per right-hand side.
pub fn points_markdown(points: &[Point]) -> String {
    let mut out = String::from(
        "| method | tol / h | error | median time | runs | RHS | Jacobians | steps (acc. + rej.) | time / RHS | note |\n\
         |---|---|---|---|---|---|---|---|---|---|\n",
    );
    for p in points {
        let setting = if p.tolerance.is_nan() {
            if p.step.is_nan() {
                "–".to_string()
            } else {
                format!("h = {:.2e}", p.step)
            }
        } else {
            format!("{:e}", p.tolerance)
        };
        let note = match &p.outcome {
            PointOutcome::Measured => String::new(),
            PointOutcome::Skipped(r) => format!("skipped: {}", r.replace('|', "\\|")),
            PointOutcome::Failed(r) => format!("failed: {}", r.replace('|', "\\|")),
        };
        let per_rhs = if p.is_measured() && p.rhs_evaluations > 0 {
            format_seconds(p.seconds / p.rhs_evaluations as f64)
        } else {
            "–".to_string()
        };
        let steps = if p.accepted_steps + p.rejected_steps > 0 {
            format!("{} + {}", p.accepted_steps, p.rejected_steps)
        } else {
            "–".to_string()
        };
        let rhs = if p.output_evaluations > 0 {
            format!("{} (+ {} output)", p.rhs_evaluations, p.output_evaluations)
        } else {
            p.rhs_evaluations.to_string()
        };
        let _ = writeln!(
            out,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            p.method,
            setting,
            format_sci(p.error),
            format_seconds(p.seconds),
            p.repeats,
            rhs,
            p.jacobian_evaluations,
            steps,
            per_rhs,
            note
        );
    }
    out
}

/// The ratios `time(numerator) / time(denominator)` at equal error, one row per pair of methods,
/// one column per error level, as a Markdown table.
pub fn ratio_markdown(points: &[Point], pairs: &[(&str, &str)], errors: &[f64]) -> String {
    let mut out = String::from("| time ratio at equal error |");
    for e in errors {
        let _ = write!(out, " {e:.0e} |");
    }
    out.push_str("\n|---|");
    out.push_str(&"---|".repeat(errors.len()));
    out.push('\n');
    for (a, b) in pairs {
        let (ca, cb) = (curve(points, a), curve(points, b));
        let _ = write!(out, "| {a} / {b} |");
        for &e in errors {
            let _ = write!(out, " {} |", format_ratio(ratio_at_error(&ca, &cb, e)));
        }
        out.push('\n');
    }
    out
}

/// The ratios `time(numerator) / time(denominator)` at the same tolerance asked for, one row per
/// pair of methods, one column per tolerance at which some pair was measured on both sides.
pub fn ratio_at_tolerance_markdown(points: &[Point], pairs: &[(&str, &str)]) -> String {
    let time = |method: &str, tol: f64| {
        points
            .iter()
            .find(|p| p.method == method && p.tolerance == tol && p.is_measured())
            .map(|p| p.seconds)
    };
    let mut tolerances: Vec<f64> = points
        .iter()
        .filter(|p| p.tolerance.is_finite())
        .map(|p| p.tolerance)
        .collect();
    tolerances.sort_by(|a, b| b.total_cmp(a));
    tolerances.dedup();
    tolerances.retain(|&t| {
        pairs
            .iter()
            .any(|(a, b)| time(a, t).is_some() && time(b, t).is_some())
    });
    if tolerances.is_empty() {
        return String::new();
    }
    let mut out = String::from("| time ratio at equal tolerance |");
    for t in &tolerances {
        let _ = write!(out, " {t:e} |");
    }
    out.push_str("\n|---|");
    out.push_str(&"---|".repeat(tolerances.len()));
    out.push('\n');
    for (a, b) in pairs {
        let _ = write!(out, "| {a} / {b} |");
        for &t in &tolerances {
            let r = time(a, t).zip(time(b, t)).map(|(x, y)| x / y);
            let _ = write!(out, " {} |", format_ratio(r));
        }
        out.push('\n');
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_quotes_only_what_needs_it() {
        assert_eq!(csv_field("Dopri5"), "Dopri5");
        assert_eq!(csv_field("a, b"), "\"a, b\"");
        assert_eq!(csv_field("say \"hi\""), "\"say \"\"hi\"\"\"");
    }

    #[test]
    fn durations_pick_their_unit() {
        assert_eq!(format_seconds(8.5e-7), "850 ns");
        assert_eq!(format_seconds(1.234e-5), "12.3 µs");
        assert_eq!(format_seconds(4.561e-3), "4.56 ms");
        assert_eq!(format_seconds(f64::NAN), "–");
    }
}
