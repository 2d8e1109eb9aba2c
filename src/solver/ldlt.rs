//! Sparse direct solve of A = Â ⊗ I₃ by an LDLᵀ factorisation of Â (faer, with an approximate
//! minimum degree fill-reducing ordering).
//!
//! [`GlobalSolver::prepare`] assembles Â through [`SystemMatrix::assemble`] and factorises it
//! (symbolic and numeric) once per time step; every [`GlobalSolver::solve`] then reuses the
//! factors for the three right-hand sides (one per coordinate). A matrix that offers no assembly,
//! or whose factorisation fails numerically, is solved by converged conjugate gradients instead
//! ([`Cg::converged`]), so the solver never panics on a valid system.
//!
//! The assembly, the factors' values, the right-hand sides and the working memory of the
//! numeric factorisation and the solves are kept from step to step and grown fallibly; the
//! symbolic factorisation allocates its own arrays, fallibly. A shortage of memory is an
//! error of `prepare` (the step fails and is undone), never an abort or a silent change of
//! solver.

use super::{Cg, Csr, GlobalSolver, SystemMatrix};
use crate::Vec3;
use crate::reserve::{reserve_total, shortage};
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::sparse::linalg::cholesky::{
    LdltRef, SymbolicCholesky, SymmetricOrdering, factorize_symbolic_cholesky,
};
use faer::sparse::{FaerError, SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, Mat, Par, Side};
use std::collections::TryReserveError;

/// Sparse LDLᵀ: factorise once per time step, one exact solve per outer iteration.
pub struct Ldlt {
    /// The symbolic factorisation of this step's Â, when it has factors (else: CG).
    symbolic: Option<SymbolicCholesky<u32>>,
    /// The values of the factors L and D.
    values: Vec<f64>,
    /// Â as assembled.
    assembled: Csr,
    fallback: Cg,
    /// The three right-hand sides, solved in place.
    rhs: Mat<f64>,
    /// Working memory of the numeric factorisation and of the solves.
    scratch: MemBuffer,
}

impl std::fmt::Debug for Ldlt {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Ldlt")
            .field("factorised", &self.symbolic.is_some())
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
            symbolic: None,
            values: Vec::new(),
            assembled: Csr::default(),
            fallback: Cg::converged(),
            rhs: Mat::zeros(0, 3),
            scratch: MemBuffer::new(StackReq::EMPTY),
        }
    }

    /// Whether the last [`GlobalSolver::prepare`] produced factors (false: CG fallback).
    pub fn is_factorised(&self) -> bool {
        self.symbolic.is_some()
    }

    /// Factorises `matrix` into `self.symbolic` and `self.values`; false when it cannot be
    /// (no assembly, an invalid one, a numerical failure), an error when memory cannot be had.
    fn factorise(&mut self, matrix: &dyn SystemMatrix) -> Result<bool, TryReserveError> {
        if !matrix.assemble(&mut self.assembled)? {
            return Ok(false);
        }
        let Csr {
            offsets,
            columns,
            values,
        } = &self.assembled;
        let Some(n) = offsets.len().checked_sub(1) else {
            return Ok(false);
        };
        if columns.len() != values.len() || offsets[n] as usize != columns.len() {
            return Ok(false);
        }
        // Â is symmetric, so its CSR arrays are also its CSC arrays.
        let pattern = SymbolicSparseColMatRef::new_checked(n, n, offsets, None, columns);
        let a = SparseColMatRef::new(pattern, values);
        let symbolic = match factorize_symbolic_cholesky(
            pattern,
            Side::Lower,
            SymmetricOrdering::Amd,
            Default::default(),
        ) {
            Ok(symbolic) => symbolic,
            Err(FaerError::OutOfMemory) => return Err(shortage()),
            Err(_) => return Ok(false),
        };
        let par = Par::Seq;
        let scratch = StackReq::or(
            symbolic.factorize_numeric_ldlt_scratch::<f64>(par, Default::default()),
            symbolic.solve_in_place_scratch::<f64>(3, par),
        );
        if !MemStack::new(&mut self.scratch).can_hold(scratch) {
            self.scratch = MemBuffer::try_new(scratch).map_err(|_| shortage())?;
        }
        self.values.clear();
        reserve_total(&mut self.values, symbolic.len_val())?;
        self.values.resize(symbolic.len_val(), 0.0);
        reserve_rhs(&mut self.rhs, n)?;
        self.rhs.resize_with(n, 3, |_, _| 0.0);
        let factorised = symbolic.factorize_numeric_ldlt(
            &mut self.values,
            a,
            Side::Lower,
            LdltRegularization::default(),
            par,
            MemStack::new(&mut self.scratch),
            Default::default(),
        );
        if factorised.is_err() || !self.values.iter().all(|v| v.is_finite()) {
            return Ok(false);
        }
        self.symbolic = Some(symbolic);
        Ok(true)
    }
}

/// Makes room in `rhs` for the three right-hand sides of `rows` unknowns.
fn reserve_rhs(rhs: &mut Mat<f64>, rows: usize) -> Result<(), TryReserveError> {
    rhs.try_reserve(rows, 3).map_err(|_| shortage())
}

impl GlobalSolver for Ldlt {
    fn try_reserve(&mut self, unknowns: usize) -> Result<(), TryReserveError> {
        // The assembly of a diagonal Â and its factors; larger ones grow in `prepare`.
        self.assembled.try_reserve(unknowns, unknowns)?;
        reserve_total(&mut self.values, unknowns)?;
        reserve_rhs(&mut self.rhs, unknowns)
    }

    fn prepare(&mut self, matrix: &dyn SystemMatrix) -> Result<(), TryReserveError> {
        self.symbolic = None;
        if !self.factorise(matrix)? {
            // The fallback's buffers, which a factorising solver does not hold.
            self.fallback.try_reserve(matrix.diagonal().len())?;
        }
        Ok(())
    }

    fn solve(&mut self, matrix: &dyn SystemMatrix, b: &[Vec3], x: &mut [Vec3]) -> usize {
        let Some(symbolic) = self.symbolic.as_ref().filter(|f| f.nrows() == x.len()) else {
            return self.fallback.solve(matrix, b, x);
        };
        for (i, b) in b.iter().enumerate() {
            for c in 0..3 {
                self.rhs[(i, c)] = b[c];
            }
        }
        LdltRef::new(symbolic, &self.values).solve_in_place_with_conj(
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
        solver.prepare(&sys).unwrap();
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
            solver.prepare(&sys).unwrap();
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
        solver.prepare(&sys).unwrap();
        assert!(!solver.is_factorised());
        let mut x = vec![Vec3::zeros(); 10];
        assert!(solver.solve(&sys, &b, &mut x) > 1);
        for (x, e) in x.iter().zip(sys.0.exact(&b)) {
            assert!((x - e).norm() <= 1e-8 * e.norm().max(1.0));
        }
    }
}
