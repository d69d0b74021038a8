//! The CSV tables, written row by row as they are formed: a table of any length takes the memory
//! of one row besides the recorded motion it is read from.

use chetaev::solution::Series;
use std::fmt;
use std::io::{self, Write};

use super::quantity_at;
use crate::expr::Expr;
use crate::run::Outcome;
use crate::scene::{Scene, Table};

/// A number as a CSV field: the shortest text that reads back to the same `f64`, in plain notation
/// between `1e-5` and `1e16` and in exponent notation outside.
#[derive(Clone, Copy, Debug)]
pub struct CsvNumber(pub f64);

impl fmt::Display for CsvNumber {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let v = self.0;
        let a = v.abs();
        if v == 0.0 || !v.is_finite() || (1e-5..1e16).contains(&a) {
            write!(f, "{v}")
        } else {
            write!(f, "{v:e}")
        }
    }
}

/// A text field for a CSV file, quoted when it holds a comma, a quote or a line break.
pub(crate) fn csv_text(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// Columns of a numeric table after `t`, read at output point `i` when the row is written.
enum Part<'a> {
    /// The first `n` entries of each row: `q`, `q̇`, `μ`, ...
    Rows(&'a Series, usize),
    /// One value per output point: `E`, `W_Φ`, ...
    Column(&'a [f64]),
    /// An output quantity, evaluated at the recorded state.
    Quantity(&'a Expr),
}

/// Writes table `which` of `out` to `w`: a header line, then one line per row.
pub(super) fn write_table<W: Write>(
    w: &mut W,
    scene: &Scene,
    out: &Outcome,
    which: Table,
) -> io::Result<()> {
    let c = &scene.coordinates;
    let (n, k) = (scene.n(), scene.k());
    let no_sensitivities = Series::new(0);
    let names = |suffix: &'static str| c.iter().map(move |x| format!("{x}{suffix}"));
    let indexed = |prefix: &'static str| (1..=k).map(move |a| format!("{prefix}_{a}"));
    let (header, parts): (Vec<String>, Vec<Part<'_>>) = match which {
        Table::State => (
            names("").chain(names("_dot")).collect(),
            vec![Part::Rows(&out.q, n), Part::Rows(&out.qd, n)],
        ),
        Table::Acceleration => (names("_ddot").collect(), vec![Part::Rows(&out.qdd, n)]),
        Table::Multipliers => (indexed("mu").collect(), vec![Part::Rows(&out.mu, k)]),
        Table::Force => (
            c.iter().map(|x| format!("Phi_{x}")).collect(),
            vec![Part::Rows(&out.phi, n)],
        ),
        Table::Residual => {
            // The velocity constraints' f, then the holonomic ones' ḣ (the rows the equations
            // hold at zero) and their h itself.
            let (kv, kh) = (scene.constraints.len(), scene.holonomic.len());
            let header = (1..=kv)
                .map(|a| format!("f_{a}"))
                .chain((1..=kh).map(|b| format!("hdot_{b}")))
                .chain((1..=kh).map(|b| format!("h_{b}")))
                .collect();
            let mut parts = vec![Part::Rows(&out.residual, k)];
            if kh > 0 {
                parts.push(Part::Rows(&out.position_residual, kh));
            }
            (header, parts)
        }
        Table::Energy => (
            ["E", "W_Phi", "W_Q", "int_dL_dt", "balance"]
                .map(String::from)
                .to_vec(),
            vec![
                Part::Column(&out.energy),
                Part::Column(&out.work),
                Part::Column(&out.work_forces),
                Part::Column(&out.dl_dt_integral),
                Part::Column(&out.balance),
            ],
        ),
        Table::Quantities => (
            scene
                .output
                .quantities
                .iter()
                .map(|(n, _)| n.clone())
                .collect(),
            scene
                .output
                .quantities
                .iter()
                .map(|(_, e)| Part::Quantity(e))
                .collect(),
        ),
        Table::Sensitivities => {
            let s = out.sensitivities.as_ref();
            let values = s.map_or(&no_sensitivities, |s| &s.values);
            let mut header = sensitivity_names(scene, false).collect::<Vec<_>>();
            let mut parts = vec![Part::Rows(values, header.len())];
            // With constraints, those of the multipliers and of the Chetaev force follow.
            if k > 0 {
                let (mu, phi) = force_sensitivity_names(scene);
                let (kp, np) = (mu.len(), phi.len());
                header.extend(mu.into_iter().chain(phi));
                parts.push(Part::Rows(s.map_or(&no_sensitivities, |s| &s.mu), kp));
                parts.push(Part::Rows(s.map_or(&no_sensitivities, |s| &s.phi), np));
            }
            (header, parts)
        }
        Table::Events => return write_events(w, scene, out),
    };
    write!(w, "t")?;
    for h in &header {
        write!(w, ",{}", csv_text(h))?;
    }
    writeln!(w)?;
    for (i, t) in out.t.iter().enumerate() {
        write!(w, "{}", CsvNumber(*t))?;
        for part in &parts {
            match part {
                Part::Rows(rows, n) => {
                    let row = rows.get(i).unwrap_or(&[]);
                    for j in 0..*n {
                        field(w, row.get(j).copied())?;
                    }
                }
                Part::Column(col) => field(w, col.get(i).copied())?,
                Part::Quantity(e) => field(w, quantity_at(e, out, i))?,
            }
        }
        writeln!(w)?;
    }
    Ok(())
}

/// `,value`, or `,` alone where nothing was recorded.
fn field<W: Write>(w: &mut W, v: Option<f64>) -> io::Result<()> {
    match v {
        Some(v) => write!(w, ",{}", CsvNumber(v)),
        None => write!(w, ","),
    }
}

/// The names of the sensitivities' columns, for each parameter `p` of `[sensitivities]` in turn:
/// `d(t)/d(p)` first if `with_time` (an event's time), then `d(x)/d(p)` for each coordinate, then
/// `d(x_dot)/d(p)` for each velocity, the order of [`chetaev::Sensitivities::values`].
pub(crate) fn sensitivity_names(
    scene: &Scene,
    with_time: bool,
) -> impl Iterator<Item = String> + '_ {
    let parameters = scene
        .sensitivities
        .as_ref()
        .map_or(&[][..], |s| &s.parameters[..]);
    let c = &scene.coordinates;
    parameters.iter().flat_map(move |p| {
        let time = with_time.then(|| "t".to_string());
        time.into_iter()
            .chain(c.iter().cloned())
            .chain(c.iter().map(|x| format!("{x}_dot")))
            .map(move |x| format!("d({x})/d({p})"))
    })
}

/// The names of the columns of the multipliers' and the Chetaev force's sensitivities: for each
/// parameter `p` of `[sensitivities]` in turn `d(mu_a)/d(p)` for every constraint, then for each
/// `p` in turn `d(Phi_x)/d(p)` for every coordinate, the orders of
/// [`chetaev::Sensitivities::mu`] and [`chetaev::Sensitivities::phi`].
fn force_sensitivity_names(scene: &Scene) -> (Vec<String>, Vec<String>) {
    let parameters = scene
        .sensitivities
        .as_ref()
        .map_or(&[][..], |s| &s.parameters[..]);
    let mu = parameters
        .iter()
        .flat_map(|p| (1..=scene.k()).map(move |a| format!("d(mu_{a})/d({p})")))
        .collect();
    let phi = parameters
        .iter()
        .flat_map(|p| {
            scene
                .coordinates
                .iter()
                .map(move |x| format!("d(Phi_{x})/d({p})"))
        })
        .collect();
    (mu, phi)
}

/// One row per located event: its name, `t`, the coordinates and the velocities; with
/// `[sensitivities]`, then for each parameter `dT/dp`, `dq(T)/dp` and `dq̇(T)/dp` (empty where the
/// event was crossed tangentially, where `T` is not differentiable).
fn write_events<W: Write>(w: &mut W, scene: &Scene, out: &Outcome) -> io::Result<()> {
    write!(w, "event,t")?;
    for x in &scene.coordinates {
        write!(w, ",{x}")?;
    }
    for x in &scene.coordinates {
        write!(w, ",{x}_dot")?;
    }
    let derivatives: Vec<String> = sensitivity_names(scene, true).collect();
    for h in &derivatives {
        write!(w, ",{}", csv_text(h))?;
    }
    writeln!(w)?;
    let moved = out.sensitivities.as_ref().map(|s| &s.events);
    for (i, e) in out.events.iter().enumerate() {
        write!(
            w,
            "{},{}",
            csv_text(out.event_name(e.index)),
            CsvNumber(e.t)
        )?;
        for v in e.q.iter().chain(&e.qd) {
            write!(w, ",{}", CsvNumber(*v))?;
        }
        match moved.and_then(|m| m.get(i)).and_then(Option::as_ref) {
            Some(d) => {
                for j in 0..d.t.len() {
                    write!(w, ",{}", CsvNumber(d.t[j]))?;
                    for v in d.q[j].iter().chain(&d.qd[j]) {
                        write!(w, ",{}", CsvNumber(*v))?;
                    }
                }
            }
            None => {
                for _ in &derivatives {
                    write!(w, ",")?;
                }
            }
        }
        writeln!(w)?;
    }
    Ok(())
}
