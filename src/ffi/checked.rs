//! Checked access to what a C caller passes: the world handle, arrays, output buffers, single
//! outputs, `PfParams` and strings. An exported function vouches for its pointer arguments
//! once, by creating [`Args`] (its one `unsafe` line, covered by its `# Safety` section);
//! every access then checks NULL, alignment and size here, and a bad pointer becomes a
//! [`Failure`] (`PF_ERROR_NULL_POINTER` or `PF_ERROR_INVALID_ARGUMENT`) before anything is
//! read or written.

use super::params::{PfParams, read_params};
use super::status::{Failure, PfStatus};
use super::world::PfWorld;
use crate::{Params, World};
use std::ffi::{CStr, c_char};
use std::marker::PhantomData;
use std::sync::MutexGuard;

/// Checks that `p` is non-NULL and aligned for `T`; `what` names the argument in messages.
fn checked_ptr<T>(p: *const T, what: &str) -> Result<*const T, Failure> {
    if p.is_null() {
        Err(Failure::null(what))
    } else if !p.is_aligned() {
        Err(Failure::invalid(format!(
            "{what} is not aligned to {} bytes",
            align_of::<T>()
        )))
    } else {
        Ok(p)
    }
}

/// Whether `len` elements of `T` fit in one allocation (at most `isize::MAX` bytes).
fn fits<T>(len: usize) -> bool {
    len.checked_mul(size_of::<T>())
        .is_some_and(|b| b <= isize::MAX as usize)
}

/// The pointer arguments of one exported call, vouched for by its caller for the duration
/// `'a` of the call. Every method checks the pointer it is given before using it.
#[derive(Clone, Copy)]
pub(super) struct Args<'a>(PhantomData<&'a ()>);

impl<'a> Args<'a> {
    /// Access to the calling exported function's pointer arguments.
    ///
    /// # Safety
    /// Every pointer later given to a method, when non-NULL, must be what the calling
    /// function's `# Safety` section promises, for the whole call: a world handle from
    /// `pf_world_create` not yet destroyed; arrays of the length given, readable and
    /// initialised (inputs, written by no one during the call) or writable (outputs,
    /// accessed by no one else during the call); NUL-terminated strings.
    pub unsafe fn trusted() -> Self {
        Self(PhantomData)
    }

    /// The body of the per-particle reads: `want` values (named `unit` in the error, e.g.
    /// `floats`) are needed; `*needed` (when not NULL; checked as `needed_name`) receives
    /// `want` on success and on a short buffer; a buffer `out` of `capacity` values shorter
    /// than `want` is `PF_ERROR_BUFFER_TOO_SMALL` and stays untouched; otherwise `write`
    /// fills it.
    pub fn per_particle<T>(
        self,
        out: *mut T,
        capacity: usize,
        (needed, needed_name): (*mut usize, &str),
        (want, unit): (usize, &str),
        write: impl FnOnce(&mut [T]) -> Result<(), usize>,
    ) -> Result<(), Failure> {
        if !needed.is_null() {
            self.write(needed, want, needed_name)?;
        }
        let short = |message: String| Failure::new(PfStatus::PF_ERROR_BUFFER_TOO_SMALL, message);
        if capacity < want {
            return Err(short(format!(
                "the buffer holds {capacity} {unit} but {want} are needed"
            )));
        }
        let out = self.out_slice(out, capacity, "out")?;
        write(out).map_err(|n| short(format!("{n}")))
    }

    /// The world behind the handle `p` (the argument `world`), locked for the call.
    pub fn world(self, p: *const PfWorld) -> Result<MutexGuard<'a, World>, Failure> {
        let p = checked_ptr(p, "world")?;
        // SAFETY: non-NULL and aligned; a live handle (the contract of `trusted`). Only
        // shared access: the world inside is behind the handle's mutex.
        unsafe { &*p }.lock()
    }

    /// The world handle `p` back in a box, to be freed; `None` when `p` is NULL.
    pub fn take_world(self, p: *mut PfWorld) -> Option<Box<PfWorld>> {
        if p.is_null() {
            return None;
        }
        // SAFETY: a handle from `pf_world_create` (`Box::into_raw`), which the caller gives
        // back and never uses again (the contract of `trusted`).
        Some(unsafe { Box::from_raw(p) })
    }

    /// The caller's array `p[..len]`; `what` names the argument in messages.
    pub fn slice<T>(self, p: *const T, len: usize, what: &str) -> Result<&'a [T], Failure> {
        let p = checked_ptr(p, what)?;
        if !fits::<T>(len) {
            return Err(Failure::invalid(format!(
                "{what} is too long ({len} elements)"
            )));
        }
        // SAFETY: non-NULL, aligned, length in range; `len` readable, initialised `T`s that
        // no one writes during the call (the contract of `trusted`).
        Ok(unsafe { std::slice::from_raw_parts(p, len) })
    }

    /// The caller's buffer `p[..len]` to write into; `p` may be NULL only when `len` is 0.
    pub fn out_slice<T>(self, p: *mut T, len: usize, what: &str) -> Result<&'a mut [T], Failure> {
        if p.is_null() && len == 0 {
            return Ok(&mut []);
        }
        let p = checked_ptr(p.cast_const(), what)?.cast_mut();
        if !fits::<T>(len) {
            return Err(Failure::invalid(format!(
                "{what} capacity {len} is too large"
            )));
        }
        // SAFETY: non-NULL, aligned, length in range; `len` writable `T`s that no one else
        // accesses during the call (the contract of `trusted`).
        Ok(unsafe { std::slice::from_raw_parts_mut(p, len) })
    }

    /// Writes `value` to `*p`; `what` names the argument in messages.
    pub fn write<T>(self, p: *mut T, value: T, what: &str) -> Result<(), Failure> {
        let p = checked_ptr(p.cast_const(), what)?.cast_mut();
        // SAFETY: non-NULL and aligned; writable (the contract of `trusted`). `write` forms
        // no reference, so the memory need not be initialised.
        unsafe { p.write(value) };
        Ok(())
    }

    /// The validated [`Params`] in `*p` (see [`read_params`]); `what` names the argument.
    pub fn params(self, p: *const PfParams, what: &str) -> Result<Params, Failure> {
        let p = checked_ptr(p, what)?;
        // SAFETY: non-NULL and aligned; a readable `PfParams` (the contract of `trusted`).
        unsafe { read_params(p) }
    }

    /// The NUL-terminated string at `p`; `what` names the argument in messages.
    pub fn c_str(self, p: *const c_char, what: &str) -> Result<&'a CStr, Failure> {
        let p = checked_ptr(p, what)?;
        // SAFETY: non-NULL; NUL-terminated and unchanged during the call (the contract of
        // `trusted`).
        Ok(unsafe { CStr::from_ptr(p) })
    }
}
