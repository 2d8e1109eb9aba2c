//! Several liquids in one world (docs/method.md §14): a material of the world's own density
//! changes nothing, a heavy blob sinks through water, each particle reads its own material's
//! density, the result does not depend on the thread count, and bad materials are refused
//! without changing the world. Two liquids at rest against the two-slope hydrostatic profile,
//! and the heavier one put on top overturning, are tested with `projfluid validate
//! two-layers`' module (cli/tests/validation.rs).

use projfluid::boundary::Aabb;
use projfluid::{Material, MaterialId, Params, Vec3, World};

/// A tank holding `count` particles (x, y, z; y up) one spacing plus r/4 from its walls, with
/// `params`, and its box.
fn tank(params: Params, count: [usize; 3]) -> (World, Aabb, f64) {
    let (r, d) = (params.particle_radius, params.spacing());
    let mut world = World::new(params).unwrap();
    let gap = d + 0.25 * r;
    let extent = |c: usize| (c - 1) as f64 * d + 2.0 * gap;
    let tank = Aabb {
        min: Vec3::zeros(),
        max: Vec3::new(extent(count[0]), 1.5 * extent(count[1]), extent(count[2])),
    };
    world.add_container(tank, 1).unwrap();
    (world, tank, gap)
}

/// The lattice of `count` particles from `gap`, split by `inside` into (outside, inside).
fn split_lattice(
    count: [usize; 3],
    d: f64,
    gap: f64,
    inside: impl Fn([usize; 3]) -> bool,
) -> (Vec<Vec3>, Vec<Vec3>) {
    let (mut outside, mut within) = (Vec::new(), Vec::new());
    for k in 0..count[2] {
        for j in 0..count[1] {
            for i in 0..count[0] {
                let p = Vec3::new(i as f64, j as f64, k as f64) * d + Vec3::repeat(gap);
                if inside([i, j, k]) {
                    within.push(p)
                } else {
                    outside.push(p)
                }
            }
        }
    }
    (outside, within)
}

/// A 12 × 16 × 12 tank of water with a 4 × 4 × 4 blob of `blob` (kg/m³) in its upper half,
/// on `threads` threads.
fn blob_world(blob: f64, threads: usize) -> World {
    let count = [12, 16, 12];
    let params = Params {
        threads,
        ..Params::default()
    };
    let d = params.spacing();
    let (mut world, _, gap) = tank(params, count);
    let middle = |c: usize| (4..8).contains(&c);
    let (water, heavy) = split_lattice(count, d, gap, |[i, j, k]| {
        middle(i) && middle(k) && (10..14).contains(&j)
    });
    world.add_fluid_particles(&water, None).unwrap();
    let material = world.add_material(Material::with_density(blob)).unwrap();
    world.set_fluid_material(material).unwrap();
    world.add_fluid_particles(&heavy, None).unwrap();
    world
}

/// The mean height (m) of the particles of `material`.
fn mean_height(world: &World, material: MaterialId) -> f64 {
    let (x, m) = (world.positions(), world.particle_materials());
    let ys: Vec<f64> = x
        .iter()
        .zip(&m)
        .filter(|(_, k)| **k == material)
        .map(|(p, _)| p.y)
        .collect();
    ys.iter().sum::<f64>() / ys.len() as f64
}

/// A material as dense as the world's own fluid steps exactly as the world's fluid does: the
/// masses, and with them every step, are the same bits.
#[test]
fn a_material_of_the_worlds_density_changes_nothing() {
    let mut one = blob_world(Params::default().rest_density, 0);
    let mut plain = blob_world(Params::default().rest_density, 0);
    // The same particles, all of the world's own fluid.
    let state = {
        let mut s = plain.export_state();
        s.materials.fill(0);
        s
    };
    plain.import_state(state).unwrap();
    for _ in 0..20 {
        one.step().unwrap();
        plain.step().unwrap();
    }
    assert_eq!(one.positions_hash(), plain.positions_hash());
    assert_eq!(
        one.particle_materials().iter().filter(|&&m| m == 1).count(),
        64
    );
}

/// A blob half again as dense as water sinks through it, most of the way to the floor
/// within 1 s (0.32 m of the 0.57 m; the projections yield to each particle's inertia,
/// docs/method.md §14); one of water's density settles with the water around it. The heavy
/// blob's particles weigh half again as much.
#[test]
fn a_heavy_blob_sinks_and_a_neutral_one_stays() {
    let mut heavy = blob_world(1500.0, 0);
    let mut neutral = blob_world(1000.0, 0);
    let (h0, n0) = (mean_height(&heavy, 1), mean_height(&neutral, 1));
    let (e_heavy, e_neutral) = (heavy.potential_energy(), neutral.potential_energy());
    let mass = heavy.particle_mass();
    let extra = 0.5 * mass * 9.81 * 64.0 * h0;
    assert!(
        ((e_heavy - e_neutral) / extra - 1.0).abs() < 1e-9,
        "potential energy {e_heavy} J against {e_neutral} J + {extra} J"
    );
    heavy.advance(1.0).unwrap();
    neutral.advance(1.0).unwrap();
    let (sunk, moved) = (h0 - mean_height(&heavy, 1), n0 - mean_height(&neutral, 1));
    assert!(
        sunk > 0.2,
        "the heavy blob sank {sunk} m in 1 s, the neutral one {moved} m"
    );
    assert!(moved.abs() < 0.05, "the neutral blob moved {moved} m");
    assert_eq!(heavy.escaped_count() + heavy.nan_count(), 0);
}

/// Two liquids in a blob world step to the same bits on one thread and on two.
#[test]
fn two_liquids_are_deterministic_across_thread_counts() {
    let mut one = blob_world(2000.0, 1);
    let mut two = blob_world(2000.0, 2);
    for _ in 0..15 {
        one.step().unwrap();
        two.step().unwrap();
    }
    assert_eq!(one.positions_hash(), two.positions_hash());
}

/// Bad materials and material ids are refused, naming the field, and change nothing.
#[test]
fn bad_materials_are_refused_and_change_nothing() {
    let mut world = World::new(Params::default()).unwrap();
    for bad in [f64::NAN, f64::INFINITY, 0.0, -1000.0, 50.0, 20_000.0] {
        let e = world
            .add_material(Material::with_density(bad))
            .unwrap_err()
            .to_string();
        assert!(e.contains("rest_density"), "{e}");
    }
    assert_eq!(world.material_count(), 1);
    let e = world.set_fluid_material(1).unwrap_err().to_string();
    assert!(e.contains("material") && e.contains("0 to 0"), "{e}");
    assert_eq!(world.fluid_material(), 0);
    let oil = world.add_material(Material::with_density(800.0)).unwrap();
    assert_eq!((oil, world.material_count()), (1, 2));
    assert_eq!(world.material(1), Some(Material::with_density(800.0)));
    assert_eq!(world.material(2), None);
    world
        .add_fluid_block(Vec3::repeat(0.1), [2, 2, 2], Vec3::zeros())
        .unwrap();
    // A state naming a material the world lacks.
    let mut state = world.export_state();
    state.materials[3] = 7;
    let e = world.import_state(state).unwrap_err().to_string();
    assert!(e.contains("state.materials"), "{e}");
    assert_eq!(world.particle_materials(), vec![0; 8]);
}

/// The built-in `oil_on_water`: the oil column collapses, spreads over the water and, while
/// the two slosh in the tank, floats on it: between 1 and 3 s the oil's mean height, sampled
/// every 0.25 s, is above the water's; nothing escapes.
#[test]
fn oil_spreads_over_water_in_the_builtin_scene() {
    let scene = projfluid::scene::Scene::builtin("oil_on_water").unwrap();
    let mut world = scene.build_world().unwrap();
    assert_eq!(world.material(1), Some(Material::with_density(800.0)));
    world.advance(1.0).unwrap();
    let (mut oil, mut water) = (0.0, 0.0);
    for _ in 0..8 {
        world.advance(0.25).unwrap();
        oil += mean_height(&world, 1) / 8.0;
        water += mean_height(&world, 0) / 8.0;
    }
    let (x, m) = (world.positions(), world.particle_materials());
    let reach = x.iter().zip(&m).filter(|(_, k)| **k == 1).map(|(p, _)| p.x);
    let reach = reach.fold(f64::MIN, f64::max);
    assert!(reach > 1.0, "the oil reached x = {reach} m");
    assert!(
        oil > water + 0.05,
        "oil at {oil} m, water at {water} m on average"
    );
    assert_eq!(world.escaped_count() + world.nan_count(), 0);
}
