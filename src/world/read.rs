//! Reading a world: particles in ascending id order (the order they were added, removed
//! particles skipped; docs/method.md §12.1), counts, energies, escapes and a digest of the
//! positions, and copies into caller buffers for embedders.

use super::{World, check_finite};
use crate::{Error, Vec3, reduce};

impl World {
    /// Copies a per-particle quantity into `out` in ascending id order.
    pub(super) fn gather_by_id<T: Copy>(&self, values: &[T], out: &mut [T]) {
        for (v, &id) in values.iter().zip(&self.fluid.ids) {
            out[self.fluid.rank(id)] = *v;
        }
    }

    /// The fluid particles' ids in ascending order, the order of every per-particle read
    /// ([`World::positions`] and the others): the order the particles were added, with the
    /// removed ones skipped. Ids are given in the order particles are added, from 0, and
    /// never reused; without removals they are 0..[`World::fluid_count`].
    pub fn ids(&self) -> Vec<u64> {
        self.fluid.ascending.clone()
    }

    /// Fluid positions (m) in ascending id order (see [`World::ids`]).
    pub fn positions(&self) -> Vec<Vec3> {
        let mut out = vec![Vec3::zeros(); self.fluid_count()];
        self.gather_by_id(&self.fluid.positions, &mut out);
        out
    }

    /// Fluid velocities (m/s) in ascending id order (see [`World::ids`]).
    pub fn velocities(&self) -> Vec<Vec3> {
        let mut out = vec![Vec3::zeros(); self.fluid_count()];
        self.gather_by_id(&self.fluid.velocities, &mut out);
        out
    }

    /// Replaces every fluid velocity (m/s), given in ascending id order (see [`World::ids`]).
    /// Rejects a length mismatch or a non-finite value without changing the world.
    pub fn set_velocities(&mut self, velocities: &[Vec3]) -> Result<(), Error> {
        if velocities.len() != self.fluid_count() {
            return Err(Error::invalid(
                "velocities",
                velocities.len(),
                &format!(
                    "must have one entry per fluid particle ({})",
                    self.fluid_count()
                ),
            ));
        }
        check_finite("velocities", velocities)?;
        let fluid = &mut self.fluid;
        for slot in 0..fluid.len() {
            fluid.velocities[slot] = velocities[fluid.rank(fluid.ids[slot])];
        }
        Ok(())
    }

    /// Fluid densities (kg/m³) after the last step, in ascending id order (see
    /// [`World::ids`]); before a particle's first step, those evaluated when fluid was last
    /// added.
    /// Each particle's density is its own material's: ρ0_i times the volume fraction its
    /// neighbourhood fills (docs/method.md §14).
    pub fn densities(&self) -> Vec<f64> {
        let mut out = vec![0.0; self.fluid_count()];
        for (slot, &id) in self.fluid.ids.iter().enumerate() {
            out[self.fluid.rank(id)] = self.material_density(slot);
        }
        out
    }

    /// The density of the particle in storage slot `slot` in its material's terms (kg/m³):
    /// the step keeps every density in the world's own fluid's terms.
    pub(super) fn material_density(&self, slot: usize) -> f64 {
        let ratio = self.materials.mass_ratios[self.fluid.materials[slot] as usize];
        self.fluid.densities[slot] * ratio
    }

    /// Boundary particle positions (m), in the world's storage order: walls, obstacles and
    /// static bodies, and the moving bodies' particles where the last step placed them. A
    /// copy: the world keeps them by component.
    pub fn boundary_positions(&self) -> Vec<Vec3> {
        self.boundary.positions.to_vec()
    }

    /// Every boundary particle where it is now (m): the static ones, then each moving body's
    /// at its current pose (also before the first step and after an import).
    pub fn boundary_particles(&self) -> Vec<Vec3> {
        let (mut points, _) = self.boundary.statics();
        for body in self.bodies.iter().filter(|b| b.moves()) {
            points.extend(body.particle_positions());
        }
        points
    }

    /// Kinetic energy Σ ½m_i|v_i|² (J), each particle of its material's mass.
    pub fn kinetic_energy(&self) -> f64 {
        let (m, fluid) = (self.constraint.mass, &self.fluid);
        let ratios = &self.materials.mass_ratios;
        self.pool.install(|| {
            reduce::sum_over(fluid.len(), |i| {
                let mi = m * ratios[fluid.materials[i] as usize];
                0.5 * mi * fluid.velocities[i].norm_squared()
            })
        })
    }

    /// Potential energy −Σ m_i g·x_i (J), zero at the origin.
    pub fn potential_energy(&self) -> f64 {
        let (m, fluid) = (self.constraint.mass, &self.fluid);
        let ratios = &self.materials.mass_ratios;
        let g = Vec3::from(self.params.gravity);
        self.pool.install(|| {
            reduce::sum_over(fluid.len(), |i| {
                -m * ratios[fluid.materials[i] as usize] * g.dot(&fluid.positions[i])
            })
        })
    }

    /// Root-mean-square speed of the fluid (m/s).
    pub fn rms_velocity(&self) -> f64 {
        let n = self.fluid_count().max(1) as f64;
        (self
            .pool
            .install(|| reduce::sum(&self.fluid.velocities, |v| v.norm_squared()))
            / n)
            .sqrt()
    }

    /// Fluid particles farther than r/2 outside every container, or non-finite (0 without containers).
    pub fn escaped_count(&self) -> usize {
        if self.containers.is_empty() {
            return 0;
        }
        let margin = 0.5 * self.params.particle_radius;
        self.fluid
            .positions
            .iter()
            .filter(|p| !self.containers.iter().any(|c| c.contains(p, margin)))
            .count()
    }

    /// Number of fluid particles with a non-finite position or velocity.
    pub fn nan_count(&self) -> usize {
        let bad = |v: &Vec3| !v.iter().all(|c| c.is_finite());
        self.fluid
            .positions
            .iter()
            .zip(&self.fluid.velocities)
            .filter(|(x, v)| bad(x) || bad(v))
            .count()
    }

    /// A hex SHA-256 digest of the positions' bit patterns in ascending id order (see
    /// [`World::ids`]); equal digests mean bitwise identical positions.
    pub fn positions_hash(&self) -> String {
        use sha2::{Digest, Sha256};
        let mut hasher = Sha256::new();
        // The particles' slots in ascending id order (a quarter of a copy of the positions).
        let mut slots = vec![0u32; self.fluid_count()];
        for (slot, &id) in self.fluid.ids.iter().enumerate() {
            slots[self.fluid.rank(id)] = slot as u32;
        }
        for &slot in &slots {
            for c in self.fluid.positions[slot as usize].iter() {
                hasher.update(c.to_bits().to_le_bytes());
            }
        }
        hasher
            .finalize()
            .iter()
            .map(|b| format!("{b:02x}"))
            .collect()
    }
}

/// Copies into caller buffers, without allocating, for embedders such as the C API.
impl World {
    /// Writes fluid positions (m) as x, y, z triples of `f32` into `out[..3·fluid_count()]`, in
    /// ascending id order (see [`World::ids`]), without allocating. Returns the number of floats
    /// needed as the error, leaving `out` untouched, when `out` is too short.
    pub fn write_positions_f32(&self, out: &mut [f32]) -> Result<(), usize> {
        self.write_vectors_f32(&self.fluid.positions, out)
    }

    /// Writes fluid velocities (m/s) like [`World::write_positions_f32`].
    pub fn write_velocities_f32(&self, out: &mut [f32]) -> Result<(), usize> {
        self.write_vectors_f32(&self.fluid.velocities, out)
    }

    /// Writes fluid densities (kg/m³, as [`World::densities`] reports them) into
    /// `out[..fluid_count()]` in ascending id order; errs with the number of floats needed,
    /// leaving `out` untouched, when `out` is too short.
    pub fn write_densities_f32(&self, out: &mut [f32]) -> Result<(), usize> {
        let n = self.fluid_count();
        let out = out.get_mut(..n).ok_or(n)?;
        for (slot, &id) in self.fluid.ids.iter().enumerate() {
            out[self.fluid.rank(id)] = self.material_density(slot) as f32;
        }
        Ok(())
    }

    fn write_vectors_f32(&self, values: &[Vec3], out: &mut [f32]) -> Result<(), usize> {
        let n = 3 * self.fluid_count();
        let out = out.get_mut(..n).ok_or(n)?;
        for (v, &id) in values.iter().zip(&self.fluid.ids) {
            let i = 3 * self.fluid.rank(id);
            out[i..i + 3].copy_from_slice(&[v.x as f32, v.y as f32, v.z as f32]);
        }
        Ok(())
    }

    /// Writes the fluid particles' ids into `out[..fluid_count()]` in ascending order (see
    /// [`World::ids`]), without allocating; errs with the number of ids needed, leaving
    /// `out` untouched, when `out` is too short.
    pub fn write_ids(&self, out: &mut [u64]) -> Result<(), usize> {
        let n = self.fluid_count();
        let out = out.get_mut(..n).ok_or(n)?;
        out.copy_from_slice(&self.fluid.ascending);
        Ok(())
    }
}
