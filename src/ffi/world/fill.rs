//! The functions that fill a `PfWorld`: fluid particles, fluid boxes, boundary particles and
//! box containers, with the checks of counts and vectors they share with the mesh functions.

use super::PfWorld;
use crate::Vec3;
use crate::boundary::Aabb;
use crate::ffi::checked::Args;
use crate::ffi::status::{Failure, PfStatus, status_call};
use std::ffi::c_uint;

/// Most particles one call may add (the world's own limit; indices must fit in 32 bits).
const MAX_PARTICLES_PER_CALL: usize = u32::MAX as usize / 64;

/// Checks a particle count: positive and at most the per-call limit.
pub(in crate::ffi) fn check_count(count: usize) -> Result<(), Failure> {
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
/// `count` must have passed [`check_count`], so that 3·count fits.
pub(in crate::ffi) fn read_vectors(
    args: Args,
    xyz: *const f32,
    count: usize,
    what: &str,
) -> Result<Vec<Vec3>, Failure> {
    let floats = args.slice(xyz, 3 * count, what)?;
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
fn read_vec3(args: Args, p: *const f32, what: &str) -> Result<Vec3, Failure> {
    let v = args.slice(p, 3, what)?;
    Ok(Vec3::new(v[0].into(), v[1].into(), v[2].into()))
}

/// Reads a container's corners `min` and `max` (3 floats each, m), each finite; the world
/// checks their order.
fn read_corners(args: Args, min: *const f32, max: *const f32) -> Result<Aabb, Failure> {
    let (min, max) = (read_vec3(args, min, "min")?, read_vec3(args, max, "max")?);
    let (min, max) = (check_finite(min, "min")?, check_finite(max, "max")?);
    Ok(Aabb { min, max })
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
    let failure = Failure::from(error);
    match failure.message.strip_prefix(rust) {
        Some(rest) => Failure::new(failure.status, format!("{c}{rest}")),
        None => failure,
    }
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
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call("pf_world_add_fluid_particles", || {
        add_fluid(args, world, xyz, None, count)
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
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call("pf_world_add_fluid_particles_with_velocities", || {
        let velocities = (!velocities.is_null()).then_some(velocities);
        add_fluid(args, world, xyz, velocities, count)
    })
}

/// The shared body of the two fluid-adding functions.
fn add_fluid(
    args: Args,
    world: *mut PfWorld,
    xyz: *const f32,
    velocities: Option<*const f32>,
    count: usize,
) -> Result<(), Failure> {
    let mut world = args.world(world)?;
    check_count(count)?;
    let positions = read_vectors(args, xyz, count, "xyz")?;
    let velocities = match velocities {
        Some(v) => Some(read_vectors(args, v, count, "velocities")?),
        None => None,
    };
    world
        .add_fluid_particles(&positions, velocities.as_deref())
        .map(|_| ())
        .map_err(|e| renamed(e, "positions", "xyz"))
}

/// Adds a box-shaped lattice of fluid particles with spacing 2r: centres at
/// `start + 2r·(i, j, k)` for i < count[0], j < count[1], k < count[2] (i fastest, then j,
/// then k, which is also the order the particles are numbered in). `start` is 3 floats (m),
/// `count` 3 sizes, `velocity` 3 floats (m/s) or NULL for particles at rest.
///
/// Errors: `PF_ERROR_NULL_POINTER`, `PF_ERROR_INVALID_ARGUMENT` (a zero count, a product
/// above the particle limit, non-finite start or velocity), `PF_ERROR_OUT_OF_MEMORY` (the
/// particles are written straight into storage reserved first). On any error no particle
/// is added.
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
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call("pf_world_add_fluid_box", || {
        let mut world = args.world(world)?;
        let start = check_finite(read_vec3(args, start, "start")?, "start")?;
        let counts = args.slice(count, 3, "count")?;
        let counts = [counts[0], counts[1], counts[2]];
        let velocity = if velocity.is_null() {
            Vec3::zeros()
        } else {
            check_finite(read_vec3(args, velocity, "velocity")?, "velocity")?
        };
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
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call("pf_world_add_boundary_particles", || {
        let mut world = args.world(world)?;
        check_count(count)?;
        let positions = read_vectors(args, xyz, count, "xyz")?;
        world
            .add_boundary_particles(&positions)
            .map_err(|e| renamed(e, "positions", "xyz"))
    })
}

/// Adds a closed box container from corner `min` to corner `max` (3 floats each, metres):
/// its six walls are sampled with boundary particles r apart, `layers` (1–3) layers thick,
/// growing outward. Fluid farther than r/2 outside every container counts as escaped.
/// `pf_world_add_container_box_spaced` samples the walls at another spacing.
///
/// Errors: `PF_ERROR_NULL_POINTER`, `PF_ERROR_INVALID_ARGUMENT` (non-finite corners, a side
/// shorter than two particle spacings or inverted, layers outside 1–3, a box needing too
/// many particles), `PF_ERROR_OUT_OF_MEMORY`. On any error no particle is added.
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
    // SAFETY: the caller keeps the contract above.
    unsafe { add_container_box("pf_world_add_container_box", world, min, max, layers, None) }
}

/// Adds a closed box container as `pf_world_add_container_box` does, its walls sampled with
/// boundary particles at most `spacing` metres apart, from r/4 to 2r (r is what
/// `pf_world_add_container_box` uses). Walls sampled at 2r hold a quarter of the particles;
/// what sparser walls gain and cost depends on the flow (docs/method.md §7).
///
/// Errors: those of `pf_world_add_container_box`, and `PF_ERROR_INVALID_ARGUMENT` for a
/// spacing outside r/4 to 2r or not finite. On any error no particle is added.
///
/// # Safety
/// As `pf_world_add_container_box`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_add_container_box_spaced(
    world: *mut PfWorld,
    min: *const f32,
    max: *const f32,
    layers: c_uint,
    spacing: f32,
) -> PfStatus {
    let spacing = Some(f64::from(spacing));
    let name = "pf_world_add_container_box_spaced";
    // SAFETY: the caller keeps the contract above.
    unsafe { add_container_box(name, world, min, max, layers, spacing) }
}

/// Adds a closed box container from corner `min` to corner `max` (each 3 floats, m) whose
/// six walls are fields rather than particles (docs/method.md §7): each adds to a fluid
/// particle's density, smoothly, what a wall of boundary particles r apart adds on average
/// along it, and costs nothing per boundary particle: a scene's `"walls": "field"`. Such
/// walls have no boundary particles, so `pf_world_boundary_count` does not count them. Fluid
/// farther than r/2 outside every container counts as escaped.
///
/// Errors: `PF_ERROR_NULL_POINTER`, `PF_ERROR_INVALID_ARGUMENT` (non-finite corners, a side
/// shorter than two particle spacings or inverted, a side longer than 10⁵·r),
/// `PF_ERROR_OUT_OF_MEMORY`. On any error the world is unchanged.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`; `min` and `max` must be NULL or point to 3 readable floats.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_add_container_field(
    world: *mut PfWorld,
    min: *const f32,
    max: *const f32,
) -> PfStatus {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call("pf_world_add_container_field", || {
        let mut world = args.world(world)?;
        world.add_container_field(read_corners(args, min, max)?)?;
        Ok(())
    })
}

/// The body of both container calls: the box with the default wall spacing, or `spacing`
/// (m). Reports errors as `name`.
///
/// # Safety
/// As `pf_world_add_container_box`.
unsafe fn add_container_box(
    name: &'static str,
    world: *mut PfWorld,
    min: *const f32,
    max: *const f32,
    layers: c_uint,
    spacing: Option<f64>,
) -> PfStatus {
    // SAFETY: the caller keeps the contract of `pf_world_add_container_box`.
    let args = unsafe { Args::trusted() };
    status_call(name, || {
        let mut world = args.world(world)?;
        let (container, layers) = (read_corners(args, min, max)?, layers as usize);
        match spacing {
            Some(spacing) => world.add_container_spaced(container, layers, spacing)?,
            None => world.add_container(container, layers)?,
        }
        Ok(())
    })
}
