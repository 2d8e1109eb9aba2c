//! Static boundary particles as the time step reads them: sorted by the neighbour grid's
//! cells, each with its Akinci mass ψ_b = ρ0·V_b (docs/method.md §2.6).

use crate::Vec3;
use crate::boundary::akinci_volumes;
use crate::kernel::CubicKernel;
use crate::neighbors::{CellTable, PointsByComponent, UniformGrid};

/// Static boundary particles, sorted by the grid's cells, with their Akinci masses.
#[derive(Clone, Debug, Default)]
pub(crate) struct Boundary {
    /// Positions (m), in the grid's cell order once sorted.
    pub positions: Vec<Vec3>,
    /// ψ_b = ρ0·V_b (kg), valid unless `dirty`.
    pub psi: Vec<f64>,
    /// Where each grid cell's particles lie in `positions`.
    pub table: CellTable,
    /// `positions` by component, for the neighbour search (valid unless `dirty`).
    pub by_component: PointsByComponent,
    /// Set when particles were added or the grid changed: sort and volumes must be redone.
    pub dirty: bool,
}

impl Boundary {
    /// Sorts the particles into `grid`'s cells and computes their Akinci masses with
    /// `kernel` and the rest density ρ0 (kg/m³); runs on the caller's thread pool.
    pub fn sort(&mut self, grid: &UniformGrid, kernel: &CubicKernel, rest_density: f64) {
        let mut order = Vec::new();
        grid.sort(&self.positions, &mut order, &mut self.table);
        self.table.release_scratch();
        self.positions = order.iter().map(|&i| self.positions[i as usize]).collect();
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
}
