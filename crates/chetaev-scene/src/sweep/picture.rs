//! The pictures of a sweep: each quantity against the variable when one varies (`sweep.svg`, a
//! panel per quantity); when two vary on a grid, a heat map per quantity with a colour bar
//! (`sweep-<quantity>.svg`) and, where the second has few enough values for lines to tell apart,
//! each quantity against the first variable with one line per value of the second
//! (`sweep.svg`).
//!
//! A random sample, or more than two variables, gets no picture: the table is the result.

use chetaev_plot::{Figure, HeatMap, Panels, Style};

use super::table::Table;

/// The most lines of one panel: two variables are drawn as lines too while the second has at
/// most this many values.
const MAX_LINES: usize = 8;

/// The most panels in one picture; the rest of the quantities are only in the table.
const MAX_PANELS: usize = 12;

/// The pictures as `(file name, SVG)`; none where the sweep has none (see the
/// [module docs](self)).
pub fn draw(table: &Table) -> Vec<(String, String)> {
    let columns: Vec<usize> = (0..table.columns.len()).take(MAX_PANELS).collect();
    if columns.is_empty() || table.rows.is_empty() {
        return Vec::new();
    }
    let distinct = |j: usize| {
        let mut v: Vec<f64> = table.rows.iter().map(|r| r.values[j]).collect();
        v.sort_by(f64::total_cmp);
        v.dedup();
        v
    };
    let title = format!("{}: sweep", table.title);
    let mut panels = Panels::new(&title).columns(columns.len().min(3));
    match table.variables.len() {
        1 => {
            let x = &table.variable_labels[0];
            let mut rows: Vec<&super::Row> = table.rows.iter().collect();
            rows.sort_by(|a, b| a.values[0].total_cmp(&b.values[0]));
            let log = log_spaced(&distinct(0));
            for &c in &columns {
                let points: Vec<(f64, f64)> = rows
                    .iter()
                    .map(|r| (r.values[0], r.quantities[c]))
                    .collect();
                let style = Style {
                    markers: rows.len() <= 60,
                    ..Style::default()
                };
                let mut f = Figure::new(&table.columns[c])
                    .x_label(x)
                    .y_label(&table.column_labels[c])
                    .line_styled("", &points, style);
                if log {
                    f = f.log_x();
                }
                panels = panels.panel(f);
            }
        }
        2 => {
            let (xs, ys) = (distinct(0), distinct(1));
            // A grid: every pair present once.
            if xs.len() * ys.len() != table.rows.len() {
                return Vec::new();
            }
            let mut maps = Vec::new();
            let (x, y) = (&table.variable_labels[0], &table.variables[1]);
            let y_label = &table.variable_labels[1];
            // The row at each grid point, found once: (i, j) → row.
            let position = |v: f64, of: &[f64]| of.binary_search_by(|a| a.total_cmp(&v)).ok();
            let mut cell: Vec<Option<usize>> = vec![None; xs.len() * ys.len()];
            for (r, row) in table.rows.iter().enumerate() {
                if let (Some(i), Some(j)) =
                    (position(row.values[0], &xs), position(row.values[1], &ys))
                {
                    cell[j * xs.len() + i] = Some(r);
                }
            }
            for &c in &columns {
                let at = |i: usize, j: usize| {
                    cell[j * xs.len() + i].map_or(f64::NAN, |r| table.rows[r].quantities[c])
                };
                if ys.len() <= MAX_LINES {
                    let mut f = Figure::new(&table.columns[c])
                        .x_label(x)
                        .y_label(&table.column_labels[c]);
                    for (j, yv) in ys.iter().enumerate() {
                        let points: Vec<(f64, f64)> =
                            (0..xs.len()).map(|i| (xs[i], at(i, j))).collect();
                        f = f.line_styled(
                            &format!("{y} = {yv}"),
                            &points,
                            Style {
                                markers: xs.len() <= 60,
                                ..Style::default()
                            },
                        );
                    }
                    if log_spaced(&xs) {
                        f = f.log_x();
                    }
                    panels = panels.panel(f);
                }
                let values: Vec<Vec<f64>> = (0..ys.len())
                    .map(|j| (0..xs.len()).map(|i| at(i, j)).collect())
                    .collect();
                let log_values = spans_decades(&values);
                let map = HeatMap::new(&table.columns[c], &xs, &ys, values)
                    .x_label(x)
                    .y_label(y_label)
                    .value_label(&table.column_labels[c]);
                let map = if log_spaced(&xs) { map.log_x() } else { map };
                let map = if log_spaced(&ys) { map.log_y() } else { map };
                let map = if log_values { map.log_values() } else { map };
                maps.push((
                    format!("sweep-{}.svg", file_stem(&table.columns[c])),
                    map.to_svg(),
                ));
            }
            if ys.len() <= MAX_LINES {
                maps.push(("sweep.svg".to_string(), panels.to_svg()));
            }
            return maps;
        }
        _ => return Vec::new(),
    }
    vec![("sweep.svg".to_string(), panels.to_svg())]
}

/// A quantity's name as part of a file name: `impact.t` stays, `d(impact.t)/d(v0)` becomes
/// `d_impact.t_d_v0`, `x@1.5` becomes `x_at_1.5`.
fn file_stem(name: &str) -> String {
    let s = name.replace('@', "_at_");
    let mut out = String::new();
    for c in s.chars() {
        if c.is_ascii_alphanumeric() || c == '.' || c == '-' || c == '_' {
            out.push(c);
        } else if !out.ends_with('_') {
            out.push('_');
        }
    }
    out.trim_matches('_').to_string()
}

/// Whether positive values are spaced geometrically (a logarithmic grid): the ratios of
/// neighbours equal and not 1 (a linear grid's ratios differ, 2/1, 3/2, ...).
fn log_spaced(v: &[f64]) -> bool {
    if v.len() < 3 || v.iter().any(|&x| x <= 0.0) {
        return false;
    }
    let r = v[1] / v[0];
    r > 1.0 + 1e-9 && v.windows(2).all(|w| ((w[1] / w[0]) / r - 1.0).abs() < 1e-6)
}

/// Whether values are best coloured by their logarithm: all positive, over more than two decades.
fn spans_decades(v: &[Vec<f64>]) -> bool {
    let finite: Vec<f64> = v
        .iter()
        .flatten()
        .copied()
        .filter(|x| x.is_finite())
        .collect();
    let lo = finite.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = finite.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    lo > 0.0 && hi / lo > 100.0
}
