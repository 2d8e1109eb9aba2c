//! XSPH viscosity (docs/method.md §1.3): v_i ← v_i + c Σ_j (m/ρ_j)(v_j − v_i) W_ij, a filter
//! that blends each velocity with its neighbours'.

use super::{Forcing, NonPressureForce};
use crate::Vec3;
use crate::fluid::Fluid;
use rayon::prelude::*;

/// The XSPH filter with coefficient c (dimensionless), with its buffer of volumes.
#[derive(Clone, Debug)]
pub(crate) struct Xsph {
    coefficient: f64,
    /// The volume m/ρ_j of every fluid particle after the step (m³).
    volumes: Vec<f64>,
}

impl Xsph {
    /// The filter with coefficient `c` (> 0).
    pub fn new(c: f64) -> Self {
        Self {
            coefficient: c,
            volumes: Vec::new(),
        }
    }
}

impl NonPressureForce for Xsph {
    fn try_reserve(&mut self, particles: usize) -> Result<(), std::collections::TryReserveError> {
        crate::reserve::reserve_total(&mut self.volumes, particles)
    }

    fn apply(&mut self, f: &Forcing, fluid: &mut Fluid, scratch: &mut Vec<Vec3>) {
        let (constraint, nb) = (f.constraint, f.nb);
        let (c, mass, volumes) = (self.coefficient, constraint.mass, &mut self.volumes);
        volumes.clear();
        volumes.par_extend(fluid.densities.par_iter().map(|rho| mass / rho));
        let state = (&fluid.positions[..], &fluid.velocities[..], &volumes[..]);
        scratch.resize(fluid.velocities.len(), Vec3::zeros());
        scratch
            .par_iter_mut()
            .enumerate()
            .for_each(|(i, out)| *out = constraint.xsph_velocity(c, i, state, nb));
        std::mem::swap(&mut fluid.velocities, scratch);
    }
}
