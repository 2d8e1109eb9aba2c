//! The grid of ρ values a sweep tries.

use projfluid::Error;

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

#[cfg(test)]
mod tests {
    use super::*;

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
}
