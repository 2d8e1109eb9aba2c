//! The artifacts rule: the limits on density error, energy and lost particles a run must keep.

use crate::summary::RunSummary;
use std::fmt;

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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bench::BenchRow;
    use crate::bench::tests::clean;

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
}
