//! The local step on the device (docs/method.md §2.5, shaders/project.wgsl): every density
//! constraint projected at the iterate X^(k), one thread per constraint; single-step
//! projections keep λ_i, multi-step ones their stencil's corrections; each member's weight
//! is divided by its material's mass ratio (docs/method.md §14). The gather of those
//! corrections is part of the global step (global.rs), which reads them from the
//! particle's side.

use super::buffers::Buffers;
use super::context::{Context, Kernel, Slot, dispatch};

/// The projection kernel with a bind group for each of the two iterate buffers holding X^(k).
pub(super) struct LocalStep {
    kernel: Kernel,
    groups: Vec<wgpu::BindGroup>,
}

impl LocalStep {
    pub fn new(ctx: &Context) -> Self {
        let mut slots = vec![Slot::Uniform];
        slots.extend([Slot::Storage; 12]);
        let kernel = ctx.kernel(
            "project",
            with_common!("shaders/project.wgsl"),
            &slots,
            &["project"],
        );
        LocalStep {
            kernel,
            groups: Vec::new(),
        }
    }

    /// Makes the bind groups again for the buffers of `b`.
    pub fn bind(&mut self, ctx: &Context, b: &Buffers) {
        self.groups = b
            .iterates
            .iter()
            .map(|current| {
                ctx.bind(
                    &self.kernel,
                    &[
                        &b.params,
                        current,
                        &b.fluid_offset,
                        &b.fluid_list,
                        &b.boundary_offset,
                        &b.boundary_list,
                        &b.boundary,
                        &b.projection,
                        &b.density,
                        &b.flags,
                        &b.kept,
                        &b.values,
                        &b.material,
                    ],
                )
            })
            .collect();
    }

    /// Records the projections at X^(k), held in `b.iterates[current]`.
    pub fn record(&self, pass: &mut wgpu::ComputePass, b: &Buffers, current: usize) {
        dispatch(pass, &self.kernel.pipelines[0], &self.groups[current], b.n);
    }
}
