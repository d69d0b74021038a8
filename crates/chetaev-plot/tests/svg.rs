//! The SVG output, parsed back: well-formed, one path per run of finite points, log axes, gaps,
//! nice ticks, legend, ranges and errors.

use std::f64::consts::{FRAC_PI_2, PI};

use chetaev_plot::{thin, Figure, Legend, Panels, PlotError, Style};

/// Parses the SVG (which fails on any malformed XML) and returns it.
fn parse(svg: &str) -> roxmltree::Document<'_> {
    roxmltree::Document::parse(svg).unwrap_or_else(|e| panic!("malformed SVG: {e}\n{svg}"))
}

/// The `<path class="series">` elements.
fn series_paths<'a>(doc: &'a roxmltree::Document<'a>) -> Vec<roxmltree::Node<'a, 'a>> {
    doc.descendants()
        .filter(|n| n.has_tag_name("path") && n.attribute("class") == Some("series"))
        .collect()
}

/// The numbers in a path's `d` attribute, as (x, y) pairs.
fn path_points(d: &str) -> Vec<(f64, f64)> {
    let cleaned: String = d
        .chars()
        .map(|c| if c.is_ascii_alphabetic() { ' ' } else { c })
        .collect();
    let nums: Vec<f64> = cleaned
        .split_whitespace()
        .map(|s| {
            s.parse::<f64>()
                .unwrap_or_else(|_| panic!("not a number: {s} in {d}"))
        })
        .collect();
    nums.chunks(2).map(|c| (c[0], c[1])).collect()
}

/// The texts of elements inside `<g class="…">`.
fn texts_in(doc: &roxmltree::Document<'_>, class: &str) -> Vec<String> {
    doc.descendants()
        .filter(|n| n.has_tag_name("g") && n.attribute("class") == Some(class))
        .flat_map(|g| g.children().filter(|c| c.has_tag_name("text")))
        .map(|t| t.text().unwrap_or_default().to_string())
        .collect()
}

/// Tick labels as numbers (the minus sign and `m×10ⁿ` understood).
fn label_value(label: &str) -> f64 {
    let s = label.replace('−', "-");
    if let Some((m, e)) = s.split_once("×10") {
        m.parse::<f64>().expect("mantissa") * 10f64.powi(superscript(e))
    } else if let Some(e) = s
        .strip_prefix("10")
        .filter(|e| !e.is_empty() && !e.starts_with(|c: char| c.is_ascii_digit()))
    {
        10f64.powi(superscript(e))
    } else {
        s.parse().unwrap_or_else(|_| panic!("label {label}"))
    }
}

fn superscript(e: &str) -> i32 {
    let mut sign = 1;
    let mut v = 0;
    for c in e.chars() {
        match c {
            '⁻' => sign = -1,
            c => {
                let d = "⁰¹²³⁴⁵⁶⁷⁸⁹"
                    .chars()
                    .position(|s| s == c)
                    .expect("superscript digit");
                v = 10 * v + d as i32;
            }
        }
    }
    sign * v
}

fn sine(n: usize) -> Vec<(f64, f64)> {
    (0..n)
        .map(|i| {
            let x = i as f64 / (n - 1) as f64 * 6.0;
            (x, x.sin())
        })
        .collect()
}

#[test]
fn well_formed_with_title_labels_and_legend() {
    let fig = Figure::new("A & B <test>")
        .x_label("t [s]")
        .y_label("μ [kg/s]")
        .line("sin", &sine(50))
        .line_styled(
            "markers \"only\"",
            &sine(7),
            Style {
                width: 0.0,
                markers: true,
                ..Style::default()
            },
        )
        .line_styled(
            "",
            &[(0.0, 0.0), (6.0, 0.0)],
            Style {
                dashed: true,
                color: Some("black"),
                ..Style::default()
            },
        );
    let svg = fig.to_svg();
    let doc = parse(&svg);
    let root = doc.root_element();
    assert!(root.has_tag_name("svg"));
    assert!(root.attribute("viewBox").is_some());
    let all_text: String = doc
        .descendants()
        .filter(|n| n.is_text())
        .filter_map(|n| n.text())
        .collect();
    assert!(all_text.contains("A & B <test>"));
    assert!(all_text.contains("μ [kg/s]") && all_text.contains("t [s]"));
    // The legend names only the named series.
    let legend = texts_in(&doc, "legend");
    assert_eq!(legend, ["sin", "markers \"only\""]);
    // Markers: 7 circles in the plot for the marker series.
    let markers = doc
        .descendants()
        .filter(|n| n.attribute("class") == Some("markers"))
        .flat_map(|g| g.children().filter(|c| c.has_tag_name("circle")))
        .count();
    assert_eq!(markers, 7);
    // Two lines drawn (the marker-only series has no path), the dashed one in its colour.
    let paths = series_paths(&doc);
    assert_eq!(paths.len(), 2);
    assert!(paths[1].attribute("stroke-dasharray").is_some());
    assert_eq!(paths[1].attribute("stroke"), Some("black"));
    assert!(!svg.contains("NaN") && !svg.contains("inf"));
}

#[test]
fn one_path_per_run_of_finite_points() {
    let mut pts = sine(30);
    pts[10].1 = f64::NAN;
    pts[20].0 = f64::INFINITY;
    pts[21].1 = f64::NEG_INFINITY;
    let svg = Figure::new("gaps").line("with gaps", &pts).to_svg();
    let doc = parse(&svg);
    let paths = series_paths(&doc);
    assert_eq!(paths.len(), 3, "runs 0..10, 11..20, 22..30");
    let counts: Vec<usize> = paths
        .iter()
        .map(|p| path_points(p.attribute("d").expect("d")).len())
        .collect();
    assert_eq!(counts, [10, 9, 8]);
    assert!(!svg.contains("NaN") && !svg.to_lowercase().contains("inf"));

    // Leading, trailing and repeated gaps produce no empty paths.
    let pts = [
        (f64::NAN, 1.0),
        (0.0, 0.0),
        (1.0, 1.0),
        (f64::NAN, f64::NAN),
        (f64::NAN, 2.0),
        (2.0, 0.0),
        (3.0, 1.0),
        (4.0, f64::NAN),
    ];
    let doc_svg = Figure::new("").line("", &pts).to_svg();
    assert_eq!(series_paths(&parse(&doc_svg)).len(), 2);

    // Nothing finite: no path, still a valid document.
    let svg = Figure::new("empty")
        .line("nan", &[(f64::NAN, f64::NAN)])
        .line("none", &[])
        .to_svg();
    assert_eq!(series_paths(&parse(&svg)).len(), 0);
}

#[test]
fn isolated_point_is_a_dot() {
    let pts = [
        (0.0, 0.0),
        (f64::NAN, 0.0),
        (1.0, 1.0),
        (f64::NAN, 0.0),
        (2.0, 0.0),
        (3.0, 1.0),
    ];
    let svg = Figure::new("").line("", &pts).to_svg();
    let doc = parse(&svg);
    let paths = series_paths(&doc);
    assert_eq!(paths.len(), 3);
    assert!(paths[0].attribute("d").expect("d").ends_with("l0 0"));
}

#[test]
fn log_axes_drop_non_positive_points() {
    let pts = [
        (1.0, 1e-3),
        (2.0, 0.0),
        (3.0, -5.0),
        (4.0, 1e-1),
        (5.0, 1e2),
    ];
    let svg = Figure::new("log").log_y().line("r", &pts).to_svg();
    let doc = parse(&svg);
    let paths = series_paths(&doc);
    assert_eq!(paths.len(), 1, "dropped points do not break the line");
    assert_eq!(path_points(paths[0].attribute("d").expect("d")).len(), 3);
    // Decade ticks cover the data: 10⁻³ … 10².
    let labels: Vec<f64> = texts_in(&doc, "tick-labels")
        .iter()
        .map(|l| label_value(l))
        .collect();
    for d in -3..=2 {
        let v = 10f64.powi(d);
        assert!(
            labels.iter().any(|l| (l / v - 1.0).abs() < 1e-12),
            "missing 10^{d}: {labels:?}"
        );
    }

    // Log x as well: the point at x = 0 is dropped.
    let pts = [(0.0, 1.0), (1e-6, 2.0), (1e-3, 3.0), (1.0, 4.0)];
    let svg = Figure::new("").log_x().line("", &pts).to_svg();
    let doc = parse(&svg);
    assert_eq!(
        path_points(series_paths(&doc)[0].attribute("d").expect("d")).len(),
        3
    );

    // Only non-positive values: nothing drawn, still well-formed with decade ticks.
    let svg = Figure::new("")
        .log_y()
        .line("", &[(0.0, 0.0), (1.0, -1.0)])
        .to_svg();
    let doc = parse(&svg);
    assert!(series_paths(&doc).is_empty());
}

/// The ticks of one axis: the labels under the plot (x, anchored in the middle) or left of it
/// (y, anchored at the end).
fn tick_values(doc: &roxmltree::Document<'_>, anchor: &str) -> Vec<f64> {
    doc.descendants()
        .filter(|n| n.has_tag_name("g") && n.attribute("class") == Some("tick-labels"))
        .flat_map(|g| g.children().filter(|c| c.has_tag_name("text")))
        .filter(|t| t.attribute("text-anchor") == Some(anchor))
        .map(|t| label_value(t.text().unwrap_or_default()))
        .collect()
}

fn is_nice(step: f64) -> bool {
    let k = step.log10().floor();
    let m = step / 10f64.powf(k);
    [1.0, 2.0, 5.0, 10.0]
        .iter()
        .any(|n| (m - n).abs() < 1e-6 * n)
}

#[test]
fn ticks_are_nice_numbers() {
    for &(scale, offset) in &[
        (1.0, 0.0),
        (1.085, 0.0),
        (3.7e-6, 1e-5),
        (4.2e4, -3e3),
        (0.397, -0.4),
    ] {
        let pts: Vec<(f64, f64)> = (0..=20)
            .map(|i| {
                let s = f64::from(i) / 20.0;
                (offset + scale * s, offset - scale * s * s)
            })
            .collect();
        let svg = Figure::new("").line("", &pts).to_svg();
        let doc = parse(&svg);
        for anchor in ["middle", "end"] {
            let v = tick_values(&doc, anchor);
            assert!(v.len() >= 3, "{anchor}: {v:?}");
            let step = (v[1] - v[0]).abs();
            assert!(is_nice(step), "step {step} of {v:?}");
            for w in v.windows(2) {
                assert!(((w[1] - w[0]).abs() - step).abs() < 1e-6 * step, "{v:?}");
            }
            for x in &v {
                assert!(
                    (x / step - (x / step).round()).abs() < 1e-6,
                    "{x} not on a multiple of {step}"
                );
            }
            // The ticks reach to within one step of both ends of the data.
            let (lo, hi) = (v[0].min(v[v.len() - 1]), v[0].max(v[v.len() - 1]));
            let (dlo, dhi) = if anchor == "middle" {
                (offset, offset + scale)
            } else {
                (offset - scale, offset)
            };
            assert!(
                lo < dlo + step && hi > dhi - step,
                "{v:?} vs [{dlo}, {dhi}]"
            );
        }
    }
}

#[test]
fn fixed_ranges_clip_lines() {
    // y(x) = ln|cos x| goes to −∞ at ±π/2: clipped to the range, with moderate coordinates.
    let pts: Vec<(f64, f64)> = (1..2000)
        .map(|i| {
            let x = -FRAC_PI_2 + PI * f64::from(i) / 2000.0;
            (x, x.cos().ln() * 1e12)
        })
        .collect();
    let svg = Figure::new("").y_range(-5e12, 1e12).line("", &pts).to_svg();
    let doc = parse(&svg);
    let paths = series_paths(&doc);
    assert_eq!(paths.len(), 1);
    let height: f64 = doc
        .root_element()
        .attribute("height")
        .expect("h")
        .parse()
        .expect("num");
    for (_, y) in path_points(paths[0].attribute("d").expect("d")) {
        assert!(y.abs() < 2.0 * height, "coordinate {y} not clipped");
    }
    let v = tick_values(&doc, "end");
    assert!(v.iter().all(|&y| (-5e12..=1e12).contains(&y)), "{v:?}");
    // A line leaving and re-entering the range gives two pieces in one path.
    let pts = [(0.0, 0.0), (1.0, 10.0), (2.0, 0.0)];
    let svg = Figure::new("").y_range(-1.0, 1.0).line("", &pts).to_svg();
    let d = series_paths(&parse(&svg))[0]
        .attribute("d")
        .expect("d")
        .to_string();
    assert_eq!(d.matches('M').count(), 2, "{d}");
}

#[test]
fn equal_aspect_has_equal_scales() {
    let pts = [(0.0, 5.0), (10.0, 0.0)];
    let svg = Figure::new("trajectory")
        .equal_aspect()
        .line("", &pts)
        .to_svg();
    let doc = parse(&svg);
    let frame = doc
        .descendants()
        .find(|n| n.attribute("class") == Some("frame"))
        .expect("frame");
    let w: f64 = frame.attribute("width").expect("w").parse().expect("num");
    let h: f64 = frame.attribute("height").expect("h").parse().expect("num");
    let xs = tick_values(&doc, "middle");
    let ys = tick_values(&doc, "end");
    let x_span = xs[xs.len() - 1] - xs[0];
    let y_span = ys[0].max(ys[ys.len() - 1]) - ys[0].min(ys[ys.len() - 1]);
    approx::assert_relative_eq!(w / x_span, h / y_span, max_relative = 1e-3);
    // The picture shrank to fit: less tall than the default.
    let height: f64 = doc
        .root_element()
        .attribute("height")
        .expect("h")
        .parse()
        .expect("num");
    assert!(height < 450.0);
}

#[test]
fn colours_cycle_and_explicit_colours_do_not_advance_it() {
    let line = [(0.0, 0.0), (1.0, 1.0)];
    let red = Style {
        color: Some("red"),
        ..Style::default()
    };
    let svg = Figure::new("")
        .line("a", &line)
        .line_styled("b", &line, red)
        .line("c", &line)
        .to_svg();
    let doc = parse(&svg);
    let strokes: Vec<&str> = series_paths(&doc)
        .iter()
        .map(|p| p.attribute("stroke").expect("stroke"))
        .collect();
    assert_eq!(
        strokes,
        [chetaev_plot::PALETTE[0], "red", chetaev_plot::PALETTE[1]]
    );
}

#[test]
fn legend_avoids_the_data_and_can_be_hidden() {
    // Data in the upper right: the legend goes elsewhere.
    let pts: Vec<(f64, f64)> = (0..=50)
        .map(|i| (f64::from(i) / 50.0, (f64::from(i) / 50.0).powi(8)))
        .collect();
    let doc_svg = Figure::new("").line("a steep curve", &pts).to_svg();
    let doc = parse(&doc_svg);
    let rect = doc
        .descendants()
        .find(|n| n.attribute("class") == Some("legend"))
        .and_then(|g| g.children().find(|c| c.has_tag_name("rect")))
        .expect("legend box");
    let frame = doc
        .descendants()
        .find(|n| n.attribute("class") == Some("frame"))
        .expect("frame");
    let x: f64 = rect.attribute("x").expect("x").parse().expect("num");
    let fx: f64 = frame.attribute("x").expect("x").parse().expect("num");
    let fw: f64 = frame.attribute("width").expect("w").parse().expect("num");
    assert!(x < fx + fw / 2.0, "legend on the left, away from the curve");

    let svg = Figure::new("")
        .legend(Legend::Hidden)
        .line("a", &pts)
        .to_svg();
    assert!(!svg.contains("class=\"legend\""));
}

#[test]
fn errors_say_what_to_do() {
    let dir = std::env::temp_dir().join(format!("chetaev-plot-test-{}", std::process::id()));
    let fig = Figure::new("").line("", &[(0.0, 0.0), (1.0, 1.0)]);
    let err = fig
        .save(dir.join("figure.png"))
        .expect_err("png is not supported");
    assert!(matches!(err, PlotError::UnsupportedFormat { .. }));
    assert!(err.to_string().contains(".svg"));

    let err = fig
        .clone()
        .y_range(1.0, 0.0)
        .save(dir.join("a.svg"))
        .expect_err("bad range");
    assert!(
        matches!(err, PlotError::InvalidRange { axis: "y", .. }),
        "{err}"
    );
    let err = fig
        .clone()
        .log_x()
        .x_range(0.0, 1.0)
        .check()
        .expect_err("log range from 0");
    assert!(matches!(err, PlotError::InvalidRange { axis: "x", .. }));
    let err = fig
        .clone()
        .size(f64::NAN, 300.0)
        .check()
        .expect_err("bad size");
    assert!(matches!(err, PlotError::InvalidSize { .. }));
    // Unusable settings still render.
    parse(&fig.clone().y_range(f64::NAN, 1.0).size(0.0, 0.0).to_svg());

    // Saving creates the directory and writes the document.
    let path = dir.join("nested").join("figure.svg");
    fig.save(&path).expect("writable");
    let written = std::fs::read_to_string(&path).expect("written");
    assert_eq!(written, fig.to_svg());
    // A directory where the file should be: an I/O error naming the path.
    let err = fig.save(dir.join("nested")).expect_err("not .svg");
    assert!(matches!(err, PlotError::UnsupportedFormat { .. }));
    std::fs::create_dir_all(dir.join("taken.svg")).expect("dir");
    let err = fig.save(dir.join("taken.svg")).expect_err("a directory");
    assert!(
        matches!(err, PlotError::Io { .. }) && err.to_string().contains("taken.svg"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn extreme_values_stay_finite() {
    let pts = [
        (-f64::MAX, 0.0),
        (0.0, f64::MAX),
        (f64::MAX, -f64::MAX),
        (1e-300, 1e300),
    ];
    let svg = Figure::new("").line("", &pts).to_svg();
    parse(&svg);
    assert!(!svg.contains("NaN") && !svg.to_lowercase().contains("inf"));
    let svg = Figure::new("").log_x().log_y().line("", &pts).to_svg();
    parse(&svg);
    assert!(!svg.contains("NaN") && !svg.to_lowercase().contains("inf"));
    let svg = Figure::new("").line("", &[(1.0, 2.0)]).to_svg();
    parse(&svg);
}

#[test]
fn a_single_point_at_zero_in_a_small_figure_and_subnormal_spans_draw() {
    // One recorded point at t0 = 0 (a run that failed at its first step) in a figure too small
    // for any labels, and spans below the smallest normal number: no axis may be empty.
    let cases: [&[(f64, f64)]; 6] = [
        &[(0.0, 1.0)],
        &[(0.0, 0.0)],
        &[(0.0, -1.0), (0.0, -1.0)],
        &[(0.0, 0.0), (0.0, 1.0)],
        &[(0.0, 0.0), (1.0, 1e-315)],
        &[(0.0, 0.0), (1e-315, 1.0)],
    ];
    for pts in cases {
        for (w, h) in [(150.0, 100.0), (100.0, 100.0), (640.0, 400.0)] {
            for log_y in [false, true] {
                let mut f = Figure::new("y").size(w, h);
                if log_y {
                    f = f.log_y();
                }
                let svg = f.line("y", pts).to_svg();
                parse(&svg);
                assert!(
                    !svg.contains("NaN") && !svg.to_lowercase().contains("inf"),
                    "{pts:?} at {w}×{h}, log y {log_y}: {svg}"
                );
            }
        }
    }
}

/// A number attribute of an element.
fn attr(n: &roxmltree::Node<'_, '_>, name: &str) -> f64 {
    n.attribute(name)
        .unwrap_or_else(|| panic!("no {name}"))
        .parse()
        .unwrap_or_else(|_| panic!("{name} is not a number"))
}

/// The rectangle `(x, y, width, height)` of the element with `class`, the `k`-th one.
fn rect_of(doc: &roxmltree::Document<'_>, class: &str, k: usize) -> (f64, f64, f64, f64) {
    let n = doc
        .descendants()
        .filter(|n| n.attribute("class") == Some(class))
        .nth(k)
        .unwrap_or_else(|| panic!("no {class} #{k}"));
    let r = if n.has_tag_name("rect") {
        n
    } else {
        n.children()
            .find(|c| c.has_tag_name("rect"))
            .unwrap_or_else(|| panic!("{class} has no rect"))
    };
    (
        attr(&r, "x"),
        attr(&r, "y"),
        attr(&r, "width"),
        attr(&r, "height"),
    )
}

/// The width and height of the document, from its viewBox.
fn view_box(doc: &roxmltree::Document<'_>) -> (f64, f64) {
    let v: Vec<f64> = doc
        .root_element()
        .attribute("viewBox")
        .expect("viewBox")
        .split_whitespace()
        .map(|s| s.parse().expect("number"))
        .collect();
    assert_eq!((v[0], v[1]), (0.0, 0.0));
    (v[2], v[3])
}

/// The width of bold text: the advance widths of DejaVu Sans Bold (the first font the SVG asks
/// for), in em, measured by rendering each character; other characters count as 0.9 em.
fn bold_width_bound(text: &str, font: f64) -> f64 {
    let em: f64 = text
        .chars()
        .map(|c| match c {
            'i' | 'j' | 'l' | ' ' | '/' | 'I' | 'J' => 0.38,
            '.' | ',' | ':' | ';' | '-' => 0.41,
            'f' | 't' | 'r' | '(' | ')' | '[' | ']' | '_' => 0.5,
            'c' | 's' | 'z' => 0.61,
            'm' => 1.05,
            'w' => 0.93,
            'M' => 1.0,
            'W' => 1.11,
            c if c.is_ascii_lowercase() || c.is_ascii_digit() => 0.72,
            c if c.is_ascii_uppercase() => 0.86,
            _ => 0.9,
        })
        .sum();
    em * font
}

/// Asserts that every title line, with its width bounded as above, lies inside the viewBox, and
/// that the lines are above the first plot frame.
fn assert_titles_inside(doc: &roxmltree::Document<'_>) -> usize {
    let (w, h) = view_box(doc);
    let titles: Vec<_> = doc
        .descendants()
        .filter(|n| n.attribute("class") == Some("title"))
        .collect();
    for t in &titles {
        let text = t.text().unwrap_or_default();
        let font = attr(t, "font-size");
        assert_eq!(t.attribute("text-anchor"), Some("middle"));
        let half = bold_width_bound(text, font) / 2.0;
        let (x, y) = (attr(t, "x"), attr(t, "y"));
        assert!(
            x - half >= 0.0 && x + half <= w,
            "title line '{text}' ({font} px) at x = {x} spills out of the width {w}"
        );
        assert!(y - font >= 0.0 && y <= h, "title line '{text}' at y = {y}");
    }
    titles.len()
}

#[test]
fn series_beyond_eight_differ_in_colour_or_dash_pattern() {
    let line = |k: usize| -> Vec<(f64, f64)> {
        (0..20)
            .map(|i| (f64::from(i), (f64::from(i) * 0.3 + k as f64).sin()))
            .collect()
    };
    let mut fig = Figure::new("forty series").legend(Legend::Below);
    for k in 0..40 {
        fig = fig.line(&format!("s{k}"), &line(k));
    }
    let svg = fig.to_svg();
    let doc = parse(&svg);
    let looks: Vec<(String, Option<String>)> = series_paths(&doc)
        .iter()
        .map(|p| {
            (
                p.attribute("stroke").expect("stroke").to_string(),
                p.attribute("stroke-dasharray").map(str::to_string),
            )
        })
        .collect();
    assert_eq!(looks.len(), 40);
    // The first eight are the solid palette, as before.
    for (k, (color, dash)) in looks.iter().take(8).enumerate() {
        assert_eq!(color, chetaev_plot::PALETTE[k]);
        assert!(dash.is_none(), "series {k} is solid");
    }
    // Every series from the ninth on is dashed, each block of eight with its own pattern.
    for block in 1..5 {
        let pattern = &looks[8 * block].1;
        assert!(pattern.is_some(), "block {block} has a dash pattern");
        for (k, look) in looks.iter().enumerate().skip(8 * block).take(8) {
            assert_eq!(&look.1, pattern, "series {k}");
            assert_eq!(look.0, chetaev_plot::PALETTE[k % 8]);
        }
    }
    // No two of the forty look the same.
    for i in 0..40 {
        for j in i + 1..40 {
            assert_ne!(looks[i], looks[j], "series {i} and {j} look the same");
        }
    }
    // The legend's swatches carry the same patterns.
    let swatches: Vec<Option<&str>> = doc
        .descendants()
        .filter(|n| n.has_tag_name("g") && n.attribute("class") == Some("legend"))
        .flat_map(|g| g.children().filter(|c| c.has_tag_name("line")))
        .map(|l| l.attribute("stroke-dasharray"))
        .collect();
    assert_eq!(swatches.len(), 40);
    for (k, s) in swatches.iter().enumerate() {
        assert_eq!(s.map(str::to_string), looks[k].1, "swatch {k}");
    }
    // An explicitly dashed series keeps the plain dash; one with its own colour does not advance
    // the cycle.
    let svg = Figure::new("")
        .line_styled(
            "own",
            &line(0),
            Style {
                color: Some("black"),
                ..Style::default()
            },
        )
        .line_styled(
            "dashed",
            &line(1),
            Style {
                dashed: true,
                ..Style::default()
            },
        )
        .to_svg();
    let doc = parse(&svg);
    let paths = series_paths(&doc);
    assert_eq!(paths[0].attribute("stroke-dasharray"), None);
    assert_eq!(paths[1].attribute("stroke"), Some(chetaev_plot::PALETTE[0]));
    assert_eq!(paths[1].attribute("stroke-dasharray"), Some("6 3.75"));
}

#[test]
fn marker_series_beyond_eight_change_shape() {
    let markers = Style {
        width: 0.0,
        markers: true,
        ..Style::default()
    };
    let mut fig = Figure::new("");
    for k in 0..10 {
        fig = fig.line_styled(&format!("m{k}"), &[(k as f64, 1.0)], markers);
    }
    let svg = fig.to_svg();
    let doc = parse(&svg);
    let shapes: Vec<String> = doc
        .descendants()
        .filter(|n| n.attribute("class") == Some("markers"))
        .map(|g| {
            let c = g.first_element_child().expect("a marker");
            c.tag_name().name().to_string()
        })
        .collect();
    assert_eq!(&shapes[..8], &["circle"; 8]);
    assert_eq!(&shapes[8..], &["rect", "rect"]);
}

#[test]
fn titles_are_never_cut() {
    // A tall, narrow trajectory with equal scales and a long title.
    let pts: Vec<(f64, f64)> = (0..=50)
        .map(|i| {
            let s = f64::from(i) / 50.0;
            (2.6 * s * s, 8.2 * s)
        })
        .collect();
    let title = "Sled on a slope with a prescribed speed: trajectory";
    let svg = Figure::new(title)
        .equal_aspect()
        .x_label("x [m]")
        .y_label("y [m]")
        .line("", &pts)
        .to_svg();
    let doc = parse(&svg);
    assert_eq!(assert_titles_inside(&doc), 1);

    // A title wider than the picture is broken into lines, all inside, all above the plot.
    let long = "A very long title that names the scene, the picture and the coordinates shown, \
                and then some more words that cannot fit on one line of a small figure";
    let svg = Figure::new(long).size(360.0, 300.0).line("", &pts).to_svg();
    let doc = parse(&svg);
    let lines = assert_titles_inside(&doc);
    assert!(lines >= 3, "{lines} lines");
    let words: Vec<String> = doc
        .descendants()
        .filter(|n| n.attribute("class") == Some("title"))
        .flat_map(|t| {
            t.text()
                .unwrap_or_default()
                .split(' ')
                .map(str::to_string)
                .collect::<Vec<_>>()
        })
        .collect();
    assert_eq!(
        words.join(" "),
        long.split_whitespace().collect::<Vec<_>>().join(" ")
    );
    let (_, frame_top, _, _) = rect_of(&doc, "frame", 0);
    let last_title = doc
        .descendants()
        .filter(|n| n.attribute("class") == Some("title"))
        .map(|t| attr(&t, "y"))
        .fold(0.0, f64::max);
    assert!(
        last_title < frame_top,
        "title at {last_title}, plot from {frame_top}"
    );
}

/// Whether rectangle `a` lies inside rectangle `b`.
fn inside(a: (f64, f64, f64, f64), b: (f64, f64, f64, f64)) -> bool {
    a.0 >= b.0 && a.1 >= b.1 && a.0 + a.2 <= b.0 + b.2 && a.1 + a.3 <= b.1 + b.3
}

#[test]
fn legend_is_inside_the_frame_beside_it_or_below_it() {
    // A narrow plot (equal scales, tall data): the legend does not fit inside. With room in the
    // width asked for, it goes right of the plot; without, below it, under the x label.
    let pts: Vec<(f64, f64)> = (0..=50)
        .map(|i| {
            let s = f64::from(i) / 50.0;
            (2.6 * s * s, 8.2 * s)
        })
        .collect();
    let marker = Style {
        width: 0.0,
        markers: true,
        ..Style::default()
    };
    let narrow = Figure::new("narrow")
        .equal_aspect()
        .x_label("x [m]")
        .y_label("y [m]")
        .line("", &pts)
        .line_styled("heading 45 degrees", &[(1.1, 0.5)], marker)
        .line_styled("bottom", &[(2.6, 8.2)], marker);
    let doc_svg = narrow.to_svg();
    let doc = parse(&doc_svg);
    let (w, h) = view_box(&doc);
    let frame = rect_of(&doc, "frame", 0);
    let legend = rect_of(&doc, "legend", 0);
    assert!(inside(legend, (0.0, 0.0, w, h)), "{legend:?} in {w} × {h}");
    assert!(
        legend.0 > frame.0 + frame.2,
        "right of the plot: {legend:?}, {frame:?}"
    );
    assert!(legend.1 >= frame.1 && legend.1 + legend.3 <= frame.1 + frame.3);
    assert!(w <= 720.0, "within the width asked for");
    assert_eq!(texts_in(&doc, "legend"), ["heading 45 degrees", "bottom"]);

    for svg in [
        narrow.clone().size(300.0, 450.0).to_svg(),
        narrow.clone().legend(Legend::Below).to_svg(),
    ] {
        let doc = parse(&svg);
        let (w, h) = view_box(&doc);
        let frame = rect_of(&doc, "frame", 0);
        let legend = rect_of(&doc, "legend", 0);
        assert!(inside(legend, (0.0, 0.0, w, h)), "{legend:?} in {w} × {h}");
        assert!(!inside(legend, frame), "this legend cannot fit inside");
        let x_label = doc
            .descendants()
            .find(|n| n.attribute("class") == Some("x-label"))
            .expect("x label");
        assert!(
            legend.1 > attr(&x_label, "y"),
            "the legend is below the x label"
        );
        assert_eq!(texts_in(&doc, "legend"), ["heading 45 degrees", "bottom"]);
    }

    // A legend that fits stays inside the frame, wherever the data leave room.
    for legend_at in [Legend::Auto, Legend::TopLeft, Legend::BottomCenter] {
        let svg = Figure::new("")
            .legend(legend_at)
            .line("a steep curve", &[(0.0, 0.0), (0.9, 0.05), (1.0, 1.0)])
            .to_svg();
        let doc = parse(&svg);
        assert!(
            inside(rect_of(&doc, "legend", 0), rect_of(&doc, "frame", 0)),
            "{legend_at:?}"
        );
    }

    // Data everywhere: no place inside is free, so the legend goes below, beside nothing.
    let zigzag: Vec<(f64, f64)> = (0..=400)
        .map(|i| (f64::from(i), if i % 2 == 0 { 0.0 } else { 1.0 }))
        .collect();
    let svg = Figure::new("dense")
        .x_label("t")
        .line("zigzag", &zigzag)
        .line("another", &[(0.0, 0.5), (400.0, 0.5)])
        .to_svg();
    let doc = parse(&svg);
    let (w, h) = view_box(&doc);
    let frame = rect_of(&doc, "frame", 0);
    let legend = rect_of(&doc, "legend", 0);
    assert!(legend.1 > frame.1 + frame.3, "below the plot");
    assert!(inside(legend, (0.0, 0.0, w, h)));
    // Both entries on one row, side by side.
    let ys: Vec<f64> = doc
        .descendants()
        .filter(|n| n.attribute("class") == Some("legend"))
        .flat_map(|g| g.children().filter(|c| c.has_tag_name("text")))
        .map(|t| attr(&t, "y"))
        .collect();
    assert_eq!(ys.len(), 2);
    assert_eq!(ys[0], ys[1]);
    // The picture keeps its size: the plot made room.
    assert_eq!((w, h), (720.0, 450.0));
}

#[test]
fn panels_share_the_x_axis_and_keep_their_own_y_axes() {
    let t: Vec<f64> = (0..=100).map(|i| f64::from(i) * 0.035).collect();
    let speed: Vec<(f64, f64)> = t.iter().map(|&t| (t, 2.0 + 0.5 * t)).collect();
    let small: Vec<(f64, f64)> = t[..50].iter().map(|&t| (t, 1e-4 * (-t).exp())).collect();
    let big: Vec<(f64, f64)> = t.iter().map(|&t| (t, -12345.0 * t)).collect();
    let panel = |label: &str, pts: &[(f64, f64)]| {
        Figure::new("")
            .x_label("t [s]")
            .y_label(label)
            .legend(Legend::Hidden)
            .line(label, pts)
    };
    let svg = Panels::new("Sled on a slope with a prescribed speed: quantities")
        .share_x()
        .panel(panel("speed [m/s]", &speed))
        .panel(panel("small [1]", &small))
        .panel(panel("big [J]", &big))
        .to_svg();
    let doc = parse(&svg);
    assert_eq!(assert_titles_inside(&doc), 1);
    let (w, h) = view_box(&doc);
    // Three frames, aligned, one above the other, inside the picture.
    let frames: Vec<(f64, f64, f64, f64)> = (0..3)
        .map(|k| {
            let f = rect_of(&doc, "frame", k);
            let g = doc
                .descendants()
                .filter(|n| n.attribute("class") == Some("panel"))
                .nth(k)
                .expect("panel group");
            let tr = g.attribute("transform").expect("translate");
            let xy: Vec<f64> = tr
                .trim_start_matches("translate(")
                .trim_end_matches(')')
                .split_whitespace()
                .map(|s| s.parse().expect("number"))
                .collect();
            (f.0 + xy[0], f.1 + xy[1], f.2, f.3)
        })
        .collect();
    for f in &frames {
        assert!(inside(*f, (0.0, 0.0, w, h)), "{f:?}");
        assert_eq!((f.0, f.2), (frames[0].0, frames[0].2), "aligned");
    }
    assert!(frames[0].1 + frames[0].3 < frames[1].1);
    assert!(frames[1].1 + frames[1].3 < frames[2].1);
    // One x label, under the last panel; every panel has its own y label.
    let x_labels = doc
        .descendants()
        .filter(|n| n.attribute("class") == Some("x-label"))
        .count();
    assert_eq!(x_labels, 1);
    let y_labels: Vec<&str> = doc
        .descendants()
        .filter(|n| n.attribute("class") == Some("y-label"))
        .filter_map(|n| n.text())
        .collect();
    assert_eq!(y_labels, ["speed [m/s]", "small [1]", "big [J]"]);
    // The same x range: the x tick labels of every panel are the same.
    let x_ticks: Vec<Vec<String>> = doc
        .descendants()
        .filter(|n| n.attribute("class") == Some("tick-labels"))
        .map(|g| {
            g.children()
                .filter(|t| t.attribute("text-anchor") == Some("middle"))
                .map(|t| t.text().unwrap_or_default().to_string())
                .collect()
        })
        .collect();
    assert_eq!(x_ticks.len(), 3);
    assert!(x_ticks.iter().all(|t| t == &x_ticks[0]), "{x_ticks:?}");
    // Clip paths are distinct, and every reference resolves.
    let ids: Vec<&str> = doc
        .descendants()
        .filter(|n| n.has_tag_name("clipPath"))
        .filter_map(|n| n.attribute("id"))
        .collect();
    assert_eq!(ids.len(), 3);
    assert!(ids[0] != ids[1] && ids[1] != ids[2] && ids[0] != ids[2]);

    // A grid of equal-aspect panels: two columns, each panel inside the picture.
    let circle: Vec<(f64, f64)> = (0..=60)
        .map(|i| {
            let a = f64::from(i) / 60.0 * std::f64::consts::TAU;
            (a.cos(), a.sin())
        })
        .collect();
    let svg = Panels::new("three projections")
        .columns(2)
        .panel_size(400.0, 360.0)
        .panel(Figure::new("x, y").equal_aspect().line("", &circle))
        .panel(Figure::new("x, z").equal_aspect().line("", &circle))
        .panel(Figure::new("y, z").equal_aspect().line("", &circle))
        .to_svg();
    let doc = parse(&svg);
    let (w, _) = view_box(&doc);
    assert!(w <= 800.0 + 1.0, "two columns of at most 400 px: {w}");
    assert_eq!(
        texts_of_class(&doc, "title"),
        ["three projections", "x, y", "x, z", "y, z"]
    );
}

fn texts_of_class(doc: &roxmltree::Document<'_>, class: &str) -> Vec<String> {
    doc.descendants()
        .filter(|n| n.attribute("class") == Some(class))
        .map(|n| n.text().unwrap_or_default().to_string())
        .collect()
}

#[test]
fn rounding_noise_is_drawn_flat() {
    // A multiplier constant up to the last bits: no fifteen-digit tick labels, a flat line.
    let pts: Vec<(f64, f64)> = (0..40)
        .map(|i| {
            let noise = [0.0, 2.0, -3.0, 1.0][i % 4] * 8.66f64 * f64::EPSILON;
            (f64::from(i as u32), 8.662_447_993_498_587 + noise)
        })
        .collect();
    let svg = Figure::new("").line("", &pts).to_svg();
    let doc = parse(&svg);
    for label in texts_in(&doc, "tick-labels") {
        assert!(label.chars().count() <= 4, "tick label {label}");
    }
    let ys: Vec<f64> = path_points(series_paths(&doc)[0].attribute("d").expect("d"))
        .iter()
        .map(|p| p.1)
        .collect();
    assert!(ys.iter().all(|&y| y == ys[0]), "{ys:?}");
    // A real variation, however small relative to the value, is shown.
    let pts: Vec<(f64, f64)> = (0..40)
        .map(|i| (f64::from(i), 8.66 + 1e-9 * f64::from(i)))
        .collect();
    let doc_svg = Figure::new("").line("", &pts).to_svg();
    let doc = parse(&doc_svg);
    let ys: Vec<f64> = path_points(series_paths(&doc)[0].attribute("d").expect("d"))
        .iter()
        .map(|p| p.1)
        .collect();
    assert!(ys[0] - ys[39] > 100.0, "{ys:?}");
}

#[test]
fn notes_sit_under_the_title() {
    let svg = Figure::new("trajectory")
        .note("x1 against y1, 2 of 10 coordinates")
        .line("", &[(0.0, 0.0), (1.0, 1.0)])
        .to_svg();
    let doc = parse(&svg);
    let title = doc
        .descendants()
        .find(|n| n.attribute("class") == Some("title"))
        .expect("title");
    let note = doc
        .descendants()
        .find(|n| n.attribute("class") == Some("note"))
        .expect("note");
    let (_, frame_top, _, _) = rect_of(&doc, "frame", 0);
    assert!(attr(&title, "y") < attr(&note, "y") && attr(&note, "y") < frame_top);
}

/// The pixel extent `(x_min, x_max, y_min, y_max)` of every series path.
fn path_extent(doc: &roxmltree::Document<'_>) -> (f64, f64, f64, f64) {
    series_paths(doc)
        .iter()
        .flat_map(|p| path_points(p.attribute("d").expect("d")))
        .fold(
            (
                f64::INFINITY,
                f64::NEG_INFINITY,
                f64::INFINITY,
                f64::NEG_INFINITY,
            ),
            |(a, b, c, d), (x, y)| (a.min(x), b.max(x), c.min(y), d.max(y)),
        )
}

#[test]
fn automatic_ranges_leave_a_five_per_cent_margin_between_the_data_and_the_frame() {
    // A line from (0, 0) to (10, 1), and one over four decades on log axes: the data's extent
    // fills 1/1.1 of the frame, centred, so 0.05/1.1 of it is left free on each side.
    let line: Vec<(f64, f64)> = (0..=100)
        .map(|i| (0.1 * f64::from(i), 0.01 * f64::from(i)))
        .collect();
    let powers: Vec<(f64, f64)> = (0..=40)
        .map(|i| {
            let e = 0.1 * f64::from(i);
            (10f64.powf(e - 2.0), 10f64.powf(-3.0 * e))
        })
        .collect();
    for (fig, what) in [
        (Figure::new("").line("", &line), "linear"),
        (Figure::new("").log_x().log_y().line("", &powers), "log"),
    ] {
        let svg = fig.to_svg();
        let doc = parse(&svg);
        let (left, top, width, height) = rect_of(&doc, "frame", 0);
        let (x0, x1, y0, y1) = path_extent(&doc);
        let (mx, my) = (0.05 / 1.1 * width, 0.05 / 1.1 * height);
        assert!(mx > 20.0 && my > 10.0, "{what}: a visible margin");
        for (got, want) in [
            (x0 - left, mx),
            (left + width - x1, mx),
            (y0 - top, my),
            (top + height - y1, my),
        ] {
            assert!(
                (got - want).abs() < 0.02,
                "{what}: margin {got} px, not {want} px"
            );
        }
        // Ticks are still nice numbers inside the frame.
        for anchor in ["middle", "end"] {
            let v = tick_values(&doc, anchor);
            assert!(v.len() >= 2, "{what} {anchor}: {v:?}");
        }
    }
    // No margin when asked: the ends of the data are on the frame.
    let doc_svg = Figure::new("").margins(0.0, 0.0).line("", &line).to_svg();
    let doc = parse(&doc_svg);
    let (left, top, width, height) = rect_of(&doc, "frame", 0);
    let (x0, x1, y0, y1) = path_extent(&doc);
    for d in [x0 - left, left + width - x1, y0 - top, top + height - y1] {
        assert!(d.abs() < 0.01, "{d}");
    }
}

#[test]
fn a_log_axis_spans_the_decades_of_the_data_not_whole_decades_around_them() {
    // n = 2 … 24 against a cost of 1e-7 … 5e-5: ticks 2, 5, 10, 20 on x, not 10⁰ … 10².
    let pts: Vec<(f64, f64)> = [2.0, 3.0, 6.0, 12.0, 24.0]
        .iter()
        .map(|&n: &f64| (n, 1e-7 * (n / 2.0).powf(2.5)))
        .collect();
    let svg = Figure::new("").log_x().log_y().line("", &pts).to_svg();
    let doc = parse(&svg);
    assert_eq!(tick_values(&doc, "middle"), [2.0, 5.0, 10.0, 20.0]);
    let y = tick_values(&doc, "end");
    assert!(y.iter().all(|&v| v > 1e-7 / 1.2 && v < 5e-5 * 1.2), "{y:?}");
    assert!(y.len() >= 3, "{y:?}");
}

#[test]
fn a_thinned_series_keeps_its_largest_value_in_the_svg_path() {
    // 20 000 points of small values with one spike, at an index every 7th point skips.
    let spike = 12_345;
    assert_ne!(spike % 7, 0);
    let pts: Vec<(f64, f64)> = (0..20_000)
        .map(|i| {
            let y = if i == spike {
                6e-10
            } else {
                1e-12 * (1.0 + (f64::from(i) * 0.01).sin().abs())
            };
            (f64::from(i), y)
        })
        .collect();
    let few = thin(&pts, 300);
    assert!(few.len() <= 602 && few.len() >= 300, "{}", few.len());
    // The overall least and greatest values are kept; every 7th point would lose the spike.
    let max = |p: &[(f64, f64)]| p.iter().map(|p| p.1).fold(0.0, f64::max);
    let min = |p: &[(f64, f64)]| p.iter().map(|p| p.1).fold(f64::INFINITY, f64::min);
    assert_eq!(max(&few), 6e-10);
    assert_eq!(min(&few), min(&pts));
    let sampled: Vec<(f64, f64)> = pts.iter().step_by(7).copied().collect();
    assert!(max(&sampled) < 1e-11);
    // In the SVG: with a fixed range the spike's pixel is known, and the path reaches it.
    let svg = Figure::new("")
        .log_y()
        .x_range(0.0, 20_000.0)
        .y_range(1e-13, 1e-9)
        .line("", &few)
        .to_svg();
    let doc = parse(&svg);
    let (left, top, width, height) = rect_of(&doc, "frame", 0);
    let want = (
        left + width * spike as f64 / 20_000.0,
        top + height * (1.0 - (6e-10f64.log10() + 13.0) / 4.0),
    );
    let path = path_points(series_paths(&doc)[0].attribute("d").expect("d"));
    assert!(
        path.iter()
            .any(|p| (p.0 - want.0).abs() < 0.01 && (p.1 - want.1).abs() < 0.01),
        "the spike at {want:?} is not on the path"
    );
    // Short series and gaps are kept whole.
    assert_eq!(thin(&pts[..100], 60), pts[..100].to_vec());
    let mut gappy = pts.clone();
    gappy[5000].1 = f64::NAN;
    assert!(thin(&gappy, 100).iter().any(|p| p.1.is_nan()));
}
