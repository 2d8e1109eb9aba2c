//! A ρ sweep as line charts in the style of the paper's Figure 4: time per step and outer
//! iterations per step over ρ, with the plain iteration as a horizontal reference line.

use super::TuneReport;
use crate::plot::{LineChart, Series, SeriesStyle};
use crate::summary::RunSummary;

/// Two charts: wall-clock milliseconds per step over ρ, and outer iterations per step over ρ.
pub fn charts(report: &TuneReport) -> [LineChart; 2] {
    let chart = |title: &str, y_label: &str, value: fn(&RunSummary) -> f64| {
        let sweep: Vec<(f64, f64)> = report
            .trials
            .iter()
            .map(|t| (t.rho, value(&t.summary)))
            .collect();
        let ends = [sweep.first(), sweep.last()];
        let plain = ends
            .iter()
            .flatten()
            .map(|(rho, _)| (*rho, value(&report.plain)))
            .collect();
        LineChart {
            title: title.to_string(),
            x_label: "ρ".to_string(),
            y_label: y_label.to_string(),
            series: vec![
                Series {
                    label: "chebyshev".to_string(),
                    points: sweep,
                    style: SeriesStyle::LineMarkers,
                },
                Series {
                    label: "plain iteration (jacobi1)".to_string(),
                    points: plain,
                    style: SeriesStyle::Line,
                },
            ],
        }
    };
    [
        chart("Time per step over ρ", "ms per step (wall clock)", |s| {
            s.wall_ms_per_step
        }),
        chart(
            "Outer iterations per step over ρ",
            "outer iterations per step",
            |s| s.outer_iterations_mean,
        ),
    ]
}
