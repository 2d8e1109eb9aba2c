//! Jacobi iteration x ← x + D⁻¹(b − Ax), matrix-free (docs/method.md §3.6).

use super::{GlobalSolver, MAX_INNER_ITERATIONS, RESIDUAL_TOLERANCE, SystemMatrix};
use crate::{Vec3, reduce};
use rayon::prelude::*;

/// Jacobi sweeps: either exactly one, or until the relative residual is small.
#[derive(Clone, Debug)]
pub struct Jacobi {
    max_sweeps: usize,
    check_residual: bool,
    residual: Vec<Vec3>,
}

impl Jacobi {
    /// Exactly one sweep per solve (exact for the diagonal formulation).
    pub fn single_sweep() -> Self {
        Self {
            max_sweeps: 1,
            check_residual: false,
            residual: Vec::new(),
        }
    }

    /// Sweeps until ‖b − Ax‖ ≤ 1e-10‖b‖ or 100 sweeps.
    pub fn converged() -> Self {
        Self {
            max_sweeps: MAX_INNER_ITERATIONS,
            check_residual: true,
            residual: Vec::new(),
        }
    }
}

impl GlobalSolver for Jacobi {
    fn try_reserve(&mut self, unknowns: usize) -> Result<(), std::collections::TryReserveError> {
        // The single sweep is fused into the step's pass and never solves here.
        if self.single_diagonal_sweep() {
            return Ok(());
        }
        crate::reserve::reserve_total(&mut self.residual, unknowns)
    }

    fn solve(&mut self, matrix: &dyn SystemMatrix, b: &[Vec3], x: &mut [Vec3]) -> usize {
        self.residual.resize(x.len(), Vec3::zeros());
        let b_norm = if self.check_residual {
            reduce::sum(b, |v| v.norm_squared()).sqrt()
        } else {
            0.0
        };
        let mut sweeps = 0;
        while sweeps < self.max_sweeps {
            matrix.apply(x, &mut self.residual);
            self.residual
                .par_iter_mut()
                .zip(b.par_iter())
                .for_each(|(r, b)| *r = b - *r);
            if self.check_residual {
                let r_norm = reduce::sum(&self.residual, |v| v.norm_squared()).sqrt();
                if r_norm <= RESIDUAL_TOLERANCE * b_norm {
                    break;
                }
            }
            x.par_iter_mut()
                .zip(self.residual.par_iter().zip(matrix.diagonal().par_iter()))
                .for_each(|(x, (r, d))| *x += r / *d);
            sweeps += 1;
        }
        sweeps
    }

    fn single_diagonal_sweep(&self) -> bool {
        self.max_sweeps == 1 && !self.check_residual
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::tests::{DenseSystem, rhs};

    #[test]
    fn converged_jacobi_matches_dense_solution() {
        let sys = DenseSystem::ring(12, 4.0);
        let b = rhs(12);
        let mut x = vec![Vec3::zeros(); 12];
        let sweeps = Jacobi::converged().solve(&sys, &b, &mut x);
        assert!(
            sweeps > 1 && sweeps < MAX_INNER_ITERATIONS,
            "{sweeps} sweeps"
        );
        for (x, e) in x.iter().zip(sys.exact(&b)) {
            assert!((x - e).norm() < 1e-8 * e.norm().max(1.0), "{x:?} vs {e:?}");
        }
    }

    #[test]
    fn single_sweep_is_one_jacobi_step() {
        let sys = DenseSystem::ring(6, 4.0);
        let b = rhs(6);
        let mut x = vec![Vec3::repeat(1.0); 6];
        assert_eq!(Jacobi::single_sweep().solve(&sys, &b, &mut x), 1);
        // x1 = x0 + (b − A x0)/4 with A x0 = (4 − 2)·1 = 2 per component.
        for (x, b) in x.iter().zip(&b) {
            assert!((x - (Vec3::repeat(1.0) + (b - Vec3::repeat(2.0)) / 4.0)).norm() < 1e-15);
        }
    }
}
