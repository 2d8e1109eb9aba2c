//! The vortex of the vorticity confinement's tests (tests/vorticity.rs, tests/gpu.rs): a
//! Lamb–Oseen vortex in a closed tank, and the swirl it keeps.

use projfluid::boundary::Aabb;
use projfluid::{Params, Vec3, World};

/// A closed tank filled with `count` particles (x, y, z), without gravity, whose fluid turns
/// about the tank's vertical axis (z) as a Lamb–Oseen vortex of core radius `core` (m) and peak
/// speed about 0.5 m/s; and the axis' position.
pub fn vortex(params: Params, count: [usize; 3], core: f64) -> (World, Vec3) {
    let (r, d) = (params.particle_radius, params.spacing());
    let mut world = World::new(Params {
        gravity: [0.0; 3],
        ..params
    })
    .unwrap();
    let gap = d + 0.25 * r;
    let extent = |c: usize| (c - 1) as f64 * d + 2.0 * gap;
    let size = Vec3::new(extent(count[0]), extent(count[1]), extent(count[2]));
    world
        .add_container(
            Aabb {
                min: Vec3::zeros(),
                max: size,
            },
            1,
        )
        .unwrap();
    let axis = size * 0.5;
    // Peak speed 0.5 m/s at r ≈ 1.12 core: Γ/(2π) = 0.5·1.12·core/0.638.
    let circulation = 0.5 * 1.12 * core / 0.638;
    let (mut points, mut velocities) = (Vec::new(), Vec::new());
    for k in 0..count[2] {
        for j in 0..count[1] {
            for i in 0..count[0] {
                let p = Vec3::new(i as f64, j as f64, k as f64) * d + Vec3::repeat(gap);
                let (dx, dy) = (p.x - axis.x, p.y - axis.y);
                let radius = (dx * dx + dy * dy).sqrt().max(1e-12);
                let speed = circulation / radius * (1.0 - (-(radius / core).powi(2)).exp());
                points.push(p);
                velocities.push(Vec3::new(-dy, dx, 0.0) * (speed / radius));
            }
        }
    }
    world
        .add_fluid_particles(&points, Some(&velocities))
        .unwrap();
    (world, axis)
}

/// The mean tangential speed (m/s) about the vertical axis through `axis` of the particles
/// between `inner` and `outer` (m) from it.
pub fn swirl(world: &World, axis: Vec3, inner: f64, outer: f64) -> f64 {
    let (mut sum, mut n) = (0.0, 0);
    for (p, v) in world.positions().iter().zip(world.velocities()) {
        let (dx, dy) = (p.x - axis.x, p.y - axis.y);
        let radius = (dx * dx + dy * dy).sqrt();
        if radius > inner && radius < outer {
            sum += (dx * v.y - dy * v.x) / radius;
            n += 1;
        }
    }
    sum / n as f64
}
