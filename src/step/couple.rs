//! The fluid's loads on the boundary (docs/method.md §11.3).
//!
//! A step moves every fluid particle from its prediction s to x^{n+1}, and the outer iteration
//! says exactly how: each global step is affine in the iterate, X̃_j − s_j =
//! Δt²k (n_j (X_j − s_j) + Σ_i c_{i,j}) / Â_jj, and Chebyshev's extrapolation is an affine
//! combination of iterates. The only terms of Σ_i c_{i,j} that come from boundary particles
//! are those of particle j's own constraint: its centre correction λ_j w_j ∇_{x_j}C_j has the
//! boundary part λ_j w_j (1/ρ0) Σ_b ψ_b ∇W(x_j − x_b). So the part u_{j,o} of the displacement
//! x_j − s_j that the particles of owner o caused follows the same recurrence, with those terms
//! alone as its source; it is carried along the iteration in one slot per fluid particle and
//! owner in reach. The owner's load is the opposite of the momentum it gave the fluid:
//! F_o = −(m/Δt²) Σ_j u_{j,o}, its moment about the origin Σ_j x_j × f_{j,o} (each pair force
//! lies on the line through the two particles, so x_j is as good an arm as x_b).
//!
//! Slots are listed in particle order and summed in blocks of fixed size in block order, so
//! the loads do not depend on the thread count.

use crate::Vec3;
use crate::boundary::Boundary;
use crate::constraint::{DensityConstraint, Projection};
use crate::neighbors::NeighborLists;
use crate::solver::Chebyshev;
use rayon::prelude::*;

/// Slots per block of the final reduction.
const BLOCK: usize = 1024;

/// What the fluid exerted on one owner of boundary particles during a step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Load {
    /// Force (N).
    pub force: Vec3,
    /// Moment about the world origin (N·m).
    pub moment: Vec3,
}

impl Load {
    fn add(&mut self, other: &Load) {
        self.force += other.force;
        self.moment += other.moment;
    }

    /// The moment about `point` (m) instead of the origin (N·m).
    pub fn torque_about(&self, point: &Vec3) -> Vec3 {
        self.moment - point.cross(&self.force)
    }
}

/// The boundary's share of the fluid's displacement, per fluid particle and owner in reach,
/// at the last three iterates of the outer iteration (m).
#[derive(Clone, Debug, Default)]
pub(crate) struct Coupling {
    /// The fluid particle of each slot.
    particle: Vec<u32>,
    /// The owner of each slot: body o, or the number of bodies for the walls and obstacles.
    owner: Vec<u32>,
    /// (1/ρ0) Σ_b ψ_b ∇W(s_j − x_b) over the owner's particles b near the slot's particle j,
    /// at the prediction s (1/m): the step moves the fluid far less than a kernel radius, so
    /// the boundary's part of ∇C_j is taken once per step.
    gradient: Vec<Vec3>,
    /// The same over all boundary particles near j (1/m).
    all: Vec<Vec3>,
    previous: Vec<Vec3>,
    current: Vec<Vec3>,
    next: Vec<Vec3>,
    /// The number of bodies.
    bodies: usize,
}

/// What one update of the shares reads: the local step's projections made at `x` = X^(k).
pub(super) struct Iterate<'a> {
    pub constraint: &'a DensityConstraint,
    pub fluid_lists: &'a NeighborLists,
    /// X^(k) (m).
    pub x: &'a [Vec3],
    pub projections: &'a [Projection],
    /// Projection weights w_j.
    pub weights: &'a [f64],
    /// Â_jj = m + Δt²k n_j (kg).
    pub diagonal: &'a [f64],
    /// Δt²k (kg).
    pub dt2k: f64,
    /// Chebyshev's recurrence and weight ω, when the step's extrapolation changes the iterate.
    pub chebyshev: Option<(&'a Chebyshev, f64)>,
}

impl Coupling {
    /// Starts a step at the prediction `s` (m): one slot, set to zero, for every fluid
    /// particle and every owner of a boundary particle in its reach.
    pub fn start(
        &mut self,
        constraint: &DensityConstraint,
        boundary: &Boundary,
        boundary_lists: &NeighborLists,
        s: &[Vec3],
        bodies: usize,
    ) {
        self.bodies = bodies;
        let owner_of = |k: u32| (boundary.owner[k as usize] as usize).min(bodies) as u32;
        let slots: Vec<(u32, u32, Vec3, Vec3)> = (0..boundary_lists.len())
            .into_par_iter()
            .flat_map_iter(|j| {
                let near = boundary_lists.of(j);
                let gradient = move |k: u32| {
                    let k = k as usize;
                    constraint.kernel.grad_w(&(s[j] - boundary.positions[k]))
                        * (boundary.psi[k] / constraint.rest_density)
                };
                let mut owners: Vec<u32> = near.iter().map(|&k| owner_of(k)).collect();
                owners.sort_unstable();
                owners.dedup();
                let all: Vec3 = near.iter().map(|&k| gradient(k)).sum();
                owners.into_iter().map(move |o| {
                    let g = near
                        .iter()
                        .filter(|&&k| owner_of(k) == o)
                        .map(|&k| gradient(k))
                        .sum();
                    (j as u32, o, g, all)
                })
            })
            .collect();
        self.particle.clear();
        self.owner.clear();
        self.gradient.clear();
        self.all.clear();
        for &(j, o, g, all) in &slots {
            self.particle.push(j);
            self.owner.push(o);
            self.gradient.push(g);
            self.all.push(all);
        }
        for u in [&mut self.previous, &mut self.current, &mut self.next] {
            u.clear();
            u.resize(slots.len(), Vec3::zeros());
        }
    }

    /// Follows one outer iteration: the shares at X^(k+1) from those at X^(k) and X^(k−1)
    /// and the boundary's corrections at X^(k).
    pub(super) fn update(&mut self, it: &Iterate) {
        let (current, previous) = (&self.current, &self.previous);
        self.next.par_iter_mut().enumerate().for_each(|(s, next)| {
            let j = self.particle[s] as usize;
            let source = it.boundary_correction(j, &self.gradient[s], &self.all[s]);
            let members = it.constraint.membership(it.fluid_lists, j);
            let plain = (current[s] * members + source) * (it.dt2k / it.diagonal[j]);
            *next = match it.chebyshev {
                Some((chebyshev, omega)) => {
                    chebyshev.extrapolated(omega, plain, current[s], previous[s])
                }
                None => plain,
            };
        });
        std::mem::swap(&mut self.previous, &mut self.current);
        std::mem::swap(&mut self.current, &mut self.next);
    }

    /// The loads of the step that ended at `x` (m) with step size `dt` (s) on every owner:
    /// `out[o]` for body o and `out[bodies]` for the walls and obstacles.
    pub fn loads(&self, mass: f64, x: &[Vec3], dt: f64, out: &mut Vec<Load>) {
        let scale = -mass / (dt * dt);
        let bodies = self.bodies;
        let partial: Vec<Vec<Load>> = self
            .current
            .par_chunks(BLOCK)
            .enumerate()
            .map(|(block, shares)| {
                let mut sums = vec![Load::default(); bodies + 1];
                for (s, u) in (block * BLOCK..).zip(shares) {
                    let force = u * scale;
                    let arm = x[self.particle[s] as usize];
                    sums[self.owner[s] as usize].add(&Load {
                        force,
                        moment: arm.cross(&force),
                    });
                }
                sums
            })
            .collect();
        out.clear();
        out.resize(bodies + 1, Load::default());
        for sums in &partial {
            for (o, s) in out.iter_mut().zip(sums) {
                o.add(s);
            }
        }
    }
}

impl Iterate<'_> {
    /// The part of constraint j's correction of its own particle that the boundary particles
    /// of one owner cause: λ_j w_j g (m), where g = (1/ρ0) Σ_b ψ_b ∇W(x_j − x_b) over them
    /// (`of_owner`) and `all` the same over every boundary particle near j (1/m).
    fn boundary_correction(&self, j: usize, of_owner: &Vec3, all: &Vec3) -> Vec3 {
        let p = &self.projections[j];
        if p.self_correction == Vec3::zeros() {
            return Vec3::zeros();
        }
        let w_j = self.weights[j];
        let lambda = if p.materialized {
            // Several projection steps: the multiplier that gives the whole correction of the
            // centre along the gradient at x.
            let c = self.constraint;
            let xj = self.x[j];
            let fluid: Vec3 = self
                .fluid_lists
                .of(j)
                .iter()
                .map(|&i| c.kernel.grad_w(&(xj - self.x[i as usize])) * (c.mass / c.rest_density))
                .sum();
            let gradient = all + fluid;
            let g2 = gradient.norm_squared() * w_j;
            if g2 == 0.0 {
                return Vec3::zeros();
            }
            p.self_correction.dot(&gradient) / g2
        } else {
            p.lambda
        };
        of_owner * (lambda * w_j)
    }
}
