//! Choosing Chebyshev's ρ the paper's way (docs/method.md §5.2): estimate the contraction of
//! the plain iteration from the ratios of successive outer displacements δ_k, then sweep ρ over
//! a grid from one warmed-up state and pick the cheapest value that stays as accurate and as
//! dissipative as the plain iteration.
//!
//! The estimators ([`fit_contraction`], [`contraction_estimate`], [`median`]) work on any δ_k
//! sequence, e.g. [`projfluid::World::last_displacements`], so an online choice of ρ can use them too.

mod charts;
mod table;

pub use charts::charts;
pub use table::{csv, markdown};

use crate::bench::above;
use crate::driver::{self, RunLength};
use crate::summary::RunSummary;
use projfluid::scene::Scene;
use projfluid::{Error, SolverKind, World};
use std::fmt;

/// The contraction factor ρ̂ of a geometrically shrinking sequence of displacements (m): the
/// least-squares fit of ln δ_k = a + k·ln ρ̂ over all entries, ρ̂ = exp(slope). Entries that
/// are zero or not finite are left out (their k still counts). `None` with fewer than two
/// usable entries.
pub fn fit_contraction(displacements: &[f64]) -> Option<f64> {
    let points: Vec<(f64, f64)> = displacements
        .iter()
        .enumerate()
        .filter(|(_, d)| d.is_finite() && **d > 0.0)
        .map(|(k, d)| (k as f64, d.ln()))
        .collect();
    if points.len() < 2 {
        return None;
    }
    let n = points.len() as f64;
    let (mean_k, mean_y) = points
        .iter()
        .fold((0.0, 0.0), |(a, b), (k, y)| (a + k / n, b + y / n));
    let (sxy, sxx) = points.iter().fold((0.0, 0.0), |(sxy, sxx), (k, y)| {
        (
            sxy + (k - mean_k) * (y - mean_y),
            sxx + (k - mean_k).powi(2),
        )
    });
    Some((sxy / sxx).exp())
}

/// ρ̂ of one step of the plain iteration (docs/method.md §5.2, step 2): [`fit_contraction`] over
/// the last half of the step's displacements δ_k, where the iteration is closest to its
/// asymptotic linear rate.
pub fn contraction_estimate(displacements: &[f64]) -> Option<f64> {
    fit_contraction(&displacements[displacements.len() / 2..])
}

/// The median of the finite `values` (the mean of the middle two for an even count); `None`
/// when there is none.
pub fn median(values: &[f64]) -> Option<f64> {
    let mut v: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
    v.sort_by(f64::total_cmp);
    let n = v.len();
    match n {
        0 => None,
        _ if n % 2 == 1 => Some(v[n / 2]),
        _ => Some(0.5 * (v[n / 2 - 1] + v[n / 2])),
    }
}

/// Largest ρ a grid may hold: ρ = 1 is outside the method's range ([`projfluid::Params::validate`]
/// demands ρ < 1), so grid points at or above 1 are replaced by this value.
pub const MAX_GRID_RHO: f64 = 0.99;

/// The sweep's ρ values `from, from + step, …` up to `to` (inclusive, with a tolerance of
/// 10⁻⁹ for round-off); points ≥ 1 become [`MAX_GRID_RHO`], duplicates are dropped.
/// Requires 0 ≤ from ≤ to ≤ 1, step > 0 and at most 1000 points.
pub fn rho_grid(from: f64, to: f64, step: f64) -> Result<Vec<f64>, Error> {
    if !(from.is_finite() && (0.0..=1.0).contains(&from)) {
        return Err(Error::invalid("from", from, "must lie in [0, 1]"));
    }
    if !(to.is_finite() && (from..=1.0).contains(&to)) {
        return Err(Error::invalid("to", to, "must lie in [from, 1]"));
    }
    if !(step.is_finite() && step > 0.0 && (to - from) / step <= 1000.0) {
        return Err(Error::invalid(
            "step",
            step,
            "must be positive and give at most 1000 grid points",
        ));
    }
    let count = ((to - from) / step + 1e-9).floor() as usize + 1;
    let mut grid: Vec<f64> = (0..count)
        .map(|i| {
            // Round to 12 digits so that 0.65 + 3·0.025 prints as 0.725.
            let rho = ((from + i as f64 * step) * 1e12).round() / 1e12;
            if rho >= 1.0 { MAX_GRID_RHO } else { rho }
        })
        .collect();
    grid.dedup();
    Ok(grid)
}

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

/// Why a ρ was not eligible (docs/method.md §5.2, step 3).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Rejection {
    /// This many steps ended at the outer iteration limit.
    MaxIterations(u64),
    /// The final total energy exceeded the plain run's by this fraction of the initial energy
    /// (more than [`ENERGY_MARGIN`]).
    EnergyRise(f64),
    /// The largest density error was this multiple of the plain run's (more than
    /// [`DENSITY_ERROR_FACTOR`]).
    DensityError(f64),
    /// Particles became non-finite or escaped (more than in the plain run).
    Broken,
}

impl fmt::Display for Rejection {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Rejection::MaxIterations(n) => write!(f, "{n} steps hit the iteration limit"),
            Rejection::EnergyRise(x) => write!(f, "energy +{:.2} % over plain", x * 100.0),
            Rejection::DensityError(x) => write!(f, "max density error {x:.2}x plain"),
            Rejection::Broken => f.write_str("NaN or escaped particles"),
        }
    }
}

/// A ρ is rejected if its final total energy exceeds the plain run's by more than this
/// fraction of the initial energy.
pub const ENERGY_MARGIN: f64 = 0.01;
/// A ρ is rejected if its largest density error exceeds the plain run's times this factor.
pub const DENSITY_ERROR_FACTOR: f64 = 1.5;
/// Candidates whose cost lies within this fraction of the minimum count as equally good; the
/// smallest such ρ next to the minimiser is taken (the cost rises steeply above the optimum).
pub const COST_TOLERANCE: f64 = 0.03;

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

/// The rejection rules of docs/method.md §5.2, step 3, against the plain run.
pub fn judge(run: &RunSummary, plain: &RunSummary) -> Option<Rejection> {
    if run.nan > plain.nan || run.escaped > plain.escaped {
        return Some(Rejection::Broken);
    }
    if run.max_iteration_hits > 0 {
        return Some(Rejection::MaxIterations(run.max_iteration_hits));
    }
    let scale = plain.energy_initial.abs().max(f64::MIN_POSITIVE);
    let rise = (run.energy_final - plain.energy_final) / scale;
    if above(rise, ENERGY_MARGIN) {
        return Some(Rejection::EnergyRise(rise));
    }
    let (err, reference) = (
        run.density_error_max_percent,
        plain.density_error_max_percent,
    );
    if above(err, DENSITY_ERROR_FACTOR * reference) {
        return Some(Rejection::DensityError(err / reference));
    }
    None
}

/// The minimiser of the mean outer iterations among eligible trials (the smaller ρ on ties), and
/// the chosen trial: walking down from the minimiser while the next smaller ρ is eligible and
/// costs at most (1 + [`COST_TOLERANCE`]) times the minimum. `trials` must be ascending in ρ.
pub fn pick(trials: &[Trial]) -> (Option<usize>, Option<usize>) {
    let cost = |i: usize| trials[i].summary.outer_iterations_mean;
    let eligible = |i: usize| trials[i].rejection.is_none();
    let minimiser = (0..trials.len())
        .filter(|&i| eligible(i))
        .min_by(|&a, &b| cost(a).total_cmp(&cost(b)));
    let best = minimiser.map(|m| {
        let limit = cost(m) * (1.0 + COST_TOLERANCE);
        let mut best = m;
        while best > 0 && eligible(best - 1) && cost(best - 1) <= limit {
            best -= 1;
        }
        best
    });
    (minimiser, best)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fit_recovers_a_geometric_rate_and_ignores_zeros() {
        let seq: Vec<f64> = (0..20).map(|k| 3e-3 * 0.9f64.powi(k)).collect();
        assert!((fit_contraction(&seq).unwrap() - 0.9).abs() < 1e-12);
        // A transient in the first half does not disturb the estimate over the second half.
        let mut noisy = seq.clone();
        noisy[0] = 1.0;
        noisy[3] = 1e-9;
        assert!((contraction_estimate(&noisy).unwrap() - 0.9).abs() < 1e-12);
        assert!((fit_contraction(&[0.0, 2.0, 0.0, 0.5]).unwrap() - 0.5).abs() < 1e-12);
        assert_eq!(fit_contraction(&[1.0]), None);
        assert_eq!(fit_contraction(&[0.0, f64::NAN, 1.0]), None);
    }

    #[test]
    fn median_of_odd_even_and_empty() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median(&[4.0, 1.0, f64::NAN, 2.0, 3.0]), Some(2.5));
        assert_eq!(median(&[]), None);
    }

    #[test]
    fn grid_includes_its_end_and_keeps_rho_below_one() {
        let grid = rho_grid(0.65, 1.0, 0.025).unwrap();
        assert_eq!(grid.len(), 15);
        assert_eq!(grid[3], 0.725);
        assert_eq!(grid[13], 0.975);
        assert_eq!(grid[14], MAX_GRID_RHO);
        assert_eq!(rho_grid(0.9, 0.9, 0.1).unwrap(), [0.9]);
        for (from, to, step, field) in [
            (-0.1, 0.9, 0.1, "from"),
            (0.9, 0.8, 0.1, "to"),
            (0.5, 0.9, 0.0, "step"),
            (0.0, 1.0, 1e-6, "step"),
        ] {
            let e = rho_grid(from, to, step).unwrap_err();
            assert!(e.to_string().starts_with(field), "{e}");
        }
    }

    fn trial(rho: f64, outer: f64, rejection: Option<Rejection>) -> Trial {
        let summary = RunSummary {
            outer_iterations_mean: outer,
            ..RunSummary::default()
        };
        Trial {
            rho,
            summary,
            rejection,
        }
    }

    #[test]
    fn pick_takes_the_smallest_rho_within_three_percent_next_to_the_minimum() {
        let hit = Some(Rejection::MaxIterations(1));
        let trials = [
            trial(0.7, 12.0, None),
            trial(0.75, 10.2, None),
            trial(0.8, 10.1, None),
            trial(0.85, 10.0, None),
            trial(0.9, 9.0, hit),
        ];
        assert_eq!(pick(&trials), (Some(3), Some(1)));
        // A rejected value breaks the walk down.
        let mut gap = trials.clone();
        gap[2].rejection = hit;
        assert_eq!(pick(&gap), (Some(3), Some(3)));
        let none = [trial(0.9, 9.0, hit)];
        assert_eq!(pick(&none), (None, None));
    }

    #[test]
    fn judge_applies_the_rejection_rules() {
        let plain = RunSummary {
            energy_initial: 100.0,
            energy_final: 80.0,
            density_error_max_percent: 0.2,
            ..RunSummary::default()
        };
        let ok = RunSummary {
            energy_final: 80.9,
            density_error_max_percent: 0.29,
            ..plain.clone()
        };
        assert_eq!(judge(&ok, &plain), None);
        let hot = RunSummary {
            energy_final: 81.5,
            ..ok.clone()
        };
        assert!(
            matches!(judge(&hot, &plain), Some(Rejection::EnergyRise(x)) if (x - 0.015).abs() < 1e-12)
        );
        let dense = RunSummary {
            density_error_max_percent: 0.4,
            ..ok.clone()
        };
        assert_eq!(judge(&dense, &plain), Some(Rejection::DensityError(2.0)));
        let capped = RunSummary {
            max_iteration_hits: 2,
            ..ok.clone()
        };
        assert_eq!(judge(&capped, &plain), Some(Rejection::MaxIterations(2)));
        let nan = RunSummary { nan: 1, ..ok };
        assert_eq!(judge(&nan, &plain), Some(Rejection::Broken));
    }
}
