//! A scene built in code: a tank with a sphere obstacle made from a triangle mesh, two blocks
//! of water (one thrown sideways), chosen solver settings; checked, printed as the JSON a scene
//! file would hold, then run.
//!
//! `cargo run --release --example custom_scene`

use projfluid::boundary::Transform;
use projfluid::boundary::shapes::Shapes;
use projfluid::scene::{ContainerSpec, ContainerWalls, FluidBlock, OutputSpec, Scene};
use projfluid::{Params, SolverKind, Vec3};

fn main() -> Result<(), projfluid::Error> {
    let params = Params {
        solver: SolverKind::Chebyshev,
        viscosity: 0.02,
        ..Params::default()
    };
    let scene = Scene {
        name: "sphere_in_a_tank".into(),
        description: "two blocks of water meet over a sphere".into(),
        params,
        containers: vec![ContainerSpec {
            min: [0.0; 3],
            max: [1.0, 0.8, 0.5],
            walls: ContainerWalls::Particles,
            layers: 1,
            spacing: None,
        }],
        obstacles: Vec::new(),
        bodies: Vec::new(),
        materials: Vec::new(),
        fluid_blocks: vec![
            FluidBlock {
                start: [0.05, 0.05, 0.05],
                count: [6, 10, 8],
                velocity: [0.0; 3],
                material: None,
            },
            FluidBlock {
                start: [0.7, 0.4, 0.05],
                count: [4, 4, 8],
                velocity: [-1.0, 0.0, 0.0],
                material: None,
            },
        ],
        emitters: Vec::new(),
        sinks: Vec::new(),
        domain: None,
        duration: 0.3,
        output: OutputSpec::default(),
        probes: None,
    };
    // Checks every key as a scene file's would be checked: errors name the field and value.
    scene.validate()?;
    println!("{}", scene.to_json());

    let mut world = scene.build_world()?;
    // An obstacle from a mesh made in code (a scene file would name an OBJ file instead).
    let mut shapes = Shapes::new();
    shapes.add_sphere(Vec3::new(0.5, 0.12, 0.25), 0.1, 3);
    let sphere = Transform::default().apply(&shapes.into_mesh()?)?;
    world.add_boundary_mesh(&sphere)?;

    world.advance(scene.duration)?;
    let stats = world.last_step().expect("a step was taken");
    println!(
        "{}: {} fluid and {} boundary particles, {} steps to t = {:.2} s, {:.4} % average \
         compression in the last step, {} escaped",
        scene.name,
        world.fluid_count(),
        world.boundary_count(),
        world.steps(),
        world.time(),
        100.0 * stats.density_error_avg,
        world.escaped_count(),
    );
    Ok(())
}
