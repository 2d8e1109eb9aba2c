//! Shared pieces of the scene tests: a small valid scene and helpers for error messages.

use super::Scene;
use crate::Error;

/// A valid scene: one container, two fluid blocks, the second moving.
pub(super) const GOOD: &str = r#"{
        "name": "box",
        "particle_radius": 0.05,
        "container": {"min": [0, 0, 0], "max": [1, 3, 1]},
        "fluid_blocks": [
            {"start": [0.1, 0.1, 0.1], "count": [4, 4, 4]},
            {"start": [0.1, 1.0, 0.1], "count": [2, 3, 2], "velocity": [1, 0, 0]}
        ],
        "duration": 0.5
    }"#;

/// The message of an expected error.
pub(super) fn message(result: Result<Scene, Error>) -> String {
    match result {
        Ok(scene) => panic!("expected an error, got {scene:?}"),
        Err(e) => e.to_string(),
    }
}

/// Asserts that `msg` mentions every one of `parts`.
pub(super) fn assert_names(msg: &str, parts: &[&str]) {
    for part in parts {
        assert!(msg.contains(part), "{msg:?} should mention {part:?}");
    }
}
