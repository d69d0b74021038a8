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
pub(super) fn csv_text(s: &str) -> String {
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
        Table::Residual => (indexed("f").collect(), vec![Part::Rows(&out.residual, k)]),
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
        Table::Events => return write_events(w, scene, out),
    };
    write!(w, "t")?;
    for h in &header {
        write!(w, ",{h}")?;
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

/// One row per located event: its name, `t`, the coordinates and the velocities.
fn write_events<W: Write>(w: &mut W, scene: &Scene, out: &Outcome) -> io::Result<()> {
    write!(w, "event,t")?;
    for x in &scene.coordinates {
        write!(w, ",{x}")?;
    }
    for x in &scene.coordinates {
        write!(w, ",{x}_dot")?;
    }
    writeln!(w)?;
    for e in &out.events {
        write!(
            w,
            "{},{}",
            csv_text(out.event_name(e.index)),
            CsvNumber(e.t)
        )?;
        for v in e.q.iter().chain(&e.qd) {
            write!(w, ",{}", CsvNumber(*v))?;
        }
        writeln!(w)?;
    }
    Ok(())
}
