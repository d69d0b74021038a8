//! What a run writes and prints: CSV tables, SVG pictures, the manifest, and the summary.
//!
//! | file | holds |
//! |---|---|
//! | `files.rs` | the output directory: [`Plan`] (checked before integrating), the [`MANIFEST`] |
//! | `table.rs` | CSV tables, streamed row by row |
//! | `picture.rs` | SVG pictures (`chetaev-plot`) |
//! | `summary.rs` | the summary, a failure in the scene's terms, values that are not finite |

mod files;
mod picture;
pub(crate) use picture::{labelled, per_time};
pub(crate) use table::csv_text;
mod summary;
mod table;

use std::path::{Path, PathBuf};

pub use files::{resolve, Plan, Written, MANIFEST};
pub(crate) use summary::state_text;
pub use summary::{count, failure, non_finite, status_text, summary, Failure, NonFinite};
pub use table::CsvNumber;

use crate::error::Error;
use crate::expr::{Env, Expr};
use crate::run::Outcome;
use crate::scene::{Picture, Scene, Table};

/// A number for a CSV file: the shortest text that reads back to the same `f64`, in plain notation
/// between `1e-5` and `1e16` and in exponent notation outside.
pub fn csv_number(v: f64) -> String {
    CsvNumber(v).to_string()
}

/// A number for the summary: 13 significant digits, trailing zeros dropped; zero without a sign.
pub fn summary_number(v: f64) -> String {
    let a = v.abs();
    if v == 0.0 {
        return "0".to_string();
    }
    if !v.is_finite() {
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

/// A term of the energy balance `E − E(t0) − W_Φ − W_Q + ∫∂L/∂t dt` besides `E − E(t0)`, written
/// where the scene's model has it: the terms left out are zero along any motion.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum BalanceTerm {
    /// `W_Φ`, with constraints.
    Chetaev,
    /// `W_Q`, with forces or a dissipation function.
    Forces,
    /// `∫∂L/∂t dt`, with a Lagrangian that reads `t`.
    Time,
}

impl BalanceTerm {
    /// The term as it stands in the balance, with its sign: " − W_Φ".
    fn signed(self) -> &'static str {
        match self {
            Self::Chetaev => " − W_Φ",
            Self::Forces => " − W_Q",
            Self::Time => " + ∫∂L/∂t dt",
        }
    }

    /// Its name in a legend.
    pub(crate) fn legend(self) -> &'static str {
        match self {
            Self::Chetaev => "W_Φ (work of the Chetaev force)",
            Self::Forces => "W_Q (work of the forces Q)",
            Self::Time => "∫∂L/∂t dt",
        }
    }

    /// Its values along the motion.
    pub(crate) fn values(self, out: &Outcome) -> &[f64] {
        match self {
            Self::Chetaev => &out.work,
            Self::Forces => &out.work_forces,
            Self::Time => &out.dl_dt_integral,
        }
    }
}

/// The terms of the energy balance that the scene's model has (none for a conservative model,
/// whose balance is `E − E(t0)` alone).
pub(crate) fn balance_terms(scene: &Scene) -> Vec<BalanceTerm> {
    [
        (scene.k() > 0, BalanceTerm::Chetaev),
        (
            !scene.forces.is_empty() || !scene.loads.is_empty() || scene.dissipation.is_some(),
            BalanceTerm::Forces,
        ),
        (scene.lagrangian.uses_time(), BalanceTerm::Time),
    ]
    .into_iter()
    .filter_map(|(has, term)| has.then_some(term))
    .collect()
}

/// The balance as the summary and the energy picture write it: "E − E(t0) − W_Φ".
pub(crate) fn balance_text(scene: &Scene) -> String {
    balance_terms(scene)
        .into_iter()
        .fold(String::from("E − E(t0)"), |s, term| s + term.signed())
}

/// Whether the quantities are written (as a table or a picture).
fn writes_quantities(scene: &Scene) -> bool {
    scene.output.tables.contains(&Table::Quantities)
        || scene.output.pictures.contains(&Picture::Quantities)
}

/// An output quantity at output point `i`, if the state there was recorded.
fn quantity_at(e: &Expr, out: &Outcome, i: usize) -> Option<f64> {
    let (t, q, qd) = (out.t.get(i)?, out.q.get(i)?, out.qd.get(i)?);
    let env = Env { t: *t, q, qd };
    if !e.reads_recorded() {
        return Some(e.eval(&env));
    }
    let mut values = Vec::new();
    recorded(out, i, &mut values);
    Some(e.eval_recorded(&env, &values))
}

/// The quantities an output quantity may read at output point `i`, in the order of the names
/// [`Symbols::recorded`](crate::expr::Symbols::recorded) gives them: the multipliers `μ` (`mu_1`,
/// ...), then the Chetaev force `Φ` (`Phi_<coordinate>`); empty where they were not recorded.
pub(crate) fn recorded(out: &Outcome, i: usize, values: &mut Vec<f64>) {
    values.clear();
    if let (Some(mu), Some(phi)) = (out.mu.get(i), out.phi.get(i)) {
        values.extend_from_slice(mu);
        values.extend_from_slice(phi);
    }
}

/// An output quantity along the recorded motion, evaluated as it is read.
fn quantity_values<'a>(e: &'a Expr, out: &'a Outcome) -> impl Iterator<Item = f64> + 'a {
    (0..out.t.len()).map(move |i| quantity_at(e, out, i).unwrap_or(f64::NAN))
}

/// Writes the tables and pictures the scene asks for into `dir` (created if missing), with the
/// [`MANIFEST`] listing them, and returns the tables and pictures written. Refuses a directory
/// holding files of an earlier run that this one would not write (see [`Plan::new`]).
pub fn write(scene: &Scene, out: &Outcome, dir: &Path) -> Result<Vec<PathBuf>, Error> {
    Ok(Plan::new(scene, dir, false)?.write(scene, out)?.files)
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
        assert_eq!(summary_number(-0.0), "0");
        assert_eq!(table::csv_text("a, b"), "\"a, b\"");
        assert_eq!(table::csv_text("plain"), "plain");
    }
}
