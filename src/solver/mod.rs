//! The global step of the local/global iteration (docs/method.md §3): the system matrix and the
//! linear solvers behind one trait, plus Chebyshev's extrapolation over the outer iterations.

mod cg;
mod chebyshev;
mod jacobi;
mod ldlt;
mod sweep;

pub use cg::Cg;
pub use chebyshev::{Chebyshev, OnlineRho};
pub use jacobi::Jacobi;
pub use ldlt::Ldlt;
pub use sweep::Sweep;

use crate::Vec3;
use crate::params::SolverKind;
use crate::reserve::reserve_total;
use rayon::prelude::*;
use std::collections::TryReserveError;

/// The matrix A of the global step, A = Â ⊗ I₃, seen by the solvers only through its action
/// and its diagonal, so that formulations other than the diagonal one can be added.
pub trait SystemMatrix: Sync {
    /// out = A·x.
    fn apply(&self, x: &[Vec3], out: &mut [Vec3]);
    /// The diagonal of Â (kg).
    fn diagonal(&self) -> &[f64];
    /// Assembles Â into `out` for the direct solvers, reusing its storage, and returns true;
    /// false (the default, `out` left as it was) when the matrix is only available through
    /// its action. Errors when memory for the arrays cannot be had.
    fn assemble(&self, _out: &mut Csr) -> Result<bool, TryReserveError> {
        Ok(false)
    }
}

/// A square matrix in compressed sparse rows, its storage kept from one assembly to the
/// next.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Csr {
    /// Where each row's entries start in `columns` and `values` (one more than rows).
    pub offsets: Vec<u32>,
    /// The column of each entry, ascending within a row.
    pub columns: Vec<u32>,
    /// The value of each entry.
    pub values: Vec<f64>,
}

impl Csr {
    /// Makes room for `rows` rows with `entries` entries in all; errors when the memory
    /// cannot be had.
    pub fn try_reserve(&mut self, rows: usize, entries: usize) -> Result<(), TryReserveError> {
        reserve_total(&mut self.offsets, rows + 1)?;
        reserve_total(&mut self.columns, entries)?;
        reserve_total(&mut self.values, entries)
    }

    /// Empties the matrix, keeping its storage, and makes room as [`Csr::try_reserve`].
    pub fn try_reset(&mut self, rows: usize, entries: usize) -> Result<(), TryReserveError> {
        self.offsets.clear();
        self.columns.clear();
        self.values.clear();
        self.try_reserve(rows, entries)
    }
}

/// Formulation F1 (docs/method.md §3.1): Â = diag(m + Δt²k(n_j + 1)), in kg.
#[derive(Clone, Debug, Default)]
pub struct DiagonalSystem {
    /// Â_jj (kg).
    pub diagonal: Vec<f64>,
}

impl SystemMatrix for DiagonalSystem {
    fn apply(&self, x: &[Vec3], out: &mut [Vec3]) {
        out.par_iter_mut()
            .zip(x.par_iter().zip(self.diagonal.par_iter()))
            .for_each(|(o, (x, d))| *o = x * *d);
    }

    fn diagonal(&self) -> &[f64] {
        &self.diagonal
    }

    fn assemble(&self, out: &mut Csr) -> Result<bool, TryReserveError> {
        let Ok(n) = u32::try_from(self.diagonal.len()) else {
            return Ok(false);
        };
        out.try_reset(self.diagonal.len(), self.diagonal.len())?;
        out.offsets.extend(0..=n);
        out.columns.extend(0..n);
        out.values.extend_from_slice(&self.diagonal);
        Ok(true)
    }
}

/// A linear solver for A·x = b (three right-hand sides at once).
pub trait GlobalSolver: Send + Sync {
    /// Reserves the solver's buffers for systems of `unknowns` particles, so that the steps
    /// of a run allocate none of them; errors when the memory cannot be had. The default
    /// reserves nothing.
    fn try_reserve(&mut self, _unknowns: usize) -> Result<(), TryReserveError> {
        Ok(())
    }
    /// Called once per time step, after A changed and before the first solve; errors when
    /// memory the solver needs for this matrix (a factorisation) cannot be had, leaving the
    /// solver to be prepared again. The default does nothing.
    fn prepare(&mut self, _matrix: &dyn SystemMatrix) -> Result<(), TryReserveError> {
        Ok(())
    }
    /// Solves A·x = b with `x` holding the warm start; returns the inner iterations used.
    fn solve(&mut self, matrix: &dyn SystemMatrix, b: &[Vec3], x: &mut [Vec3]) -> usize;
    /// True when every solve is exactly one Jacobi sweep x ← x + D⁻¹(b − Ax), which on a
    /// [`DiagonalSystem`] is x_j + (b_j − Â_jj·x_j)/Â_jj: the time step may then compute it
    /// in the same pass as the right-hand side (bitwise the same result).
    fn single_diagonal_sweep(&self) -> bool {
        false
    }
}

/// Relative residual ‖b − Ax‖ ≤ this·‖b‖ ends the converging solvers (docs/method.md §3.4).
pub const RESIDUAL_TOLERANCE: f64 = 1e-10;
/// The converging solvers stop after this many inner iterations.
pub const MAX_INNER_ITERATIONS: usize = 100;

/// The linear solver behind a [`SolverKind`].
pub fn linear_solver(kind: SolverKind) -> Box<dyn GlobalSolver> {
    match kind {
        SolverKind::Chebyshev | SolverKind::Jacobi1 => Box::new(Jacobi::single_sweep()),
        SolverKind::Jacobi => Box::new(Jacobi::converged()),
        SolverKind::Cg => Box::new(Cg::converged()),
        SolverKind::Cg1 => Box::new(Cg::single_iteration()),
        SolverKind::Ldlt => Box::new(Ldlt::new()),
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A small SPD test matrix Â (dense, symmetric) with its exact solve by Gaussian elimination.
    pub struct DenseSystem {
        pub n: usize,
        pub a: Vec<f64>,
        pub diag: Vec<f64>,
    }

    impl DenseSystem {
        /// Diagonally dominant SPD matrix: 4 on the diagonal, −1 to ring neighbours.
        pub fn ring(n: usize, diag: f64) -> Self {
            let mut a = vec![0.0; n * n];
            for i in 0..n {
                a[i * n + i] = diag;
                a[i * n + (i + 1) % n] -= 1.0;
                a[i * n + (i + n - 1) % n] -= 1.0;
            }
            Self {
                n,
                diag: (0..n).map(|i| a[i * n + i]).collect(),
                a,
            }
        }

        pub fn exact(&self, b: &[Vec3]) -> Vec<Vec3> {
            let n = self.n;
            let mut m = self.a.clone();
            let mut x = b.to_vec();
            for c in 0..n {
                for r in c + 1..n {
                    let f = m[r * n + c] / m[c * n + c];
                    for k in c..n {
                        m[r * n + k] -= f * m[c * n + k];
                    }
                    let xc = x[c];
                    x[r] -= xc * f;
                }
            }
            for c in (0..n).rev() {
                let mut v = x[c];
                for k in c + 1..n {
                    v -= x[k] * m[c * n + k];
                }
                x[c] = v / m[c * n + c];
            }
            x
        }
    }

    impl SystemMatrix for DenseSystem {
        fn apply(&self, x: &[Vec3], out: &mut [Vec3]) {
            for (i, o) in out.iter_mut().enumerate() {
                *o = (0..self.n).map(|j| x[j] * self.a[i * self.n + j]).sum();
            }
        }
        fn diagonal(&self) -> &[f64] {
            &self.diag
        }
        fn assemble(&self, out: &mut Csr) -> Result<bool, TryReserveError> {
            out.try_reset(self.n, self.n * self.n)?;
            out.offsets.push(0);
            for i in 0..self.n {
                for j in 0..self.n {
                    let a = self.a[i * self.n + j];
                    if a != 0.0 {
                        out.columns.push(j as u32);
                        out.values.push(a);
                    }
                }
                out.offsets.push(out.columns.len() as u32);
            }
            Ok(true)
        }
    }

    pub fn rhs(n: usize) -> Vec<Vec3> {
        (0..n)
            .map(|i| Vec3::new(i as f64, (i * i % 7) as f64 - 3.0, 1.0 / (i + 1) as f64))
            .collect()
    }

    #[test]
    fn diagonal_system_applies_its_diagonal() {
        let sys = DiagonalSystem {
            diagonal: vec![2.0, 3.0],
        };
        let mut out = vec![Vec3::zeros(); 2];
        sys.apply(&[Vec3::repeat(1.0), Vec3::new(1.0, 2.0, 3.0)], &mut out);
        assert_eq!(out, vec![Vec3::repeat(2.0), Vec3::new(3.0, 6.0, 9.0)]);
        let mut csr = Csr::default();
        assert_eq!(sys.assemble(&mut csr), Ok(true));
        let expected = Csr {
            offsets: vec![0, 1, 2],
            columns: vec![0, 1],
            values: vec![2.0, 3.0],
        };
        assert_eq!(csr, expected);
    }
}
