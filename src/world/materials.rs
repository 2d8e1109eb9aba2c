//! Materials in a world (docs/method.md §14): adding them, choosing the one that fluid added
//! next is made of, and reading every particle's.

use super::World;
use crate::Error;
use crate::forces;
use crate::material::{Material, MaterialId};

impl World {
    /// Adds a fluid material and returns its id (1 for the first added: 0 is the world's own
    /// fluid, of [`crate::Params::rest_density`]). Fluid of it is added after
    /// [`World::set_fluid_material`] chooses it. Errors, changing nothing, on a rest density
    /// that is not finite or lies outside [`crate::material::DENSITY_RATIO_RANGE`] times the
    /// world's, or on more than [`crate::material::MAX_MATERIALS`] materials.
    ///
    /// A material with a kinematic viscosity brings the implicit viscosity solve into the
    /// step (docs/method.md §13), on either backend.
    ///
    /// A material with a surface tension brings the surface force into the step
    /// (docs/method.md §17), which the GPU backend refuses.
    pub fn add_material(&mut self, material: Material) -> Result<MaterialId, Error> {
        if material.surface_tension > 0.0 {
            self.refuse_on_gpu(super::backend::SURFACE_TENSION)?;
        }
        let id = self.materials.add(material, self.params.rest_density)?;
        self.update_forces();
        Ok(id)
    }

    /// Sets the kinematic viscosity ν (m²/s) of material `id` (0 is the world's own fluid,
    /// whose [`crate::Params::kinematic_viscosity`] follows), from the next step on. Errors,
    /// changing nothing, on an id the world has no material for or a viscosity that is
    /// negative or not finite.
    pub fn set_material_kinematic_viscosity(
        &mut self,
        id: MaterialId,
        nu: f64,
    ) -> Result<(), Error> {
        self.materials.set_viscosity(id, nu)?;
        if id == 0 {
            self.params.kinematic_viscosity = nu;
        }
        self.update_forces();
        Ok(())
    }

    /// Sets the surface tension σ (N/m) of material `id` (0 is the world's own fluid, whose
    /// [`crate::Params::surface_tension`] follows), from the next step on. Errors, changing
    /// nothing, on an id the world has no material for, a surface tension that is negative or
    /// not finite, or a surface tension on a world that steps on the GPU, which does not
    /// support it yet.
    pub fn set_material_surface_tension(
        &mut self,
        id: MaterialId,
        sigma: f64,
    ) -> Result<(), Error> {
        if sigma > 0.0 {
            self.refuse_on_gpu(super::backend::SURFACE_TENSION)?;
        }
        self.materials.set_surface_tension(id, sigma)?;
        if id == 0 {
            self.params.surface_tension = sigma;
        }
        self.update_forces();
        Ok(())
    }

    /// Makes the non-pressure forces again, as the materials now ask for them (the
    /// viscosity solve where any has a viscosity); their buffers are reserved before the
    /// next step.
    fn update_forces(&mut self) {
        self.forces = forces::of_world(&self.params, &self.materials);
    }

    /// Chooses the material of the fluid added from now on: by [`World::add_fluid_block`],
    /// [`World::add_fluid_particles`] and the emitters added from now on
    /// ([`World::add_emitter`]). Errors, changing nothing, on an id the world has no
    /// material for.
    pub fn set_fluid_material(&mut self, material: MaterialId) -> Result<(), Error> {
        self.materials.check_id("material", material)?;
        self.materials.current = material;
        Ok(())
    }

    /// The material the fluid added next is made of (0, the world's own fluid, until
    /// [`World::set_fluid_material`] chooses another).
    pub fn fluid_material(&self) -> MaterialId {
        self.materials.current
    }

    /// Material `id`, if the world has it.
    pub fn material(&self, id: MaterialId) -> Option<Material> {
        self.materials.get(id, self.params.rest_density)
    }

    /// Number of materials, the world's own fluid included.
    pub fn material_count(&self) -> usize {
        self.materials.len()
    }

    /// Every fluid particle's material, in ascending id order (see [`World::ids`]).
    pub fn particle_materials(&self) -> Vec<MaterialId> {
        let mut out = vec![0; self.fluid_count()];
        self.gather_by_id(&self.fluid.materials, &mut out);
        out
    }

    /// Writes every fluid particle's material into `out[..n]` in ascending id order,
    /// n = [`World::fluid_count`], without allocating; `Err(n)` when `out` is shorter.
    pub fn write_materials(&self, out: &mut [MaterialId]) -> Result<(), usize> {
        let n = self.fluid_count();
        let out = out.get_mut(..n).ok_or(n)?;
        self.gather_by_id(&self.fluid.materials, out);
        Ok(())
    }
}
