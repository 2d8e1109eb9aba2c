//! The functions that read a `PfWorld` without changing it: counts, time, parameters, the
//! last step's statistics, positions, velocities, densities, particle ids and the positions'
//! hash.

use super::PfWorld;
use crate::ffi::checked::Args;
use crate::ffi::params::PfParams;
use crate::ffi::status::{Failure, PfStatus, status_call};
use std::ffi::c_char;

/// What the last step did, plus the world's current counters.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PfStepStats {
    /// Steps taken so far. 0 means no step yet; the per-step fields below are then 0.
    pub step_count: u64,
    /// Simulated time (s) after the last step.
    pub time: f64,
    /// Size of the last step (s).
    pub dt: f64,
    /// Outer (local/global) iterations of the last step; up to twice `max_outer_iterations`
    /// where Chebyshev's extrapolation reached the limit and the step started over without
    /// it.
    pub outer_iterations: usize,
    /// Inner linear-solver iterations of the last step, summed over its outer iterations.
    pub inner_iterations: usize,
    /// The last step stopped at `max_outer_iterations` instead of a stopping rule (for
    /// Chebyshev: in the pass without extrapolation that followed).
    pub hit_max_iterations: bool,
    /// Largest particle displacement (m) in the last outer iteration of the last step.
    pub last_displacement: f64,
    /// Mean compression max(ρ/ρ0 − 1, 0) over fluid particles after the last step (percent).
    pub density_error_avg_percent: f64,
    /// Largest compression of any fluid particle after the last step (percent).
    pub density_error_max_percent: f64,
    /// Fluid particles now farther than r/2 outside every container (0 without containers).
    pub escaped_count: usize,
    /// Fluid particles now with a non-finite position or velocity.
    pub nan_count: usize,
}

/// Stores the number of fluid particles in `*out`.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`; `out` must be NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_fluid_count(world: *const PfWorld, out: *mut usize) -> PfStatus {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call("pf_world_fluid_count", || {
        let n = args.world(world)?.fluid_count();
        args.write(out, n, "out")
    })
}

/// Stores in `*out` how many fluid particles the last `pf_world_add_fluid_box`,
/// `pf_world_add_fluid_particles` or `pf_world_add_fluid_particles_with_velocities` call
/// made: those asked for less the ones whose centres lay inside a solid (outside every
/// container box, or inside a closed obstacle or body), which are not created. 0 before any
/// such call.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`; `out` must be NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_last_added_count(
    world: *const PfWorld,
    out: *mut usize,
) -> PfStatus {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call("pf_world_last_added_count", || {
        let n = args.world(world)?.last_added_count();
        args.write(out, n, "out")
    })
}

/// Stores the number of boundary particles in `*out`.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`; `out` must be NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_boundary_count(
    world: *const PfWorld,
    out: *mut usize,
) -> PfStatus {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call("pf_world_boundary_count", || {
        let n = args.world(world)?.boundary_count();
        args.write(out, n, "out")
    })
}

/// Stores the simulated time (s) in `*out`.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`; `out` must be NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_time(world: *const PfWorld, out: *mut f64) -> PfStatus {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call("pf_world_time", || {
        let t = args.world(world)?.time();
        args.write(out, t, "out")
    })
}

/// Stores the world's parameters in `*out`.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`; `out` must be NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_get_params(
    world: *const PfWorld,
    out: *mut PfParams,
) -> PfStatus {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call("pf_world_get_params", || {
        let p = PfParams::from(args.world(world)?.params());
        args.write(out, p, "out")
    })
}

/// Stores statistics of the last step and the world's counters in `*out` (all per-step
/// fields are 0 before the first step; see `step_count`).
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`; `out` must be NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_last_step_stats(
    world: *const PfWorld,
    out: *mut PfStepStats,
) -> PfStatus {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call("pf_world_last_step_stats", || {
        let world = args.world(world)?;
        let mut stats = PfStepStats {
            step_count: world.steps(),
            time: world.time(),
            escaped_count: world.escaped_count(),
            nan_count: world.nan_count(),
            ..PfStepStats::default()
        };
        if let Some(last) = world.last_step() {
            stats.dt = last.dt;
            stats.outer_iterations = last.outer_iterations;
            stats.inner_iterations = last.inner_iterations;
            stats.hit_max_iterations = last.hit_max_iterations;
            stats.last_displacement = last.last_displacement;
            stats.density_error_avg_percent = last.density_error_avg * 100.0;
            stats.density_error_max_percent = last.density_error_max * 100.0;
        }
        args.write(out, stats, "out")
    })
}

/// Which per-particle quantity a getter copies.
#[derive(Clone, Copy)]
enum Quantity {
    Positions,
    Velocities,
    Densities,
}

/// The shared body of the three getters.
fn get(
    args: Args,
    name: &str,
    quantity: Quantity,
    world: *const PfWorld,
    out: *mut f32,
    capacity: usize,
    needed: *mut usize,
) -> PfStatus {
    status_call(name, || {
        let world = args.world(world)?;
        let per_particle = match quantity {
            Quantity::Densities => 1,
            _ => 3,
        };
        let want = per_particle * world.fluid_count();
        // A misaligned `needed` is reported as `out`, as it always has been.
        args.per_particle(
            out,
            capacity,
            (needed, "out"),
            (want, "floats"),
            |out| match quantity {
                Quantity::Positions => world.write_positions_f32(out),
                Quantity::Velocities => world.write_velocities_f32(out),
                Quantity::Densities => world.write_densities_f32(out),
            },
        )
    })
}

/// Copies the fluid positions (m) into `out` as x, y, z floats per particle, in ascending id
/// order (the order the particles were added, removed ones skipped; see `pf_world_get_ids`).
/// `capacity_floats` is the length of `out` in floats; 3·fluid count are needed and written.
/// `*needed` (when `needed` is not NULL) receives that number on success and on
/// `PF_ERROR_BUFFER_TOO_SMALL`, in which case `out` is untouched. `out` may be NULL only with
/// capacity 0, to query the size. The world is not changed.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`; `out` must be NULL or point to `capacity_floats` writable floats; `needed` must be NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_get_positions(
    world: *const PfWorld,
    out: *mut f32,
    capacity_floats: usize,
    needed: *mut usize,
) -> PfStatus {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    get(
        args,
        "pf_world_get_positions",
        Quantity::Positions,
        world,
        out,
        capacity_floats,
        needed,
    )
}

/// Copies the fluid velocities (m/s) into `out`, like `pf_world_get_positions`.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`; `out` must be NULL or point to `capacity_floats` writable floats; `needed` must be NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_get_velocities(
    world: *const PfWorld,
    out: *mut f32,
    capacity_floats: usize,
    needed: *mut usize,
) -> PfStatus {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    get(
        args,
        "pf_world_get_velocities",
        Quantity::Velocities,
        world,
        out,
        capacity_floats,
        needed,
    )
}

/// Copies the fluid densities (kg/m³; before a particle's first step, those evaluated when
/// fluid was last added) into `out`, one float per particle in ascending id order; otherwise
/// like `pf_world_get_positions`.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`; `out` must be NULL or point to `capacity_floats` writable floats; `needed` must be NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_get_densities(
    world: *const PfWorld,
    out: *mut f32,
    capacity_floats: usize,
    needed: *mut usize,
) -> PfStatus {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    get(
        args,
        "pf_world_get_densities",
        Quantity::Densities,
        world,
        out,
        capacity_floats,
        needed,
    )
}

/// Copies the fluid particles' ids into `out` in ascending order, the order of every other
/// per-particle read. Ids are given from 0 in the order particles are added and never
/// reused, so a world without removals has the ids 0..n−1. `capacity` is the length of `out`
/// in ids; fluid count are needed and written. `*needed` (when `needed` is not NULL)
/// receives that number on success and on `PF_ERROR_BUFFER_TOO_SMALL`, in which case `out`
/// is untouched. `out` may be NULL only with capacity 0, to query the size. The world is not
/// changed.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`; `out` must be NULL or point to `capacity` writable `uint64_t`s; `needed` must be NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_get_ids(
    world: *const PfWorld,
    out: *mut u64,
    capacity: usize,
    needed: *mut usize,
) -> PfStatus {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call("pf_world_get_ids", || {
        let world = args.world(world)?;
        let want = world.fluid_count();
        args.per_particle(out, capacity, (needed, "needed"), (want, "ids"), |out| {
            world.write_ids(out)
        })
    })
}

/// Writes the hex SHA-256 of the fluid positions' exact (double precision) bit patterns, in
/// ascending id order, as a NUL-terminated string of 64 hex digits into
/// `out` (capacity in bytes, at least 65). Equal strings mean bitwise equal positions, e.g.
/// between the C API and the Rust API or between runs. `*needed` (when not NULL) receives 65;
/// a short buffer gives `PF_ERROR_BUFFER_TOO_SMALL` and is left untouched.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`; `out` must be NULL or point to `capacity` writable bytes; `needed` must be NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_positions_hash(
    world: *const PfWorld,
    out: *mut c_char,
    capacity: usize,
    needed: *mut usize,
) -> PfStatus {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call("pf_world_positions_hash", || {
        let hash = args.world(world)?.positions_hash();
        let want = hash.len() + 1;
        if !needed.is_null() {
            // A misaligned `needed` is reported as `out`, as it always has been.
            args.write(needed, want, "out")?;
        }
        if capacity < want {
            return Err(Failure::new(
                PfStatus::PF_ERROR_BUFFER_TOO_SMALL,
                format!("the buffer holds {capacity} bytes but {want} are needed"),
            ));
        }
        let out = args.out_slice(out.cast::<u8>(), capacity, "out")?;
        out[..hash.len()].copy_from_slice(hash.as_bytes());
        out[hash.len()] = 0;
        Ok(())
    })
}
