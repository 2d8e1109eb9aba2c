//! The GPU backend (feature `gpu`): the time step of a world's fluid and static boundary
//! particles on a graphics card, through wgpu compute shaders in WGSL (docs/method.md §16),
//! in single precision. The fluid stays on the device during a step; a step waits on the
//! device once per four outer iterations, whose stopping rules (§4) the device applies
//! itself (and where the neighbour lists or the pool of kept corrections must grow), and
//! once at its end for its statistics, the CFL rule (§8) and the fluid's state together.
//!
//! Deterministic on one device and driver: integer atomics only where their result does not
//! depend on the order (counting particles per cell; each cell's particles are then sorted
//! by index), sums in a fixed tree, and every per-particle sum gathered by the particle
//! itself in the order of its neighbour list.
//!
//! It steps worlds without bodies and walls built as fields, with Chebyshev's solver or one
//! Jacobi sweep (without the warm start and the coarse correction, stepper.rs): the fluid
//! and the static boundary as particles, with several materials (their mass ratios dividing
//! the projection weights, §14), the physical viscosity (§13), vorticity confinement (§15)
//! and XSPH. Emitters, sinks and the domain (§12) act on the host between
//! steps; where they change the number of particles the stepper is remade on the same
//! device, its kernels kept.
//!
//! One file per stage: [`context`] (device, kernels, read-backs), [`buffers`] (the state on
//! the device), [`search`] and [`scan`] (the counting sort and the neighbour lists),
//! [`local`] (the projections), [`global`] (gather, Jacobi sweep, Chebyshev), [`reduce`]
//! (the reductions of the stopping rules and statistics), [`control`] (the stopping rules),
//! [`finish`] (velocities, densities, vorticity confinement, XSPH, CFL), [`viscosity`] (the
//! physical viscosity's solve), [`timer`] (the device's time per stage) and [`stepper`]
//! (the step in order). Shaders are in
//! `shaders/`.

/// A shader's WGSL source with shaders/common.wgsl (the step's constants, the kernel, the
/// grid) and shaders/pool.wgsl (the pool of kept corrections) before it.
macro_rules! with_common {
    ($path:literal) => {
        concat!(
            include_str!("shaders/common.wgsl"),
            "\n",
            include_str!("shaders/pool.wgsl"),
            "\n",
            include_str!($path)
        )
    };
}

mod buffers;
mod context;
mod control;
mod finish;
mod global;
mod local;
mod reduce;
mod scan;
mod search;
mod stepper;
mod timer;
mod viscosity;

pub(crate) use context::check_limits;
pub(crate) use stepper::{GpuStepper, Scene};

/// Opens the device once, to tell whether the GPU backend can run here; errors as
/// [`context::Context::new`], naming what is missing.
pub(crate) fn probe() -> Result<(), crate::Error> {
    context::Context::new().map(|_| ())
}
