//! The SVG pictures, drawn by `chetaev-plot`.
//!
//! * Axis labels carry the units the scene declares (`[model] units`, `[output.units]`): `x [m]`,
//!   `t [s]`; velocities and accelerations get theirs from the coordinate's and time's
//!   (`ẋ [m/s]`, `ẍ [m/s²]`), the Chetaev force from the energy's and the coordinate's.
//! * Curves of different units never share a linear axis: a picture whose curves have several
//!   units is one panel per unit, stacked on one time axis. Output quantities without a declared
//!   unit get a panel each, since nothing says they compare.
//! * The trajectory draws the pairs of coordinates of `output.trajectory`, one panel per entry.

use std::path::Path;

use chetaev::integrate::events::EventHit;
use chetaev::solution::Series;
use chetaev_plot::{Figure, Legend, Panels, PlotError, Style, PALETTE};

use super::{balance_terms, balance_text, quantity_values};
use crate::run::Outcome;
use crate::scene::{Picture, Scene};

/// A picture: one figure, or several panels in one file.
pub(super) enum Drawing {
    One(Box<Figure>),
    Many(Panels),
}

impl Drawing {
    pub(super) fn save(&self, path: &Path) -> Result<(), PlotError> {
        match self {
            Drawing::One(f) => f.save(path),
            Drawing::Many(p) => p.save(path),
        }
    }
}

/// Each panel's largest size when a picture is split by unit.
const STACKED_PANEL: (f64, f64) = (720.0, 250.0);
/// Each panel's largest size in a trajectory of several panels, two to a row.
const TRAJECTORY_PANEL: (f64, f64) = (480.0, 420.0);

/// `name [unit]`; the name alone if no unit is declared, or the unit is declared empty.
pub(crate) fn labelled(name: &str, unit: Option<&str>) -> String {
    match unit {
        Some(u) if !u.is_empty() => format!("{name} [{u}]"),
        _ => name.to_string(),
    }
}

/// A unit as a numerator: in parentheses if it is a quotient (`m/s` → `(m/s)`).
fn numerator(u: &str) -> String {
    if u.is_empty() {
        "1".to_string()
    } else if u.contains('/') {
        format!("({u})")
    } else {
        u.to_string()
    }
}

/// A unit as a denominator: in parentheses if it is a product or quotient.
fn denominator(u: &str) -> String {
    if u.contains(['/', ' ', '·', '*']) {
        format!("({u})")
    } else {
        u.to_string()
    }
}

/// The unit of the first (`order = 1`) or second time derivative of a quantity in `unit`:
/// `m`, `s` → `m/s`, `m/s²`. `None` unless both units are declared.
pub(crate) fn per_time(unit: Option<&str>, time: Option<&str>, order: u32) -> Option<String> {
    let (u, t) = (unit?, time?);
    if t.is_empty() {
        return Some(u.to_string());
    }
    let square = if order == 2 { "²" } else { "" };
    Some(format!("{}/{}{square}", numerator(u), denominator(t)))
}

/// The unit of a generalised force conjugate to a coordinate in `coordinate`, for an energy in
/// `energy`: `J`, `m` → `N`; `J`, `rad` → `J/rad`. `None` unless both are declared.
fn force_unit(energy: Option<&str>, coordinate: Option<&str>) -> Option<String> {
    let (e, c) = (energy?, coordinate?);
    Some(match (e, c) {
        (e, "") => e.to_string(),
        ("J", "m") => "N".to_string(),
        (e, c) => format!("{}/{}", numerator(e), denominator(c)),
    })
}

/// The name of a coordinate's time derivative: a dot over a one-letter name (`x` → `ẋ`, `y2` →
/// `ẏ2`), else the scene's own `theta_dot`.
fn dotted(name: &str, order: u32) -> String {
    let mut chars = name.chars();
    match chars.next() {
        Some(c) if c.is_ascii_alphabetic() && chars.all(|r| r.is_ascii_digit() || r == '_') => {
            let mark = if order == 2 { '\u{308}' } else { '\u{307}' };
            format!("{c}{mark}{}", &name[1..])
        }
        _ => format!("{name}_{}", if order == 2 { "ddot" } else { "dot" }),
    }
}

/// `sym` with subscript `a` (`μ₁`), or `sym` alone if there is one.
fn indexed(sym: &str, a: usize, count: usize) -> String {
    if count == 1 {
        return sym.to_string();
    }
    const SUB: [char; 10] = ['₀', '₁', '₂', '₃', '₄', '₅', '₆', '₇', '₈', '₉'];
    let digits: String = a
        .to_string()
        .chars()
        .map(|d| SUB[d.to_digit(10).unwrap_or(0) as usize])
        .collect();
    format!("{sym}{digits}")
}

/// Component `j` of every vector of a series.
fn column(rows: &Series, j: usize) -> Vec<f64> {
    rows.iter()
        .map(|r| r.get(j).copied().unwrap_or(f64::NAN))
        .collect()
}

fn series(t: &[f64], v: &[f64]) -> Vec<(f64, f64)> {
    t.iter().copied().zip(v.iter().copied()).collect()
}

/// One curve against `t`: its name, unit and points.
struct Curve {
    name: String,
    unit: Option<String>,
    points: Vec<(f64, f64)>,
    style: Style,
}

impl Curve {
    fn new(name: String, unit: Option<String>, points: Vec<(f64, f64)>) -> Self {
        Self {
            name,
            unit,
            points,
            style: Style::default(),
        }
    }
}

/// The curves grouped by unit, in the order of first appearance. With `alone`, curves without a
/// declared unit get a group each.
fn by_unit(curves: Vec<Curve>, alone: bool) -> Vec<Vec<Curve>> {
    let mut groups: Vec<Vec<Curve>> = Vec::new();
    for c in curves {
        let joins = |g: &Vec<Curve>| g[0].unit == c.unit && !(alone && c.unit.is_none());
        match groups.iter_mut().find(|g| joins(g)) {
            Some(g) => g.push(c),
            None => groups.push(vec![c]),
        }
    }
    groups
}

/// What the y axis of a group is called: its curve's name, two or three names, or `what`.
fn group_label(group: &[Curve], what: &str) -> String {
    let name = match group.len() {
        1 => group[0].name.clone(),
        2 | 3 => group
            .iter()
            .map(|c| c.name.as_str())
            .collect::<Vec<_>>()
            .join(", "),
        _ => what.to_string(),
    };
    labelled(&name, group[0].unit.as_deref())
}

/// Curves against `t`: one figure if they share a unit, else one panel per unit on one time axis.
fn against_t(
    title: &str,
    what: &str,
    t_label: &str,
    curves: Vec<Curve>,
    alone: bool,
    log_y: bool,
) -> Drawing {
    let mut groups = by_unit(curves, alone);
    let panel = |title: &str, group: Vec<Curve>| {
        let mut f = Figure::new(title)
            .x_label(t_label)
            .y_label(&group_label(&group, what));
        if log_y {
            f = f.log_y();
            // Nothing to draw on a log axis: say so, over the time the run covered.
            let points = group.iter().flat_map(|c| &c.points);
            if !points.clone().any(|&(_, y)| y > 0.0 && y.is_finite()) {
                let (lo, hi) = points
                    .filter(|(t, _)| t.is_finite())
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &(t, _)| {
                        (lo.min(t), hi.max(t))
                    });
                f = f.note("zero at every recorded point: nothing to draw on a log axis");
                if lo < hi {
                    f = f.x_range(lo, hi);
                }
            }
        }
        if group.len() == 1 {
            f = f.legend(Legend::Hidden);
        }
        group
            .into_iter()
            .fold(f, |f, c| f.line_styled(&c.name, &c.points, c.style))
    };
    if groups.len() == 1 {
        let group = groups.pop().unwrap_or_default();
        return Drawing::One(Box::new(panel(title, group)));
    }
    // Each curve keeps one colour across the panels, so that no two look alike.
    let mut k = 0;
    for c in groups.iter_mut().flatten() {
        if c.style.color.is_none() {
            c.style.color = Some(PALETTE[k % PALETTE.len()]);
            c.style.dashed = (k / PALETTE.len()) % 2 == 1;
            k += 1;
        }
    }
    Drawing::Many(
        groups.into_iter().fold(
            Panels::new(title)
                .share_x()
                .panel_size(STACKED_PANEL.0, STACKED_PANEL.1),
            |p, g| p.panel(panel("", g)),
        ),
    )
}

/// The default panels of the trajectory: the second coordinate against the first; with three
/// coordinates, each of the three pairs.
fn default_panels(n: usize) -> Vec<Vec<(usize, usize)>> {
    match n {
        3 => vec![vec![(0, 1)], vec![(0, 2)], vec![(1, 2)]],
        _ => vec![vec![(0, 1)]],
    }
}

/// The label of one axis of a trajectory panel drawing the coordinates `idx`.
fn axis_label(scene: &Scene, idx: &[usize]) -> String {
    let mut distinct: Vec<usize> = Vec::new();
    for &i in idx {
        if !distinct.contains(&i) {
            distinct.push(i);
        }
    }
    let names: Vec<&str> = distinct
        .iter()
        .map(|&i| scene.coordinates[i].as_str())
        .collect();
    let name = if names.len() <= 3 {
        names.join(", ")
    } else {
        format!("{}, …, {}", names[0], names[names.len() - 1])
    };
    let units = &scene.units.coordinates;
    let unit = units[distinct[0]].as_deref();
    let common = distinct.iter().all(|&i| units[i].as_deref() == unit);
    labelled(&name, if common { unit } else { None })
}

/// One panel of the trajectory: each pair `(i, j)` draws `q_j` against `q_i`, events marked.
fn trajectory_panel(scene: &Scene, out: &Outcome, pairs: &[(usize, usize)], title: &str) -> Figure {
    let c = &scene.coordinates;
    let units = &scene.units.coordinates;
    let xs: Vec<usize> = pairs.iter().map(|p| p.0).collect();
    let ys: Vec<usize> = pairs.iter().map(|p| p.1).collect();
    let mut f = Figure::new(title)
        .x_label(&axis_label(scene, &xs))
        .y_label(&axis_label(scene, &ys));
    // Equal scales unless the two axes have different declared units.
    if pairs.iter().all(|&(i, j)| units[i] == units[j]) {
        f = f.equal_aspect();
    }
    for &(i, j) in pairs {
        let name = if pairs.len() > 1 {
            format!("({}, {})", c[i], c[j])
        } else {
            String::new()
        };
        let pts: Vec<(f64, f64)> = out.q.iter().map(|q| (q[i], q[j])).collect();
        f = f.line(&name, &pts);
    }
    mark_events(f, out, |e| {
        pairs.iter().map(|&(i, j)| (e.q[i], e.q[j])).collect()
    })
}

/// One marker series per event, with all its hits, each at the points `at` gives for it.
fn mark_events(mut f: Figure, out: &Outcome, at: impl Fn(&EventHit) -> Vec<(f64, f64)>) -> Figure {
    let mut names: Vec<usize> = Vec::new();
    for e in &out.events {
        if !names.contains(&e.index) {
            names.push(e.index);
        }
    }
    for index in names {
        let pts: Vec<(f64, f64)> = out
            .events
            .iter()
            .filter(|e| e.index == index)
            .flat_map(&at)
            .collect();
        f = f.line_styled(
            out.event_name(index),
            &pts,
            Style {
                width: 0.0,
                markers: true,
                ..Style::default()
            },
        );
    }
    f
}

/// The trajectory of a scene of one coordinate: the coordinate against `t`, events marked.
fn trajectory_in_time(scene: &Scene, out: &Outcome, title: &str, t_label: &str) -> Drawing {
    let pts: Vec<(f64, f64)> = out
        .t
        .iter()
        .zip(out.q.iter())
        .map(|(&t, q)| (t, q[0]))
        .collect();
    let f = Figure::new(title)
        .x_label(t_label)
        .y_label(&axis_label(scene, &[0]))
        .line(&scene.coordinates[0], &pts);
    Drawing::One(Box::new(mark_events(f, out, |e| vec![(e.t, e.q[0])])))
}

fn trajectory(scene: &Scene, out: &Outcome, title: &str) -> Drawing {
    let c = &scene.coordinates;
    let n = scene.n();
    let chosen = scene.output.trajectory.as_ref();
    let panels = chosen.cloned().unwrap_or_else(|| default_panels(n));
    let note = if chosen.is_none() && n >= 4 {
        format!(
            "{} against {}, the first two of {n} coordinates; output.trajectory chooses others",
            c[1], c[0]
        )
    } else {
        String::new()
    };
    let span = |j: usize| {
        let (lo, hi) = out
            .q
            .iter()
            .map(|q| q[j])
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                (lo.min(v), hi.max(v))
            });
        hi - lo
    };
    if let [pairs] = panels.as_slice() {
        // A motion taller than wide gets a taller picture.
        let tall = pairs.iter().any(|&(i, j)| span(j) > span(i));
        let (w, h) = if tall { (640.0, 640.0) } else { (720.0, 450.0) };
        return Drawing::One(Box::new(
            trajectory_panel(scene, out, pairs, title)
                .note(&note)
                .size(w, h),
        ));
    }
    let heading = |pairs: &[(usize, usize)]| match pairs {
        [(i, j)] => format!("{} against {}", c[*j], c[*i]),
        _ => String::new(),
    };
    // Panels all wider than tall go one under the other (with one horizontal coordinate, on one
    // scale: a plan over an elevation); others two to a row.
    let wide = panels
        .iter()
        .flatten()
        .all(|&(i, j)| span(i) >= 1.5 * span(j));
    let mut drawing = Panels::new(title).note(&note);
    drawing = if wide {
        let first = panels[0][0].0;
        if panels.iter().flatten().all(|p| p.0 == first) {
            drawing = drawing.share_x();
        }
        drawing.panel_size(STACKED_PANEL.0, TRAJECTORY_PANEL.1)
    } else {
        drawing
            .columns(2)
            .panel_size(TRAJECTORY_PANEL.0, TRAJECTORY_PANEL.1)
    };
    Drawing::Many(panels.iter().fold(drawing, |p, pairs| {
        p.panel(trajectory_panel(scene, out, pairs, &heading(pairs)))
    }))
}

/// The energy balance: the terms on one axis, the balance (orders of magnitude smaller along a
/// good motion) on its own.
fn energy(scene: &Scene, out: &Outcome, title: &str, t_label: &str) -> Drawing {
    let unit = scene.units.energy.as_deref();
    let t = &out.t;
    let e0 = out.energy.first().copied().unwrap_or(0.0);
    let de: Vec<f64> = out.energy.iter().map(|e| e - e0).collect();
    let balance_terms = balance_terms(scene);
    if balance_terms.is_empty() {
        // E − E(t0) is the balance itself.
        return Drawing::One(Box::new(
            Figure::new(title)
                .note("no constraint, force or time in L: the energy is conserved along an exact motion")
                .x_label(t_label)
                .y_label(&labelled("E − E(t0)", unit))
                .legend(Legend::Hidden)
                .line("E − E(t0)", &series(t, &de)),
        ));
    }
    let mut terms = Figure::new("")
        .x_label(t_label)
        .y_label(&labelled("energy", unit))
        .line_styled(
            "E − E(t0)",
            &series(t, &de),
            Style {
                width: 4.0,
                ..Style::default()
            },
        );
    for term in balance_terms {
        terms = terms.line(term.legend(), &series(t, term.values(out)));
    }
    let balance = balance_text(scene);
    let balance_panel = Figure::new("")
        .x_label(t_label)
        .y_label(&labelled("balance", unit))
        .legend(Legend::Hidden)
        .line_styled(
            "balance",
            &series(t, &out.balance),
            Style {
                color: Some(PALETTE[3]),
                ..Style::default()
            },
        );
    Drawing::Many(
        Panels::new(title)
            .note(&format!("balance = {balance}, zero along an exact motion"))
            .share_x()
            .panel_size(STACKED_PANEL.0, STACKED_PANEL.1)
            .panel(terms)
            .panel(balance_panel),
    )
}

pub(super) fn figure(scene: &Scene, out: &Outcome, which: Picture) -> Drawing {
    let c = &scene.coordinates;
    let u = &scene.units;
    let title = |what: &str| format!("{}: {what}", scene.name);
    let t_label = labelled("t", u.time.as_deref());
    let t = &out.t;
    let rows = |names: Vec<String>, units: Vec<Option<String>>, rows: &Series| -> Vec<Curve> {
        names
            .into_iter()
            .zip(units)
            .enumerate()
            .map(|(j, (name, unit))| Curve::new(name, unit, series(t, &column(rows, j))))
            .collect()
    };
    let k = scene.k();
    match which {
        Picture::Trajectory if scene.n() >= 2 => trajectory(scene, out, &title("trajectory")),
        Picture::Trajectory => trajectory_in_time(scene, out, &title("trajectory"), &t_label),
        Picture::State => against_t(
            &title("coordinates"),
            "coordinates",
            &t_label,
            rows(c.clone(), u.coordinates.clone(), &out.q),
            false,
            false,
        ),
        Picture::Velocity => against_t(
            &title("velocities"),
            "velocities",
            &t_label,
            rows(
                c.iter().map(|x| dotted(x, 1)).collect(),
                u.coordinates
                    .iter()
                    .map(|q| per_time(q.as_deref(), u.time.as_deref(), 1))
                    .collect(),
                &out.qd,
            ),
            false,
            false,
        ),
        Picture::Acceleration => against_t(
            &title("accelerations"),
            "accelerations",
            &t_label,
            rows(
                c.iter().map(|x| dotted(x, 2)).collect(),
                u.coordinates
                    .iter()
                    .map(|q| per_time(q.as_deref(), u.time.as_deref(), 2))
                    .collect(),
                &out.qdd,
            ),
            false,
            false,
        ),
        Picture::Multipliers => against_t(
            &title("multipliers"),
            "μ",
            &t_label,
            rows(
                (1..=k).map(|a| indexed("μ", a, k)).collect(),
                u.multipliers.clone(),
                &out.mu,
            ),
            false,
            false,
        ),
        Picture::Force => against_t(
            &title("Chetaev force Φ = Jᵀμ"),
            "Φ",
            &t_label,
            rows(
                c.iter().map(|x| format!("Φ_{x}")).collect(),
                u.coordinates
                    .iter()
                    .map(|q| force_unit(u.energy.as_deref(), q.as_deref()))
                    .collect(),
                &out.phi,
            ),
            false,
            false,
        ),
        Picture::Residual => {
            let mut abs = Series::new(out.residual.width());
            for r in out.residual.iter() {
                abs.push(&r.iter().map(|v| v.abs()).collect::<Vec<f64>>());
            }
            against_t(
                &title("constraint residual"),
                "|f|",
                &t_label,
                rows(
                    (1..=k)
                        .map(|a| format!("|{}|", indexed("f", a, k)))
                        .collect(),
                    vec![None; k],
                    &abs,
                ),
                false,
                true,
            )
        }
        Picture::Energy => energy(scene, out, &title("energy balance"), &t_label),
        Picture::Quantities => {
            let curves = scene
                .output
                .quantities
                .iter()
                .zip(&u.quantities)
                .map(|((name, e), unit)| {
                    let v: Vec<f64> = quantity_values(e, out).collect();
                    Curve::new(name.clone(), unit.clone(), series(t, &v))
                })
                .collect();
            against_t(
                &title("quantities"),
                "quantities",
                &t_label,
                curves,
                true,
                false,
            )
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn units_of_derivatives() {
        assert_eq!(per_time(Some("m"), Some("s"), 1).as_deref(), Some("m/s"));
        assert_eq!(per_time(Some("m"), Some("s"), 2).as_deref(), Some("m/s²"));
        assert_eq!(
            per_time(Some("rad"), Some("s"), 1).as_deref(),
            Some("rad/s")
        );
        assert_eq!(
            per_time(Some("m/s"), Some("s"), 1).as_deref(),
            Some("(m/s)/s")
        );
        assert_eq!(per_time(Some(""), Some("s"), 1).as_deref(), Some("1/s"));
        assert_eq!(per_time(Some("m"), None, 1), None);
        assert_eq!(per_time(None, Some("s"), 1), None);
        assert_eq!(force_unit(Some("J"), Some("m")).as_deref(), Some("N"));
        assert_eq!(force_unit(Some("J"), Some("rad")).as_deref(), Some("J/rad"));
        assert_eq!(force_unit(Some("J"), None), None);
    }

    #[test]
    fn names_of_derivatives() {
        assert_eq!(dotted("x", 1), "x\u{307}");
        assert_eq!(dotted("y2", 2), "y\u{308}2");
        assert_eq!(dotted("theta", 1), "theta_dot");
        assert_eq!(dotted("theta", 2), "theta_ddot");
        assert_eq!(indexed("μ", 2, 3), "μ₂");
        assert_eq!(indexed("μ", 1, 1), "μ");
        assert_eq!(indexed("μ", 12, 12), "μ₁₂");
        assert_eq!(labelled("x", Some("m")), "x [m]");
        assert_eq!(labelled("x", Some("")), "x");
        assert_eq!(labelled("x", None), "x");
    }
}
