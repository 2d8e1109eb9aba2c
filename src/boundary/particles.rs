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

    /// Removes the moving bodies' particles, keeping the static ones in their order.
    pub fn drop_moving(&mut self) {
        if !self.owner.iter().any(|&o| self.is_moving(o)) {
            return;
        }
        let keep: Vec<bool> = self.owner.iter().map(|&o| !self.is_moving(o)).collect();
        let mut k = keep.iter();
        self.positions
            .retain(|_| *k.next().expect("one flag per particle"));
        if self.psi.len() == keep.len() {
            let mut k = keep.iter();
            self.psi
                .retain(|_| *k.next().expect("one flag per particle"));
        }
        let mut k = keep.iter();
        self.owner
            .retain(|_| *k.next().expect("one flag per particle"));
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
        let mut order = Vec::new();
        grid.sort(&self.positions, &mut order, &mut self.table);
        self.table.release_scratch();
        self.positions = order.iter().map(|&i| self.positions[i as usize]).collect();
        self.psi = order.iter().map(|&i| self.psi[i as usize]).collect();
        self.owner = order.iter().map(|&i| self.owner[i as usize]).collect();
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
