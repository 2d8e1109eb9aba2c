//! The fluid's loads on the bodies and the walls (docs/method.md §11.3).
//!
//! A step moves every fluid particle from its prediction s to x^{n+1}, and the outer iteration
//! says exactly how: each global step is affine in the iterate, X̃_j − s_j =
//! Δt²k (n_j (X_j − s_j) + Σ_i c_{i,j}) / Â_jj, and Chebyshev's extrapolation is an affine
//! combination of iterates. The only terms of Σ_i c_{i,j} that come from boundary particles
//! are those of particle j's own constraint: its centre correction λ_j w_j ∇_{x_j}C_j has the
//! boundary part λ_j w_j (1/ρ0) Σ_b ψ_b ∇W(x_j − x_b). So the part u_{j,o} of the displacement
//! x_j − s_j that the particles of body o caused follows the same recurrence, with those terms
//! alone as its source; it is carried along the iteration in one slot per fluid particle and
//! body in reach. The body's load is the opposite of the momentum it gave the fluid:
//! F_o = −(m/Δt²) Σ_j u_{j,o}, its moment about the origin Σ_j x_j × f_{j,o} (each pair force
//! lies on the line through the two particles, so x_j is as good an arm as x_b). The walls and
//! obstacles take the rest of what the fluid exchanged, K − Σ_o F_o with
//! K = −(m/Δt²) Σ_j (x_j − s_j).
//!
//! Slots are listed in particle order and summed in blocks of fixed size in block order, so
//! the loads do not depend on the thread count. Their storage is kept from step to step and
//! grown fallibly as a step starts, so that a step short of memory for it fails before it
//! moves the fluid (docs/method.md §1.3).

use super::search::Prediction;
use crate::Vec3;
use crate::boundary::Boundary;
use crate::constraint::{Corrections, DensityConstraint, Projection};
use crate::neighbors::NeighborLists;
use crate::reserve::reserve_total;
use crate::solver::Chebyshev;
use rayon::prelude::*;
use std::collections::TryReserveError;

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

/// The bodies' share of the fluid's displacement, per fluid particle and body in reach, at
/// the last three iterates of the outer iteration (m).
#[derive(Clone, Debug, Default)]
pub(crate) struct Coupling {
    /// The fluid particle of each slot.
    particle: Vec<u32>,
    /// The body of each slot.
    owner: Vec<u32>,
    /// (1/ρ0) Σ_b ψ_b ∇W(s_j − x_b) over the owner's particles b near the slot's particle j,
    /// at the prediction s (1/m): the step moves the fluid far less than a kernel radius, so
    /// the boundary's part of ∇C_j is taken once per step.
    gradient: Vec<Vec3>,
    /// The same over all boundary particles near j (1/m).
    all: Vec<Vec3>,
    /// Δt²k n_j / Â_jj (dimensionless): how much of the share the global step keeps.
    keep: Vec<f64>,
    /// Δt²k w_j / Â_jj (dimensionless): the factor of the boundary's correction λ_j·g that
    /// the global step adds to the share.
    gain: Vec<f64>,
    /// The shares at X^(k−1), X^(k) and X^(k+1) (m).
    previous: Vec<Vec3>,
    current: Vec<Vec3>,
    next: Vec<Vec3>,
    /// The number of bodies.
    bodies: usize,
    /// The number of slots of each fluid particle (scratch of [`Coupling::start`]).
    counts: Vec<u32>,
    /// Every block's sums of the bodies' loads (scratch of [`Coupling::loads`]).
    partial: Vec<Load>,
    /// Every block's sum of the fluid's exchanged momentum and moment (scratch of
    /// [`Coupling::loads`]).
    exchanged: Vec<Load>,
}

/// What one update of the shares reads: the local step's projections made at `x` = X^(k).
pub(super) struct Iterate<'a> {
    pub constraint: &'a DensityConstraint,
    pub fluid_lists: &'a NeighborLists,
    /// X^(k) (m).
    pub x: &'a [Vec3],
    pub projections: &'a [Projection],
    /// The projections' first λ.
    pub corrections: &'a Corrections,
    /// Projection weights w_j.
    pub weights: &'a [f64],
    /// Chebyshev's recurrence and weight ω, when the step's extrapolation changes the iterate.
    pub chebyshev: Option<(&'a Chebyshev, f64)>,
}

impl Coupling {
    /// Starts a step at the prediction `s` (m): one slot, set to zero, for every fluid
    /// particle and every body with a boundary particle in its reach. Makes room for
    /// everything the step's coupling and loads keep, reusing the last step's storage;
    /// errors when that memory cannot be had (the caller undoes the step).
    pub fn start(
        &mut self,
        constraint: &DensityConstraint,
        boundary: &Boundary,
        boundary_lists: &NeighborLists,
        s: &[Vec3],
        bodies: usize,
    ) -> Result<(), TryReserveError> {
        self.bodies = bodies;
        let particles = boundary_lists.len();
        let owner_of = |k: u32| (boundary.owner[k as usize] as usize).min(bodies) as u32;
        // Most particles near a boundary touch only walls: they get no slot (the walls' load
        // is what the bodies leave of the fluid's momentum balance).
        self.counts.clear();
        reserve_total(&mut self.counts, particles)?;
        self.counts.resize(particles, 0);
        self.counts
            .par_iter_mut()
            .enumerate()
            .for_each(|(j, count)| {
                *count = owners_near(boundary_lists.of(j), owner_of, bodies).count() as u32;
            });
        let slots: usize = self.counts.iter().map(|&c| c as usize).sum();
        for v in [&mut self.particle, &mut self.owner] {
            v.clear();
            reserve_total(v, slots)?;
        }
        for v in [
            &mut self.gradient,
            &mut self.all,
            &mut self.previous,
            &mut self.current,
            &mut self.next,
        ] {
            v.clear();
            reserve_total(v, slots)?;
        }
        for v in [&mut self.keep, &mut self.gain] {
            v.clear();
            reserve_total(v, slots)?;
        }
        self.partial.clear();
        reserve_total(&mut self.partial, slots.div_ceil(BLOCK) * bodies)?;
        self.exchanged.clear();
        reserve_total(&mut self.exchanged, particles.div_ceil(BLOCK))?;
        // Slots in particle order; `owner` holds each slot's rank among its particle's
        // bodies until the slot is filled.
        for (j, &count) in self.counts.iter().enumerate() {
            for rank in 0..count {
                self.particle.push(j as u32);
                self.owner.push(rank);
            }
        }
        self.gradient.resize(slots, Vec3::zeros());
        self.all.resize(slots, Vec3::zeros());
        self.owner
            .par_iter_mut()
            .zip(self.gradient.par_iter_mut())
            .zip(self.all.par_iter_mut())
            .zip(self.particle.par_iter())
            .for_each(|(((owner, g), all), &j)| {
                let j = j as usize;
                let near = boundary_lists.of(j);
                let gradient = |k: u32| {
                    let k = k as usize;
                    constraint.kernel.grad_w(&(s[j] - boundary.positions.at(k)))
                        * (boundary.psi[k] / constraint.rest_density)
                };
                let o = owners_near(near, owner_of, bodies)
                    .nth(*owner as usize)
                    .expect("every slot's rank is below its particle's count of bodies");
                *owner = o;
                *g = near
                    .iter()
                    .filter(|&&k| owner_of(k) == o)
                    .map(|&k| gradient(k))
                    .sum();
                *all = near.iter().map(|&k| gradient(k)).sum();
            });
        for u in [&mut self.previous, &mut self.current, &mut self.next] {
            u.resize(slots, Vec3::zeros());
        }
        Ok(())
    }

    /// Takes the global step's coefficients Δt²k n_j/Â_jj and Δt²k w_j/Â_jj for every slot,
    /// once the step's system (`diagonal` Â_jj, kg) and projection `weights` are set up;
    /// `dt2k` is Δt²k (kg). Allocates nothing: [`Coupling::start`] made the room.
    pub(super) fn prepare(
        &mut self,
        constraint: &DensityConstraint,
        fluid_lists: &NeighborLists,
        weights: &[f64],
        diagonal: &[f64],
        dt2k: f64,
    ) {
        self.keep.clear();
        self.gain.clear();
        for &j in &self.particle {
            let j = j as usize;
            let scale = dt2k / diagonal[j];
            self.keep
                .push(constraint.membership(fluid_lists, j) * scale);
            let correction = constraint.correction_scale(fluid_lists, j);
            self.gain.push(weights[j] * correction * scale);
        }
    }

    /// Forgets the outer iterations followed so far, for an iteration that starts over from
    /// the prediction (the shares at X^(0) = X^(−1) = s are zero).
    pub(super) fn restart(&mut self) {
        for u in [&mut self.previous, &mut self.current, &mut self.next] {
            u.fill(Vec3::zeros());
        }
    }

    /// Follows one outer iteration: the shares at X^(k+1) from those at X^(k) and X^(k−1)
    /// and the boundary's corrections at X^(k).
    pub(super) fn update(&mut self, it: &Iterate) {
        let (current, previous) = (&self.current, &self.previous);
        self.next.par_iter_mut().enumerate().for_each(|(s, next)| {
            let j = self.particle[s] as usize;
            let lambda = it.multiplier(j, &self.all[s]);
            let plain = current[s] * self.keep[s] + self.gradient[s] * (self.gain[s] * lambda);
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

    /// The loads of the step that moved the fluid from the prediction `s` to `x` (m) with
    /// step size `dt` (s), for particles of masses `masses` (kg, in the fluid's order):
    /// `out[o]` for body o, and `out[bodies]` for the walls and obstacles, which take the
    /// rest of the momentum the fluid exchanged in the step, K = −Σ_j (m_j/Δt²)(x_j − s_j),
    /// and of its moment.
    pub(super) fn loads(
        &mut self,
        masses: &[f64],
        s: &Prediction,
        x: &[Vec3],
        dt: f64,
        out: &mut Vec<Load>,
    ) {
        let dt2 = dt * dt;
        let bodies = self.bodies;
        let (particle, owner) = (&self.particle, &self.owner);
        // The room for the sums was made by `start` (and for `out` before the step).
        self.partial.clear();
        self.partial
            .resize(self.current.len().div_ceil(BLOCK) * bodies, Load::default());
        self.partial
            .par_chunks_mut(bodies.max(1))
            .zip(self.current.par_chunks(BLOCK))
            .enumerate()
            .for_each(|(block, (sums, shares))| {
                for (slot, u) in (block * BLOCK..).zip(shares) {
                    let i = particle[slot] as usize;
                    let force = u * (-masses[i] / dt2);
                    let arm = x[i];
                    sums[owner[slot] as usize].add(&Load {
                        force,
                        moment: arm.cross(&force),
                    });
                }
            });
        self.exchanged.clear();
        self.exchanged
            .resize(x.len().div_ceil(BLOCK), Load::default());
        self.exchanged
            .par_iter_mut()
            .zip(x.par_chunks(BLOCK))
            .enumerate()
            .for_each(|(block, (sum, xs))| {
                for (j, xj) in (block * BLOCK..).zip(xs) {
                    let force = (xj - s.at(j)) * (-masses[j] / dt2);
                    sum.add(&Load {
                        force,
                        moment: xj.cross(&force),
                    });
                }
            });
        out.clear();
        out.resize(bodies + 1, Load::default());
        for sums in self.partial.chunks(bodies.max(1)) {
            for (o, s) in out.iter_mut().zip(sums) {
                o.add(s);
            }
        }
        let mut walls = Load::default();
        for e in &self.exchanged {
            walls.add(e);
        }
        for body in &out[..bodies] {
            walls.force -= body.force;
            walls.moment -= body.moment;
        }
        out[bodies] = walls;
    }
}

/// The bodies (those below `bodies`; `owner_of` gives a boundary particle's owner, `bodies`
/// for walls and obstacles) that own a particle of `near`, ascending, each once: one pass
/// over `near` per body, and no storage.
fn owners_near(
    near: &[u32],
    owner_of: impl Fn(u32) -> u32,
    bodies: usize,
) -> impl Iterator<Item = u32> {
    let after = move |last: Option<u32>| {
        near.iter()
            .map(|&k| owner_of(k))
            .filter(|&o| (o as usize) < bodies && last.is_none_or(|last| o > last))
            .min()
    };
    std::iter::successors(after(None), move |&o| after(Some(o)))
}

impl Iterate<'_> {
    /// λ_j of constraint j's projection at X^(k) (m²; 0 when inactive): the boundary particles
    /// of an owner corrected particle j by λ_j w_j g, g = (1/ρ0) Σ_b ψ_b ∇W(x_j − x_b) over
    /// them. `all` is g over every boundary particle near j (1/m).
    fn multiplier(&self, j: usize, all: &Vec3) -> f64 {
        let p = &self.projections[j];
        if !p.materialized {
            return self.corrections.lambda(j);
        }
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
        let g2 = gradient.norm_squared() * self.weights[j];
        if g2 == 0.0 {
            return 0.0;
        }
        p.self_correction.dot(&gradient) / g2
    }
}
