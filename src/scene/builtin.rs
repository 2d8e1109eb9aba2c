//! The built-in scenes (also shipped as `scenes/NAME.json`).

use super::{
    BodyShape, BoxSpec, ContainerSpec, ContainerWalls, FluidBlock, MeshSource, MotionSpec,
    ObstacleSpec, OutputSpec, Scene, SceneBody, SceneEmitter, SceneMaterial,
};
use crate::body::BodyKind;
use crate::boundary::Transform;
use crate::params::Params;
use crate::{EmitterShape, EmitterSpec, Vec3};

/// Names of the built-in scenes, smallest first.
pub(super) const NAMES: &[&str] = &[
    "dam_break_small",
    "fountain",
    "droplet",
    "honey_dam_break",
    "oil_on_water",
    "floating_boxes",
    "wave_tank",
    "dam_break_30k",
    "dam_break_88k",
    "double_dam_break_128k",
    "obstacle_298k",
    "dam_break_1m",
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
        "honey_dam_break" => {
            let mut scene = dam_break(
                name,
                "The dam_break_small block as honey: 16x20x12 particles of density 1420 kg/m³ and kinematic viscosity 0.01 m²/s, sticking to the walls (no slip), collapse slowly in a 2 x 1.5 x 0.65 m box. Walls r/4 outside the nominal box.",
                [16, 20, 12],
                [2.00625, 1.50625, 0.65625],
                2.0,
            );
            scene.params.rest_density = 1420.0;
            scene.params.kinematic_viscosity = 0.01;
            Some(scene)
        }
        "oil_on_water" => {
            let mut scene = dam_break(
                name,
                "A 12x16x12 column of oil (800 kg/m³) collapses onto a layer of water 4 particles deep (38x4x12) in a 2 x 1.5 x 0.65 m box and spreads over it. Walls r/4 outside the nominal box.",
                [38, 4, 12],
                [2.00625, 1.50625, 0.65625],
                2.0,
            );
            scene.materials.push(SceneMaterial {
                name: "oil".into(),
                rest_density: 800.0,
                kinematic_viscosity: None,
                surface_tension: None,
            });
            scene.fluid_blocks.push(FluidBlock {
                material: Some("oil".into()),
                ..block([0.05, 0.25, 0.05], [12, 16, 12])
            });
            Some(scene)
        }
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
        "dam_break_1m" => Some(dam_break(
            name,
            "A 97x129x80 block of water (1,001,040 particles) collapses in a 16.1 x 9.65 x 4.05 m box: the 30k setup scaled by 3.22 with the same particle radius. Walls r/4 outside the nominal box.",
            [97, 129, 80],
            [16.10625, 9.65625, 4.05625],
            2.0,
        )),
        "double_dam_break_128k" => Some(Scene {
            materials: Vec::new(),
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
            materials: Vec::new(),
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
        "droplet" => Some(droplet()),
        "wave_tank" => Some(wave_tank()),
        "fountain" => Some(fountain()),
        "floating_boxes" => Some(floating_boxes()),
        _ => None,
    }
}

/// A drop of water in open space: a 1 cm cube of 16×16×16 particles (r = 0.3125 mm), without
/// gravity, pulled round by its surface tension (0.0728 N/m, water against air) and then
/// oscillating about a sphere, its n = 2 mode with Rayleigh's period of 0.127 s
/// (docs/validation.md, "An oscillating drop"). As in that validation, XSPH is off and a
/// kinematic viscosity of 10⁻⁵ m²/s keeps the particles calm; the step goes down to 1 µs
/// for the capillary limit.
fn droplet() -> Scene {
    let r = 0.0003125;
    let mut params = Params::with_radius(r);
    params.gravity = [0.0; 3];
    params.viscosity = 0.0;
    params.kinematic_viscosity = 1e-5;
    params.surface_tension = 0.0728;
    params.dt_min = 1e-6;
    Scene {
        name: "droplet".into(),
        description: "A 1 cm cube of water (16x16x16 particles, r = 0.3125 mm) in open space without gravity rounds into a drop under its surface tension (0.0728 N/m) and oscillates about a sphere (Rayleigh's n = 2 period: 0.127 s). XSPH off, kinematic viscosity 1e-5 m²/s.".into(),
        params,
        containers: Vec::new(),
        obstacles: Vec::new(),
        bodies: Vec::new(),
        materials: Vec::new(),
        fluid_blocks: vec![block([r; 3], [16, 16, 16])],
        emitters: Vec::new(),
        sinks: Vec::new(),
        domain: None,
        duration: 0.5,
        output: OutputSpec::default(),
        probes: None,
    }
}

/// A wave tank: 4.5 m long, 1.25 m wide, water 0.75 m deep, with a piston paddle across its
/// left end that oscillates 0.1 m along x every 1.5 s, starting at rest position moving into
/// the water. The paddle fills the tank's cross-section but for 1.6 cm gaps to the walls
/// (less than r, so no particle passes); its face starts 0.08 m (more than one spacing
/// 2r) from the water, whose other sides are 2r + r/4 from the walls.
fn wave_tank() -> Scene {
    let paddle = SceneBody {
        kind: BodyKind::Kinematic,
        shape: BodyShape::Box {
            half_extents: [0.02, 0.74, 0.615],
        },
        density: None,
        position: [0.25, 0.75, 0.625],
        rotation: [1.0, 0.0, 0.0, 0.0],
        velocity: [0.0; 3],
        angular_velocity: [0.0; 3],
        motion: Some(MotionSpec {
            amplitude: [0.1, 0.0, 0.0],
            angular_amplitude: [0.0; 3],
            period: 1.5,
            phase: 0.0,
        }),
    };
    Scene {
        materials: Vec::new(),
        fluid_blocks: vec![block([0.35, 0.05, 0.05], [83, 15, 24])],
        bodies: vec![paddle],
        ..dam_break(
            "wave_tank",
            "A wave tank: 83x15x24 particles of water (29,880), 0.75 m deep, in a 4.5 x 1.5 x 1.25 m tank, driven by a kinematic piston paddle at its left end that oscillates 0.1 m along x with a period of 1.5 s, starting from its rest position moving into the water. Walls r/4 outside the nominal box.",
            [1, 1, 1],
            [4.50625, 1.50625, 1.25625],
            4.0,
        )
    }
}

/// A fountain: a disc emitter (radius 0.1 m, 12 lattice points a layer) 1 m above the floor
/// of a 1 x 1.2 x 1 m basin pours water straight down at 2 m/s (480 particles/s) into a
/// pool 0.2 m deep; a drain, a sink box over the floor's corner at the origin, removes the
/// water that reaches it, so that the level stays bounded. The basin's walls are two layers
/// thick: with one, the jet's impact pushed a particle through the floor after about 1.2 s.
fn fountain() -> Scene {
    let emitter = EmitterSpec {
        shape: EmitterShape::Disc { radius: 0.1 },
        position: Vec3::new(0.5, 1.0, 0.5),
        direction: Vec3::new(0.0, -1.0, 0.0),
        speed: 2.0,
        end_time: None,
    };
    let drain = BoxSpec {
        min: [-0.1; 3],
        max: [0.2, 0.15, 0.2],
    };
    let mut scene = Scene {
        materials: Vec::new(),
        fluid_blocks: vec![block([0.05; 3], [19, 4, 19])],
        emitters: vec![SceneEmitter {
            spec: emitter,
            material: None,
        }],
        sinks: vec![drain],
        ..dam_break(
            "fountain",
            "A fountain: a disc emitter (radius 0.1 m) 1 m above the floor of a 1 x 1.2 x 1 m basin pours water straight down at 2 m/s (480 particles/s) into a 19x4x19 pool (1,444 particles); a drain, a sink box [-0.1, 0.2] x [-0.1, 0.15] x [-0.1, 0.2] m over the floor's corner, removes the water that reaches it. Walls two layers thick, r/4 outside the nominal box.",
            [1, 1, 1],
            [1.00625, 1.20625, 1.00625],
            4.0,
        )
    };
    scene.containers[0].layers = 2;
    scene
}

/// Floating boxes: three dynamic boxes, 0.5 x 0.3 x 0.5 m, of density 300, 600 and 900 kg/m³,
/// dropped side by side from 5 cm above the water of a 3 x 1.2 x 1.2 m tank filled 0.6 m deep.
/// Each settles with the fraction ρ_body/ρ0 of its height under water.
fn floating_boxes() -> Scene {
    let boxed = |x: f64, density: f64| SceneBody {
        kind: BodyKind::Dynamic,
        shape: BodyShape::Box {
            half_extents: [0.25, 0.15, 0.25],
        },
        density: Some(density),
        position: [x, 0.85, 0.6],
        rotation: [1.0, 0.0, 0.0, 0.0],
        velocity: [0.0; 3],
        angular_velocity: [0.0; 3],
        motion: None,
    };
    Scene {
        bodies: vec![boxed(0.6, 300.0), boxed(1.5, 600.0), boxed(2.4, 900.0)],
        ..dam_break(
            "floating_boxes",
            "Floating boxes: three dynamic boxes, 0.5 x 0.3 x 0.5 m, of density 300, 600 and 900 kg/m³ are dropped side by side from 5 cm above the water (59x12x23 particles, 16,284) of a 3 x 1.2 x 1.2 m tank; each settles with the fraction ρ_body/ρ0 of its height under water. Walls r/4 outside the nominal box.",
            [59, 12, 23],
            [3.00625, 1.20625, 1.20625],
            5.0,
        )
    }
}

/// A block of fluid at rest with its first particle centre at `start` (m).
fn block(start: [f64; 3], count: [usize; 3]) -> FluidBlock {
    FluidBlock {
        start,
        count,
        velocity: [0.0; 3],
        material: None,
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
            walls: ContainerWalls::Particles,
            layers: 1,
            spacing: None,
        }],
        obstacles: Vec::new(),
        bodies: Vec::new(),
        materials: Vec::new(),
        fluid_blocks: vec![block([0.05; 3], count)],
        emitters: Vec::new(),
        sinks: Vec::new(),
        domain: None,
        duration,
        output: OutputSpec::default(),
        probes: None,
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
            ("droplet", 4096),
            ("wave_tank", 29_880),
            ("floating_boxes", 16_284),
            ("dam_break_30k", 30_000),
            ("dam_break_88k", 88_236),
            ("double_dam_break_128k", 128_000),
            ("obstacle_298k", 297_754),
            ("dam_break_1m", 1_001_040),
        ] {
            assert_eq!(Scene::builtin(name).unwrap().particle_count(), count);
        }
        // One particle radius across scenes (docs/method.md §9), but for the drop a
        // centimetre across, whose surface tension acts at the millimetre scale.
        for name in Scene::builtin_names() {
            let r = Scene::builtin(name).unwrap().params.particle_radius;
            assert_eq!(r, if *name == "droplet" { 0.0003125 } else { 0.025 });
        }
    }

    /// Every fluid block starts at least one spacing 2r inside its container's walls (where
    /// the scene has any) and from every axis-aligned box body, so that no particle starts
    /// compressed.
    #[test]
    fn builtin_fluid_starts_clear_of_walls_and_bodies() {
        for name in Scene::builtin_names() {
            let scene = Scene::builtin(name).unwrap();
            let d = 2.0 * scene.params.particle_radius;
            for b in &scene.fluid_blocks {
                let lo = b.start;
                let hi: [f64; 3] = std::array::from_fn(|a| lo[a] + (b.count[a] - 1) as f64 * d);
                let clear = |c: &ContainerSpec| {
                    (0..3).all(|a| lo[a] - c.min[a] >= d - 1e-9 && c.max[a] - hi[a] >= d - 1e-9)
                };
                let open = scene.containers.is_empty();
                assert!(open || scene.containers.iter().any(clear), "{name}: {b:?}");
                for body in &scene.bodies {
                    let BodyShape::Box { half_extents } = body.shape else {
                        panic!("{name}: only box bodies are checked");
                    };
                    assert_eq!(body.rotation, [1.0, 0.0, 0.0, 0.0]);
                    let gap = (0..3)
                        .map(|a| {
                            let (bl, bh) = (
                                body.position[a] - half_extents[a],
                                body.position[a] + half_extents[a],
                            );
                            (lo[a] - bh).max(bl - hi[a])
                        })
                        .fold(f64::NEG_INFINITY, f64::max);
                    assert!(gap >= d - 1e-9, "{name}: a body {gap} m from {b:?}");
                }
            }
        }
    }

    /// The wave tank's paddle pushes the water: after 0.2 s the water moves along +x
    /// near the paddle, and none has escaped or passed the paddle.
    #[test]
    fn wave_tank_paddle_pushes_the_water() {
        let mut scene = Scene::builtin("wave_tank").unwrap();
        scene.params.threads = 2;
        let mut world = scene.build_world().unwrap();
        while world.time() < 0.2 {
            world.step().unwrap();
        }
        let paddle = world.bodies()[0].centre_of_mass();
        assert!(paddle.x > 0.25, "{paddle}");
        let (positions, velocities) = (world.positions(), world.velocities());
        assert!(positions.iter().all(|p| p.x > paddle.x));
        let near: f64 = positions
            .iter()
            .zip(&velocities)
            .filter(|(p, _)| p.x < 0.6)
            .map(|(_, v)| v.x)
            .sum();
        assert!(near > 0.0, "{near}");
        assert_eq!(world.escaped_count(), 0);
        assert_eq!(world.nan_count(), 0);
    }

    /// The fountain pours and drains over its whole run: every half second the emitted count
    /// has grown, the drain keeps the fluid below 1,600 particles, and none has escaped the
    /// basin or turned NaN.
    #[test]
    fn fountain_pours_and_drains() {
        let mut scene = Scene::builtin("fountain").unwrap();
        scene.params.threads = 2;
        let mut world = scene.build_world().unwrap();
        let mut emitted = vec![0];
        for k in 1..=8 {
            while world.time() < 0.5 * k as f64 {
                world.step().unwrap();
            }
            emitted.push(world.emitted_count());
            assert!(world.fluid_count() < 1600, "{}", world.fluid_count());
            assert_eq!(world.escaped_count(), 0, "t = {}", world.time());
            assert_eq!(world.nan_count(), 0);
        }
        assert!(emitted.windows(2).all(|w| w[0] < w[1]), "{emitted:?}");
        // About 480 particles a second.
        assert!((1800..=2050).contains(&emitted[8]), "{emitted:?}");
        let removed = world.removed_count();
        assert!(removed > 1000, "{removed}");
        assert_eq!(world.fluid_count() as u64, 1444 + emitted[8] - removed);
        let basin = &scene.containers[0];
        assert!(
            world
                .positions()
                .iter()
                .all(|p| (0..3).all(|a| p[a] > basin.min[a] && p[a] < basin.max[a]))
        );
    }
}
