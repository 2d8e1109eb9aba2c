//! Checks of [`Params`]: every field in its range; errors name the field and its value.

use super::{MAX_VORTICITY_CONFINEMENT, Params, check_step};
use crate::Error;

impl Params {
    /// Checks every field; the error names the first bad field and its value.
    pub fn validate(&self) -> Result<(), Error> {
        let positive = [
            ("particle_radius", self.particle_radius),
            ("rest_density", self.rest_density),
            ("mass_factor", self.mass_factor),
            ("stiffness", self.stiffness),
            ("displacement_tolerance", self.displacement_tolerance),
            ("cfl_factor", self.cfl_factor),
        ];
        for (name, value) in positive {
            if !(value.is_finite() && value > 0.0) {
                return Err(Error::invalid(
                    name,
                    value,
                    "must be a positive finite number",
                ));
            }
        }
        for (name, dt) in [
            ("dt_min", self.dt_min),
            ("dt_max", self.dt_max),
            ("dt_initial", self.dt_initial),
        ] {
            check_step(name, dt)?;
        }
        let mass = self.particle_mass();
        if !(mass.is_finite() && mass > 0.0) {
            return Err(Error::invalid(
                "particle_radius",
                self.particle_radius,
                &format!(
                    "gives a particle mass of {mass} kg with this rest density and mass factor; it must be positive and finite"
                ),
            ));
        }
        for (axis, g) in self.gravity.iter().enumerate() {
            if !g.is_finite() {
                return Err(Error::invalid(
                    format!("gravity[{axis}]"),
                    g,
                    "must be finite",
                ));
            }
        }
        if self.dt_min > self.dt_max {
            return Err(Error::invalid(
                "dt_min",
                self.dt_min,
                "must not exceed dt_max",
            ));
        }
        if !(self.viscosity.is_finite() && (0.0..=1.0).contains(&self.viscosity)) {
            return Err(Error::invalid(
                "viscosity",
                self.viscosity,
                "must lie in [0, 1]",
            ));
        }
        crate::material::check_viscosity(self.kinematic_viscosity)?;
        crate::material::check_surface_tension(self.surface_tension)?;
        let most = 2.0 * crate::material::MAX_SURFACE_TENSION;
        crate::material::check_coefficient("wall_adhesion", self.wall_adhesion, most)?;
        if !(self.vorticity_confinement.is_finite()
            && (0.0..=MAX_VORTICITY_CONFINEMENT).contains(&self.vorticity_confinement))
        {
            return Err(Error::invalid(
                "vorticity_confinement",
                self.vorticity_confinement,
                &format!("must lie in [0, {MAX_VORTICITY_CONFINEMENT}] (0 turns it off)"),
            ));
        }
        if !(self.density_tolerance.is_finite() && (0.0..1.0).contains(&self.density_tolerance)) {
            return Err(Error::invalid(
                "density_tolerance",
                self.density_tolerance,
                "must lie in [0, 1) (0 turns the density rule off)",
            ));
        }
        if !(self.warm_start.is_finite() && (0.0..1.0).contains(&self.warm_start)) {
            return Err(Error::invalid(
                "warm_start",
                self.warm_start,
                "must lie in [0, 1) (0 starts every step from its prediction)",
            ));
        }
        let c = &self.chebyshev;
        if !(c.rho.is_finite() && (0.0..1.0).contains(&c.rho)) {
            return Err(Error::invalid("rho", c.rho, "must lie in [0, 1)"));
        }
        if c.delay < 1 {
            return Err(Error::invalid("delay", c.delay, "must be at least 1"));
        }
        if !(c.gamma.is_finite() && c.gamma > 0.0 && c.gamma <= 1.0) {
            return Err(Error::invalid("gamma", c.gamma, "must lie in (0, 1]"));
        }
        if self.min_outer_iterations < 1 {
            let n = self.min_outer_iterations;
            return Err(Error::invalid(
                "min_outer_iterations",
                n,
                "must be at least 1",
            ));
        }
        if self.max_outer_iterations < self.min_outer_iterations
            || self.max_outer_iterations > 100_000
        {
            let n = self.max_outer_iterations;
            return Err(Error::invalid(
                "max_outer_iterations",
                n,
                "must lie between min_outer_iterations and 100000",
            ));
        }
        if self.threads > 1024 {
            return Err(Error::invalid(
                "threads",
                self.threads,
                "must be at most 1024",
            ));
        }
        Ok(())
    }
}
