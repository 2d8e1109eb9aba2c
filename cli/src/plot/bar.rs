//! Drawing a [`BarChart`]: checks, axes with category names, grouped bars, legend.

use super::BarChart;
use super::axes::{padded_range, tick};
use super::canvas::{Area, FONT, colour, render};
use super::legend::{draw_legend, emptiest_corner};
use plotters::prelude::*;
use projfluid::Error;
use std::path::Path;

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
