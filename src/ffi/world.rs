//! `PfWorld`, the opaque handle over a [`World`], and the functions that create, fill, step
//! and read it.

use super::params::{PfParams, read_params};
use super::status::{Failure, PfStatus, status_call};
use super::{checked_mut_ptr, checked_ptr, input_slice, output_slice};
use crate::Params;
use crate::boundary::Aabb;
use crate::{Vec3, World};
use std::ffi::{c_char, c_uint};
use std::sync::{Arc, Mutex, MutexGuard, PoisonError, TryLockError};
use std::thread::JoinHandle;

/// Most particles one call may add (the world's own limit; indices must fit in 32 bits).
const MAX_PARTICLES_PER_CALL: usize = u32::MAX as usize / 64;

/// An opaque simulation world: fluid particles, boundary particles, parameters and its own
/// worker threads. Create it with `pf_world_create`, free it with `pf_world_destroy`.
///
/// Thread safety: a world may move between threads, but must not be used from two threads
/// at once; such a call is detected and returns `PF_ERROR_BUSY` without touching the world.
/// Distinct worlds are independent and may be stepped in parallel.
pub struct PfWorld {
    world: Mutex<World>,
    /// The world's worker threads, joined by `pf_world_destroy` so that none outlives it.
    threads: Vec<JoinHandle<()>>,
}

impl PfWorld {
    /// A world on a thread pool of `params.threads` workers whose threads can be joined.
    fn new(params: Params) -> Result<Self, Failure> {
        let handles = Arc::new(Mutex::new(Vec::new()));
        let spawned = Arc::clone(&handles);
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(params.threads)
            .thread_name(|i| format!("projfluid-{i}"))
            .spawn_handler(move |thread| {
                let mut builder = std::thread::Builder::new();
                if let Some(name) = thread.name() {
                    builder = builder.name(name.to_string());
                }
                let handle = builder.spawn(|| thread.run())?;
                spawned
                    .lock()
                    .unwrap_or_else(PoisonError::into_inner)
                    .push(handle);
                Ok(())
            })
            .build();
        let world = pool
            .map_err(|e| {
                Failure::invalid(format!(
                    "params->threads = {}: could not start the worker threads: {e}",
                    params.threads
                ))
            })
            .and_then(|pool| World::with_pool(params, pool).map_err(Failure::from));
        let threads = std::mem::take(&mut *handles.lock().unwrap_or_else(PoisonError::into_inner));
        match world {
            Ok(world) => Ok(Self {
                world: Mutex::new(world),
                threads,
            }),
            Err(failure) => {
                // The pool is gone already; wait for whatever threads it had started.
                threads.into_iter().for_each(|h| drop(h.join()));
                Err(failure)
            }
        }
    }

    /// Drops the world, which tells its pool to stop, then waits for every worker to exit,
    /// so that no library code runs after `pf_world_destroy` returns.
    fn shutdown(self) {
        let Self { world, threads } = self;
        drop(world);
        for handle in threads {
            // A worker that panicked has exited too; there is nothing left to report to.
            let _ = handle.join();
        }
    }
}

// The handle crosses threads in C; keep that sound.
const _: fn() = || {
    fn send_sync<T: Send + Sync>() {}
    send_sync::<PfWorld>();
};

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
    /// Outer (local/global) iterations of the last step.
    pub outer_iterations: usize,
    /// Inner linear-solver iterations of the last step, summed over its outer iterations.
    pub inner_iterations: usize,
    /// The last step stopped at `max_outer_iterations` instead of the displacement rule.
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

/// Locks the world behind `handle` for the duration of one call.
///
/// # Safety
/// `handle`, when non-NULL, must come from `pf_world_create` and not be destroyed.
pub(super) unsafe fn lock<'a>(handle: *const PfWorld) -> Result<MutexGuard<'a, World>, Failure> {
    let handle = checked_ptr(handle, "world")?;
    // SAFETY: a live handle from pf_world_create (the caller's promise); only shared access.
    let handle = unsafe { &*handle };
    handle.world.try_lock().map_err(|e| match e {
        TryLockError::WouldBlock => Failure::new(
            PfStatus::PF_ERROR_BUSY,
            "the world is being used by another thread; one world must be used by one thread at a time",
        ),
        TryLockError::Poisoned(_) => Failure::new(
            PfStatus::PF_ERROR_WORLD_POISONED,
            "the world panicked in an earlier call and may be inconsistent; destroy it",
        ),
    })
}

/// Checks a particle count: positive and at most the per-call limit.
pub(super) fn check_count(count: usize) -> Result<(), Failure> {
    if count == 0 {
        Err(Failure::invalid("count must be positive, got 0"))
    } else if count > MAX_PARTICLES_PER_CALL {
        Err(Failure::invalid(format!(
            "count must be at most {MAX_PARTICLES_PER_CALL}, got {count}"
        )))
    } else {
        Ok(())
    }
}

/// Reads `count` xyz triples from `xyz` into vectors, reporting allocation failure.
///
/// # Safety
/// `xyz`, when non-NULL, must point to `3·count` readable floats.
pub(super) unsafe fn read_vectors(
    xyz: *const f32,
    count: usize,
    what: &str,
) -> Result<Vec<Vec3>, Failure> {
    // SAFETY: forwarded from the caller; count ≤ MAX_PARTICLES_PER_CALL, so 3·count fits.
    let floats = unsafe { input_slice(xyz, 3 * count, what) }?;
    let mut out = Vec::new();
    out.try_reserve_exact(count)
        .map_err(|_| Failure::out_of_memory(what))?;
    out.extend(
        floats
            .chunks_exact(3)
            .map(|c| Vec3::new(c[0].into(), c[1].into(), c[2].into())),
    );
    Ok(out)
}

/// Reads a 3-vector from `p` (3 floats).
///
/// # Safety
/// `p`, when non-NULL, must point to 3 readable floats.
unsafe fn read_vec3(p: *const f32, what: &str) -> Result<Vec3, Failure> {
    // SAFETY: forwarded from the caller.
    let v = unsafe { input_slice(p, 3, what) }?;
    Ok(Vec3::new(v[0].into(), v[1].into(), v[2].into()))
}

/// Rejects a non-finite 3-vector argument, naming it.
fn check_finite(v: Vec3, what: &str) -> Result<Vec3, Failure> {
    if v.iter().all(|c| c.is_finite()) {
        Ok(v)
    } else {
        Err(Failure::invalid(format!(
            "{what} must be finite, got {:?}",
            v.as_slice()
        )))
    }
}

/// A world error whose message starts with the Rust argument name `rust`, renamed to the C
/// argument name `c` (e.g. `positions[3]` → `xyz[3]`).
fn renamed(error: crate::Error, rust: &str, c: &str) -> Failure {
    let text = error.to_string();
    Failure::invalid(match text.strip_prefix(rust) {
        Some(rest) => format!("{c}{rest}"),
        None => text,
    })
}

/// Writes `value` to `*out`.
///
/// # Safety
/// `out`, when non-NULL, must be writable.
unsafe fn write_out<T>(out: *mut T, value: T) -> Result<(), Failure> {
    let out = checked_mut_ptr(out, "out")?;
    // SAFETY: non-NULL and aligned; writability is the caller's promise.
    unsafe { out.write(value) };
    Ok(())
}

/// Creates a world with the parameters `*params` (validated; see `pf_params_default`) and
/// stores its handle in `*out`. The caller owns the world and frees it with
/// `pf_world_destroy`. On failure `*out` is set to NULL (when `out` is not NULL).
///
/// Errors: `PF_ERROR_NULL_POINTER` (params or out NULL), `PF_ERROR_INVALID_ARGUMENT` (a bad
/// parameter, named in the message).
///
/// # Safety
/// `params` must be NULL or point to a readable `PfParams`; `out` must be NULL or point to a writable `PfWorld*`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_create(
    params: *const PfParams,
    out: *mut *mut PfWorld,
) -> PfStatus {
    status_call("pf_world_create", || {
        let out = checked_mut_ptr(out, "out")?;
        // SAFETY: checked pointer; the caller promises it is writable.
        unsafe { out.write(std::ptr::null_mut()) };
        let params = checked_ptr(params, "params")?;
        // SAFETY: checked pointer; the caller promises it points to a PfParams.
        let params = unsafe { read_params(params) }?;
        let handle = Box::new(PfWorld::new(params)?);
        // SAFETY: as above.
        unsafe { out.write(Box::into_raw(handle)) };
        Ok(())
    })
}

/// Frees a world and everything it owns, waiting for its worker threads to exit.
/// NULL is a no-op. The handle must not be used afterwards, nor be in use by another
/// thread during the call.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create` that is not used again.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_destroy(world: *mut PfWorld) {
    let _ = status_call("pf_world_destroy", || {
        if !world.is_null() {
            // SAFETY: a handle from pf_world_create, destroyed once (the caller's promise).
            unsafe { Box::from_raw(world) }.shutdown();
        }
        Ok(())
    });
}

/// Adds `count` fluid particles at rest at positions `xyz` (3·count floats: x, y, z per
/// particle, metres). Particles are numbered in the order they are added across all calls.
///
/// Errors: `PF_ERROR_NULL_POINTER`, `PF_ERROR_INVALID_ARGUMENT` (count 0 or above the limit,
/// a non-finite coordinate — its index is named — or too many particles in total),
/// `PF_ERROR_OUT_OF_MEMORY`. On any error no particle is added.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`; `xyz` must be NULL or point to 3·count readable floats.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_add_fluid_particles(
    world: *mut PfWorld,
    xyz: *const f32,
    count: usize,
) -> PfStatus {
    status_call("pf_world_add_fluid_particles", || {
        // SAFETY: forwarded from the caller's promises (see the doc comment).
        unsafe { add_fluid(world, xyz, None, count) }
    })
}

/// Like `pf_world_add_fluid_particles`, with initial velocities `velocities` (3·count floats,
/// m/s). `velocities` may be NULL for particles at rest.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`; `xyz`, and `velocities` unless NULL, must be NULL or point to 3·count readable floats.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_add_fluid_particles_with_velocities(
    world: *mut PfWorld,
    xyz: *const f32,
    velocities: *const f32,
    count: usize,
) -> PfStatus {
    status_call("pf_world_add_fluid_particles_with_velocities", || {
        let velocities = (!velocities.is_null()).then_some(velocities);
        // SAFETY: forwarded from the caller's promises.
        unsafe { add_fluid(world, xyz, velocities, count) }
    })
}

/// The shared body of the two fluid-adding functions.
///
/// # Safety
/// As documented on `pf_world_add_fluid_particles`.
unsafe fn add_fluid(
    world: *mut PfWorld,
    xyz: *const f32,
    velocities: Option<*const f32>,
    count: usize,
) -> Result<(), Failure> {
    // SAFETY: forwarded.
    let mut world = unsafe { lock(world) }?;
    check_count(count)?;
    // SAFETY: forwarded.
    let positions = unsafe { read_vectors(xyz, count, "xyz") }?;
    let velocities = match velocities {
        // SAFETY: forwarded.
        Some(v) => Some(unsafe { read_vectors(v, count, "velocities") }?),
        None => None,
    };
    world
        .try_reserve_fluid(count)
        .map_err(|_| Failure::out_of_memory("fluid particles"))?;
    world
        .add_fluid_particles(&positions, velocities.as_deref())
        .map_err(|e| renamed(e, "positions", "xyz"))
}

/// Adds a box-shaped lattice of fluid particles with spacing 2r: centres at
/// `start + 2r·(i, j, k)` for i < count[0], j < count[1], k < count[2] (i fastest, then j,
/// then k, which is also the order the particles are numbered in). `start` is 3 floats (m),
/// `count` 3 sizes, `velocity` 3 floats (m/s) or NULL for particles at rest.
///
/// Errors: `PF_ERROR_NULL_POINTER`, `PF_ERROR_INVALID_ARGUMENT` (a zero count, a product
/// above the particle limit, non-finite start or velocity), `PF_ERROR_OUT_OF_MEMORY`.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`; `start` and `velocity` must be NULL or point to 3 readable floats, `count` to 3 readable sizes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_add_fluid_box(
    world: *mut PfWorld,
    start: *const f32,
    count: *const usize,
    velocity: *const f32,
) -> PfStatus {
    status_call("pf_world_add_fluid_box", || {
        // SAFETY: forwarded from the caller's promises.
        let mut world = unsafe { lock(world) }?;
        // SAFETY: as above.
        let start = check_finite(unsafe { read_vec3(start, "start") }?, "start")?;
        // SAFETY: as above.
        let counts = unsafe { input_slice(count, 3, "count") }?;
        let counts = [counts[0], counts[1], counts[2]];
        let velocity = if velocity.is_null() {
            Vec3::zeros()
        } else {
            // SAFETY: as above.
            check_finite(unsafe { read_vec3(velocity, "velocity") }?, "velocity")?
        };
        let total = counts.iter().try_fold(1usize, |a, &c| a.checked_mul(c));
        if let Some(n) = total.filter(|&n| n > 0 && n <= MAX_PARTICLES_PER_CALL) {
            world
                .try_reserve_fluid(n)
                .map_err(|_| Failure::out_of_memory("fluid particles"))?;
        }
        world.add_fluid_block(start, counts, velocity)?;
        Ok(())
    })
}

/// Adds `count` static boundary particles at `xyz` (3·count floats, metres), e.g. samples of
/// an obstacle's surface with spacing about r. Boundary particles never move.
///
/// Errors: as `pf_world_add_fluid_particles`.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`; `xyz` must be NULL or point to 3·count readable floats.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_add_boundary_particles(
    world: *mut PfWorld,
    xyz: *const f32,
    count: usize,
) -> PfStatus {
    status_call("pf_world_add_boundary_particles", || {
        // SAFETY: forwarded from the caller's promises.
        let mut world = unsafe { lock(world) }?;
        check_count(count)?;
        // SAFETY: as above.
        let positions = unsafe { read_vectors(xyz, count, "xyz") }?;
        world
            .try_reserve_boundary(count)
            .map_err(|_| Failure::out_of_memory("boundary particles"))?;
        world
            .add_boundary_particles(&positions)
            .map_err(|e| renamed(e, "positions", "xyz"))
    })
}

/// Adds a closed box container from corner `min` to corner `max` (3 floats each, metres):
/// its six walls are sampled with boundary particles, `layers` (1–3) layers thick, growing
/// outward. Fluid farther than r/2 outside every container counts as escaped.
///
/// Errors: `PF_ERROR_NULL_POINTER`, `PF_ERROR_INVALID_ARGUMENT` (non-finite corners, a side
/// shorter than two particle spacings or inverted, layers outside 1–3, a box needing too
/// many particles).
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`; `min` and `max` must be NULL or point to 3 readable floats.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_add_container_box(
    world: *mut PfWorld,
    min: *const f32,
    max: *const f32,
    layers: c_uint,
) -> PfStatus {
    status_call("pf_world_add_container_box", || {
        // SAFETY: forwarded from the caller's promises.
        let mut world = unsafe { lock(world) }?;
        // SAFETY: as above.
        let (min, max) = unsafe { (read_vec3(min, "min")?, read_vec3(max, "max")?) };
        let (min, max) = (check_finite(min, "min")?, check_finite(max, "max")?);
        world.add_container(Aabb { min, max }, layers as usize)?;
        Ok(())
    })
}

/// Takes one time step of `dt` seconds (0 < dt ≤ 1), or of the CFL-limited size when
/// `dt` ≤ 0 (the usual choice). The CFL rule sets the size of the next CFL step either way.
///
/// Errors: `PF_ERROR_INVALID_ARGUMENT` (dt NaN, infinite or above 1; no fluid particles).
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_step(world: *mut PfWorld, dt: f64) -> PfStatus {
    status_call("pf_world_step", || {
        // SAFETY: forwarded from the caller's promises.
        let mut world = unsafe { lock(world) }?;
        if !dt.is_finite() {
            return Err(Failure::invalid(format!(
                "dt must be finite (≤ 0 for the CFL step), got {dt}"
            )));
        }
        if dt <= 0.0 {
            world.step()?;
        } else {
            world.step_with_dt(dt)?;
        }
        Ok(())
    })
}

/// Takes CFL-limited steps until `seconds` more simulated time has passed (the last step
/// is shortened to land exactly). 0 takes no step.
///
/// Errors: `PF_ERROR_INVALID_ARGUMENT` (seconds negative or not finite; no fluid particles
/// while seconds > 0).
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_advance(world: *mut PfWorld, seconds: f64) -> PfStatus {
    status_call("pf_world_advance", || {
        // SAFETY: forwarded from the caller's promises.
        let mut world = unsafe { lock(world) }?;
        world.advance(seconds)?;
        Ok(())
    })
}

/// Relaxes the fluid towards its equilibrium: takes CFL-limited steps like
/// `pf_world_advance` for `seconds`, and after every step of Δt scales every fluid velocity
/// by exp(−`damping`·Δt) (`damping` in 1/s; 0 is `pf_world_advance`). A block of particles
/// on a lattice is not at rest under gravity; 10 s at 4/s bring a tank to its equilibrium
/// packing, from which it stays at rest under the calm settings (`pf_params_calm`).
///
/// Errors: `PF_ERROR_INVALID_ARGUMENT` (seconds or damping negative or not finite; no fluid
/// particles while seconds > 0), taking no step.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_relax(
    world: *mut PfWorld,
    seconds: f64,
    damping: f64,
) -> PfStatus {
    status_call("pf_world_relax", || {
        // SAFETY: forwarded from the caller's promises.
        let mut world = unsafe { lock(world) }?;
        world.relax(seconds, damping)?;
        Ok(())
    })
}

/// Stores the number of fluid particles in `*out`.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`; `out` must be NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_fluid_count(world: *const PfWorld, out: *mut usize) -> PfStatus {
    status_call("pf_world_fluid_count", || {
        // SAFETY: forwarded from the caller's promises.
        let n = unsafe { lock(world) }?.fluid_count();
        // SAFETY: as above.
        unsafe { write_out(out, n) }
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
    status_call("pf_world_boundary_count", || {
        // SAFETY: forwarded from the caller's promises.
        let n = unsafe { lock(world) }?.boundary_count();
        // SAFETY: as above.
        unsafe { write_out(out, n) }
    })
}

/// Stores the simulated time (s) in `*out`.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`; `out` must be NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_time(world: *const PfWorld, out: *mut f64) -> PfStatus {
    status_call("pf_world_time", || {
        // SAFETY: forwarded from the caller's promises.
        let t = unsafe { lock(world) }?.time();
        // SAFETY: as above.
        unsafe { write_out(out, t) }
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
    status_call("pf_world_get_params", || {
        // SAFETY: forwarded from the caller's promises.
        let p = PfParams::from(unsafe { lock(world) }?.params());
        // SAFETY: as above.
        unsafe { write_out(out, p) }
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
    status_call("pf_world_last_step_stats", || {
        // SAFETY: forwarded from the caller's promises.
        let world = unsafe { lock(world) }?;
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
        // SAFETY: as above.
        unsafe { write_out(out, stats) }
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
///
/// # Safety
/// As documented on `pf_world_get_positions`.
unsafe fn get(
    name: &str,
    quantity: Quantity,
    world: *const PfWorld,
    out: *mut f32,
    capacity: usize,
    needed: *mut usize,
) -> PfStatus {
    status_call(name, || {
        // SAFETY: forwarded from the caller's promises.
        let world = unsafe { lock(world) }?;
        let per_particle = match quantity {
            Quantity::Densities => 1,
            _ => 3,
        };
        let want = per_particle * world.fluid_count();
        if !needed.is_null() {
            // SAFETY: as above.
            unsafe { write_out(needed, want) }?;
        }
        if capacity < want {
            return Err(Failure::new(
                PfStatus::PF_ERROR_BUFFER_TOO_SMALL,
                format!("the buffer holds {capacity} floats but {want} are needed"),
            ));
        }
        // SAFETY: as above.
        let out = unsafe { output_slice(out, capacity, "out") }?;
        let written = match quantity {
            Quantity::Positions => world.write_positions_f32(out),
            Quantity::Velocities => world.write_velocities_f32(out),
            Quantity::Densities => world.write_densities_f32(out),
        };
        written.map_err(|n| Failure::new(PfStatus::PF_ERROR_BUFFER_TOO_SMALL, format!("{n}")))
    })
}

/// Copies the fluid positions (m) into `out` as x, y, z floats per particle, in the order
/// the particles were added. `capacity_floats` is the length of `out` in floats; 3·fluid
/// count are needed and written. `*needed` (when `needed` is not NULL) receives that number
/// on success and on `PF_ERROR_BUFFER_TOO_SMALL`, in which case `out` is untouched. `out`
/// may be NULL only with capacity 0, to query the size. The world is not changed.
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
    // SAFETY: forwarded from the caller's promises.
    unsafe {
        get(
            "pf_world_get_positions",
            Quantity::Positions,
            world,
            out,
            capacity_floats,
            needed,
        )
    }
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
    // SAFETY: forwarded from the caller's promises.
    unsafe {
        get(
            "pf_world_get_velocities",
            Quantity::Velocities,
            world,
            out,
            capacity_floats,
            needed,
        )
    }
}

/// Copies the fluid densities (kg/m³, 0 before the first step) into `out`, one float per
/// particle in the order the particles were added; otherwise like `pf_world_get_positions`.
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
    // SAFETY: forwarded from the caller's promises.
    unsafe {
        get(
            "pf_world_get_densities",
            Quantity::Densities,
            world,
            out,
            capacity_floats,
            needed,
        )
    }
}

/// Writes the hex SHA-256 of the fluid positions' exact (double precision) bit patterns, in
/// the order the particles were added, as a NUL-terminated string of 64 hex digits into
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
    status_call("pf_world_positions_hash", || {
        // SAFETY: forwarded from the caller's promises.
        let hash = unsafe { lock(world) }?.positions_hash();
        let want = hash.len() + 1;
        if !needed.is_null() {
            // SAFETY: as above.
            unsafe { write_out(needed, want) }?;
        }
        if capacity < want {
            return Err(Failure::new(
                PfStatus::PF_ERROR_BUFFER_TOO_SMALL,
                format!("the buffer holds {capacity} bytes but {want} are needed"),
            ));
        }
        // SAFETY: as above.
        let out = unsafe { output_slice(out.cast::<u8>(), capacity, "out") }?;
        out[..hash.len()].copy_from_slice(hash.as_bytes());
        out[hash.len()] = 0;
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ffi::pf_params_default;
    use crate::ffi::status::message;

    #[test]
    fn a_world_that_panicked_is_poisoned_until_destroyed() {
        let mut params = std::mem::MaybeUninit::<PfParams>::uninit();
        let mut world = std::ptr::null_mut();
        // SAFETY: valid out-pointers; the world is destroyed below.
        unsafe {
            assert_eq!(pf_params_default(params.as_mut_ptr()), PfStatus::PF_OK);
            let mut params = params.assume_init();
            params.threads = 1;
            assert_eq!(pf_world_create(&params, &mut world), PfStatus::PF_OK);
        }
        // A bug inside a call: the wrapper turns the panic into a status.
        let status = status_call("pf_test", || {
            // SAFETY: a live handle.
            let _world = unsafe { lock(world) }?;
            panic!("simulated bug")
        });
        assert_eq!(status, PfStatus::PF_ERROR_PANIC);
        assert!(message().contains("simulated bug"), "{}", message());
        // Every later call on that world refuses to touch it.
        let mut n = 0usize;
        // SAFETY: a live handle and a valid out-pointer.
        let status = unsafe { pf_world_fluid_count(world, &mut n) };
        assert_eq!(status, PfStatus::PF_ERROR_WORLD_POISONED);
        assert!(message().contains("destroy it"), "{}", message());
        // SAFETY: destroyed once, not used afterwards.
        unsafe { pf_world_destroy(world) };
    }
}
