//! The built-in scenes (also shipped as `scenes/NAME.json`).

use super::{ContainerSpec, FluidBlock, OutputSpec, Scene};
use crate::params::Params;

/// Names of the built-in scenes, smallest first.
pub(super) const NAMES: &[&str] = &["dam_break_small", "dam_break_30k"];

/// Particle radius of the built-in scenes (m).
const RADIUS: f64 = 0.025;

/// The built-in scene called `name`.
pub(super) fn builtin(name: &str) -> Option<Scene> {
    match name {
        "dam_break_small" => Some(dam_break(
            name,
            "A 16x20x12 block of water collapses in a 2 x 1.5 x 0.65 m box. The walls sit r/4 = 0.00625 m outside the nominal box [0, L] so that no particle starts compressed in a three-wall corner.",
            [16, 20, 12],
            [2.00625, 1.50625, 0.65625],
            1.0,
        )),
        "dam_break_30k" => Some(dam_break(
            name,
            "A 30x40x25 block of water (30,000 particles) collapses in a 5 x 3 x 1.3 m box. The walls sit r/4 = 0.00625 m outside the nominal box [0, L] so that no particle starts compressed in a three-wall corner.",
            [30, 40, 25],
            [5.00625, 3.00625, 1.30625],
            2.0,
        )),
        _ => None,
    }
}

/// A dam break: one block of fluid at rest in the corner of a box, r = 0.025 m, gravity −y,
/// every other parameter at its default.
///
/// The nominal box is [0, L]; its walls sit r/4 = 0.00625 m farther out on every side, so the
/// fluid (first particle centre at 2r = 0.05 m) starts 2.25r from each wall. At a gap of
/// exactly 2r, single-layer Akinci walls over-count the density in a three-wall corner by
/// about 3 %, and the corner particles would start compressed.
fn dam_break(
    name: &str,
    description: &str,
    count: [usize; 3],
    max: [f64; 3],
    duration: f64,
) -> Scene {
    Scene {
        name: name.to_string(),
        description: description.to_string(),
        params: Params::with_radius(RADIUS),
        containers: vec![ContainerSpec {
            min: [-0.00625; 3],
            max,
            layers: 1,
        }],
        obstacles: Vec::new(),
        fluid_blocks: vec![FluidBlock {
            start: [0.05; 3],
            count,
            velocity: [0.0; 3],
        }],
        duration,
        output: OutputSpec::default(),
    }
}
