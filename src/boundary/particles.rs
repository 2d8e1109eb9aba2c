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

/// Reorders `data` so that slot k holds the old `data[order[k]]`, through `spare`.
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
    /// `kernel` and the rest density ρ0 (kg/m³); runs on the caller's thread pool.
    pub fn sort(&mut self, grid: &UniformGrid, kernel: &CubicKernel, rest_density: f64) {
        self.drop_moving();
        let mut order = Vec::new();
        grid.sort(&self.positions, &mut order, &mut self.table);
        self.table.release_scratch();
        self.positions = order.iter().map(|&i| self.positions[i as usize]).collect();
        self.owner = order.iter().map(|&i| self.owner[i as usize]).collect();
        self.by_component.fill(&self.positions);
        let volumes = akinci_volumes(
            grid,
            &self.table,
            &self.positions,
            &self.by_component,
            kernel,
        );
        self.psi = volumes.iter().map(|v| v * rest_density).collect();
        self.dirty = false;
    }

    /// Replaces the moving bodies' particles by `moving` (position (m), ψ (kg), owner) and
    /// sorts all particles into `grid`'s cells, carrying masses and owners along. The static
    /// particles keep their relative order (the sort is stable and they were sorted).
    pub fn place_moving(
        &mut self,
        grid: &UniformGrid,
        moving: impl Iterator<Item = (Vec3, f64, u32)>,
    ) {
        self.drop_moving();
        for (x, psi, owner) in moving {
            self.positions.push(x);
            self.psi.push(psi);
            self.owner.push(owner);
        }
        // The sort's order and the permuted copies live in reusable buffers: this runs every
        // step while bodies move.
        let order = &mut self.spare.order;
        grid.sort(&self.positions, order, &mut self.table);
        permute(order, &mut self.positions, &mut self.spare.positions);
        permute(order, &mut self.psi, &mut self.spare.psi);
        permute(order, &mut self.owner, &mut self.spare.owner);
        self.by_component.fill(&self.positions);
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
