//! The SVG output, parsed back: well-formed, one path per run of finite points, log axes, gaps,
//! nice ticks, legend, ranges and errors.

use std::f64::consts::{FRAC_PI_2, PI};

use chetaev_plot::{Figure, Legend, PlotError, Style};

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
            // The ticks cover the data on automatic ranges.
            let (lo, hi) = (v[0].min(v[v.len() - 1]), v[0].max(v[v.len() - 1]));
            let (dlo, dhi) = if anchor == "middle" {
                (offset, offset + scale)
            } else {
                (offset - scale, offset)
            };
            assert!(
                lo <= dlo + 1e-9 * scale && hi >= dhi - 1e-9 * scale,
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
