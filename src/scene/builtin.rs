//! The built-in scenes (also shipped as `scenes/NAME.json`).

use super::{ContainerSpec, FluidBlock, MeshSource, ObstacleSpec, OutputSpec, Scene};
use crate::boundary::Transform;
use crate::params::Params;

/// Names of the built-in scenes, smallest first.
pub(super) const NAMES: &[&str] = &[
    "dam_break_small",
    "dam_break_30k",
    "dam_break_88k",
    "double_dam_break_128k",
    "obstacle_298k",
];

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
        "dam_break_88k" => Some(dam_break(
            name,
            "A 43x57x36 block of water (88,236 particles) collapses in a 7.2 x 4.3 x 1.85 m box: the 30k setup scaled by 1.43 with the same particle radius. Walls r/4 outside the nominal box.",
            [43, 57, 36],
            [7.20625, 4.30625, 1.85625],
            2.0,
        )),
        "double_dam_break_128k" => Some(Scene {
            fluid_blocks: vec![
                block([0.05; 3], [32, 50, 40]),
                block([6.4, 0.05, 0.05], [32, 50, 40]),
            ],
            ..dam_break(
                name,
                "Two 32x50x40 blocks of water (128,000 particles) at both ends of an 8 x 4 x 2.05 m box collapse and collide in the middle. Walls r/4 outside the nominal box.",
                [1, 1, 1],
                [8.00625, 4.00625, 2.05625],
                2.0,
            )
        }),
        "obstacle_298k" => Some(Scene {
            fluid_blocks: vec![
                block([0.05; 3], [53, 53, 53]),
                block([5.35, 0.05, 5.35], [53, 53, 53]),
            ],
            obstacles: vec![ObstacleSpec {
                mesh: MeshSource::Generated("sculpture".to_string()),
                transform: Transform {
                    translate: [4.0, 0.0, 4.0],
                    ..Transform::default()
                },
            }],
            ..dam_break(
                name,
                "Two 53x53x53 cubes of water (297,754 particles) in opposite corners of an 8 x 5 x 8 m tank collapse around a sculpture standing in the middle (the generated mesh `sculpture`: an arch-shaped body, a head, ears and a thin curled tail fin; also in scenes/obstacle.obj). Walls r/4 outside the nominal box.",
                [1, 1, 1],
                [8.00625, 5.00625, 8.00625],
                3.0,
            )
        }),
        _ => None,
    }
}

/// A block of fluid at rest with its first particle centre at `start` (m).
fn block(start: [f64; 3], count: [usize; 3]) -> FluidBlock {
    FluidBlock {
        start,
        count,
        velocity: [0.0; 3],
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
        fluid_blocks: vec![block([0.05; 3], count)],
        duration,
        output: OutputSpec::default(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    #[test]
    fn builtin_files_match_builtins() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
        for name in Scene::builtin_names() {
            let loaded = Scene::load(&dir.join(format!("{name}.json"))).unwrap();
            assert_eq!(Some(loaded), Scene::builtin(name), "{name}");
        }
    }

    #[test]
    fn builtins_are_valid_and_sized_as_named() {
        assert!(Scene::builtin("nope").is_none());
        for name in Scene::builtin_names() {
            let scene = Scene::builtin(name).unwrap();
            scene.validate().unwrap();
            assert_eq!(&scene.name, name);
        }
        for (name, count) in [
            ("dam_break_30k", 30_000),
            ("dam_break_88k", 88_236),
            ("double_dam_break_128k", 128_000),
            ("obstacle_298k", 297_754),
        ] {
            assert_eq!(Scene::builtin(name).unwrap().particle_count(), count);
        }
        // One particle radius across scenes (docs/method.md §9).
        for name in Scene::builtin_names() {
            assert_eq!(Scene::builtin(name).unwrap().params.particle_radius, 0.025);
        }
    }
}
