//! Neighbourhoods of the particles where they are now, built afresh for a read that evaluates
//! the constraint between steps (densities, pressures), so that such a read never depends on
//! or disturbs the step's own buffers.

use super::World;
use crate::Vec3;
use crate::boundary::{Aabb, akinci_volumes};
use crate::constraint::Neighborhood;
use crate::neighbors::{CellTable, NeighborLists, PointsByComponent, UniformGrid};

/// The fluid particles sorted along the search grid, with their neighbourhood.
pub(crate) struct Snapshot<'a> {
    /// Fluid positions (m) in grid order.
    pub x: &'a [Vec3],
    /// `order[k]` is the storage index of the particle at `x[k]`.
    pub order: &'a [u32],
    /// Every particle's fluid and boundary neighbours, in grid order.
    pub nb: &'a Neighborhood<'a>,
}

impl World {
    /// Runs `read` on a snapshot of the current positions, in the world's thread pool.
    /// `None` without fluid particles.
    pub(crate) fn with_snapshot<R: Send>(
        &self,
        read: impl FnOnce(&Snapshot) -> R + Send,
    ) -> Option<R> {
        let h = self.params.support_radius();
        let fluid = &self.fluid.positions;
        let boundary = &self.boundary;
        let fluid_bounds = Aabb::around(fluid)?;
        let bounds =
            Aabb::around(&boundary.positions).map_or(fluid_bounds, |b| b.union(&fluid_bounds));
        Some(self.pool.install(|| {
            let grid = UniformGrid::covering(bounds.min, bounds.max, h);
            let sorted = |points: &[Vec3], table: &mut CellTable| {
                let mut order = Vec::new();
                grid.sort(points, &mut order, table);
                order
            };
            let (mut fluid_table, mut boundary_table) =
                (CellTable::default(), CellTable::default());
            let order = sorted(fluid, &mut fluid_table);
            let boundary_order = sorted(&boundary.positions, &mut boundary_table);
            let x: Vec<Vec3> = order.iter().map(|&i| fluid[i as usize]).collect();
            let bx: Vec<Vec3> = boundary_order
                .iter()
                .map(|&i| boundary.positions[i as usize])
                .collect();
            // Before the first step the boundary has no masses yet: they are computed here
            // from the particles present, as the step would.
            let psi: Vec<f64> = if boundary.psi.len() == boundary.positions.len() {
                boundary_order
                    .iter()
                    .map(|&i| boundary.psi[i as usize])
                    .collect()
            } else {
                let mut by_component = PointsByComponent::default();
                by_component.fill(&bx);
                let kernel = &self.constraint.kernel;
                akinci_volumes(&grid, &boundary_table, &bx, &by_component, kernel)
                    .iter()
                    .map(|v| v * self.params.rest_density)
                    .collect()
            };
            let (mut fluid_lists, mut boundary_lists) =
                (NeighborLists::default(), NeighborLists::default());
            grid.search(&fluid_table, &x, &x, h, true, &mut fluid_lists);
            grid.search(&boundary_table, &bx, &x, h, false, &mut boundary_lists);
            let mut weights = Vec::new();
            self.constraint.weights(&fluid_lists, &mut weights);
            let nb = Neighborhood {
                fluid: &fluid_lists,
                boundary: &boundary_lists,
                boundary_positions: &bx,
                boundary_psi: &psi,
                weights: &weights,
            };
            read(&Snapshot {
                x: &x,
                order: &order,
                nb: &nb,
            })
        }))
    }

    /// The SPH density ρ_i (kg/m³) of every fluid particle at its current position, in
    /// ascending id order (see [`World::ids`]). Unlike [`World::densities`], which reports
    /// the densities the last step ended with, this evaluates them now: before the first step
    /// it shows whether the fluid starts at rest density, against walls and obstacles too.
    pub fn current_densities(&self) -> Vec<f64> {
        let in_storage_order = self
            .with_snapshot(|s| {
                let mut rho = Vec::new();
                self.constraint.densities(s.x, s.nb, &mut rho);
                let mut out = vec![0.0; rho.len()];
                for (&k, value) in s.order.iter().zip(rho) {
                    out[k as usize] = value;
                }
                out
            })
            .unwrap_or_default();
        let mut out = vec![0.0; self.fluid_count()];
        self.gather_by_id(&in_storage_order, &mut out);
        out
    }
}
