//! Several liquids in one world (docs/method.md §14): a material of the world's own density
//! changes nothing, two layers at rest keep their order and carry a two-slope hydrostatic
//! pressure, a heavy blob sinks through water, each particle reads its own material's
//! density, the result does not depend on the thread count, and bad materials are refused
//! without changing the world.

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
    let material = world.add_material(Material { rest_density: blob }).unwrap();
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

/// A blob three times as dense as water sinks through it; one of water's density settles
/// with the water around it. The heavy blob's particles weigh three times as much.
#[test]
fn a_heavy_blob_sinks_and_a_neutral_one_stays() {
    let mut heavy = blob_world(3000.0, 0);
    let mut neutral = blob_world(1000.0, 0);
    let (h0, n0) = (mean_height(&heavy, 1), mean_height(&neutral, 1));
    let (e_heavy, e_neutral) = (heavy.potential_energy(), neutral.potential_energy());
    let mass = heavy.particle_mass();
    let extra = 2.0 * mass * 9.81 * 64.0 * h0;
    assert!(
        ((e_heavy - e_neutral) / extra - 1.0).abs() < 1e-9,
        "potential energy {e_heavy} J against {e_neutral} J + {extra} J"
    );
    heavy.advance(1.0).unwrap();
    neutral.advance(1.0).unwrap();
    let (sunk, moved) = (h0 - mean_height(&heavy, 1), n0 - mean_height(&neutral, 1));
    assert!(
        sunk > moved + 0.08,
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

/// Oil (800 kg/m³) over water at rest: the layers keep their order (within two spacings of
/// the interface), each reads its own
/// density, and the constraints carry a pressure that grows with depth at 0.8·ρ0·g in the
/// oil and ρ0·g in the water (within 5 %).
#[test]
fn oil_over_water_keeps_its_layers_and_two_hydrostatic_slopes() {
    let count = [10, 16, 10];
    let params = Params::default().calm();
    let (r, d) = (params.particle_radius, params.spacing());
    let (mut world, tank, gap) = tank(params, count);
    let (water, oil_points) = split_lattice(count, d, gap, |[_, j, _]| j >= 8);
    world.add_fluid_particles(&water, None).unwrap();
    let oil = world
        .add_material(Material {
            rest_density: 800.0,
        })
        .unwrap();
    world.set_fluid_material(oil).unwrap();
    world.add_fluid_particles(&oil_points, None).unwrap();
    let interface = gap + 7.5 * d;
    world.relax(2.0, 4.0).unwrap();
    world.advance(0.5).unwrap();
    let (x, m) = (world.positions(), world.particle_materials());
    let lowest_oil = x
        .iter()
        .zip(&m)
        .filter(|(_, k)| **k == oil)
        .map(|(p, _)| p.y);
    let highest_water = x.iter().zip(&m).filter(|(_, k)| **k == 0).map(|(p, _)| p.y);
    let lowest_oil = lowest_oil.fold(f64::MAX, f64::min);
    let highest_water = highest_water.fold(f64::MIN, f64::max);
    // Particles beside the walls trade places across the interface, within two spacings.
    assert!(
        lowest_oil > interface - 2.0 * d && highest_water < interface + 2.0 * d,
        "oil down to {lowest_oil} m, water up to {highest_water} m, interface at {interface} m"
    );
    // Densities in each material's own terms: the mean over the particles away from the
    // free surface is that material's rest density.
    let densities = world.densities();
    let top = x.iter().map(|p| p.y).fold(f64::MIN, f64::max);
    for (material, rest) in [(0, 1000.0), (oil, 800.0)] {
        let inner: Vec<f64> = (0..x.len())
            .filter(|&i| m[i] == material && x[i].y < top - 4.0 * r)
            .map(|i| densities[i])
            .collect();
        let mean = inner.iter().sum::<f64>() / inner.len() as f64;
        assert!(
            (mean / rest - 1.0).abs() < 0.01,
            "material {material}: {mean} kg/m³"
        );
    }
    // The pressure, read with a tight solve (as the hydrostatic validation reads it) and
    // averaged over layers one support radius from the side walls.
    world.set_density_tolerance(0.0).unwrap();
    world.set_displacement_tolerance(1e-5 * r).unwrap();
    let h = world.params().support_radius();
    let mut layers = vec![(0.0, 0.0, 0usize); count[1] + 4];
    let start = world.time();
    while world.time() < start + 0.2 {
        world.step().unwrap();
        for (p, pressure) in world.constraint_pressures().samples {
            let inner = [(p.x, tank.max.x), (p.z, tank.max.z)];
            if inner.iter().all(|&(c, max)| c > h && c < max - h) {
                let layer = &mut layers[((p.y / d) as usize).min(count[1] + 3)];
                *layer = (layer.0 + p.y, layer.1 + pressure, layer.2 + 1);
            }
        }
    }
    let means: Vec<(f64, f64)> = layers
        .iter()
        .filter(|l| l.2 > 0)
        .map(|l| (l.0 / l.2 as f64, l.1 / l.2 as f64))
        .collect();
    // −dp/dy by least squares over the layers between heights `low` and `high` (m).
    let slope = |low: f64, high: f64| {
        let points: Vec<&(f64, f64)> = means
            .iter()
            .filter(|(y, _)| *y > low && *y < high)
            .collect();
        assert!(points.len() >= 3, "{points:?}");
        let n = points.len() as f64;
        let (my, mp) = points
            .iter()
            .fold((0.0, 0.0), |a, (y, p)| (a.0 + y / n, a.1 + p / n));
        let (sxy, sxx) = points.iter().fold((0.0, 0.0), |a, (y, p)| {
            (a.0 + (y - my) * (p - mp), a.1 + (y - my) * (y - my))
        });
        -sxy / sxx
    };
    let g = 9.81;
    let water_slope = slope(h, interface - 0.5 * h) / (1000.0 * g);
    let oil_slope = slope(interface + 0.5 * h, top - h) / (800.0 * g);
    assert!(
        (water_slope - 1.0).abs() < 0.03,
        "water: {water_slope} ρ0·g"
    );
    assert!((oil_slope - 1.0).abs() < 0.03, "oil: {oil_slope} ρ_oil·g");
}

/// Bad materials and material ids are refused, naming the field, and change nothing.
#[test]
fn bad_materials_are_refused_and_change_nothing() {
    let mut world = World::new(Params::default()).unwrap();
    for bad in [f64::NAN, f64::INFINITY, 0.0, -1000.0, 50.0, 20_000.0] {
        let e = world
            .add_material(Material { rest_density: bad })
            .unwrap_err()
            .to_string();
        assert!(e.contains("rest_density"), "{e}");
    }
    assert_eq!(world.material_count(), 1);
    let e = world.set_fluid_material(1).unwrap_err().to_string();
    assert!(e.contains("material") && e.contains("0 to 0"), "{e}");
    assert_eq!(world.fluid_material(), 0);
    let oil = world
        .add_material(Material {
            rest_density: 800.0,
        })
        .unwrap();
    assert_eq!((oil, world.material_count()), (1, 2));
    assert_eq!(
        world.material(1),
        Some(Material {
            rest_density: 800.0
        })
    );
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
    assert_eq!(
        world.material(1),
        Some(Material {
            rest_density: 800.0
        })
    );
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
