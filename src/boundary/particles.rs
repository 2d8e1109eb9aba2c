//! Boundary particles as the time step reads them: sorted by the neighbour grid's cells, each
//! with its Akinci mass ψ_b = ρ0·V_b (docs/method.md §2.6) and the owner it belongs to (the
//! walls and obstacles, or a body, docs/method.md §11).
//!
//! Static particles (walls, obstacles, static bodies) are sorted and given volumes once. The
//! particles of moving bodies are placed anew before every step at the bodies' poses, with
//! the masses computed in their own frames, and sorted in among the static ones.

use super::WALLS;
use crate::Vec3;
use crate::boundary::akinci_volumes;
use crate::kernel::CubicKernel;
use crate::neighbors::{CellTable, PointsByComponent, UniformGrid};
use crate::reserve::reserve_total;
use std::collections::TryReserveError;

/// Boundary particles, sorted by the grid's cells, with their Akinci masses and owners.
#[derive(Clone, Debug, Default)]
pub(crate) struct Boundary {
    /// Positions (m), in the grid's cell order once sorted.
    pub positions: Vec<Vec3>,
    /// ψ_b = ρ0·V_b (kg), valid unless `dirty`.
    pub psi: Vec<f64>,
    /// The body each particle belongs to, or [`WALLS`].
    pub owner: Vec<u32>,
    /// Where each grid cell's particles lie in `positions`.
    pub table: CellTable,
    /// `positions` by component, for the neighbour search (valid unless `dirty`).
    pub by_component: PointsByComponent,
    /// Set when particles were added or the grid changed: sort and volumes must be redone.
    pub dirty: bool,
    /// Whether the body of each owner index moves (its particles are placed every step).
    moving: Vec<bool>,
    /// Buffers of the per-step sort while bodies move.
    spare: Spare,
}

/// The sort order and the previous arrays of [`Boundary::place_moving`], kept for reuse.
#[derive(Clone, Debug, Default)]
struct Spare {
    order: Vec<u32>,
    positions: Vec<Vec3>,
    psi: Vec<f64>,
    owner: Vec<u32>,
}

/// A copy of the arrays of a [`Boundary`] that a step changes (sorting it anew, placing the
/// moving bodies' particles), taken before it changes them so that a step that fails can
/// put them back ([`Boundary::restore`]). Its storage is kept from step to step.
#[derive(Clone, Debug, Default)]
pub(crate) struct BoundaryCopy {
    positions: Vec<Vec3>,
    psi: Vec<f64>,
    owner: Vec<u32>,
    table: CellTable,
    by_component: PointsByComponent,
    dirty: bool,
    /// The arrays hold a copy not yet put back or discarded.
    held: bool,
}

impl BoundaryCopy {
    /// Forgets the copy held (after the step that took it succeeded), keeping the storage.
    pub fn discard(&mut self) {
        self.held = false;
    }
}

/// Makes `out` a copy of `from`, reusing its storage.
fn copy_into<T: Copy>(out: &mut Vec<T>, from: &[T]) -> Result<(), TryReserveError> {
    out.clear();
    reserve_total(out, from.len())?;
    out.extend_from_slice(from);
    Ok(())
}

/// `data` reordered so that slot k holds `data[order[k]]`, in new storage.
fn permuted<T: Copy>(order: &[u32], data: &[T]) -> Result<Vec<T>, TryReserveError> {
    let mut out = Vec::new();
    out.try_reserve_exact(order.len())?;
    out.extend(order.iter().map(|&i| data[i as usize]));
    Ok(out)
}

/// Reorders `data` so that slot k holds the old `data[order[k]]`, through `spare`, which
/// has room for `order.len()` entries.
fn permute<T: Copy>(order: &[u32], data: &mut Vec<T>, spare: &mut Vec<T>) {
    spare.clear();
    spare.extend(order.iter().map(|&i| data[i as usize]));
    std::mem::swap(data, spare);
}

impl Boundary {
    /// Adds static particles at `positions` (m) that belong to `owner`.
    pub fn add_static(&mut self, positions: &[Vec3], owner: u32) {
        self.positions.extend_from_slice(positions);
        self.owner.resize(self.positions.len(), owner);
        self.dirty = true;
    }

    /// Records whether body `owner`'s particles move.
    pub fn set_moving(&mut self, owner: u32, moves: bool) {
        let o = owner as usize;
        if self.moving.len() <= o {
            self.moving.resize(o + 1, false);
        }
        self.moving[o] = moves;
    }

    /// Whether any body moves.
    pub fn has_moving(&self) -> bool {
        self.moving.iter().any(|&m| m)
    }

    fn is_moving(&self, owner: u32) -> bool {
        owner != WALLS && self.moving.get(owner as usize).copied().unwrap_or(false)
    }

    /// Removes the moving bodies' particles, keeping the static ones in their order (in place;
    /// ψ is compacted alongside when it is valid for every particle).
    pub fn drop_moving(&mut self) {
        let with_psi = self.psi.len() == self.positions.len();
        let mut kept = 0;
        for k in 0..self.positions.len() {
            if self.is_moving(self.owner[k]) {
                continue;
            }
            self.positions[kept] = self.positions[k];
            self.owner[kept] = self.owner[k];
            if with_psi {
                self.psi[kept] = self.psi[k];
            }
            kept += 1;
        }
        self.positions.truncate(kept);
        self.owner.truncate(kept);
        if with_psi {
            self.psi.truncate(kept);
        }
    }

    /// Sorts the static particles into `grid`'s cells and computes their Akinci masses with
    /// `kernel` and the rest density ρ0 (kg/m³); runs on the caller's thread pool. Errors
    /// when memory for the sort or the volumes cannot be had: the boundary is then left
    /// marked for sorting (`dirty`), its moving bodies' particles dropped, and a caller that
    /// must change nothing keeps a copy ([`Boundary::save`]).
    pub fn sort(
        &mut self,
        grid: &UniformGrid,
        kernel: &CubicKernel,
        rest_density: f64,
    ) -> Result<(), TryReserveError> {
        self.dirty = true;
        self.drop_moving();
        let mut order = Vec::new();
        grid.sort(&self.positions, &mut order, &mut self.table)?;
        self.table.release_scratch();
        let positions = permuted(&order, &self.positions)?;
        let owner = permuted(&order, &self.owner)?;
        self.by_component.fill(&positions)?;
        let volumes = akinci_volumes(grid, &self.table, &positions, &self.by_component, kernel)?;
        self.positions = positions;
        self.owner = owner;
        // The volumes' storage becomes the masses'.
        self.psi = volumes;
        self.psi.iter_mut().for_each(|v| *v *= rest_density);
        self.dirty = false;
        Ok(())
    }

    /// Replaces the moving bodies' particles by `moving` (position (m), ψ (kg), owner) and
    /// sorts all particles into `grid`'s cells, carrying masses and owners along. The static
    /// particles keep their relative order (the sort is stable and they were sorted). Errors
    /// when memory for the particles or the sort cannot be had, leaving the boundary part
    /// placed: a caller that must change nothing keeps a copy ([`Boundary::save`]).
    pub fn place_moving(
        &mut self,
        grid: &UniformGrid,
        moving: impl Iterator<Item = (Vec3, f64, u32)>,
    ) -> Result<(), TryReserveError> {
        self.drop_moving();
        for (x, psi, owner) in moving {
            self.positions.try_reserve(1)?;
            self.psi.try_reserve(1)?;
            self.owner.try_reserve(1)?;
            self.positions.push(x);
            self.psi.push(psi);
            self.owner.push(owner);
        }
        // The sort's order and the permuted copies live in reusable buffers: this runs every
        // step while bodies move.
        let (n, spare) = (self.positions.len(), &mut self.spare);
        grid.sort(&self.positions, &mut spare.order, &mut self.table)?;
        reserve_total(&mut spare.positions, n)?;
        reserve_total(&mut spare.psi, n)?;
        reserve_total(&mut spare.owner, n)?;
        self.by_component.try_reserve(n)?;
        permute(&spare.order, &mut self.positions, &mut spare.positions);
        permute(&spare.order, &mut self.psi, &mut spare.psi);
        permute(&spare.order, &mut self.owner, &mut spare.owner);
        self.by_component.fill(&self.positions)
    }

    /// Copies into `copy` the arrays that sorting or placing changes, unless it holds a copy
    /// already (the boundary as it was before the first change of a step); errors when
    /// memory for the copy cannot be had, changing nothing but `copy`'s storage.
    pub fn save(&self, copy: &mut BoundaryCopy) -> Result<(), TryReserveError> {
        if copy.held {
            return Ok(());
        }
        copy_into(&mut copy.positions, &self.positions)?;
        copy_into(&mut copy.psi, &self.psi)?;
        copy_into(&mut copy.owner, &self.owner)?;
        copy.table.try_copy_from(&self.table)?;
        copy.by_component.try_copy_from(&self.by_component)?;
        copy.dirty = self.dirty;
        copy.held = true;
        Ok(())
    }

    /// Puts back the arrays `copy` holds, if it holds any (swapped, not copied: this cannot
    /// fail), and leaves `copy` holding none.
    pub fn restore(&mut self, copy: &mut BoundaryCopy) {
        if !std::mem::take(&mut copy.held) {
            return;
        }
        std::mem::swap(&mut self.positions, &mut copy.positions);
        std::mem::swap(&mut self.psi, &mut copy.psi);
        std::mem::swap(&mut self.owner, &mut copy.owner);
        std::mem::swap(&mut self.table, &mut copy.table);
        std::mem::swap(&mut self.by_component, &mut copy.by_component);
        self.dirty = copy.dirty;
    }

    /// A boundary of static particles at `positions` (m) that belong to `owner`s, unsorted,
    /// with this one's record of which bodies move.
    pub fn with_statics(&self, positions: Vec<Vec3>, owner: Vec<u32>) -> Self {
        Boundary {
            positions,
            owner,
            dirty: true,
            moving: self.moving.clone(),
            ..Default::default()
        }
    }

    /// The static particles' positions (m) and owners, in their sorted order.
    pub fn statics(&self) -> (Vec<Vec3>, Vec<u32>) {
        self.positions
            .iter()
            .zip(&self.owner)
            .filter(|(_, o)| !self.is_moving(**o))
            .map(|(x, o)| (*x, *o))
            .unzip()
    }
}
