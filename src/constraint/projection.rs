//! The local step: every constraint projected by Newton-like steps on a private copy of its
//! stencil (docs/method.md §2.5), and what each projection produced ([`Projection`]).

use super::gather::Corrections;
use super::stencil::{Members, SCRATCH, Scratch};
use super::{
    CHUNK, CONSTRAINT_GOAL, DensityConstraint, MAX_PROJECTION_STEPS, NEWTON_STEP_LIMIT,
    Neighborhood, REGULARIZATION,
};
use crate::Vec3;
use crate::neighbors::par_segments_zip_mut;
use crate::reserve::reserve_total;
use rayon::prelude::*;
use std::collections::TryReserveError;

/// What the local step of one constraint produced, besides the λ of its first step (kept in
/// [`Corrections`], [`Corrections::lambda`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Projection {
    /// The correction of the constraint's own particle, P_{i,i} − x_i (m).
    pub self_correction: Vec3,
    /// The neighbours' corrections were written out (multi-step projection), to the segment
    /// of [`Corrections`] that starts at `segment`.
    pub materialized: bool,
    /// Start of this constraint's segment in [`Corrections`] (meaningful when `materialized`).
    pub segment: u32,
    /// ρ_i at the iterate, before any correction (kg/m³): the density the constraint was
    /// evaluated at, which the density stopping rule reads (docs/method.md §4).
    pub density: f64,
}

impl DensityConstraint {
    /// The local step: projects every constraint i at the iterate `x`. Single-step projections
    /// (the usual case) keep only λ_i; longer ones write their stencil corrections
    /// P_{i,j} − x_j (m) into `corrections`: once all constraints are projected, the few
    /// multi-step ones are projected again into segments sized for them alone (a projection
    /// is a pure function of `x`, so the second pass repeats the first bit for bit).
    ///
    /// Errors when memory for the projections or the kept segments cannot be had; the
    /// projections and corrections are then incomplete (a step that fails is undone). The
    /// per-thread buffers grow as a stencil needs, within the room a time step reserves for
    /// its largest stencil before it projects.
    pub fn project(
        &self,
        x: &[Vec3],
        nb: &Neighborhood,
        projections: &mut Vec<Projection>,
        corrections: &mut Corrections,
    ) -> Result<(), TryReserveError> {
        let c = corrections;
        reserve_total(projections, x.len())?;
        reserve_total(&mut c.lambdas, x.len())?;
        reserve_total(&mut c.moved, x.len())?;
        projections.resize(x.len(), Projection::default());
        c.lambdas.resize(x.len(), 0.0);
        c.moved.resize(x.len(), 0);
        let kept = projections
            .par_chunks_mut(CHUNK)
            .zip(c.lambdas.par_chunks_mut(CHUNK))
            .zip(c.moved.par_chunks_mut(CHUNK))
            .enumerate()
            .map(|(chunk, ((outs, lambdas), moved))| {
                SCRATCH.with_borrow_mut(|scratch| {
                    // Corrections written here are dropped; the buffer only grows.
                    let mut dp = std::mem::take(&mut scratch.dp);
                    let mut kept = 0;
                    for (k, ((out, lambda), moved)) in
                        outs.iter_mut().zip(lambdas).zip(moved).enumerate()
                    {
                        let i = chunk * CHUNK + k;
                        let members = nb.fluid.count(i) + 1;
                        if dp.len() < members {
                            dp.resize(members, Vec3::zeros());
                        }
                        *lambda = self.project_one(i, x, nb, &mut dp[..members], out, scratch);
                        *moved = u8::from(*lambda != 0.0 && !out.materialized);
                        kept += usize::from(out.materialized);
                    }
                    scratch.dp = dp;
                    kept
                })
            })
            .sum::<usize>();

        // The flags were set only if the last local step kept a segment (rarely); only then
        // are they cleared.
        let flags_set = !c.owners.is_empty();
        reserve_total(&mut c.owners, kept)?;
        reserve_total(&mut c.near_kept, projections.len())?;
        reserve_total(&mut c.offsets, kept + 1)?;
        c.owners.clear();
        if kept > 0 {
            // In one pass over the flags, within the room just made.
            c.owners.extend(
                (0..projections.len() as u32).filter(|&i| projections[i as usize].materialized),
            );
        }
        if c.near_kept.len() != projections.len() || flags_set {
            c.near_kept.clear();
            c.near_kept.resize(projections.len(), false);
        }
        for &i in &c.owners {
            for &j in nb.fluid.of(i as usize) {
                c.near_kept[j as usize] = true;
            }
        }
        c.offsets.clear();
        c.offsets.push(0);
        for &i in &c.owners {
            let start = *c.offsets.last().unwrap_or(&0);
            projections[i as usize].segment = start;
            c.offsets
                .push(start + nb.fluid.count(i as usize) as u32 + 1);
        }
        c.data.clear();
        let segments = *c.offsets.last().unwrap_or(&0) as usize;
        // The segments of a strongly compressed fluid can be as large as the neighbour
        // lists, and six times their bytes.
        #[cfg(test)]
        if c.segment_limit.is_some_and(|limit| segments > limit) {
            return Err(crate::reserve::shortage());
        }
        reserve_total(&mut c.data, segments)?;
        c.data.resize(segments, Vec3::zeros());
        par_segments_zip_mut(&c.offsets, &mut c.data, &mut c.owners, |_, dp, &mut i| {
            let mut again = Projection::default();
            SCRATCH.with_borrow_mut(|scratch| {
                self.project_one(i as usize, x, nb, dp, &mut again, scratch)
            });
        })
    }

    /// Σ_j w_j ∇_{x_j} C_i (1/m) over the fluid members j of constraint i's stencil, i
    /// included, at positions `x`: multiplied by k·λ_i (N·m), the force constraint i exerts
    /// on the fluid (docs/method.md §10.1).
    pub(crate) fn weighted_gradient_sum(&self, i: usize, x: &[Vec3], nb: &Neighborhood) -> Vec3 {
        let scale = self.mass / self.rest_density;
        let pi = x[i];
        // ∇_{x_i} C_i gathers the boundary's and the walls' share and minus every member's
        // gradient ∇_{x_j} C_i = −(m/ρ0)∇W(x_i − x_j), as in `gradients`.
        let (grad_i, members) = nb.fluid.of(i).iter().fold(
            (self.boundary_gradient(pi, i, nb), Vec3::zeros()),
            |(grad_i, members), &j| {
                let g = self.kernel.grad_w(&(pi - x[j as usize])) * scale;
                (grad_i + g, members - g * self.weight_of(nb, j as usize))
            },
        );
        grad_i * self.weight_of(nb, i) + members
    }

    /// The boundary's and the walls' share of ∇_{x_i} C_i (1/m) for particle i at `pi`:
    /// (Σ_b ψ_b ∇W(pi − x_b) + the walls built as fields) / ρ0. Wall adhesion pulls along it
    /// (docs/method.md §17.2).
    pub(crate) fn boundary_gradient(&self, pi: Vec3, i: usize, nb: &Neighborhood) -> Vec3 {
        let kernel = &self.kernel;
        (nb.boundary
            .of(i)
            .iter()
            .map(|&b| {
                let b = b as usize;
                kernel.grad_w(&(pi - nb.boundary_positions.at(b))) * nb.boundary_psi[b]
            })
            .sum::<Vec3>()
            + self.walls_at(pi, nb.walls).gradient)
            / self.rest_density
    }

    /// ∇_{p_i} C_i (returned with D = Σ_j |∇_{p_j} C_i|² over the fluid members; boundary
    /// particles are not unknowns); `grads[s]` receives ∇_{p_j} C_i = −(m/ρ0)∇W(p_i − p_j)
    /// for the s-th fluid neighbour at `neighbor(s)`.
    fn gradients(
        &self,
        i: usize,
        pi: Vec3,
        neighbor: impl Fn(usize) -> Vec3,
        nb: &Neighborhood,
        grads: &mut Vec<Vec3>,
    ) -> (Vec3, f64) {
        let kernel = &self.kernel;
        let scale = self.mass / self.rest_density;
        let mut grad_i = self.boundary_gradient(pi, i, nb);
        let mut denominator = 0.0;
        grads.clear();
        for s in 0..nb.fluid.count(i) {
            let g = kernel.grad_w(&(pi - neighbor(s))) * scale;
            grad_i += g;
            denominator += g.norm_squared();
            grads.push(-g);
        }
        (grad_i, denominator + grad_i.norm_squared())
    }

    /// λ of a Newton step after the first, shortened so that no member of the stencil moves
    /// farther than [`NEWTON_STEP_LIMIT`]·H: `own` is particle i's weighted gradient, `grads`
    /// the members' gradients and `w` their weights.
    #[inline(never)]
    fn bounded_newton_step(
        &self,
        lambda: f64,
        own: Vec3,
        grads: &[Vec3],
        w: impl Fn(usize) -> f64,
    ) -> f64 {
        let stride = grads
            .iter()
            .enumerate()
            .map(|(s, g)| g.norm() * w(s))
            .fold(own.norm(), f64::max);
        self.bounded(lambda, stride)
    }

    /// λ of a projection's first Newton step, shortened so that the move the global step
    /// makes of it moves no stencil member farther than [`NEWTON_STEP_LIMIT`]·H: member j's
    /// correction λ·w_j·∇_{x_j}C_i is one of the n_j + 1 the global step averages, so it moves
    /// j by about λ·w_j·|∇_{x_j}C_i|/(n_j + 1). `own` is particle i's weighted gradient and
    /// `members` the members' gradients and weights that [`Self::first_gradients`] left.
    #[inline(always)]
    fn bounded_first_step(
        &self,
        lambda: f64,
        own: Vec3,
        members: &Members,
        i: usize,
        nb: &Neighborhood,
    ) -> f64 {
        let n = members.n;
        let shares = |j: usize| (nb.fluid.count(j) + 1) as f64;
        let limit = NEWTON_STEP_LIMIT * self.kernel.support_radius();
        // w_j/(n_j + 1) ≤ w_j: a bound from the stencil's own arrays decides nearly every
        // projection without reading the members' neighbour counts.
        let largest_g2 = members.values[..n].iter().fold(0.0, |a: f64, &b| a.max(b));
        let largest_w = members.weights[..n].iter().fold(0.0, |a: f64, &b| a.max(b));
        let own_share = own.norm() / shares(i);
        if lambda.abs() * own_share.max(largest_g2.sqrt() * largest_w) <= limit {
            return lambda;
        }
        let stride = members.values[..n]
            .iter()
            .zip(&members.weights[..n])
            .zip(nb.fluid.of(i))
            .map(|((g2, w), &j)| g2.sqrt() * w / shares(j as usize))
            .fold(own.norm() / shares(i), f64::max);
        self.bounded(lambda, stride)
    }

    /// `lambda` shortened so that the member that moves farthest per unit λ (`stride`, m per
    /// m²) moves no farther than [`NEWTON_STEP_LIMIT`]·H.
    #[inline(always)]
    fn bounded(&self, lambda: f64, stride: f64) -> f64 {
        let largest = stride * lambda.abs();
        let limit = NEWTON_STEP_LIMIT * self.kernel.support_radius();
        if largest > limit {
            lambda * (limit / largest)
        } else {
            lambda
        }
    }

    crate::simd::avx2_dispatch! {
        /// Projection of constraint i (docs/method.md §2.5): Newton-like steps on a private
        /// copy p = x + dp of the stencil until C_i(p) ≤ 1e-14; returns the sum of its
        /// steps' λ (m², 0 for an inactive constraint), the multiplier the step carries for
        /// its pressures. A projection that ends after its first step is recorded by that λ
        /// alone; otherwise `dp[0]` (i) and `dp[s + 1]` (s-th neighbour) receive the
        /// corrections. The AVX2 build runs the loops over a stencil's members
        /// four lanes wide, bitwise alike (tested).
        fn project_one / project_one_avx2(
            &self,
            i: usize,
            x: &[Vec3],
            nb: &Neighborhood,
            dp: &mut [Vec3],
            out: &mut Projection,
            scratch: &mut Scratch,
        ) -> f64 where !self.portable => project_one_portable
    }

    /// The body of [`Self::project_one`], inlined into both builds.
    #[inline(always)]
    fn project_one_portable(
        &self,
        i: usize,
        x: &[Vec3],
        nb: &Neighborhood,
        dp: &mut [Vec3],
        out: &mut Projection,
        scratch: &mut Scratch,
    ) -> f64 {
        *out = Projection::default();
        let (mut first_lambda, mut total_lambda) = (0.0, 0.0);
        let members = nb.fluid.of(i);
        let at = |s: usize| x[members[s] as usize];
        let w = |s: usize| self.weight_of(nb, members[s] as usize);
        let mut materialized = false;
        let mut relaxes = false;
        for step in 0..MAX_PROJECTION_STEPS {
            if relaxes {
                // ρ_i after the first step is surely ≤ ρ0: the projection ends here.
                break;
            }
            let pi = x[i] + out.self_correction;
            let rho = match (step, materialized) {
                (0, _) => self.first_density(i, pi, x, nb, scratch),
                (_, true) => self.density_at(i, pi, |s| at(s) + dp[s + 1], nb),
                // After the first step p_j = x_j + λ w_j ∇_{p_j}C_i (λ kept, not written out).
                (_, false) => {
                    self.first_step_density(first_lambda, out.self_correction, nb, scratch)
                }
            };
            if step == 0 {
                out.density = rho;
            }
            let c = (rho / self.rest_density - 1.0).max(0.0);
            if step > 0 && !materialized && (c > CONSTRAINT_GOAL || self.materialize_all) {
                // A second step is needed (or requested): write the first step's corrections out.
                dp[0] = out.self_correction;
                let m = &scratch.members;
                for (s, w) in m.weights[..m.n].iter().enumerate() {
                    dp[s + 1] = m.gradient(s) * (first_lambda * w);
                }
                materialized = true;
            }
            if c <= CONSTRAINT_GOAL {
                break;
            }
            let (grad_i, denominator) = if materialized {
                self.gradients(i, pi, |s| at(s) + dp[s + 1], nb, &mut scratch.grads)
            } else {
                // Only the first step is not materialized: the iterate's offsets are kept.
                self.first_gradients(i, nb, scratch)
            };
            if denominator == 0.0 {
                break;
            }
            let mut lambda = -c / (denominator + REGULARIZATION);
            let w_i = self.weight_of(nb, i);
            lambda = if materialized {
                self.bounded_newton_step(lambda, grad_i * w_i, &scratch.grads, w)
            } else {
                self.bounded_first_step(lambda, grad_i * w_i, &scratch.members, i, nb)
            };
            out.self_correction += grad_i * (lambda * w_i);
            total_lambda += lambda;
            if step == 0 && !self.evaluate_first_step && !self.materialize_all {
                relaxes = self.first_step_surely_relaxes(rho, lambda, grad_i, w_i, scratch);
            }
            if materialized {
                for (s, g) in scratch.grads.iter().enumerate() {
                    dp[s + 1] += g * (lambda * w(s));
                }
                dp[0] = out.self_correction;
            } else {
                first_lambda = lambda;
            }
        }
        out.materialized = materialized;
        total_lambda
    }
}
