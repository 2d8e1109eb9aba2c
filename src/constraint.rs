//! The SPH density constraint C_i = max(ρ_i/ρ0 − 1, 0) and its local projection
//! (ALGORITHM.md §2.3–2.5).

use crate::Vec3;
use crate::kernel::CubicKernel;
use crate::neighbors::{NeighborLists, par_segments_mut};
use crate::params::ProjectionWeight;
use rayon::prelude::*;

/// The local projection stops once C_i ≤ this value ([SEED], [SPH]).
const CONSTRAINT_GOAL: f64 = 1e-14;
/// At most this many Newton-like steps per projection.
const MAX_PROJECTION_STEPS: usize = 100;
/// Regularisation ε of λ = −C/(|∇C|² + ε), in m⁻².
const REGULARIZATION: f64 = 1e-6;

/// Everything a constraint reads during one time step: the fluid's neighbour lists and the
/// static boundary particles with their Akinci masses ψ_b = ρ0·V_b (kg).
#[derive(Clone, Copy)]
pub struct Neighborhood<'a> {
    /// Fluid neighbours of each fluid particle (j ≠ i).
    pub fluid: &'a NeighborLists,
    /// Boundary neighbours of each fluid particle.
    pub boundary: &'a NeighborLists,
    /// Boundary particle positions (m).
    pub boundary_positions: &'a [Vec3],
    /// Boundary particle masses ψ_b (kg).
    pub boundary_psi: &'a [f64],
    /// Start of each particle's stencil segment, `fluid.offsets[i] + i`; one extra entry.
    pub stencil_offsets: &'a [u32],
}

impl Neighborhood<'_> {
    /// Start of particle i's stencil segment (centre, then its fluid neighbours) in a buffer
    /// laid out like the neighbour lists with one extra slot per particle.
    #[inline]
    pub fn stencil_start(&self, i: usize) -> usize {
        self.stencil_offsets[i] as usize
    }

    /// Total length of a stencil buffer: one slot per particle and one per fluid pair.
    pub fn stencil_len(&self) -> usize {
        self.fluid.indices.len() + self.fluid.len()
    }

    /// Fills `out` with the stencil offsets `fluid.offsets[i] + i` of `lists`.
    pub fn stencil_offsets_of(lists: &NeighborLists, out: &mut Vec<u32>) {
        out.clear();
        out.extend(lists.offsets.iter().enumerate().map(|(i, &o)| o + i as u32));
    }
}

/// The fluid density constraint with the constants of the local projection.
#[derive(Clone, Copy, Debug)]
pub struct DensityConstraint {
    /// The SPH kernel.
    pub kernel: CubicKernel,
    /// Fluid particle mass m (kg).
    pub mass: f64,
    /// Rest density ρ0 (kg/m³).
    pub rest_density: f64,
    /// Weighting of the projection.
    pub weight: ProjectionWeight,
}

impl DensityConstraint {
    /// ρ_i with particle i at `xi` and its s-th fluid neighbour at `neighbor(s)`.
    #[inline]
    fn density_at(
        &self,
        i: usize,
        xi: Vec3,
        neighbor: impl Fn(usize) -> Vec3,
        nb: &Neighborhood,
    ) -> f64 {
        let k = &self.kernel;
        let fluid: f64 = (0..nb.fluid.count(i))
            .map(|s| k.w((xi - neighbor(s)).norm()))
            .sum();
        let boundary: f64 = nb
            .boundary
            .of(i)
            .iter()
            .map(|&b| {
                let b = b as usize;
                nb.boundary_psi[b] * k.w((xi - nb.boundary_positions[b]).norm())
            })
            .sum();
        self.mass * (k.w_zero() + fluid) + boundary
    }

    /// SPH density ρ_i (kg/m³) of every fluid particle at `positions`, written into `out`.
    pub fn densities(&self, positions: &[Vec3], nb: &Neighborhood, out: &mut Vec<f64>) {
        out.resize(positions.len(), 0.0);
        out.par_iter_mut().enumerate().for_each(|(i, rho)| {
            let members = nb.fluid.of(i);
            *rho = self.density_at(i, positions[i], |s| positions[members[s] as usize], nb);
        });
    }

    /// The weight w_j of fluid particle j in a projection (ALGORITHM.md §2.5).
    #[inline]
    fn weight_of(&self, nb: &Neighborhood, j: usize) -> f64 {
        match self.weight {
            ProjectionWeight::NeighborCount => (nb.fluid.count(j) + 1) as f64,
            ProjectionWeight::Unit => 1.0,
        }
    }

    /// The local step: projects every constraint i at the iterate `x`, writing the stencil
    /// corrections P_{i,j} − x_j (m) into `corrections` (layout of [`Neighborhood::stencil_start`]).
    pub fn project(&self, x: &[Vec3], nb: &Neighborhood, corrections: &mut Vec<Vec3>) {
        corrections.resize(nb.stencil_len(), Vec3::zeros());
        par_segments_mut(nb.stencil_offsets, corrections, |i, dp| {
            self.project_one(i, x, nb, dp)
        });
    }

    /// Projection of constraint i (ALGORITHM.md §2.5): Newton-like steps on a private copy
    /// p = x + dp of the stencil until C_i(p) ≤ 1e-14. `dp[0]` belongs to i, `dp[s + 1]` to
    /// its s-th fluid neighbour.
    fn project_one(&self, i: usize, x: &[Vec3], nb: &Neighborhood, dp: &mut [Vec3]) {
        dp.fill(Vec3::zeros());
        let members = nb.fluid.of(i);
        let kernel = &self.kernel;
        let scale = self.mass / self.rest_density;
        for step in 0..MAX_PROJECTION_STEPS {
            let pi = x[i] + dp[0];
            let rho = self.density_at(i, pi, |s| x[members[s] as usize] + dp[s + 1], nb);
            let c = (rho / self.rest_density - 1.0).max(0.0);
            if c <= CONSTRAINT_GOAL {
                return;
            }
            // ∇_{p_j} C_i = −(m/ρ0)∇W(p_i − p_j); ∇_{p_i} C_i collects the fluid and boundary terms.
            let mut grad_i: Vec3 = nb
                .boundary
                .of(i)
                .iter()
                .map(|&b| {
                    let b = b as usize;
                    kernel.grad_w(&(pi - nb.boundary_positions[b])) * nb.boundary_psi[b]
                })
                .sum::<Vec3>()
                / self.rest_density;
            let mut denominator = 0.0;
            for s in 0..members.len() {
                let g = kernel.grad_w(&(pi - (x[members[s] as usize] + dp[s + 1]))) * scale;
                grad_i += g;
                denominator += g.norm_squared();
                if step == 0 {
                    // dp is zero on the first step: keep −g there until λ is known.
                    dp[s + 1] = -g;
                }
            }
            denominator += grad_i.norm_squared();
            if denominator == 0.0 {
                return;
            }
            let lambda = -c / (denominator + REGULARIZATION);
            for s in 0..members.len() {
                let j = members[s] as usize;
                let g = if step == 0 {
                    dp[s + 1]
                } else {
                    -kernel.grad_w(&(pi - (x[j] + dp[s + 1]))) * scale
                };
                let delta = g * (lambda * self.weight_of(nb, j));
                dp[s + 1] = if step == 0 { delta } else { dp[s + 1] + delta };
            }
            dp[0] += grad_i * (lambda * self.weight_of(nb, i));
        }
    }
}
