//! The physical viscosity on the device (docs/method.md §13, shaders/viscosity.wgsl): the
//! implicit viscous update of src/forces/viscosity.rs, with its Laplacian, calibration,
//! harmonic-mean pair viscosities, no-slip walls and preconditioned conjugate gradients,
//! between the update of the velocities and the vorticity confinement and XSPH filter.
//!
//! The solve's scalars stay on the device; the host submits the iterations in batches of
//! [`BATCH`] and reads back after each batch whether the solve has stopped, the iterations
//! after the stop leaving everything as it is.

use super::buffers::{Buffers, MATERIAL_SLOTS};
use super::context::{Context, Kernel, Slot, dispatch, dispatch_groups, floats};
use super::reduce::Reduction;
use super::timer::{Stage, Timer};
use crate::Error;
use crate::forces::viscosity::{
    LAPLACIAN_FACTOR, MAX_ITERATIONS, MOST_CALIBRATION, REGULARISATION, TOLERANCE,
};
use crate::params::Params;
use bytemuck::{Pod, Zeroable};

/// Conjugate-gradient iterations submitted between two reads of the stop flag.
const BATCH: usize = 8;

/// vec4 slots of `work` before the particles' regions (shaders/viscosity.wgsl).
const SCALARS: u64 = 2;

/// Per-particle regions of `work`: (V, ν), κ, r, z, p, A·p and the two halves of the
/// inverse blocks.
const REGIONS: u64 = 8;

/// `ViscosityParams` in shaders/viscosity.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct ViscosityParams {
    /// c = 2(d + 2)Δt (s), ε (m²), 1 for no-slip walls, the tolerance squared.
    coupling: f32,
    epsilon: f32,
    no_slip: u32,
    tolerance2: f32,
    /// 2/(2(d + 2)), the largest calibration, the most iterations.
    exact: f32,
    most_calibration: f32,
    max_iterations: f32,
    pad: f32,
    /// ν (m²/s) of every material, four to an entry.
    nu: [[f32; 4]; MATERIAL_SLOTS / 4],
}

/// The entry points of shaders/viscosity.wgsl, by their place in [`ENTRIES`] and in the
/// kernel's pipelines.
#[derive(Clone, Copy)]
enum Entry {
    Volumes,
    Calibrate,
    Begin,
    RightSide,
    Start,
    Check,
    Product,
    StepSize,
    Advance,
    NextDirection,
    Direction,
}

/// The entry points' names, in the order of [`Entry`].
const ENTRIES: [&str; 11] = [
    "volumes",
    "calibrate",
    "begin",
    "right_side",
    "start",
    "check",
    "product",
    "step_size",
    "advance",
    "next_direction",
    "direction",
];

/// The step a solve belongs to.
#[derive(Clone, Copy)]
pub(super) struct ViscousStep<'a> {
    /// The world's parameters: its support radius and wall condition.
    pub params: &'a Params,
    /// Each material's kinematic viscosity ν (m²/s), by id.
    pub viscosities: &'a [f64],
    /// The step size Δt (s).
    pub dt: f64,
}

/// The viscosity solve's kernels, with its working buffer and bind group for the buffers
/// last bound.
pub(super) struct ViscositySolve {
    kernel: Kernel,
    params: wgpu::Buffer,
    work: Option<wgpu::Buffer>,
    group: Option<wgpu::BindGroup>,
}

impl ViscositySolve {
    /// The solve's kernels, compiled.
    pub fn new(ctx: &Context) -> Self {
        let mut slots = vec![Slot::Uniform, Slot::Uniform];
        slots.extend([Slot::Storage; 12]);
        let kernel = ctx.kernel(
            "viscosity",
            with_common!("shaders/viscosity.wgsl"),
            &slots,
            &ENTRIES,
        );
        ViscositySolve {
            kernel,
            params: ctx.uniform("viscosity", &ViscosityParams::zeroed()),
            work: None,
            group: None,
        }
    }

    /// Makes the working buffer and the bind group again for the buffers of `b` and the
    /// reduction `reduction` of `b.values`.
    pub fn bind(&mut self, ctx: &Context, b: &Buffers, reduction: &Reduction) {
        let slots = SCALARS + REGIONS * u64::from(b.n);
        let work = ctx.storage("viscosity", slots * 16);
        self.group = Some(ctx.bind(
            &self.kernel,
            &[
                &b.params,
                &self.params,
                &b.x,
                &b.v,
                &b.material,
                &b.density,
                &b.fluid_offset,
                &b.fluid_list,
                &b.boundary_offset,
                &b.boundary_list,
                &b.boundary,
                &work,
                &b.values,
                &reduction.result,
            ],
        ));
        self.work = Some(work);
    }

    /// Solves for the velocities in `b.v` after the update of `step`, with the reduction
    /// `reduction` of `b.values`, its passes timed by `timer`. Errors when the device fails.
    pub fn solve(
        &self,
        ctx: &Context,
        timer: &mut Timer,
        b: &Buffers,
        reduction: &Reduction,
        step: &ViscousStep,
    ) -> Result<(), Error> {
        let ViscousStep {
            params,
            viscosities,
            dt,
        } = *step;
        let (Some(group), Some(work)) = (&self.group, &self.work) else {
            return Err(crate::world::gpu_error("the viscosity solve is not bound"));
        };
        let mut nu = [[0.0f32; 4]; MATERIAL_SLOTS / 4];
        for (slot, &v) in nu.as_flattened_mut().iter_mut().zip(viscosities) {
            *slot = v as f32;
        }
        let params = ViscosityParams {
            coupling: (LAPLACIAN_FACTOR * dt) as f32,
            epsilon: (REGULARISATION * params.support_radius().powi(2)) as f32,
            no_slip: u32::from(params.no_slip),
            tolerance2: (TOLERANCE * TOLERANCE) as f32,
            exact: (2.0 / LAPLACIAN_FACTOR) as f32,
            most_calibration: MOST_CALIBRATION as f32,
            max_iterations: MAX_ITERATIONS as f32,
            pad: 0.0,
            nu,
        };
        ctx.queue
            .write_buffer(&self.params, 0, bytemuck::bytes_of(&params));
        let pipelines = &self.kernel.pipelines;
        // Over every particle, or on one thread.
        let each = |pass: &mut wgpu::ComputePass, e: Entry| {
            dispatch(pass, &pipelines[e as usize], group, b.n);
        };
        let one = |pass: &mut wgpu::ComputePass, e: Entry| {
            dispatch_groups(pass, &pipelines[e as usize], group, 1);
        };
        let mut encoder = ctx.encoder();
        {
            let mut pass = timer.pass(&mut encoder, Stage::End);
            each(&mut pass, Entry::Volumes);
            each(&mut pass, Entry::Calibrate);
            each(&mut pass, Entry::Begin);
            reduction.record(&mut pass);
            one(&mut pass, Entry::Start);
            each(&mut pass, Entry::RightSide);
            reduction.record(&mut pass);
            one(&mut pass, Entry::Check);
        }
        ctx.queue.submit([encoder.finish()]);
        for _ in 0..MAX_ITERATIONS.div_ceil(BATCH) {
            let mut encoder = ctx.encoder();
            {
                let mut pass = timer.pass(&mut encoder, Stage::End);
                for _ in 0..BATCH {
                    each(&mut pass, Entry::Product);
                    reduction.record(&mut pass);
                    one(&mut pass, Entry::StepSize);
                    each(&mut pass, Entry::Advance);
                    reduction.record(&mut pass);
                    one(&mut pass, Entry::NextDirection);
                    each(&mut pass, Entry::Direction);
                }
            }
            // work[0].w: the stop flag.
            let scalars = floats(&ctx.read(encoder, work, 16)?);
            if scalars[3] != 0.0 {
                break;
            }
        }
        Ok(())
    }
}
