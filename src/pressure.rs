//! Pressure read from the density constraint: its multipliers play the role of a pressure
//! field (docs/method.md §10.1).
//!
//! The force constraint i exerts on neighbour j at the converged iterate is
//! f_ij = k·(P_ij − x_j) = k·λ_i·w_j·∇_{x_j}C_i = −k·λ_i·w_j·(m/ρ0)·∇W(x_i − x_j)
//! (from M(x − s)/Δt² = k·Σ_i (P_i − x), the global step at its fixed point). The symmetric SPH
//! pressure force particle i's pressure p_i exerts on j is m²·(p_i/ρ0²)·∇W(x_i − x_j). Equating
//! the two gives p_i = −k·λ_i·w_j/V with V = m/ρ0; with w_j ≈ w_i this is the per-particle
//! estimate p_i = −k·λ_i·w_i/V. It is a reading of the constraint forces (their magnitude is
//! set by the force balance, not by an equation of state).
//!
//! The step's iteration rarely ends at that fixed point, so k·λ_i is taken from the
//! multipliers the last step carried through its iteration (docs/method.md §10.1): what its
//! constraints did over the whole step, wherever the iteration stopped. Where the last step
//! did not carry them (the warm start, the coarse correction) or particles were added or
//! moved since, λ_i is the multiplier of a local step at the current positions, which needs a
//! tight outer tolerance to be accurate.

use crate::constraint::{Corrections, Neighborhood, Projection};
use crate::reduce::sum_over;
use crate::world::Snapshot;
use crate::{Vec3, World};

/// Pressures estimated from the constraint forces at the current positions.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ConstraintPressures {
    /// Every fluid particle's position (m) and pressure estimate (Pa), in the order of a
    /// neighbour grid's cells.
    pub samples: Vec<(Vec3, f64)>,
    /// The mean vertical (y) constraint force per fluid particle (N): in a tank at rest it
    /// balances the particle's weight.
    pub mean_vertical_force: f64,
}

impl World {
    /// The pressure estimate p_i = −k·λ_i·w_i/V (Pa) of every fluid particle, from the
    /// multipliers the last step carried (or a local step at the current positions, see the
    /// module docs), with its position; and the mean vertical constraint force per particle
    /// at the current positions (N).
    ///
    /// # Panics
    /// When memory for the neighbour lists and projections cannot be had (a reading for
    /// the Rust API and the tools, not part of the C API).
    pub fn constraint_pressures(&self) -> ConstraintPressures {
        self.pool.install(|| {
            let Some(snapshot) = self.snapshot() else {
                return ConstraintPressures::default();
            };
            let (pressures, mean_vertical_force) = self.pressure_field(&snapshot);
            ConstraintPressures {
                samples: snapshot.fluid.iter().copied().zip(pressures).collect(),
                mean_vertical_force,
            }
        })
    }

    /// The pressure estimate (Pa) of every fluid particle of `snapshot`, in its order, and the
    /// mean vertical constraint force per particle (N). Runs on the caller's thread pool.
    /// The pressures are the last step's, carried through its iteration, where it kept them
    /// and nothing moved or added particles since; else they are read from a local step at
    /// the current positions (see the module docs).
    pub(crate) fn pressure_field(&self, snapshot: &Snapshot) -> (Vec<f64>, f64) {
        let carried = &self.fluid.pressures;
        self.with_neighborhood(snapshot, |nb| {
            if carried.len() == self.fluid.len() {
                let slots = snapshot.fluid_order.iter();
                let pressures: Vec<f64> = slots.map(|&slot| carried[slot as usize]).collect();
                let support = self.mean_vertical_force(&snapshot.fluid, nb, &pressures);
                (pressures, support)
            } else {
                self.pressures_in(&snapshot.fluid, nb)
            }
        })
    }

    /// The mean vertical constraint force per particle (N) of the fluid particles at `x` with
    /// neighbourhood `nb` whose constraints hold `pressures` (Pa): k·λ_i = −p_i·V/μ_i, and
    /// constraint i pushes the fluid with k·λ_i·Σ_j w_j ∇_{x_j} C_i.
    fn mean_vertical_force(&self, x: &[Vec3], nb: &Neighborhood, pressures: &[f64]) -> f64 {
        let c = &self.constraint;
        let volume = c.mass / c.rest_density;
        let force_sum = sum_over(x.len(), |i| {
            let k_lambda = -pressures[i] * volume / c.membership(nb.fluid, i);
            k_lambda * c.weighted_gradient_sum(i, x, nb).y
        });
        force_sum / x.len().max(1) as f64
    }

    /// The pressure estimates (Pa) of the fluid particles at `x` with neighbourhood `nb`, and
    /// the mean vertical constraint force per particle (N), from a local step at `x`.
    fn pressures_in(&self, x: &[Vec3], nb: &Neighborhood) -> (Vec<f64>, f64) {
        let params = &self.params;
        let c = &self.constraint;
        let (mut projections, mut corrections) = (Vec::<Projection>::new(), Corrections::default());
        c.project(x, nb, &mut projections, &mut corrections)
            .expect("out of memory for the pressure estimate");
        let volume = c.mass / c.rest_density;
        // Σ_i k·(P_ij − x_j): the constraint force on each particle, gathered as the global
        // step gathers it.
        let mut gathered = vec![Vec3::zeros(); x.len()];
        c.gathered_corrections(0, x, nb, &projections, &corrections, &mut gathered);
        let force_sum: f64 = gathered.iter().map(|p| p.y).sum();
        let support = force_sum * params.stiffness / x.len().max(1) as f64;
        let pressures = (0..x.len())
            .map(|i| {
                let weight = c.membership(nb.fluid, i);
                -params.stiffness * corrections.lambda(i) * weight / volume
            })
            .collect();
        (pressures, support)
    }
}
