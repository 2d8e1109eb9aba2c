//! Where a test finds the shared library `cargo test` built.

use std::path::PathBuf;

/// `libprojfluid.so` of this build: cargo puts the crate's cdylib next to the test's
/// executable, in `target/<profile>/deps/`. Panics when it is missing.
pub fn shared_library() -> PathBuf {
    let exe = std::env::current_exe().expect("the test knows its own path");
    let library = exe.with_file_name("libprojfluid.so");
    assert!(
        library.exists(),
        "{} is missing; the crate's cdylib should be built by cargo test",
        library.display()
    );
    library
}
