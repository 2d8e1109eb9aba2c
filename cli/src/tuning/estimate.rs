//! Estimators of the plain iteration's contraction from its outer displacements δ_k, usable on
//! any δ_k sequence.

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
}
