//! The functions for several liquids in one `PfWorld` (docs/method.md §14): adding fluid
//! materials, choosing the one that fluid added next is made of, and reading the materials
//! back, per material and per particle.
//!
//! Materials are addressed by their id, a `uint16_t`: 0 is the world's own fluid (of
//! `PfParams.rest_density`), then 1, 2, … in the order `pf_world_add_material` added them.

use super::PfWorld;
use crate::Material;
use crate::ffi::checked::Args;
use crate::ffi::status::{Failure, PfStatus, status_call};
use crate::material::MaterialId;

/// The failure for a material id `material` that `world` does not have, naming the argument.
fn unknown_material(material: MaterialId, count: usize) -> Failure {
    Failure::invalid(format!(
        "material must name one of the world's {count} materials (0 to {}), got {material}",
        count - 1
    ))
}

/// Adds a fluid material of rest density `rest_density` (kg/m³) and stores its id in `*out`:
/// 1 for the first material added, then 2, 3, …; material 0 is the world's own fluid, of
/// `PfParams.rest_density`. Fluid of the new material is made once
/// `pf_world_set_fluid_material` chooses it. Every material shares the world's particle
/// radius, so a particle of material i weighs rest_density_i / `PfParams.rest_density` times
/// the world's particle mass, and its density reads about rest_density_i at rest
/// (docs/method.md §14).
///
/// Errors: `PF_ERROR_NULL_POINTER` (world or out NULL), `PF_ERROR_INVALID_ARGUMENT` (a
/// rest density that is not finite or lies outside 0.1 to 10 times the world's rest
/// density, the message giving the range in kg/m³; a world holding 256 materials already).
/// On any error no material is added and `*out` is untouched. Thread safety: one thread at a
/// time per world.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`; `out` must be NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_add_material(
    world: *mut PfWorld,
    rest_density: f64,
    out: *mut u16,
) -> PfStatus {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call("pf_world_add_material", || {
        let mut world = args.world(world)?;
        // Checked before the material is added, so that a bad `out` adds nothing.
        let out = args.out_slice(out, 1, "out")?;
        out[0] = world.add_material(Material::with_density(rest_density))?;
        Ok(())
    })
}

/// Chooses `material` as the material of the fluid added from now on: by
/// `pf_world_add_fluid_particles`, `pf_world_add_fluid_particles_with_velocities`,
/// `pf_world_add_fluid_box`, and by the emitters added from now on (`pf_world_add_emitter_disc`,
/// `pf_world_add_emitter_rect`; an emitter keeps the material chosen when it was added).
/// Fluid already in the world keeps its material. A new world makes fluid of material 0.
///
/// Errors: `PF_ERROR_NULL_POINTER` (world NULL), `PF_ERROR_INVALID_ARGUMENT` (a material the
/// world does not have, the message giving the valid range). On any error the choice is
/// unchanged. Thread safety: one thread at a time per world.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_set_fluid_material(
    world: *mut PfWorld,
    material: u16,
) -> PfStatus {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call("pf_world_set_fluid_material", || {
        Ok(args.world(world)?.set_fluid_material(material)?)
    })
}

/// Stores in `*out` the material the fluid added next is made of: 0, the world's own fluid,
/// until `pf_world_set_fluid_material` chooses another.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`; `out` must be NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_fluid_material(world: *const PfWorld, out: *mut u16) -> PfStatus {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call("pf_world_fluid_material", || {
        let material = args.world(world)?.fluid_material();
        args.write(out, material, "out")
    })
}

/// Stores in `*out` the number of materials, the world's own fluid included: 1 in a new
/// world, and the valid material ids are 0 to `*out` − 1.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`; `out` must be NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_material_count(
    world: *const PfWorld,
    out: *mut usize,
) -> PfStatus {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call("pf_world_material_count", || {
        let n = args.world(world)?.material_count();
        args.write(out, n, "out")
    })
}

/// Writes `property` of `material` into `*out` for the function `name`: the shared body of
/// the per-material reads.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`; `out` must be NULL or writable.
unsafe fn read_material(
    name: &'static str,
    world: *const PfWorld,
    material: u16,
    out: *mut f64,
    property: fn(&Material) -> f64,
) -> PfStatus {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call(name, || {
        let world = args.world(world)?;
        let found = world
            .material(material)
            .ok_or_else(|| unknown_material(material, world.material_count()))?;
        args.write(out, property(&found), "out")
    })
}

/// Stores in `*out` the rest density (kg/m³) of `material`: `PfParams.rest_density` for
/// material 0, and for the others the value `pf_world_add_material` was given.
///
/// Errors: `PF_ERROR_NULL_POINTER` (world or out NULL), `PF_ERROR_INVALID_ARGUMENT` (a
/// material the world does not have, the message giving the valid range); `*out` is then
/// untouched.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`; `out` must be NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_get_material_rest_density(
    world: *const PfWorld,
    material: u16,
    out: *mut f64,
) -> PfStatus {
    let name = "pf_world_get_material_rest_density";
    // SAFETY: the caller keeps the contract above, which is read_material's.
    unsafe { read_material(name, world, material, out, |m| m.rest_density) }
}

/// Sets the kinematic viscosity ν (m²/s) of `material` from the next step on: 0 leaves it
/// without physical viscosity, water is 1e-6, honey 1e-2 and more (docs/method.md §13).
/// Material 0 is the world's own fluid, whose `PfParams.kinematic_viscosity` was its
/// viscosity so far; other materials start without one. Where two materials meet, the
/// solve couples them with the harmonic mean of their viscosities.
///
/// Errors: `PF_ERROR_NULL_POINTER` (world NULL), `PF_ERROR_INVALID_ARGUMENT` (a material
/// the world does not have, the message giving the valid range; a viscosity that is
/// negative or not finite). On any error nothing changes. Thread safety: one thread at a time per world.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_set_material_kinematic_viscosity(
    world: *mut PfWorld,
    material: u16,
    kinematic_viscosity: f64,
) -> PfStatus {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call("pf_world_set_material_kinematic_viscosity", || {
        let mut world = args.world(world)?;
        Ok(world.set_material_kinematic_viscosity(material, kinematic_viscosity)?)
    })
}

/// Stores in `*out` the kinematic viscosity ν (m²/s) of `material`: for material 0
/// `PfParams.kinematic_viscosity` until `pf_world_set_material_kinematic_viscosity` sets
/// it, for the others 0 until it does.
///
/// Errors: `PF_ERROR_NULL_POINTER` (world or out NULL), `PF_ERROR_INVALID_ARGUMENT` (a
/// material the world does not have, the message giving the valid range); `*out` is then
/// untouched.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`; `out` must be NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_get_material_kinematic_viscosity(
    world: *const PfWorld,
    material: u16,
    out: *mut f64,
) -> PfStatus {
    let name = "pf_world_get_material_kinematic_viscosity";
    // SAFETY: the caller keeps the contract above, which is read_material's.
    unsafe { read_material(name, world, material, out, |m| m.kinematic_viscosity) }
}

/// Sets the surface tension σ (N/m) of `material` from the next step on: 0 leaves it
/// without surface tension (and costs nothing), water against air is 0.0728
/// (docs/method.md §17). Material 0 is the world's own fluid, whose
/// `PfParams.surface_tension` was its surface tension so far; other materials start without
/// one. Each particle at the fluid's free surface is pulled with its own material's σ; where
/// two liquids meet there is no surface force. A world with surface tension limits its steps
/// by the capillary rule (docs/method.md §8).
///
/// Errors: `PF_ERROR_NULL_POINTER` (world NULL), `PF_ERROR_INVALID_ARGUMENT` (a material
/// the world does not have, the message giving the valid range; a surface tension that is
/// negative or not finite; a positive surface tension on a world that steps on the GPU,
/// which does not support it yet, the message naming `surface_tension`). On any error
/// nothing changes. Thread safety: one thread at a time per world.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_set_material_surface_tension(
    world: *mut PfWorld,
    material: u16,
    surface_tension: f64,
) -> PfStatus {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call("pf_world_set_material_surface_tension", || {
        let mut world = args.world(world)?;
        Ok(world.set_material_surface_tension(material, surface_tension)?)
    })
}

/// Stores in `*out` the surface tension σ (N/m) of `material`: for material 0
/// `PfParams.surface_tension` until `pf_world_set_material_surface_tension` sets it, for
/// the others 0 until it does.
///
/// Errors: `PF_ERROR_NULL_POINTER` (world or out NULL), `PF_ERROR_INVALID_ARGUMENT` (a
/// material the world does not have, the message giving the valid range); `*out` is then
/// untouched.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`; `out` must be NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_get_material_surface_tension(
    world: *const PfWorld,
    material: u16,
    out: *mut f64,
) -> PfStatus {
    let name = "pf_world_get_material_surface_tension";
    // SAFETY: the caller keeps the contract above, which is read_material's.
    unsafe { read_material(name, world, material, out, |m| m.surface_tension) }
}

/// Copies every fluid particle's material id into `out`, in ascending id order, the order
/// of every other per-particle read (`pf_world_get_positions`, `pf_world_get_densities`,
/// `pf_world_get_ids`, …). `capacity` is the length of `out` in ids; fluid count are needed
/// and written. `*needed` (when `needed` is not NULL) receives that number on success and
/// on `PF_ERROR_BUFFER_TOO_SMALL`, in which case `out` is untouched. `out` may be NULL only
/// with capacity 0, to query the size. The world is not changed.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create`; `out` must be NULL or point to `capacity` writable `uint16_t`s; `needed` must be NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_get_materials(
    world: *const PfWorld,
    out: *mut u16,
    capacity: usize,
    needed: *mut usize,
) -> PfStatus {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call("pf_world_get_materials", || {
        let world = args.world(world)?;
        let want = world.fluid_count();
        let unit = "material ids";
        args.per_particle(out, capacity, (needed, "needed"), (want, unit), |out| {
            world.write_materials(out)
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ffi::params::PfParams;
    use crate::ffi::status::message;
    use crate::ffi::{
        pf_params_default, pf_world_add_container_box, pf_world_add_fluid_box, pf_world_create,
        pf_world_destroy, pf_world_remove_particles, pf_world_step,
    };
    use std::ptr::{null, null_mut};

    /// A world of 27 particles of water, then 8 of material 1 (1500 kg/m³) and 8 more of
    /// water, in a box.
    fn two_liquids() -> *mut PfWorld {
        let mut params = std::mem::MaybeUninit::<PfParams>::uninit();
        let mut world = null_mut();
        let (lo, hi) = ([0.0f32; 3], [0.5f32; 3]);
        // SAFETY: valid pointers throughout; the caller destroys the world.
        unsafe {
            assert_eq!(pf_params_default(params.as_mut_ptr()), PfStatus::PF_OK);
            let mut params = params.assume_init();
            params.threads = 1;
            assert_eq!(pf_world_create(&params, &mut world), PfStatus::PF_OK);
            let status = pf_world_add_container_box(world, lo.as_ptr(), hi.as_ptr(), 1);
            assert_eq!(status, PfStatus::PF_OK);
            let add = |start: [f32; 3], n: usize| {
                let count = [n; 3];
                let status = pf_world_add_fluid_box(world, start.as_ptr(), count.as_ptr(), null());
                assert_eq!(status, PfStatus::PF_OK, "{}", message());
            };
            add([0.05; 3], 3);
            let mut heavy = 0u16;
            assert_eq!(
                pf_world_add_material(world, 1500.0, &mut heavy),
                PfStatus::PF_OK
            );
            assert_eq!(heavy, 1);
            assert_eq!(pf_world_set_fluid_material(world, heavy), PfStatus::PF_OK);
            add([0.3, 0.05, 0.05], 2);
            assert_eq!(pf_world_set_fluid_material(world, 0), PfStatus::PF_OK);
            add([0.05, 0.3, 0.3], 2);
        }
        world
    }

    /// The per-particle read gives `World::particle_materials`, in the order of the ids,
    /// after steps (which sort the particles) and after removals (which break 0..n).
    #[test]
    fn materials_read_in_the_order_of_the_ids_and_of_particle_materials() {
        let world = two_liquids();
        let read = || {
            let mut needed = 0usize;
            // SAFETY: a live world; a NULL buffer of capacity 0.
            let status = unsafe { pf_world_get_materials(world, null_mut(), 0, &mut needed) };
            assert_eq!(status, PfStatus::PF_ERROR_BUFFER_TOO_SMALL);
            let mut out = vec![u16::MAX; needed];
            // SAFETY: `out` holds `needed` ids.
            let status =
                unsafe { pf_world_get_materials(world, out.as_mut_ptr(), out.len(), null_mut()) };
            assert_eq!(status, PfStatus::PF_OK);
            // SAFETY: a live handle, used by this thread only.
            let expected = unsafe { &*world }.lock().unwrap().particle_materials();
            assert_eq!(out, expected);
            out
        };
        let before = read();
        let expected: Vec<u16> = [vec![0; 27], vec![1; 8], vec![0; 8]].concat();
        assert_eq!(before, expected);
        // SAFETY: a live world and valid pointers.
        unsafe {
            for _ in 0..3 {
                assert_eq!(pf_world_step(world, 0.0), PfStatus::PF_OK);
            }
            assert_eq!(read(), expected);
            let (ids, mut removed) = ([3u64, 28, 40], 0usize);
            let status = pf_world_remove_particles(world, ids.as_ptr(), 3, &mut removed);
            assert_eq!(status, PfStatus::PF_OK);
        }
        let mut left = expected.clone();
        for i in [40, 28, 3] {
            left.remove(i);
        }
        assert_eq!(read(), left);
        // SAFETY: a live world.
        unsafe {
            assert_eq!(pf_world_step(world, 0.0), PfStatus::PF_OK);
        }
        assert_eq!(read(), left);
        // SAFETY: destroyed once, not used afterwards.
        unsafe { pf_world_destroy(world) };
    }

    #[test]
    fn bad_materials_are_refused_naming_the_argument() {
        let world = two_liquids();
        let (mut id, mut rho, mut n) = (77u16, -1.0f64, 0usize);
        // SAFETY: a live world and valid (or NULL) pointers.
        unsafe {
            for bad in [f64::NAN, f64::INFINITY, 0.0, 99.0, 10_001.0, -1000.0] {
                let status = pf_world_add_material(world, bad, &mut id);
                assert_eq!(status, PfStatus::PF_ERROR_INVALID_ARGUMENT, "{bad}");
                assert!(message().starts_with("pf_world_add_material: rest_density"));
            }
            assert_eq!(
                pf_world_add_material(world, 1200.0, null_mut()),
                PfStatus::PF_ERROR_NULL_POINTER
            );
            assert_eq!(message(), "pf_world_add_material: out must not be NULL");
            assert_eq!(id, 77);
            assert_eq!(pf_world_material_count(world, &mut n), PfStatus::PF_OK);
            assert_eq!(n, 2);
            assert_eq!(
                pf_world_set_fluid_material(world, 2),
                PfStatus::PF_ERROR_INVALID_ARGUMENT
            );
            assert!(message().contains("material"), "{}", message());
            let status = pf_world_get_material_rest_density(world, 9, &mut rho);
            assert_eq!(status, PfStatus::PF_ERROR_INVALID_ARGUMENT);
            assert_eq!(
                message(),
                "pf_world_get_material_rest_density: material must name one of the world's \
                 2 materials (0 to 1), got 9"
            );
            assert_eq!(rho, -1.0);
            let status = pf_world_get_material_rest_density(world, 1, &mut rho);
            assert_eq!(status, PfStatus::PF_OK);
            assert_eq!(rho, 1500.0);
            pf_world_destroy(world);
        }
    }

    /// A material's viscosity is set and read back; bad ones and bad ids change nothing.
    #[test]
    fn material_viscosities_are_set_read_and_checked() {
        let world = two_liquids();
        let mut nu = -1.0f64;
        let set = |material: u16, nu: f64| {
            // SAFETY: a live world.
            unsafe { pf_world_set_material_kinematic_viscosity(world, material, nu) }
        };
        let get = |material: u16, out: *mut f64| {
            // SAFETY: a live world; `out` is NULL or points to an f64.
            unsafe { pf_world_get_material_kinematic_viscosity(world, material, out) }
        };
        assert_eq!(get(1, &mut nu), PfStatus::PF_OK);
        assert_eq!(nu, 0.0);
        assert_eq!(set(1, 0.05), PfStatus::PF_OK);
        for bad in [f64::NAN, -1.0, f64::INFINITY] {
            assert_eq!(set(1, bad), PfStatus::PF_ERROR_INVALID_ARGUMENT, "{bad}");
            assert!(
                message()
                    .starts_with("pf_world_set_material_kinematic_viscosity: kinematic_viscosity"),
                "{}",
                message()
            );
        }
        assert_eq!(set(5, 0.1), PfStatus::PF_ERROR_INVALID_ARGUMENT);
        assert!(message().contains("material"), "{}", message());
        assert_eq!(get(1, &mut nu), PfStatus::PF_OK);
        assert_eq!(nu, 0.05);
        assert_eq!(get(0, &mut nu), PfStatus::PF_OK);
        assert_eq!(nu, 0.0);
        assert_eq!(get(1, null_mut()), PfStatus::PF_ERROR_NULL_POINTER);
        assert_eq!(get(3, &mut nu), PfStatus::PF_ERROR_INVALID_ARGUMENT);
        assert_eq!(nu, 0.0);
        // SAFETY: NULL is refused before anything is read.
        let status = unsafe { pf_world_set_material_kinematic_viscosity(null_mut(), 0, 0.1) };
        assert_eq!(status, PfStatus::PF_ERROR_NULL_POINTER);
        // SAFETY: destroyed once, not used afterwards.
        unsafe { pf_world_destroy(world) };
    }
}
