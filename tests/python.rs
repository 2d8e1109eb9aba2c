//! Runs the Python package's tests (`python/tests`, pytest) against the library this build
//! made: the package's sources from `python/src` load `libprojfluid.so` from this test's
//! directory (`PROJFLUID_LIB`), so `cargo test` checks the current Rust and Python code
//! together. The interpreter is `$PROJFLUID_PYTHON` or `python3`, with numpy and pytest
//! installed (`.ci/run` makes such a virtualenv). Outside CI a missing interpreter or
//! module skips the check with a note; under CI it fails the test.

#[path = "support/library.rs"]
mod library;

use std::path::PathBuf;
use std::process::Command;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The interpreter to run, when it has numpy and pytest; panics under CI otherwise.
fn python() -> Option<String> {
    let python = std::env::var("PROJFLUID_PYTHON").unwrap_or_else(|_| "python3".to_string());
    let found = Command::new(&python)
        .args(["-c", "import numpy, pytest"])
        .output()
        .is_ok_and(|o| o.status.success());
    if !found {
        assert!(
            std::env::var_os("CI").is_none(),
            "{python} with numpy and pytest is needed, and CI must run every check: \
             .ci/run installs them in a virtualenv and sets PROJFLUID_PYTHON"
        );
        eprintln!("note: {python} lacks numpy or pytest; skipping the Python package's tests");
        return None;
    }
    Some(python)
}

#[test]
fn the_python_packages_tests_pass_against_this_library() {
    let Some(python) = python() else {
        return;
    };
    let library = library::shared_library();
    let cache = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("pytest-cache");
    let output = Command::new(&python)
        .current_dir(root().join("python"))
        .args(["-m", "pytest", "-q", "-p", "no:cacheprovider", "tests"])
        .env("PYTHONPATH", root().join("python/src"))
        .env("PROJFLUID_LIB", &library)
        .env("PYTHONPYCACHEPREFIX", &cache)
        .output()
        .expect("python runs");
    assert!(
        output.status.success(),
        "pytest failed ({}):\n{}\n{}",
        output.status,
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    );
}
