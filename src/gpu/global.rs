//! The global step on the device (docs/method.md §3.1, §3.6, §3.7; shaders/sweep.wgsl):
//! the gather of the local step's corrections, one Jacobi sweep on the diagonal system and
//! Chebyshev's extrapolation in one pass, X^(k+1) written over X^(k−1). The weights ω come
//! from the host's [`crate::solver::Chebyshev`], as on the CPU.

use super::buffers::Buffers;
use super::context::{Context, Kernel, Slot, dispatch};

/// The sweep kernel with a bind group for each assignment of the two iterate buffers.
pub(super) struct GlobalStep {
    kernel: Kernel,
    groups: Vec<wgpu::BindGroup>,
}

impl GlobalStep {
    pub fn new(ctx: &Context) -> Self {
        let mut slots = vec![Slot::Uniform, Slot::Uniform];
        slots.extend([Slot::Storage; 11]);
        let kernel = ctx.kernel(
            "sweep",
            with_common!("shaders/sweep.wgsl"),
            &slots,
            &["sweep"],
        );
        GlobalStep {
            kernel,
            groups: Vec::new(),
        }
    }

    /// Makes the bind groups again for the buffers of `b`.
    pub fn bind(&mut self, ctx: &Context, b: &Buffers) {
        self.groups = (0..2)
            .map(|current| {
                ctx.bind(
                    &self.kernel,
                    &[
                        &b.params,
                        &b.iter,
                        &b.iterates[current],
                        &b.iterates[1 - current],
                        &b.s,
                        &b.fluid_offset,
                        &b.fluid_list,
                        &b.projection,
                        &b.flags,
                        &b.kept,
                        &b.values,
                        &b.material,
                        &b.schedule,
                    ],
                )
            })
            .collect();
    }

    /// Records the sweep from X^(k) in `b.iterates[current]`, writing X^(k+1) over X^(k−1)
    /// in the other.
    pub fn record(&self, pass: &mut wgpu::ComputePass, b: &Buffers, current: usize) {
        dispatch(pass, &self.kernel.pipelines[0], &self.groups[current], b.n);
    }
}
