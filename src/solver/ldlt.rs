//! Sparse direct solve of A = Â ⊗ I₃ by an LDLᵀ factorisation of Â (faer, with an approximate
//! minimum degree fill-reducing ordering).
//!
//! [`GlobalSolver::prepare`] assembles Â through [`SystemMatrix::assemble`] and factorises it
//! (symbolic and numeric) once per time step; every [`GlobalSolver::solve`] then reuses the
//! factors for the three right-hand sides (one per coordinate). A matrix that offers no assembly,
//! or whose factorisation fails, is solved by converged conjugate gradients instead
//! ([`Cg::converged`]), so the solver never panics on a valid system.

use super::{Cg, GlobalSolver, SystemMatrix};
use crate::Vec3;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::sparse::linalg::cholesky::{
    LdltRef, SymbolicCholesky, SymmetricOrdering, factorize_symbolic_cholesky,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, Mat, Par, Side};

/// The factors of one time step.
struct Factors {
    symbolic: SymbolicCholesky<u32>,
    values: Vec<f64>,
}

/// Sparse LDLᵀ: factorise once per time step, one exact solve per outer iteration.
pub struct Ldlt {
    factors: Option<Factors>,
    fallback: Cg,
    rhs: Mat<f64>,
    scratch: MemBuffer,
}

impl std::fmt::Debug for Ldlt {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Ldlt")
            .field("factorised", &self.factors.is_some())
            .finish_non_exhaustive()
    }
}

impl Default for Ldlt {
    fn default() -> Self {
        Self::new()
    }
}

impl Ldlt {
    /// A solver with no factors yet (call [`GlobalSolver::prepare`] first).
    pub fn new() -> Self {
        Self {
            factors: None,
            fallback: Cg::converged(),
            rhs: Mat::zeros(0, 3),
            scratch: MemBuffer::new(faer::dyn_stack::StackReq::EMPTY),
        }
    }

    /// Whether the last [`GlobalSolver::prepare`] produced factors (false: CG fallback).
    pub fn is_factorised(&self) -> bool {
        self.factors.is_some()
    }

    fn factorise(matrix: &dyn SystemMatrix) -> Option<Factors> {
        let (offsets, cols, values) = matrix.assemble()?;
        let n = offsets.len().checked_sub(1)?;
        if cols.len() != values.len() || offsets[n] as usize != cols.len() {
            return None;
        }
        // Â is symmetric, so its CSR arrays are also its CSC arrays.
        let pattern = SymbolicSparseColMatRef::new_checked(n, n, &offsets, None, &cols);
        let a = SparseColMatRef::new(pattern, &values);
        let symbolic = factorize_symbolic_cholesky(
            pattern,
            Side::Lower,
            SymmetricOrdering::Amd,
            Default::default(),
        )
        .ok()?;
        let mut l_values = vec![0.0; symbolic.len_val()];
        let par = Par::Seq;
        let mut mem = MemBuffer::try_new(
            symbolic.factorize_numeric_ldlt_scratch::<f64>(par, Default::default()),
        )
        .ok()?;
        symbolic
            .factorize_numeric_ldlt(
                &mut l_values,
                a,
                Side::Lower,
                LdltRegularization::default(),
                par,
                MemStack::new(&mut mem),
                Default::default(),
            )
            .ok()?;
        if !l_values.iter().all(|v| v.is_finite()) {
            return None;
        }
        Some(Factors {
            symbolic,
            values: l_values,
        })
    }
}

impl GlobalSolver for Ldlt {
    fn prepare(&mut self, matrix: &dyn SystemMatrix) {
        self.factors = Self::factorise(matrix);
        if let Some(f) = &self.factors {
            let n = f.symbolic.nrows();
            if self.rhs.nrows() != n {
                self.rhs = Mat::zeros(n, 3);
            }
            self.scratch = MemBuffer::new(f.symbolic.solve_in_place_scratch::<f64>(3, Par::Seq));
        }
    }

    fn solve(&mut self, matrix: &dyn SystemMatrix, b: &[Vec3], x: &mut [Vec3]) -> usize {
        let Some(f) = self
            .factors
            .as_ref()
            .filter(|f| f.symbolic.nrows() == x.len())
        else {
            return self.fallback.solve(matrix, b, x);
        };
        for (i, b) in b.iter().enumerate() {
            for c in 0..3 {
                self.rhs[(i, c)] = b[c];
            }
        }
        LdltRef::new(&f.symbolic, &f.values).solve_in_place_with_conj(
            Conj::No,
            self.rhs.as_mut(),
            Par::Seq,
            MemStack::new(&mut self.scratch),
        );
        for (i, x) in x.iter_mut().enumerate() {
            *x = Vec3::new(self.rhs[(i, 0)], self.rhs[(i, 1)], self.rhs[(i, 2)]);
        }
        1
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::DiagonalSystem;
    use crate::solver::tests::{DenseSystem, rhs};

    #[test]
    fn ldlt_is_exact_on_a_diagonal_system() {
        let sys = DiagonalSystem {
            diagonal: (0..30).map(|i| 0.5 + (i * 7 % 11) as f64).collect(),
        };
        let b = rhs(30);
        let mut solver = Ldlt::new();
        solver.prepare(&sys);
        assert!(solver.is_factorised());
        let mut x = vec![Vec3::repeat(3.0); 30];
        assert_eq!(solver.solve(&sys, &b, &mut x), 1);
        for ((x, b), d) in x.iter().zip(&b).zip(&sys.diagonal) {
            let e = b / *d;
            assert!(
                (x - e).norm() <= 1e-12 * e.norm().max(1e-300),
                "{x:?} vs {e:?}"
            );
        }
    }

    #[test]
    fn ldlt_matches_dense_solution_on_a_coupled_system() {
        for (n, diag) in [(12, 4.0), (25, 2.5)] {
            let sys = DenseSystem::ring(n, diag);
            let b = rhs(n);
            let mut solver = Ldlt::new();
            solver.prepare(&sys);
            assert!(solver.is_factorised());
            let exact = sys.exact(&b);
            // Two solves with the same factors (as in successive outer iterations).
            for _ in 0..2 {
                let mut x = vec![Vec3::zeros(); n];
                assert_eq!(solver.solve(&sys, &b, &mut x), 1);
                let scale = exact.iter().map(|e| e.norm()).fold(0.0, f64::max);
                for (x, e) in x.iter().zip(&exact) {
                    assert!((x - e).norm() <= 1e-12 * scale, "{x:?} vs {e:?}");
                }
            }
        }
    }

    /// A system that only offers its action: LDLᵀ falls back to CG.
    struct Unassembled(DenseSystem);

    impl SystemMatrix for Unassembled {
        fn apply(&self, x: &[Vec3], out: &mut [Vec3]) {
            self.0.apply(x, out)
        }
        fn diagonal(&self) -> &[f64] {
            self.0.diagonal()
        }
    }

    #[test]
    fn without_assembly_falls_back_to_cg() {
        let sys = Unassembled(DenseSystem::ring(10, 4.0));
        let b = rhs(10);
        let mut solver = Ldlt::new();
        solver.prepare(&sys);
        assert!(!solver.is_factorised());
        let mut x = vec![Vec3::zeros(); 10];
        assert!(solver.solve(&sys, &b, &mut x) > 1);
        for (x, e) in x.iter().zip(sys.0.exact(&b)) {
            assert!((x - e).norm() <= 1e-8 * e.norm().max(1.0));
        }
    }
}
