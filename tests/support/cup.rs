//! The thin-walled cup of the no-leak test, shared with `examples/cupleak.rs`.

use projfluid::Vec3;
use projfluid::boundary::mesh::TriangleMesh;
use projfluid::boundary::shapes::Shapes;

/// A square cup standing on y = 0: a floor slab and four walls, all `wall` metres thick,
/// outer size 0.3 × 0.25 × 0.3 m, centred on x = z = 0.4. Closed shells that touch.
pub fn thin_walled_cup(wall: f64) -> TriangleMesh {
    let (lo, hi, top) = (0.25, 0.55, 0.25);
    let mut shapes = Shapes::new();
    shapes.add_box(Vec3::new(lo, 0.0, lo), Vec3::new(hi, wall, hi));
    shapes.add_box(Vec3::new(lo, wall, lo), Vec3::new(lo + wall, top, hi));
    shapes.add_box(Vec3::new(hi - wall, wall, lo), Vec3::new(hi, top, hi));
    shapes.add_box(
        Vec3::new(lo + wall, wall, lo),
        Vec3::new(hi - wall, top, lo + wall),
    );
    shapes.add_box(
        Vec3::new(lo + wall, wall, hi - wall),
        Vec3::new(hi - wall, top, hi),
    );
    shapes.into_mesh().unwrap()
}
