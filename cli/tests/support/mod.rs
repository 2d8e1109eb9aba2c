//! Helpers shared by the validation tests that run the `projfluid` binary.

use std::path::PathBuf;
use std::process::{Command, Output};

/// Runs the `projfluid` binary with `args`.
pub fn projfluid(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_projfluid"))
        .args(args)
        .output()
        .expect("run projfluid")
}

/// Runs the `projfluid` binary with `args`, asserts that it succeeded (showing its output
/// if not) and returns its standard output.
pub fn projfluid_ok(args: &[&str]) -> String {
    let out = projfluid(args);
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        out.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    stdout
}

/// `group/name` under the target's directory for test files, emptied but not created (the
/// commands under test create their output directories).
pub fn scratch(group: &str, name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join(group)
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    dir
}
