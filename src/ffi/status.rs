//! Status codes, the thread-local last-error message, and the one wrapper every exported
//! function goes through ([`call`]): it catches panics, turns failures into a [`PfStatus`] and
//! records a message that [`pf_last_error_message`] returns.

use std::cell::RefCell;
use std::ffi::{CString, c_char, c_int};
use std::panic::{self, AssertUnwindSafe};

/// What a `pf_` function did. Every function that can fail returns one of these; on anything
/// but `PF_OK` the call changed nothing and `pf_last_error_message` explains why.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[allow(non_camel_case_types)]
pub enum PfStatus {
    /// Success.
    PF_OK = 0,
    /// A required pointer argument was NULL.
    PF_ERROR_NULL_POINTER = 1,
    /// An argument was out of range, non-finite, inconsistent or misaligned, or the world was
    /// not in a state that allows the call (e.g. stepping a world without fluid).
    PF_ERROR_INVALID_ARGUMENT = 2,
    /// An output buffer was too short; the size needed was written to `*needed`.
    PF_ERROR_BUFFER_TOO_SMALL = 3,
    /// Memory could not be allocated: for particles, boundaries, meshes, or what the next
    /// steps need (buffers and neighbour lists reserved before the first step of a call, or
    /// what grows during a step: neighbour lists, grid, corrections, the body coupling, the
    /// LDLᵀ factorisation). A step aborts for want of memory only in the thread pool's own
    /// bookkeeping (a few hundred bytes).
    PF_ERROR_OUT_OF_MEMORY = 4,
    /// The library panicked (a bug); the world involved, if any, is now poisoned.
    PF_ERROR_PANIC = 5,
    /// The world panicked in an earlier call and may be inconsistent: only
    /// `pf_world_destroy` may be called on it.
    PF_ERROR_WORLD_POISONED = 6,
    /// Another thread is using the same world right now. A world must be used by one thread
    /// at a time; this is detected and reported instead of corrupting the world.
    PF_ERROR_BUSY = 7,
}

/// A failed call: the status to return and the message to record.
#[derive(Debug)]
pub(crate) struct Failure {
    pub status: PfStatus,
    pub message: String,
}

impl Failure {
    /// A failure with `status` and `message`.
    pub fn new(status: PfStatus, message: impl Into<String>) -> Self {
        Self {
            status,
            message: message.into(),
        }
    }

    /// `PF_ERROR_INVALID_ARGUMENT` with `message`.
    pub fn invalid(message: impl Into<String>) -> Self {
        Self::new(PfStatus::PF_ERROR_INVALID_ARGUMENT, message)
    }

    /// `PF_ERROR_NULL_POINTER` naming the argument `what`.
    pub fn null(what: &str) -> Self {
        Self::new(
            PfStatus::PF_ERROR_NULL_POINTER,
            format!("{what} must not be NULL"),
        )
    }

    /// `PF_ERROR_OUT_OF_MEMORY` for `what`.
    pub fn out_of_memory(what: &str) -> Self {
        Self::new(
            PfStatus::PF_ERROR_OUT_OF_MEMORY,
            format!("out of memory while allocating {what}"),
        )
    }
}

impl From<crate::Error> for Failure {
    fn from(e: crate::Error) -> Self {
        match e {
            crate::Error::OutOfMemory(message) => {
                Self::new(PfStatus::PF_ERROR_OUT_OF_MEMORY, message)
            }
            other => Self::invalid(other.to_string()),
        }
    }
}

thread_local! {
    /// The message of this thread's last failed call; empty after a successful one.
    static LAST_ERROR: RefCell<CString> = RefCell::new(CString::default());
}

fn set_last_error(message: &str) {
    let text = CString::new(message.replace('\0', "\\0")).unwrap_or_default();
    // During thread teardown the slot may be gone; there is nobody left to read it then.
    let _ = LAST_ERROR.try_with(|slot| *slot.borrow_mut() = text);
}

fn clear_last_error() {
    let _ = LAST_ERROR.try_with(|slot| {
        let mut slot = slot.borrow_mut();
        if !slot.as_bytes().is_empty() {
            *slot = CString::default();
        }
    });
}

/// The wrapper around every exported function: runs `body`, catching panics. A failure or
/// panic records `"{name}: {message}"` as this thread's last error and yields its status;
/// success leaves the message alone (see [`status_call`] for functions returning a status).
pub(crate) fn call<T>(
    name: &str,
    body: impl FnOnce() -> Result<T, Failure>,
) -> Result<T, PfStatus> {
    match panic::catch_unwind(AssertUnwindSafe(body)) {
        Ok(Ok(value)) => Ok(value),
        Ok(Err(failure)) => {
            set_last_error(&format!("{name}: {}", failure.message));
            Err(failure.status)
        }
        Err(payload) => {
            let what = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".to_string());
            set_last_error(&format!("{name}: internal error (panic): {what}"));
            Err(PfStatus::PF_ERROR_PANIC)
        }
    }
}

/// [`call`] for functions that return a [`PfStatus`]: success clears the last-error message.
pub(crate) fn status_call(name: &str, body: impl FnOnce() -> Result<(), Failure>) -> PfStatus {
    match call(name, body) {
        Ok(()) => {
            clear_last_error();
            PfStatus::PF_OK
        }
        Err(status) => status,
    }
}

/// The message of the calling thread's last failed `pf_` call, as a NUL-terminated UTF-8
/// string naming the function and what was wrong (e.g. which argument, which index, which
/// value). It is the empty string (never NULL) when the thread's last status-returning call
/// succeeded or no call was made yet.
///
/// Ownership: the string belongs to the library. It stays valid and unchanged until the
/// calling thread makes its next `pf_` call; copy it to keep it. Thread safety: each thread
/// has its own message.
#[unsafe(no_mangle)]
pub extern "C" fn pf_last_error_message() -> *const c_char {
    static EMPTY: &[u8] = b"\0";
    call("pf_last_error_message", || {
        Ok(LAST_ERROR
            .try_with(|slot| slot.borrow().as_ptr())
            .unwrap_or(EMPTY.as_ptr().cast()))
    })
    .unwrap_or(EMPTY.as_ptr().cast())
}

/// The name of a status code as a static NUL-terminated string (e.g. `"PF_ERROR_NULL_POINTER"`),
/// or `"PF_UNKNOWN_STATUS"` for values that are not a `PfStatus`. Never NULL; never freed.
/// The argument is an `int` so that any value may be passed safely.
#[unsafe(no_mangle)]
pub extern "C" fn pf_status_name(status: c_int) -> *const c_char {
    let name: &'static [u8] = call("pf_status_name", || {
        Ok(match status {
            0 => &b"PF_OK\0"[..],
            1 => b"PF_ERROR_NULL_POINTER\0",
            2 => b"PF_ERROR_INVALID_ARGUMENT\0",
            3 => b"PF_ERROR_BUFFER_TOO_SMALL\0",
            4 => b"PF_ERROR_OUT_OF_MEMORY\0",
            5 => b"PF_ERROR_PANIC\0",
            6 => b"PF_ERROR_WORLD_POISONED\0",
            7 => b"PF_ERROR_BUSY\0",
            _ => b"PF_UNKNOWN_STATUS\0",
        })
    })
    .unwrap_or(b"PF_UNKNOWN_STATUS\0");
    name.as_ptr().cast()
}

/// The calling thread's last error message, for tests.
#[cfg(test)]
pub(crate) fn message() -> String {
    // SAFETY: the library returns a valid NUL-terminated string.
    unsafe { std::ffi::CStr::from_ptr(pf_last_error_message()) }
        .to_string_lossy()
        .into_owned()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::ffi::CStr;

    #[test]
    fn panics_become_a_status_and_a_message() {
        let status = status_call("pf_test", || panic!("boom {}", 42));
        assert_eq!(status, PfStatus::PF_ERROR_PANIC);
        assert_eq!(message(), "pf_test: internal error (panic): boom 42");
        assert_eq!(status_call("pf_test", || Ok(())), PfStatus::PF_OK);
        assert_eq!(message(), "");
    }

    #[test]
    fn failures_record_their_message_per_thread() {
        let status = status_call("pf_test", || Err(Failure::null("out")));
        assert_eq!(status, PfStatus::PF_ERROR_NULL_POINTER);
        assert_eq!(message(), "pf_test: out must not be NULL");
        std::thread::spawn(|| assert_eq!(message(), ""))
            .join()
            .unwrap();
        // Messages with NUL bytes survive as escaped text.
        let _ = status_call("pf_test", || Err(Failure::invalid("a\0b")));
        assert_eq!(message(), "pf_test: a\\0b");
    }

    #[test]
    fn status_names_cover_every_code() {
        for (code, name) in [
            (PfStatus::PF_OK, "PF_OK"),
            (PfStatus::PF_ERROR_BUSY, "PF_ERROR_BUSY"),
            (PfStatus::PF_ERROR_WORLD_POISONED, "PF_ERROR_WORLD_POISONED"),
        ] {
            // SAFETY: static NUL-terminated strings.
            let got = unsafe { CStr::from_ptr(pf_status_name(code as c_int)) };
            assert_eq!(got.to_str().unwrap(), name);
        }
        let got = unsafe { CStr::from_ptr(pf_status_name(-3)) };
        assert_eq!(got.to_str().unwrap(), "PF_UNKNOWN_STATUS");
    }
}
