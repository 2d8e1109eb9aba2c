//! Library and ABI versions.

use super::status::call;
use std::ffi::c_char;

/// Version of the binary interface; the header's `PF_ABI_VERSION` macro (in `cbindgen.toml`)
/// must equal it, which `tests/header.rs` checks. Raised on every incompatible change of a
/// function signature, struct layout or enum value.
pub const PF_ABI_VERSION: u32 = 7;

/// The library's version as a static NUL-terminated string, e.g. `"0.1.0"`. Never NULL; the
/// string is owned by the library and never freed. Thread safe.
#[unsafe(no_mangle)]
pub extern "C" fn pf_version_string() -> *const c_char {
    const VERSION: &str = concat!(env!("CARGO_PKG_VERSION"), "\0");
    call("pf_version_string", || Ok(VERSION.as_ptr().cast())).unwrap_or(VERSION.as_ptr().cast())
}

/// The ABI version of the loaded library; equals `PF_ABI_VERSION` when header and library
/// match. Thread safe.
#[unsafe(no_mangle)]
pub extern "C" fn pf_abi_version() -> u32 {
    call("pf_abi_version", || Ok(PF_ABI_VERSION)).unwrap_or(PF_ABI_VERSION)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn version_matches_cargo_toml() {
        // SAFETY: a static NUL-terminated string.
        let s = unsafe { std::ffi::CStr::from_ptr(pf_version_string()) };
        assert_eq!(s.to_str().unwrap(), env!("CARGO_PKG_VERSION"));
        assert_eq!(pf_abi_version(), PF_ABI_VERSION);
    }
}
