//! The coarse correction's linear system (docs/method.md §3.8): a finite-volume Poisson
//! equation for the displacement potential φ on the fluid cells of a lattice, solved by
//! conjugate gradients with a Jacobi preconditioner. Sums are [`reduce::sum_over`]'s, so the
//! solution is the same for any thread count.

use crate::reduce;
use crate::reserve::reserve_total;
use rayon::prelude::*;
use std::collections::TryReserveError;

/// What a lattice cell holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Cell {
    /// Neither fluid nor solid: φ = 0 at the fluid's surface next to it.
    Air,
    /// Fluid particles: one unknown.
    Fluid,
    /// Outside a container whose walls are fields: no flux through the faces it shares
    /// with fluid cells. (Walls of particles close the faces in front of the fluid instead,
    /// [`Layout::closed`].)
    Solid,
}

/// The relative residual ‖r‖ ≤ tolerance · ‖b‖ at which the solve stops; the fine iteration
/// resolves far smaller errors than the correction leaves at this accuracy.
const TOLERANCE: f64 = 1e-4;

/// The most conjugate-gradient iterations of one solve.
const MAX_ITERATIONS: usize = 500;

/// A small multiple of φ_c added to every cell's equation, so that fluid enclosed by solids
/// without any free surface still has a unique, bounded potential (m⁻²·m², i.e. per cell).
const REGULARISATION: f64 = 1e-6;

/// The system Σ_faces a_f (φ_c − φ_f) = b_c over the fluid cells, a_f = 1 towards fluid,
/// 1/θ_c towards air, 0 towards solids; and its solver's vectors.
#[derive(Clone, Debug, Default)]
pub(super) struct Poisson {
    /// The preconditioner: every fluid cell's diagonal, 0 elsewhere.
    diagonal: Vec<f64>,
    residual: Vec<f64>,
    direction: Vec<f64>,
    product: Vec<f64>,
    preconditioned: Vec<f64>,
}

/// The lattice's cells and the distances to the free surface the system is built on.
pub(super) struct Layout<'a> {
    pub cells: &'a [Cell],
    /// For each fluid cell, the distance from its centre to the free surface where it
    /// borders air, in cell edges.
    pub theta: &'a [f64],
    /// For each fluid cell, the faces a solid closes (bit 2a for the face towards −a, 2a + 1
    /// towards +a), whatever the cell beyond them holds: boundary particles beyond its fluid,
    /// in the cell or in the one across the face, within the fluid's extent along the face.
    pub closed: &'a [u8],
    /// Index steps to the neighbour along x, y and z (the lattice has a margin of one
    /// non-fluid cell on every side, so a fluid cell's six neighbours exist).
    pub strides: [usize; 3],
}

impl Layout<'_> {
    /// The neighbour of fluid cell `c` along axis `a` (towards +a if `up`) and what the face
    /// between them opens onto: a closed face counts as solid.
    pub(super) fn neighbour(&self, c: usize, a: usize, up: bool) -> (usize, Cell) {
        let nb = if up {
            c + self.strides[a]
        } else {
            c - self.strides[a]
        };
        if self.closed[c] & (1 << (2 * a + usize::from(up))) != 0 {
            (nb, Cell::Solid)
        } else {
            (nb, self.cells[nb])
        }
    }

    /// The six faces of fluid cell `c`.
    fn faces(&self, c: usize) -> impl Iterator<Item = (usize, Cell)> + '_ {
        (0..6).map(move |f| self.neighbour(c, f / 2, f % 2 == 1))
    }

    /// The system's diagonal at fluid cell `c`.
    fn diagonal(&self, c: usize) -> f64 {
        let mut sum = REGULARISATION;
        for (_, cell) in self.faces(c) {
            match cell {
                Cell::Fluid => sum += 1.0,
                Cell::Air => sum += 1.0 / self.theta[c],
                Cell::Solid => {}
            }
        }
        sum
    }

    /// (A v)_c for fluid cell `c`.
    fn product(&self, v: &[f64], c: usize) -> f64 {
        let mut sum = REGULARISATION * v[c];
        for (nb, cell) in self.faces(c) {
            match cell {
                Cell::Fluid => sum += v[c] - v[nb],
                Cell::Air => sum += v[c] / self.theta[c],
                Cell::Solid => {}
            }
        }
        sum
    }
}

impl Poisson {
    /// Solves A φ = `rhs` over the fluid cells of `layout`, from the start in `phi` (0
    /// outside fluid cells), and returns the iterations taken. Errors, leaving `phi` as it
    /// was, when memory for the solver's vectors cannot be had.
    pub(super) fn solve(
        &mut self,
        layout: &Layout,
        rhs: &[f64],
        phi: &mut [f64],
    ) -> Result<usize, TryReserveError> {
        let n = layout.cells.len();
        for v in [
            &mut self.diagonal,
            &mut self.residual,
            &mut self.direction,
            &mut self.product,
            &mut self.preconditioned,
        ] {
            reserve_total(v, n)?;
            v.clear();
            v.resize(n, 0.0);
        }
        let fluid = |c: usize| layout.cells[c] == Cell::Fluid;
        self.diagonal
            .par_iter_mut()
            .enumerate()
            .for_each(|(c, d)| *d = if fluid(c) { layout.diagonal(c) } else { 0.0 });
        let norm_rhs = reduce::sum_over(n, |c| rhs[c] * rhs[c]).sqrt();
        if norm_rhs == 0.0 {
            phi.fill(0.0);
            return Ok(0);
        }
        let diagonal = &self.diagonal;
        self.residual.par_iter_mut().enumerate().for_each(|(c, r)| {
            *r = if fluid(c) {
                rhs[c] - layout.product(phi, c)
            } else {
                0.0
            }
        });
        let precondition = |r: &[f64], z: &mut [f64]| {
            z.par_iter_mut()
                .enumerate()
                .for_each(|(c, z)| *z = if fluid(c) { r[c] / diagonal[c] } else { 0.0 });
        };
        precondition(&self.residual, &mut self.preconditioned);
        self.direction.copy_from_slice(&self.preconditioned);
        let (residual, preconditioned) = (&self.residual, &self.preconditioned);
        let mut rz = reduce::sum_over(n, |c| residual[c] * preconditioned[c]);
        let mut iterations = 0;
        while iterations < MAX_ITERATIONS {
            let residual_norm = reduce::sum_over(n, |c| self.residual[c].powi(2)).sqrt();
            if residual_norm <= TOLERANCE * norm_rhs {
                break;
            }
            let direction = &self.direction;
            self.product.par_iter_mut().enumerate().for_each(|(c, q)| {
                *q = if fluid(c) {
                    layout.product(direction, c)
                } else {
                    0.0
                }
            });
            let product = &self.product;
            let curvature = reduce::sum_over(n, |c| direction[c] * product[c]);
            if curvature <= 0.0 || !curvature.is_finite() {
                break;
            }
            let alpha = rz / curvature;
            phi.par_iter_mut()
                .zip(self.residual.par_iter_mut())
                .enumerate()
                .for_each(|(c, (phi, r))| {
                    *phi += alpha * direction[c];
                    *r -= alpha * product[c];
                });
            precondition(&self.residual, &mut self.preconditioned);
            let (residual, preconditioned) = (&self.residual, &self.preconditioned);
            let next = reduce::sum_over(n, |c| residual[c] * preconditioned[c]);
            let beta = next / rz;
            rz = next;
            self.direction
                .par_iter_mut()
                .zip(self.preconditioned.par_iter())
                .for_each(|(p, z)| *p = z + beta * *p);
            iterations += 1;
        }
        Ok(iterations)
    }
}
