//! Non-pressure forces: what acts on the fluid besides the density constraint (viscosity
//! today; surface tension would join here). They change the velocities after a step's
//! positions are final (docs/method.md §1.3).

use crate::Vec3;
use crate::constraint::{DensityConstraint, Neighborhood};
use crate::fluid::Fluid;
use crate::params::Params;
use xsph::Xsph;

mod xsph;

/// A force other than pressure, applied to the fluid's velocities at the end of a step.
pub(crate) trait NonPressureForce: Send + Sync + std::fmt::Debug {
    /// Reserves the force's buffers for `particles` fluid particles, so that applying it
    /// allocates nothing; errors when the memory cannot be had. The default has none.
    fn try_reserve(&mut self, _particles: usize) -> Result<(), std::collections::TryReserveError> {
        Ok(())
    }

    /// Changes `fluid.velocities` (m/s) given the final positions and densities and the
    /// step's neighbourhoods; `scratch` is a per-particle buffer the force may use.
    fn apply(
        &mut self,
        constraint: &DensityConstraint,
        nb: &Neighborhood,
        fluid: &mut Fluid,
        scratch: &mut Vec<Vec3>,
    );
}

/// The non-pressure forces that `params` ask for, in the order they apply.
pub(crate) fn from_params(params: &Params) -> Vec<Box<dyn NonPressureForce>> {
    let mut forces: Vec<Box<dyn NonPressureForce>> = Vec::new();
    if params.viscosity > 0.0 {
        forces.push(Box::new(Xsph::new(params.viscosity)));
    }
    forces
}
