//! Non-pressure forces: what acts on the fluid besides the density constraint (surface
//! tension, the physical viscosity, vorticity confinement and the XSPH filter). They change the velocities after a step's positions are
//! final (docs/method.md §1.3).

use crate::Vec3;
use crate::boundary::Boundary;
use crate::constraint::{DensityConstraint, Neighborhood};
use crate::fluid::Fluid;
use crate::material::Materials;
use crate::params::Params;
use surface_tension::SurfaceTension;
use viscosity::Viscosity;
use vorticity::VorticityConfinement;
use xsph::Xsph;

mod surface_tension;
pub(crate) mod viscosity;
mod vorticity;
mod xsph;

/// What a force reads besides the fluid: the constraint's constants, the step's
/// neighbourhoods (lists found on the prediction), the boundary and the step size.
pub(crate) struct Forcing<'a> {
    pub constraint: &'a DensityConstraint,
    pub nb: &'a Neighborhood<'a>,
    pub boundary: &'a Boundary,
    /// Each material's kinematic viscosity ν (m²/s), indexed by material.
    pub viscosities: &'a [f64],
    /// Step size Δt (s).
    pub dt: f64,
}

/// A force other than pressure, applied to the fluid's velocities at the end of a step.
pub(crate) trait NonPressureForce: Send + Sync + std::fmt::Debug {
    /// Reserves the force's buffers for `particles` fluid particles, so that applying it
    /// allocates nothing; errors when the memory cannot be had. The default has none.
    fn try_reserve(&mut self, _particles: usize) -> Result<(), std::collections::TryReserveError> {
        Ok(())
    }

    /// Changes `fluid.velocities` (m/s) given the final positions and densities and what
    /// `f` holds; `scratch` is a per-particle buffer the force may use.
    fn apply(&mut self, f: &Forcing, fluid: &mut Fluid, scratch: &mut Vec<Vec3>);
}

/// The non-pressure forces that `params` and the `materials` ask for, in the order they
/// apply: surface tension and adhesion where any material has a surface tension or the
/// walls an adhesion, the physical viscosity where any material has one, vorticity
/// confinement and XSPH.
pub(crate) fn of_world(params: &Params, materials: &Materials) -> Vec<Box<dyn NonPressureForce>> {
    let mut forces: Vec<Box<dyn NonPressureForce>> = Vec::new();
    if materials.tense() || params.wall_adhesion > 0.0 {
        forces.push(Box::new(SurfaceTension::new(params, materials)));
    }
    if materials.viscous() {
        forces.push(Box::new(Viscosity::new(params.no_slip)));
    }
    if params.vorticity_confinement > 0.0 {
        let epsilon = params.vorticity_confinement;
        forces.push(Box::new(VorticityConfinement::new(epsilon)));
    }
    if params.viscosity > 0.0 {
        forces.push(Box::new(Xsph::new(params.viscosity)));
    }
    forces
}
