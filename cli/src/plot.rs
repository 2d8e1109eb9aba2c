//! PNG charts: line/marker charts and grouped bar charts, drawn with `plotters` into an RGB
//! buffer and encoded as PNG. Text uses DejaVu Sans, vendored in `assets/fonts/` and compiled
//! into the library, so no system fonts are needed.
//!
//! ```no_run
//! use projfluid_lab::plot::{LineChart, Series, SeriesStyle};
//! let chart = LineChart {
//!     title: "Surge front".into(),
//!     x_label: "T".into(),
//!     y_label: "Z".into(),
//!     series: vec![Series {
//!         label: "simulation".into(),
//!         points: vec![(0.0, 1.0), (1.0, 1.4), (2.0, 2.3)],
//!         style: SeriesStyle::Line,
//!     }],
//! };
//! chart.write_png(std::path::Path::new("front.png")).unwrap();
//! ```
//!
//! The chart types live here; how each is drawn, the canvas and its PNG encoding, the axes
//! and the legend live in submodules.

mod axes;
mod bar;
mod canvas;
mod legend;
mod line;

/// Width of every chart (pixels).
pub const WIDTH: u32 = 800;
/// Height of every chart (pixels).
pub const HEIGHT: u32 = 500;

/// How a series is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SeriesStyle {
    /// Points joined by straight lines, in the given order.
    Line,
    /// One filled circle per point.
    Markers,
    /// Lines and circles.
    LineMarkers,
}

/// One labelled set of (x, y) points of a [`LineChart`].
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    /// Legend text.
    pub label: String,
    /// Points in data units; at least one, all finite.
    pub points: Vec<(f64, f64)>,
    /// How the points are drawn.
    pub style: SeriesStyle,
}

/// A chart of y against x with one colour per series (from a fixed palette) and a legend.
/// Axis ranges cover all points with a margin.
#[derive(Clone, Debug, PartialEq)]
pub struct LineChart {
    /// Caption above the plot.
    pub title: String,
    /// Horizontal axis label (with units).
    pub x_label: String,
    /// Vertical axis label (with units).
    pub y_label: String,
    /// The data; at least one series.
    pub series: Vec<Series>,
}

/// A grouped bar chart: one group per category, one bar (and colour) per series.
#[derive(Clone, Debug, PartialEq)]
pub struct BarChart {
    /// Caption above the plot.
    pub title: String,
    /// Vertical axis label (with units).
    pub y_label: String,
    /// Category names along the horizontal axis; at least one.
    pub categories: Vec<String>,
    /// (legend text, one finite value per category) for each series; at least one series.
    pub series: Vec<(String, Vec<f64>)>,
}
