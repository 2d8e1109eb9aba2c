//! The scene of part 1 of `tests/c/bodies.c` built through the Rust API, with the same
//! float inputs widened to f64 exactly as the C API does, and its report in the program's
//! format: the positions' hash, then every body's pose, velocity, force and torque and the
//! walls' force as the bit patterns of their doubles.

use projfluid::body::{BodyKind, BodyMass, BodySpec, Pose, Shape, Velocity};
use projfluid::boundary::Aabb;
use projfluid::boundary::mesh::TriangleMesh;
use projfluid::{Params, Vec3, World};

fn v(x: f32, y: f32, z: f32) -> Vec3 {
    Vec3::new(x.into(), y.into(), z.into())
}

fn spec(kind: BodyKind, mesh: TriangleMesh, density: f64, at: [f64; 3]) -> BodySpec {
    BodySpec {
        kind,
        mesh,
        mass: (density > 0.0).then_some(BodyMass::Density(density)),
        pose: Pose::from_parts(Vec3::from(at), [1.0, 0.0, 0.0, 0.0]).unwrap(),
        velocity: Velocity::default(),
        motion: None,
    }
}

/// The paddle tank after `steps` CFL steps, reported as `bodies STEPS` prints it.
pub fn paddle_report(steps: usize) -> String {
    let params = Params {
        threads: 2,
        ..Params::default()
    };
    let r = params.particle_radius;
    let mut world = World::new(params).unwrap();
    let tank = Aabb {
        min: v(0.0, 0.0, 0.0),
        max: v(0.70625, 0.5, 0.30625),
    };
    world.add_container(tank, 1).unwrap();
    world
        .add_fluid_block(v(0.3, 0.05, 0.05), [8, 4, 5], Vec3::zeros())
        .unwrap();
    let blade = Shape::Box {
        half_extents: Vec3::new(0.01, 0.22, 0.145),
    };
    let paddle = spec(
        BodyKind::Kinematic,
        blade.mesh(r).unwrap(),
        0.0,
        [0.24, 0.23, 0.153125],
    );
    let id = world.add_body(paddle).unwrap();
    let push = Velocity {
        linear: Vec3::new(0.5, 0.0, 0.0),
        angular: Vec3::zeros(),
    };
    world.set_body_velocity(id, push).unwrap();
    let ball = Shape::Sphere { radius: 0.04 }.mesh(r).unwrap();
    world
        .add_body(spec(BodyKind::Dynamic, ball, 500.0, [0.5, 0.32, 0.15]))
        .unwrap();
    let corners = [
        v(0.0, 0.0, 0.0),
        v(0.08, 0.0, 0.0),
        v(0.0, 0.08, 0.0),
        v(0.0, 0.0, 0.08),
    ];
    let faces = vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
    let tetrahedron = TriangleMesh::new(corners.to_vec(), faces).unwrap();
    world
        .add_body(spec(BodyKind::Static, tetrahedron, 0.0, [0.58, 0.35, 0.1]))
        .unwrap();
    for _ in 0..steps {
        world.step().unwrap();
    }

    let bits = |values: &[f64]| -> String {
        values
            .iter()
            .map(|x| format!(" {:016x}", x.to_bits()))
            .collect()
    };
    let mut out = format!("hash {}\n", world.positions_hash());
    for (id, b) in world.bodies().iter().enumerate() {
        let (p, vel) = (b.pose(), b.velocity());
        out += &format!(
            "body {id}{}{}{}{}{}{}\n",
            bits(p.position.as_slice()),
            bits(&p.wxyz()),
            bits(vel.linear.as_slice()),
            bits(vel.angular.as_slice()),
            bits(b.force().as_slice()),
            bits(b.torque().as_slice()),
        );
    }
    out + &format!("wall{}\n", bits(world.wall_force().as_slice()))
}
