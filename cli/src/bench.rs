//! The solver benchmark of the paper's Table 1: every scene with every global solver, the same
//! parameters and stopping rule, the first N steps; a table of cost, accuracy and an
//! "artifacts" verdict, written as Markdown and CSV, and bar charts of time and iterations.
//!
//! The runs live here; the artifacts rule, the table and the charts live in submodules.

mod artifacts;
mod charts;
mod table;

pub(crate) use artifacts::above;
pub use artifacts::{
    AVG_DENSITY_ERROR_LIMIT_PERCENT, Artifact, ENERGY_RISE_LIMIT, MAX_DENSITY_ERROR_LIMIT_PERCENT,
    artifacts,
};
pub use charts::charts;
pub use table::{csv, markdown};

use crate::driver::{RunError, RunLength, Runner};
use crate::summary::RunSummary;
use projfluid::scene::Scene;
use projfluid::{Error, SolverKind};
use std::convert::Infallible;

/// The paper's protocol: the mean over the first 80 time steps.
pub const DEFAULT_STEPS: u64 = 80;

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

#[cfg(test)]
mod tests {
    use super::*;

    /// A run that breaks no limit.
    pub(super) fn clean() -> RunSummary {
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
                .all(|s| s.steps == 16 && s.outer_iterations_mean >= 1.0)
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
}
