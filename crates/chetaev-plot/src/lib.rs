//! SVG line plots for chetaev's example programs, scene runner and work-precision program.
//!
//! A [`Figure`] is built with chained calls and written as a self-contained SVG file. It needs no
//! fonts and no system libraries: SVG text is laid out by whatever displays the file. [`Panels`]
//! puts several figures in one file, stacked (sharing the time axis) or in a grid.
//!
//! ```
//! use chetaev_plot::{Figure, Style};
//!
//! let t: Vec<f64> = (0..=100).map(|i| f64::from(i) * 0.01).collect();
//! let exact: Vec<(f64, f64)> = t.iter().map(|&t| (t, -0.5 * t.tanh())).collect();
//! let numerical: Vec<(f64, f64)> = exact.iter().step_by(10).copied().collect();
//! let figure = Figure::new("Multiplier")
//!     .x_label("t [s]")
//!     .y_label("μ [kg/s]")
//!     .line("closed form", &exact)
//!     .line_styled("numerical", &numerical, Style { width: 0.0, markers: true, ..Style::default() });
//! let svg = figure.to_svg();
//! assert!(svg.starts_with("<?xml") && svg.contains("Multiplier"));
//! ```
//!
//! # What is drawn
//!
//! * Each series is a polyline through its points, in the order given. A point with a NaN or
//!   infinite coordinate breaks the line: each run of finite points is one `<path>` element, so the
//!   SVG never contains a non-finite number. On a log axis, points with a non-positive coordinate
//!   on that axis are dropped and the line joins their neighbours.
//! * Axes get "nice" ticks: steps of 1, 2 or 5 times a power of ten on linear axes, decades on log
//!   axes (every 2nd, 5th, 10th, ... decade when they would crowd; 1-2-5 times powers of ten on
//!   a log axis holding fewer than two decades), spaced so the labels do not overlap. An automatic
//!   range is the data's extent with a margin of 5 % of its span on each side (decades on a log
//!   axis), so no point lies on the frame; its ends need not be ticks ([`Figure::margins`] sets
//!   the margin). A fixed range ([`Figure::x_range`]) is kept as given, and lines are clipped to
//!   it.
//! * [`thin`] keeps the extremes of a series too long to draw point by point.
//! * A legend lists the series with non-empty names. It goes inside the plot, in the corner (or at
//!   the middle of the top or bottom edge) where it covers no data; where every such place would
//!   cover data, or the legend does not fit inside the plot, it goes beside a plot narrowed by
//!   equal scales if the width asked for has room, else below the plot, in as many columns as the
//!   width allows. [`Figure::legend`] chooses a place instead.
//! * Series without their own colour ([`Style::color`]) take the next of eight colours readable on
//!   white (Okabe and Ito's palette without its yellow, plus grey and brown) and, from the ninth
//!   on, a dash pattern too: the first eight are solid, the next eight dashed, then dotted,
//!   dash-dotted and long-dashed, so 40 series differ in colour or pattern. Marker-only series
//!   change the marker's shape instead (circle, square, diamond, triangle, cross). A series with
//!   its own colour does not advance the cycle.
//! * The title is never cut: a title wider than the picture is broken into lines, and a picture
//!   narrowed by [`Figure::equal_aspect`] keeps the width of its title and of its legend.

mod axis;
mod heatmap;
mod panels;
mod render;
mod thin;

pub use heatmap::HeatMap;
pub use panels::Panels;
pub use thin::thin;

use std::path::{Path, PathBuf};

/// The default colour cycle: Okabe and Ito's colour-blind-safe palette without its yellow (too
/// light on white), then dark grey and brown.
pub const PALETTE: [&str; 8] = [
    "#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#404040", "#8C564B",
];

/// The dash patterns of the cycle, in the order they are used (every eight series without their own
/// colour take the next one): solid, dashed, dotted, dash-dotted, long-dashed.
pub const DASH_PATTERNS: [&str; 5] = ["solid", "dashed", "dotted", "dash-dot", "long dash"];

/// How one series is drawn.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Style {
    /// Line width in pixels; `0` draws no line (markers only, with `markers: true`).
    pub width: f64,
    /// A dashed line instead of a solid one (or instead of the pattern the cycle would give).
    pub dashed: bool,
    /// Any SVG colour (`"#D55E00"`, `"black"`); `None` takes the next colour of [`PALETTE`] and,
    /// from the ninth such series on, the next pattern of [`DASH_PATTERNS`].
    pub color: Option<&'static str>,
    /// A hollow circle at every point inside the plot (lines underneath stay visible).
    pub markers: bool,
}

impl Default for Style {
    /// A solid line 1.5 px wide, the next colour of the cycle, no markers.
    fn default() -> Self {
        Self {
            width: 1.5,
            dashed: false,
            color: None,
            markers: false,
        }
    }
}

/// Where the legend goes. A legend that does not fit inside the plot goes below it wherever inside
/// it was asked to go.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[non_exhaustive]
pub enum Legend {
    /// The first place inside the plot where the legend covers no data, of top right, top left,
    /// bottom right, bottom left, top centre, bottom centre; if there is none, right of a plot
    /// narrowed by [`Figure::equal_aspect`] when the figure's width has room for it there, else
    /// below the plot (the default).
    #[default]
    Auto,
    /// Inside, top left.
    TopLeft,
    /// Inside, top right.
    TopRight,
    /// Inside, bottom left.
    BottomLeft,
    /// Inside, bottom right.
    BottomRight,
    /// Inside, top, centred.
    TopCenter,
    /// Inside, bottom, centred.
    BottomCenter,
    /// Below the plot (and its axis label), centred, in as many columns as fit.
    Below,
    /// Right of the plot, level with its top.
    Right,
    /// No legend.
    Hidden,
}

/// Everything that can go wrong when writing a figure.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PlotError {
    /// The file could not be written.
    #[error("could not write the figure to {path}: {source}; check that the directory exists or can be created and is writable")]
    Io {
        /// The file.
        path: PathBuf,
        /// What the operating system said.
        #[source]
        source: std::io::Error,
    },
    /// The file name does not end in a supported extension.
    #[error("cannot write {path}: only SVG is supported, give a file name ending in .svg (convert to PNG with a tool such as rsvg-convert)")]
    UnsupportedFormat {
        /// The file.
        path: PathBuf,
    },
    /// A fixed axis range cannot be drawn.
    #[error("the {axis} range [{lo}, {hi}] cannot be drawn: it needs finite ends with lo < hi, and lo > 0 on a log axis; fix the range or leave it out for an automatic one")]
    InvalidRange {
        /// `"x"` or `"y"`.
        axis: &'static str,
        /// The lower end given.
        lo: f64,
        /// The upper end given.
        hi: f64,
    },
    /// The figure size cannot be drawn.
    #[error("the figure size {width} × {height} px cannot be drawn: give finite sizes of at least 100 px")]
    InvalidSize {
        /// Width given.
        width: f64,
        /// Height given.
        height: f64,
    },
}

/// One axis as configured.
#[derive(Clone, Debug, Default)]
struct AxisSpec {
    label: String,
    log: bool,
    range: Option<(f64, f64)>,
    /// The margin of an automatic range, as a fraction of the data's span; `None` for the default.
    margin: Option<f64>,
}

impl AxisSpec {
    /// The fixed range in axis units, if one is set and usable.
    fn fixed(&self) -> Option<(f64, f64)> {
        let (lo, hi) = self.range?;
        if !(lo.is_finite() && hi.is_finite() && lo < hi) {
            return None;
        }
        if self.log {
            (lo > 0.0).then(|| (lo.log10(), hi.log10()))
        } else {
            Some((lo, hi))
        }
    }

    fn check(&self, axis: &'static str) -> Result<(), PlotError> {
        match self.range {
            Some((lo, hi)) if self.fixed().is_none() => {
                Err(PlotError::InvalidRange { axis, lo, hi })
            }
            _ => Ok(()),
        }
    }
}

/// One series.
#[derive(Clone, Debug)]
struct Series {
    name: String,
    points: Vec<(f64, f64)>,
    style: Style,
}

/// A line plot: title, axis labels, axis scales and ranges, and any number of named series.
#[derive(Clone, Debug)]
pub struct Figure {
    title: String,
    note: String,
    x: AxisSpec,
    y: AxisSpec,
    equal_aspect: bool,
    series: Vec<Series>,
    width: f64,
    height: f64,
    legend: Legend,
}

impl Figure {
    /// An empty figure, 720 × 450 px, with a title (empty for none).
    pub fn new(title: &str) -> Self {
        Self {
            title: title.to_string(),
            note: String::new(),
            x: AxisSpec::default(),
            y: AxisSpec::default(),
            equal_aspect: false,
            series: Vec::new(),
            width: 720.0,
            height: 450.0,
            legend: Legend::Auto,
        }
    }

    /// A line of smaller text under the title (empty for none), for what a reader should know
    /// about the picture, such as which of several coordinates it shows.
    pub fn note(mut self, note: &str) -> Self {
        self.note = note.to_string();
        self
    }

    /// The label under the x axis.
    pub fn x_label(mut self, label: &str) -> Self {
        self.x.label = label.to_string();
        self
    }

    /// The label left of the y axis.
    pub fn y_label(mut self, label: &str) -> Self {
        self.y.label = label.to_string();
        self
    }

    /// A base-10 logarithmic x axis; points with `x ≤ 0` are dropped.
    pub fn log_x(mut self) -> Self {
        self.x.log = true;
        self
    }

    /// A base-10 logarithmic y axis; points with `y ≤ 0` are dropped.
    pub fn log_y(mut self) -> Self {
        self.y.log = true;
        self
    }

    /// A fixed x range (data units, also on a log axis). Lines are clipped to it. An unusable range
    /// (not finite, `lo ≥ hi`, or `lo ≤ 0` on a log axis) is ignored by [`Figure::to_svg`] and
    /// reported by [`Figure::check`] and [`Figure::save`].
    pub fn x_range(mut self, lo: f64, hi: f64) -> Self {
        self.x.range = Some((lo, hi));
        self
    }

    /// A fixed y range; see [`Figure::x_range`].
    pub fn y_range(mut self, lo: f64, hi: f64) -> Self {
        self.y.range = Some((lo, hi));
        self
    }

    /// The room left between the data and the frame on automatic ranges, as fractions of the
    /// data's span on the x and the y axis (in decades on a log axis), on each side: 0.05 unless
    /// set, as in matplotlib; `0` lets the extreme points touch the frame. A fraction that is not
    /// a finite number ≥ 0 counts as 0. Fixed ranges ([`Figure::x_range`]) have no margin.
    pub fn margins(mut self, x: f64, y: f64) -> Self {
        self.x.margin = Some(x);
        self.y.margin = Some(y);
        self
    }

    /// The same scale on both axes, for trajectories: one unit is as long across as up. The plot
    /// area shrinks in one direction to fit the figure size, and the figure with it.
    pub fn equal_aspect(mut self) -> Self {
        self.equal_aspect = true;
        self
    }

    /// The largest size of the picture in pixels (720 × 450 unless set). With
    /// [`Figure::equal_aspect`] one side may come out smaller.
    pub fn size(mut self, width: f64, height: f64) -> Self {
        self.width = width;
        self.height = height;
        self
    }

    /// Where the legend goes ([`Legend::Auto`] unless set).
    pub fn legend(mut self, legend: Legend) -> Self {
        self.legend = legend;
        self
    }

    /// Adds a series drawn with the default [`Style`]. An empty `name` leaves it out of the legend.
    pub fn line(self, name: &str, points: &[(f64, f64)]) -> Self {
        self.line_styled(name, points, Style::default())
    }

    /// Adds a series drawn with `style`. An empty `name` leaves it out of the legend.
    pub fn line_styled(mut self, name: &str, points: &[(f64, f64)], style: Style) -> Self {
        self.series.push(Series {
            name: name.to_string(),
            points: points.to_vec(),
            style,
        });
        self
    }

    /// Whether the size is usable.
    fn check_size(&self) -> bool {
        self.width.is_finite()
            && self.height.is_finite()
            && self.width >= 100.0
            && self.height >= 100.0
    }

    /// Whether the x axis is logarithmic.
    pub(crate) fn is_log_x(&self) -> bool {
        self.x.log
    }

    /// Checks what [`Figure::to_svg`] would silently work around: unusable fixed ranges or size.
    pub fn check(&self) -> Result<(), PlotError> {
        self.x.check("x")?;
        self.y.check("y")?;
        if !self.check_size() {
            return Err(PlotError::InvalidSize {
                width: self.width,
                height: self.height,
            });
        }
        Ok(())
    }

    /// The figure as a self-contained SVG document. Never fails: unusable settings fall back to
    /// defaults (automatic ranges, 720 × 450 px); [`Figure::check`] reports them.
    pub fn to_svg(&self) -> String {
        render::render(self)
    }

    /// Writes the figure to `path`, which must end in `.svg`; missing parent directories are
    /// created.
    pub fn save(&self, path: impl AsRef<Path>) -> Result<(), PlotError> {
        write_svg(path.as_ref(), || self.check(), || self.to_svg())
    }
}

/// Writes `svg()` to `path` after `check()`: the extension first, then the settings, then the file.
pub(crate) fn write_svg(
    path: &Path,
    check: impl FnOnce() -> Result<(), PlotError>,
    svg: impl FnOnce() -> String,
) -> Result<(), PlotError> {
    let is_svg = path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("svg"));
    if !is_svg {
        return Err(PlotError::UnsupportedFormat {
            path: path.to_path_buf(),
        });
    }
    check()?;
    let io = |source| PlotError::Io {
        path: path.to_path_buf(),
        source,
    };
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(io)?;
    }
    std::fs::write(path, svg()).map_err(io)
}
