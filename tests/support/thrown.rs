//! A block of water thrown at a floor in a closed tank (tests/containment.rs, tests/gpu.rs).
#![allow(dead_code)]

use projfluid::boundary::Aabb;
use projfluid::{Params, Vec3, World};

/// A closed box of `cells` particle spacings along each axis for particles of radius `r`
/// (m), with a block of `count` particles 0.25 spacings from its lower walls.
pub fn tank(r: f64, cells: f64, count: [usize; 3]) -> World {
    let mut world = World::new(Params::with_radius(r)).unwrap();
    let d = 2.0 * r;
    let container = Aabb {
        min: Vec3::zeros(),
        max: Vec3::repeat(cells * d),
    };
    world.add_container(container, 1).unwrap();
    world
        .add_fluid_block(Vec3::repeat(0.5 * d), count, Vec3::zeros())
        .unwrap();
    world
}

/// The least distance (m) of any fluid particle from the planes of the walls of the box
/// [0, `side`]³, negative for a particle outside.
pub fn clearance(world: &World, side: f64) -> f64 {
    world
        .positions()
        .iter()
        .map(|p| p.min().min(side - p.max()))
        .fold(f64::INFINITY, f64::min)
}

/// A block of 8³ particles (r = 25 mm) in a closed box 24 spacings wide, thrown at the floor
/// at 4 m/s (and sideways at 1 and 0.5 m/s), with r and the box's side (m).
pub fn thrown_at_the_floor() -> (World, f64, f64) {
    let r = 0.025;
    let cells = 24.0;
    let mut world = tank(r, cells, [8, 8, 8]);
    let thrown = vec![Vec3::new(1.0, -4.0, 0.5); world.fluid_count()];
    world.set_velocities(&thrown).unwrap();
    (world, r, cells * 2.0 * r)
}
