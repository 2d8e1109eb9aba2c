//! Rigid bodies in the C API (docs/method.md §11): adding boxes, spheres, cylinders and
//! triangle meshes as static, kinematic or dynamic bodies; moving them and reading their
//! poses, velocities and the fluid's loads is in [`motion`] and [`read`].
//!
//! Bodies are addressed by their id, a `size_t` counting from 0 in the order they were
//! added to their world; ids never change. Body vectors are `double` (unlike particle
//! arrays), so that poses and velocities cross the interface exactly.

use super::checked::Args;
use super::mesh::read_mesh;
use super::status::{Failure, PfStatus, status_call};
use super::world::PfWorld;
use crate::body::{BodyKind, BodyMass, BodySpec, Pose, Shape, Velocity};
use crate::boundary::mesh::TriangleMesh;
use crate::{BodyId, Vec3, World};
use std::ffi::c_int;

// cbindgen lists functions in the order their modules are declared: motion, then read (the
// blank line keeps rustfmt from sorting them).
mod motion;

mod read;

pub use motion::*;
pub use read::*;

/// How a body moves. Functions take it as an `int` holding one of these values, so that any
/// value a caller passes is checked instead of being undefined behaviour.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[allow(non_camel_case_types)]
pub enum PfBodyKind {
    /// Never moves; its particles join the walls'. Its pose and velocity cannot be set.
    PF_BODY_STATIC = 0,
    /// Moves as the program says (`pf_body_set_pose`, `pf_body_set_velocity`,
    /// `pf_body_set_target_pose`); the fluid does not move it.
    PF_BODY_KINEMATIC = 1,
    /// Moved by gravity and the fluid's force and torque; needs a density.
    PF_BODY_DYNAMIC = 2,
}

impl From<BodyKind> for PfBodyKind {
    fn from(kind: BodyKind) -> Self {
        match kind {
            BodyKind::Static => Self::PF_BODY_STATIC,
            BodyKind::Kinematic => Self::PF_BODY_KINEMATIC,
            BodyKind::Dynamic => Self::PF_BODY_DYNAMIC,
        }
    }
}

/// Where a body's frame is: the position of its origin in world coordinates (m) and its
/// orientation as a unit quaternion `w, x, y, z` (body frame → world). A body's shape or
/// mesh is given in its own frame, so the pose places it. The identity is position 0 and
/// rotation (1, 0, 0, 0) (`pf_pose_identity`). Inputs must be finite, with |q| within 1e-6
/// of 1 (the library normalises it). Plain data owned by the caller; the library copies it.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PfPose {
    /// The body frame's origin (m).
    pub position: [f64; 3],
    /// The orientation as a unit quaternion: w, x, y, z.
    pub rotation: [f64; 4],
}

impl From<Pose> for PfPose {
    fn from(pose: Pose) -> Self {
        Self {
            position: pose.position.into(),
            rotation: pose.wxyz(),
        }
    }
}

/// Writes the identity pose (origin 0, rotation w = 1, x = y = z = 0) to `*out`.
///
/// Errors: `PF_ERROR_NULL_POINTER`. Thread safety: may be called from any thread.
///
/// # Safety
/// `out` must be NULL or point to a writable `PfPose`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_pose_identity(out: *mut PfPose) -> PfStatus {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call("pf_pose_identity", || {
        args.write(out, Pose::default().into(), "out")
    })
}

/// The validated pose in `*pose`; errors name `pose.position` or `pose.rotation`.
pub(super) fn read_pose(args: Args, pose: *const PfPose) -> Result<Pose, Failure> {
    let p = args.slice(pose, 1, "pose")?[0];
    Pose::from_parts(Vec3::from(p.position), p.rotation)
        .map_err(|e| Failure::invalid(format!("pose.{e}")))
}

/// The body kind behind the int `kind`.
fn read_kind(kind: c_int) -> Result<BodyKind, Failure> {
    match kind {
        0 => Ok(BodyKind::Static),
        1 => Ok(BodyKind::Kinematic),
        2 => Ok(BodyKind::Dynamic),
        n => Err(Failure::invalid(format!(
            "kind must be a PfBodyKind (PF_BODY_STATIC, PF_BODY_KINEMATIC or PF_BODY_DYNAMIC), \
             got {n}"
        ))),
    }
}

/// The mass a density gives: 0 means none (not allowed for dynamic bodies); a positive
/// finite density fills the closed mesh; anything else is rejected.
fn read_density(kind: BodyKind, density: f64) -> Result<Option<BodyMass>, Failure> {
    if density == 0.0 && kind != BodyKind::Dynamic {
        Ok(None)
    } else if density == 0.0 {
        Err(Failure::invalid(
            "density must be positive for a dynamic body (PF_BODY_DYNAMIC), got 0",
        ))
    } else if density.is_finite() && density > 0.0 {
        Ok(Some(BodyMass::Density(density)))
    } else {
        Err(Failure::invalid(format!(
            "density must be 0 (none) or a positive finite number of kg/m³, got {density}"
        )))
    }
}

/// Checks that `id` names a body of `world`.
pub(super) fn check_id(world: &World, id: usize) -> Result<BodyId, Failure> {
    let n = world.bodies().len();
    if id < n {
        Ok(id)
    } else {
        Err(Failure::invalid(format!(
            "id {id} is not a body of this world, which has {n} bodies"
        )))
    }
}

/// A length argument that must be positive and finite (m).
fn positive(value: f64, what: &str) -> Result<f64, Failure> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(Failure::invalid(format!(
            "{what} must be a positive finite length (m), got {value}"
        )))
    }
}

/// The shared part of every add function: checks the arguments (all before anything
/// changes, the output pointer included), makes the mesh and adds the body.
#[allow(clippy::too_many_arguments)]
fn add_body(
    args: Args,
    world: *mut PfWorld,
    kind: c_int,
    mesh: impl FnOnce(f64) -> Result<TriangleMesh, Failure>,
    density: f64,
    pose: *const PfPose,
    out_id: *mut usize,
) -> Result<(), Failure> {
    let mut world = args.world(world)?;
    let kind = read_kind(kind)?;
    let mass = read_density(kind, density)?;
    let pose = read_pose(args, pose)?;
    let out = args.out_slice(out_id, 1, "out_id")?;
    let mesh = mesh(world.params().particle_radius)?;
    let id = world.add_body(BodySpec {
        kind,
        mesh,
        mass,
        pose,
        velocity: Velocity::default(),
        motion: None,
    })?;
    out[0] = id;
    Ok(())
}

/// Adds a box-shaped rigid body of `kind` (a `PfBodyKind`) with half-extents
/// `half_extents[0..3]` (m, along the body's x, y and z axes) centred on its frame's origin,
/// placed by `*pose`, and stores its id in `*out_id`. Its surface is sampled with boundary
/// particles about r apart (Poisson disk, as `pf_world_add_mesh`), reproducibly, and the
/// samples are set back r into the body (half way through parts thinner than 2r), so that
/// the fluid meets the box's own surface and a floating box displaces its own volume.
///
/// `density` (kg/m³) fills the box: it is required (> 0) for `PF_BODY_DYNAMIC` bodies,
/// whose mass and inertia it gives; for static and kinematic bodies 0 means none, and a
/// positive density only sets the centre of mass that torques are reported about (without
/// one, the centroid of the enclosed volume). Bodies start at rest; a static body never
/// moves. A closed body makes room for itself: fluid whose centre lies inside it or nearer
/// than r to its surface is removed (counted by `pf_world_removed_count`), and the fluid next
/// to it is settled (docs/method.md §2.7).
///
/// Errors: `PF_ERROR_NULL_POINTER` (world, half_extents, pose or out_id NULL),
/// `PF_ERROR_INVALID_ARGUMENT` (kind not a `PfBodyKind`; a density that is negative, NaN or
/// infinite, or 0 for a dynamic body; a half-extent that is not positive and finite, named
/// as `half_extents[i]`; a non-finite `pose.position`; a `pose.rotation` that is not finite
/// or whose length differs from 1 by more than 1e-6; a body far larger than r or needing too
/// many particles). On any error no body is added and `*out_id` is untouched.
/// Thread safety: one thread at a time per world.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`; `half_extents` must be NULL or point to 3 readable doubles; `pose` must be NULL or point to a readable `PfPose`; `out_id` must be NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_add_body_box(
    world: *mut PfWorld,
    kind: c_int,
    half_extents: *const f64,
    density: f64,
    pose: *const PfPose,
    out_id: *mut usize,
) -> PfStatus {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call("pf_world_add_body_box", || {
        let mesh = |r: f64| {
            let h = args.slice(half_extents, 3, "half_extents")?;
            for (i, &v) in h.iter().enumerate() {
                positive(v, &format!("half_extents[{i}]"))?;
            }
            let shape = Shape::Box {
                half_extents: Vec3::new(h[0], h[1], h[2]),
            };
            Ok(shape.mesh(r)?)
        };
        add_body(args, world, kind, mesh, density, pose, out_id)
    })
}

/// Adds a spherical rigid body of `radius` (m) centred on its frame's origin; otherwise as
/// `pf_world_add_body_box` (the sphere is a subdivided icosahedron fine enough for r).
///
/// Errors: as `pf_world_add_body_box`, with `radius` named when it is not positive and
/// finite. On any error no body is added. Thread safety: one thread at a time per world.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`; `pose` must be NULL or point to a readable `PfPose`; `out_id` must be NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_add_body_sphere(
    world: *mut PfWorld,
    kind: c_int,
    radius: f64,
    density: f64,
    pose: *const PfPose,
    out_id: *mut usize,
) -> PfStatus {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call("pf_world_add_body_sphere", || {
        let mesh = |r: f64| {
            let radius = positive(radius, "radius")?;
            Ok(Shape::Sphere { radius }.mesh(r)?)
        };
        add_body(args, world, kind, mesh, density, pose, out_id)
    })
}

/// Adds a cylindrical rigid body of `radius` and `height` (m) whose axis is its frame's y
/// axis, centred on its frame's origin; otherwise as `pf_world_add_body_box`.
///
/// Errors: as `pf_world_add_body_box`, with `radius` or `height` named when it is not
/// positive and finite. On any error no body is added. Thread safety: one thread at a time
/// per world.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`; `pose` must be NULL or point to a readable `PfPose`; `out_id` must be NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_add_body_cylinder(
    world: *mut PfWorld,
    kind: c_int,
    radius: f64,
    height: f64,
    density: f64,
    pose: *const PfPose,
    out_id: *mut usize,
) -> PfStatus {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call("pf_world_add_body_cylinder", || {
        let mesh = |r: f64| {
            let radius = positive(radius, "radius")?;
            let height = positive(height, "height")?;
            Ok(Shape::Cylinder { radius, height }.mesh(r)?)
        };
        add_body(args, world, kind, mesh, density, pose, out_id)
    })
}

/// Adds a rigid body whose surface is a triangle mesh given in the body's own frame, as in
/// `pf_world_add_mesh`: `vertex_count` vertices `vertices` (3·vertex_count floats, m) and
/// `triangle_count` triangles `indices` (3·triangle_count zero-based vertex indices). The
/// mesh is copied and kept with the body. Otherwise as `pf_world_add_body_box`: a density
/// (required for dynamic bodies) fills the mesh, which must then be closed and consistently
/// oriented (either orientation).
///
/// Errors: those of `pf_world_add_mesh` and of `pf_world_add_body_box`, plus
/// `PF_ERROR_INVALID_ARGUMENT` for a density given with a mesh that encloses no volume. On
/// any error no body is added. Thread safety: one thread at a time per world.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`; `vertices` must be NULL or point to 3·vertex_count readable floats; `indices` must be NULL or point to 3·triangle_count readable `uint32_t`s; `pose` must be NULL or point to a readable `PfPose`; `out_id` must be NULL or writable.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn pf_world_add_body_mesh(
    world: *mut PfWorld,
    kind: c_int,
    vertices: *const f32,
    vertex_count: usize,
    indices: *const u32,
    triangle_count: usize,
    density: f64,
    pose: *const PfPose,
    out_id: *mut usize,
) -> PfStatus {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call("pf_world_add_body_mesh", || {
        let mesh = |_: f64| read_mesh(args, vertices, vertex_count, indices, triangle_count);
        add_body(args, world, kind, mesh, density, pose, out_id)
    })
}

/// Stores the number of bodies in `*out`; their ids are 0 to that number minus 1.
///
/// Errors: `PF_ERROR_NULL_POINTER`. Thread safety: one thread at a time per world.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`; `out` must be NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_body_count(world: *const PfWorld, out: *mut usize) -> PfStatus {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call("pf_world_body_count", || {
        let n = args.world(world)?.bodies().len();
        args.write(out, n, "out")
    })
}
