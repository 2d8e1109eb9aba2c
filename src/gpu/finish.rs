//! The end of a step on the device (docs/method.md §1.3 steps 5–8; shaders/finish.wgsl):
//! the new positions, kept inside their containers (§7), velocities from the positions, the
//! densities at them, then (after the physical viscosity where a material has one,
//! viscosity.rs) the vorticity confinement where it is on (§15, shaders/vorticity.wgsl), the
//! XSPH filter, and the per-particle values of the step's density errors and of the CFL
//! rule, reduced after (reduce.rs). The CFL rule itself is [`next_step_size`].

use super::buffers::Buffers;
use super::context::{Context, Kernel, Slot, dispatch};
use super::timer::{Stage, Timer};
use crate::params::Params;

/// The finishing kernels with a bind group for each iterate buffer holding the result, and
/// the vorticity confinement's where it is on.
pub(super) struct Finish {
    kernel: Kernel,
    groups: Vec<wgpu::BindGroup>,
    vorticity: Option<Vorticity>,
}

/// The vorticity confinement's kernels (`vorticity`, `confine`) and their bind group.
struct Vorticity {
    kernel: Kernel,
    group: Option<wgpu::BindGroup>,
}

impl Finish {
    /// The finishing kernels, with the vorticity confinement's where `confine` (its ε > 0).
    pub fn new(ctx: &Context, confine: bool) -> Self {
        let mut slots = vec![Slot::Uniform, Slot::Uniform];
        slots.extend([Slot::Storage; 12]);
        let kernel = ctx.kernel(
            "finish",
            with_common!("shaders/finish.wgsl"),
            &slots,
            &["update", "xsph"],
        );
        let vorticity = confine.then(|| {
            let mut slots = vec![Slot::Uniform];
            slots.extend([Slot::Storage; 5]);
            Vorticity {
                kernel: ctx.kernel(
                    "vorticity",
                    with_common!("shaders/vorticity.wgsl"),
                    &slots,
                    &["vorticity", "confine"],
                ),
                group: None,
            }
        });
        Finish {
            kernel,
            groups: Vec::new(),
            vorticity,
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
                        &b.containers,
                    ],
                )
            })
            .collect();
        if let Some(v) = &mut self.vorticity {
            v.group = Some(ctx.bind(
                &v.kernel,
                &[
                    &b.params,
                    &b.x,
                    &b.v,
                    &b.fluid_offset,
                    &b.fluid_list,
                    &b.vorticity,
                ],
            ));
        }
    }

    /// Records the update from the result in `b.iterates[result]`: the velocities from the
    /// positions, the new positions and the densities at them.
    pub fn record_update(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut Timer,
        b: &Buffers,
        result: usize,
    ) {
        let mut pass = timer.pass(encoder, Stage::End);
        dispatch(
            &mut pass,
            &self.kernel.pipelines[0],
            &self.groups[result],
            b.n,
        );
    }

    /// Records what follows the update and the physical viscosity: the vorticity
    /// confinement where it is on and the XSPH filter, whose velocities are copied back
    /// into `b.v`.
    pub fn record_filters(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut Timer,
        b: &Buffers,
        result: usize,
    ) {
        {
            let mut pass = timer.pass(encoder, Stage::End);
            if let Some(v) = &self.vorticity {
                let confine = v.group.as_ref().expect("Finish::bind runs before a step");
                dispatch(&mut pass, &v.kernel.pipelines[0], confine, b.n);
                dispatch(&mut pass, &v.kernel.pipelines[1], confine, b.n);
            }
            dispatch(
                &mut pass,
                &self.kernel.pipelines[1],
                &self.groups[result],
                b.n,
            );
        }
        encoder.copy_buffer_to_buffer(&b.v_out, 0, &b.v, 0, u64::from(b.n) * 16);
    }
}

/// The CFL rule (docs/method.md §8), as on the CPU ([`crate::step::cfl_step`]), from
/// `fastest_squared` = max_i |v_i + Δt·g|² (m²/s²): the next step's size (s).
pub(super) fn next_step_size(params: &Params, fastest_squared: f64) -> f64 {
    crate::step::cfl_step(params, fastest_squared.sqrt())
}
