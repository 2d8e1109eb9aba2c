//! Pressure read from the density constraint: its multipliers play the role of a pressure
//! field (docs/method.md §10.1).
//!
//! The force constraint i exerts on neighbour j at the converged iterate is
//! f_ij = k·(P_ij − x_j) = k·λ_i·w_j·∇_{x_j}C_i = −k·λ_i·w_j·(m/ρ0)·∇W(x_i − x_j)
//! (from M(x − s)/Δt² = k·Σ_i (P_i − x), the global step at its fixed point). The symmetric SPH
//! pressure force particle i's pressure p_i exerts on j is m²·(p_i/ρ0²)·∇W(x_i − x_j). Equating
//! the two gives p_i = −k·λ_i·w_j/V with V = m/ρ0; with w_j ≈ w_i this is the per-particle
//! estimate p_i = −k·λ_i·w_i/V, λ_i being the local step's multiplier at the current positions.
//! It is a reading of the constraint forces (their magnitude is set by the force balance, not
//! by an equation of state), and as such needs a tight outer tolerance to be accurate.

use crate::boundary::Aabb;
use crate::constraint::{Corrections, Neighborhood, Projection};
use crate::neighbors::{CellTable, NeighborLists, UniformGrid};
use crate::{Vec3, World};

/// Pressures estimated from the constraint forces at the current positions.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ConstraintPressures {
    /// Every fluid particle's position (m) and pressure estimate (Pa), in the world's storage
    /// order.
    pub samples: Vec<(Vec3, f64)>,
    /// The mean vertical (y) constraint force per fluid particle (N): in a tank at rest it
    /// balances the particle's weight.
    pub mean_vertical_force: f64,
}

impl World {
    /// The pressure estimate p_i = −k·λ_i·w_i/V (Pa) of every fluid particle at its current
    /// position (see the module docs), with that position, in storage order; and the mean
    /// vertical constraint force per particle (N).
    ///
    /// # Panics
    /// When memory for the neighbour lists and projections cannot be had (a diagnostic for
    /// validation runs, not part of the C API).
    pub fn constraint_pressures(&self) -> ConstraintPressures {
        let world = self;
        let params = &world.params;
        let h = params.support_radius();
        let fluid = &world.fluid.positions;
        let boundary = &world.boundary;
        let bounds = [fluid.as_slice(), &boundary.positions]
            .iter()
            .filter_map(|p| Aabb::around(p))
            .reduce(|a, b| a.union(&b));
        let Some(bounds) = bounds else {
            return ConstraintPressures::default();
        };
        world.pool.install(|| {
            let out_of_memory = "out of memory for the pressure estimate";
            let grid = UniformGrid::covering(bounds.min, bounds.max, h).expect(out_of_memory);
            let sorted = |points: &[Vec3], table: &mut CellTable| {
                let mut order = Vec::new();
                grid.sort(points, &mut order, table).expect(out_of_memory);
                order
            };
            let (mut fluid_table, mut boundary_table) =
                (CellTable::default(), CellTable::default());
            let fluid_order = sorted(fluid, &mut fluid_table);
            let boundary_order = sorted(&boundary.positions, &mut boundary_table);
            let x: Vec<Vec3> = fluid_order.iter().map(|&i| fluid[i as usize]).collect();
            let bx: Vec<Vec3> = boundary_order
                .iter()
                .map(|&i| boundary.positions[i as usize])
                .collect();
            let psi: Vec<f64> = boundary_order
                .iter()
                .map(|&i| boundary.psi[i as usize])
                .collect();
            let (mut fluid_lists, mut boundary_lists) =
                (NeighborLists::default(), NeighborLists::default());
            grid.search(&fluid_table, &x, &x, h, true, &mut fluid_lists)
                .expect(out_of_memory);
            grid.search(&boundary_table, &bx, &x, h, false, &mut boundary_lists)
                .expect(out_of_memory);
            let mut weights = Vec::new();
            world.constraint.weights(&fluid_lists, &mut weights);
            let nb = Neighborhood {
                fluid: &fluid_lists,
                boundary: &boundary_lists,
                boundary_positions: &bx,
                boundary_psi: &psi,
                weights: &weights,
            };
            let (mut projections, mut corrections) =
                (Vec::<Projection>::new(), Corrections::default());
            world
                .constraint
                .project(&x, &nb, &mut projections, &mut corrections)
                .expect(out_of_memory);
            let volume = world.constraint.mass / world.constraint.rest_density;
            // Σ_i k·(P_ij − x_j): the constraint force on each particle, gathered as the global
            // step gathers it.
            let c = &world.constraint;
            let mut gathered = vec![Vec3::zeros(); x.len()];
            c.gathered_corrections(0, &x, &nb, &projections, &corrections, &mut gathered);
            let force_sum: f64 = gathered.iter().map(|p| p.y).sum();
            let support = force_sum * params.stiffness / x.len().max(1) as f64;
            let pressures = x
                .iter()
                .zip(&projections)
                .enumerate()
                .map(|(i, (p, proj))| {
                    let weight = c.membership(&fluid_lists, i);
                    (*p, -params.stiffness * proj.lambda * weight / volume)
                })
                .collect();
            ConstraintPressures {
                samples: pressures,
                mean_vertical_force: support,
            }
        })
    }
}
