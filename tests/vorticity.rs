//! Vorticity confinement (docs/method.md §15): a vortex in a closed tank, filled and without
//! gravity, keeps more of its rotation with the confinement than without, whose projections
//! and XSPH damp it; and the confined flow is the same on one thread and on two.

use projfluid::boundary::Aabb;
use projfluid::{Params, Vec3, World};

/// A closed tank filled with `count` particles (x, y, z), without gravity, whose fluid turns
/// about the tank's vertical axis (z) as a Lamb–Oseen vortex of core radius `core` (m) and peak
/// speed about 0.5 m/s; and the axis' position.
fn vortex(params: Params, count: [usize; 3], core: f64) -> (World, Vec3) {
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
fn swirl(world: &World, axis: Vec3, inner: f64, outer: f64) -> f64 {
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

/// Without confinement the vortex's core (0.10–0.25 m from the axis, the core radius being
/// 0.15 m) loses a third of its swirl in 1 s (0.68 kept); ε = 0.3 keeps 0.84 of it and ε = 1
/// all of it.
#[test]
fn confinement_keeps_a_vortex_turning() {
    let kept = |epsilon: f64| {
        let params = Params {
            vorticity_confinement: epsilon,
            ..Params::default()
        };
        let (mut world, axis) = vortex(params, [20, 20, 4], 0.15);
        let start = swirl(&world, axis, 0.1, 0.25);
        world.advance(1.0).unwrap();
        assert_eq!(world.escaped_count() + world.nan_count(), 0);
        swirl(&world, axis, 0.1, 0.25) / start
    };
    let (plain, confined, strong) = (kept(0.0), kept(0.3), kept(1.0));
    assert!(
        plain < 0.8,
        "without confinement the core keeps {plain} of its swirl"
    );
    assert!(
        confined > plain + 0.1 && strong > confined + 0.1,
        "the core keeps {plain}, {confined} and {strong} of its swirl at ε = 0, 0.3 and 1"
    );
}

/// The confinement's sums are gathers: one thread and two give the same bits.
#[test]
fn confinement_is_the_same_on_one_thread_and_two() {
    let run = |threads: usize| {
        let params = Params {
            vorticity_confinement: 0.5,
            threads,
            ..Params::default()
        };
        let (mut world, _) = vortex(params, [12, 12, 4], 0.1);
        for _ in 0..20 {
            world.step().unwrap();
        }
        world.positions_hash()
    };
    assert_eq!(run(1), run(2));
}

/// Bad coefficients are refused, naming the field.
#[test]
fn bad_coefficients_are_refused() {
    for bad in [-0.1, 10.5, f64::NAN, f64::INFINITY] {
        let params = Params {
            vorticity_confinement: bad,
            ..Params::default()
        };
        let e = World::new(params).err().expect("refused").to_string();
        assert!(e.contains("vorticity_confinement"), "{e}");
    }
}
