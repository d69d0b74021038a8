//! What a run writes: CSV tables, SVG pictures, and the text of the summary.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use chetaev::prelude::Status;
use chetaev_plot::{Figure, Style};

use crate::error::Error;
use crate::expr::Env;
use crate::run::Outcome;
use crate::scene::{Picture, Scene, Table};

/// A number for a CSV file: the shortest text that reads back to the same `f64`, in plain notation
/// between `1e-5` and `1e16` and in exponent notation outside.
pub fn csv_number(v: f64) -> String {
    let a = v.abs();
    if v == 0.0 || !v.is_finite() || (1e-5..1e16).contains(&a) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// A text field for a CSV file, quoted when it holds a comma, a quote or a line break.
fn csv_text(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// A number for the summary: 13 significant digits, trailing zeros dropped.
pub fn summary_number(v: f64) -> String {
    let a = v.abs();
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    if (1e-3..1e7).contains(&a) {
        let decimals = (12 - a.log10().floor() as i32).clamp(0, 15) as usize;
        let s = format!("{v:.decimals$}");
        let s = if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        };
        return s;
    }
    let s = format!("{v:.12e}");
    match s.split_once('e') {
        Some((m, e)) if m.contains('.') => {
            format!("{}e{e}", m.trim_end_matches('0').trim_end_matches('.'))
        }
        _ => s,
    }
}

/// A table's header and its rows.
struct Csv {
    header: Vec<String>,
    rows: Vec<Vec<String>>,
}

impl Csv {
    fn text(&self) -> String {
        let mut s = self.header.join(",");
        s.push('\n');
        for r in &self.rows {
            s.push_str(&r.join(","));
            s.push('\n');
        }
        s
    }
}

fn numeric(header: Vec<String>, t: &[f64], columns: &[Vec<f64>]) -> Csv {
    let rows = (0..t.len())
        .map(|i| {
            std::iter::once(csv_number(t[i]))
                .chain(
                    columns
                        .iter()
                        .map(|c| c.get(i).copied().map_or_else(String::new, csv_number)),
                )
                .collect()
        })
        .collect();
    Csv { header, rows }
}

/// Column `j` of a list of rows.
fn column(rows: &[Vec<f64>], j: usize) -> Vec<f64> {
    rows.iter()
        .map(|r| r.get(j).copied().unwrap_or(f64::NAN))
        .collect()
}

/// The output quantities along the recorded motion, one vector per quantity.
fn quantities(scene: &Scene, out: &Outcome) -> Vec<Vec<f64>> {
    scene
        .output
        .quantities
        .iter()
        .map(|(_, e)| {
            (0..out.t.len())
                .map(|i| {
                    e.eval(&Env {
                        t: out.t[i],
                        q: &out.q[i],
                        qd: &out.qd[i],
                    })
                })
                .collect()
        })
        .collect()
}

fn table(scene: &Scene, out: &Outcome, which: Table) -> Csv {
    let c = &scene.coordinates;
    let names =
        |suffix: &str| -> Vec<String> { c.iter().map(|x| format!("{x}{suffix}")).collect() };
    let indexed = |prefix: &str| -> Vec<String> {
        (1..=scene.k()).map(|a| format!("{prefix}_{a}")).collect()
    };
    let with_t = |rest: Vec<String>| -> Vec<String> {
        std::iter::once("t".to_string()).chain(rest).collect()
    };
    let cols = |rows: &[Vec<f64>], n: usize| -> Vec<Vec<f64>> {
        (0..n).map(|j| column(rows, j)).collect()
    };
    match which {
        Table::State => {
            let mut columns = cols(&out.q, scene.n());
            columns.extend(cols(&out.qd, scene.n()));
            let mut header = names("");
            header.extend(names("_dot"));
            numeric(with_t(header), &out.t, &columns)
        }
        Table::Acceleration => numeric(with_t(names("_ddot")), &out.t, &cols(&out.qdd, scene.n())),
        Table::Multipliers => numeric(with_t(indexed("mu")), &out.t, &cols(&out.mu, scene.k())),
        Table::Force => numeric(
            with_t(c.iter().map(|x| format!("Phi_{x}")).collect()),
            &out.t,
            &cols(&out.phi, scene.n()),
        ),
        Table::Residual => numeric(
            with_t(indexed("f")),
            &out.t,
            &cols(&out.residual, scene.k()),
        ),
        Table::Energy => numeric(
            with_t(vec![
                "E".into(),
                "W_Phi".into(),
                "int_dL_dt".into(),
                "balance".into(),
            ]),
            &out.t,
            &[
                out.energy.clone(),
                out.work.clone(),
                out.dl_dt_integral.clone(),
                out.balance.clone(),
            ],
        ),
        Table::Events => {
            let mut header = vec!["event".to_string(), "t".to_string()];
            header.extend(names(""));
            header.extend(names("_dot"));
            let rows = out
                .events
                .iter()
                .map(|e| {
                    std::iter::once(csv_text(&e.name))
                        .chain(std::iter::once(csv_number(e.t)))
                        .chain(e.q.iter().chain(&e.qd).map(|v| csv_number(*v)))
                        .collect()
                })
                .collect();
            Csv { header, rows }
        }
        Table::Quantities => numeric(
            with_t(
                scene
                    .output
                    .quantities
                    .iter()
                    .map(|(n, _)| n.clone())
                    .collect(),
            ),
            &out.t,
            &quantities(scene, out),
        ),
    }
}

fn series(t: &[f64], v: &[f64]) -> Vec<(f64, f64)> {
    t.iter().copied().zip(v.iter().copied()).collect()
}

fn figure(scene: &Scene, out: &Outcome, which: Picture) -> Figure {
    let c = &scene.coordinates;
    let title = |what: &str| format!("{}: {what}", scene.name);
    let against_t = |fig: Figure, names: Vec<String>, rows: &[Vec<f64>]| -> Figure {
        names.iter().enumerate().fold(fig, |f, (j, name)| {
            f.line(name, &series(&out.t, &column(rows, j)))
        })
    };
    let k_names =
        |sym: &str| -> Vec<String> { (1..=scene.k()).map(|a| format!("{sym}_{a}")).collect() };
    match which {
        Picture::Trajectory if scene.n() >= 2 => {
            let pts: Vec<(f64, f64)> = out.q.iter().map(|q| (q[0], q[1])).collect();
            let mut f = Figure::new(&title("trajectory"))
                .x_label(&c[0])
                .y_label(&c[1])
                .equal_aspect()
                .line("", &pts);
            for e in &out.events {
                f = f.line_styled(
                    &e.name,
                    &[(e.q[0], e.q[1])],
                    Style {
                        width: 0.0,
                        markers: true,
                        ..Style::default()
                    },
                );
            }
            f
        }
        Picture::Trajectory | Picture::State => against_t(
            Figure::new(&title("coordinates")).x_label("t"),
            c.clone(),
            &out.q,
        ),
        Picture::Velocity => against_t(
            Figure::new(&title("velocities")).x_label("t"),
            c.iter().map(|x| format!("{x}_dot")).collect(),
            &out.qd,
        ),
        Picture::Acceleration => against_t(
            Figure::new(&title("accelerations")).x_label("t"),
            c.iter().map(|x| format!("{x}_ddot")).collect(),
            &out.qdd,
        ),
        Picture::Multipliers => against_t(
            Figure::new(&title("multipliers")).x_label("t").y_label("μ"),
            k_names("μ"),
            &out.mu,
        ),
        Picture::Force => against_t(
            Figure::new(&title("Chetaev force Φ = Jᵀμ")).x_label("t"),
            c.iter().map(|x| format!("Φ_{x}")).collect(),
            &out.phi,
        ),
        Picture::Residual => {
            let abs: Vec<Vec<f64>> = out
                .residual
                .iter()
                .map(|r| r.iter().map(|v| v.abs()).collect())
                .collect();
            against_t(
                Figure::new(&title("constraint residual"))
                    .x_label("t")
                    .y_label("|f|")
                    .log_y(),
                k_names("|f|"),
                &abs,
            )
        }
        Picture::Energy => {
            let e0 = out.energy.first().copied().unwrap_or(0.0);
            let de: Vec<f64> = out.energy.iter().map(|e| e - e0).collect();
            Figure::new(&title("energy balance"))
                .x_label("t")
                .line_styled(
                    "E − E(t0)",
                    &series(&out.t, &de),
                    Style {
                        width: 4.0,
                        ..Style::default()
                    },
                )
                .line(
                    "W_Φ (work of the Chetaev force)",
                    &series(&out.t, &out.work),
                )
                .line("∫∂L/∂t dt", &series(&out.t, &out.dl_dt_integral))
                .line_styled(
                    "balance E − E(t0) − W_Φ + ∫∂L/∂t dt",
                    &series(&out.t, &out.balance),
                    Style {
                        dashed: true,
                        ..Style::default()
                    },
                )
        }
        Picture::Quantities => {
            let values = quantities(scene, out);
            scene.output.quantities.iter().zip(&values).fold(
                Figure::new(&title("quantities")).x_label("t"),
                |f, ((name, _), v)| f.line(name, &series(&out.t, v)),
            )
        }
    }
}

/// Writes the tables and pictures the scene asks for into `dir` (created if missing) and returns
/// the files written.
pub fn write(scene: &Scene, out: &Outcome, dir: &Path) -> Result<Vec<PathBuf>, Error> {
    let mut written = Vec::new();
    if scene.output.tables.is_empty() && scene.output.pictures.is_empty() {
        return Ok(written);
    }
    std::fs::create_dir_all(dir).map_err(|e| Error::Write {
        path: dir.display().to_string(),
        reason: e.to_string(),
    })?;
    for &t in &scene.output.tables {
        let path = dir.join(format!("{}.csv", t.name()));
        std::fs::write(&path, table(scene, out, t).text()).map_err(|e| Error::Write {
            path: path.display().to_string(),
            reason: e.to_string(),
        })?;
        written.push(path);
    }
    for &p in &scene.output.pictures {
        let path = dir.join(format!("{}.svg", p.name()));
        figure(scene, out, p)
            .save(&path)
            .map_err(|e| Error::Write {
                path: path.display().to_string(),
                reason: e.to_string(),
            })?;
        written.push(path);
    }
    Ok(written)
}

/// The summary a run prints: the scene, the method, why it stopped, the events with their state,
/// and the work done.
pub fn summary(scene: &Scene, out: &Outcome) -> String {
    let mut s = String::new();
    let n = summary_number;
    let _ = writeln!(s, "{} ({})", scene.name, scene.file.path);
    let k = scene.k();
    let plural = |k: usize, w: &str| format!("{k} {w}{}", if k == 1 { "" } else { "s" });
    let _ = writeln!(
        s,
        "  model    N = {} ({}), K = {}",
        scene.n(),
        scene.coordinates.join(", "),
        if k == 0 {
            "0 (unconstrained)".to_string()
        } else {
            plural(k, "constraint")
        }
    );
    let tol = match &scene.solve.atol {
        chetaev::prelude::Atol::Scalar(a) => format!("atol = {a:e}"),
        chetaev::prelude::Atol::PerComponent(_) => "atol per component".to_string(),
    };
    let method = match scene.solve.method {
        crate::scene::MethodSpec::Rk4 { step } => format!("Rk4, step = {}", n(step)),
        m => format!("{}, rtol = {:e}, {tol}", m.name(), scene.solve.rtol),
    };
    let _ = writeln!(
        s,
        "  method   {method}; t from {} to {}",
        n(scene.t0),
        n(scene.solve.t_end)
    );
    let end = out.t.last().copied().unwrap_or(scene.t0);
    let status = match &out.status {
        Status::Success => format!("reached t_end = {}", n(end)),
        Status::Terminated { event } => format!(
            "stopped by the terminal event '{}' at t = {}",
            scene.events.get(*event).map_or("?", |e| e.name.as_str()),
            n(end)
        ),
        Status::Failed(e) => format!("FAILED at t = {}: {e}", n(end)),
    };
    let _ = writeln!(s, "  status   {status}");
    if out.events.is_empty() {
        if !scene.events.is_empty() {
            let _ = writeln!(s, "  events   none located");
        }
    } else {
        let width = out
            .events
            .iter()
            .map(|e| e.name.chars().count())
            .max()
            .unwrap_or(0);
        for (i, e) in out.events.iter().enumerate() {
            let label = if i == 0 { "events" } else { "" };
            let mut line = format!("  {label:<8} {:<width$}  t = {}", e.name, n(e.t));
            for (j, c) in scene.coordinates.iter().enumerate() {
                let _ = write!(line, ", {c} = {}", n(e.q[j]));
            }
            for (j, c) in scene.coordinates.iter().enumerate() {
                let _ = write!(line, ", {c}_dot = {}", n(e.qd[j]));
            }
            let _ = writeln!(s, "{line}");
        }
    }
    let st = &out.stats;
    let mut work = format!(
        "{} accepted and {} rejected steps, {} right-hand sides",
        st.accepted_steps, st.rejected_steps, st.rhs_evaluations
    );
    if st.jacobian_evaluations > 0 {
        let _ = write!(
            work,
            ", {} Jacobians, {} LU decompositions",
            st.jacobian_evaluations, st.lu_decompositions
        );
    }
    if st.event_evaluations > 0 {
        let _ = write!(work, ", {} event evaluations", st.event_evaluations);
    }
    if st.projections > 0 {
        let _ = write!(
            work,
            ", {} projections ({} iterations)",
            st.projections, st.projection_iterations
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
    if !out.residual.is_empty() && k > 0 {
        let max = out
            .residual
            .iter()
            .flatten()
            .fold(0.0f64, |m, v| m.max(v.abs()));
        let _ = writeln!(
            s,
            "  residual max |f| = {} over {} output points",
            n(max),
            out.t.len()
        );
    }
    let wants_quantities = scene.output.tables.contains(&Table::Quantities)
        || scene.output.pictures.contains(&Picture::Quantities);
    if wants_quantities {
        for ((name, _), values) in scene.output.quantities.iter().zip(quantities(scene, out)) {
            let bad = values.iter().filter(|v| !v.is_finite()).count();
            if bad > 0 {
                let _ = writeln!(
                    s,
                    "  warning  the quantity '{name}' is not finite at {bad} of {} output times (written as NaN or inf); check its domain",
                    values.len()
                );
            }
        }
    }
    if let Some(b) = out.balance.iter().map(|b| b.abs()).reduce(f64::max) {
        let _ = writeln!(s, "  energy   max |E − E(t0) − W_Φ + ∫∂L/∂t dt| = {}", n(b));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_round_trip_and_read_well() {
        for v in [
            0.0,
            1.0,
            -2.5,
            1e-20,
            6.02e23,
            1.085_038_501_948_426_5,
            f64::MIN_POSITIVE,
        ] {
            assert_eq!(csv_number(v).parse::<f64>().ok(), Some(v), "{v}");
        }
        assert_eq!(csv_number(1e-20), "1e-20");
        assert_eq!(summary_number(1.085_038_501_948_426_5), "1.085038501948");
        assert_eq!(summary_number(10.0), "10");
        assert_eq!(summary_number(-7.657_510_943_466), "-7.657510943466");
        assert_eq!(summary_number(2.5e-16), "2.5e-16");
        assert_eq!(csv_text("a, b"), "\"a, b\"");
        assert_eq!(csv_text("plain"), "plain");
    }
}
