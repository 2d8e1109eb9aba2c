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

use plotters::coord::CoordTranslate;
use plotters::prelude::*;
use plotters::style::{FontStyle, register_font};
use projfluid::Error;
use std::path::Path;
use std::sync::OnceLock;

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

/// Colours of series 0, 1, … (repeating): the Tableau 10 palette.
const PALETTE: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

/// The family name the vendored font is registered under.
const FONT: &str = "sans-serif";

fn colour(i: usize) -> RGBColor {
    PALETTE[i % PALETTE.len()]
}

/// Registers the vendored DejaVu Sans with plotters, once per process.
fn ensure_font() -> Result<(), Error> {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    let ok = *REGISTERED.get_or_init(|| {
        let bytes: &'static [u8] = include_bytes!("../assets/fonts/DejaVuSans.ttf");
        register_font(FONT, FontStyle::Normal, bytes).is_ok()
    });
    if ok {
        Ok(())
    } else {
        Err(Error::Io(
            "the vendored chart font could not be loaded".into(),
        ))
    }
}

impl LineChart {
    /// Draws the chart and writes it to `path` as an 800×500 PNG (whatever the extension).
    /// Errors, writing nothing, when there is no series, a series has no points or a
    /// non-finite point, or the file cannot be written.
    pub fn write_png(&self, path: &Path) -> Result<(), Error> {
        self.check()?;
        let points = || self.series.iter().flat_map(|s| s.points.iter());
        let x = padded_range("x", points().map(|p| p.0), false)?;
        let y = padded_range("y", points().map(|p| p.1), false)?;
        render(path, |root| self.draw(root, x, y))
    }

    fn check(&self) -> Result<(), Error> {
        if self.series.is_empty() {
            return Err(Error::invalid("series", 0, "must hold at least one series"));
        }
        for (i, s) in self.series.iter().enumerate() {
            if s.points.is_empty() {
                return Err(Error::invalid(
                    format!("series[{i}].points"),
                    format!("none for `{}`", s.label),
                    "must hold at least one point",
                ));
            }
            if let Some(j) = s
                .points
                .iter()
                .position(|p| !(p.0.is_finite() && p.1.is_finite()))
            {
                return Err(Error::invalid(
                    format!("series[{i}].points[{j}]"),
                    format!("{:?}", s.points[j]),
                    "must be finite",
                ));
            }
        }
        Ok(())
    }

    fn draw(&self, root: &Area, x: (f64, f64), y: (f64, f64)) -> Result<(), String> {
        let mut chart = ChartBuilder::on(root)
            .caption(&self.title, (FONT, 22))
            .margin(12)
            .x_label_area_size(45)
            .y_label_area_size(80)
            .build_cartesian_2d(x.0..x.1, y.0..y.1)
            .map_err(|e| e.to_string())?;
        chart
            .configure_mesh()
            .x_desc(&self.x_label)
            .y_desc(&self.y_label)
            .x_label_formatter(&|v| tick(*v, x.1 - x.0))
            .y_label_formatter(&|v| tick(*v, y.1 - y.0))
            .label_style((FONT, 14))
            .axis_desc_style((FONT, 16))
            .light_line_style(RGBColor(235, 235, 235))
            .draw()
            .map_err(|e| e.to_string())?;
        for (i, s) in self.series.iter().enumerate() {
            let c = colour(i);
            let line = matches!(s.style, SeriesStyle::Line | SeriesStyle::LineMarkers);
            let markers = matches!(s.style, SeriesStyle::Markers | SeriesStyle::LineMarkers);
            if line {
                chart
                    .draw_series(LineSeries::new(s.points.iter().copied(), c.stroke_width(2)))
                    .map_err(|e| e.to_string())?;
            }
            if markers {
                chart
                    .draw_series(s.points.iter().map(|&p| Circle::new(p, 4, c.filled())))
                    .map_err(|e| e.to_string())?;
            }
            // An invisible element carries the legend entry, drawn in the series' style.
            chart
                .draw_series(std::iter::empty::<Circle<(f64, f64), i32>>())
                .map_err(|e| e.to_string())?
                .label(&s.label)
                .legend(move |(lx, ly)| {
                    // A short line, a dot, or both; the absent part is transparent.
                    let visible = |on: bool| if on { c.to_rgba() } else { TRANSPARENT };
                    EmptyElement::at((lx, ly))
                        + PathElement::new(vec![(0, 0), (20, 0)], visible(line).stroke_width(2))
                        + Circle::new((10, 0), 4, visible(markers).filled())
                });
        }
        let corner = emptiest_corner(self.series.iter().flat_map(|s| s.points.iter()), x, y);
        draw_legend(&mut chart, corner)
    }
}

/// Draws the legend of `chart` in `corner`.
fn draw_legend<'a, CT: CoordTranslate>(
    chart: &mut ChartContext<'a, BitMapBackend<'a>, CT>,
    corner: SeriesLabelPosition,
) -> Result<(), String> {
    chart
        .configure_series_labels()
        .position(corner)
        .label_font((FONT, 14))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()
        .map_err(|e| e.to_string())
}

/// The corner of the plot whose quarter-size box holds the fewest points: where the legend
/// hides the least data (upper corners win ties).
fn emptiest_corner<'a>(
    points: impl Iterator<Item = &'a (f64, f64)>,
    x: (f64, f64),
    y: (f64, f64),
) -> SeriesLabelPosition {
    let mut counts = [0usize; 4]; // upper left, upper right, lower left, lower right
    for p in points {
        let u = (p.0 - x.0) / (x.1 - x.0);
        let v = (p.1 - y.0) / (y.1 - y.0);
        let (left, right, low, high) = (u < 0.4, u > 0.6, v < 0.4, v > 0.6);
        for (i, inside) in [high && left, high && right, low && left, low && right]
            .into_iter()
            .enumerate()
        {
            counts[i] += usize::from(inside);
        }
    }
    let best = (0..4).min_by_key(|&i| counts[i]).unwrap_or(0);
    match best {
        0 => SeriesLabelPosition::UpperLeft,
        1 => SeriesLabelPosition::UpperRight,
        2 => SeriesLabelPosition::LowerLeft,
        _ => SeriesLabelPosition::LowerRight,
    }
}

impl BarChart {
    /// Draws the chart and writes it to `path` as an 800×500 PNG (whatever the extension).
    /// The vertical axis always includes zero. Errors, writing nothing, when there is no
    /// category or series, a series does not have one finite value per category, or the file
    /// cannot be written.
    pub fn write_png(&self, path: &Path) -> Result<(), Error> {
        self.check()?;
        let values = self.series.iter().flat_map(|s| s.1.iter().copied());
        let y = padded_range("y", values, true)?;
        render(path, |root| self.draw(root, y))
    }

    fn check(&self) -> Result<(), Error> {
        if self.categories.is_empty() {
            return Err(Error::invalid(
                "categories",
                0,
                "must hold at least one category",
            ));
        }
        if self.series.is_empty() {
            return Err(Error::invalid("series", 0, "must hold at least one series"));
        }
        let n = self.categories.len();
        for (i, (label, values)) in self.series.iter().enumerate() {
            if values.len() != n {
                return Err(Error::invalid(
                    format!("series[{i}]"),
                    format!("{} values for `{label}`", values.len()),
                    &format!("must hold one value per category ({n})"),
                ));
            }
            if let Some(j) = values.iter().position(|v| !v.is_finite()) {
                return Err(Error::invalid(
                    format!("series[{i}][{j}]"),
                    values[j],
                    "must be finite",
                ));
            }
        }
        Ok(())
    }

    fn draw(&self, root: &Area, y: (f64, f64)) -> Result<(), String> {
        let n = self.categories.len();
        let mut chart = ChartBuilder::on(root)
            .caption(&self.title, (FONT, 22))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(80)
            .build_cartesian_2d(-0.5..n as f64 - 0.5, y.0..y.1)
            .map_err(|e| e.to_string())?;
        // Category i is centred on x = i; ticks fall on the integers.
        let name = |v: &f64| {
            let i = v.round();
            if (v - i).abs() < 1e-6 && (0.0..n as f64).contains(&i) {
                self.categories[i as usize].clone()
            } else {
                String::new()
            }
        };
        chart
            .configure_mesh()
            .disable_x_mesh()
            .x_labels(n)
            .x_label_formatter(&name)
            .y_desc(&self.y_label)
            .y_label_formatter(&|v| tick(*v, y.1 - y.0))
            .label_style((FONT, 14))
            .axis_desc_style((FONT, 16))
            .light_line_style(RGBColor(235, 235, 235))
            .draw()
            .map_err(|e| e.to_string())?;
        let groups = self.series.len() as f64;
        let width = 0.8 / groups;
        for (s, (label, values)) in self.series.iter().enumerate() {
            let c = colour(s);
            let bars = values.iter().enumerate().map(|(i, &v)| {
                let left = i as f64 - 0.4 + s as f64 * width;
                Rectangle::new([(left, 0.0), (left + width * 0.95, v)], c.filled())
            });
            chart
                .draw_series(bars)
                .map_err(|e| e.to_string())?
                .label(label)
                .legend(move |(lx, ly)| {
                    Rectangle::new([(lx, ly - 6), (lx + 14, ly + 6)], c.filled())
                });
        }
        // Each bar counts as its top and its foot.
        let ends: Vec<(f64, f64)> = self
            .series
            .iter()
            .flat_map(|(_, v)| v.iter().enumerate())
            .flat_map(|(i, &v)| [(i as f64, v), (i as f64, 0.0)])
            .collect();
        let corner = emptiest_corner(ends.iter(), (-0.5, n as f64 - 0.5), y);
        draw_legend(&mut chart, corner)
    }
}

/// An axis tick label on an axis spanning `span`: the value rounded to 9 significant digits
/// (hiding binary round-off such as 0.30000000000000004), in the shortest form that reads
/// back the same; values within 1e-9·span of zero read "0".
fn tick(v: f64, span: f64) -> String {
    if v.abs() <= 1e-9 * span || !v.is_finite() {
        return "0".into();
    }
    let rounded: f64 = format!("{v:.8e}").parse().unwrap_or(v);
    let text = format!("{rounded}");
    if text == "-0" { "0".into() } else { text }
}

type Area<'a> = DrawingArea<BitMapBackend<'a>, plotters::coord::Shift>;

/// Draws with `draw` on a white 800×500 canvas and writes the PNG to `path`.
fn render(path: &Path, draw: impl FnOnce(&Area) -> Result<(), String>) -> Result<(), Error> {
    ensure_font()?;
    let mut rgb = vec![0u8; (WIDTH * HEIGHT * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, (WIDTH, HEIGHT)).into_drawing_area();
        let drawn = root
            .fill(&WHITE)
            .map_err(|e| e.to_string())
            .and_then(|()| draw(&root))
            .and_then(|()| root.present().map_err(|e| e.to_string()));
        drawn.map_err(|e| Error::Io(format!("cannot draw chart {}: {e}", path.display())))?;
    }
    let png = encode_png(&rgb)
        .map_err(|e| Error::Io(format!("cannot encode chart {}: {e}", path.display())))?;
    std::fs::write(path, png)
        .map_err(|e| Error::Io(format!("cannot write chart {}: {e}", path.display())))
}

/// Encodes an 8-bit RGB buffer of the chart size as PNG.
fn encode_png(rgb: &[u8]) -> Result<Vec<u8>, png::EncodingError> {
    let mut out = Vec::new();
    let mut encoder = png::Encoder::new(&mut out, WIDTH, HEIGHT);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_compression(png::Compression::Best);
    let mut writer = encoder.write_header()?;
    writer.write_image_data(rgb)?;
    writer.finish()?;
    Ok(out)
}

/// The range of `values` widened by 5 % on each side (or by 1 when all are equal), and
/// stretched to include 0 when `with_zero`. Errors when the span overflows.
fn padded_range(
    axis: &str,
    values: impl Iterator<Item = f64>,
    with_zero: bool,
) -> Result<(f64, f64), Error> {
    let init = if with_zero {
        (0.0, 0.0)
    } else {
        (f64::MAX, f64::MIN)
    };
    let (lo, hi) = values.fold(init, |(lo, hi), v| (lo.min(v), hi.max(v)));
    let span = hi - lo;
    let pad = if span > 0.0 {
        0.05 * span
    } else {
        (0.05 * hi.abs()).max(1.0)
    };
    let range = (lo - pad, hi + pad);
    if !(range.1 - range.0).is_finite() {
        return Err(Error::invalid(
            axis,
            format!("{lo:e}..{hi:e}"),
            "must span a finite range",
        ));
    }
    Ok(range)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tick_labels_are_short() {
        assert_eq!(tick(0.1 + 0.2, 1.0), "0.3");
        assert_eq!(tick(90000.0, 1e5), "90000");
        assert_eq!(tick(-0.0, 1.0), "0");
        assert_eq!(tick(-1.25, 1.0), "-1.25");
        assert_eq!(tick(5.5e-17, 1.0), "0");
        assert_eq!(tick(2e-12, 1e-11), "0.000000000002");
    }

    #[test]
    fn padded_range_handles_single_values_and_zero() {
        assert_eq!(
            padded_range("x", [2.0].into_iter(), false).unwrap(),
            (1.0, 3.0)
        );
        let (lo, hi) = padded_range("y", [1.0, 3.0].into_iter(), true).unwrap();
        assert!(lo < 0.0 && hi > 3.0);
        assert!(padded_range("x", [-1e308, 1e308].into_iter(), false).is_err());
    }
}
