//! Reading bodies without changing them: kind, pose, velocity, centre of mass and the
//! fluid's loads on a body and on the walls.

use super::{PfBodyKind, PfPose, check_id};
use crate::Vec3;
use crate::ffi::checked::Args;
use crate::ffi::status::{PfStatus, status_call};
use crate::ffi::world::PfWorld;

/// Stores the kind of body `id` in `*out`.
///
/// Errors: `PF_ERROR_NULL_POINTER`, `PF_ERROR_INVALID_ARGUMENT` (an unknown id, named).
/// Thread safety: one thread at a time per world.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`; `out` must be NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_body_get_kind(
    world: *const PfWorld,
    id: usize,
    out: *mut PfBodyKind,
) -> PfStatus {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call("pf_body_get_kind", || {
        let world = args.world(world)?;
        let id = check_id(&world, id)?;
        args.write(out, world.bodies()[id].kind().into(), "out")
    })
}

/// Stores the current pose of body `id` (its frame's origin in m and its unit quaternion
/// w, x, y, z) in `*out`. After a step, a moving body's pose is where the step left it.
///
/// Errors: `PF_ERROR_NULL_POINTER`, `PF_ERROR_INVALID_ARGUMENT` (an unknown id, named).
/// Thread safety: one thread at a time per world.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`; `out` must be NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_body_get_pose(
    world: *const PfWorld,
    id: usize,
    out: *mut PfPose,
) -> PfStatus {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call("pf_body_get_pose", || {
        let world = args.world(world)?;
        let id = check_id(&world, id)?;
        args.write(out, world.bodies()[id].pose().into(), "out")
    })
}

/// Copies two vectors into the caller's 3-double arrays `a` and `b`, both checked before
/// either is written.
fn write_pair(
    args: Args,
    (a, a_name): (*mut f64, &str),
    (b, b_name): (*mut f64, &str),
    values: (Vec3, Vec3),
) -> Result<(), crate::ffi::status::Failure> {
    let a = args.out_slice(a, 3, a_name)?;
    let b = args.out_slice(b, 3, b_name)?;
    a.copy_from_slice(values.0.as_slice());
    b.copy_from_slice(values.1.as_slice());
    Ok(())
}

/// Copies the velocity of body `id` into `linear[0..3]` (its centre of mass, m/s) and
/// `angular[0..3]` (about its centre of mass, rad/s, world axes). Static bodies report 0.
///
/// Errors: `PF_ERROR_NULL_POINTER` (either array NULL: neither is written),
/// `PF_ERROR_INVALID_ARGUMENT` (an unknown id, named). Thread safety: one thread at a time
/// per world.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`; `linear` and `angular` must be NULL or point to 3 writable doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_body_get_velocity(
    world: *const PfWorld,
    id: usize,
    linear: *mut f64,
    angular: *mut f64,
) -> PfStatus {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call("pf_body_get_velocity", || {
        let world = args.world(world)?;
        let id = check_id(&world, id)?;
        let v = world.bodies()[id].velocity();
        write_pair(
            args,
            (linear, "linear"),
            (angular, "angular"),
            (v.linear, v.angular),
        )
    })
}

/// Copies the centre of mass of body `id` in world coordinates (m) into `out[0..3]`: the
/// point its velocity and torque refer to. With a density it is the centre of mass of the
/// filled mesh; without, the centroid of the volume the mesh encloses (of its bounding box
/// for an open mesh).
///
/// Errors: `PF_ERROR_NULL_POINTER`, `PF_ERROR_INVALID_ARGUMENT` (an unknown id, named).
/// Thread safety: one thread at a time per world.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`; `out` must be NULL or point to 3 writable doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_body_get_centre_of_mass(
    world: *const PfWorld,
    id: usize,
    out: *mut f64,
) -> PfStatus {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call("pf_body_get_centre_of_mass", || {
        let world = args.world(world)?;
        let id = check_id(&world, id)?;
        let c = world.bodies()[id].centre_of_mass();
        args.out_slice(out, 3, "out")?.copy_from_slice(c.as_slice());
        Ok(())
    })
}

/// Copies the fluid's force on body `id` during the last step into `force[0..3]` (N) and its
/// torque about the body's centre of mass into `torque[0..3]` (N·m); both are 0 before the
/// first step. The load is the momentum the boundary particles of the body took from the
/// fluid in that step, followed through the solver's iteration (docs/method.md §11.3); an
/// engine's rigid solver can apply it for two-way coupling (see c_examples/coupling.c).
///
/// Errors: `PF_ERROR_NULL_POINTER` (either array NULL: neither is written),
/// `PF_ERROR_INVALID_ARGUMENT` (an unknown id, named). Thread safety: one thread at a time
/// per world.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`; `force` and `torque` must be NULL or point to 3 writable doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_body_get_force_torque(
    world: *const PfWorld,
    id: usize,
    force: *mut f64,
    torque: *mut f64,
) -> PfStatus {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call("pf_body_get_force_torque", || {
        let world = args.world(world)?;
        let id = check_id(&world, id)?;
        let b = &world.bodies()[id];
        write_pair(
            args,
            (force, "force"),
            (torque, "torque"),
            (b.force(), b.torque()),
        )
    })
}

/// Copies the fluid's force on the container walls, static obstacles and boundary particles
/// together during the last step into `force[0..3]` (N); static bodies report theirs
/// separately (`pf_body_get_force_torque`). It is measured only in worlds with bodies, and
/// is 0 otherwise and before the first step. Measured as the bodies' loads are.
///
/// Errors: `PF_ERROR_NULL_POINTER`. Thread safety: one thread at a time per world.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`; `force` must be NULL or point to 3 writable doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_get_wall_force(
    world: *const PfWorld,
    force: *mut f64,
) -> PfStatus {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call("pf_world_get_wall_force", || {
        let f = args.world(world)?.wall_force();
        args.out_slice(force, 3, "force")?
            .copy_from_slice(f.as_slice());
        Ok(())
    })
}
