//! Drawing a [`LineChart`]: checks, axes, one line and/or markers per series, legend.

use super::axes::{padded_range, tick};
use super::canvas::{Area, FONT, colour, render};
use super::legend::{draw_legend, emptiest_corner};
use super::{LineChart, SeriesStyle};
use plotters::prelude::*;
use projfluid::Error;
use std::path::Path;

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
                // Segment by segment: plotters joins a wide polyline's segments with mitres,
                // which at a sharp reversal (a gauge reading that drops and jumps within a few
                // samples) shoot far outside the chart.
                let segments = s.points.windows(2);
                chart
                    .draw_series(segments.map(|w| PathElement::new(w.to_vec(), c.stroke_width(2))))
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
