//! For engines that render with wgpu (feature `gpu`): a world stepped on the caller's own
//! `wgpu::Device` and `Queue`, and its particle positions as a device buffer the caller can
//! bind without a copy.

use super::World;
use super::backend::GpuSlot;
use crate::{Backend, Error, Vec3};

/// The fluid's positions on the device after the last step ([`World::gpu_positions`]).
#[derive(Clone, Copy, Debug)]
pub struct GpuPositions<'a> {
    /// One `vec4<f32>` per particle (16 bytes): x, y and z in metres from [`origin`], and
    /// in w the particle's pressure in pascals, as [`World::constraint_pressures`] reads it
    /// after a step (for colouring by pressure). Particles lie in the device's order, which
    /// the steps change. Its usages are `STORAGE`, `COPY_SRC` and `COPY_DST`: bind it
    /// read-only as a storage buffer (in a vertex shader, for instance), or copy it.
    ///
    /// [`origin`]: GpuPositions::origin
    pub buffer: &'a wgpu::Buffer,
    /// Particles in the buffer.
    pub count: u32,
    /// The point the positions are measured from (m, world frame), so that single
    /// precision keeps its resolution in a scene far from the world's origin.
    pub origin: Vec3,
}

impl World {
    /// Steps the world on the caller's `device` and `queue` (an engine's, made from its
    /// own adapter), as [`World::set_backend`] with [`Backend::Gpu`] does on a device it
    /// opens; the fluid is uploaded at the next step. The device needs
    /// `max_storage_buffers_per_shader_stage` of at least 12 in its limits. projfluid's
    /// work on it runs in error scopes and leaves its uncaptured-error handler alone.
    /// Errors, changing nothing: a world with what the GPU backend does not step yet, or a
    /// device whose limits are too low, naming the limit.
    pub fn set_gpu_device(
        &mut self,
        device: wgpu::Device,
        queue: wgpu::Queue,
    ) -> Result<(), Error> {
        self.check_gpu_world()?;
        crate::gpu::check_limits(&device.limits(), "the caller's device")?;
        self.gpu = Some(Box::new(GpuSlot::on(Some((device, queue)))));
        self.params.backend = Backend::Gpu;
        Ok(())
    }

    /// The fluid's positions on the device after the last step, for rendering without a
    /// copy: `None` on the CPU backend and before the first step on the GPU. The buffer
    /// holds the same positions as [`World::positions`], in single precision and in the
    /// device's order, until the next step or a change to the fluid.
    pub fn gpu_positions(&self) -> Option<GpuPositions<'_>> {
        let stepper = self.gpu.as_ref()?.context.as_ref()?;
        let (buffer, count, origin) = stepper.positions();
        Some(GpuPositions {
            buffer,
            count,
            origin,
        })
    }
}
