//! The outer local/global iteration of a step (docs/method.md §1.3, §3, §4): the system
//! matrix of formulation F1 frozen for the step, then local projections and global solves
//! from X^(0) = X^(−1) = s or its warm start (§4.1, withdrawn where the fluid does not need
//! it), with Chebyshev's extrapolation, until
//! the fluid's average compression is at most η (once no particle moves farther than 10τ)
//! or no particle moved farther than τ; a step whose extrapolation reaches K_max starts
//! over from s without it.

use super::search::Prediction;
use super::{StepBuffers, carry, coarse, couple, warm_start};
use crate::boundary::Boundary;
use crate::constraint::{CHUNK, DensityConstraint, Neighborhood, Projection, weigh_by_inertia};
use crate::fluid::Fluid;
use crate::params::{Params, SolverKind};
use crate::solver::{Chebyshev, GlobalSolver, Sweep};
use crate::stats::StepTimings;
use crate::{Vec3, reduce};
use rayon::prelude::*;
use std::collections::TryReserveError;
use std::time::Instant;

/// The density rule also waits until the last outer iteration moved no particle farther
/// than this multiple of τ: a few particles still moving fast (a splash particle being pushed
/// back out of a wall) keep the iteration going, though they hardly change the average
/// (docs/method.md §4).
pub(crate) const DENSITY_RULE_MOTION: f64 = 10.0;

/// What the iteration reads besides the buffers.
pub(super) struct Iteration<'a> {
    pub params: &'a Params,
    pub constraint: &'a DensityConstraint,
    pub boundary: &'a Boundary,
    /// The fluid as the step found it, in its order from before the step's sort.
    pub fluid: &'a Fluid,
    /// g (m/s²).
    pub gravity: Vec3,
    pub solver: &'a mut dyn GlobalSolver,
    pub chebyshev: &'a mut Chebyshev,
    /// Step size (s).
    pub dt: f64,
    /// Follow the boundary's share of the displacement in `b.coupling` (worlds with bodies).
    pub couple: bool,
    /// Start from the warm start rather than from s (docs/method.md §4.1).
    pub warm: bool,
    /// Correct the start on the coarse lattice (docs/method.md §3.8).
    pub coarse: bool,
}

/// How the iteration ended.
pub(super) struct Outcome {
    /// Outer iterations taken.
    pub outer: usize,
    /// Inner iterations of the linear solver, summed over the outer ones.
    pub inner: usize,
    /// Largest displacement of the last outer iteration (m).
    pub displacement: f64,
    /// Chebyshev's ρ_c in this step (0 without extrapolation).
    pub rho: f64,
    /// A stopping rule held (rather than the iteration limit).
    pub converged: bool,
    /// The density rule stopped the iteration after a local step, whose densities at
    /// X^(k) are in `b.projections` (docs/method.md §4).
    pub densities_known: bool,
}

/// Iterates until the density rule, the displacement rule or the iteration limit stops; the
/// result X^(k) is left in `b.current`. Adds the local and global times to `timings`.
/// Errors when the solver's factorisation or a local step's kept corrections need more
/// memory than can be had (the caller undoes the step).
pub(super) fn iterate(
    it: Iteration,
    b: &mut StepBuffers,
    timings: &mut StepTimings,
) -> Result<Outcome, TryReserveError> {
    let Iteration {
        params,
        constraint,
        boundary,
        fluid,
        gravity,
        solver,
        chebyshev,
        dt,
        couple,
        warm,
        coarse,
    } = it;
    // The system matrix of formulation F1, frozen for the step. Every row is written for the
    // world's particle mass m: a material's mass ratio scales a row's inertia and constraint
    // terms alike, so it cancels here and acts through the projections' weights below
    // (docs/method.md §14).
    let mass = constraint.mass;
    let dt2k = dt * dt * params.stiffness;
    let lists = &b.fluid_lists;
    b.system.diagonal.resize(lists.len(), 0.0);
    b.system
        .diagonal
        .par_iter_mut()
        .enumerate()
        .for_each(|(j, a)| *a = mass + dt2k * constraint.membership(lists, j));
    solver.prepare(&b.system)?;

    // The fluid holds one support per particle once a step with the warm start recorded
    // them (none before: the iteration then starts from s).
    b.start_offsets.clear();
    if warm && fluid.supports.len() == fluid.len() {
        let (share, reach) = (params.warm_start, params.particle_radius);
        let (x, offsets) = (&mut b.current, &mut b.start_offsets);
        warm_start::start(x, offsets, &fluid.supports, &b.order, share, dt, reach)?;
    }
    b.previous.clone_from(&b.current);
    constraint.weights(&b.fluid_lists, &mut b.weights);
    if b.masses.iter().any(|&m| m != mass) {
        let masses = &b.masses;
        weigh_by_inertia(&mut b.weights, mass, |j| masses[j]);
    }
    let nb = Neighborhood {
        fluid: &b.fluid_lists,
        boundary: &b.boundary_lists,
        boundary_positions: &boundary.positions,
        boundary_psi: &boundary.psi,
        weights: &b.weights,
        walls: &boundary.walls,
    };
    chebyshev.reset();
    b.coarse.start_step();
    b.carry.start(b.current.len())?;
    if !b.start_offsets.is_empty() {
        b.carry.abandon();
    }
    let mut accelerate = params.solver == SolverKind::Chebyshev;
    // The ρ_c the step extrapolates with (reported also where it falls back).
    let rho = if accelerate { chebyshev.rho() } else { 0.0 };
    let single_sweep = solver.single_diagonal_sweep();
    // The density rule, at the densities of a local step (the motion of the last outer
    // iteration is `displacement`, passed in).
    let density_rule = |displacement: f64, projections: &[Projection]| {
        displacement < DENSITY_RULE_MOTION * params.displacement_tolerance
            && average_compression(constraint, projections) <= params.density_tolerance
    };
    let (mut outer, mut inner, mut displacement) = (0, 0, f64::INFINITY);
    let (mut converged, mut densities_known) = (false, false);
    // The outer iterations of the current pass (the second, if any, is the fallback).
    let mut k = 0;
    b.displacements.clear();
    if couple {
        let (lists, diagonal) = (&b.fluid_lists, &b.system.diagonal);
        b.coupling
            .prepare(constraint, lists, &b.weights, diagonal, dt2k);
    }
    loop {
        if k == params.max_outer_iterations {
            // A fixed count (K_min = K_max, as ρ sweeps ask for) ends here too.
            if !accelerate || params.min_outer_iterations >= params.max_outer_iterations {
                break;
            }
            // The extrapolation reached K_max without a rule holding: the step starts over
            // from s without it, for at most K_max more (docs/method.md §4, "Fallback").
            let predicted = Prediction::new(fluid, Some(&b.order), dt, gravity);
            b.current
                .par_iter_mut()
                .enumerate()
                .for_each(|(j, x)| *x = predicted.at(j));
            b.previous.clone_from(&b.current);
            b.start_offsets.clear();
            if couple {
                b.coupling.restart();
            }
            b.carry.restart();
            // The online estimate learns from the extrapolated pass before it is dropped.
            chebyshev.finish_step(&b.displacements);
            (accelerate, k, displacement) = (false, 0, f64::INFINITY);
            b.displacements.clear();
        }
        let t = Instant::now();
        constraint.project(&b.current, &nb, &mut b.projections, &mut b.corrections)?;
        let mut t_local = t.elapsed().as_secs_f64();
        if coarse
            && k % coarse::PERIOD == 0
            && average_compression(constraint, &b.projections)
                > params.density_tolerance.max(coarse::THRESHOLD)
        {
            // docs/method.md §3.8: the correction moves the start; the local step is
            // taken again where it moved it.
            let fluid = coarse::Fluid {
                projections: &b.projections,
                boundary,
                rest_density: constraint.rest_density,
                volume: constraint.mass / constraint.rest_density,
                tolerated: params.density_tolerance.max(coarse::THRESHOLD),
                support_radius: params.support_radius(),
                reach: coarse::REACH * gravity.norm() * dt * dt,
            };
            let (current, previous) = (&mut b.current, &mut b.previous);
            if b.coarse.correct(current, previous, &fluid)? {
                b.carry.abandon();
                constraint.project(&b.current, &nb, &mut b.projections, &mut b.corrections)?;
                t_local = t.elapsed().as_secs_f64();
            }
        }
        if k >= params.min_outer_iterations && density_rule(displacement, &b.projections) {
            // X^(k) is the result, and its densities are known.
            timings.local += t_local;
            (converged, densities_known) = (true, true);
            break;
        }
        let omega = if accelerate {
            chebyshev.next_weight(k)
        } else {
            1.0
        };
        let extrapolation =
            (accelerate && chebyshev.changes(omega)).then_some((&*chebyshev, omega));
        if couple {
            b.coupling.update(&couple::Iterate {
                constraint,
                fluid_lists: &b.fluid_lists,
                x: &b.current,
                projections: &b.projections,
                corrections: &b.corrections,
                weights: &b.weights,
                chebyshev: extrapolation,
            });
        }
        let (projections, corrections) = (&b.projections, &b.corrections);
        let current = &b.current;
        let predicted = Prediction::new(fluid, Some(&b.order), dt, gravity);
        // b_j = m s_j + Δt²k Σ_{i: j∈N̄_i} P_{i,j}, with P_{i,j} = X_j + correction,
        // for the particles of chunk `chunk`.
        let fill_rhs = |chunk: usize, rhs: &mut [Vec3]| {
            let first = chunk * CHUNK;
            constraint.gathered_corrections(first, current, &nb, projections, corrections, rhs);
            for (j, rhs) in (first..).zip(rhs) {
                let members = constraint.membership(lists, j);
                let scale = constraint.correction_scale(lists, j);
                *rhs = predicted.at(j) * mass + (current[j] * members + *rhs * scale) * dt2k;
            }
        };
        if single_sweep {
            let sweep = Sweep {
                diagonal: &b.system.diagonal,
                current,
                chebyshev: extrapolation,
            };
            // The right-hand side lives only as long as its chunk's sweep, and X^(k+1)
            // replaces X^(k−1) in place.
            displacement = b
                .previous
                .par_chunks_mut(CHUNK)
                .enumerate()
                .map(|(chunk, previous)| {
                    let mut rhs = [Vec3::zeros(); CHUNK];
                    let rhs = &mut rhs[..previous.len()];
                    fill_rhs(chunk, rhs);
                    sweep.apply(chunk * CHUNK, rhs, previous)
                })
                .reduce(|| f64::NEG_INFINITY, reduce::nan_max);
            inner += 1;
        } else {
            b.rhs.resize(b.current.len(), Vec3::zeros());
            b.next.resize(b.current.len(), Vec3::zeros());
            b.rhs
                .par_chunks_mut(CHUNK)
                .enumerate()
                .for_each(|(chunk, rhs)| fill_rhs(chunk, rhs));
            b.next.copy_from_slice(&b.current);
            inner += solver.solve(&b.system, &b.rhs, &mut b.next);
            if accelerate {
                chebyshev.extrapolate(omega, &mut b.next, &b.current, &b.previous);
            }
            displacement = max_distance(&b.next, &b.current);
        }
        b.displacements.push(displacement);
        b.carry.advance(&carry::Advance {
            constraint,
            lists: &b.fluid_lists,
            corrections: &b.corrections,
            system: &b.system,
            dt2k,
            chebyshev: extrapolation,
        });

        // Rotate: X^(k−1) ← X^(k) ← X^(k+1) (which the fused sweep left in `previous`).
        std::mem::swap(&mut b.previous, &mut b.current);
        if !single_sweep {
            std::mem::swap(&mut b.current, &mut b.next);
        }
        if !b.start_offsets.is_empty() {
            let (current, previous) = (&mut b.current, &mut b.previous);
            let (offsets, rest) = (&mut b.start_offsets, constraint.rest_density);
            warm_start::release(current, previous, offsets, &b.projections, rest);
        }
        outer += 1;
        k += 1;
        timings.local += t_local;
        timings.global += t.elapsed().as_secs_f64() - t_local;
        if k >= params.min_outer_iterations && displacement < params.displacement_tolerance {
            converged = true;
            break;
        }
    }

    if accelerate {
        chebyshev.finish_step(&b.displacements);
    }
    Ok(Outcome {
        outer,
        inner,
        displacement,
        rho,
        converged,
        densities_known,
    })
}

/// The fluid's average compression at the iterate of the last local step,
/// Σ_i max(ρ_i/ρ0 − 1, 0) / N (dimensionless), the same for any thread count.
fn average_compression(constraint: &DensityConstraint, projections: &[Projection]) -> f64 {
    let rest = constraint.rest_density;
    reduce::sum(projections, |p| (p.density / rest - 1.0).max(0.0)) / projections.len() as f64
}

/// max_i |a_i − b_i| (m).
fn max_distance(a: &[Vec3], b: &[Vec3]) -> f64 {
    reduce::max_over(a.len(), |i| (a[i] - b[i]).norm())
}
