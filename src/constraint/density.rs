//! Densities ρ_i at the iterate and at projected positions, the stencil members they fill, the
//! XSPH filter over the same members, and the weights and memberships of the projection
//! (docs/method.md §2.3, §2.5, §3.1).

use super::stencil::{Members, SCRATCH, Scratch, members_sum, padded};
use super::{DensityConstraint, Neighborhood};
use crate::Vec3;
use crate::neighbors::NeighborLists;
use crate::params::ProjectionWeight;
use rayon::prelude::*;

impl DensityConstraint {
    /// ρ_i with particle i at `xi` and its s-th fluid neighbour at `neighbor(s)`.
    #[inline]
    pub(super) fn density_at(
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
                nb.boundary_psi[b] * k.w((xi - nb.boundary_positions.at(b)).norm())
            })
            .sum();
        self.mass * (k.w_zero() + fluid) + boundary + self.walls_at(xi, nb.walls).density
    }

    /// Fills `m` with the fluid members of stencil i, particle i at `xi` and its neighbours
    /// at `x`: their offsets x_i − x_j and distances (m), and their kernel values W (1/m³)
    /// in `m.values`.
    #[inline(always)]
    fn fill_members(&self, i: usize, xi: Vec3, x: &[Vec3], nb: &Neighborhood, m: &mut Members) {
        let k = &self.kernel;
        let neighbors = nb.fluid.of(i);
        m.resize(neighbors.len());
        for (((&j, rx), ry), rz) in neighbors
            .iter()
            .zip(&mut m.rx)
            .zip(&mut m.ry)
            .zip(&mut m.rz)
        {
            let xj = &x[j as usize];
            (*rx, *ry, *rz) = (xi.x - xj.x, xi.y - xj.y, xi.z - xj.z);
        }
        for ((((len, w), rx), ry), rz) in m.len[..padded(m.n)]
            .iter_mut()
            .zip(&mut m.values)
            .zip(&m.rx)
            .zip(&m.ry)
            .zip(&m.rz)
        {
            *len = (rx * rx + ry * ry + rz * rz).sqrt();
            *w = k.w(*len);
        }
    }

    /// [`Self::density_at`] at the iterate (`xi` = x_i, neighbours at `x`), keeping every
    /// member's offset and distance in `scratch` for [`Self::first_gradients`]. The same
    /// density up to the order of the summation.
    #[inline(always)]
    pub(super) fn first_density(
        &self,
        i: usize,
        xi: Vec3,
        x: &[Vec3],
        nb: &Neighborhood,
        scratch: &mut Scratch,
    ) -> f64 {
        let k = &self.kernel;
        let m = &mut scratch.members;
        self.fill_members(i, xi, x, nb, m);
        let fluid = members_sum(&m.values, m.n);
        let walls = nb.boundary.of(i);
        let bm = &mut scratch.boundary;
        bm.resize(walls.len());
        // One index check per member: the components and masses are slices of one length.
        let (bx, by, bz) = nb.boundary_positions.components();
        let bpsi = &nb.boundary_psi[..bx.len()];
        for ((((&b, rx), ry), rz), psi) in walls
            .iter()
            .zip(&mut bm.rx)
            .zip(&mut bm.ry)
            .zip(&mut bm.rz)
            .zip(&mut bm.psi)
        {
            let b = b as usize;
            (*rx, *ry, *rz) = (xi.x - bx[b], xi.y - by[b], xi.z - bz[b]);
            *psi = bpsi[b];
        }
        for (((((len, w), rx), ry), rz), psi) in bm.len[..padded(bm.n)]
            .iter_mut()
            .zip(&mut bm.values)
            .zip(&bm.rx)
            .zip(&bm.ry)
            .zip(&bm.rz)
            .zip(&bm.psi)
        {
            *len = (rx * rx + ry * ry + rz * rz).sqrt();
            *w = psi * k.w(*len);
        }
        scratch.wall_at = xi;
        scratch.wall = self.walls_at(xi, nb.walls);
        self.mass * (k.w_zero() + fluid) + members_sum(&bm.values, bm.n) + scratch.wall.density
    }

    /// SPH density ρ_i (kg/m³) of every fluid particle at `positions`, written into `out`.
    pub fn densities(&self, positions: &[Vec3], nb: &Neighborhood, out: &mut Vec<f64>) {
        out.resize(positions.len(), 0.0);
        out.par_iter_mut().enumerate().for_each(|(i, rho)| {
            *rho = SCRATCH.with_borrow_mut(|scratch| self.density_of(i, positions, nb, scratch));
        });
    }

    crate::simd::avx2_dispatch! {
        /// ρ_i (kg/m³) with the particles at `x`, by [`Self::first_density`] (four lanes
        /// wide in the AVX2 build, bitwise alike).
        fn density_of / density_of_avx2(
            &self,
            i: usize,
            x: &[Vec3],
            nb: &Neighborhood,
            scratch: &mut Scratch,
        ) -> f64 where !self.portable => density_of_portable
    }

    /// The body of [`Self::density_of`].
    #[inline(always)]
    fn density_of_portable(
        &self,
        i: usize,
        x: &[Vec3],
        nb: &Neighborhood,
        scratch: &mut Scratch,
    ) -> f64 {
        self.first_density(i, x[i], x, nb, scratch)
    }

    /// The XSPH-filtered velocity of fluid particle i (m/s), docs/method.md §1.3:
    /// v_i + c Σ_j (m/ρ_j)(v_j − v_i) W_ij, with positions `x` (m), velocities `v` (m/s)
    /// and volumes m/ρ_j (m³) of the fluid (one division per particle, not per pair).
    pub fn xsph_velocity(
        &self,
        c: f64,
        i: usize,
        state: (&[Vec3], &[Vec3], &[f64]),
        nb: &Neighborhood,
    ) -> Vec3 {
        SCRATCH.with_borrow_mut(|scratch| self.xsph_into(c, i, state, nb, &mut scratch.members))
    }

    crate::simd::avx2_dispatch! {
        /// [`Self::xsph_velocity`] with the thread's buffers; the AVX2 build evaluates the
        /// kernel four lanes wide, bitwise alike (tested).
        fn xsph_into / xsph_into_avx2(
            &self,
            c: f64,
            i: usize,
            state: (&[Vec3], &[Vec3], &[f64]),
            nb: &Neighborhood,
            members: &mut Members,
        ) -> Vec3 where !self.portable => xsph_portable
    }

    /// The body of [`Self::xsph_velocity`].
    #[inline(always)]
    fn xsph_portable(
        &self,
        c: f64,
        i: usize,
        (x, v, volumes): (&[Vec3], &[Vec3], &[f64]),
        nb: &Neighborhood,
        members: &mut Members,
    ) -> Vec3 {
        self.fill_members(i, x[i], x, nb, members);
        let vi = v[i];
        let sum: Vec3 = nb
            .fluid
            .of(i)
            .iter()
            .zip(&members.values)
            .map(|(&j, w)| {
                let j = j as usize;
                (v[j] - vi) * (volumes[j] * w)
            })
            .sum();
        vi + sum * c
    }

    /// The weight w_j of every fluid particle j in a projection (docs/method.md §2.5), given
    /// the fluid's neighbour lists, written into `out` (for [`Neighborhood::weights`]).
    pub fn weights(&self, lists: &NeighborLists, out: &mut Vec<f64>) {
        out.clear();
        out.par_extend((0..lists.len()).into_par_iter().map(|j| match self.weight {
            ProjectionWeight::NeighborCount => (lists.count(j) + 1) as f64,
            ProjectionWeight::Unit => 1.0,
            ProjectionWeight::Uniform => self.rest_stencil_size,
        }));
    }

    /// The weight w_j of fluid particle j in a projection (docs/method.md §2.5).
    #[inline]
    pub(super) fn weight_of(&self, nb: &Neighborhood, j: usize) -> f64 {
        nb.weights[j]
    }

    /// How many stencils the global step counts particle j as a member of: n_j + 1, or c
    /// for [`ProjectionWeight::Uniform`] (docs/method.md §3.1; docs/solvers.md, "Projection weighting").
    #[inline]
    pub fn membership(&self, nb: &NeighborLists, j: usize) -> f64 {
        match self.weight {
            ProjectionWeight::Uniform => self.rest_stencil_size,
            _ => ((nb.count(j) + 1) as f64).max(self.membership_floor),
        }
    }

    /// The factor M_j/(n_j + 1) ≥ 1 by which the global step scales the corrections gathered
    /// for particle j (dimensionless): the membership floor stiffens a sparse particle's
    /// pull towards its projections without moving their target (docs/method.md §3.1).
    #[inline]
    pub fn correction_scale(&self, nb: &NeighborLists, j: usize) -> f64 {
        match self.weight {
            ProjectionWeight::Uniform => 1.0,
            _ => self.membership(nb, j) / (nb.count(j) + 1) as f64,
        }
    }
}

/// Divides every fluid particle's projection weight w_j in `weights` by its mass ratio
/// m_j/m, m_j = `mass_of(j)` (kg) being its mass and m = `mass` (kg) the world's particle
/// mass: each projection then moves its members in inverse proportion to their masses, as a
/// projection in the metric of the masses does, so that a heavier liquid yields less to the
/// same constraint than a lighter one within every outer iteration (docs/method.md §14).
pub(crate) fn weigh_by_inertia(
    weights: &mut [f64],
    mass: f64,
    mass_of: impl Fn(usize) -> f64 + Sync,
) {
    weights
        .par_iter_mut()
        .enumerate()
        .for_each(|(j, w)| *w *= mass / mass_of(j));
}
