//! Layout and SVG output of a [`Figure`].

use std::fmt::Write;

use crate::axis::{self, extent, text_width, Axis, Room};
use crate::{AxisSpec, Figure, Legend, Style, PALETTE};

const FONT_FAMILY: &str = "DejaVu Sans, Helvetica, Arial, sans-serif";
const TITLE_FONT: f64 = 16.0;
const LABEL_FONT: f64 = 14.0;
const TICK_FONT: f64 = 12.0;
const LEGEND_FONT: f64 = 12.0;
const TICK_LENGTH: f64 = 5.0;
const MINOR_TICK_LENGTH: f64 = 3.0;
const OUTER_PAD: f64 = 12.0;
/// Lines are clipped, in fractions of the plot area, to this much beyond it on every side before
/// the exact clip of the SVG viewer: the file then holds only coordinates of moderate size.
const CLIP_MARGIN: f64 = 0.25;
const FRAME_COLOR: &str = "#333333";
const GRID_COLOR: &str = "#e4e4e4";
const TEXT_COLOR: &str = "#222222";

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
    let (fixed, (lo, hi)) = match spec.fixed() {
        Some(r) => (true, r),
        None => (
            false,
            // Nothing to show: [0, 1], or [1, 10] on a log axis.
            data.unwrap_or((0.0, 1.0)),
        ),
    };
    if spec.log {
        axis::log(lo, hi, fixed, room)
    } else {
        axis::linear(lo, hi, fixed, room)
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

/// The page layout: canvas size, plot frame and both axes.
struct Layout {
    width: f64,
    height: f64,
    frame: Frame,
    x: Axis,
    y: Axis,
}

fn layout(fig: &Figure, series: &[Runs]) -> Layout {
    let (width, height) = if fig.check_size() {
        (fig.width, fig.height)
    } else {
        (720.0, 450.0)
    };
    let all = || series.iter().flat_map(|s| s.runs.iter().flatten());
    let x_data = extent(all().map(|p| p.0));
    let y_data = extent(all().map(|p| p.1));

    let top = if fig.title.is_empty() {
        OUTER_PAD + 4.0
    } else {
        OUTER_PAD + TITLE_FONT + 14.0
    };
    let bottom = TICK_LENGTH
        + 4.0
        + TICK_FONT
        + if fig.x.label.is_empty() {
            OUTER_PAD
        } else {
            10.0 + LABEL_FONT + OUTER_PAD
        };
    let y_label_room = if fig.y.label.is_empty() {
        0.0
    } else {
        LABEL_FONT + 10.0
    };

    // Two passes: the widths of the y tick labels set the left margin, which sets the plot width,
    // which sets the x ticks.
    let mut left = OUTER_PAD + y_label_room + 40.0 + TICK_LENGTH;
    let mut right = 20.0;
    let mut x = resolve(&fig.x, x_data, x_room(width - left - right));
    let mut y = resolve(&fig.y, y_data, y_room(height - top - bottom));
    for _ in 0..2 {
        let widest = y
            .labels()
            .map(|(_, l)| text_width(l, TICK_FONT))
            .fold(0.0, f64::max);
        left = OUTER_PAD + y_label_room + widest + TICK_LENGTH + 4.0;
        let last_x = x
            .labels()
            .filter(|(p, _)| (x.fraction(*p) - 1.0).abs() < 1e-9)
            .map(|(_, l)| text_width(l, TICK_FONT) / 2.0 + 4.0)
            .fold(0.0, f64::max);
        right = last_x.max(20.0);
        x = resolve(&fig.x, x_data, x_room(width - left - right));
        y = resolve(&fig.y, y_data, y_room(height - top - bottom));
    }
    let mut frame = Frame {
        left,
        top,
        width: (width - left - right).max(20.0),
        height: (height - top - bottom).max(20.0),
    };
    let (mut width, mut height) = (width, height);
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
        // Keep room for the title.
        let title_width = text_width(&fig.title, TITLE_FONT) + 2.0 * OUTER_PAD;
        if width < title_width {
            frame.left += (title_width - width) / 2.0;
            width = title_width;
        }
    }
    Layout {
        width,
        height,
        frame,
        x,
        y,
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
fn num(v: f64) -> String {
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
fn escape(text: &str) -> String {
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

/// The stroke attributes of a style in colour `color`.
fn stroke_attributes(style: &Style, color: &str) -> String {
    let mut s = format!(
        r#"fill="none" stroke="{}" stroke-width="{}" stroke-linejoin="round" stroke-linecap="round""#,
        escape(color),
        num(style.width)
    );
    if style.dashed {
        let dash = (4.0 * style.width).max(5.0);
        let gap = (2.5 * style.width).max(3.5);
        let _ = write!(s, r#" stroke-dasharray="{} {}""#, num(dash), num(gap));
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

/// Whether a style draws anything.
fn draws_line(style: &Style) -> bool {
    style.width > 0.0 && style.width.is_finite()
}

/// A short, stable identifier for the clip path, so that several figures inlined in one HTML page
/// do not share one (FNV-1a of the title and the layout).
fn clip_id(fig: &Figure, l: &Layout) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let key = format!(
        "{}|{}|{}|{}|{}|{}",
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

/// The legend's box: position and size in pixels.
struct LegendBox {
    x: f64,
    y: f64,
    width: f64,
    height: f64,
}

const LEGEND_ROW: f64 = LEGEND_FONT * 1.55;
const LEGEND_SWATCH: f64 = 28.0;
const LEGEND_PAD: f64 = 7.0;
const LEGEND_INSET: f64 = 8.0;

fn legend_box(
    fig: &Figure,
    l: &Layout,
    entries: &[usize],
    pixels: &[Vec<Polylines>],
) -> Option<LegendBox> {
    if entries.is_empty() || fig.legend == Legend::Hidden {
        return None;
    }
    let text = entries
        .iter()
        .map(|&i| text_width(&fig.series[i].name, LEGEND_FONT))
        .fold(0.0, f64::max);
    let width = LEGEND_PAD + LEGEND_SWATCH + 6.0 + text + LEGEND_PAD;
    let height =
        2.0 * LEGEND_PAD + entries.len() as f64 * LEGEND_ROW - (LEGEND_ROW - LEGEND_FONT) / 2.0;
    let f = l.frame;
    let left = f.left + LEGEND_INSET;
    let right = f.left + f.width - LEGEND_INSET - width;
    let top = f.top + LEGEND_INSET;
    let bottom = f.top + f.height - LEGEND_INSET - height;
    let at = |x, y| LegendBox {
        x,
        y,
        width,
        height,
    };
    let center = f.left + (f.width - width) / 2.0;
    let corners = [
        (Legend::TopRight, right, top),
        (Legend::TopLeft, left, top),
        (Legend::BottomRight, right, bottom),
        (Legend::BottomLeft, left, bottom),
        (Legend::TopCenter, center, top),
        (Legend::BottomCenter, center, bottom),
    ];
    if let Some(&(_, x, y)) = corners.iter().find(|c| c.0 == fig.legend) {
        return Some(at(x, y));
    }
    // Auto: the place covering the fewest points, sampled every few pixels along the lines.
    let covered = |x: f64, y: f64| {
        let (x0, x1, y0, y1) = (x - 4.0, x + width + 4.0, y - 4.0, y + height + 4.0);
        let hit = |p: (f64, f64)| p.0 >= x0 && p.0 <= x1 && p.1 >= y0 && p.1 <= y1;
        let mut count = 0usize;
        for line in pixels.iter().flatten().flatten() {
            for (i, &p) in line.iter().enumerate() {
                count += usize::from(hit(p));
                if let Some(&q) = line.get(i + 1) {
                    let len = (q.0 - p.0).hypot(q.1 - p.1);
                    let n = (len / 4.0).ceil().min(1000.0) as usize;
                    for k in 1..n {
                        let t = k as f64 / n as f64;
                        count += usize::from(hit((p.0 + t * (q.0 - p.0), p.1 + t * (q.1 - p.1))));
                    }
                }
            }
        }
        count
    };
    let mut best = (usize::MAX, right, top);
    for &(_, x, y) in &corners {
        let c = covered(x, y);
        if c < best.0 {
            best = (c, x, y);
        }
    }
    Some(at(best.1, best.2))
}

pub(crate) fn render(fig: &Figure) -> String {
    let series: Vec<Runs> = fig
        .series
        .iter()
        .map(|s| split_runs(&s.points, fig.x.log, fig.y.log))
        .collect();
    let l = layout(fig, &series);
    let f = l.frame;

    // Colours: the cycle advances only for series without their own colour.
    let mut next = 0;
    let colors: Vec<&str> = fig
        .series
        .iter()
        .map(|s| {
            s.style.color.unwrap_or_else(|| {
                let c = PALETTE[next % PALETTE.len()];
                next += 1;
                c
            })
        })
        .collect();
    // Per series, per run of finite points, the visible polylines in pixels.
    let pixels: Vec<Vec<Polylines>> = series
        .iter()
        .map(|s| s.runs.iter().map(|r| clipped_polylines(r, &l)).collect())
        .collect();

    let mut svg = String::new();
    let _ = writeln!(svg, r#"<?xml version="1.0" encoding="UTF-8"?>"#);
    let _ = writeln!(
        svg,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="{FONT_FAMILY}" fill="{TEXT_COLOR}">"#,
        w = num(l.width.ceil()),
        h = num(l.height.ceil())
    );
    if !fig.title.is_empty() {
        let _ = writeln!(svg, "<title>{}</title>", escape(&fig.title));
    }
    let id = clip_id(fig, &l);
    let _ = writeln!(
        svg,
        r#"<defs><clipPath id="{id}"><rect x="{}" y="{}" width="{}" height="{}"/></clipPath></defs>"#,
        num(f.left),
        num(f.top),
        num(f.width),
        num(f.height)
    );
    let _ = writeln!(svg, r#"<rect width="100%" height="100%" fill="white"/>"#);

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
                stroke_attributes(&s.style, colors[i])
            );
        }
    }
    let _ = writeln!(svg, "</g>");

    // Markers at the points inside the plot area.
    for (i, s) in fig.series.iter().enumerate() {
        if !s.style.markers {
            continue;
        }
        let r = num(marker_radius(&s.style));
        let _ = writeln!(
            svg,
            r#"<g class="markers" data-series="{i}" fill="none" stroke="{}" stroke-width="1.3">"#,
            escape(colors[i])
        );
        for &(a, b) in series[i].runs.iter().flatten() {
            let (fx, fy) = (l.x.fraction(a), l.y.fraction(b));
            let eps = 1e-3;
            if (-eps..=1.0 + eps).contains(&fx) && (-eps..=1.0 + eps).contains(&fy) {
                let (x, y) = f.at(fx, fy);
                let _ = writeln!(svg, r#"<circle cx="{}" cy="{}" r="{r}"/>"#, num(x), num(y));
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

    // Title and axis labels.
    if !fig.title.is_empty() {
        let _ = writeln!(
            svg,
            r#"<text class="title" x="{}" y="{}" text-anchor="middle" font-size="{TITLE_FONT}" font-weight="bold">{}</text>"#,
            num(l.width / 2.0),
            num(OUTER_PAD + TITLE_FONT * 0.8),
            escape(&fig.title)
        );
    }
    if !fig.x.label.is_empty() {
        let _ = writeln!(
            svg,
            r#"<text class="x-label" x="{}" y="{}" text-anchor="middle" font-size="{LABEL_FONT}">{}</text>"#,
            num(f.left + f.width / 2.0),
            num(l.height - OUTER_PAD - LABEL_FONT * 0.2),
            escape(&fig.x.label)
        );
    }
    if !fig.y.label.is_empty() {
        let (x, y) = (OUTER_PAD + LABEL_FONT * 0.8, f.top + f.height / 2.0);
        let _ = writeln!(
            svg,
            r#"<text class="y-label" x="{x}" y="{y}" transform="rotate(-90 {x} {y})" text-anchor="middle" font-size="{LABEL_FONT}">{}</text>"#,
            escape(&fig.y.label),
            x = num(x),
            y = num(y)
        );
    }

    // Legend.
    let entries: Vec<usize> = (0..fig.series.len())
        .filter(|&i| !fig.series[i].name.is_empty())
        .collect();
    if let Some(b) = legend_box(fig, &l, &entries, &pixels) {
        let _ = writeln!(svg, r#"<g class="legend" font-size="{LEGEND_FONT}">"#);
        let _ = writeln!(
            svg,
            r##"<rect x="{}" y="{}" width="{}" height="{}" rx="3" fill="white" fill-opacity="0.88" stroke="#bbbbbb" stroke-width="1"/>"##,
            num(b.x),
            num(b.y),
            num(b.width),
            num(b.height)
        );
        for (row, &i) in entries.iter().enumerate() {
            let s = &fig.series[i];
            let cy = b.y + LEGEND_PAD + LEGEND_FONT / 2.0 + row as f64 * LEGEND_ROW;
            let (x0, x1) = (b.x + LEGEND_PAD, b.x + LEGEND_PAD + LEGEND_SWATCH);
            if draws_line(&s.style) {
                let _ = writeln!(
                    svg,
                    r#"<line x1="{}" y1="{y}" x2="{}" y2="{y}" {}/>"#,
                    num(x0),
                    num(x1),
                    stroke_attributes(&s.style, colors[i]),
                    y = num(cy)
                );
            }
            if s.style.markers {
                let _ = writeln!(
                    svg,
                    r#"<circle cx="{}" cy="{}" r="{}" fill="none" stroke="{}" stroke-width="1.3"/>"#,
                    num((x0 + x1) / 2.0),
                    num(cy),
                    num(marker_radius(&s.style)),
                    escape(colors[i])
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
    let _ = writeln!(svg, "</svg>");
    svg
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
