//! Axis ranges and ticks: 1-2-5 steps on linear axes, decades on log axes, and tick labels.
//!
//! Everything here works in *axis units*: the data value on a linear axis, its base-10 logarithm on
//! a log axis.

/// Text metrics: an estimate of the width of `text` at `font_size` pixels. SVG text is rendered by
/// the viewer with a font we do not know, so layout uses the average advance of a sans-serif face
/// (about 0.6 em for digits and lower-case letters).
pub(crate) fn text_width(text: &str, font_size: f64) -> f64 {
    text.chars()
        .map(|c| match c {
            '.' | ',' | ':' | ';' | 'i' | 'j' | 'l' | '|' | '\'' | ' ' | '(' | ')' | '[' | ']' => {
                0.32
            }
            'f' | 't' | 'r' | 'I' => 0.4,
            'm' | 'w' | 'M' | 'W' | '—' => 0.9,
            '⁰' | '¹' | '²' | '³' | '⁴' | '⁵' | '⁶' | '⁷' | '⁸' | '⁹' | '⁻' => {
                0.4
            }
            // Combining marks (the dot of ẋ written as x + U+0307) take no room.
            '\u{0300}'..='\u{036F}' => 0.0,
            c if c.is_uppercase() => 0.7,
            _ => 0.6,
        })
        .sum::<f64>()
        * font_size
}

/// One tick: its position in axis units and its label (`None` for a minor, unlabelled tick).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Tick {
    pub pos: f64,
    pub label: Option<String>,
}

/// A labelled tick at each of `positions`, with the label beside it.
fn labelled(positions: &[f64], labels: Vec<String>) -> Vec<Tick> {
    positions
        .iter()
        .zip(labels)
        .map(|(&pos, label)| Tick {
            pos,
            label: Some(label),
        })
        .collect()
}

/// A resolved axis: the range in axis units and the ticks inside it.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Axis {
    pub log: bool,
    /// Lower end, in axis units.
    pub lo: f64,
    /// Upper end, in axis units.
    pub hi: f64,
    pub ticks: Vec<Tick>,
}

impl Axis {
    /// Maps a data value to axis units: itself, or `log10` on a log axis (`None` for a value a log
    /// axis cannot show, or a non-finite value).
    pub fn to_axis_units(log: bool, v: f64) -> Option<f64> {
        if !v.is_finite() {
            None
        } else if log {
            (v > 0.0).then(|| v.log10())
        } else {
            Some(v)
        }
    }

    /// The position of `a` (axis units) as a fraction of the axis length, 0 at `lo`, 1 at `hi`.
    pub fn fraction(&self, a: f64) -> f64 {
        (a - self.lo) / (self.hi - self.lo)
    }

    /// The labelled ticks.
    pub fn labels(&self) -> impl Iterator<Item = (f64, &str)> {
        self.ticks
            .iter()
            .filter_map(|t| t.label.as_deref().map(|l| (t.pos, l)))
    }
}

/// How ticks are spaced on the page: the axis length in pixels, the least distance between two
/// labelled ticks, and how much room a label takes along the axis (its width on a horizontal axis,
/// its height on a vertical one).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Room {
    pub length_px: f64,
    pub min_spacing_px: f64,
    pub font_size: f64,
    pub horizontal: bool,
}

impl Room {
    fn label_extent(&self, label: &str) -> f64 {
        if self.horizontal {
            text_width(label, self.font_size) + 0.8 * self.font_size
        } else {
            1.6 * self.font_size
        }
    }

    /// Whether labelled ticks `spacing` pixels apart leave room for the widest of `labels`.
    fn fits<'a>(&self, spacing: f64, labels: impl Iterator<Item = &'a str>) -> bool {
        let widest = labels.map(|l| self.label_extent(l)).fold(0.0, f64::max);
        spacing >= self.min_spacing_px.max(widest)
    }
}

/// The extent `[lo, hi]` of finite values, `None` if there are none.
pub(crate) fn extent(values: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    values
        .filter(|v| v.is_finite())
        .fold(None, |acc, v| match acc {
            None => Some((v, v)),
            Some((lo, hi)) => Some((lo.min(v), hi.max(v))),
        })
}

/// Widens a degenerate or overflowing extent into a usable one: a single value `v` becomes
/// `v ± max(|v|/2, 1)` on a linear axis and `v ± 1` decade on a log axis (axis units either way).
fn usable(lo: f64, hi: f64, log: bool) -> (f64, f64) {
    let (lo, hi) = if hi - lo > 0.0 && (hi - lo).is_finite() {
        (lo, hi)
    } else if hi - lo > 0.0 {
        // The span overflows: keep both ends within half the largest float.
        (lo.max(-f64::MAX / 4.0), hi.min(f64::MAX / 4.0))
    } else {
        let d = if log { 1.0 } else { (0.5 * lo.abs()).max(1.0) };
        (lo - d, hi + d)
    };
    if hi - lo > 0.0 {
        (lo, hi)
    } else {
        // A value so large that ± d rounds away: fall back to a range around it by scaling.
        (lo - lo.abs() * 0.5, hi + hi.abs() * 0.5)
    }
}

/// The relative span below which an automatic linear range is one value.
const ROUNDING: f64 = 1e-12;

/// The margin of automatic ranges unless a figure sets its own: this fraction of the data's span
/// (in axis units, so decades on a log axis) on each side, as matplotlib's default.
pub(crate) const MARGIN: f64 = 0.05;

/// A "nice" step: `m · 10^k` with `m ∈ {1, 2, 5}`, in increasing order from the first one not
/// smaller than `start`.
fn nice_steps(start: f64) -> impl Iterator<Item = f64> {
    let k0 = if start > 0.0 && start.is_finite() {
        start.log10().floor() as i32 - 1
    } else {
        0
    };
    (k0..k0 + 40).flat_map(|k| [1.0, 2.0, 5.0].map(|m| m * exp10(k)))
}

/// `10^k`, also below `1e-308`, where `powi` forms it as `1/10^(−k)`, whose divisor overflows:
/// there as two factors, the last a subnormal number.
fn exp10(k: i32) -> f64 {
    if k >= -300 {
        10f64.powi(k)
    } else {
        10f64.powi(k + 300) * 1e-300
    }
}

/// How an axis gets its range: as given, or from the data's extent with a margin.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Span {
    /// The range is `[lo, hi]` exactly.
    Fixed,
    /// The data's extent `[lo, hi]`, widened on each side by this fraction of its span.
    Auto(f64),
}

/// `[lo, hi]` widened on each side by `margin` times its span (a margin that is not a finite
/// non-negative number counts as none), kept within half the largest float.
fn padded(lo: f64, hi: f64, margin: f64) -> (f64, f64) {
    let margin = if margin.is_finite() && margin > 0.0 {
        margin
    } else {
        0.0
    };
    let pad = (hi - lo) * margin;
    let (a, b) = (lo - pad, hi + pad);
    if a.is_finite() && b.is_finite() && b > a {
        (a.max(-f64::MAX / 4.0), b.min(f64::MAX / 4.0))
    } else {
        (lo, hi)
    }
}

/// Chooses a linear axis: a 1-2-5 step whose labelled ticks are at least the room's spacing
/// apart. An automatic range is the data's extent widened by the margin, so no point lies on the
/// frame; its ends need not be ticks, and at least two ticks fall inside it. A fixed range is kept.
pub(crate) fn linear(lo: f64, hi: f64, span: Span, room: Room) -> Axis {
    let fixed = span == Span::Fixed;
    // Automatic ranges: values that differ by rounding only (a span below 1e-12 of their size, a
    // few units in the last place) are one value, drawn flat, not their rounding noise on tick
    // labels of fifteen digits.
    let (lo, hi) = if !fixed && hi - lo <= ROUNDING * lo.abs().max(hi.abs()) {
        let mid = lo + (hi - lo) / 2.0;
        (mid, mid)
    } else {
        (lo, hi)
    };
    let (lo, hi) = usable(lo, hi, false);
    let (a, b) = match span {
        Span::Fixed => (lo, hi),
        Span::Auto(margin) => padded(lo, hi, margin),
    };
    let start = (b - a) / 60.0;
    let mut fallback = None;
    for step in nice_steps(start) {
        let first = (a / step - 1e-9).ceil();
        let last = (b / step + 1e-9).floor();
        let count = last - first + 1.0;
        if !(count.is_finite() && count <= 60.0) {
            continue;
        }
        let values: Vec<f64> = (0..count.max(0.0) as usize)
            .map(|i| (first + i as f64) * step)
            .collect();
        let labels = format_linear(&values, step);
        let spacing = room.length_px * step / (b - a);
        let ticks = labelled(&values, labels);
        let axis = Axis {
            log: false,
            lo: a,
            hi: b,
            ticks,
        };
        if room.fits(spacing, axis.labels().map(|(_, l)| l)) && (count >= 2.0 || fixed) {
            return axis;
        }
        if count >= 1.0 || fallback.is_none() {
            fallback = Some(axis);
        }
        if count <= 2.0 {
            // Larger steps only lose ticks.
            break;
        }
    }
    fallback.unwrap_or(Axis {
        log: false,
        lo: a,
        hi: b,
        ticks: Vec::new(),
    })
}

/// Chooses a log axis (axis units are decades): labelled ticks at every `k`-th decade for the
/// smallest `k` in 1, 2, 5, 10, ... that leaves room, with unlabelled ticks at 2…9 times each
/// decade while those are at least 2.5 px apart. An automatic range is the data's extent in
/// decades widened by the margin; it does not reach out to whole decades. A range holding fewer
/// than two decades gets ticks at 1-2-5 (or 1-3, or 1) times powers of ten instead.
pub(crate) fn log(lo: f64, hi: f64, span: Span, room: Room) -> Axis {
    let (lo, hi) = usable(lo, hi, true);
    let (a, b) = match span {
        Span::Fixed => (lo, hi),
        Span::Auto(margin) => padded(lo, hi, margin),
    };
    let mut chosen: Option<(f64, Vec<f64>, Vec<String>)> = None;
    for k in [1.0, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0] {
        let first = (a / k - 1e-9).ceil();
        let last = (b / k + 1e-9).floor();
        let count = last - first + 1.0;
        if !count.is_finite() || count > 400.0 {
            continue;
        }
        if count < 2.0 && chosen.is_some() {
            // Thinner decades would leave one label: keep the crowded choice.
            break;
        }
        let decades: Vec<f64> = (0..count.max(0.0) as usize)
            .map(|i| (first + i as f64) * k)
            .collect();
        let spacing = room.length_px * k / (b - a);
        let labels: Vec<String> = decades.iter().map(|&d| power_of_ten(d)).collect();
        let fits = room.fits(spacing, labels.iter().map(String::as_str));
        chosen = Some((k, decades, labels));
        if fits || k >= 100.0 {
            break;
        }
    }
    let Some((k, decades, labels)) = chosen else {
        return Axis {
            log: true,
            lo: a,
            hi: b,
            ticks: Vec::new(),
        };
    };
    if decades.len() < 2 {
        return log_narrow(a, b, room);
    }
    let mut ticks = labelled(&decades, labels);
    // Minor ticks at 2..9 × 10^d, if decades are labelled one by one and they fit.
    if k == 1.0 {
        ticks.extend(minor_log_ticks(a, b, room, &[1.0]));
    }
    Axis {
        log: true,
        lo: a,
        hi: b,
        ticks,
    }
}

/// Unlabelled ticks at `m × 10^d` (`m` = 1…9, leaving out the mantissas `labelled`) inside
/// `[a, b]` (decades), while the closest of them (9 and 10) are at least 2.5 px apart.
fn minor_log_ticks(a: f64, b: f64, room: Room, labelled: &[f64]) -> Vec<Tick> {
    let px_per_decade = room.length_px / (b - a);
    let mut ticks = Vec::new();
    if px_per_decade * (10f64.log10() - 9f64.log10()) < 2.5 {
        return ticks;
    }
    for d in a.floor() as i64..b.ceil() as i64 + 1 {
        for m in 1..10 {
            let m = f64::from(m);
            if labelled.contains(&m) {
                continue;
            }
            let pos = d as f64 + m.log10();
            if pos >= a - 1e-12 && pos <= b + 1e-12 {
                ticks.push(Tick { pos, label: None });
            }
        }
    }
    ticks
}

/// A log range holding fewer than two decades: labelled ticks at 1-2-5 multiples of powers of ten,
/// or at 1-3 or at 1 times them where those crowd, if at least two fall inside; otherwise linear
/// 1-2-5 ticks of the values, placed logarithmically. The other multiples 2…9 get unlabelled ticks
/// where they fit.
fn log_narrow(a: f64, b: f64, room: Room) -> Axis {
    let at = |mantissas: &[f64]| -> Vec<Tick> {
        let mut ticks = Vec::new();
        for d in a.floor() as i64..=b.ceil() as i64 {
            for &m in mantissas {
                let pos = d as f64 + f64::log10(m);
                if pos >= a - 1e-12 && pos <= b + 1e-12 {
                    let value = m * exp10(d as i32);
                    let label = if m == 1.0 && !(1e-3..1e6).contains(&value) {
                        power_of_ten(d as f64)
                    } else {
                        format_single(value, value)
                    };
                    ticks.push(Tick {
                        pos,
                        label: Some(label),
                    });
                }
            }
        }
        ticks
    };
    let px = |pos: f64| room.length_px * (pos - a) / (b - a);
    let sets: [&[f64]; 3] = [&[1.0, 2.0, 5.0], &[1.0, 3.0], &[1.0]];
    let mut fallback = None;
    for mantissas in sets {
        let ticks = at(mantissas);
        if ticks.len() < 2 {
            continue;
        }
        let fits = ticks.windows(2).all(|w| {
            let spacing = px(w[1].pos) - px(w[0].pos);
            room.fits(
                spacing,
                w.iter()
                    .filter_map(|t| t.label.as_deref())
                    .collect::<Vec<_>>()
                    .into_iter(),
            )
        });
        fallback = Some((ticks, mantissas));
        if fits {
            break;
        }
    }
    // The first set that fits, else the sparsest of at least two ticks, else linear ticks.
    let ticks = match fallback {
        Some((mut ticks, mantissas)) => {
            ticks.extend(minor_log_ticks(a, b, room, mantissas));
            ticks.sort_by(|p, q| p.pos.total_cmp(&q.pos));
            ticks
        }
        None => {
            let (lo, hi) = (10f64.powf(a), 10f64.powf(b));
            linear(lo, hi, Span::Fixed, room)
                .ticks
                .into_iter()
                .filter(|t| t.pos > 0.0)
                .map(|t| Tick {
                    pos: t.pos.log10(),
                    label: t.label,
                })
                .collect()
        }
    };
    Axis {
        log: true,
        lo: a,
        hi: b,
        ticks,
    }
}

const SUPERSCRIPTS: [char; 10] = ['⁰', '¹', '²', '³', '⁴', '⁵', '⁶', '⁷', '⁸', '⁹'];

/// `10^d` written with superscript digits, e.g. `10⁻¹²`.
pub(crate) fn power_of_ten(d: f64) -> String {
    let d = d.round() as i64;
    let mut s = String::from("10");
    if d < 0 {
        s.push('⁻');
    }
    for c in d.unsigned_abs().to_string().chars() {
        let digit = c.to_digit(10).unwrap_or(0) as usize;
        s.push(SUPERSCRIPTS[digit]);
    }
    s
}

/// Replaces the ASCII hyphen of a negative number by the typographic minus sign.
fn minus(s: String) -> String {
    if let Some(rest) = s.strip_prefix('-') {
        format!("−{rest}")
    } else {
        s
    }
}

/// Labels of equally spaced tick values `step` apart: fixed-point with as many decimals as the
/// step needs, or, for very large or very small magnitudes, `m×10ⁿ` with one common exponent.
pub(crate) fn format_linear(values: &[f64], step: f64) -> Vec<String> {
    let largest = values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let step_exp = step.abs().log10().floor() as i32;
    let scientific = largest >= 1e6 || (largest > 0.0 && largest < 1e-3);
    values
        .iter()
        .map(|&v| {
            // Snap values within rounding of zero to zero.
            let v = if v.abs() < 1e-9 * step.abs() { 0.0 } else { v };
            if v == 0.0 {
                return "0".to_string();
            }
            if scientific {
                let e = largest.log10().floor() as i32;
                let decimals = (e - step_exp).clamp(0, 15) as usize;
                let m = v / exp10(e);
                let mantissa = minus(format!("{m:.decimals$}"));
                format!("{mantissa}×{}", power_of_ten(f64::from(e)))
            } else {
                let decimals = (-step_exp).clamp(0, 15) as usize;
                minus(format!("{v:.decimals$}"))
            }
        })
        .collect()
}

/// The label of one value with the precision of `resolution`.
fn format_single(value: f64, resolution: f64) -> String {
    format_linear(&[value], resolution)
        .pop()
        .unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;

    const AUTO: Span = Span::Auto(MARGIN);

    fn room(px: f64) -> Room {
        Room {
            length_px: px,
            min_spacing_px: 60.0,
            font_size: 12.0,
            horizontal: true,
        }
    }

    /// Whether `step` is `m · 10^k` with `m ∈ {1, 2, 5}`.
    fn is_nice(step: f64) -> bool {
        let k = step.log10().floor();
        let m = step / 10f64.powf(k);
        [1.0, 2.0, 5.0, 10.0]
            .iter()
            .any(|n| (m - n).abs() < 1e-9 * n)
    }

    #[test]
    fn linear_ticks_are_nice_and_cover_the_data() {
        for &(lo, hi) in &[
            (0.0, 1.085),
            (0.0, 10.0),
            (-0.397, 0.0),
            (3.2e-7, 9.1e-7),
            (-1234.5, 98765.0),
            (1.0, 1.0),
            (-1e300, 1e300),
            (0.999_999, 1.000_001),
        ] {
            let axis = linear(lo, hi, AUTO, room(600.0));
            assert!(axis.lo < lo && axis.hi > hi, "{lo} {hi}: {axis:?}");
            assert!(axis.ticks.len() >= 2, "{lo} {hi}: {axis:?}");
            let pos: Vec<f64> = axis.ticks.iter().map(|t| t.pos).collect();
            let step = pos[1] - pos[0];
            assert!(is_nice(step), "step {step} for [{lo}, {hi}]");
            // The exact nice step, free of the cancellation in the difference.
            let k = step.log10().floor();
            let step = (step / 10f64.powf(k)).round() * 10f64.powf(k);
            for w in pos.windows(2) {
                assert!(((w[1] - w[0]) - step).abs() <= 1e-6 * step.abs());
            }
            for p in &pos {
                let r = p / step;
                assert!(
                    (r - r.round()).abs() < 1e-6 * r.abs().max(1.0),
                    "{p} not a multiple of {step}"
                );
                assert!(*p >= axis.lo && *p <= axis.hi, "tick {p} outside {axis:?}");
            }
        }
    }

    #[test]
    fn automatic_ranges_have_a_five_per_cent_margin() {
        let axis = linear(0.0, 10.0, AUTO, room(600.0));
        assert_eq!((axis.lo, axis.hi), (-0.5, 10.5));
        let axis = linear(-1e-16, 10.0, Span::Auto(0.0), room(600.0));
        assert_eq!((axis.lo, axis.hi), (-1e-16, 10.0));
        // On a log axis the margin is in decades: 2 … 24 is 1.08 decades.
        let (lo, hi) = (2f64.log10(), 24f64.log10());
        let axis = log(lo, hi, AUTO, room(600.0));
        let pad = 0.05 * (hi - lo);
        assert!((axis.lo - (lo - pad)).abs() < 1e-12 && (axis.hi - (hi + pad)).abs() < 1e-12);
    }

    #[test]
    fn linear_labels() {
        let axis = linear(0.0, 1.085, AUTO, room(600.0));
        let labels: Vec<&str> = axis.labels().map(|(_, l)| l).collect();
        assert_eq!(labels, ["0", "0.2", "0.4", "0.6", "0.8", "1.0"]);
        let axis = linear(-0.5, 0.0, AUTO, room(300.0));
        assert!(
            axis.labels().all(|(_, l)| !l.contains('-')),
            "uses the minus sign"
        );
        assert!(axis.labels().any(|(_, l)| l.starts_with('−')));
        assert_eq!(
            format_linear(&[0.0, 2e-5, 4e-5], 2e-5),
            ["0", "2×10⁻⁵", "4×10⁻⁵"]
        );
        assert_eq!(format_linear(&[1e6, 1.5e6], 5e5), ["1.0×10⁶", "1.5×10⁶"]);
    }

    #[test]
    fn narrow_screen_gets_fewer_ticks() {
        let wide = linear(0.0, 100.0, AUTO, room(800.0));
        let narrow = linear(0.0, 100.0, AUTO, room(150.0));
        assert!(narrow.ticks.len() < wide.ticks.len());
        assert!(narrow.ticks.len() >= 2);
    }

    #[test]
    fn fixed_ranges_are_kept() {
        let axis = linear(-15.7, 15.7, Span::Fixed, room(600.0));
        assert_eq!((axis.lo, axis.hi), (-15.7, 15.7));
        assert!(axis.ticks.iter().all(|t| t.pos >= -15.7 && t.pos <= 15.7));
        assert!(axis.labels().any(|(_, l)| l == "0"));
    }

    #[test]
    fn log_ticks_are_decades_inside_a_range_that_fits_the_data() {
        let axis = log(-15.3, -11.2, AUTO, room(400.0));
        // 4.1 decades and 5 % of them on each side, not the whole decades 10⁻¹⁶ … 10⁻¹¹.
        assert!((axis.lo - (-15.3 - 0.205)).abs() < 1e-12, "{axis:?}");
        assert!((axis.hi - (-11.2 + 0.205)).abs() < 1e-12, "{axis:?}");
        let labelled: Vec<(f64, &str)> = axis.labels().collect();
        assert_eq!(labelled.len(), 5);
        for (pos, label) in &labelled {
            assert_eq!(pos.fract(), 0.0);
            assert!(label.starts_with("10⁻"), "{label}");
        }
        assert_eq!(labelled[0].1, "10⁻¹⁵");
        // Minor ticks at 2..9 × 10^d, also below the first decade.
        assert!(axis
            .ticks
            .iter()
            .any(|t| t.label.is_none() && (t.pos - (-16.0 + 5f64.log10())).abs() < 1e-12));
        assert!(axis
            .ticks
            .iter()
            .all(|t| t.pos >= axis.lo && t.pos <= axis.hi));
    }

    #[test]
    fn a_log_range_of_about_one_decade_gets_one_two_five_ticks() {
        // n = 2 … 24, as a cost against the number of coordinates.
        let axis = log(2f64.log10(), 24f64.log10(), AUTO, room(600.0));
        let labels: Vec<&str> = axis.labels().map(|(_, l)| l).collect();
        assert_eq!(labels, ["2", "5", "10", "20"]);
        let axis = log(-7.0 + 2f64.log10(), -6.0 + 8f64.log10(), AUTO, room(400.0));
        let labels: Vec<&str> = axis.labels().map(|(_, l)| l).collect();
        assert_eq!(labels, ["2×10⁻⁷", "5×10⁻⁷", "10⁻⁶", "2×10⁻⁶", "5×10⁻⁶"]);
        // Crowded: 1 and 3.
        let axis = log(2f64.log10(), 24f64.log10(), AUTO, room(120.0));
        let labels: Vec<&str> = axis.labels().map(|(_, l)| l).collect();
        assert_eq!(labels, ["3", "10"]);
    }

    #[test]
    fn many_decades_are_thinned() {
        let axis = log(-300.0, 300.0, AUTO, room(300.0));
        let pos: Vec<f64> = axis.labels().map(|(p, _)| p).collect();
        let step = pos[1] - pos[0];
        assert!(step > 1.0 && is_nice(step), "{step}");
        assert!(
            axis.ticks.iter().all(|t| t.label.is_some()),
            "no minor ticks when thinned"
        );
    }

    #[test]
    fn narrow_fixed_log_range() {
        let axis = log(2f64.log10(), 8f64.log10(), Span::Fixed, room(400.0));
        let labels: Vec<&str> = axis.labels().map(|(_, l)| l).collect();
        assert_eq!(labels, ["2", "5"]);
    }

    #[test]
    fn superscripts() {
        assert_eq!(power_of_ten(-12.0), "10⁻¹²");
        assert_eq!(power_of_ten(0.0), "10⁰");
        assert_eq!(power_of_ten(3.0), "10³");
    }
}
