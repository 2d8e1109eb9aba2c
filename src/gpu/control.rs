//! The stopping rules of the outer iteration on the device (docs/method.md §4;
//! shaders/control.wgsl): after each outer iteration one thread applies the density and
//! displacement rules and the most iterations, as src/step/iterate.rs does, so that the host
//! submits [`BATCH`] iterations at a time with Chebyshev's weights laid out in advance (the
//! schedule) and reads back only where they stopped. The iterations recorded after a stop
//! change nothing. Before the first iteration the same thread checks the neighbour lists'
//! lengths against their room.
//!
//! The rules compare single-precision reductions with the double-precision tolerances; each
//! tolerance goes to the device as the single-precision bound with which the device's
//! comparison accepts exactly the values the host's double-precision comparison accepts.

use super::buffers::Buffers;
use super::context::{Context, Kernel, Slot, dispatch_groups, floats, words};
use super::reduce::Reduction;
use crate::Error;
use crate::params::Params;
use crate::step::iterate::DENSITY_RULE_MOTION;
use bytemuck::{Pod, Zeroable};

/// Outer iterations submitted between two reads of where the iteration stands.
pub(super) const BATCH: usize = 4;

/// Bytes of the pool's header before `stopped` (its cursor and overflow flag), and of the
/// control block before the displacements (shaders/control.wgsl).
const POOL_STOP: u64 = 8;
const CONTROL_HEADER: u64 = 32;

/// `ControlParams` in shaders/control.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct ControlParams {
    min_iterations: u32,
    max_iterations: u32,
    n: u32,
    pad: u32,
    tau: f32,
    motion: f32,
    compression: f32,
    pad1: f32,
}

/// How a batch of outer iterations left the iteration.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Stop {
    /// Not stopped: more iterations follow.
    Going,
    /// A stopping rule held.
    Converged,
    /// The local step of iteration `k` found the pool of kept corrections full, having
    /// asked for `entries` entries; iteration `k` changed nothing and is to be taken again.
    PoolFull { entries: u64 },
    /// The iteration reached its most iterations.
    Exhausted,
    /// The neighbour lists the search counted, of `fluid` and `boundary` entries, do not fit
    /// their room; the outer iteration has not begun.
    ListsFull { fluid: u64, boundary: u64 },
}

/// Where the outer iteration stands (`Control` in shaders/control.wgsl).
#[derive(Clone, Copy, Debug)]
pub(super) struct Standing {
    pub stop: Stop,
    /// The next iteration's k (iterations since the start or the fallback's restart).
    pub k: usize,
    /// Outer iterations taken in the step.
    pub outer: usize,
    /// The iterate buffer holding the result.
    pub current: usize,
    pub densities_known: bool,
    /// The last outer iteration's largest move (m; infinite before the first).
    pub displacement: f64,
}

/// The rules' kernels (the decision after an iteration, the lists' check), their constants
/// and their bind group.
pub(super) struct Control {
    kernel: Kernel,
    params: wgpu::Buffer,
    group: Option<wgpu::BindGroup>,
}

impl Control {
    /// The kernel, compiled.
    pub fn new(ctx: &Context) -> Self {
        let mut slots = vec![Slot::Uniform];
        slots.extend([Slot::Storage; 7]);
        Control {
            kernel: ctx.kernel(
                "control",
                concat!(
                    include_str!("shaders/pool.wgsl"),
                    "\n",
                    include_str!("shaders/control.wgsl")
                ),
                &slots,
                &["decide", "lists"],
            ),
            params: ctx.uniform("control", &ControlParams::zeroed()),
            group: None,
        }
    }

    /// Makes the bind group again for the buffers of `b` and the reduction `reduction`.
    pub fn bind(&mut self, ctx: &Context, b: &Buffers, reduction: &Reduction) {
        self.group = Some(ctx.bind(
            &self.kernel,
            &[
                &self.params,
                &reduction.result,
                &b.kept,
                &b.control,
                &b.fluid_offset,
                &b.boundary_offset,
                &b.fluid_list,
                &b.boundary_list,
            ],
        ));
    }

    /// Writes the rules of `params` for `n` fluid particles.
    pub fn set_rules(&self, ctx: &Context, params: &Params, n: u32) {
        let count = |k: usize| u32::try_from(k).unwrap_or(u32::MAX);
        let tau = params.displacement_tolerance;
        let rules = ControlParams {
            min_iterations: count(params.min_outer_iterations),
            max_iterations: count(params.max_outer_iterations),
            n,
            pad: 0,
            tau: below(tau),
            motion: below(DENSITY_RULE_MOTION * tau),
            compression: at_most(params.density_tolerance, f64::from(n.max(1))),
            pad1: 0.0,
        };
        ctx.queue
            .write_buffer(&self.params, 0, bytemuck::bytes_of(&rules));
    }

    /// Writes ω_k and whether to extrapolate for every outer iteration k into the schedule.
    pub fn set_schedule(&self, ctx: &Context, b: &Buffers, schedule: &[(f64, bool)]) {
        let entries: Vec<[f32; 4]> = schedule
            .iter()
            .map(|&(omega, extrapolate)| [omega as f32, f32::from(u8::from(extrapolate)), 0.0, 0.0])
            .collect();
        ctx.queue
            .write_buffer(&b.schedule, 0, bytemuck::cast_slice(&entries));
    }

    /// Starts the outer iteration at k = 0 from the iterate buffer 0, with `outer`
    /// iterations already taken in the step.
    pub fn start(&self, ctx: &Context, b: &Buffers, outer: usize) {
        let header: [u32; 8] = [
            u32::try_from(outer).unwrap_or(u32::MAX),
            0,
            0,
            0,
            f32::MAX.to_bits(),
            0,
            0,
            0,
        ];
        ctx.queue
            .write_buffer(&b.control, 0, bytemuck::cast_slice(&header));
        self.resume(ctx, b, 0);
    }

    /// Lets the iteration go on at iteration `k` after a stop.
    pub fn resume(&self, ctx: &Context, b: &Buffers, k: usize) {
        let state = [0u32, u32::try_from(k).unwrap_or(u32::MAX)];
        ctx.queue
            .write_buffer(&b.kept, POOL_STOP, bytemuck::cast_slice(&state));
    }

    /// Records the rules' decision after an outer iteration's reduction.
    pub fn record(&self, pass: &mut wgpu::ComputePass) {
        self.record_entry(pass, 0);
    }

    /// Records the check of the neighbour lists' lengths against their room, before the
    /// first outer iteration.
    pub fn record_lists(&self, pass: &mut wgpu::ComputePass) {
        self.record_entry(pass, 1);
    }

    fn record_entry(&self, pass: &mut wgpu::ComputePass, entry: usize) {
        let group = self
            .group
            .as_ref()
            .expect("Control::bind runs before a step");
        dispatch_groups(pass, &self.kernel.pipelines[entry], group, 1);
    }

    /// Where the iteration stands after the commands of `encoder` run.
    pub fn read(
        &self,
        ctx: &Context,
        b: &Buffers,
        encoder: wgpu::CommandEncoder,
    ) -> Result<Standing, Error> {
        let read = ctx.read_many(encoder, &[(&b.kept, 16), (&b.control, CONTROL_HEADER)])?;
        let (pool, control) = (words(&read[0]), words(&read[1]));
        let displacement = floats(&read[1][16..20])[0];
        let k = pool[3] as usize;
        let stop = match pool[2] {
            0 => Stop::Going,
            1 => Stop::Converged,
            2 => Stop::PoolFull {
                entries: u64::from(control[5]),
            },
            3 => Stop::Exhausted,
            _ => Stop::ListsFull {
                fluid: u64::from(control[5]),
                boundary: u64::from(control[6]),
            },
        };
        Ok(Standing {
            stop,
            k,
            outer: control[0] as usize,
            current: control[1] as usize,
            densities_known: control[3] != 0,
            displacement: if displacement == f32::MAX {
                f64::INFINITY
            } else {
                f64::from(displacement)
            },
        })
    }

    /// δ_0 … δ_{k−1} of the iterations since the start or the fallback's restart (m).
    pub fn displacements(&self, ctx: &Context, b: &Buffers, k: usize) -> Result<Vec<f64>, Error> {
        let bytes = CONTROL_HEADER + 4 * k as u64;
        let read = ctx.read(ctx.encoder(), &b.control, bytes)?;
        Ok(floats(&read[CONTROL_HEADER as usize..])
            .into_iter()
            .take(k)
            .map(f64::from)
            .collect())
    }
}

/// The smallest single-precision value not below `bound`: the b with m < b exactly where
/// f64(m) < `bound`, for every single-precision m.
fn below(bound: f64) -> f32 {
    let b = bound as f32;
    if f64::from(b) < bound { b.next_up() } else { b }
}

/// The largest single-precision c with f64(c)/`n` ≤ `tolerance`.
fn at_most(tolerance: f64, n: f64) -> f32 {
    let mut c = (tolerance * n) as f32;
    while c > 0.0 && f64::from(c) / n > tolerance {
        c = c.next_down();
    }
    while f64::from(c.next_up()) / n <= tolerance && c.next_up().is_finite() {
        c = c.next_up();
    }
    c
}
