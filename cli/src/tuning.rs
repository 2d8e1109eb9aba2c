//! Choosing Chebyshev's ρ the paper's way (docs/method.md §5.2): estimate the contraction of
//! the plain iteration from the ratios of successive outer displacements δ_k, then sweep ρ over
//! a grid from one warmed-up state and pick the cheapest value that stays as accurate and as
//! dissipative as the plain iteration.
//!
//! The estimators ([`fit_contraction`], [`contraction_estimate`], [`median`]) work on any δ_k
//! sequence, e.g. [`projfluid::World::last_displacements`], so an online choice of ρ can use them too.
//!
//! Submodules hold the estimators, the ρ grid ([`rho_grid`]), the rules that reject and pick a
//! value ([`judge`], [`pick`]), and the table and charts of a sweep; the sweep itself is
//! [`tune_rho`].

mod charts;
mod choice;
mod estimate;
mod grid;
mod table;

pub use charts::charts;
pub use choice::{COST_TOLERANCE, DENSITY_ERROR_FACTOR, ENERGY_MARGIN, Rejection, judge, pick};
pub use estimate::{contraction_estimate, fit_contraction, median};
pub use grid::{MAX_GRID_RHO, rho_grid};
pub use table::{csv, markdown};

use crate::driver::{self, RunLength};
use crate::summary::RunSummary;
use projfluid::scene::Scene;
use projfluid::{Error, SolverKind, World};

/// How a ρ sweep runs (defaults: docs/method.md §5.2).
#[derive(Clone, Debug, PartialEq)]
pub struct TuneConfig {
    /// Steps of plain iteration from the scene's start to the snapshot every run starts from.
    pub warmup_steps: u64,
    /// Steps T of every measured run.
    pub steps: u64,
    /// Fixed number K of outer iterations per step in the estimation run.
    pub estimate_iterations: usize,
    /// The ρ values to try, ascending.
    pub grid: Vec<f64>,
}

impl Default for TuneConfig {
    fn default() -> Self {
        Self {
            warmup_steps: 20,
            steps: 60,
            estimate_iterations: 60,
            grid: rho_grid(0.65, 1.0, 0.025).unwrap_or_default(),
        }
    }
}

/// One measured run of the sweep.
#[derive(Clone, Debug, PartialEq)]
pub struct Trial {
    /// Chebyshev's ρ.
    pub rho: f64,
    /// The run's summary (its steps only, not the warm-up).
    pub summary: RunSummary,
    /// Why the value is not eligible, if it is not.
    pub rejection: Option<Rejection>,
}

/// The outcome of [`tune_rho`].
#[derive(Clone, Debug, PartialEq)]
pub struct TuneReport {
    /// The run settings.
    pub config: TuneConfig,
    /// Median over steps of the per-step contraction estimate ρ̂ of the plain iteration
    /// (`None` if no step gave one).
    pub estimate: Option<f64>,
    /// Per-step estimates the median was taken over.
    pub step_estimates: Vec<f64>,
    /// The plain iteration (`jacobi1`) with the production stopping rule, the reference.
    pub plain: RunSummary,
    /// One trial per grid value, ascending in ρ.
    pub trials: Vec<Trial>,
    /// Index into `trials` of the eligible value with the fewest outer iterations.
    pub minimiser: Option<usize>,
    /// Index into `trials` of the chosen value: the smallest ρ reachable from the minimiser
    /// through eligible neighbours whose cost is within [`COST_TOLERANCE`] of the minimum.
    pub best: Option<usize>,
    /// Chebyshev with ρ estimated online (`auto_rho`) from the same state, for comparison;
    /// its `rho` is the mean online estimate.
    pub auto: Trial,
}

impl TuneReport {
    /// The chosen ρ, if any value was eligible.
    pub fn best_rho(&self) -> Option<f64> {
        self.best.map(|i| self.trials[i].rho)
    }
}

/// What [`tune_rho`] is doing, for progress messages.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Phase {
    /// The fixed-K plain run that estimates ρ̂.
    Estimate,
    /// The plain reference run.
    Plain,
    /// The run with this ρ.
    Rho(f64),
    /// The run with ρ estimated online.
    Auto,
}

/// Runs the whole procedure of docs/method.md §5.2 on `scene` (its parameters as given, e.g.
/// τ, K_max, threads, Chebyshev delay and ω₂ rule): every run starts from the same state
/// after `warmup_steps` of plain iteration (rebuilt and re-run, which is deterministic), the
/// estimation run forces `estimate_iterations` outer iterations per step, the plain run and
/// one run per grid value use the production stopping rule. The objective is the mean number
/// of outer iterations per step (deterministic); wall time is recorded alongside. `on_phase`
/// is called before each run.
pub fn tune_rho(
    scene: &Scene,
    config: &TuneConfig,
    mut on_phase: impl FnMut(Phase),
) -> Result<TuneReport, Error> {
    if config.steps == 0 {
        return Err(Error::invalid("steps", 0, "must be at least 1"));
    }
    if config.grid.is_empty()
        || config
            .grid
            .windows(2)
            .any(|w| w[0].partial_cmp(&w[1]) != Some(std::cmp::Ordering::Less))
    {
        return Err(Error::invalid(
            "grid",
            format!("{:?}", config.grid),
            "must hold at least one ρ, in ascending order",
        ));
    }
    let length = RunLength::Steps(config.steps);

    on_phase(Phase::Estimate);
    let mut world = snapshot(scene, config.warmup_steps)?;
    let k = config.estimate_iterations;
    world.set_outer_iterations(k, k)?;
    let mut step_estimates = Vec::new();
    driver::run(&mut world, length, |r| {
        step_estimates.extend(contraction_estimate(r.world.last_displacements()));
        Ok::<(), std::convert::Infallible>(())
    })?;

    on_phase(Phase::Plain);
    let mut world = snapshot(scene, config.warmup_steps)?;
    let plain = driver::run_quietly(&mut world, length)?.summary(&scene.name, &world);

    let mut trials = Vec::with_capacity(config.grid.len());
    for &rho in &config.grid {
        on_phase(Phase::Rho(rho));
        let mut world = snapshot(scene, config.warmup_steps)?;
        let chebyshev = projfluid::ChebyshevParams {
            rho,
            auto_rho: false,
            ..scene.params.chebyshev
        };
        world.set_solver(SolverKind::Chebyshev, chebyshev)?;
        let summary = driver::run_quietly(&mut world, length)?.summary(&scene.name, &world);
        let rejection = judge(&summary, &plain);
        trials.push(Trial {
            rho,
            summary,
            rejection,
        });
    }
    on_phase(Phase::Auto);
    let mut world = snapshot(scene, config.warmup_steps)?;
    let online = projfluid::ChebyshevParams {
        auto_rho: true,
        ..scene.params.chebyshev
    };
    world.set_solver(SolverKind::Chebyshev, online)?;
    let summary = driver::run_quietly(&mut world, length)?.summary(&scene.name, &world);
    let auto = Trial {
        rho: summary.rho,
        rejection: judge(&summary, &plain),
        summary,
    };
    let (minimiser, best) = pick(&trials);
    Ok(TuneReport {
        auto,
        config: config.clone(),
        estimate: median(&step_estimates),
        step_estimates,
        plain,
        trials,
        minimiser,
        best,
    })
}

/// The scene's world after `warmup_steps` steps of plain iteration, with the plain solver still
/// selected.
fn snapshot(scene: &Scene, warmup_steps: u64) -> Result<World, Error> {
    let mut scene = scene.clone();
    scene.params.solver = SolverKind::Jacobi1;
    let mut world = scene.build_world()?;
    driver::run_quietly(&mut world, RunLength::Steps(warmup_steps))?;
    Ok(world)
}
