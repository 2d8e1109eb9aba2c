//! A ρ sweep as a Markdown table and as CSV: the plain iteration first, then one row per ρ,
//! then the online estimate (`auto`).

use super::TuneReport;
use crate::summary::RunSummary;

use crate::table::{self, Cell, Column};

/// One table row: the label (`plain` or the value of ρ), the run, the plain run, the verdict.
struct Row<'a> {
    label: String,
    run: &'a RunSummary,
    plain: &'a RunSummary,
    verdict: String,
}

fn rows(report: &TuneReport) -> Vec<Row<'_>> {
    let plain = &report.plain;
    let mut rows = vec![Row {
        label: "plain".to_string(),
        run: plain,
        plain,
        verdict: "reference".to_string(),
    }];
    for (i, t) in report.trials.iter().enumerate() {
        let verdict = match t.rejection {
            Some(r) => format!("rejected: {r}"),
            None if Some(i) == report.best => "chosen".to_string(),
            None if Some(i) == report.minimiser => "minimum".to_string(),
            None => "eligible".to_string(),
        };
        rows.push(Row {
            label: t.rho.to_string(),
            run: &t.summary,
            plain,
            verdict,
        });
    }
    let auto = &report.auto;
    rows.push(Row {
        label: "auto".to_string(),
        run: &auto.summary,
        plain,
        verdict: match auto.rejection {
            Some(r) => format!("rejected: {r} (mean ρ {:.3})", auto.rho),
            None => format!("online estimate (mean ρ {:.3})", auto.rho),
        },
    });
    rows
}

/// Final energy relative to the plain run's, as a percentage of the initial energy.
fn energy_vs_plain(run: &RunSummary, plain: &RunSummary) -> f64 {
    (run.energy_final - plain.energy_final) / plain.energy_initial * 100.0
}

/// The table's columns.
fn columns<'a>() -> [Column<Row<'a>>; 8] {
    [
        Column {
            title: "ρ",
            key: "rho",
            cell: |r| Cell::Text(r.label.clone()),
        },
        Column {
            title: "ms / step",
            key: "ms_per_step",
            cell: |r| Cell::Number(r.run.wall_ms_per_step, 1),
        },
        Column {
            title: "CPU ms / step",
            key: "cpu_ms_per_step",
            cell: |r| Cell::Number(r.run.cpu_ms_per_step.unwrap_or(f64::NAN), 1),
        },
        Column {
            title: "outer it. / step",
            key: "outer_iterations_mean",
            cell: |r| Cell::Number(r.run.outer_iterations_mean, 2),
        },
        Column {
            title: "K_max hits",
            key: "max_iteration_hits",
            cell: |r| Cell::Number(r.run.max_iteration_hits as f64, 0),
        },
        Column {
            title: "max density error %",
            key: "density_error_max_percent",
            cell: |r| Cell::Number(r.run.density_error_max_percent, 3),
        },
        Column {
            title: "final energy vs plain %",
            key: "energy_vs_plain_percent",
            cell: |r| Cell::Number(energy_vs_plain(r.run, r.plain), 3),
        },
        Column {
            title: "verdict",
            key: "verdict",
            cell: |r| Cell::Text(r.verdict.clone()),
        },
    ]
}

/// The sweep as GitHub Markdown: the plain iteration first, then one row per ρ.
pub fn markdown(report: &TuneReport) -> String {
    table::markdown(&columns(), &rows(report))
}

/// The sweep as CSV; the plain run's `rho` cell is `plain`.
pub fn csv(report: &TuneReport) -> String {
    table::csv(&columns(), &rows(report))
}
