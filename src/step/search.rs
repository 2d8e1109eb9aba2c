//! The neighbour phase of a step (docs/method.md §1.3, §6): the inertial prediction, the
//! grid that covers it, the Z-order sort of the prediction, and the fluid and boundary
//! neighbour searches on s. The phase changes nothing of the world that a failed step
//! could not put back ([`super::Undo`]): the fluid's own arrays are reordered only once the step
//! can no longer fail ([`permute_fluid`]).

use super::StepBuffers;
use crate::Vec3;
use crate::boundary::{Aabb, Boundary, BoundaryCopy};
use crate::fluid::Fluid;
use crate::kernel::CubicKernel;
use crate::neighbors::UniformGrid;
use crate::params::Params;
use crate::permutation::permute_in_place;
use rayon::prelude::*;
use std::collections::TryReserveError;

impl StepBuffers {
    /// Reserves what steps of `fluid` fluid particles need, so that they allocate nothing
    /// where sizes are known (docs/method.md §1.3): every per-particle buffer, the scratch of
    /// the sort, the blocks of the neighbour lists, δ_k for `iterations` outer iterations,
    /// the loads on `bodies` bodies and the walls, and room to keep the state of `bodies`
    /// bodies and `emitters` emitters for an undo. What cannot be known before a step — the
    /// neighbour lists themselves, the segments of kept corrections, a rebuilt grid, the
    /// slots of the body coupling — grows during it through fallible reservations, and a
    /// step that cannot have it is undone.
    pub(crate) fn try_reserve(
        &mut self,
        fluid: usize,
        iterations: usize,
        bodies: usize,
        emitters: usize,
    ) -> Result<(), TryReserveError> {
        use crate::reserve::reserve_total;
        for buffer in [
            &mut self.previous,
            &mut self.current,
            &mut self.next,
            &mut self.rhs,
        ] {
            reserve_total(buffer, fluid)?;
        }
        reserve_total(&mut self.projections, fluid)?;
        reserve_total(&mut self.order, fluid)?;
        reserve_total(&mut self.weights, fluid)?;
        reserve_total(&mut self.system.diagonal, fluid)?;
        reserve_total(&mut self.displacements, iterations)?;
        self.table.try_reserve(fluid, 0)?;
        self.corrections.try_reserve(fluid)?;
        self.fluid_lists.try_reserve(fluid)?;
        self.boundary_lists.try_reserve(fluid)?;
        if bodies > 0 {
            reserve_total(&mut self.loads, bodies + 1)?;
        }
        self.undo.try_reserve(bodies, iterations, emitters)
    }

    /// Gives back the neighbour lists' storage, after a step that failed part-way grew them.
    pub(super) fn release_lists(&mut self) {
        self.fluid_lists.release();
        self.boundary_lists.release();
    }
}

/// The inertial prediction s = x + Δt v + Δt² g (m), into `s` (the buffer of X^(0); where
/// s is read later, it is evaluated again, [`Prediction`]).
pub(super) fn predict(
    pool: &rayon::ThreadPool,
    fluid: &Fluid,
    dt: f64,
    gravity: Vec3,
    s: &mut Vec<Vec3>,
) {
    pool.install(|| {
        s.resize(fluid.len(), Vec3::zeros());
        s.par_iter_mut()
            .zip(fluid.positions.par_iter().zip(fluid.velocities.par_iter()))
            .for_each(|(s, (x, v))| *s = predicted(x, v, dt, gravity));
    });
}

/// s = x + Δt v + Δt² g (m) of a particle at `x` (m) moving at `v` (m/s), over `dt` (s)
/// under `gravity` (m/s²): the one expression of the prediction, so that s comes out bit
/// for bit the same wherever it is evaluated.
#[inline(always)]
fn predicted(x: &Vec3, v: &Vec3, dt: f64, gravity: Vec3) -> Vec3 {
    x + v * dt + gravity * (dt * dt)
}

/// The inertial prediction s of the step (m), evaluated where it is read rather than kept:
/// from the fluid's positions and velocities, which the step leaves as they are until it can
/// no longer fail.
#[derive(Clone, Copy)]
pub(super) struct Prediction<'a> {
    fluid: &'a Fluid,
    /// The sort's order, while the fluid's arrays are not yet in it: slot k of the sort then
    /// holds particle `order[k]`.
    order: Option<&'a [u32]>,
    /// Δt (s).
    dt: f64,
    /// g (m/s²).
    gravity: Vec3,
}

impl<'a> Prediction<'a> {
    /// The prediction of `fluid` over `dt` (s) under `gravity` (m/s²), its slots in the
    /// order `order` of the step's sort, or in the fluid's own with `None` (once the fluid
    /// is sorted).
    pub fn new(fluid: &'a Fluid, order: Option<&'a [u32]>, dt: f64, gravity: Vec3) -> Self {
        Prediction {
            fluid,
            order,
            dt,
            gravity,
        }
    }

    /// s of the particle in slot `k` of the sort (m).
    #[inline]
    pub fn at(&self, k: usize) -> Vec3 {
        let i = self.order.map_or(k, |order| order[k] as usize);
        let f = self.fluid;
        predicted(&f.positions[i], &f.velocities[i], self.dt, self.gravity)
    }
}

/// The grid's slack on every side, as a fraction of the extent of what it covers: room for
/// splashes before a rebuild, at the cost of the memory of empty cells.
const GRID_SLACK: f64 = 0.1;

/// The neighbour grid, kept across steps, and whether it reached its cell limit.
#[derive(Clone, Debug, Default)]
pub(crate) struct SearchGrid {
    /// The grid, once there are particles to cover.
    pub grid: Option<UniformGrid>,
    /// The grid reached its cell limit and no longer grows.
    pub capped: bool,
}

impl SearchGrid {
    /// Makes sure there is a grid and the boundary is sorted with volumes. The grid is
    /// (re)built, with slack around the prediction `b.current` and the boundary, when there
    /// is none, when the boundary changed, or when `outgrown` (some of the prediction lies
    /// outside it) unless it already hit its cell limit; then outlying particles are clamped
    /// into border cells, which stays correct. The grid as it was, and what sorting the
    /// boundary changes, are kept in `b.undo`. Errors when memory for the grid, the sort or
    /// what is kept cannot be had.
    fn prepare(
        &mut self,
        pool: &rayon::ThreadPool,
        params: &Params,
        kernel: &CubicKernel,
        boundary: &mut Boundary,
        b: &mut StepBuffers,
        outgrown: bool,
    ) -> Result<(), TryReserveError> {
        let (points, undo) = (&b.current, &mut b.undo);
        let outgrown = self.grid.is_none() || (outgrown && !self.capped);
        if outgrown || boundary.dirty {
            let bounds = [
                Aabb::around(points),
                Aabb::enclosing(boundary.positions.iter()),
            ]
            .into_iter()
            .flatten()
            .reduce(|a, b| a.union(&b));
            let Some(bounds) = bounds else {
                return Ok(());
            };
            let finite = |v: Vec3| {
                v.map(|c| {
                    if c.is_finite() {
                        c.clamp(-1e6, 1e6)
                    } else {
                        0.0
                    }
                })
            };
            // Slack, so that a splash does not rebuild the grid every step.
            let slack = (bounds.max - bounds.min) * GRID_SLACK;
            let h = params.support_radius();
            let grid =
                UniformGrid::covering(finite(bounds.min - slack), finite(bounds.max + slack), h)?;
            let capped = !pool.install(|| grid.covers(points));
            let replaced = std::mem::replace(
                self,
                SearchGrid {
                    grid: Some(grid),
                    capped,
                },
            );
            // The grid from before the step, not one this step built and replaces again.
            undo.grid.get_or_insert(replaced);
            self.sort_boundary(pool, params, kernel, boundary, &mut undo.boundary)?;
        }
        Ok(())
    }

    /// Sorts `boundary` into the grid's cells with fresh Akinci masses (nothing without a
    /// grid), keeping what it changes in `copy`; errors as [`Boundary::sort`].
    pub fn sort_boundary(
        &self,
        pool: &rayon::ThreadPool,
        params: &Params,
        kernel: &CubicKernel,
        boundary: &mut Boundary,
        copy: &mut BoundaryCopy,
    ) -> Result<(), TryReserveError> {
        match &self.grid {
            Some(grid) => pool.install(|| boundary.sort(grid, kernel, params.rest_density, copy)),
            None => Ok(()),
        }
    }

    /// Prepares the grid around the prediction in `buffers.current` and sorts it into
    /// `buffers.order` and `buffers.table`; the sort's pass also tells whether the grid still
    /// covers s, and if not the grid is rebuilt around it and s sorted again. Errors when
    /// memory for the grid, the boundary's sort or the table cannot be had, with the grid
    /// and the boundary as they were kept in `buffers.undo`.
    pub(super) fn sorted(
        &mut self,
        pool: &rayon::ThreadPool,
        params: &Params,
        kernel: &CubicKernel,
        boundary: &mut Boundary,
        b: &mut StepBuffers,
    ) -> Result<&UniformGrid, TryReserveError> {
        self.prepare(pool, params, kernel, boundary, b, false)?;
        let sort = |grid: &Option<UniformGrid>, b: &mut StepBuffers| {
            let grid = grid.as_ref().expect("prepare builds the grid");
            pool.install(|| grid.sort(&b.current, &mut b.order, &mut b.table))
        };
        if !sort(&self.grid, b)? && !self.capped {
            self.prepare(pool, params, kernel, boundary, b, true)?;
            sort(&self.grid, b)?;
        }
        Ok(self.grid.as_ref().expect("prepare builds the grid"))
    }
}

/// Reorders the prediction s by the sort's order, then finds the fluid and the boundary
/// neighbours of every particle on s within the support radius `h` (m). Errors when the
/// lists need more memory than can be had; the fluid is not touched either way.
pub(super) fn search(
    grid: &UniformGrid,
    boundary: &Boundary,
    h: f64,
    b: &mut StepBuffers,
) -> Result<(), TryReserveError> {
    // X^(k−1) is free until the iteration starts: it serves as the scratch.
    permute(&b.order, &mut b.current, &mut b.previous);
    grid.search(
        &b.table,
        &b.current,
        &b.current,
        h,
        true,
        &mut b.fluid_lists,
    )?;
    grid.search_in(
        &boundary.table,
        &boundary.positions,
        &b.current,
        h,
        false,
        &mut b.boundary_lists,
    )
}

/// Reorders the fluid's own arrays by the sort's order, as [`search`] reordered s: once the
/// step can no longer fail. X^(k−1) of the finished iteration serves as the scratch of the
/// positions and velocities; the ids are reordered in place.
pub(super) fn permute_fluid(fluid: &mut Fluid, b: &mut StepBuffers) {
    permute(&b.order, &mut fluid.positions, &mut b.previous);
    permute(&b.order, &mut fluid.velocities, &mut b.previous);
    permute_in_place(&mut b.order, |a, c| {
        fluid.ids.swap(a, c);
        fluid.materials.swap(a, c);
    });
}

/// Reorders `data` so that slot k holds the old `data[order[k]]`.
fn permute<T: Copy + Send + Sync + Default>(
    order: &[u32],
    data: &mut Vec<T>,
    scratch: &mut Vec<T>,
) {
    scratch.resize(data.len(), T::default());
    scratch
        .par_iter_mut()
        .zip(order.par_iter())
        .for_each(|(s, &o)| *s = data[o as usize]);
    std::mem::swap(data, scratch);
}
