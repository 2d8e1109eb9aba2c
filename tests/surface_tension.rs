//! Surface tension and wall adhesion (docs/method.md §17): what they change, what they
//! conserve, and how bad values are refused.

use projfluid::boundary::Aabb;
use projfluid::{Material, Params, Vec3, World};

/// A world without gravity or XSPH, of particle radius 0.5 mm, with surface tension
/// `sigma` (N/m) and wall adhesion `adhesion` (N/m), on `threads` threads.
fn params(sigma: f64, adhesion: f64, threads: usize) -> Params {
    Params {
        gravity: [0.0; 3],
        viscosity: 0.0,
        surface_tension: sigma,
        wall_adhesion: adhesion,
        threads,
        ..Params::with_radius(0.0005)
    }
}

/// A 6×6×6 cube of fluid at rest, its corner at the origin.
fn cube(sigma: f64, threads: usize) -> World {
    let mut world = World::new(params(sigma, 0.0, threads)).unwrap();
    world
        .add_fluid_block(Vec3::repeat(0.0005), [6, 6, 6], Vec3::zeros())
        .unwrap();
    world
}

/// The largest distance (m) of a particle from the fluid's centre.
fn reach(world: &World) -> f64 {
    let x = world.positions();
    let centre = x.iter().sum::<Vec3>() / x.len() as f64;
    x.iter().map(|p| (p - centre).norm()).fold(0.0, f64::max)
}

/// Surface tension pulls a cube's corners in: after 5 ms its farthest particle is closer to
/// its centre than at the start, while a cube without surface tension stays as it was.
#[test]
fn surface_tension_rounds_a_cube() {
    let mut plain = cube(0.0, 2);
    let mut tense = cube(0.0728, 2);
    let start = reach(&tense);
    plain.advance(0.005).unwrap();
    tense.advance(0.005).unwrap();
    assert!(
        (reach(&plain) - start).abs() < 1e-6 * start,
        "{}",
        reach(&plain)
    );
    assert!(reach(&tense) < 0.97 * start, "{} {start}", reach(&tense));
    assert_eq!(tense.nan_count(), 0);
}

/// The surface force is symmetric over a closed surface: a cube pulled round keeps its
/// centre of mass and its total momentum stays a small fraction of its particles' own.
#[test]
fn a_rounding_cube_does_not_drift() {
    let mut world = cube(0.0728, 2);
    let centre = |w: &World| w.positions().iter().sum::<Vec3>() / w.fluid_count() as f64;
    let start = centre(&world);
    for _ in 0..20 {
        world.step().unwrap();
    }
    let momentum: Vec3 = world.velocities().iter().sum();
    let speed = world.rms_velocity();
    assert!(speed > 1e-3, "the cube moved at {speed} m/s");
    assert!(
        momentum.norm() < 1e-6 * speed * world.fluid_count() as f64,
        "{momentum}"
    );
    assert!(
        (centre(&world) - start).norm() < 1e-9,
        "{}",
        centre(&world) - start
    );
}

/// σ = 0 adds no work: a world whose surface tension was set and taken back steps bit for
/// bit as one that never had any.
#[test]
fn no_surface_tension_changes_no_bits() {
    let mut never = cube(0.0, 2);
    let mut undone = cube(0.0, 2);
    undone.set_material_surface_tension(0, 0.05).unwrap();
    undone.set_material_surface_tension(0, 0.0).unwrap();
    for w in [&mut never, &mut undone] {
        w.step().unwrap();
        w.set_velocities(&vec![Vec3::new(0.1, -0.2, 0.05); w.fluid_count()])
            .unwrap();
        for _ in 0..5 {
            w.step().unwrap();
        }
    }
    assert_eq!(never.positions_hash(), undone.positions_hash());
    assert!(never.velocities() == undone.velocities());
    assert_eq!(never.next_dt(), undone.next_dt());
}

/// The forces are gathers in a fixed order: one and three threads give the same bits.
#[test]
fn surface_tension_is_deterministic_across_thread_counts() {
    let mut one = cube(0.0728, 1);
    let mut three = cube(0.0728, 3);
    for w in [&mut one, &mut three] {
        for _ in 0..10 {
            w.step().unwrap();
        }
    }
    assert_eq!(one.positions_hash(), three.positions_hash());
    assert!(one.velocities() == three.velocities());
}

/// Surface tension limits the step to the capillary rule c·√(ρ d³/(2πσ)) (docs/method.md
/// §8), the stronger the shorter, down to dt_min.
#[test]
fn surface_tension_limits_the_step() {
    let plain = cube(0.0, 2);
    let weak = cube(0.01, 2);
    let strong = cube(1.0, 2);
    let d: f64 = 0.001;
    let c = projfluid::material::CAPILLARY_FACTOR;
    let capillary =
        |sigma: f64| c * (1000.0 * d.powi(3) / (2.0 * std::f64::consts::PI * sigma)).sqrt();
    assert_eq!(plain.next_dt(), 1e-3);
    assert!((weak.next_dt() - capillary(0.01)).abs() < 1e-15);
    assert_eq!(strong.next_dt(), 1e-4, "dt_min bounds the capillary limit");
    assert!(strong.next_dt() < plain.next_dt());
}

/// Adhesion pulls fluid towards a wall: a layer of fluid just above a floor, without
/// gravity, moves down with wall adhesion and stays put without it.
#[test]
fn wall_adhesion_pulls_fluid_to_a_wall() {
    let drift = |adhesion: f64| {
        let mut world = World::new(params(0.0, adhesion, 2)).unwrap();
        let r = world.params().particle_radius;
        world
            .add_container(
                Aabb {
                    min: Vec3::new(-0.01, 0.0, -0.01),
                    max: Vec3::new(0.02, 0.02, 0.02),
                },
                1,
            )
            .unwrap();
        // The lowest layer 1.5 spacings above the floor: within the kernel's reach of the
        // wall's particles but not pressed against them.
        world
            .add_fluid_block(Vec3::new(0.0, 3.0 * r, 0.0), [6, 2, 6], Vec3::zeros())
            .unwrap();
        let before: f64 = world.positions().iter().map(|p| p.y).sum();
        for _ in 0..5 {
            world.step().unwrap();
        }
        let after: f64 = world.positions().iter().map(|p| p.y).sum();
        (after - before) / world.fluid_count() as f64
    };
    let (none, some) = (drift(0.0), drift(0.1));
    assert!(none.abs() < 1e-9, "{none}");
    assert!(some < -1e-6, "{some}");
}

/// Bad surface tensions and adhesions are refused naming the field, changing nothing.
#[test]
fn bad_values_are_refused_naming_the_field() {
    for bad in [f64::NAN, f64::INFINITY, -0.01, 10.5] {
        let e = World::new(params(bad, 0.0, 1)).err().unwrap();
        assert!(e.to_string().contains("surface_tension"), "{e}");
    }
    for bad in [f64::NAN, f64::INFINITY, -0.01, 20.5] {
        let e = World::new(params(0.0, bad, 1)).err().unwrap();
        assert!(e.to_string().contains("wall_adhesion"), "{e}");
    }
    let mut world = cube(0.02, 1);
    let oil = world
        .add_material(Material {
            surface_tension: 0.03,
            ..Material::with_density(800.0)
        })
        .unwrap();
    for bad in [f64::NAN, -1.0, 11.0] {
        let e = world.set_material_surface_tension(oil, bad).unwrap_err();
        assert!(e.to_string().contains("surface_tension"), "{e}");
        let e = world
            .add_material(Material {
                surface_tension: bad,
                ..Material::with_density(800.0)
            })
            .unwrap_err();
        assert!(e.to_string().contains("surface_tension"), "{e}");
    }
    let e = world.set_material_surface_tension(7, 0.01).unwrap_err();
    assert!(e.to_string().contains("material"), "{e}");
    assert_eq!(world.material(oil).unwrap().surface_tension, 0.03);
    assert_eq!(world.material(0).unwrap().surface_tension, 0.02);
    assert_eq!(world.params().surface_tension, 0.02);
    assert_eq!(world.material_count(), 2);
}

/// A drop on a floor spreads wider when the floor holds it: a cube of water resting on a
/// floor without gravity, after 50 ms, covers more of the floor (its particles' RMS
/// distance from the vertical axis through its centre) with a work of adhesion 2σ, which
/// wets fully, than with none, where it pulls up into a ball.
#[test]
fn a_drop_spreads_wider_on_a_floor_that_holds_it() {
    let spread = |adhesion: f64| {
        // As in the drop's validation, a little viscosity keeps the particles calm.
        let calm = Params {
            kinematic_viscosity: 1e-5,
            dt_min: 1e-6,
            ..params(0.0728, adhesion, 2)
        };
        let mut world = World::new(calm).unwrap();
        let r = world.params().particle_radius;
        world
            .add_container(
                Aabb {
                    min: Vec3::new(-0.01, -0.5 * r, -0.01),
                    max: Vec3::new(0.02, 0.02, 0.02),
                },
                1,
            )
            .unwrap();
        world
            .add_fluid_block(Vec3::new(0.0, 1.5 * r, 0.0), [6, 6, 6], Vec3::zeros())
            .unwrap();
        world.advance(0.05).unwrap();
        let x = world.positions();
        let centre = x.iter().sum::<Vec3>() / x.len() as f64;
        let squares: f64 = x
            .iter()
            .map(|p| (p.x - centre.x).powi(2) + (p.z - centre.z).powi(2))
            .sum();
        assert_eq!(world.nan_count(), 0);
        (squares / x.len() as f64).sqrt()
    };
    let (dry, wet) = (spread(0.0), spread(2.0 * 0.0728));
    assert!(wet > 1.2 * dry, "RMS radius {wet} m wetting, {dry} m not");
}
