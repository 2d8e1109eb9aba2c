//! `PfWorld`, the opaque handle over a [`World`], with the functions that create and destroy
//! it; the functions that fill it, let fluid in and out, choose its liquids, step it and read
//! it are in [`fill`], [`flow`], [`materials`], [`step`] and [`read`].

use super::checked::Args;
use super::params::PfParams;
use super::status::{Failure, PfStatus, call, status_call};
use crate::{Params, World};
use std::sync::{Arc, Mutex, MutexGuard, PoisonError, TryLockError};
use std::thread::JoinHandle;

// cbindgen lists functions in the order their modules are declared: fill, flow, materials,
// step, read (the blank line keeps rustfmt from sorting them).
mod fill;
mod flow;
mod materials;
mod step;

mod read;

pub use fill::*;
pub use flow::*;
pub use materials::*;
pub use read::*;
pub use step::*;

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
    pub(in crate::ffi) fn new(params: Params) -> Result<Self, Failure> {
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

    /// Locks the world for the duration of one call.
    pub(in crate::ffi) fn lock(&self) -> Result<MutexGuard<'_, World>, Failure> {
        self.world.try_lock().map_err(|e| match e {
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

    /// Drops the world, which tells its pool to stop, then waits for every worker to exit,
    /// so that no library code runs after `pf_world_destroy` returns.
    pub(in crate::ffi) fn shutdown(self) {
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

/// Creates a world with the parameters `*params` (validated; see `pf_params_default`) and
/// stores its handle in `*out`. The caller owns the world and frees it with
/// `pf_world_destroy`. On failure `*out` is set to NULL (when `out` is not NULL).
///
/// With `params->backend = PF_BACKEND_GPU` the world steps on the GPU, which is opened here.
///
/// Errors: `PF_ERROR_NULL_POINTER` (params or out NULL), `PF_ERROR_INVALID_ARGUMENT` (a bad
/// parameter, named in the message; and for the GPU, a message starting `backend gpu: `
/// that says what is missing: `not available: this build of projfluid has no `gpu`
/// feature`, no Vulkan adapter, or a solver the GPU backend does not run). No world is made then; there is no fallback to the CPU.
///
/// # Safety
/// `params` must be NULL or point to a readable `PfParams`; `out` must be NULL or point to a writable `PfWorld*`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_create(
    params: *const PfParams,
    out: *mut *mut PfWorld,
) -> PfStatus {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call("pf_world_create", || {
        args.write(out, std::ptr::null_mut(), "out")?;
        let params = args.params(params, "params")?;
        let handle = Box::new(PfWorld::new(params)?);
        args.write(out, Box::into_raw(handle), "out")
    })
}

/// Frees a world and everything it owns, waiting for its worker threads to exit.
/// NULL is a no-op. The handle must not be used afterwards, nor be in use by another
/// thread during the call. Returning nothing, it leaves the last error message alone.
///
/// # Safety
/// `world` must be NULL or a live handle from `pf_world_create` that is not used again.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_world_destroy(world: *mut PfWorld) {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    // `call`, not `status_call`: only status-returning calls clear the message.
    let _ = call("pf_world_destroy", || {
        if let Some(world) = args.take_world(world) {
            world.shutdown();
        }
        Ok(())
    });
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
        // SAFETY: a live handle.
        let args = unsafe { Args::trusted() };
        let status = status_call("pf_test", || {
            let _world = args.world(world)?;
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
