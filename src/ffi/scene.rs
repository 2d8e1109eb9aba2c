//! Worlds made from scenes: a built-in scene by name or a JSON scene file (docs/scene-format.md),
//! through the same `Scene` the command line runs.

use super::checked::Args;
use super::status::{Failure, PfStatus, status_call};
use super::world::PfWorld;
use crate::scene::Scene;
use std::ffi::c_char;

/// Creates a world from a scene and stores its handle in `*out`: `name_or_path` (a
/// NUL-terminated UTF-8 string) is the name of a built-in scene (`dam_break_small`,
/// `fountain`, …; `projfluid scenes` lists them) or the path of a JSON scene file
/// (docs/scene-format.md). The world has the scene's parameters (read them with
/// `pf_world_get_params`; `threads` as the scene sets it, 0 = one per core), containers,
/// obstacles, rigid bodies (body `i` of the scene gets id `i`), fluid blocks, emitters, sinks
/// and domain, at time 0, ready to step; the scene's duration and output settings are not
/// part of a world. The same scene gives the same world as `projfluid run`, bit for bit.
/// The caller owns the world and frees it with `pf_world_destroy`. On failure `*out` is set to
/// NULL (when `out` is not NULL).
///
/// Errors: `PF_ERROR_NULL_POINTER` (name_or_path or out NULL), `PF_ERROR_INVALID_ARGUMENT`:
/// a string that is not UTF-8; a name that is neither a built-in scene nor an existing file
/// (the message lists the built-in names); a file that cannot be read, is not valid JSON or
/// not a valid scene (the message starts with the path and names the key and value, or the
/// line and column); an obstacle or body mesh that cannot be read or sampled
/// (`obstacles[i]: …`, `bodies[i]: …`); a scene whose `backend` is `"gpu"` where the GPU
/// cannot be had, or with what it does not step (as `pf_world_create`, `backend gpu: …`).
/// Thread safety: may be called from any thread; each call makes its own world.
///
/// # Safety
/// `name_or_path` must be NULL or a NUL-terminated string; `out` must be NULL or point to a writable `PfWorld*`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_create_from_scene(
    name_or_path: *const c_char,
    out: *mut *mut PfWorld,
) -> PfStatus {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call("pf_world_create_from_scene", || {
        args.write(out, std::ptr::null_mut(), "out")?;
        let name_or_path = args
            .c_str(name_or_path, "name_or_path")?
            .to_str()
            .map_err(|_| Failure::invalid("name_or_path must be UTF-8"))?;
        // Scene files are validated as they are read; built-in scenes are valid.
        let scene = Scene::resolve(name_or_path)?;
        let handle = PfWorld::new(scene.params.clone())?;
        // The world is new and owned here, so the lock is free.
        let filled = handle
            .lock()
            .and_then(|mut world| scene.fill_world(&mut world).map_err(Failure::from));
        match filled {
            Ok(()) => args.write(out, Box::into_raw(Box::new(handle)), "out"),
            Err(failure) => {
                handle.shutdown();
                Err(failure)
            }
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ffi::pf_world_destroy;
    use crate::ffi::status::message;

    fn create(name: &[u8]) -> (PfStatus, *mut PfWorld) {
        let mut world = std::ptr::NonNull::dangling().as_ptr(); // must be overwritten
        // SAFETY: a NUL-terminated string and a writable out-pointer.
        let status = unsafe { pf_world_create_from_scene(name.as_ptr().cast(), &mut world) };
        (status, world)
    }

    #[test]
    fn a_built_in_scene_becomes_the_world_the_rust_api_builds() {
        let (status, world) = create(b"dam_break_small\0");
        assert_eq!(status, PfStatus::PF_OK, "{}", message());
        // SAFETY: a live handle, locked only here.
        let c_world = unsafe { &*world }.lock().unwrap();
        let rust = Scene::builtin("dam_break_small")
            .unwrap()
            .build_world()
            .unwrap();
        assert_eq!(c_world.fluid_count(), rust.fluid_count());
        assert_eq!(c_world.boundary_count(), rust.boundary_count());
        assert_eq!(c_world.positions_hash(), rust.positions_hash());
        drop(c_world);
        // SAFETY: destroyed once.
        unsafe { pf_world_destroy(world) };
    }

    #[test]
    fn unknown_names_and_bad_strings_are_rejected_with_a_null_world() {
        let (status, world) = create(b"no_such_scene\0");
        assert_eq!(status, PfStatus::PF_ERROR_INVALID_ARGUMENT);
        assert!(world.is_null());
        let text = message();
        assert!(
            text.starts_with("pf_world_create_from_scene: scene `no_such_scene` is neither")
                && text.contains("dam_break_small"),
            "{text}"
        );
        let (status, world) = create(b"\xff\0");
        assert_eq!(status, PfStatus::PF_ERROR_INVALID_ARGUMENT);
        assert!(world.is_null());
        assert_eq!(
            message(),
            "pf_world_create_from_scene: name_or_path must be UTF-8"
        );
        let mut out = std::ptr::null_mut();
        // SAFETY: NULL is allowed and rejected.
        let status = unsafe { pf_world_create_from_scene(std::ptr::null(), &mut out) };
        assert_eq!(status, PfStatus::PF_ERROR_NULL_POINTER);
        assert_eq!(
            message(),
            "pf_world_create_from_scene: name_or_path must not be NULL"
        );
    }

    /// A scene whose `backend` is `"gpu"` makes no world in a build without the `gpu`
    /// feature: the message names the backend and the missing feature.
    #[cfg(not(feature = "gpu"))]
    #[test]
    fn a_scene_for_the_gpu_makes_no_world_without_the_feature() {
        let mut scene = Scene::builtin("dam_break_small").unwrap();
        scene.params.backend = crate::Backend::Gpu;
        let path = std::env::temp_dir().join(format!(
            "projfluid-ffi-gpu-scene-{}.json",
            std::process::id()
        ));
        std::fs::write(&path, scene.to_json()).unwrap();
        let mut name = path.to_str().unwrap().as_bytes().to_vec();
        name.push(0);
        let (status, world) = create(&name);
        std::fs::remove_file(&path).unwrap();
        assert_eq!(status, PfStatus::PF_ERROR_INVALID_ARGUMENT);
        assert!(world.is_null());
        assert_eq!(
            message(),
            "pf_world_create_from_scene: backend gpu: not available: this build of projfluid \
             has no `gpu` feature"
        );
    }
}
