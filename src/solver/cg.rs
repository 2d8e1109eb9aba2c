//! Matrix-free, unpreconditioned conjugate gradients on A = Â ⊗ I₃ (docs/method.md §3).
//!
//! The three coordinates are solved together as one N×3 block: every inner product sums over
//! all three coordinates, so α and β are shared. Because A = Â ⊗ I₃, this is plain CG on the
//! 3N×3N system A·vec(x) = vec(b), which is SPD whenever Â is, so the method and its
//! convergence guarantees are those of ordinary CG. All sums go through [`reduce::sum`], so the
//! iterates do not depend on the thread count.

use super::{GlobalSolver, MAX_INNER_ITERATIONS, RESIDUAL_TOLERANCE, SystemMatrix};
use crate::{Vec3, reduce};
use rayon::prelude::*;

/// The true residual r = b − Ax replaces the recurrence every this many iterations.
pub const RESIDUAL_REFRESH: usize = 50;

/// Conjugate gradients: either to convergence or exactly one iteration.
#[derive(Clone, Debug)]
pub struct Cg {
    max_iterations: usize,
    check_residual: bool,
    residual: Vec<Vec3>,
    direction: Vec<Vec3>,
    product: Vec<Vec3>,
}

impl Cg {
    fn with(max_iterations: usize, check_residual: bool) -> Self {
        Self {
            max_iterations,
            check_residual,
            residual: Vec::new(),
            direction: Vec::new(),
            product: Vec::new(),
        }
    }

    /// Iterates until ‖b − Ax‖₂ ≤ 1e-10‖b‖₂ or 100 iterations.
    pub fn converged() -> Self {
        Self::with(MAX_INNER_ITERATIONS, true)
    }

    /// Exactly one CG iteration from the warm start: a steepest-descent step with exact line
    /// search along r = b − Ax (not exact even for the diagonal formulation).
    pub fn single_iteration() -> Self {
        Self::with(1, false)
    }

    fn dot(a: &[Vec3], b: &[Vec3]) -> f64 {
        reduce::sum_over(a.len(), |i| a[i].dot(&b[i]))
    }

    /// r = b − A x.
    fn true_residual(&mut self, matrix: &dyn SystemMatrix, b: &[Vec3], x: &[Vec3]) {
        matrix.apply(x, &mut self.residual);
        self.residual
            .par_iter_mut()
            .zip(b.par_iter())
            .for_each(|(r, b)| *r = b - *r);
    }
}

impl GlobalSolver for Cg {
    fn try_reserve(&mut self, unknowns: usize) -> Result<(), std::collections::TryReserveError> {
        for buffer in [&mut self.residual, &mut self.direction, &mut self.product] {
            crate::reserve::reserve_total(buffer, unknowns)?;
        }
        Ok(())
    }

    fn solve(&mut self, matrix: &dyn SystemMatrix, b: &[Vec3], x: &mut [Vec3]) -> usize {
        let n = x.len();
        self.residual.resize(n, Vec3::zeros());
        self.direction.resize(n, Vec3::zeros());
        self.product.resize(n, Vec3::zeros());
        let b_norm = reduce::sum(b, |v| v.norm_squared()).sqrt();
        self.true_residual(matrix, b, x);
        self.direction.copy_from_slice(&self.residual);
        let mut rr = reduce::sum(&self.residual, |v| v.norm_squared());
        let mut iterations = 0;
        loop {
            if self.check_residual && rr.sqrt() <= RESIDUAL_TOLERANCE * b_norm {
                return iterations;
            }
            if iterations == self.max_iterations || rr == 0.0 {
                return iterations;
            }
            matrix.apply(&self.direction, &mut self.product);
            let p_ap = Self::dot(&self.direction, &self.product);
            if p_ap.is_nan() || p_ap <= 0.0 {
                // Breakdown (A not SPD along p, or p below round-off): keep the iterate.
                return iterations;
            }
            let alpha = rr / p_ap;
            x.par_iter_mut()
                .zip(self.direction.par_iter())
                .for_each(|(x, p)| *x += p * alpha);
            iterations += 1;
            if iterations % RESIDUAL_REFRESH == 0 {
                self.true_residual(matrix, b, x);
            } else {
                self.residual
                    .par_iter_mut()
                    .zip(self.product.par_iter())
                    .for_each(|(r, ap)| *r -= ap * alpha);
            }
            let rr_next = reduce::sum(&self.residual, |v| v.norm_squared());
            let beta = rr_next / rr;
            rr = rr_next;
            self.direction
                .par_iter_mut()
                .zip(self.residual.par_iter())
                .for_each(|(p, r)| *p = r + *p * beta);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::DiagonalSystem;
    use crate::solver::tests::{DenseSystem, rhs};

    /// ‖x − x*‖_A² = (x − x*)ᵀ A (x − x*).
    fn energy_error(sys: &DenseSystem, x: &[Vec3], exact: &[Vec3]) -> f64 {
        let e: Vec<Vec3> = x.iter().zip(exact).map(|(x, e)| x - e).collect();
        let mut ae = vec![Vec3::zeros(); e.len()];
        sys.apply(&e, &mut ae);
        e.iter().zip(&ae).map(|(e, ae)| e.dot(ae)).sum()
    }

    #[test]
    fn converged_cg_matches_dense_solution() {
        for (n, diag) in [(12, 4.0), (40, 2.1), (7, 10.0)] {
            let sys = DenseSystem::ring(n, diag);
            let b = rhs(n);
            let mut x = vec![Vec3::repeat(0.5); n];
            let iterations = Cg::converged().solve(&sys, &b, &mut x);
            assert!(
                (1..MAX_INNER_ITERATIONS).contains(&iterations),
                "{iterations} iterations"
            );
            let exact = sys.exact(&b);
            let scale = exact.iter().map(|e| e.norm()).fold(0.0, f64::max);
            for (x, e) in x.iter().zip(&exact) {
                assert!((x - e).norm() <= 1e-8 * scale, "{x:?} vs {e:?}");
            }
        }
    }

    #[test]
    fn converged_cg_is_exact_on_a_diagonal_system() {
        let sys = DiagonalSystem {
            diagonal: (0..20).map(|i| 1.0 + (i % 5) as f64).collect(),
        };
        let b = rhs(20);
        let mut x = vec![Vec3::zeros(); 20];
        let iterations = Cg::converged().solve(&sys, &b, &mut x);
        // Five distinct eigenvalues: CG terminates in at most five iterations.
        assert!(iterations <= 5, "{iterations}");
        for ((x, b), d) in x.iter().zip(&b).zip(&sys.diagonal) {
            assert!((x - b / *d).norm() <= 1e-10 * b.norm().max(1.0));
        }
    }

    #[test]
    fn single_iteration_reduces_the_energy_error_without_solving() {
        let sys = DenseSystem::ring(12, 4.0);
        let b = rhs(12);
        let exact = sys.exact(&b);
        let x0 = vec![Vec3::repeat(1.0); 12];
        let mut x = x0.clone();
        assert_eq!(Cg::single_iteration().solve(&sys, &b, &mut x), 1);
        let (before, after) = (
            energy_error(&sys, &x0, &exact),
            energy_error(&sys, &x, &exact),
        );
        assert!(after < before, "{after} vs {before}");
        assert!(
            after > 1e-6 * before,
            "one step should not solve: {after} vs {before}"
        );
        // Steepest descent with exact line search: x1 = x0 + (rᵀr / rᵀAr) r.
        let mut r = vec![Vec3::zeros(); 12];
        sys.apply(&x0, &mut r);
        let r: Vec<Vec3> = b.iter().zip(&r).map(|(b, ar)| b - ar).collect();
        let mut ar = vec![Vec3::zeros(); 12];
        sys.apply(&r, &mut ar);
        let alpha = r.iter().map(|r| r.norm_squared()).sum::<f64>()
            / r.iter().zip(&ar).map(|(r, ar)| r.dot(ar)).sum::<f64>();
        for ((x, x0), r) in x.iter().zip(&x0).zip(&r) {
            assert!((x - (x0 + r * alpha)).norm() < 1e-12);
        }
    }

    #[test]
    fn zero_residual_returns_at_once() {
        let sys = DenseSystem::ring(5, 4.0);
        let b = vec![Vec3::zeros(); 5];
        let mut x = vec![Vec3::zeros(); 5];
        assert_eq!(Cg::converged().solve(&sys, &b, &mut x), 0);
        assert_eq!(Cg::single_iteration().solve(&sys, &b, &mut x), 0);
        assert!(x.iter().all(|x| *x == Vec3::zeros()));
    }
}
