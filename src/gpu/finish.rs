//! The end of a step on the device (docs/method.md §1.3 steps 5–8; shaders/finish.wgsl):
//! velocities from the positions, the new positions, the densities at them, the XSPH
//! filter, and the per-particle values of the step's density errors and of the CFL rule,
//! reduced after (reduce.rs). The CFL rule itself is [`next_step_size`].

use super::buffers::Buffers;
use super::context::{Context, Kernel, Slot, dispatch};
use crate::params::Params;

/// The finishing kernels with a bind group for each iterate buffer holding the result.
pub(super) struct Finish {
    kernel: Kernel,
    groups: Vec<wgpu::BindGroup>,
}

impl Finish {
    pub fn new(ctx: &Context) -> Self {
        let mut slots = vec![Slot::Uniform, Slot::Uniform];
        slots.extend([Slot::Storage; 11]);
        let kernel = ctx.kernel(
            "finish",
            with_common!("shaders/finish.wgsl"),
            &slots,
            &["update", "xsph"],
        );
        Finish {
            kernel,
            groups: Vec::new(),
        }
    }

    /// Makes the bind groups again for the buffers of `b`.
    pub fn bind(&mut self, ctx: &Context, b: &Buffers) {
        self.groups = b
            .iterates
            .iter()
            .map(|result| {
                ctx.bind(
                    &self.kernel,
                    &[
                        &b.params,
                        &b.iter,
                        result,
                        &b.x,
                        &b.v,
                        &b.v_out,
                        &b.density,
                        &b.fluid_offset,
                        &b.fluid_list,
                        &b.boundary_offset,
                        &b.boundary_list,
                        &b.boundary,
                        &b.values,
                    ],
                )
            })
            .collect();
    }

    /// Records the update from the result in `b.iterates[result]` and the XSPH filter, whose
    /// velocities are copied back into `b.v`.
    pub fn record(&self, encoder: &mut wgpu::CommandEncoder, b: &Buffers, result: usize) {
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            let group = &self.groups[result];
            dispatch(&mut pass, &self.kernel.pipelines[0], group, b.n);
            dispatch(&mut pass, &self.kernel.pipelines[1], group, b.n);
        }
        encoder.copy_buffer_to_buffer(&b.v_out, 0, &b.v, 0, u64::from(b.n) * 16);
    }
}

/// The CFL rule (docs/method.md §8), as on the CPU: Δt = λ·0.4·2r/v_max clamped to
/// [Δt_min, Δt_max] (s), from `fastest_squared` = max_i |v_i + Δt·g|² (m²/s²).
pub(super) fn next_step_size(params: &Params, fastest_squared: f64) -> f64 {
    let v_max = fastest_squared.max(1e-9).sqrt();
    let cfl = params.cfl_factor * 0.4 * params.spacing() / v_max;
    if cfl.is_finite() {
        cfl.clamp(params.dt_min, params.dt_max)
    } else {
        params.dt_min
    }
}
