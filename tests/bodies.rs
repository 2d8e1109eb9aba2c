//! Rigid bodies in the fluid: kinematic motion that pushes fluid without leaks, free fall of a
//! dynamic body, determinism across thread counts, exact export and import of a state with
//! bodies, and rejected input.

use projfluid::body::{
    BodyKind, BodyMass, BodySpec, BodyState, Oscillation, Pose, Rotation, Shape, Velocity,
};
use projfluid::boundary::Aabb;
use projfluid::{Params, Vec3, World};

fn params(threads: usize) -> Params {
    Params {
        threads,
        ..Params::default()
    }
}

fn spec(kind: BodyKind, shape: Shape, mass: Option<BodyMass>, position: Vec3) -> BodySpec {
    BodySpec {
        kind,
        mesh: shape.mesh(0.025).unwrap(),
        mass,
        pose: Pose {
            position,
            rotation: Rotation::identity(),
        },
        velocity: Velocity::default(),
        motion: None,
    }
}

/// A channel 1.2 m long with water in its far part and a thin paddle (2 cm, thinner than a
/// particle) across it, which moves at 2 m/s into the water for 0.2 s.
fn paddle_channel(threads: usize) -> (World, usize) {
    let mut world = World::new(params(threads)).unwrap();
    let (width, depth) = (0.4, 0.8);
    world
        .add_container(
            Aabb {
                min: Vec3::zeros(),
                max: Vec3::new(1.2, depth, width),
            },
            1,
        )
        .unwrap();
    world
        .add_fluid_block(Vec3::new(0.4, 0.05, 0.05), [15, 5, 7], Vec3::zeros())
        .unwrap();
    let paddle = Shape::Box {
        half_extents: Vec3::new(0.01, 0.38, 0.19),
    };
    let mut s = spec(
        BodyKind::Kinematic,
        paddle,
        None,
        Vec3::new(0.3, 0.4, width / 2.0),
    );
    s.velocity.linear = Vec3::new(2.0, 0.0, 0.0);
    let id = world.add_body(s).unwrap();
    (world, id)
}

#[test]
fn a_thin_kinematic_paddle_at_two_metres_per_second_lets_no_particle_through() {
    let (mut world, paddle) = paddle_channel(0);
    world.advance(0.2).unwrap();
    let x = world.body(paddle).unwrap().centre_of_mass().x;
    assert!((x - 0.7).abs() < 1e-9, "the paddle moved to x = {x}");
    let behind = world.positions().iter().filter(|p| p.x < x).count();
    assert_eq!(behind, 0, "particles passed the paddle");
    assert_eq!(world.escaped_count(), 0);
    // It pushed: the fluid moves in +x, and the fluid pushes back on the paddle.
    let momentum: f64 = world.velocities().iter().map(|v| v.x).sum();
    assert!(momentum > 0.0, "{momentum}");
    assert!(world.body(paddle).unwrap().force().x < 0.0);
}

#[test]
fn a_dynamic_body_falls_freely_in_air() {
    let mut world = World::new(params(1)).unwrap();
    world
        .add_fluid_block(Vec3::new(5.0, 0.0, 0.0), [2, 2, 2], Vec3::zeros())
        .unwrap();
    let cube = Shape::Box {
        half_extents: Vec3::repeat(0.1),
    };
    let id = world
        .add_body(spec(
            BodyKind::Dynamic,
            cube,
            Some(BodyMass::Density(500.0)),
            Vec3::new(0.0, 2.0, 0.0),
        ))
        .unwrap();
    let mut t = 0.0;
    for _ in 0..50 {
        t += world.step().unwrap().dt;
    }
    let body = world.body(id).unwrap();
    // Symplectic Euler from rest: the drop is g·Σ_k (k Δt²) for steps of equal size, within
    // one step's g·Δt·t of ½gt²; the velocity is exactly g·t.
    let v = body.velocity().linear;
    assert!((v.y + 9.81 * t).abs() < 1e-9, "{v}");
    let drop = 2.0 - body.centre_of_mass().y;
    let dt = world.last_step().unwrap().dt;
    assert!((drop - 0.5 * 9.81 * t * t).abs() <= 9.81 * dt * t, "{drop}");
    assert_eq!(body.pose().rotation, Rotation::identity());
    assert_eq!(body.force(), Vec3::zeros());
}

/// A dynamic box dropped into water and a scripted paddle, for the determinism tests.
fn busy_tank(threads: usize) -> World {
    let mut world = World::new(params(threads)).unwrap();
    world
        .add_container(
            // The walls r/4 beyond one spacing from the water, so that its corners do not
            // start compressed (docs/method.md §7).
            Aabb {
                min: Vec3::repeat(-0.00625),
                max: Vec3::new(1.0, 0.8, 0.4),
            },
            1,
        )
        .unwrap();
    world
        .add_fluid_block(Vec3::new(0.2, 0.05, 0.05), [13, 5, 7], Vec3::zeros())
        .unwrap();
    let cube = Shape::Box {
        half_extents: Vec3::new(0.08, 0.06, 0.08),
    };
    let mut falling = spec(
        BodyKind::Dynamic,
        cube,
        Some(BodyMass::Density(600.0)),
        Vec3::new(0.6, 0.45, 0.2),
    );
    falling.velocity.angular = Vec3::new(0.0, 0.0, 2.0);
    world.add_body(falling).unwrap();
    let blade = Shape::Box {
        half_extents: Vec3::new(0.01, 0.3, 0.15),
    };
    let mut paddle = spec(BodyKind::Kinematic, blade, None, Vec3::new(0.1, 0.35, 0.2));
    paddle.motion = Some(Oscillation {
        amplitude: Vec3::new(0.05, 0.0, 0.0),
        angular_amplitude: Vec3::new(0.0, 0.0, 0.2),
        period: 0.5,
        phase: 0.0,
    });
    world.add_body(paddle).unwrap();
    let post = Shape::Cylinder {
        radius: 0.04,
        height: 0.5,
    };
    world
        .add_body(spec(
            BodyKind::Static,
            post,
            None,
            Vec3::new(0.92, 0.25, 0.2),
        ))
        .unwrap();
    world
}

/// The particles' digest, every body's pose, velocity and load, and the walls' load.
fn fingerprint(world: &World) -> (String, Vec<BodyState>, Vec3) {
    let bodies = world.bodies().iter().map(|b| b.state()).collect();
    (world.positions_hash(), bodies, world.wall_force())
}

#[test]
fn bodies_give_the_same_result_on_one_and_two_threads() {
    let mut one = busy_tank(1);
    let mut two = busy_tank(2);
    for _ in 0..60 {
        one.step().unwrap();
        two.step().unwrap();
    }
    assert_eq!(fingerprint(&one), fingerprint(&two));
    let falling = one.body(0).unwrap();
    assert!(
        falling.centre_of_mass().y < 0.45,
        "the box did not fall: at {} after {} s",
        falling.centre_of_mass(),
        one.time()
    );
    assert_ne!(
        falling.force(),
        Vec3::zeros(),
        "the water never touched the box"
    );
}

#[test]
fn a_state_with_bodies_exports_and_imports_exactly() {
    let mut reference = busy_tank(2);
    for _ in 0..30 {
        reference.step().unwrap();
    }
    let state = reference.export_state();
    let mut resumed = busy_tank(1);
    resumed.import_state(state).unwrap();
    for _ in 0..30 {
        reference.step().unwrap();
        resumed.step().unwrap();
    }
    assert_eq!(fingerprint(&resumed), fingerprint(&reference));
}

#[test]
fn bad_bodies_and_moves_are_rejected_and_change_nothing() {
    let mut world = busy_tank(1);
    let before = (world.bodies().len(), world.boundary_count());
    let cube = Shape::Box {
        half_extents: Vec3::repeat(0.05),
    };
    let message = |e: projfluid::Error| e.to_string();
    let e = world
        .add_body(spec(BodyKind::Dynamic, cube, None, Vec3::zeros()))
        .unwrap_err();
    assert!(message(e).contains("mass"));
    let e = world
        .add_body(spec(
            BodyKind::Dynamic,
            cube,
            Some(BodyMass::Density(-300.0)),
            Vec3::zeros(),
        ))
        .unwrap_err();
    assert!(message(e).contains("density"));
    let flat = projfluid::boundary::mesh::TriangleMesh::new(
        vec![Vec3::zeros(), Vec3::x() * 0.2, Vec3::y() * 0.2],
        vec![[0, 1, 2]],
    )
    .unwrap();
    let mut open = spec(
        BodyKind::Dynamic,
        cube,
        Some(BodyMass::Density(500.0)),
        Vec3::zeros(),
    );
    open.mesh = flat;
    assert!(message(world.add_body(open).unwrap_err()).contains("closed"));
    let mut scripted_dynamic = spec(
        BodyKind::Dynamic,
        cube,
        Some(BodyMass::Density(500.0)),
        Vec3::zeros(),
    );
    scripted_dynamic.motion = Some(Oscillation {
        amplitude: Vec3::x(),
        angular_amplitude: Vec3::zeros(),
        period: 1.0,
        phase: 0.0,
    });
    assert!(message(world.add_body(scripted_dynamic).unwrap_err()).contains("kinematic"));
    assert_eq!((world.bodies().len(), world.boundary_count()), before);

    let poses = fingerprint(&world).1;
    assert!(Pose::from_parts(Vec3::zeros(), [1.0, 0.1, 0.0, 0.0]).is_err());
    assert!(Pose::from_parts(Vec3::new(f64::NAN, 0.0, 0.0), [1.0, 0.0, 0.0, 0.0]).is_err());
    let nan = Velocity {
        linear: Vec3::new(f64::NAN, 0.0, 0.0),
        angular: Vec3::zeros(),
    };
    assert!(world.set_body_velocity(0, nan).is_err());
    assert!(world.set_body_pose(2, Pose::default()).is_err(), "static");
    assert!(world.set_body_pose(1, Pose::default()).is_err(), "scripted");
    assert!(
        world.set_body_target_pose(0, Pose::default()).is_err(),
        "dynamic"
    );
    assert!(
        world.set_body_pose(7, Pose::default()).is_err(),
        "no such body"
    );
    assert_eq!(fingerprint(&world).1, poses);
}

#[test]
fn boundary_particles_show_moving_bodies_where_they_are() {
    let (mut world, paddle) = paddle_channel(1);
    let body_particles = world.body(paddle).unwrap().particle_count();
    let walls = world.boundary_positions().len();
    let before = world.boundary_particles();
    assert_eq!(before.len(), walls + body_particles);
    let xs = |points: &[Vec3]| {
        points
            .iter()
            .filter(|p| p.x < 1.15 && p.y > 0.05 && p.y < 0.75 && p.z > 0.05 && p.z < 0.35)
            .map(|p| p.x)
            .fold(0.0, f64::max)
    };
    assert!((xs(&before) - 0.31).abs() < 0.02, "{}", xs(&before));
    world.advance(0.05).unwrap();
    let after = world.boundary_particles();
    assert_eq!(after.len(), walls + body_particles);
    assert!((xs(&after) - 0.41).abs() < 0.02, "{}", xs(&after));
}
