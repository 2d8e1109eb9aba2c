//! The benchmark as a table, in Markdown and as CSV: one row per run.

use super::BenchRow;
use crate::table::{self, Cell, Column};

/// The columns of [`markdown`] and [`csv`].
const COLUMNS: [Column<BenchRow>; 14] = [
    Column {
        title: "scene",
        key: "scene",
        cell: |r| Cell::Text(r.summary.scene.clone()),
    },
    Column {
        title: "solver",
        key: "solver",
        cell: |r| Cell::Text(r.summary.solver.clone()),
    },
    Column {
        title: "particles",
        key: "particles",
        cell: |r| Cell::Number(r.summary.particles as f64, 0),
    },
    Column {
        title: "threads",
        key: "threads",
        cell: |r| Cell::Number(r.summary.threads as f64, 0),
    },
    Column {
        title: "steps",
        key: "steps",
        cell: |r| Cell::Number(r.summary.steps as f64, 0),
    },
    Column {
        title: "ms / step",
        key: "ms_per_step",
        cell: |r| Cell::Number(r.summary.wall_ms_per_step, 1),
    },
    Column {
        title: "CPU ms / step",
        key: "cpu_ms_per_step",
        cell: |r| Cell::Number(r.summary.cpu_ms_per_step.unwrap_or(f64::NAN), 1),
    },
    Column {
        title: "outer it. / step",
        key: "outer_iterations_mean",
        cell: |r| Cell::Number(r.summary.outer_iterations_mean, 2),
    },
    Column {
        title: "inner it. / step",
        key: "inner_iterations_mean",
        cell: |r| Cell::Number(r.summary.inner_iterations_mean, 2),
    },
    Column {
        title: "K_max hits",
        key: "max_iteration_hits",
        cell: |r| Cell::Number(r.summary.max_iteration_hits as f64, 0),
    },
    Column {
        title: "avg density error %",
        key: "density_error_avg_percent",
        cell: |r| Cell::Number(r.summary.density_error_avg_percent, 4),
    },
    Column {
        title: "max density error %",
        key: "density_error_max_percent",
        cell: |r| Cell::Number(r.summary.density_error_max_percent, 3),
    },
    Column {
        title: "energy rise %",
        key: "energy_rise_percent",
        cell: |r| Cell::Number(r.energy_rise_percent(), 2),
    },
    Column {
        title: "artifacts",
        key: "artifacts",
        cell: |r| Cell::Text(r.verdict()),
    },
];

/// The table as GitHub Markdown, one row per run.
pub fn markdown(rows: &[BenchRow]) -> String {
    table::markdown(&COLUMNS, rows)
}

/// The table as CSV (header line of keys, numbers in full precision).
pub fn csv(rows: &[BenchRow]) -> String {
    table::csv(&COLUMNS, rows)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bench::tests::clean;

    #[test]
    fn tables_have_one_line_per_row_and_matching_columns() {
        let rows = vec![
            BenchRow {
                summary: clean(),
                artifacts: vec![],
            };
            2
        ];
        let md = markdown(&rows);
        assert_eq!(md.lines().count(), 4);
        assert!(
            md.lines()
                .all(|l| l.matches('|').count() == COLUMNS.len() + 1)
        );
        let csv = csv(&rows);
        assert_eq!(csv.lines().count(), 3);
        assert!(csv.lines().all(|l| l.split(',').count() == COLUMNS.len()));
        assert!(csv.lines().nth(1).unwrap().ends_with(",0,none"));
    }
}
