//! Which ρ a sweep takes: the rules that reject a trial against the plain run, and the pick
//! among the eligible ones (docs/method.md §5.2, step 3).

use super::Trial;
use crate::bench::above;
use crate::summary::RunSummary;
use std::fmt;

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
