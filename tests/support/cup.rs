//! The thin-walled cup of the no-leak test, shared with `examples/cupleak.rs`.

use projfluid::boundary::Aabb;
use projfluid::boundary::mesh::TriangleMesh;
use projfluid::boundary::shapes::Shapes;
use projfluid::{Params, Vec3, World};

/// The solid boxes (min, max corners in m) of a square cup standing on y = 0: a floor slab and
/// four walls, all `wall` metres thick, outer size 0.3 × 0.25 × 0.3 m, centred on x = z = 0.4.
pub fn cup_boxes(wall: f64) -> Vec<(Vec3, Vec3)> {
    let (lo, hi, top) = (0.25, 0.55, 0.25);
    vec![
        (Vec3::new(lo, 0.0, lo), Vec3::new(hi, wall, hi)),
        (Vec3::new(lo, wall, lo), Vec3::new(lo + wall, top, hi)),
        (Vec3::new(hi - wall, wall, lo), Vec3::new(hi, top, hi)),
        (
            Vec3::new(lo + wall, wall, lo),
            Vec3::new(hi - wall, top, lo + wall),
        ),
        (
            Vec3::new(lo + wall, wall, hi - wall),
            Vec3::new(hi - wall, top, hi),
        ),
    ]
}

/// The cup of [`cup_boxes`] as a mesh: closed box shells that touch.
pub fn thin_walled_cup(wall: f64) -> TriangleMesh {
    let mut shapes = Shapes::new();
    for (min, max) in cup_boxes(wall) {
        shapes.add_box(min, max);
    }
    shapes.into_mesh().unwrap()
}

/// How deep `p` lies inside the solid `boxes` (m): the largest distance from `p` to the
/// nearest face of a box holding it, 0 outside all of them.
pub fn depth_inside(boxes: &[(Vec3, Vec3)], p: &Vec3) -> f64 {
    boxes
        .iter()
        .map(|(min, max)| {
            (0..3)
                .map(|a| (p[a] - min[a]).min(max[a] - p[a]))
                .fold(f64::INFINITY, f64::min)
        })
        .fold(0.0, f64::max)
}

/// The no-leak scene with `params`: a 0.8 × 0.9 × 0.8 m tank, `cup` in it, and 12 × 6 × 12
/// particles above the cup, overhanging it by about 0.1 m on every side.
pub fn pour_over_cup(params: Params, cup: &TriangleMesh) -> World {
    let mut world = World::new(params).unwrap();
    let tank = Aabb {
        min: Vec3::repeat(-0.00625),
        max: Vec3::new(0.80625, 0.90625, 0.80625),
    };
    world.add_container(tank, 1).unwrap();
    world.add_boundary_mesh(cup).unwrap();
    world
        .add_fluid_block(Vec3::new(0.125, 0.35, 0.125), [12, 6, 12], Vec3::zeros())
        .unwrap();
    world
}
