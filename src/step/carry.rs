//! The constraint multipliers carried through the outer iteration, from which a step reads its
//! pressures (docs/method.md §10.1). A global step moves particle j by
//! Δt²k (μ_j (X_j − s_j) + c_j Σ_i λ_i w_j ∇_{x_j}C_i)/Â_jj from its prediction s_j, and
//! Chebyshev's extrapolation is an affine combination of iterates, so the displacement at the
//! end of a step sums every local step's corrections, carried through that recurrence. Λ_j
//! follows the same recurrence with particle j's own multiplier λ_j as its source. At the
//! iteration's fixed point Λ_j = Δt²k c_j λ_j/m, so k·λ_j = m Λ_j/(Δt² c_j) there, and the
//! same expression measures what the constraints did over the whole step wherever the step
//! ended: near the fixed point, as with a soft stiffness, or near the hard-constraint solution,
//! as with a stiff one.

use crate::constraint::{Corrections, DensityConstraint};
use crate::neighbors::NeighborLists;
use crate::reserve::reserve_total;
use crate::solver::{Chebyshev, DiagonalSystem};
use rayon::prelude::*;
use std::collections::TryReserveError;

/// Λ^(k) and Λ^(k−1) of every slot (m²), and whether they account for every move of the step.
#[derive(Clone, Debug, Default)]
pub(super) struct Carry {
    current: Vec<f64>,
    previous: Vec<f64>,
    /// False once something moved the iterate outside the recurrence (the warm start, the
    /// coarse correction): the step's pressures are then not read from the carry.
    complete: bool,
}

/// What one outer iteration's recurrence reads.
pub(super) struct Advance<'a> {
    pub constraint: &'a DensityConstraint,
    pub lists: &'a NeighborLists,
    pub corrections: &'a Corrections,
    pub system: &'a DiagonalSystem,
    /// Δt²k (kg).
    pub dt2k: f64,
    /// The extrapolation and its weight ω, where it changes the iterate.
    pub chebyshev: Option<(&'a Chebyshev, f64)>,
}

impl Carry {
    /// Starts a step of `n` slots from Λ = 0. Errors, leaving the carry incomplete, when the
    /// memory cannot be had.
    pub(super) fn start(&mut self, n: usize) -> Result<(), TryReserveError> {
        self.complete = false;
        reserve_total(&mut self.current, n)?;
        reserve_total(&mut self.previous, n)?;
        self.current.clear();
        self.current.resize(n, 0.0);
        self.previous.clone_from(&self.current);
        self.complete = true;
        Ok(())
    }

    /// Starts over from Λ = 0, as the iteration does where it falls back to s.
    pub(super) fn restart(&mut self) {
        self.current.iter_mut().for_each(|a| *a = 0.0);
        self.previous.iter_mut().for_each(|a| *a = 0.0);
    }

    /// The iterate moved outside the recurrence: this step's pressures are not carried.
    pub(super) fn abandon(&mut self) {
        self.complete = false;
    }

    /// Λ^(k+1) from the local step's multipliers λ^(k), as the global step and the
    /// extrapolation make X^(k+1) from X^(k).
    pub(super) fn advance(&mut self, a: &Advance) {
        if !self.complete {
            return;
        }
        let c = a.constraint;
        self.current
            .par_iter_mut()
            .zip(self.previous.par_iter_mut())
            .enumerate()
            .for_each(|(j, (current, previous))| {
                let (mu, scale) = (c.membership(a.lists, j), c.correction_scale(a.lists, j));
                let lambda = a.corrections.lambda(j);
                let plain = a.dt2k * (mu * *current + scale * lambda) / a.system.diagonal[j];
                let next = match a.chebyshev {
                    Some((chebyshev, omega)) => {
                        chebyshev.extrapolated(omega, plain, *current, *previous)
                    }
                    None => plain,
                };
                *previous = *current;
                *current = next;
            });
    }

    /// Writes every slot's pressure p_j = −k λ_j μ_j / V (Pa), with k λ_j = m Λ_j/(Δt² c_j),
    /// into `pressures`, m being the world's particle mass (kg), Δt = `dt` (s) and V the rest
    /// volume m/ρ0 (m³); or leaves it empty where the carry is incomplete. The step reserved
    /// the room before it could fail; were it missing, the pressures are left empty too.
    pub(super) fn pressures(
        &self,
        constraint: &DensityConstraint,
        lists: &NeighborLists,
        dt: f64,
        pressures: &mut Vec<f64>,
    ) {
        pressures.clear();
        if !self.complete || reserve_total(pressures, self.current.len()).is_err() {
            return;
        }
        let mass = constraint.mass;
        let volume = mass / constraint.rest_density;
        pressures.par_extend(self.current.par_iter().enumerate().map(|(j, carried)| {
            let scale = constraint.correction_scale(lists, j);
            let k_lambda = mass * carried / (dt * dt * scale);
            -k_lambda * constraint.membership(lists, j) / volume
        }));
    }
}
