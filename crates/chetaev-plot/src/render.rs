//! Layout and SVG output of a [`Figure`].

use std::fmt::Write;

use crate::axis::{self, extent, text_width, Axis, Room, Span};
use crate::{AxisSpec, Figure, Legend, Style, PALETTE};

pub(crate) const FONT_FAMILY: &str = "DejaVu Sans, Helvetica, Arial, sans-serif";
pub(crate) const TITLE_FONT: f64 = 16.0;
const LABEL_FONT: f64 = 14.0;
const TICK_FONT: f64 = 12.0;
const LEGEND_FONT: f64 = 12.0;
const TICK_LENGTH: f64 = 5.0;
const MINOR_TICK_LENGTH: f64 = 3.0;
pub(crate) const OUTER_PAD: f64 = 12.0;
/// Lines are clipped, in fractions of the plot area, to this much beyond it on every side before
/// the exact clip of the SVG viewer: the file then holds only coordinates of moderate size.
const CLIP_MARGIN: f64 = 0.25;
const FRAME_COLOR: &str = "#333333";
const GRID_COLOR: &str = "#e4e4e4";
pub(crate) const TEXT_COLOR: &str = "#222222";

/// A series in axis units, split into runs of drawable points.
struct Runs {
    runs: Vec<Vec<(f64, f64)>>,
}

/// Splits points into runs of finite points, in axis units. Non-finite points end a run; points
/// a log axis cannot show (`≤ 0`) are dropped without ending it.
fn split_runs(points: &[(f64, f64)], log_x: bool, log_y: bool) -> Runs {
    let mut runs = Vec::new();
    let mut current = Vec::new();
    for &(x, y) in points {
        if !(x.is_finite() && y.is_finite()) {
            if !current.is_empty() {
                runs.push(std::mem::take(&mut current));
            }
            continue;
        }
        if let (Some(a), Some(b)) = (Axis::to_axis_units(log_x, x), Axis::to_axis_units(log_y, y)) {
            current.push((a, b));
        }
    }
    if !current.is_empty() {
        runs.push(current);
    }
    Runs { runs }
}

/// The plot area in pixels.
#[derive(Clone, Copy, Debug)]
struct Frame {
    left: f64,
    top: f64,
    width: f64,
    height: f64,
}

impl Frame {
    fn px(&self, x_axis: &Axis, a: f64) -> f64 {
        self.left + x_axis.fraction(a) * self.width
    }
    fn py(&self, y_axis: &Axis, b: f64) -> f64 {
        self.top + (1.0 - y_axis.fraction(b)) * self.height
    }
    /// Pixel position of a point given as fractions of the plot area.
    fn at(&self, fx: f64, fy: f64) -> (f64, f64) {
        (
            self.left + fx * self.width,
            self.top + (1.0 - fy) * self.height,
        )
    }
}

/// Resolves one axis for a given length on the page.
fn resolve(spec: &AxisSpec, data: Option<(f64, f64)>, room: Room) -> Axis {
    let (span, (lo, hi)) = match spec.fixed() {
        Some(r) => (Span::Fixed, r),
        None => (
            Span::Auto(spec.margin.unwrap_or(axis::MARGIN)),
            // Nothing to show: [0, 1], or [1, 10] on a log axis.
            data.unwrap_or((0.0, 1.0)),
        ),
    };
    if spec.log {
        axis::log(lo, hi, span, room)
    } else {
        axis::linear(lo, hi, span, room)
    }
}

fn x_room(length_px: f64) -> Room {
    Room {
        length_px,
        min_spacing_px: 75.0,
        font_size: TICK_FONT,
        horizontal: true,
    }
}

fn y_room(length_px: f64) -> Room {
    Room {
        length_px,
        min_spacing_px: 42.0,
        font_size: TICK_FONT,
        horizontal: false,
    }
}

/// How a figure is drawn: alone (the default), or as one panel of [`Panels`](crate::Panels).
#[derive(Clone, Debug)]
pub(crate) struct Chrome {
    /// The title's font size.
    pub title_font: f64,
    /// A left margin to use instead of the figure's own (at least as wide), so that panels
    /// stacked in a column have their frames aligned.
    pub left: Option<f64>,
    /// The x extent in axis units, shared with the other panels of a column.
    pub x_data: Option<(f64, f64)>,
    /// Whether the x label is drawn.
    pub x_label: bool,
    /// Mixed into the clip-path identifier, so that panels of one document differ.
    pub salt: String,
    /// Whether a white rectangle fills the canvas first (a panel's document has its own).
    pub background: bool,
}

impl Default for Chrome {
    fn default() -> Self {
        Self {
            title_font: TITLE_FONT,
            left: None,
            x_data: None,
            x_label: true,
            salt: String::new(),
            background: true,
        }
    }
}

/// Bold text is about 15 % wider than regular text of the same size (DejaVu Sans, measured); 20 %
/// leaves room for titles of wide letters.
pub(crate) const BOLD: f64 = 1.2;
/// Line spacing, in font sizes.
pub(crate) const LINE: f64 = 1.25;
pub(crate) const NOTE_FONT: f64 = 12.0;
pub(crate) const NOTE_COLOR: &str = "#555555";
/// Room between the x label and a legend below the plot.
const LEGEND_GAP: f64 = 10.0;
/// Room between the columns of a legend below the plot.
const LEGEND_COLUMN_GAP: f64 = 18.0;
/// Axis labels are made smaller to fit their side of the plot, down to this size.
const MIN_LABEL_FONT: f64 = 9.0;

/// The width of `text` at `font` px, bold by a factor `weight` (1 for regular text).
fn width_of(text: &str, font: f64, weight: f64) -> f64 {
    text_width(text, font) * weight
}

/// Breaks `text` into lines no wider than `max` (at spaces; a word wider than `max` stands on its
/// own line). Empty text gives no lines.
pub(crate) fn wrap(text: &str, max: f64, font: f64, weight: f64) -> Vec<String> {
    let mut lines: Vec<String> = Vec::new();
    let mut current = String::new();
    for word in text.split(' ').filter(|w| !w.is_empty()) {
        let candidate = if current.is_empty() {
            word.to_string()
        } else {
            format!("{current} {word}")
        };
        if current.is_empty() || width_of(&candidate, font, weight) <= max {
            current = candidate;
        } else {
            lines.push(std::mem::replace(&mut current, word.to_string()));
        }
    }
    if !current.is_empty() {
        lines.push(current);
    }
    lines
}

/// The font size at which `text` fits in `room` px, from `font` down to [`MIN_LABEL_FONT`].
fn fitted_font(text: &str, room: f64, font: f64) -> f64 {
    let w = text_width(text, font);
    if w <= room || w <= 0.0 {
        font
    } else {
        (font * room / w).max(MIN_LABEL_FONT)
    }
}

/// A legend below the plot: its size and how its entries are arranged.
#[derive(Clone, Copy, Debug)]
struct Below {
    columns: usize,
    column_width: f64,
    width: f64,
    height: f64,
}

/// The page layout: canvas size, plot frame, both axes, and the text around them.
struct Layout {
    width: f64,
    height: f64,
    frame: Frame,
    x: Axis,
    y: Axis,
    /// The left margin the figure needs on its own (before any shift or forced margin).
    natural_left: f64,
    title: Vec<String>,
    title_font: f64,
    note: Vec<String>,
    /// Horizontal position of the (rotated) y label's baseline.
    y_label_x: f64,
    y_label_font: f64,
    x_label_font: f64,
    x_label: bool,
}

/// Room kept outside the plot for the legend.
#[derive(Clone, Copy, Debug)]
enum Outside {
    /// None.
    No,
    /// Under the x label.
    Below(Below),
    /// Right of the plot, this wide.
    Right(f64),
}

fn layout(fig: &Figure, series: &[Runs], chrome: &Chrome, outside: Outside) -> Layout {
    let below = match &outside {
        Outside::Below(b) => Some(b),
        _ => None,
    };
    let beside = match outside {
        Outside::Right(w) => w + LEGEND_GAP,
        _ => 0.0,
    };
    let (max_width, height) = if fig.check_size() {
        (fig.width, fig.height)
    } else {
        (720.0, 450.0)
    };
    let all = || series.iter().flat_map(|s| s.runs.iter().flatten());
    let x_data = chrome.x_data.or_else(|| extent(all().map(|p| p.0)));
    let y_data = extent(all().map(|p| p.1));

    let inner = max_width - 2.0 * OUTER_PAD;
    let title = wrap(&fig.title, inner, chrome.title_font, BOLD);
    let note = wrap(&fig.note, inner, NOTE_FONT, 1.0);
    let top = if title.is_empty() && note.is_empty() {
        OUTER_PAD + 4.0
    } else {
        OUTER_PAD
            + title.len() as f64 * chrome.title_font * LINE
            + note.len() as f64 * NOTE_FONT * LINE
            + 10.0
    };
    let x_label = chrome.x_label && !fig.x.label.is_empty();
    let bottom = TICK_LENGTH
        + 4.0
        + TICK_FONT
        + if x_label {
            10.0 + LABEL_FONT + OUTER_PAD
        } else {
            OUTER_PAD
        }
        + below.map_or(0.0, |b| b.height + LEGEND_GAP);
    let y_label_room = if fig.y.label.is_empty() {
        0.0
    } else {
        LABEL_FONT + 10.0
    };

    // Two passes: the widths of the y tick labels set the left margin, which sets the plot width,
    // which sets the x ticks.
    let mut natural_left = OUTER_PAD + y_label_room + 40.0 + TICK_LENGTH;
    let mut left = chrome.left.unwrap_or(natural_left).max(natural_left);
    let mut right = 20.0 + beside;
    let mut x = resolve(&fig.x, x_data, x_room(max_width - left - right));
    let mut y = resolve(&fig.y, y_data, y_room(height - top - bottom));
    for _ in 0..2 {
        let widest = y
            .labels()
            .map(|(_, l)| text_width(l, TICK_FONT))
            .fold(0.0, f64::max);
        natural_left = OUTER_PAD + y_label_room + widest + TICK_LENGTH + 4.0;
        left = chrome.left.unwrap_or(natural_left).max(natural_left);
        let last_x = x
            .labels()
            .filter(|(p, _)| (x.fraction(*p) - 1.0).abs() < 1e-9)
            .map(|(_, l)| text_width(l, TICK_FONT) / 2.0 + 4.0)
            .fold(0.0, f64::max);
        right = last_x.max(20.0) + beside;
        x = resolve(&fig.x, x_data, x_room(max_width - left - right));
        y = resolve(&fig.y, y_data, y_room(height - top - bottom));
    }
    let mut frame = Frame {
        left,
        top,
        width: (max_width - left - right).max(20.0),
        height: (height - top - bottom).max(20.0),
    };
    let (mut width, mut height) = (max_width, height);
    if fig.equal_aspect {
        let (xs, ys) = (x.hi - x.lo, y.hi - y.lo);
        let scale = (frame.width / xs).min(frame.height / ys);
        let (w, h) = (xs * scale, ys * scale);
        if w < frame.width - 0.5 {
            frame.width = w;
            x = resolve(
                &AxisSpec {
                    range: Some(unaxis(&x)),
                    ..fig.x.clone()
                },
                None,
                x_room(w),
            );
        }
        if h < frame.height - 0.5 {
            frame.height = h;
            y = resolve(
                &AxisSpec {
                    range: Some(unaxis(&y)),
                    ..fig.y.clone()
                },
                None,
                y_room(h),
            );
        }
        width = frame.left + frame.width + right;
        height = frame.top + frame.height + bottom;
    }
    // Keep room for the title, the note and a legend below: the canvas is at least as wide as they
    // are, with the plot centred in it.
    let needed = title
        .iter()
        .map(|l| width_of(l, chrome.title_font, BOLD))
        .chain(note.iter().map(|l| width_of(l, NOTE_FONT, 1.0)))
        .chain(below.map(|b| b.width))
        .fold(0.0, f64::max)
        + 2.0 * OUTER_PAD;
    let mut shift = 0.0;
    if width < needed {
        shift = (needed - width) / 2.0;
        frame.left += shift;
        width = needed;
    }
    let y_label_font = fitted_font(&fig.y.label, frame.height + 40.0, LABEL_FONT);
    let x_label_font = fitted_font(&fig.x.label, width - 2.0 * OUTER_PAD, LABEL_FONT);
    Layout {
        width,
        height,
        frame,
        x,
        y,
        natural_left,
        title,
        title_font: chrome.title_font,
        note,
        y_label_x: OUTER_PAD + shift + y_label_font * 0.8,
        y_label_font,
        x_label_font,
        x_label,
    }
}

/// The range of an axis in data units.
fn unaxis(a: &Axis) -> (f64, f64) {
    if a.log {
        (10f64.powf(a.lo), 10f64.powf(a.hi))
    } else {
        (a.lo, a.hi)
    }
}

/// A pixel coordinate, rounded to 1/100 px, without trailing zeros.
pub(crate) fn num(v: f64) -> String {
    debug_assert!(v.is_finite());
    let v = if v.is_finite() { v } else { 0.0 };
    let mut s = format!("{v:.2}");
    if s.contains('.') {
        while s.ends_with('0') {
            s.pop();
        }
        if s.ends_with('.') {
            s.pop();
        }
    }
    if s == "-0" {
        s = "0".to_string();
    }
    s
}

/// Escapes text for SVG content and attribute values.
pub(crate) fn escape(text: &str) -> String {
    let mut s = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => s.push_str("&amp;"),
            '<' => s.push_str("&lt;"),
            '>' => s.push_str("&gt;"),
            '"' => s.push_str("&quot;"),
            '\'' => s.push_str("&#39;"),
            c if c.is_control() => s.push(' '),
            c => s.push(c),
        }
    }
    s
}

/// Clips the segment `p → q` (fractions of the plot area) to `[lo, hi]²` (Liang–Barsky). Returns
/// the visible part, if any; an end that is not cut is returned unchanged.
fn clip_segment(
    p: (f64, f64),
    q: (f64, f64),
    lo: f64,
    hi: f64,
) -> Option<((f64, f64), (f64, f64))> {
    let (dx, dy) = (q.0 - p.0, q.1 - p.1);
    let mut t0 = 0.0f64;
    let mut t1 = 1.0f64;
    for (d, dist) in [
        (-dx, p.0 - lo),
        (dx, hi - p.0),
        (-dy, p.1 - lo),
        (dy, hi - p.1),
    ] {
        if d == 0.0 {
            if dist < 0.0 {
                return None;
            }
        } else {
            let r = dist / d;
            if d < 0.0 {
                t0 = t0.max(r);
            } else {
                t1 = t1.min(r);
            }
        }
    }
    if t0 > t1 {
        return None;
    }
    // Unclipped ends are returned exactly, so callers can tell them from cut ones.
    let a = if t0 > 0.0 {
        (p.0 + t0 * dx, p.1 + t0 * dy)
    } else {
        p
    };
    let b = if t1 < 1.0 {
        (p.0 + t1 * dx, p.1 + t1 * dy)
    } else {
        q
    };
    Some((a, b))
}

/// Polylines in pixels.
type Polylines = Vec<Vec<(f64, f64)>>;

/// The polylines of one run, clipped to the plot area plus [`CLIP_MARGIN`], in pixels.
fn clipped_polylines(run: &[(f64, f64)], l: &Layout) -> Polylines {
    let (lo, hi) = (-CLIP_MARGIN, 1.0 + CLIP_MARGIN);
    let frac: Vec<(f64, f64)> = run
        .iter()
        .map(|&(a, b)| (l.x.fraction(a), l.y.fraction(b)))
        .collect();
    let inside = |p: (f64, f64)| p.0 >= lo && p.0 <= hi && p.1 >= lo && p.1 <= hi;
    let mut lines: Vec<Vec<(f64, f64)>> = Vec::new();
    if frac.len() == 1 {
        if inside(frac[0]) {
            lines.push(vec![l.frame.at(frac[0].0, frac[0].1)]);
        }
        return lines;
    }
    let mut current: Vec<(f64, f64)> = Vec::new();
    for w in frac.windows(2) {
        let (p, q) = (w[0], w[1]);
        if !(p.0.is_finite() && p.1.is_finite() && q.0.is_finite() && q.1.is_finite()) {
            // A coordinate so large that its fraction overflows: treat as a gap.
            if current.len() > 1 {
                lines.push(std::mem::take(&mut current));
            }
            current.clear();
            continue;
        }
        match clip_segment(p, q, lo, hi) {
            Some((a, b)) => {
                let a_px = l.frame.at(a.0, a.1);
                let b_px = l.frame.at(b.0, b.1);
                if current.is_empty() || a != p {
                    if current.len() > 1 {
                        lines.push(std::mem::take(&mut current));
                    }
                    current = vec![a_px];
                }
                current.push(b_px);
                if b != q {
                    lines.push(std::mem::take(&mut current));
                }
            }
            None => {
                if current.len() > 1 {
                    lines.push(std::mem::take(&mut current));
                }
                current.clear();
            }
        }
    }
    if current.len() > 1 {
        lines.push(current);
    }
    lines
}

/// SVG path data for polylines: `M x y L x y x y …` per polyline, repeated pixels left out. A
/// polyline of one point is drawn as a dot (a zero-length segment with round caps).
fn path_data(lines: &[Vec<(f64, f64)>]) -> String {
    let mut d = String::new();
    for line in lines {
        let mut last = String::new();
        let mut n = 0;
        for (i, &(x, y)) in line.iter().enumerate() {
            let xy = format!("{} {}", num(x), num(y));
            if xy == last {
                continue;
            }
            if i == 0 {
                d.push('M');
            } else if n == 1 {
                d.push('L');
            } else {
                d.push(' ');
            }
            d.push_str(&xy);
            last = xy;
            n += 1;
        }
        if n == 1 {
            d.push_str("l0 0");
        }
    }
    d
}

/// How one series looks once the cycle is applied: colour, dash pattern (an index into
/// [`DASH_PATTERNS`](crate::DASH_PATTERNS)) and marker shape (an index into [`SHAPES`]).
#[derive(Clone, Copy, Debug)]
struct Look<'a> {
    color: &'a str,
    dash: usize,
    shape: usize,
}

/// The marker shapes of the cycle, in order.
const SHAPES: usize = 5;

/// The looks of a figure's series: the cycle advances only for series without their own colour;
/// every [`PALETTE`] length of them, the dash pattern and the marker shape change.
fn looks(fig: &Figure) -> Vec<Look<'_>> {
    let mut next = 0;
    fig.series
        .iter()
        .map(|s| {
            let (color, round) = match s.style.color {
                Some(c) => (c, 0),
                None => {
                    let k = next;
                    next += 1;
                    (PALETTE[k % PALETTE.len()], k / PALETTE.len())
                }
            };
            Look {
                color,
                dash: if s.style.dashed {
                    1
                } else {
                    round % crate::DASH_PATTERNS.len()
                },
                shape: round % SHAPES,
            }
        })
        .collect()
}

/// The dash array of pattern `dash` for a line `w` px wide (`None` for solid). Lengths grow with the
/// width and have a floor, so thin lines still show the pattern.
fn dash_array(dash: usize, w: f64) -> Option<Vec<f64>> {
    let dot = (0.3 * w).max(0.5);
    match dash {
        1 => Some(vec![(4.0 * w).max(5.0), (2.5 * w).max(3.5)]),
        2 => Some(vec![dot, (2.5 * w).max(3.5)]),
        3 => Some(vec![
            (4.0 * w).max(6.0),
            (2.0 * w).max(3.0),
            dot,
            (2.0 * w).max(3.0),
        ]),
        4 => Some(vec![(8.0 * w).max(10.0), (3.0 * w).max(4.0)]),
        _ => None,
    }
}

/// The stroke attributes of a style with a look.
fn stroke_attributes(style: &Style, look: &Look<'_>) -> String {
    let mut s = format!(
        r#"fill="none" stroke="{}" stroke-width="{}" stroke-linejoin="round" stroke-linecap="round""#,
        escape(look.color),
        num(style.width)
    );
    if let Some(d) = dash_array(look.dash, style.width) {
        let d: Vec<String> = d.into_iter().map(num).collect();
        let _ = write!(s, r#" stroke-dasharray="{}""#, d.join(" "));
    }
    s
}

fn marker_radius(style: &Style) -> f64 {
    if style.width > 0.0 {
        2.2 + style.width
    } else {
        3.2
    }
}

/// One hollow marker of shape `shape` at `(x, y)` with radius `r` (the group sets the stroke).
fn marker(shape: usize, x: f64, y: f64, r: f64) -> String {
    let p = |dx: f64, dy: f64| format!("{} {}", num(x + dx * r), num(y + dy * r));
    match shape % SHAPES {
        1 => format!(
            r#"<rect x="{}" y="{}" width="{w}" height="{w}"/>"#,
            num(x - 0.85 * r),
            num(y - 0.85 * r),
            w = num(1.7 * r)
        ),
        2 => format!(
            r#"<path d="M{}L{} {} {}Z"/>"#,
            p(0.0, -1.2),
            p(1.2, 0.0),
            p(0.0, 1.2),
            p(-1.2, 0.0)
        ),
        3 => format!(
            r#"<path d="M{}L{} {}Z"/>"#,
            p(0.0, -1.2),
            p(1.05, 0.65),
            p(-1.05, 0.65)
        ),
        4 => format!(
            r#"<path d="M{}L{}M{}L{}"/>"#,
            p(-1.0, -1.0),
            p(1.0, 1.0),
            p(-1.0, 1.0),
            p(1.0, -1.0)
        ),
        _ => format!(
            r#"<circle cx="{}" cy="{}" r="{}"/>"#,
            num(x),
            num(y),
            num(r)
        ),
    }
}

/// Whether a style draws anything.
fn draws_line(style: &Style) -> bool {
    style.width > 0.0 && style.width.is_finite()
}

/// A short, stable identifier for the clip path, so that several figures inlined in one HTML page
/// (or panels of one document) do not share one (FNV-1a of the title and the layout).
fn clip_id(fig: &Figure, l: &Layout, salt: &str) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let key = format!(
        "{}|{}|{}|{}|{}|{}{salt}",
        fig.title,
        l.frame.left,
        l.frame.top,
        l.frame.width,
        l.frame.height,
        fig.series.len()
    );
    for b in key.bytes() {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    format!("plot-area-{:08x}", h & 0xffff_ffff)
}

/// The legend's box: position and size in pixels, and its entries' arrangement.
#[derive(Clone, Copy, Debug)]
struct LegendBox {
    x: f64,
    y: f64,
    width: f64,
    height: f64,
    columns: usize,
    column_width: f64,
}

const LEGEND_ROW: f64 = LEGEND_FONT * 1.55;
const LEGEND_SWATCH: f64 = 28.0;
const LEGEND_PAD: f64 = 7.0;
const LEGEND_INSET: f64 = 8.0;

/// The width of one legend entry: swatch, gap, name.
fn entry_width(fig: &Figure, i: usize) -> f64 {
    LEGEND_SWATCH + 6.0 + text_width(&fig.series[i].name, LEGEND_FONT)
}

/// The height of a legend of `rows` rows.
fn legend_height(rows: usize) -> f64 {
    2.0 * LEGEND_PAD + rows as f64 * LEGEND_ROW - (LEGEND_ROW - LEGEND_FONT) / 2.0
}

/// A legend below the plot in as many columns as `max_width` holds.
fn below_block(fig: &Figure, entries: &[usize], max_width: f64) -> Below {
    let column_width = entries
        .iter()
        .map(|&i| entry_width(fig, i))
        .fold(0.0, f64::max);
    let room = max_width - 2.0 * OUTER_PAD - 2.0 * LEGEND_PAD;
    let fit = ((room + LEGEND_COLUMN_GAP) / (column_width + LEGEND_COLUMN_GAP)).floor();
    let columns = (fit.max(1.0) as usize).min(entries.len()).max(1);
    let rows = entries.len().div_ceil(columns);
    Below {
        columns,
        column_width,
        width: 2.0 * LEGEND_PAD
            + columns as f64 * column_width
            + (columns as f64 - 1.0) * LEGEND_COLUMN_GAP,
        height: legend_height(rows),
    }
}

/// Where the legend goes inside the plot, if it fits there (and, with [`Legend::Auto`], covers no
/// data there); `None` sends it below the plot.
fn inside_box(
    fig: &Figure,
    l: &Layout,
    entries: &[usize],
    pixels: &[Vec<Polylines>],
) -> Option<LegendBox> {
    let width = 2.0 * LEGEND_PAD
        + entries
            .iter()
            .map(|&i| entry_width(fig, i))
            .fold(0.0, f64::max);
    let height = legend_height(entries.len());
    let f = l.frame;
    if width > f.width - 2.0 * LEGEND_INSET || height > f.height - 2.0 * LEGEND_INSET {
        return None;
    }
    let left = f.left + LEGEND_INSET;
    let right = f.left + f.width - LEGEND_INSET - width;
    let top = f.top + LEGEND_INSET;
    let bottom = f.top + f.height - LEGEND_INSET - height;
    let at = |x, y| LegendBox {
        x,
        y,
        width,
        height,
        columns: 1,
        column_width: width - 2.0 * LEGEND_PAD,
    };
    let center = f.left + (f.width - width) / 2.0;
    let places = [
        (Legend::TopRight, right, top),
        (Legend::TopLeft, left, top),
        (Legend::BottomRight, right, bottom),
        (Legend::BottomLeft, left, bottom),
        (Legend::TopCenter, center, top),
        (Legend::BottomCenter, center, bottom),
    ];
    if let Some(&(_, x, y)) = places.iter().find(|c| c.0 == fig.legend) {
        return Some(at(x, y));
    }
    // Auto: the first place covering no point, sampled every few pixels along the lines.
    let covers = |x: f64, y: f64| {
        let (x0, x1, y0, y1) = (x - 4.0, x + width + 4.0, y - 4.0, y + height + 4.0);
        let hit = |p: (f64, f64)| p.0 >= x0 && p.0 <= x1 && p.1 >= y0 && p.1 <= y1;
        pixels.iter().flatten().flatten().any(|line| {
            line.iter().enumerate().any(|(i, &p)| {
                hit(p)
                    || line.get(i + 1).is_some_and(|&q| {
                        let len = (q.0 - p.0).hypot(q.1 - p.1);
                        let n = (len / 4.0).ceil().min(1000.0) as usize;
                        (1..n).any(|k| {
                            let t = k as f64 / n as f64;
                            hit((p.0 + t * (q.0 - p.0), p.1 + t * (q.1 - p.1)))
                        })
                    })
            })
        })
    };
    places
        .iter()
        .find(|&&(_, x, y)| !covers(x, y))
        .map(|&(_, x, y)| at(x, y))
}

/// A figure drawn as the inside of an `<svg>` element (or of a panel's group), and its size.
pub(crate) struct Body {
    pub svg: String,
    pub width: f64,
    pub height: f64,
}

/// What a panel needs to know of a figure before it is drawn: its own left margin and its x
/// extent in axis units.
pub(crate) fn measure(fig: &Figure, chrome: &Chrome) -> (f64, Option<(f64, f64)>) {
    let series = runs(fig);
    let l = layout(fig, &series, chrome, Outside::No);
    let all = series.iter().flat_map(|s| s.runs.iter().flatten());
    (l.natural_left, extent(all.map(|p| p.0)))
}

fn runs(fig: &Figure) -> Vec<Runs> {
    fig.series
        .iter()
        .map(|s| split_runs(&s.points, fig.x.log, fig.y.log))
        .collect()
}

pub(crate) fn render(fig: &Figure) -> String {
    let body = body(fig, &Chrome::default());
    let mut svg = String::new();
    let _ = writeln!(svg, r#"<?xml version="1.0" encoding="UTF-8"?>"#);
    let _ = writeln!(
        svg,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="{FONT_FAMILY}" fill="{TEXT_COLOR}">"#,
        w = num(body.width.ceil()),
        h = num(body.height.ceil())
    );
    if !fig.title.is_empty() {
        let _ = writeln!(svg, "<title>{}</title>", escape(&fig.title));
    }
    svg.push_str(&body.svg);
    let _ = writeln!(svg, "</svg>");
    svg
}

/// The pixels of every series: per series, per run of finite points, the visible polylines.
fn pixels(series: &[Runs], l: &Layout) -> Vec<Vec<Polylines>> {
    series
        .iter()
        .map(|s| s.runs.iter().map(|r| clipped_polylines(r, l)).collect())
        .collect()
}

/// Draws `fig` in its own coordinates, from `(0, 0)`.
pub(crate) fn body(fig: &Figure, chrome: &Chrome) -> Body {
    let series = runs(fig);
    let entries: Vec<usize> = (0..fig.series.len())
        .filter(|&i| !fig.series[i].name.is_empty())
        .collect();
    let mut l = layout(fig, &series, chrome, Outside::No);
    let mut pixels = pixels(&series, &l);
    let mut legend = None;
    if !entries.is_empty() && fig.legend != Legend::Hidden {
        legend = if matches!(fig.legend, Legend::Below | Legend::Right) {
            None
        } else {
            inside_box(fig, &l, &entries, &pixels)
        };
        let (width, height) = (
            2.0 * LEGEND_PAD
                + entries
                    .iter()
                    .map(|&i| entry_width(fig, i))
                    .fold(0.0, f64::max),
            legend_height(entries.len()),
        );
        let max_width = if fig.check_size() { fig.width } else { 720.0 };
        // Beside a plot narrowed by equal scales, if the requested width has room for it (or if
        // asked for).
        let beside = fig.legend == Legend::Right
            || (fig.legend == Legend::Auto
                && fig.equal_aspect
                && l.width + width + LEGEND_GAP <= max_width
                && height <= l.frame.height);
        if legend.is_none() && beside {
            l = layout(fig, &series, chrome, Outside::Right(width));
            pixels = self::pixels(&series, &l);
            let f = l.frame;
            legend = Some(LegendBox {
                x: f.left + f.width + LEGEND_GAP,
                y: f.top,
                width,
                height,
                columns: 1,
                column_width: width - 2.0 * LEGEND_PAD,
            });
        } else if legend.is_none() {
            // As many columns as the picture's width holds (a picture narrowed by equal scales
            // keeps its width if it can).
            let below = below_block(fig, &entries, l.width);
            l = layout(fig, &series, chrome, Outside::Below(below));
            pixels = self::pixels(&series, &l);
            let f = l.frame;
            let x = (f.left + (f.width - below.width) / 2.0)
                .min(l.width - OUTER_PAD - below.width)
                .max(OUTER_PAD);
            let label = if l.x_label { 10.0 + LABEL_FONT } else { 0.0 };
            legend = Some(LegendBox {
                x,
                y: f.top + f.height + TICK_LENGTH + 4.0 + TICK_FONT + label + LEGEND_GAP,
                width: below.width,
                height: below.height,
                columns: below.columns,
                column_width: below.column_width,
            });
        }
    }
    let f = l.frame;
    let looks = looks(fig);

    let mut svg = String::new();
    let id = clip_id(fig, &l, &chrome.salt);
    let _ = writeln!(
        svg,
        r#"<defs><clipPath id="{id}"><rect x="{}" y="{}" width="{}" height="{}"/></clipPath></defs>"#,
        num(f.left),
        num(f.top),
        num(f.width),
        num(f.height)
    );
    if chrome.background {
        let _ = writeln!(svg, r#"<rect width="100%" height="100%" fill="white"/>"#);
    }

    // Grid at the labelled ticks.
    let _ = writeln!(
        svg,
        r#"<g class="grid" stroke="{GRID_COLOR}" stroke-width="1">"#
    );
    for (p, _) in l.x.labels() {
        let x = f.px(&l.x, p);
        let _ = writeln!(
            svg,
            r#"<line x1="{x}" y1="{}" x2="{x}" y2="{}"/>"#,
            num(f.top),
            num(f.top + f.height),
            x = num(x)
        );
    }
    for (p, _) in l.y.labels() {
        let y = f.py(&l.y, p);
        let _ = writeln!(
            svg,
            r#"<line x1="{}" y1="{y}" x2="{}" y2="{y}"/>"#,
            num(f.left),
            num(f.left + f.width),
            y = num(y)
        );
    }
    let _ = writeln!(svg, "</g>");

    // Lines, clipped to the plot area.
    let _ = writeln!(svg, r#"<g class="lines" clip-path="url(#{id})">"#);
    for (i, s) in fig.series.iter().enumerate() {
        if !draws_line(&s.style) {
            continue;
        }
        // One path per run of finite points; a run cut by a fixed range has several subpaths.
        for lines in pixels[i].iter().filter(|p| !p.is_empty()) {
            let _ = writeln!(
                svg,
                r#"<path class="series" data-series="{i}" d="{}" {}/>"#,
                path_data(lines),
                stroke_attributes(&s.style, &looks[i])
            );
        }
    }
    let _ = writeln!(svg, "</g>");

    // Markers at the points inside the plot area.
    for (i, s) in fig.series.iter().enumerate() {
        if !s.style.markers {
            continue;
        }
        let r = marker_radius(&s.style);
        let _ = writeln!(
            svg,
            r#"<g class="markers" data-series="{i}" fill="none" stroke="{}" stroke-width="1.3">"#,
            escape(looks[i].color)
        );
        for &(a, b) in series[i].runs.iter().flatten() {
            let (fx, fy) = (l.x.fraction(a), l.y.fraction(b));
            let eps = 1e-3;
            if (-eps..=1.0 + eps).contains(&fx) && (-eps..=1.0 + eps).contains(&fy) {
                let (x, y) = f.at(fx, fy);
                let _ = writeln!(svg, "{}", marker(looks[i].shape, x, y, r));
            }
        }
        let _ = writeln!(svg, "</g>");
    }

    // Frame, ticks and tick labels.
    let _ = writeln!(
        svg,
        r#"<rect class="frame" x="{}" y="{}" width="{}" height="{}" fill="none" stroke="{FRAME_COLOR}" stroke-width="1"/>"#,
        num(f.left),
        num(f.top),
        num(f.width),
        num(f.height)
    );
    let _ = writeln!(
        svg,
        r#"<g class="ticks" stroke="{FRAME_COLOR}" stroke-width="1">"#
    );
    let bottom = f.top + f.height;
    for t in &l.x.ticks {
        let x = num(f.px(&l.x, t.pos));
        let len = if t.label.is_some() {
            TICK_LENGTH
        } else {
            MINOR_TICK_LENGTH
        };
        let _ = writeln!(
            svg,
            r#"<line x1="{x}" y1="{}" x2="{x}" y2="{}"/>"#,
            num(bottom),
            num(bottom + len)
        );
    }
    for t in &l.y.ticks {
        let y = num(f.py(&l.y, t.pos));
        let len = if t.label.is_some() {
            TICK_LENGTH
        } else {
            MINOR_TICK_LENGTH
        };
        let _ = writeln!(
            svg,
            r#"<line x1="{}" y1="{y}" x2="{}" y2="{y}"/>"#,
            num(f.left - len),
            num(f.left)
        );
    }
    let _ = writeln!(svg, "</g>");
    let _ = writeln!(svg, r#"<g class="tick-labels" font-size="{TICK_FONT}">"#);
    for (p, label) in l.x.labels() {
        let _ = writeln!(
            svg,
            r#"<text x="{}" y="{}" text-anchor="middle">{}</text>"#,
            num(f.px(&l.x, p)),
            num(bottom + TICK_LENGTH + 3.0 + TICK_FONT * 0.85),
            escape(label)
        );
    }
    for (p, label) in l.y.labels() {
        let _ = writeln!(
            svg,
            r#"<text x="{}" y="{}" text-anchor="end">{}</text>"#,
            num(f.left - TICK_LENGTH - 3.0),
            num(f.py(&l.y, p) + TICK_FONT * 0.35),
            escape(label)
        );
    }
    let _ = writeln!(svg, "</g>");

    // Title, note and axis labels.
    for (k, line) in l.title.iter().enumerate() {
        let _ = writeln!(
            svg,
            r#"<text class="title" x="{}" y="{}" text-anchor="middle" font-size="{}" font-weight="bold">{}</text>"#,
            num(l.width / 2.0),
            num(OUTER_PAD + l.title_font * (0.8 + LINE * k as f64)),
            num(l.title_font),
            escape(line)
        );
    }
    let note_top = OUTER_PAD + l.title.len() as f64 * l.title_font * LINE;
    for (k, line) in l.note.iter().enumerate() {
        let _ = writeln!(
            svg,
            r#"<text class="note" x="{}" y="{}" text-anchor="middle" font-size="{NOTE_FONT}" fill="{NOTE_COLOR}">{}</text>"#,
            num(l.width / 2.0),
            num(note_top + NOTE_FONT * (0.8 + LINE * k as f64)),
            escape(line)
        );
    }
    if l.x_label {
        let _ = writeln!(
            svg,
            r#"<text class="x-label" x="{}" y="{}" text-anchor="middle" font-size="{}">{}</text>"#,
            num(f.left + f.width / 2.0),
            num(bottom + TICK_LENGTH + 4.0 + TICK_FONT + 10.0 + LABEL_FONT * 0.8),
            num(l.x_label_font),
            escape(&fig.x.label)
        );
    }
    if !fig.y.label.is_empty() {
        let (x, y) = (l.y_label_x, f.top + f.height / 2.0);
        let _ = writeln!(
            svg,
            r#"<text class="y-label" x="{x}" y="{y}" transform="rotate(-90 {x} {y})" text-anchor="middle" font-size="{}">{}</text>"#,
            num(l.y_label_font),
            escape(&fig.y.label),
            x = num(x),
            y = num(y)
        );
    }

    // Legend.
    if let Some(b) = legend {
        let _ = writeln!(svg, r#"<g class="legend" font-size="{LEGEND_FONT}">"#);
        let _ = writeln!(
            svg,
            r##"<rect x="{}" y="{}" width="{}" height="{}" rx="3" fill="white" fill-opacity="0.88" stroke="#bbbbbb" stroke-width="1"/>"##,
            num(b.x),
            num(b.y),
            num(b.width),
            num(b.height)
        );
        for (e, &i) in entries.iter().enumerate() {
            let s = &fig.series[i];
            let (row, column) = (e / b.columns, e % b.columns);
            let cy = b.y + LEGEND_PAD + LEGEND_FONT / 2.0 + row as f64 * LEGEND_ROW;
            let x0 = b.x + LEGEND_PAD + column as f64 * (b.column_width + LEGEND_COLUMN_GAP);
            let x1 = x0 + LEGEND_SWATCH;
            if draws_line(&s.style) {
                let _ = writeln!(
                    svg,
                    r#"<line x1="{}" y1="{y}" x2="{}" y2="{y}" {}/>"#,
                    num(x0),
                    num(x1),
                    stroke_attributes(&s.style, &looks[i]),
                    y = num(cy)
                );
            }
            if s.style.markers {
                let m = marker(looks[i].shape, (x0 + x1) / 2.0, cy, marker_radius(&s.style));
                let _ = writeln!(
                    svg,
                    "{}",
                    m.replace(
                        "/>",
                        &format!(
                            r#" fill="none" stroke="{}" stroke-width="1.3"/>"#,
                            escape(looks[i].color)
                        )
                    )
                );
            }
            let _ = writeln!(
                svg,
                r#"<text x="{}" y="{}">{}</text>"#,
                num(x1 + 6.0),
                num(cy + LEGEND_FONT * 0.35),
                escape(&s.name)
            );
        }
        let _ = writeln!(svg, "</g>");
    }
    Body {
        svg,
        width: l.width,
        height: l.height,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn num_trims() {
        assert_eq!(num(1.0), "1");
        assert_eq!(num(1.5), "1.5");
        assert_eq!(num(-0.001), "0");
        assert_eq!(num(12.345), "12.35");
    }

    #[test]
    fn clipping() {
        // Inside: unchanged.
        assert_eq!(
            clip_segment((0.1, 0.1), (0.9, 0.5), 0.0, 1.0),
            Some(((0.1, 0.1), (0.9, 0.5)))
        );
        // Outside: nothing.
        assert_eq!(clip_segment((2.0, 2.0), (3.0, 5.0), 0.0, 1.0), None);
        // Through: cut at both sides.
        let (a, b) = clip_segment((-1.0, 0.5), (2.0, 0.5), 0.0, 1.0).expect("crosses");
        assert_eq!((a, b), ((0.0, 0.5), (1.0, 0.5)));
        // A huge excursion is cut to moderate numbers.
        let (_, b) = clip_segment((0.5, 0.5), (0.5, -1e30), -0.25, 1.25).expect("crosses");
        assert_eq!(b, (0.5, -0.25));
    }

    #[test]
    fn escaping() {
        assert_eq!(escape("a<b & \"c\""), "a&lt;b &amp; &quot;c&quot;");
    }
}
