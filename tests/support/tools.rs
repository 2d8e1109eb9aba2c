//! Which external tools a test may use. Outside CI a missing tool skips the check that needs
//! it, with a note; under CI (the `CI` environment variable set, as `.ci/run` runs) a missing
//! tool fails the test, so that CI cannot go green by skipping.

use std::process::Command;

/// Whether `tool --version` runs. Panics under CI when it does not.
pub fn available(tool: &str) -> bool {
    available_with(tool, &["--version"])
}

/// Whether `tool args` runs and succeeds, for tools without `--version` (`luajit -v`).
/// Panics under CI when it does not.
pub fn available_with(tool: &str, args: &[&str]) -> bool {
    let found = Command::new(tool)
        .args(args)
        .output()
        .is_ok_and(|o| o.status.success());
    if !found {
        assert!(
            std::env::var_os("CI").is_none(),
            "{tool} is not on PATH, and CI must run every check: install it (.ci/run does)"
        );
        eprintln!("note: {tool} is not on PATH; skipping the check that needs it");
    }
    found
}
