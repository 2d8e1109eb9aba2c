//! The end of a step (docs/method.md §1.3): velocities from the positions, the new
//! positions, densities at them (kept from the last local step where it evaluated them), the
//! non-pressure forces, and the step's statistics.

use super::StepBuffers;
use super::contain::Containment;
use super::iterate::Outcome;
use crate::boundary::Boundary;
use crate::constraint::{DensityConstraint, Neighborhood};
use crate::fluid::Fluid;
use crate::forces::{Forcing, NonPressureForce};
use crate::reduce;
use crate::stats::{StepStats, StepTimings};
use rayon::prelude::*;
use std::time::Instant;

/// What the end of a step reads besides the fluid and the buffers.
pub(super) struct Finish<'a> {
    pub constraint: &'a DensityConstraint,
    pub boundary: &'a Boundary,
    pub forces: &'a mut [Box<dyn NonPressureForce>],
    /// Each material's kinematic viscosity ν (m²/s).
    pub viscosities: &'a [f64],
    /// Step size (s).
    pub dt: f64,
    /// The containers the fluid is kept inside.
    pub containment: Containment<'a>,
}

/// Moves the fluid to the iteration's result X^(k) (in `b.current`), kept inside its
/// containers (docs/method.md §7), with v = (x^{n+1} − x^n)/Δt, evaluates the densities, applies the non-pressure forces and measures the step.
pub(super) fn finish(
    f: Finish,
    fluid: &mut Fluid,
    b: &mut StepBuffers,
    outcome: Outcome,
    timings: &mut StepTimings,
) -> StepStats {
    let Finish {
        constraint,
        boundary,
        forces,
        viscosities,
        dt,
        containment,
    } = f;
    let t = Instant::now();
    containment.keep_inside(&fluid.positions, &mut b.current);
    fluid
        .velocities
        .par_iter_mut()
        .zip(b.current.par_iter().zip(fluid.positions.par_iter()))
        .for_each(|(v, (new, old))| *v = (new - old) / dt);
    std::mem::swap(&mut fluid.positions, &mut b.current);

    // Densities at the new positions with the step's neighbour lists, then the forces.
    let nb = Neighborhood {
        fluid: &b.fluid_lists,
        boundary: &b.boundary_lists,
        boundary_positions: &boundary.positions,
        boundary_psi: &boundary.psi,
        weights: &b.weights,
        walls: &boundary.walls,
    };
    if outcome.densities_known {
        // The local step that ended the iteration evaluated them at these positions.
        fluid.densities.clear();
        fluid
            .densities
            .par_extend(b.projections.par_iter().map(|p| p.density));
    } else {
        constraint.densities(&fluid.positions, &nb, &mut fluid.densities);
    }
    let forcing = Forcing {
        constraint,
        nb: &nb,
        boundary,
        viscosities,
        dt,
    };
    for force in forces.iter_mut() {
        // X^(k−1) of the finished iteration serves as the forces' scratch.
        force.apply(&forcing, fluid, &mut b.previous);
    }
    let rest = constraint.rest_density;
    let errors = |rho: &f64| (rho / rest - 1.0).max(0.0);
    let n = fluid.densities.len() as f64;
    let density_error_avg = reduce::sum(&fluid.densities, errors) / n;
    let density_error_max = reduce::max(&fluid.densities, errors);
    timings.rest = t.elapsed().as_secs_f64();
    StepStats {
        dt,
        outer_iterations: outcome.outer,
        inner_iterations: outcome.inner,
        hit_max_iterations: !outcome.converged,
        rho: outcome.rho,
        last_displacement: outcome.displacement,
        density_error_avg,
        density_error_max,
        timings: *timings,
    }
}
