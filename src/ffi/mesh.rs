//! Obstacles in the C API: triangle meshes given as arrays or read from OBJ files, placed by
//! a `PfTransform`, their surfaces sampled with boundary particles.

use super::checked::Args;
use super::status::{Failure, status_call};
use super::world::{PfWorld, check_count, read_vectors};
use crate::boundary::Transform;
use crate::boundary::mesh::TriangleMesh;
use std::ffi::c_char;

/// Where a mesh goes: every vertex p becomes `translate + R·(scale ∘ p)`, i.e. a per-axis
/// scale about the origin, then a rotation, then a translation. The rotation is given as
/// Euler angles in degrees about the fixed world axes, applied x first, then y, then z
/// (R = R_z·R_y·R_x, right-handed). Fill it with `pf_transform_identity` and change what
/// you need. Plain data owned by the caller.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PfTransform {
    /// Scale factors along x, y and z (positive). Identity: 1, 1, 1.
    pub scale: [f64; 3],
    /// Rotation angles about the world x, y and z axes (degrees), applied in that order.
    pub rotate_deg: [f64; 3],
    /// Translation (m), applied last.
    pub translate: [f64; 3],
}

impl From<PfTransform> for Transform {
    fn from(t: PfTransform) -> Self {
        Transform {
            scale: t.scale,
            rotate_deg: t.rotate_deg,
            translate: t.translate,
        }
    }
}

/// Writes the identity transform (scale 1, no rotation, no translation) to `*out`.
///
/// Errors: `PF_ERROR_NULL_POINTER`.
///
/// # Safety
/// `out` must be NULL or point to a writable `PfTransform`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_transform_identity(out: *mut PfTransform) -> super::PfStatus {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call("pf_transform_identity", || {
        let t = Transform::default();
        let identity = PfTransform {
            scale: t.scale,
            rotate_deg: t.rotate_deg,
            translate: t.translate,
        };
        args.write(out, identity, "out")
    })
}

/// The transform behind `transform`: the identity when NULL, else the caller's, validated.
fn read_transform(args: Args, transform: *const PfTransform) -> Result<Transform, Failure> {
    if transform.is_null() {
        return Ok(Transform::default());
    }
    let t: Transform = args.slice(transform, 1, "transform")?[0].into();
    t.validate()
        .map_err(|e| Failure::invalid(format!("transform.{e}")))?;
    Ok(t)
}

/// Adds a static obstacle given as a triangle mesh: `vertex_count` vertices `vertices`
/// (3·vertex_count floats: x, y, z per vertex, metres) and `triangle_count` triangles
/// `indices` (3·triangle_count zero-based vertex indices). The surface is sampled by
/// Poisson disk with boundary particles about one particle radius r apart (no two closer
/// than r, no surface point farther than about 1.4·r from one), reproducibly (the same mesh
/// always gives the same particles). Winding does not matter, and the mesh need not be
/// closed or connected; only its surface is sampled. A closed mesh is kept: fluid added
/// later is not created inside it, fluid already inside it or nearer than r to its surface is
/// removed (counted by `pf_world_removed_count`), and the fluid next to it is settled
/// (docs/method.md §2.7).
///
/// Errors: `PF_ERROR_NULL_POINTER`, `PF_ERROR_INVALID_ARGUMENT` (a count of 0 or above the
/// limit; a non-finite vertex, named as `vertices[i]`; an index not below vertex_count,
/// named as `triangles[t][k]`, i.e. `indices[3·t + k]`; a degenerate triangle `triangles[t]`
/// with a repeated index or collinear corners; a mesh far larger than r or needing too many
/// particles), `PF_ERROR_OUT_OF_MEMORY`. On any error no particle is added.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`; `vertices` must be NULL or point to 3·vertex_count readable floats; `indices` must be NULL or point to 3·triangle_count readable `uint32_t`s.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_add_mesh(
    world: *mut PfWorld,
    vertices: *const f32,
    vertex_count: usize,
    indices: *const u32,
    triangle_count: usize,
) -> super::PfStatus {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call("pf_world_add_mesh", || {
        add_mesh(
            args,
            world,
            vertices,
            vertex_count,
            indices,
            triangle_count,
            None,
        )
    })
}

/// Like `pf_world_add_mesh`, with the mesh first placed by `*transform` (see
/// `PfTransform`; NULL means the identity). Transformed vertices are computed in double
/// precision.
///
/// Errors: those of `pf_world_add_mesh`, plus `PF_ERROR_INVALID_ARGUMENT` for a transform
/// with a non-finite component or a scale factor that is not positive (named as
/// `transform.scale` etc.), or one that makes a triangle degenerate. On any error no particle
/// is added.
///
/// # Safety
/// As `pf_world_add_mesh`; `transform` must be NULL or point to a readable `PfTransform`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_add_mesh_transformed(
    world: *mut PfWorld,
    vertices: *const f32,
    vertex_count: usize,
    indices: *const u32,
    triangle_count: usize,
    transform: *const PfTransform,
) -> super::PfStatus {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call("pf_world_add_mesh_transformed", || {
        let transform = read_transform(args, transform)?;
        add_mesh(
            args,
            world,
            vertices,
            vertex_count,
            indices,
            triangle_count,
            Some(transform),
        )
    })
}

/// Reads a mesh from the caller's arrays, places it and adds it to the world.
fn add_mesh(
    args: Args,
    world: *mut PfWorld,
    vertices: *const f32,
    vertex_count: usize,
    indices: *const u32,
    triangle_count: usize,
    transform: Option<Transform>,
) -> Result<(), Failure> {
    let mut world = args.world(world)?;
    let mut mesh = read_mesh(args, vertices, vertex_count, indices, triangle_count)?;
    if let Some(t) = transform {
        mesh = t
            .apply(&mesh)
            .map_err(|e| Failure::invalid(format!("after the transform, {e}")))?;
    }
    world.add_boundary_mesh(&mesh)?;
    Ok(())
}

/// The validated mesh in the caller's arrays: `vertex_count` xyz float triples at
/// `vertices` and `triangle_count` index triples at `indices` (see `pf_world_add_mesh`).
pub(super) fn read_mesh(
    args: Args,
    vertices: *const f32,
    vertex_count: usize,
    indices: *const u32,
    triangle_count: usize,
) -> Result<TriangleMesh, Failure> {
    check_count(vertex_count).map_err(|f| named(f, "vertex_count"))?;
    check_count(triangle_count).map_err(|f| named(f, "triangle_count"))?;
    let positions = read_vectors(args, vertices, vertex_count, "vertices")?;
    // triangle_count ≤ MAX_PARTICLES_PER_CALL, so 3·triangle_count fits.
    let flat = args.slice(indices, 3 * triangle_count, "indices")?;
    let mut triangles = Vec::new();
    triangles
        .try_reserve_exact(triangle_count)
        .map_err(|_| Failure::out_of_memory("indices"))?;
    triangles.extend(flat.chunks_exact(3).map(|t| [t[0], t[1], t[2]]));
    Ok(TriangleMesh::new(positions, triangles)?)
}

/// Adds a static obstacle read from the Wavefront OBJ file at `path` (a NUL-terminated
/// UTF-8 path; coordinates in metres), placed by `*transform` (NULL means the identity) and
/// sampled as in `pf_world_add_mesh`. Vertex positions and faces are used (polygons split
/// into triangle fans); normals, texture coordinates, lines and materials are ignored.
///
/// Errors: `PF_ERROR_NULL_POINTER` (world or path), `PF_ERROR_INVALID_ARGUMENT`: a path that
/// is not UTF-8, a file that cannot be read ("cannot read OBJ file PATH: …"), a file error
/// naming the file and line ("PATH:LINE: malformed face …", "… face vertex index 9 is out of
/// range …", "… face `f 1 2 2` is degenerate …"), a bad transform, or a mesh too large for
/// the particle radius. On any error no particle is added.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`; `path` must be NULL or a NUL-terminated string; `transform` must be NULL or point to a readable `PfTransform`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_add_obj(
    world: *mut PfWorld,
    path: *const c_char,
    transform: *const PfTransform,
) -> super::PfStatus {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call("pf_world_add_obj", || {
        let mut world = args.world(world)?;
        let path = args
            .c_str(path, "path")?
            .to_str()
            .map_err(|_| Failure::invalid("path must be UTF-8"))?;
        let transform = read_transform(args, transform)?;
        let mesh = crate::io::load_obj(std::path::Path::new(path))?;
        let mesh = transform
            .apply(&mesh)
            .map_err(|e| Failure::invalid(format!("{path}: after the transform, {e}")))?;
        world.add_boundary_mesh(&mesh)?;
        Ok(())
    })
}

/// `failure` with its leading word `count` replaced by the argument name `name`.
fn named(failure: Failure, name: &str) -> Failure {
    match failure.message.strip_prefix("count") {
        Some(rest) => Failure::new(failure.status, format!("{name}{rest}")),
        None => failure,
    }
}
