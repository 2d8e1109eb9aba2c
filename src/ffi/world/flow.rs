//! The functions for fluid that enters and leaves a `PfWorld` (docs/method.md §12): emitters,
//! sinks, the domain, removal by id, and the emitted and removed counts.
//!
//! Emitters and sinks are addressed by their index, a `size_t` counting from 0 in the order
//! they were added to their world. Their vectors are `double`, like the bodies'.

use super::PfWorld;
use crate::boundary::Aabb;
use crate::emitter::{EmitterShape, EmitterSpec};
use crate::ffi::checked::Args;
use crate::ffi::status::{Failure, PfStatus, status_call};
use crate::{Error, Vec3};

/// Reads a finite 3-vector of doubles from `p`, naming it `what`.
fn read_point(args: Args, p: *const f64, what: &str) -> Result<Vec3, Failure> {
    let v = args.slice(p, 3, what)?;
    if v.iter().all(|c| c.is_finite()) {
        Ok(Vec3::new(v[0], v[1], v[2]))
    } else {
        Err(Failure::invalid(format!(
            "{what} must be finite, got {v:?}"
        )))
    }
}

/// The end time an `end_time` argument means: none for ≤ 0 or +∞, else itself; NaN is
/// rejected.
fn read_end_time(end_time: f64) -> Result<Option<f64>, Failure> {
    if end_time.is_nan() {
        Err(Failure::invalid(
            "end_time must be a time (s), or ≤ 0 or INFINITY for none, got NaN",
        ))
    } else if end_time <= 0.0 || end_time == f64::INFINITY {
        Ok(None)
    } else {
        Ok(Some(end_time))
    }
}

/// An emitter error with its field (`emitter.speed`, `emitter.shape.radius`, …) renamed to
/// the C argument (`speed`, `radius`, `half_a`, …); an error of the whole opening names its
/// size arguments and their values.
fn emitter_failure(error: Error, shape: &EmitterShape) -> Failure {
    let Error::InvalidArgument { field, message } = error else {
        return Failure::from(error);
    };
    let Some(rest) = message.strip_prefix(field.as_str()) else {
        return Failure::invalid(message);
    };
    let argument = match field.as_str() {
        "emitter.shape.radius" => "radius",
        "emitter.shape.half_extents[0]" => "half_a",
        "emitter.shape.half_extents[1]" => "half_b",
        "emitter.shape" => {
            // The value is the Rust shape: give the C arguments' values instead.
            let rule = rest.rsplit_once(", got ").map_or(rest, |(rule, _)| rule);
            return Failure::invalid(match *shape {
                EmitterShape::Disc { radius } => format!("radius{rule}, got {radius}"),
                EmitterShape::Rectangle {
                    half_extents: [a, b],
                } => format!("half_a, half_b{rule}, got {a}, {b}"),
            });
        }
        other => other.strip_prefix("emitter.").unwrap_or(other),
    };
    Failure::invalid(format!("{argument}{rest}"))
}

/// The shared body of the two emitter functions: every argument is checked, the output
/// pointer included, before the emitter is added.
#[allow(clippy::too_many_arguments)]
fn add_emitter(
    args: Args,
    world: *mut PfWorld,
    shape: EmitterShape,
    position: *const f64,
    direction: *const f64,
    speed: f64,
    end_time: f64,
    out_id: *mut usize,
) -> Result<(), Failure> {
    let mut world = args.world(world)?;
    let spec = EmitterSpec {
        shape,
        position: read_point(args, position, "position")?,
        direction: read_point(args, direction, "direction")?,
        speed,
        end_time: read_end_time(end_time)?,
    };
    let out = args.out_slice(out_id, 1, "out_id")?;
    out[0] = world
        .add_emitter(spec)
        .map_err(|e| emitter_failure(e, &shape))?;
    Ok(())
}

/// Adds an emitter with a disc-shaped opening of `radius` (m) centred on `position`
/// (3 doubles, m), in the plane normal to `direction` (3 doubles, any non-zero length), and
/// stores its index in `*out_id`. From the start of the next step it inserts fluid
/// particles moving at `speed` (m/s) along `direction`: a layer on a square lattice of
/// spacing 2r over the opening each time the layer before has travelled 2r (speed × area /
/// (2r)³ particles per second), skipping lattice points closer than 0.9 · 2r to fluid or
/// inside a solid, and settling the new particles next to walls, obstacles and bodies.
/// `end_time` (s) is the simulated time from which no more layers are emitted; a value ≤ 0
/// or `INFINITY` means none (the emitter runs forever). Emitted particles get new ids; see
/// `pf_world_emitted_count`.
///
/// Errors: `PF_ERROR_NULL_POINTER` (world, position, direction or out_id NULL),
/// `PF_ERROR_INVALID_ARGUMENT` (a non-finite position or direction, a zero direction, a
/// speed that is not positive and finite, a NaN end_time, a radius that is not positive and
/// finite or holds no lattice point — "zero area" — or far too many). On any error no
/// emitter is added and `*out_id` is untouched. Thread safety: one thread at a time per
/// world.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`; `position` and `direction` must be NULL or point to 3 readable doubles; `out_id` must be NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_add_emitter_disc(
    world: *mut PfWorld,
    position: *const f64,
    direction: *const f64,
    radius: f64,
    speed: f64,
    end_time: f64,
    out_id: *mut usize,
) -> PfStatus {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call("pf_world_add_emitter_disc", || {
        let shape = EmitterShape::Disc { radius };
        add_emitter(
            args, world, shape, position, direction, speed, end_time, out_id,
        )
    })
}

/// Like `pf_world_add_emitter_disc`, with a rectangular opening of half-extents `half_a`
/// and `half_b` (m) along the opening plane's first and second axes: the coordinate axis
/// least aligned with `direction` projected into the plane, and `direction` × that (x and z
/// for a direction −y, y and z for +x). Only whole lattice cells of side 2r count.
///
/// Errors: as `pf_world_add_emitter_disc`, with `half_a` or `half_b` named.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`; `position` and `direction` must be NULL or point to 3 readable doubles; `out_id` must be NULL or writable.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn pf_world_add_emitter_rect(
    world: *mut PfWorld,
    position: *const f64,
    direction: *const f64,
    half_a: f64,
    half_b: f64,
    speed: f64,
    end_time: f64,
    out_id: *mut usize,
) -> PfStatus {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call("pf_world_add_emitter_rect", || {
        let shape = EmitterShape::Rectangle {
            half_extents: [half_a, half_b],
        };
        add_emitter(
            args, world, shape, position, direction, speed, end_time, out_id,
        )
    })
}

/// Reads the box from `min` to `max` (3 doubles each, m): finite, `min` ≤ `max` per axis.
fn read_box(args: Args, min: *const f64, max: *const f64) -> Result<Aabb, Failure> {
    let (min, max) = (read_point(args, min, "min")?, read_point(args, max, "max")?);
    if let Some(a) = (0..3).find(|&a| min[a] > max[a]) {
        return Err(Failure::invalid(format!(
            "max must be at least min along every axis, got min[{a}] = {} > max[{a}] = {}",
            min[a], max[a]
        )));
    }
    Ok(Aabb { min, max })
}

/// Adds a sink, the box from `min` to `max` (3 doubles each, m), and stores its index in
/// `*out_id`: at the end of every step each fluid particle in it (faces included) is removed
/// (see `pf_world_removed_count`).
///
/// Errors: `PF_ERROR_NULL_POINTER` (world, min, max or out_id NULL),
/// `PF_ERROR_INVALID_ARGUMENT` (non-finite corners, or min > max along an axis). On any
/// error no sink is added and `*out_id` is untouched. Thread safety: one thread at a time
/// per world.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`; `min` and `max` must be NULL or point to 3 readable doubles; `out_id` must be NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_add_sink(
    world: *mut PfWorld,
    min: *const f64,
    max: *const f64,
    out_id: *mut usize,
) -> PfStatus {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call("pf_world_add_sink", || {
        let mut world = args.world(world)?;
        let sink = read_box(args, min, max)?;
        let out = args.out_slice(out_id, 1, "out_id")?;
        out[0] = world.add_sink(sink)?;
        Ok(())
    })
}

/// Sets the domain to the box from `min` to `max` (3 doubles each, m), replacing any
/// earlier one: at the end of every step each fluid particle outside it (faces count as
/// inside), or with a non-finite position, is removed. A new world has no domain.
///
/// Errors: `PF_ERROR_NULL_POINTER`, `PF_ERROR_INVALID_ARGUMENT` (non-finite corners, or
/// min > max along an axis); the domain is then unchanged. Thread safety: one thread at a
/// time per world.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`; `min` and `max` must be NULL or point to 3 readable doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_set_domain(
    world: *mut PfWorld,
    min: *const f64,
    max: *const f64,
) -> PfStatus {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call("pf_world_set_domain", || {
        let mut world = args.world(world)?;
        let domain = read_box(args, min, max)?;
        world.set_domain(Some(domain))?;
        Ok(())
    })
}

/// Removes the domain, if any: no particle is removed for leaving it any more.
///
/// Errors: `PF_ERROR_NULL_POINTER`. Thread safety: one thread at a time per world.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_clear_domain(world: *mut PfWorld) -> PfStatus {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call("pf_world_clear_domain", || {
        Ok(args.world(world)?.set_domain(None)?)
    })
}

/// Removes the fluid particles whose ids are `ids[0..count]` (see `pf_world_get_ids`) now,
/// between steps, and stores how many were removed (`count`) in `*removed`. The other
/// particles keep their ids and order; removed ids are never given again. `ids` may be NULL
/// when `count` is 0.
///
/// Errors: `PF_ERROR_NULL_POINTER` (world or removed NULL, or ids NULL with count > 0),
/// `PF_ERROR_INVALID_ARGUMENT` (an id that is not that of a fluid particle of the world —
/// never given, or removed already — or one listed twice; the id is named). On any error no
/// particle is removed and `*removed` is untouched. Thread safety: one thread at a time per
/// world.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`; `ids` must be NULL or point to `count` readable `uint64_t`s; `removed` must be NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_remove_particles(
    world: *mut PfWorld,
    ids: *const u64,
    count: usize,
    removed: *mut usize,
) -> PfStatus {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call("pf_world_remove_particles", || {
        let mut world = args.world(world)?;
        let ids = if count == 0 && ids.is_null() {
            &[]
        } else {
            args.slice(ids, count, "ids")?
        };
        let out = args.out_slice(removed, 1, "removed")?;
        out[0] = world.remove_particles(ids)?;
        Ok(())
    })
}

/// Stores in `*out` the number of fluid particles removed so far: by sinks, by the domain,
/// by `pf_world_remove_particles` and by closed solids added where fluid stood.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`; `out` must be NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_removed_count(world: *const PfWorld, out: *mut u64) -> PfStatus {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call("pf_world_removed_count", || {
        let n = args.world(world)?.removed_count();
        args.write(out, n, "out")
    })
}

/// Stores in `*out` the number of fluid particles inserted by emitters so far.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`; `out` must be NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_emitted_count(world: *const PfWorld, out: *mut u64) -> PfStatus {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call("pf_world_emitted_count", || {
        let n = args.world(world)?.emitted_count();
        args.write(out, n, "out")
    })
}
