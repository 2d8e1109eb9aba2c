//! Boundary particles as the time step reads them: sorted by the neighbour grid's cells, each
//! with its Akinci mass ψ_b = ρ0·V_b (docs/method.md §2.6) and the owner it belongs to (the
//! walls and obstacles, or a body, docs/method.md §11).
//!
//! Static particles (walls, obstacles, static bodies) are sorted and given volumes once. The
//! particles of moving bodies are placed anew before every step at the bodies' poses, with
//! the masses computed in their own frames, and sorted in among the static ones.

use super::undo::BoundaryCopy;
use super::{WALLS, WallField};
use crate::Vec3;
use crate::boundary::akinci_volumes;
use crate::kernel::CubicKernel;
use crate::neighbors::{CellTable, PointsByComponent, UniformGrid};
use crate::permutation::permute_in_place;
use crate::reserve::reserve_total;
use std::collections::TryReserveError;

/// Boundary particles, sorted by the grid's cells, with their Akinci masses and owners.
#[derive(Clone, Debug, Default)]
pub(crate) struct Boundary {
    /// Positions (m), in the grid's cell order once sorted; by component, as the neighbour
    /// search reads them.
    pub positions: PointsByComponent,
    /// ψ_b = ρ0·V_b (kg), valid unless `dirty`.
    pub psi: Vec<f64>,
    /// The body each particle belongs to, or [`WALLS`].
    pub owner: Vec<u32>,
    /// Where each grid cell's particles lie in `positions`.
    pub table: CellTable,
    /// Container walls without particles (docs/method.md §7).
    pub walls: Vec<WallField>,
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
    positions: PointsByComponent,
    psi: Vec<f64>,
    owner: Vec<u32>,
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

    /// The number of particles.
    pub fn len(&self) -> usize {
        self.positions.len()
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

    /// Whether particle `k` belongs to a moving body.
    pub fn is_moving_particle(&self, k: usize) -> bool {
        self.is_moving(self.owner[k])
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
            self.positions.set(kept, self.positions.at(k));
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
    /// `kernel` and the rest density ρ0 (kg/m³); runs on the caller's thread pool. What the
    /// sort changes is kept in `copy` first, unless it holds the boundary from before a
    /// change already: the whole boundary where bodies move (their particles are dropped),
    /// else only the order the particles are sorted into (they are reordered in place), with
    /// the masses and the cell table that the sort replaces. Errors when memory for the sort,
    /// the volumes or the copy cannot be had, with what it changed kept in `copy`
    /// ([`Boundary::restore`] puts it back).
    pub fn sort(
        &mut self,
        grid: &UniformGrid,
        kernel: &CubicKernel,
        rest_density: f64,
        copy: &mut BoundaryCopy,
    ) -> Result<(), TryReserveError> {
        if self.has_moving() {
            self.save(copy)?;
            self.dirty = true;
            self.drop_moving();
        }
        let (mut order, mut table) = (Vec::new(), CellTable::default());
        grid.sort_by_component(&self.positions, &mut order, &mut table)?;
        table.release_scratch();
        let (positions, owner) = (&mut self.positions, &mut self.owner);
        permute_in_place(&mut order, |a, b| {
            positions.swap(a, b);
            owner.swap(a, b);
        });
        let table = std::mem::replace(&mut self.table, table);
        let psi = std::mem::take(&mut self.psi);
        copy.sorted(order, psi, table, self.dirty);
        self.dirty = true;
        let volumes = akinci_volumes(grid, &self.table, &self.positions, kernel)?;
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
            self.positions.try_reserve(self.positions.len() + 1)?;
            self.psi.try_reserve(1)?;
            self.owner.try_reserve(1)?;
            self.positions.push(x);
            self.psi.push(psi);
            self.owner.push(owner);
        }
        // The sort's order and the permuted copies live in reusable buffers: this runs every
        // step while bodies move.
        let (n, spare) = (self.positions.len(), &mut self.spare);
        grid.sort_by_component(&self.positions, &mut spare.order, &mut self.table)?;
        reserve_total(&mut spare.psi, n)?;
        reserve_total(&mut spare.owner, n)?;
        spare
            .positions
            .try_permuted_from(&self.positions, &spare.order)?;
        std::mem::swap(&mut self.positions, &mut spare.positions);
        permute(&spare.order, &mut self.psi, &mut spare.psi);
        permute(&spare.order, &mut self.owner, &mut spare.owner);
        Ok(())
    }

    /// A boundary of static particles at `positions` (m) that belong to `owner`s, unsorted,
    /// with this one's record of which bodies move; or an error when memory for it cannot
    /// be had.
    pub fn with_statics(
        &self,
        positions: &[Vec3],
        owner: Vec<u32>,
    ) -> Result<Self, TryReserveError> {
        let mut boundary = Boundary {
            owner,
            dirty: true,
            moving: self.moving.clone(),
            ..Default::default()
        };
        boundary.positions.try_reserve(positions.len())?;
        boundary.positions.extend_from_slice(positions);
        Ok(boundary)
    }

    /// The static particles' positions (m) and owners, in their sorted order.
    pub fn statics(&self) -> (Vec<Vec3>, Vec<u32>) {
        self.positions
            .iter()
            .zip(&self.owner)
            .filter(|(_, o)| !self.is_moving(**o))
            .map(|(x, o)| (x, *o))
            .unzip()
    }
}
