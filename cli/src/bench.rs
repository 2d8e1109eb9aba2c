//! The solver benchmark of the paper's Table 1: every scene with every global solver, the same
//! parameters and stopping rule, the first N steps; a table of cost, accuracy and an
//! "artifacts" verdict, written as Markdown and CSV, and bar charts of time and iterations.

use crate::driver::{RunError, RunLength, Runner};
use crate::plot::BarChart;
use crate::summary::RunSummary;
use crate::table::{self, Cell, Column};
use projfluid::scene::Scene;
use projfluid::{Error, SolverKind};
use std::convert::Infallible;
use std::fmt;

/// The paper's protocol: the mean over the first 80 time steps.
pub const DEFAULT_STEPS: u64 = 80;

/// A run "has artifacts" when its mean density error exceeds this (percent; docs/method.md §10.1
/// asks for ≲ 0.1 %).
pub const AVG_DENSITY_ERROR_LIMIT_PERCENT: f64 = 0.1;
/// … or its largest density error exceeds this (percent; the upper end of the ≲ 1–3 % of
/// docs/method.md §10.1).
pub const MAX_DENSITY_ERROR_LIMIT_PERCENT: f64 = 3.0;
/// … or its total energy ever rose above the initial value by more than this fraction of it
/// (implicit Euler and XSPH only dissipate, so a converged run never rises at all).
pub const ENERGY_RISE_LIMIT: f64 = 0.01;

/// One reason a run counts as having artifacts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Artifact {
    /// This many particles had a non-finite position or velocity.
    NotFinite(usize),
    /// This many particles left the container.
    Escaped(usize),
    /// Mean density error (percent) above [`AVG_DENSITY_ERROR_LIMIT_PERCENT`].
    AverageDensityError(f64),
    /// Largest density error (percent) above [`MAX_DENSITY_ERROR_LIMIT_PERCENT`].
    MaxDensityError(f64),
    /// Total energy rose above its initial value by this fraction (above [`ENERGY_RISE_LIMIT`]).
    EnergyRise(f64),
}

impl fmt::Display for Artifact {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Artifact::NotFinite(n) => write!(f, "{n} NaN"),
            Artifact::Escaped(n) => write!(f, "{n} escaped"),
            Artifact::AverageDensityError(p) => write!(f, "avg density error {p:.3} %"),
            Artifact::MaxDensityError(p) => write!(f, "max density error {p:.2} %"),
            Artifact::EnergyRise(x) => write!(f, "energy +{:.2} %", x * 100.0),
        }
    }
}

/// The artifacts rule: every limit a run broke (empty when none). A non-finite statistic
/// counts as broken.
pub fn artifacts(s: &RunSummary) -> Vec<Artifact> {
    let mut found = Vec::new();
    if s.nan > 0 {
        found.push(Artifact::NotFinite(s.nan));
    }
    if s.escaped > 0 {
        found.push(Artifact::Escaped(s.escaped));
    }
    if above(s.density_error_avg_percent, AVG_DENSITY_ERROR_LIMIT_PERCENT) {
        found.push(Artifact::AverageDensityError(s.density_error_avg_percent));
    }
    if above(s.density_error_max_percent, MAX_DENSITY_ERROR_LIMIT_PERCENT) {
        found.push(Artifact::MaxDensityError(s.density_error_max_percent));
    }
    if let Some(rise) = s.energy_rise()
        && above(rise, ENERGY_RISE_LIMIT)
    {
        found.push(Artifact::EnergyRise(rise));
    }
    found
}

/// `value` exceeds `limit`, or is NaN (a broken statistic never passes a limit).
pub(crate) fn above(value: f64, limit: f64) -> bool {
    value.is_nan() || value > limit
}

/// One scene run with one solver.
#[derive(Clone, Debug, PartialEq)]
pub struct BenchRow {
    /// The run's statistics.
    pub summary: RunSummary,
    /// What the artifacts rule found.
    pub artifacts: Vec<Artifact>,
}

impl BenchRow {
    /// The verdict as one cell: `none`, or the broken limits joined by `; `.
    pub fn verdict(&self) -> String {
        if self.artifacts.is_empty() {
            return "none".to_string();
        }
        let parts: Vec<String> = self.artifacts.iter().map(|a| a.to_string()).collect();
        parts.join("; ")
    }

    /// Relative energy rise in percent (0 when the energy never rose; NaN when undefined).
    fn energy_rise_percent(&self) -> f64 {
        self.summary.energy_rise().map_or(f64::NAN, |x| x * 100.0)
    }
}

/// What [`run_bench`] is doing, for progress messages.
#[derive(Clone, Copy, Debug)]
pub enum BenchEvent<'a> {
    /// A run of `scene` with `solver` starts.
    Start {
        /// Scene name.
        scene: &'a str,
        /// Solver.
        solver: SolverKind,
    },
    /// A run finished.
    Done(&'a BenchRow),
}

/// Steps each solver runs before the next one takes its turn ([`run_bench`]'s `turn`).
pub const DEFAULT_TURN: u64 = 10;

/// Runs every scene with every solver for `steps` steps, each from the scene's initial state
/// with the scene's parameters except the solver, and returns one row per run, scenes outer,
/// solvers inner, in the given orders.
///
/// The solvers of a scene take turns of `turn` steps each, round after round, so that a
/// machine whose speed drifts (other programs, a shared host) slows them alike and the ratios
/// of their times hold; every world is then in memory at once. With `turn` 0 each solver runs
/// to the end before the next starts, one world at a time. The turns change no result but the
/// times: each world steps exactly as it would alone.
pub fn run_bench(
    scenes: &[Scene],
    solvers: &[SolverKind],
    steps: u64,
    turn: u64,
    mut on_event: impl FnMut(BenchEvent<'_>),
) -> Result<Vec<BenchRow>, Error> {
    let mut rows = Vec::with_capacity(scenes.len() * solvers.len());
    for scene in scenes {
        if turn == 0 {
            for solver in solvers {
                let group = std::slice::from_ref(solver);
                rows.extend(run_in_turns(scene, group, steps, steps, &mut on_event)?);
            }
        } else {
            rows.extend(run_in_turns(scene, solvers, steps, turn, &mut on_event)?);
        }
    }
    Ok(rows)
}

/// Runs `scene` with every solver of `solvers` for `steps` steps, in turns of `turn` steps.
fn run_in_turns(
    scene: &Scene,
    solvers: &[SolverKind],
    steps: u64,
    turn: u64,
    on_event: &mut impl FnMut(BenchEvent<'_>),
) -> Result<Vec<BenchRow>, Error> {
    let mut runs = Vec::with_capacity(solvers.len());
    for &solver in solvers {
        on_event(BenchEvent::Start {
            scene: &scene.name,
            solver,
        });
        let mut scene = scene.clone();
        scene.params.solver = solver;
        let world = scene.build_world()?;
        let runner = Runner::new(&world, RunLength::Steps(steps))?;
        runs.push((world, runner));
    }
    let mut stepping = true;
    while stepping {
        stepping = false;
        for (world, runner) in &mut runs {
            for _ in 0..turn {
                let step = runner.steps() + 1;
                match runner.step(world) {
                    Ok(Some(_)) => stepping = true,
                    Ok(None) => break,
                    Err(error) => {
                        return Err(RunError::<Infallible>::Step { step, error }.into());
                    }
                }
            }
        }
    }
    let mut rows = Vec::with_capacity(runs.len());
    for (world, runner) in runs {
        let summary = runner.finish().summary(&scene.name, &world);
        let row = BenchRow {
            artifacts: artifacts(&summary),
            summary,
        };
        on_event(BenchEvent::Done(&row));
        rows.push(row);
    }
    Ok(rows)
}

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

#[cfg(test)]
mod tests {
    use super::*;

    fn clean() -> RunSummary {
        RunSummary {
            scene: "s".into(),
            solver: "jacobi1".into(),
            density_error_avg_percent: 0.01,
            density_error_max_percent: 0.2,
            energy_initial: 100.0,
            energy_max: 100.0,
            energy_final: 90.0,
            ..RunSummary::default()
        }
    }

    #[test]
    fn artifacts_rule_flags_each_broken_limit() {
        assert!(artifacts(&clean()).is_empty());
        let broken = RunSummary {
            nan: 2,
            escaped: 3,
            density_error_avg_percent: 0.2,
            density_error_max_percent: f64::NAN,
            energy_max: 101.5,
            ..clean()
        };
        let found = artifacts(&broken);
        assert_eq!(found.len(), 5, "{found:?}");
        assert_eq!(found[4], Artifact::EnergyRise(0.015));
        let row = BenchRow {
            summary: broken,
            artifacts: found,
        };
        assert!(
            row.verdict()
                .starts_with("2 NaN; 3 escaped; avg density error 0.200 %")
        );
    }

    /// Taking turns changes no result but the times: every world steps as it would alone,
    /// with its own energy datum and statistics.
    #[test]
    fn solvers_taking_turns_match_solvers_run_one_after_another() {
        let mut scene = Scene::builtin("dam_break_small").unwrap();
        scene.params.threads = 1;
        let solvers = [SolverKind::Chebyshev, SolverKind::Cg, SolverKind::Jacobi1];
        let run = |turn| {
            let mut events = Vec::new();
            let rows = run_bench(std::slice::from_ref(&scene), &solvers, 16, turn, |e| {
                events.push(match e {
                    BenchEvent::Start { solver, .. } => format!("start {}", solver.name()),
                    BenchEvent::Done(row) => format!("done {}", row.summary.solver),
                })
            })
            .unwrap();
            let untimed: Vec<RunSummary> = rows
                .into_iter()
                .map(|r| RunSummary {
                    wall_ms_per_step: 0.0,
                    cpu_ms_per_step: None,
                    ms_per_step_breakdown: [0.0; 4],
                    ..r.summary
                })
                .collect();
            (untimed, events)
        };
        let (alone, events) = run(0);
        assert_eq!(
            events,
            ["start chebyshev", "done chebyshev", "start cg", "done cg"]
                .into_iter()
                .chain(["start jacobi1", "done jacobi1"])
                .collect::<Vec<_>>()
        );
        assert!(
            alone
                .iter()
                .all(|s| s.steps == 16 && s.outer_iterations_mean > 1.0)
        );
        assert_ne!(alone[0].positions_hash, alone[1].positions_hash);
        // Turns of 5 steps (the last one short), and turns longer than the run.
        for turn in [5, 100] {
            let (turns, events) = run(turn);
            assert_eq!(turns, alone, "turn {turn}");
            assert_eq!(
                events[..3],
                ["start chebyshev", "start cg", "start jacobi1"]
            );
            assert_eq!(events[3..], ["done chebyshev", "done cg", "done jacobi1"]);
        }
    }

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
