//! Moving kinematic and dynamic bodies between steps: a new pose, a new velocity, or (for
//! kinematic bodies) the pose to reach at the end of the next step.

use super::{PfPose, check_id, read_pose};
use crate::body::{BodyKind, Velocity};
use crate::ffi::checked::Args;
use crate::ffi::status::{Failure, PfStatus, status_call};
use crate::ffi::world::PfWorld;
use crate::{BodyId, Vec3, World};

/// Checks that body `id` exists and may be moved: not static, and kinematic when `target`.
fn movable(world: &World, id: usize, target: bool) -> Result<BodyId, Failure> {
    let id = check_id(world, id)?;
    match world.bodies()[id].kind() {
        BodyKind::Static => Err(Failure::invalid(format!(
            "body {id} is static (PF_BODY_STATIC): its pose and velocity cannot change"
        ))),
        BodyKind::Dynamic if target => Err(Failure::invalid(format!(
            "body {id} is dynamic (PF_BODY_DYNAMIC): only kinematic bodies follow a target pose"
        ))),
        _ => Ok(id),
    }
}

/// A finite 3-vector of doubles read from `p`, named `what` in errors.
fn read_vector(args: Args, p: *const f64, what: &str) -> Result<Vec3, Failure> {
    let v = args.slice(p, 3, what)?;
    let v = Vec3::new(v[0], v[1], v[2]);
    if v.iter().all(|c| c.is_finite()) {
        Ok(v)
    } else {
        Err(Failure::invalid(format!(
            "{what} must be finite, got {:?}",
            v.as_slice()
        )))
    }
}

/// Moves kinematic or dynamic body `id` to `*pose` now (a teleport: its velocity stays, and
/// the next step moves it on from there), cancelling a target pose set before. The pose is
/// that of the body's frame (see `PfPose`).
///
/// Errors: `PF_ERROR_NULL_POINTER` (world or pose NULL), `PF_ERROR_INVALID_ARGUMENT` (an id
/// that is not a body of the world, named in the message; a static body; a non-finite
/// position; a rotation that is not finite or whose length differs from 1 by more than
/// 1e-6). On any error the body is unchanged. Thread safety: one thread at a time per world.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`; `pose` must be NULL or point to a readable `PfPose`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_body_set_pose(
    world: *mut PfWorld,
    id: usize,
    pose: *const PfPose,
) -> PfStatus {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call("pf_body_set_pose", || {
        let mut world = args.world(world)?;
        let id = movable(&world, id, false)?;
        let pose = read_pose(args, pose)?;
        Ok(world.set_body_pose(id, pose)?)
    })
}

/// Sets the velocity of kinematic or dynamic body `id`: `linear[0..3]`, of its centre of
/// mass (m/s), and `angular[0..3]`, about its centre of mass (rad/s, world axes). The next
/// step moves a kinematic body with it (and keeps it until it is set again); a dynamic body
/// starts from it and gravity and the fluid change it. Cancels a target pose set before.
///
/// Errors: `PF_ERROR_NULL_POINTER` (world, linear or angular NULL),
/// `PF_ERROR_INVALID_ARGUMENT` (an unknown id, named; a static body; a non-finite component,
/// naming `linear` or `angular`). On any error the body is unchanged. Thread safety: one
/// thread at a time per world.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`; `linear` and `angular` must be NULL or point to 3 readable doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_body_set_velocity(
    world: *mut PfWorld,
    id: usize,
    linear: *const f64,
    angular: *const f64,
) -> PfStatus {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call("pf_body_set_velocity", || {
        let mut world = args.world(world)?;
        let id = movable(&world, id, false)?;
        let velocity = Velocity {
            linear: read_vector(args, linear, "linear")?,
            angular: read_vector(args, angular, "angular")?,
        };
        Ok(world.set_body_velocity(id, velocity)?)
    })
}

/// Sets where kinematic body `id` is to be at the end of the next step: the step moves it
/// from its pose to `*pose`, with the velocity that takes it there in that step (linear of
/// the centre of mass, angular as the rotation's axis times its angle over the step's size),
/// which stays its velocity afterwards. Setting the pose or the velocity cancels it.
///
/// Errors: `PF_ERROR_NULL_POINTER` (world or pose NULL), `PF_ERROR_INVALID_ARGUMENT` (an
/// unknown id, named; a body that is not kinematic; a bad pose, as in `pf_body_set_pose`).
/// On any error the body is unchanged. Thread safety: one thread at a time per world.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`; `pose` must be NULL or point to a readable `PfPose`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_body_set_target_pose(
    world: *mut PfWorld,
    id: usize,
    pose: *const PfPose,
) -> PfStatus {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call("pf_body_set_target_pose", || {
        let mut world = args.world(world)?;
        let id = movable(&world, id, true)?;
        let pose = read_pose(args, pose)?;
        Ok(world.set_body_target_pose(id, pose)?)
    })
}
