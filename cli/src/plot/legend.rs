//! The legend: drawn in the corner of the plot that hides the least data.

use super::canvas::FONT;
use plotters::coord::CoordTranslate;
use plotters::prelude::*;

/// Draws the legend of `chart` in `corner`.
pub(super) fn draw_legend<'a, CT: CoordTranslate>(
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
pub(super) fn emptiest_corner<'a>(
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
