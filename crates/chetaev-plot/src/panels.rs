//! Several figures in one SVG document: stacked in a column (sharing the x axis) or in a grid.

use std::fmt::Write;
use std::path::Path;

use crate::axis::text_width;
use crate::render::{
    self, Chrome, BOLD, FONT_FAMILY, LINE, NOTE_COLOR, NOTE_FONT, OUTER_PAD, TEXT_COLOR, TITLE_FONT,
};
use crate::{Figure, PlotError};

/// The font of a panel's heading (its figure's title).
const PANEL_TITLE_FONT: f64 = 13.0;

/// Several figures, the *panels*, in one SVG document under one title: one column by default
/// (stacked), or a grid of [`Panels::columns`] columns filled row by row.
///
/// Each panel is drawn as a [`Figure`] of [`Panels::panel_size`] (its own size is ignored), with
/// its title as the panel's heading in a smaller font. With [`Panels::share_x`], the panels of each
/// column have the same x range and their plot frames aligned, and only the bottom panel of a
/// column has the x label: the layout for quantities of different size or unit against one time
/// axis, each on its own y axis.
///
/// ```
/// use chetaev_plot::{Figure, Legend, Panels};
///
/// let t: Vec<f64> = (0..=50).map(|i| f64::from(i) * 0.02).collect();
/// let speed: Vec<(f64, f64)> = t.iter().map(|&t| (t, 2.0 + 0.5 * t)).collect();
/// let angle: Vec<(f64, f64)> = t.iter().map(|&t| (t, 1e-3 * (-t).exp())).collect();
/// let svg = Panels::new("Sled")
///     .share_x()
///     .panel(Figure::new("").x_label("t [s]").y_label("speed [m/s]").legend(Legend::Hidden).line("speed", &speed))
///     .panel(Figure::new("").x_label("t [s]").y_label("heading [rad]").legend(Legend::Hidden).line("heading", &angle))
///     .to_svg();
/// assert_eq!(svg.matches(r#"class="frame""#).count(), 2);
/// ```
#[derive(Clone, Debug)]
pub struct Panels {
    title: String,
    note: String,
    panels: Vec<Figure>,
    columns: usize,
    share_x: bool,
    panel_width: f64,
    panel_height: f64,
}

impl Panels {
    /// No panels yet, one column, panels of 720 × 260 px, and a title (empty for none).
    pub fn new(title: &str) -> Self {
        Self {
            title: title.to_string(),
            note: String::new(),
            panels: Vec::new(),
            columns: 1,
            share_x: false,
            panel_width: 720.0,
            panel_height: 260.0,
        }
    }

    /// A line of smaller text under the title (empty for none).
    pub fn note(mut self, note: &str) -> Self {
        self.note = note.to_string();
        self
    }

    /// Adds a panel.
    pub fn panel(mut self, figure: Figure) -> Self {
        self.panels.push(figure);
        self
    }

    /// The number of columns of the grid (at least 1; 1 unless set).
    pub fn columns(mut self, columns: usize) -> Self {
        self.columns = columns.max(1);
        self
    }

    /// The same x range, aligned plot frames and one x label in each column.
    pub fn share_x(mut self) -> Self {
        self.share_x = true;
        self
    }

    /// The largest size of each panel in pixels (720 × 260 unless set); panels with
    /// [`Figure::equal_aspect`] may come out smaller.
    pub fn panel_size(mut self, width: f64, height: f64) -> Self {
        self.panel_width = width;
        self.panel_height = height;
        self
    }

    /// The number of panels.
    pub fn len(&self) -> usize {
        self.panels.len()
    }

    /// Whether there are no panels.
    pub fn is_empty(&self) -> bool {
        self.panels.is_empty()
    }

    /// Checks every panel as [`Figure::check`] does, at the panel size.
    pub fn check(&self) -> Result<(), PlotError> {
        self.sized().iter().try_for_each(Figure::check)
    }

    /// The panels at the panel size.
    fn sized(&self) -> Vec<Figure> {
        self.panels
            .iter()
            .map(|f| f.clone().size(self.panel_width, self.panel_height))
            .collect()
    }

    /// The document as a self-contained SVG. Never fails; see [`Figure::to_svg`].
    pub fn to_svg(&self) -> String {
        let panels = self.sized();
        let n = panels.len();
        let columns = self.columns.min(n).max(1);
        let rows = n.div_ceil(columns);
        let mut chromes: Vec<Chrome> = (0..n)
            .map(|i| Chrome {
                title_font: PANEL_TITLE_FONT,
                salt: format!("{}|panel {i}", self.title),
                ..Chrome::default()
            })
            .collect();
        if self.share_x {
            for c in 0..columns {
                let members: Vec<usize> = (c..n).step_by(columns).collect();
                let measured: Vec<(f64, Option<(f64, f64)>)> = members
                    .iter()
                    .map(|&i| render::measure(&panels[i], &chromes[i]))
                    .collect();
                let left = measured.iter().map(|m| m.0).fold(0.0, f64::max);
                let same_scale = members
                    .iter()
                    .all(|&i| panels[i].is_log_x() == panels[members[0]].is_log_x());
                let x_data = measured
                    .iter()
                    .filter_map(|m| m.1)
                    .reduce(|a, b| (a.0.min(b.0), a.1.max(b.1)));
                let last = members.last().copied();
                for &i in &members {
                    chromes[i].left = Some(left);
                    if same_scale {
                        chromes[i].x_data = x_data;
                    }
                    chromes[i].x_label = Some(i) == last;
                }
            }
        }
        let bodies: Vec<render::Body> = panels
            .iter()
            .zip(&chromes)
            .map(|(f, c)| render::body(f, c))
            .collect();
        let column_width: Vec<f64> = (0..columns)
            .map(|c| {
                (c..n)
                    .step_by(columns)
                    .map(|i| bodies[i].width)
                    .fold(0.0, f64::max)
            })
            .collect();
        let row_height: Vec<f64> = (0..rows)
            .map(|r| {
                (r * columns..((r + 1) * columns).min(n))
                    .map(|i| bodies[i].height)
                    .fold(0.0, f64::max)
            })
            .collect();
        let grid_width: f64 = column_width.iter().sum();
        let inner = grid_width - 2.0 * OUTER_PAD;
        let title = render::wrap(&self.title, inner, TITLE_FONT, BOLD);
        let note = render::wrap(&self.note, inner, NOTE_FONT, 1.0);
        let widest = title
            .iter()
            .map(|l| text_width(l, TITLE_FONT) * BOLD)
            .chain(note.iter().map(|l| text_width(l, NOTE_FONT)))
            .fold(0.0, f64::max)
            + 2.0 * OUTER_PAD;
        let width = grid_width.max(widest).max(100.0);
        let top = if title.is_empty() && note.is_empty() {
            0.0
        } else {
            OUTER_PAD
                + title.len() as f64 * TITLE_FONT * LINE
                + note.len() as f64 * NOTE_FONT * LINE
        };
        let height = top + row_height.iter().sum::<f64>();

        let mut svg = String::new();
        let _ = writeln!(svg, r#"<?xml version="1.0" encoding="UTF-8"?>"#);
        let _ = writeln!(
            svg,
            r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="{FONT_FAMILY}" fill="{TEXT_COLOR}">"#,
            w = render::num(width.ceil()),
            h = render::num(height.ceil().max(1.0))
        );
        if !self.title.is_empty() {
            let _ = writeln!(svg, "<title>{}</title>", render::escape(&self.title));
        }
        let _ = writeln!(svg, r#"<rect width="100%" height="100%" fill="white"/>"#);
        for (k, line) in title.iter().enumerate() {
            let _ = writeln!(
                svg,
                r#"<text class="title" x="{}" y="{}" text-anchor="middle" font-size="{TITLE_FONT}" font-weight="bold">{}</text>"#,
                render::num(width / 2.0),
                render::num(OUTER_PAD + TITLE_FONT * (0.8 + LINE * k as f64)),
                render::escape(line)
            );
        }
        let note_top = OUTER_PAD + title.len() as f64 * TITLE_FONT * LINE;
        for (k, line) in note.iter().enumerate() {
            let _ = writeln!(
                svg,
                r#"<text class="note" x="{}" y="{}" text-anchor="middle" font-size="{NOTE_FONT}" fill="{NOTE_COLOR}">{}</text>"#,
                render::num(width / 2.0),
                render::num(note_top + NOTE_FONT * (0.8 + LINE * k as f64)),
                render::escape(line)
            );
        }
        let offset = (width - column_width.iter().sum::<f64>()) / 2.0;
        for (i, body) in bodies.iter().enumerate() {
            let (r, c) = (i / columns, i % columns);
            let x = offset
                + column_width[..c].iter().sum::<f64>()
                + (column_width[c] - body.width) / 2.0;
            let y = top + row_height[..r].iter().sum::<f64>();
            let _ = writeln!(
                svg,
                r#"<g class="panel" transform="translate({} {})">"#,
                render::num(x),
                render::num(y)
            );
            svg.push_str(&body.svg);
            let _ = writeln!(svg, "</g>");
        }
        let _ = writeln!(svg, "</svg>");
        svg
    }

    /// Writes the document to `path`, which must end in `.svg`; missing parent directories are
    /// created.
    pub fn save(&self, path: impl AsRef<Path>) -> Result<(), PlotError> {
        crate::write_svg(path.as_ref(), || self.check(), || self.to_svg())
    }
}
