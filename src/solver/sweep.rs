//! One Jacobi sweep on the diagonal system fused with Chebyshev's extrapolation and the
//! displacement measure, so that a single-sweep solver costs one pass over the particles
//! (docs/method.md §3.6, §3.7).

use super::Chebyshev;
use crate::{Vec3, reduce};

/// The global step of a solver that is one Jacobi sweep on the diagonal system, fused with
/// Chebyshev's extrapolation and the displacement, for the particles of one chunk.
pub struct Sweep<'a> {
    /// Â_jj (kg).
    pub diagonal: &'a [f64],
    /// X^(k) (m).
    pub current: &'a [Vec3],
    /// The recurrence and its weight ω, when the extrapolation changes the iterate.
    pub chebyshev: Option<(&'a Chebyshev, f64)>,
}

impl Sweep<'_> {
    /// For the particles `first..` of the right-hand sides `rhs` (kg·m), replaces X^(k−1)_j
    /// in `previous` by X^(k+1)_j (m): the sweep X_j + (b_j − Â_jj·X_j)/Â_jj, bitwise as
    /// [`super::Jacobi`] computes it, then extrapolated, which reads X^(k−1)_j alone, so the
    /// three iterates need two buffers. Returns max_j |X^(k+1)_j − X^(k)_j| (m) over the chunk.
    pub fn apply(&self, first: usize, rhs: &[Vec3], previous: &mut [Vec3]) -> f64 {
        let mut largest = f64::NEG_INFINITY;
        for (j, (b, slot)) in (first..).zip(rhs.iter().zip(previous)) {
            let (x, d) = (self.current[j], self.diagonal[j]);
            let mut plain = x + (b - x * d) / d;
            if let Some((chebyshev, omega)) = self.chebyshev {
                plain = chebyshev.extrapolated(omega, plain, x, *slot);
            }
            *slot = plain;
            largest = reduce::nan_max(largest, (plain - x).norm());
        }
        largest
    }
}
