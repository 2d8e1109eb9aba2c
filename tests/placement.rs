//! Fluid starts calm wherever it is placed (docs/method.md §2.7): a block put 0 to 3 particle
//! radii from container walls (of particles and of fields), a closed obstacle mesh, and a
//! static and a kinematic body takes its first steps without a jolt, on one and two threads
//! alike; fluid placed inside a solid is not created, and the adding call says how much was.

use projfluid::body::{BodyKind, BodyMass, BodySpec, Pose, Rotation, Shape, Velocity};
use projfluid::boundary::Aabb;
use projfluid::boundary::winding::is_inside;
use projfluid::{Params, Vec3, World};

/// Particle radius r of every world here (m).
const R: f64 = 0.025;
/// Blocks are this many particles along each axis.
const BLOCK: usize = 6;

/// What the block is placed against.
#[derive(Clone, Copy, Debug)]
enum Against {
    /// The floor and two walls of a box of wall particles.
    WallParticles,
    /// The floor and two walls of a box whose walls are fields.
    WallFields,
    /// The top face of a closed box mesh, a static obstacle.
    Obstacle,
    /// The top face of a static box body.
    StaticBody,
    /// The top face of a kinematic box body at rest.
    KinematicBody,
}

/// The solid box the block rests on where it is not the container: centre and half-extents (m).
const SLAB_CENTRE: Vec3 = Vec3::new(0.5, 0.1, 0.3);
const SLAB_HALF: Vec3 = Vec3::new(0.2, 0.1, 0.2);

fn slab() -> Shape {
    Shape::Box {
        half_extents: SLAB_HALF,
    }
}

/// A world with the solid of `against` and an empty container, on `threads` threads.
fn solids(against: Against, threads: usize) -> World {
    let mut world = World::new(Params {
        threads,
        ..Params::default()
    })
    .unwrap();
    match against {
        Against::WallParticles | Against::WallFields => {
            let tank = Aabb {
                min: Vec3::zeros(),
                max: Vec3::repeat(0.4),
            };
            match against {
                Against::WallFields => world.add_container_field(tank).unwrap(),
                _ => world.add_container(tank, 1).unwrap(),
            }
        }
        _ => {
            let tank = Aabb {
                min: Vec3::zeros(),
                max: Vec3::new(1.0, 0.8, 0.6),
            };
            world.add_container(tank, 1).unwrap();
            let mesh = slab().mesh(R).unwrap();
            let pose = Pose {
                position: SLAB_CENTRE,
                rotation: Rotation::identity(),
            };
            let body = |kind| BodySpec {
                kind,
                mesh: mesh.clone(),
                mass: None,
                pose,
                velocity: Velocity::default(),
                motion: None,
            };
            match against {
                Against::Obstacle => {
                    let placed: Vec<Vec3> =
                        mesh.vertices().iter().map(|v| v + SLAB_CENTRE).collect();
                    let placed = projfluid::boundary::mesh::TriangleMesh::new(
                        placed,
                        mesh.triangles().to_vec(),
                    )
                    .unwrap();
                    world.add_boundary_mesh(&placed).unwrap();
                }
                Against::StaticBody => {
                    world.add_body(body(BodyKind::Static)).unwrap();
                }
                _ => {
                    world.add_body(body(BodyKind::Kinematic)).unwrap();
                }
            }
        }
    }
    world
}

/// The first particle's centre of a block whose lowest layer lies `gap` (m) above the solid of
/// `against` (and, for the container, `gap` from two of its walls as well).
fn block_start(against: Against, gap: f64) -> Vec3 {
    match against {
        Against::WallParticles | Against::WallFields => Vec3::repeat(gap),
        _ => {
            let width = (BLOCK - 1) as f64 * 2.0 * R;
            Vec3::new(
                SLAB_CENTRE.x - width / 2.0,
                SLAB_CENTRE.y + SLAB_HALF.y + gap,
                SLAB_CENTRE.z - width / 2.0,
            )
        }
    }
}

/// How deep `p` (m) lies inside the slab (m; negative outside), or 0 where the solid is the
/// container.
fn depth_in_slab(against: Against, p: &Vec3) -> f64 {
    match against {
        Against::WallParticles | Against::WallFields => 0.0,
        _ => (0..3)
            .map(|a| SLAB_HALF[a] - (p[a] - SLAB_CENTRE[a]).abs())
            .fold(f64::INFINITY, f64::min),
    }
}

fn centre_height(world: &World) -> f64 {
    let x = world.positions();
    x.iter().map(|p| p.y).sum::<f64>() / x.len() as f64
}

/// Takes a step of `world` (`case` names it) and checks that it was calm: no iteration limit
/// and at most 12 outer iterations; no particle faster than a fall at twice gravity plus
/// 5 cm/s (a block resting on a solid collapses sideways under its own weight); the centre of
/// mass not above `start_height` (m); nothing escaped.
fn calm_step(world: &mut World, case: &str, start_height: f64) {
    let stats = world.step().unwrap().clone();
    assert!(
        !stats.hit_max_iterations && stats.outer_iterations <= 12,
        "{case}: {stats:?}"
    );
    let fastest = world
        .velocities()
        .iter()
        .map(|v| v.norm())
        .fold(0.0, f64::max);
    let bound = 2.0 * 9.81 * world.time() + 0.05;
    assert!(fastest <= bound, "{case}: {fastest} m/s > {bound} m/s");
    let height = centre_height(world);
    assert!(
        height <= start_height + 1e-4,
        "{case}: the centre of mass rose from {start_height} m to {height} m"
    );
    assert_eq!(world.escaped_count(), 0, "{case}");
}

/// Places the block `gap` (m) from the solid of `against` on `threads` threads, takes five
/// steps, checks each and returns the particles' final positions.
fn place_and_check(against: Against, gap: f64, threads: usize) -> Vec<Vec3> {
    let mut world = solids(against, threads);
    let added = world
        .add_fluid_block(block_start(against, gap), [BLOCK; 3], Vec3::zeros())
        .unwrap();
    let case = format!("{against:?}, {:.2} r, {threads} threads", gap / R);
    assert_eq!(
        added,
        BLOCK * BLOCK * BLOCK,
        "{case}: nothing lies inside a solid"
    );
    assert_eq!(world.fluid_count(), added);
    let start_height = centre_height(&world);
    let container = world.containers()[0];
    for step in 1..=5 {
        let case = format!("{case}, step {step}");
        // Before placement settled new fluid, these steps took 200 outer iterations (the
        // limit, twice) and threw particles at 6–90 m/s.
        calm_step(&mut world, &case, start_height);
        for p in world.positions() {
            assert!(container.contains(&p, 0.0), "{case}: {p:?} left the box");
            let depth = depth_in_slab(against, &p);
            assert!(
                depth < 0.2 * R,
                "{case}: {p:?} lies {depth} m inside the solid"
            );
        }
    }
    world.positions()
}

#[test]
fn blocks_placed_0_to_3_radii_from_any_solid_start_calm_on_one_and_two_threads() {
    for against in [
        Against::WallParticles,
        Against::WallFields,
        Against::Obstacle,
        Against::StaticBody,
        Against::KinematicBody,
    ] {
        for gap in [0.0, 0.5, 1.0, 1.5, 2.0, 3.0] {
            let one = place_and_check(against, gap * R, 1);
            let two = place_and_check(against, gap * R, 2);
            assert!(one == two, "{against:?}, {gap} r: thread counts differ");
        }
    }
}

/// A block overlapping a closed obstacle, a closed body and the outside of its container: the
/// particles whose centres lie in a solid are not created, and the call counts those it made.
#[test]
fn fluid_placed_inside_a_solid_is_not_created_and_the_count_says_so() {
    for against in [
        Against::Obstacle,
        Against::StaticBody,
        Against::KinematicBody,
    ] {
        let mut world = solids(against, 1);
        // A 10 × 6 × 6 block whose first two columns lie inside the slab up to its third
        // layer, the third column on the slab's face, and whose last column reaches beyond
        // the container's far wall.
        let start = SLAB_CENTRE + Vec3::new(0.1, SLAB_HALF.y - 0.12, -0.1);
        let count = [10, 6, 6];
        let container = world.containers()[0];
        let d = 2.0 * R;
        let mut expected = 0;
        for k in 0..count[2] {
            for j in 0..count[1] {
                for i in 0..count[0] {
                    let p = start + Vec3::new(i as f64, j as f64, k as f64) * d;
                    // A centre on the slab's surface is not inside it.
                    if container.contains(&p, 0.0) && depth_in_slab(against, &p) <= 1e-12 {
                        expected += 1;
                    }
                }
            }
        }
        assert!(expected > 0 && expected < 10 * 6 * 6 - 36, "{expected}");
        let added = world.add_fluid_block(start, count, Vec3::zeros()).unwrap();
        assert_eq!(added, expected, "{against:?}");
        assert_eq!(world.fluid_count(), expected);
        assert_eq!(world.last_added_count(), expected);
        let mesh = slab().mesh(R).unwrap();
        let placed = projfluid::boundary::mesh::TriangleMesh::new(
            mesh.vertices().iter().map(|v| v + SLAB_CENTRE).collect(),
            mesh.triangles().to_vec(),
        )
        .unwrap();
        for p in world.positions() {
            assert!(
                !is_inside(&placed, &p),
                "{against:?}: {p:?} inside the solid"
            );
            assert!(
                container.contains(&p, 0.0),
                "{against:?}: {p:?} outside the box"
            );
        }
        // Particles given one by one are filtered the same way.
        let inside = SLAB_CENTRE;
        let outside = SLAB_CENTRE + Vec3::new(0.0, SLAB_HALF.y + 0.2, 0.0);
        assert_eq!(
            world.add_fluid_particles(&[inside, outside], None).unwrap(),
            1
        );
        assert_eq!(world.last_added_count(), 1);
        assert_eq!(world.fluid_count(), expected + 1);
    }
}

/// The densities a world reports before its first step (what frame 0 holds) are those of the
/// particles where they were placed.
#[test]
fn densities_before_the_first_step_are_those_where_the_fluid_stands() {
    let mut world = solids(Against::WallParticles, 1);
    world
        .add_fluid_block(Vec3::repeat(R), [BLOCK; 3], Vec3::zeros())
        .unwrap();
    let reported = world.densities();
    let evaluated = world.current_densities();
    assert_eq!(reported, evaluated);
    let rho0 = world.params().rest_density;
    assert!(
        reported
            .iter()
            .all(|&rho| rho > 0.3 * rho0 && rho < rho0 * 1.001)
    );
}

/// A closed solid added where fluid already stands makes room for itself: a closed obstacle
/// mesh and static, kinematic and dynamic bodies put into a resting block remove the fluid
/// whose centres lie in them or nearer than r to them (the removed count says how much) and
/// settle the fluid next to them, so that the first steps are calm, on one and two threads alike.
#[test]
fn a_solid_added_into_standing_fluid_makes_room_and_the_fluid_starts_calm() {
    // The slab, sunk into a block that stands on the container's floor, clear of the floor.
    let sunk = Vec3::new(0.5, 0.15, 0.3);
    for kind in [
        None,
        Some(BodyKind::Static),
        Some(BodyKind::Kinematic),
        Some(BodyKind::Dynamic),
    ] {
        let mut ends = Vec::new();
        for threads in [1, 2] {
            let mut world = World::new(Params {
                threads,
                ..Params::default()
            })
            .unwrap();
            let tank = Aabb {
                min: Vec3::zeros(),
                max: Vec3::new(1.0, 0.8, 0.6),
            };
            world.add_container(tank, 1).unwrap();
            // A block 16 × 6 × 10 from one spacing above the floor: 0.05–0.8 m along x.
            world
                .add_fluid_block(Vec3::new(0.05, 0.05, 0.05), [16, 6, 10], Vec3::zeros())
                .unwrap();
            let mesh = slab().mesh(R).unwrap();
            let placed = projfluid::boundary::mesh::TriangleMesh::new(
                mesh.vertices().iter().map(|v| v + sunk).collect(),
                mesh.triangles().to_vec(),
            )
            .unwrap();
            // Centres inside the slab or nearer than r to it.
            let near_or_inside = |p: &Vec3| {
                let outside: Vec3 = (p - sunk).abs() - SLAB_HALF;
                outside.map(|e| e.max(0.0)).norm() < R
            };
            let inside = world
                .positions()
                .iter()
                .filter(|p| near_or_inside(p))
                .count();
            assert!(inside > 100, "{inside}");
            let before = world.fluid_count();
            match kind {
                None => world.add_boundary_mesh(&placed).unwrap(),
                Some(kind) => {
                    world
                        .add_body(BodySpec {
                            kind,
                            mesh: mesh.clone(),
                            mass: (kind == BodyKind::Dynamic).then_some(BodyMass::Density(800.0)),
                            pose: Pose {
                                position: sunk,
                                rotation: Rotation::identity(),
                            },
                            velocity: Velocity::default(),
                            motion: None,
                        })
                        .unwrap();
                }
            }
            let case = format!("{kind:?}, {threads} threads");
            assert_eq!(world.fluid_count(), before - inside, "{case}");
            assert_eq!(world.removed_count(), inside as u64, "{case}");
            let start_height = centre_height(&world);
            for step in 1..=5 {
                let case = format!("{case}, step {step}");
                calm_step(&mut world, &case, start_height);
                // The slab where it stands now (a dynamic one moves).
                let centre = match world.bodies().first() {
                    Some(body) => body.pose().position,
                    None => sunk,
                };
                for p in world.positions() {
                    let depth = (0..3)
                        .map(|a| SLAB_HALF[a] - (p[a] - centre[a]).abs())
                        .fold(f64::INFINITY, f64::min);
                    assert!(
                        depth < 0.2 * R,
                        "{case}: {p:?} lies {depth} m inside the solid"
                    );
                }
            }
            ends.push(world.positions());
        }
        assert!(ends[0] == ends[1], "{kind:?}: thread counts differ");
    }
}
