//! The gather: for every particle, the sum of the corrections all projections of the local
//! step made to it, from the λ_i of single-step projections and the kept segments of the
//! others ([`Corrections`]), gathered from the particle's side (docs/method.md §2.5, §6).

use super::stencil::{ordered_dot, pad_each, padded_room};
use super::{DensityConstraint, Neighborhood, Projection};
use crate::Vec3;
use crate::reserve::reserve_total;
use std::collections::TryReserveError;

/// The stencil corrections P_{i,j} − x_j (m) of the multi-step projections of one local step,
/// and of those only: constraint i's segment holds its own correction and then one per fluid
/// neighbour in stencil order. Single-step projections, the usual case, keep λ_i alone, so
/// this stays small (it used to be one entry per stencil member of every particle).
#[derive(Clone, Debug, Default)]
pub struct Corrections {
    /// The constraints with a segment, in index order.
    pub(super) owners: Vec<u32>,
    /// Segment k spans `data[offsets[k]..offsets[k + 1]]`.
    pub(super) offsets: Vec<u32>,
    pub(super) data: Vec<Vec3>,
    /// λ_i of every projection, the sum over its Newton steps (one, usually), 0 for an
    /// inactive constraint, in a compact array (8 bytes per particle, against 40 for a
    /// [`Projection`]): the gather reads it for every neighbour that `moved` marks.
    pub(super) lambdas: Vec<f64>,
    /// 1 where a single-step projection moved its stencil (λ not 0): one byte per particle,
    /// so that the gather's scan of a particle's neighbours reads an array that stays in the
    /// nearest cache.
    pub(super) moved: Vec<u8>,
    /// Whether particle j is a member of a stencil whose projection kept a segment: only
    /// then does its gather look for segments.
    pub(super) near_kept: Vec<bool>,
    /// Tests refuse segments of more entries than this, as a shortage of memory would.
    #[cfg(test)]
    pub(crate) segment_limit: Option<usize>,
}

impl Corrections {
    /// Reserves the per-particle arrays for `particles` fluid particles (the segments of kept
    /// corrections, few and of unknown size, are not reserved).
    pub(crate) fn try_reserve(
        &mut self,
        particles: usize,
    ) -> Result<(), std::collections::TryReserveError> {
        use crate::reserve::reserve_total;
        reserve_total(&mut self.lambdas, particles)?;
        reserve_total(&mut self.moved, particles)?;
        reserve_total(&mut self.near_kept, particles)
    }

    /// How many projections of the last local step kept their corrections.
    pub fn kept(&self) -> usize {
        self.owners.len()
    }

    /// λ of projection i in the last local step, summed over its Newton steps (m²; 0 for an
    /// inactive constraint).
    pub fn lambda(&self, i: usize) -> f64 {
        self.lambdas[i]
    }

    /// P_{i,j} − x_j (m) from the segment that projection i kept (out of the gather's hot
    /// loop: few projections keep one).
    #[inline(never)]
    fn kept_correction(
        &self,
        i: usize,
        j: usize,
        nb: &Neighborhood,
        projections: &[Projection],
    ) -> Vec3 {
        // j's place in i's ascending list (the lists are symmetric), after i's own correction
        // at the segment's start.
        let place = nb.fluid.of(i).binary_search(&(j as u32));
        let member = place.expect("neighbour lists are symmetric") as u32 + 1;
        self.data[(projections[i].segment + member) as usize]
    }
}

/// Per-thread buffers of one gather ([`DensityConstraint::gathered_corrections`]): the
/// neighbours whose projection moved the particle, their λ (m²), offsets x_j − x_i (m) by
/// component, and λ times the kernel's gradient coefficient (1/m³).
#[derive(Default)]
struct Gather {
    ids: Vec<u32>,
    lambdas: Vec<f64>,
    rx: Vec<f64>,
    ry: Vec<f64>,
    rz: Vec<f64>,
    factors: Vec<f64>,
}

impl Gather {
    /// Reserves room for particles of up to `n` neighbours, as [`Gather::resize`] grows the
    /// arrays for them, so that it then allocates nothing.
    fn try_reserve(&mut self, n: usize) -> Result<(), TryReserveError> {
        reserve_total(&mut self.ids, n)?;
        for v in [
            &mut self.lambdas,
            &mut self.rx,
            &mut self.ry,
            &mut self.rz,
            &mut self.factors,
        ] {
            reserve_total(v, padded_room(n))?;
        }
        Ok(())
    }

    /// Room for `n` neighbours in every array.
    fn resize(&mut self, n: usize) {
        if self.ids.len() < n {
            self.ids.resize(n, 0);
            let arrays = [
                &mut self.lambdas,
                &mut self.rx,
                &mut self.ry,
                &mut self.rz,
                &mut self.factors,
            ];
            pad_each([], arrays, n);
        }
    }
}

thread_local! {
    static GATHER: std::cell::RefCell<Gather> = std::cell::RefCell::new(Gather::default());
}

/// Reserves the calling thread's gather buffers for particles of up to `n` neighbours.
pub(super) fn reserve_gather(n: usize) -> Result<(), TryReserveError> {
    GATHER.with_borrow_mut(|gather| gather.try_reserve(n))
}

impl DensityConstraint {
    /// Σ_{i: j∈N̄_j} (P_{i,j} − x_j): the sum of all corrections the local step made to
    /// particle j's position (m), gathered from its own and its neighbours' projections,
    /// for every particle j of `first..first + out.len()`, into `out[j − first]`.
    #[inline]
    pub fn gathered_corrections(
        &self,
        first: usize,
        x: &[Vec3],
        nb: &Neighborhood,
        projections: &[Projection],
        corrections: &Corrections,
        out: &mut [Vec3],
    ) {
        GATHER.with_borrow_mut(|gather| {
            for (j, sum) in (first..).zip(out) {
                *sum = self.gather_into(j, x, nb, projections, corrections, gather);
            }
        })
    }

    crate::simd::avx2_dispatch! {
        /// [`Self::gathered_corrections`] with the thread's buffers; the AVX2 build evaluates
        /// the gradients four lanes wide, bitwise alike (tested).
        fn gather_into / gather_into_avx2(
            &self,
            j: usize,
            x: &[Vec3],
            nb: &Neighborhood,
            projections: &[Projection],
            corrections: &Corrections,
            gather: &mut Gather,
        ) -> Vec3 where !self.portable => gathered_correction_portable
    }

    /// The body of [`Self::gathered_corrections`]. A first pass lists, without branches and
    /// from one byte per particle, the neighbours i whose single-step projection moved j
    /// (λ_i ≠ 0; about a quarter of them in a flow, in no predictable order); a second reads
    /// their λ_i and offsets, and a third evaluates their λ_i∇W(x_j − x_i) by component, four
    /// at a time. Kept segments are read apart (rare).
    #[inline(always)]
    fn gathered_correction_portable(
        &self,
        j: usize,
        x: &[Vec3],
        nb: &Neighborhood,
        projections: &[Projection],
        corrections: &Corrections,
        gather: &mut Gather,
    ) -> Vec3 {
        let neighbors = nb.fluid.of(j);
        gather.resize(neighbors.len());
        let mut active = 0;
        // Through a slice, so that its bounds stay in registers across the stores.
        let ids = &mut gather.ids[..neighbors.len()];
        for &i in neighbors {
            // Written for every neighbour, kept only where the count moves on.
            ids[active] = i;
            active += usize::from(corrections.moved[i as usize]);
        }
        let g = gather;
        let xj = x[j];
        for ((((&i, lambda), rx), ry), rz) in g.ids[..active]
            .iter()
            .zip(&mut g.lambdas)
            .zip(&mut g.rx)
            .zip(&mut g.ry)
            .zip(&mut g.rz)
        {
            *lambda = corrections.lambdas[i as usize];
            let xi = &x[i as usize];
            (*rx, *ry, *rz) = (xj.x - xi.x, xj.y - xi.y, xj.z - xi.z);
        }
        for ((((f, lambda), rx), ry), rz) in g.factors[..active]
            .iter_mut()
            .zip(&g.lambdas)
            .zip(&g.rx)
            .zip(&g.ry)
            .zip(&g.rz)
        {
            let len = (rx * rx + ry * ry + rz * rz).sqrt();
            *f = self.kernel.grad_w_coefficient(len) * lambda;
        }
        let (f, n) = (&g.factors[..active], active);
        // λ_i w_j ∇_{x_j}C_i with ∇_{x_j}C_i = (m/ρ0)∇W(x_j − x_i), w_j and m/ρ0 common.
        let moved = Vec3::new(
            ordered_dot(&g.rx[..n], f),
            ordered_dot(&g.ry[..n], f),
            ordered_dot(&g.rz[..n], f),
        );
        let scale = self.weight_of(nb, j) * self.mass / self.rest_density;
        let mut sum = projections[j].self_correction + moved * scale;
        if corrections.near_kept[j] {
            for &i in neighbors {
                if projections[i as usize].materialized {
                    sum += corrections.kept_correction(i as usize, j, nb, projections);
                }
            }
        }
        sum
    }
}
