//! The fluid's loads on the boundary (docs/method.md §11.3).
//!
//! The distribution over owners comes from the constraint corrections: k·c_{i,j} is the force
//! of constraint i on particle j (N) at the fixed point of the global step, and the part of
//! constraint i's correction of its own centre that stems from the boundary particles in its
//! density is their push on particle i. By the third law each boundary particle b receives
//!
//! r_b = −k · (λ_i w_i) · (ψ_b/ρ0) · ∇W(x_i − x_b),
//!
//! summed over the fluid particles i near it. The scale comes from the fluid's momentum: the
//! iteration stops at τ, before the corrections reach their fixed point, and the neighbour-count
//! weighting does not conserve momentum between fluid particles, so the raw sums miss the
//! momentum the fluid actually exchanged. That momentum is exact: the boundaries together took
//! K = −Σ_i m (x_i^{n+1} − s_i)/Δt² (N) from the fluid in this step. Every raw load is scaled by
//! the one factor α = (K·R)/|R|², R = Σ r_b, so that the loads add up to K along R.
//!
//! Gathered per block of fluid particles of fixed size and summed in block order, so that the
//! result does not depend on the thread count.

use crate::Vec3;
use crate::boundary::Boundary;
use crate::constraint::{DensityConstraint, Projection};
use crate::neighbors::{NeighborLists, PointsByComponent};
use rayon::prelude::*;

/// Fluid particles per block of the reduction.
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

/// What the loads are computed from: the last local step's projections, made at `x`.
pub(super) struct Reaction<'a> {
    /// Stiffness k (N/m).
    pub stiffness: f64,
    pub constraint: &'a DensityConstraint,
    pub boundary: &'a Boundary,
    pub fluid_lists: &'a NeighborLists,
    pub boundary_lists: &'a NeighborLists,
    /// The fluid positions the projections were made at, X^(k) (m).
    pub x: &'a [Vec3],
    pub projections: &'a [Projection],
    /// Projection weights w_i.
    pub weights: &'a [f64],
    /// The inertial prediction s (m).
    pub predicted: &'a PointsByComponent,
    /// The positions at the end of the step, x^{n+1} (m).
    pub positions: &'a [Vec3],
    /// Step size (s).
    pub dt: f64,
}

impl Reaction<'_> {
    /// The loads on every owner of boundary particles: `out[o]` for body `o` (o < `bodies`)
    /// and `out[bodies]` for the walls and obstacles.
    pub fn loads(&self, bodies: usize, out: &mut Vec<Load>) {
        let n = self.x.len();
        let mass_per_dt2 = self.constraint.mass / (self.dt * self.dt);
        let partial: Vec<(Vec<Load>, Vec3)> = (0..n.div_ceil(BLOCK))
            .into_par_iter()
            .map(|block| {
                let mut sums = vec![Load::default(); bodies + 1];
                let mut taken = Vec3::zeros();
                for i in block * BLOCK..((block + 1) * BLOCK).min(n) {
                    self.add_particle(i, bodies, &mut sums);
                    taken -= (self.positions[i] - self.predicted.at(i)) * mass_per_dt2;
                }
                (sums, taken)
            })
            .collect();
        out.clear();
        out.resize(bodies + 1, Load::default());
        let mut taken = Vec3::zeros();
        for (sums, t) in &partial {
            for (o, s) in out.iter_mut().zip(sums) {
                o.add(s);
            }
            taken += t;
        }
        let raw = out.iter().fold(Vec3::zeros(), |r, l| r + l.force);
        let r2 = raw.norm_squared();
        let alpha = if r2 > 0.0 {
            (taken.dot(&raw) / r2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        for load in out.iter_mut() {
            load.force *= alpha;
            load.moment *= alpha;
        }
    }

    /// Adds the reaction to constraint i's projection to `sums`: the net correction the
    /// constraint gave its fluid members, k λ_i Σ_m w_m ∇_{x_m}C_i (N), taken by the boundary
    /// particles in its density, each in proportion to ψ_b |∇W(x_i − x_b)|.
    fn add_particle(&self, i: usize, bodies: usize, sums: &mut [Load]) {
        let near = self.boundary_lists.of(i);
        let p = &self.projections[i];
        if near.is_empty() || p.self_correction == Vec3::zeros() {
            return;
        }
        let c = self.constraint;
        let b = self.boundary;
        let xi = self.x[i];
        let w_i = self.weights[i];
        let (centre, members) = self.gradients(i);
        let lambda = if p.materialized {
            // Several projection steps: the multiplier that gives the whole correction of the
            // centre along the gradient at x.
            let g2 = centre.norm_squared() * w_i;
            if g2 == 0.0 {
                return;
            }
            p.self_correction.dot(&centre) / g2
        } else {
            p.lambda
        };
        let net = (centre * w_i + members) * (self.stiffness * lambda);
        let share = |k: u32| {
            let k = k as usize;
            b.psi[k] * c.kernel.grad_w(&(xi - b.positions[k])).norm()
        };
        let total: f64 = near.iter().map(|&k| share(k)).sum();
        if total == 0.0 {
            return;
        }
        for &k in near {
            let f = -net * (share(k) / total);
            let xb = b.positions[k as usize];
            let owner = (b.owner[k as usize] as usize).min(bodies);
            sums[owner].add(&Load {
                force: f,
                moment: xb.cross(&f),
            });
        }
    }

    /// ∇_{x_i} C_i at x (1/m, docs/method.md §2.4) and Σ_j w_j ∇_{x_j} C_i over the fluid
    /// neighbours j (1/m).
    fn gradients(&self, i: usize) -> (Vec3, Vec3) {
        let c = self.constraint;
        let xi = self.x[i];
        let (mut fluid, mut members) = (Vec3::zeros(), Vec3::zeros());
        for &j in self.fluid_lists.of(i) {
            let g = c.kernel.grad_w(&(xi - self.x[j as usize])) * c.mass;
            fluid += g;
            members -= g * self.weights[j as usize];
        }
        let b = self.boundary;
        let walls: Vec3 = self
            .boundary_lists
            .of(i)
            .iter()
            .map(|&k| c.kernel.grad_w(&(xi - b.positions[k as usize])) * b.psi[k as usize])
            .sum();
        ((fluid + walls) / c.rest_density, members / c.rest_density)
    }
}
