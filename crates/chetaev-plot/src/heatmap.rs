//! A heat map: a value over a grid of two variables, as coloured cells with a colour bar.

use std::fmt::Write as _;
use std::path::Path;

use crate::axis::{self, Axis, Room, Span};
use crate::render::{escape, TITLE_FONT};
use crate::{write_svg, PlotError};

const TICK_FONT: f64 = 12.0;
const LABEL_FONT: f64 = 14.0;

/// Viridis (van der Walt and Smith, matplotlib's default), sampled at nine equally spaced
/// points: perceptually uniform, readable in grey and by the colour-blind.
const VIRIDIS: [(f64, f64, f64); 9] = [
    (68.0, 1.0, 84.0),
    (71.0, 44.0, 122.0),
    (59.0, 81.0, 139.0),
    (44.0, 113.0, 142.0),
    (33.0, 144.0, 141.0),
    (39.0, 173.0, 129.0),
    (92.0, 200.0, 99.0),
    (170.0, 220.0, 50.0),
    (253.0, 231.0, 37.0),
];

/// The colour of `u ∈ [0, 1]` on the colour scale, as `#rrggbb`.
pub fn color(u: f64) -> String {
    let u = if u.is_finite() {
        u.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let x = u * (VIRIDIS.len() - 1) as f64;
    let i = (x.floor() as usize).min(VIRIDIS.len() - 2);
    let f = x - i as f64;
    let (a, b) = (VIRIDIS[i], VIRIDIS[i + 1]);
    let mix = |p: f64, q: f64| (p + (q - p) * f).round() as u8;
    format!(
        "#{:02x}{:02x}{:02x}",
        mix(a.0, b.0),
        mix(a.1, b.1),
        mix(a.2, b.2)
    )
}

/// A value `z` over the grid of `x` and `y`: each cell coloured by its value (viridis), a colour
/// bar with the value's label, and cells without a finite value drawn grey. The cells' edges lie
/// halfway between neighbouring grid values (in the axis's units, so on a log axis halfway in
/// the logarithm).
///
/// ```
/// use chetaev_plot::HeatMap;
///
/// let x = [1.0, 2.0, 3.0];
/// let y = [10.0, 20.0];
/// let z = vec![vec![1.0, 2.0, 3.0], vec![4.0, 5.0, f64::NAN]]; // z[j][i] at (x[i], y[j])
/// let svg = HeatMap::new("range", &x, &y, z).x_label("v0 [m/s]").y_label("h0 [m]").to_svg();
/// assert!(svg.contains("range") && svg.contains("v0 [m/s]"));
/// ```
#[derive(Clone, Debug)]
pub struct HeatMap {
    title: String,
    x: Vec<f64>,
    y: Vec<f64>,
    z: Vec<Vec<f64>>,
    x_label: String,
    y_label: String,
    value_label: String,
    log_x: bool,
    log_y: bool,
    log_values: bool,
    width: f64,
    height: f64,
}

impl HeatMap {
    /// A heat map of `z[j][i]` at `(x[i], y[j])`; `x` and `y` ascending.
    pub fn new(title: &str, x: &[f64], y: &[f64], z: Vec<Vec<f64>>) -> Self {
        Self {
            title: title.to_string(),
            x: x.to_vec(),
            y: y.to_vec(),
            z,
            x_label: String::new(),
            y_label: String::new(),
            value_label: String::new(),
            log_x: false,
            log_y: false,
            log_values: false,
            width: 720.0,
            height: 480.0,
        }
    }

    /// The label under the x axis.
    pub fn x_label(mut self, label: &str) -> Self {
        self.x_label = label.to_string();
        self
    }

    /// The label beside the y axis.
    pub fn y_label(mut self, label: &str) -> Self {
        self.y_label = label.to_string();
        self
    }

    /// The label of the colour bar (the value and its unit).
    pub fn value_label(mut self, label: &str) -> Self {
        self.value_label = label.to_string();
        self
    }

    /// A logarithmic x axis (the grid values must be positive).
    pub fn log_x(mut self) -> Self {
        self.log_x = true;
        self
    }

    /// A logarithmic y axis (the grid values must be positive).
    pub fn log_y(mut self) -> Self {
        self.log_y = true;
        self
    }

    /// Colours by the logarithm of the value, with a logarithmic colour bar (the values must be
    /// positive; others are drawn as missing).
    pub fn log_values(mut self) -> Self {
        self.log_values = true;
        self
    }

    /// Writes the heat map to `path`, which must end in `.svg`.
    pub fn save(&self, path: impl AsRef<Path>) -> Result<(), PlotError> {
        write_svg(path.as_ref(), || Ok(()), || self.to_svg())
    }

    /// The heat map as a self-contained SVG document.
    pub fn to_svg(&self) -> String {
        let (w, h) = (self.width, self.height);
        let (left, right, top, bottom) = (80.0, 150.0, 50.0, 60.0);
        let (pw, ph) = (w - left - right, h - top - bottom);
        let xs = units(&self.x, self.log_x);
        let ys = units(&self.y, self.log_y);
        let (xe, ye) = (edges(&xs), edges(&ys));
        let room = |px: f64, horizontal: bool| Room {
            length_px: px,
            min_spacing_px: if horizontal { 75.0 } else { 42.0 },
            font_size: TICK_FONT,
            horizontal,
        };
        let axis_of = |e: &[f64], log: bool, px: f64, horizontal: bool| -> Axis {
            let (lo, hi) = (e[0], e[e.len() - 1]);
            if log {
                axis::log(lo, hi, Span::Fixed, room(px, horizontal))
            } else {
                axis::linear(lo, hi, Span::Fixed, room(px, horizontal))
            }
        };
        let xa = axis_of(&xe, self.log_x, pw, true);
        let ya = axis_of(&ye, self.log_y, ph, false);
        let px = |a: f64| left + xa.fraction(a) * pw;
        let py = |b: f64| top + ph - ya.fraction(b) * ph;

        // The values in colour-bar units: themselves, or their logarithm.
        let zu = |v: f64| Axis::to_axis_units(self.log_values, v);
        let finite: Vec<f64> = self.z.iter().flatten().filter_map(|&v| zu(v)).collect();
        let (zlo, zhi) = match axis::extent(finite.iter().copied()) {
            Some((a, b)) if b > a => (a, b),
            Some((a, _)) => (a - 0.5, a + 0.5),
            None => (0.0, 1.0),
        };
        let mut s = String::new();
        let _ = writeln!(
            s,
            "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<svg xmlns=\"http://www.w3.org/2000/svg\" \
             width=\"{w}\" height=\"{h}\" viewBox=\"0 0 {w} {h}\" font-family=\"sans-serif\">\n\
             <rect width=\"{w}\" height=\"{h}\" fill=\"white\"/>"
        );
        let _ = writeln!(
            s,
            "<text x=\"{}\" y=\"{}\" font-size=\"{TITLE_FONT}\" text-anchor=\"middle\">{}</text>",
            w / 2.0,
            top - 20.0,
            escape(&self.title)
        );
        let mut missing = false;
        // Cells edge to edge, without anti-aliased seams between them.
        s.push_str("<g shape-rendering=\"crispEdges\">\n");
        for (j, row) in self.z.iter().enumerate().take(self.y.len()) {
            for (i, &v) in row.iter().enumerate().take(self.x.len()) {
                let (x0, x1) = (px(xe[i]), px(xe[i + 1]));
                let (y0, y1) = (py(ye[j + 1]), py(ye[j]));
                let fill = match zu(v) {
                    Some(u) => color((u - zlo) / (zhi - zlo)),
                    None => {
                        missing = true;
                        "#d0d0d0".to_string()
                    }
                };
                let _ = writeln!(
                    s,
                    "<rect x=\"{x0:.2}\" y=\"{y0:.2}\" width=\"{:.2}\" height=\"{:.2}\" fill=\"{fill}\"/>",
                    (x1 - x0).abs(),
                    (y1 - y0).abs()
                );
            }
        }
        s.push_str("</g>\n");
        // Frame and ticks.
        let _ = writeln!(
            s,
            "<rect x=\"{left}\" y=\"{top}\" width=\"{pw}\" height=\"{ph}\" fill=\"none\" stroke=\"black\"/>"
        );
        for (pos, label) in xa.labels() {
            let x = px(pos);
            let _ = writeln!(
                s,
                "<line x1=\"{x:.2}\" y1=\"{}\" x2=\"{x:.2}\" y2=\"{}\" stroke=\"black\"/>\
                 <text x=\"{x:.2}\" y=\"{}\" font-size=\"{TICK_FONT}\" text-anchor=\"middle\">{}</text>",
                top + ph,
                top + ph + 5.0,
                top + ph + 18.0,
                escape(label)
            );
        }
        for (pos, label) in ya.labels() {
            let y = py(pos);
            let _ = writeln!(
                s,
                "<line x1=\"{}\" y1=\"{y:.2}\" x2=\"{left}\" y2=\"{y:.2}\" stroke=\"black\"/>\
                 <text x=\"{}\" y=\"{:.2}\" font-size=\"{TICK_FONT}\" text-anchor=\"end\">{}</text>",
                left - 5.0,
                left - 8.0,
                y + 4.0,
                escape(label)
            );
        }
        let _ = writeln!(
            s,
            "<text x=\"{}\" y=\"{}\" font-size=\"{LABEL_FONT}\" text-anchor=\"middle\">{}</text>",
            left + pw / 2.0,
            h - 15.0,
            escape(&self.x_label)
        );
        let _ = writeln!(
            s,
            "<text transform=\"translate(20 {}) rotate(-90)\" font-size=\"{LABEL_FONT}\" \
             text-anchor=\"middle\">{}</text>",
            top + ph / 2.0,
            escape(&self.y_label)
        );
        // The colour bar.
        let (bx, bw) = (left + pw + 25.0, 18.0);
        let steps = 64;
        for k in 0..steps {
            let u0 = k as f64 / steps as f64;
            let y0 = top + ph * (1.0 - u0 - 1.0 / steps as f64);
            let _ = writeln!(
                s,
                "<rect x=\"{bx}\" y=\"{y0:.2}\" width=\"{bw}\" height=\"{:.2}\" fill=\"{}\"/>",
                ph / steps as f64 + 0.5,
                color(u0 + 0.5 / steps as f64)
            );
        }
        let _ = writeln!(
            s,
            "<rect x=\"{bx}\" y=\"{top}\" width=\"{bw}\" height=\"{ph}\" fill=\"none\" stroke=\"black\"/>"
        );
        let za = if self.log_values {
            axis::log(zlo, zhi, Span::Fixed, room(ph, false))
        } else {
            axis::linear(zlo, zhi, Span::Fixed, room(ph, false))
        };
        for (pos, label) in za.labels() {
            let y = top + ph - za.fraction(pos) * ph;
            let _ = writeln!(
                s,
                "<line x1=\"{}\" y1=\"{y:.2}\" x2=\"{}\" y2=\"{y:.2}\" stroke=\"black\"/>\
                 <text x=\"{}\" y=\"{:.2}\" font-size=\"{TICK_FONT}\">{}</text>",
                bx + bw,
                bx + bw + 4.0,
                bx + bw + 7.0,
                y + 4.0,
                escape(label)
            );
        }
        let _ = writeln!(
            s,
            "<text transform=\"translate({} {}) rotate(-90)\" font-size=\"{LABEL_FONT}\" \
             text-anchor=\"middle\">{}</text>",
            w - 15.0,
            top + ph / 2.0,
            escape(&if self.log_values {
                format!("{} (log scale)", self.value_label)
            } else {
                self.value_label.clone()
            })
        );
        if missing {
            let _ = writeln!(
                s,
                "<text x=\"{left}\" y=\"{}\" font-size=\"{TICK_FONT}\" fill=\"#606060\">grey: no \
                 value (the run did not reach it)</text>",
                top - 5.0
            );
        }
        s.push_str("</svg>\n");
        s
    }
}

/// Grid values in axis units (their logarithm on a log axis; a value a log axis cannot show is
/// put next to its neighbour).
fn units(v: &[f64], log: bool) -> Vec<f64> {
    let mut out: Vec<f64> = v
        .iter()
        .map(|&x| Axis::to_axis_units(log, x).unwrap_or(f64::NAN))
        .collect();
    for i in 0..out.len() {
        if !out[i].is_finite() {
            out[i] = if i > 0 { out[i - 1] } else { 0.0 };
        }
    }
    out
}

/// The cells' edges: halfway between neighbours, and half a cell beyond the ends (one cell of
/// width 1 around a single value).
fn edges(c: &[f64]) -> Vec<f64> {
    match c.len() {
        0 => vec![0.0, 1.0],
        1 => vec![c[0] - 0.5, c[0] + 0.5],
        n => {
            let mut e = Vec::with_capacity(n + 1);
            e.push(c[0] - (c[1] - c[0]) / 2.0);
            for w in c.windows(2) {
                e.push((w[0] + w[1]) / 2.0);
            }
            e.push(c[n - 1] + (c[n - 1] - c[n - 2]) / 2.0);
            e
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_colour_scale_runs_from_viridis_dark_purple_to_yellow() {
        assert_eq!(color(0.0), "#440154");
        assert_eq!(color(1.0), "#fde725");
        assert_eq!(color(f64::NAN), "#440154");
    }

    #[test]
    fn every_cell_is_drawn_with_its_colour_and_missing_ones_grey() {
        let z = vec![vec![0.0, 1.0], vec![2.0, f64::NAN]];
        let svg = HeatMap::new("z", &[1.0, 2.0], &[3.0, 4.0], z).to_svg();
        assert!(svg.contains("fill=\"#440154\""), "the least value");
        assert!(svg.contains("fill=\"#fde725\""), "the largest value");
        assert!(svg.contains("fill=\"#d0d0d0\"") && svg.contains("grey: no value"));
        assert!(!svg.contains("NaN") && !svg.contains("inf"));
    }

    #[test]
    fn cell_edges_lie_halfway_between_grid_values() {
        assert_eq!(edges(&[1.0, 2.0, 4.0]), vec![0.5, 1.5, 3.0, 5.0]);
        assert_eq!(edges(&[3.0]), vec![2.5, 3.5]);
    }
}
