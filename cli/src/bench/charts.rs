//! The benchmark as bar charts: time and outer iterations per step, by scene and solver.

use super::BenchRow;
use crate::plot::BarChart;
use crate::summary::RunSummary;

/// The table as two bar charts, one group of bars per scene and one bar per solver: wall-clock
/// milliseconds per step, and outer iterations per step.
pub fn charts(rows: &[BenchRow]) -> [BarChart; 2] {
    let mut scenes: Vec<String> = Vec::new();
    let mut solvers: Vec<String> = Vec::new();
    for row in rows {
        for (list, name) in [
            (&mut scenes, &row.summary.scene),
            (&mut solvers, &row.summary.solver),
        ] {
            if !list.contains(name) {
                list.push(name.clone());
            }
        }
    }
    let chart = |title: &str, y_label: &str, value: fn(&RunSummary) -> f64| BarChart {
        title: title.to_string(),
        y_label: y_label.to_string(),
        categories: scenes.clone(),
        series: solvers
            .iter()
            .map(|solver| {
                let values = scenes
                    .iter()
                    .map(|scene| {
                        rows.iter()
                            .find(|r| &r.summary.scene == scene && &r.summary.solver == solver)
                            .map_or(f64::NAN, |r| value(&r.summary))
                    })
                    .collect();
                (solver.clone(), values)
            })
            .collect(),
    };
    [
        chart("Time per step", "ms per step (wall clock)", |s| {
            s.wall_ms_per_step
        }),
        chart(
            "Outer iterations per step",
            "outer iterations per step",
            |s| s.outer_iterations_mean,
        ),
    ]
}
