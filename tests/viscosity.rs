//! The implicit viscosity solve (docs/method.md §13): what it conserves and what it damps.
//! Its flow against the analytic duct flow is tested with `projfluid validate poiseuille`'s
//! code, in cli/tests/validation.rs.

#[path = "support/honey.rs"]
mod honey;

use honey::{fronts, honey_beside_water};
use projfluid::{Material, Params, Vec3, World};

/// A ball of `n`³ particles without gravity or walls, spinning at `omega` (rad/s) about the
/// y axis through its centre and sheared by `shear` (1/s: v_x grows with y), with the
/// kinematic viscosity `nu` (m²/s) and no XSPH filter.
fn spinning_ball(nu: f64, omega: f64, shear: f64, threads: usize) -> World {
    let params = Params {
        kinematic_viscosity: nu,
        viscosity: 0.0,
        gravity: [0.0; 3],
        threads,
        ..Params::with_radius(0.01)
    };
    let d = params.spacing();
    let mut world = World::new(params).unwrap();
    let n = 12;
    world
        .add_fluid_block(Vec3::zeros(), [n, n, n], Vec3::zeros())
        .unwrap();
    let centre = Vec3::repeat(0.5 * (n - 1) as f64 * d);
    let v: Vec<Vec3> = world
        .positions()
        .iter()
        .map(|p| {
            let r = p - centre;
            Vec3::new(omega * r.z + shear * r.y, 0.0, -omega * r.x)
        })
        .collect();
    world.set_velocities(&v).unwrap();
    world
}

/// Linear momentum (kg·m/s per particle mass) and angular momentum about the centre of mass
/// (kg·m²/s per particle mass) of the fluid.
fn momenta(world: &World) -> (Vec3, Vec3) {
    let (x, v) = (world.positions(), world.velocities());
    let centre = x.iter().sum::<Vec3>() / x.len() as f64;
    let linear = v.iter().sum::<Vec3>();
    let angular = x.iter().zip(&v).map(|(x, v)| (x - centre).cross(v)).sum();
    (linear, angular)
}

fn kinetic(world: &World) -> f64 {
    world
        .velocities()
        .iter()
        .map(|v| 0.5 * v.norm_squared())
        .sum()
}

/// The viscous forces act along the line between two particles, equal and opposite, so a
/// free ball keeps its momentum and its angular momentum, and a rigid spin is not slowed;
/// a shear is: it loses most of its energy within a few viscous times, the spin part of it
/// staying.
#[test]
fn viscosity_keeps_momentum_and_spin_and_damps_shear() {
    let nu = 2e-2;
    let mut spin = spinning_ball(nu, 2.0, 0.0, 0);
    let mut sheared = spinning_ball(nu, 0.0, 2.0, 0);
    let (_, spin_start) = momenta(&spin);
    let (linear_start, shear_start) = momenta(&sheared);
    let (spin_energy, shear_energy) = (kinetic(&spin), kinetic(&sheared));
    spin.advance(0.2).unwrap();
    sheared.advance(0.2).unwrap();
    let (_, spin_end) = momenta(&spin);
    let (linear_end, shear_end) = momenta(&sheared);
    // Up to the solve's tolerance, against the sum of the particles' speeds.
    let scale: f64 = sheared.velocities().iter().map(|v| v.norm()).sum();
    let drift = (linear_end - linear_start).norm() / scale;
    assert!(drift < 1e-6, "momentum drifted by {drift:e} of Σ|v|");
    let lost = (spin_end - spin_start).norm() / spin_start.norm();
    assert!(
        lost < 0.01,
        "the spin's angular momentum changed by {:.2} %",
        100.0 * lost
    );
    let lost = (shear_end - shear_start).norm() / shear_start.norm();
    assert!(
        lost < 0.01,
        "the shear's angular momentum changed by {:.2} %",
        100.0 * lost
    );
    let kept = kinetic(&spin) / spin_energy;
    assert!(
        kept > 0.9,
        "the spin kept {:.1} % of its energy",
        100.0 * kept
    );
    // A simple shear is half spin, half strain: the strain's energy, half of the total,
    // goes into heat.
    let kept = kinetic(&sheared) / shear_energy;
    assert!(
        kept < 0.7,
        "the shear kept {:.1} % of its energy",
        100.0 * kept
    );
}

/// The solve's sums are taken in a fixed order: one and two threads give the same bits.
#[test]
fn viscosity_is_the_same_on_one_and_two_threads() {
    let runs: Vec<Vec<Vec3>> = [1, 2]
        .into_iter()
        .map(|threads| {
            let mut world = spinning_ball(1e-2, 1.0, 1.0, threads);
            world.advance(0.05).unwrap();
            world.velocities()
        })
        .collect();
    assert!(runs[0] == runs[1]);
}

/// How far (m) the front of a 12 × 16 × 8 column (r = 2.5 cm) collapsing in a tank has run
/// after 0.4 s with kinematic viscosity `nu` (m²/s): the 99th percentile of the particles' x.
fn dam_break_front(nu: f64) -> f64 {
    let params = Params {
        kinematic_viscosity: nu,
        ..Params::default()
    };
    let (r, d) = (params.particle_radius, params.spacing());
    let mut world = World::new(params).unwrap();
    let gap = 0.25 * r;
    world
        .add_container(
            projfluid::boundary::Aabb {
                min: Vec3::repeat(-gap),
                max: Vec3::new(2.0 + gap, 1.2 + gap, 8.0 * d + gap),
            },
            1,
        )
        .unwrap();
    world
        .add_fluid_block(Vec3::repeat(r), [12, 16, 8], Vec3::zeros())
        .unwrap();
    world.advance(0.4).unwrap();
    assert_eq!(world.escaped_count(), 0, "nu {nu}");
    let mut x: Vec<f64> = world.positions().iter().map(|p| p.x).collect();
    x.sort_by(f64::total_cmp);
    x[x.len() * 99 / 100]
}

/// The more viscous the water, the slower its front runs: each tenfold viscosity from
/// 10⁻³ to 1 m²/s holds the front back further, and at 1 m²/s (thick honey) the front runs
/// less than a quarter as far as water's.
#[test]
fn a_more_viscous_column_collapses_more_slowly() {
    let fronts: Vec<(f64, f64)> = [0.0, 1e-3, 1e-2, 1e-1, 1.0]
        .into_iter()
        .map(|nu| (nu, dam_break_front(nu)))
        .collect();
    for pair in fronts.windows(2) {
        assert!(pair[1].1 < pair[0].1, "fronts (nu, m): {fronts:?}");
    }
    let start = 12.0 * 0.05;
    let (water, thick) = (fronts[0].1 - start, fronts[4].1 - start);
    assert!(thick < 0.25 * water, "fronts (nu, m): {fronts:?}");
}

/// A spinning, sheared ball of a material of the world's density and viscosity `nu`, in a
/// world whose own fluid has none, steps to the same bits as the ball of the world's own
/// fluid with `nu` in the parameters: the solve reads each particle's viscosity from its
/// material.
#[test]
fn a_material_viscosity_acts_as_the_parameter_does() {
    let nu = 1e-2;
    let mut own = spinning_ball(nu, 2.0, 3.0, 2);
    let mut params = own.params().clone();
    params.kinematic_viscosity = 0.0;
    let mut by_material = World::new(params).unwrap();
    let water = Material {
        rest_density: 1000.0,
        kinematic_viscosity: nu,
        surface_tension: 0.0,
    };
    let id = by_material.add_material(water).unwrap();
    by_material.set_fluid_material(id).unwrap();
    by_material
        .add_fluid_particles(&own.positions(), Some(&own.velocities()))
        .unwrap();
    let mut inviscid = spinning_ball(0.0, 2.0, 3.0, 2);
    for _ in 0..20 {
        own.step().unwrap();
        by_material.step().unwrap();
        inviscid.step().unwrap();
    }
    assert_eq!(own.positions(), by_material.positions());
    assert_eq!(own.velocities(), by_material.velocities());
    assert!(kinetic(&inviscid) > 1.1 * kinetic(&own));
}

/// Honey (1420 kg/m³, ν = 0.1 m²/s) and water side by side: two 8 × 16 × 8 columns
/// (r = 2.5 cm) at the two ends of one tank collapse towards each other. After 0.4 s the
/// water's front has run more than twice as far as the honey's; with the honey's viscosity
/// set to 0 it runs as far as the water's (within 10 %), so the difference is the
/// viscosity's, not the density's.
#[test]
fn honey_beside_water_runs_more_slowly() {
    let run = |honey_nu: f64| {
        let (mut world, honey) = honey_beside_water(honey_nu);
        world.advance(0.4).unwrap();
        assert_eq!(world.escaped_count(), 0);
        fronts(&world, honey)
    };
    let (water, honey) = run(0.1);
    assert!(water > 2.0 * honey, "water {water} m, honey {honey} m");
    let (water, thin) = run(0.0);
    assert!(
        (thin - water).abs() < 0.1 * water,
        "water {water} m, inviscid honey {thin} m"
    );
}

/// A material's viscosity is set through the world, and bad values change nothing.
#[test]
fn material_viscosities_are_set_and_checked() {
    let mut world = World::new(Params::default()).unwrap();
    let oil = world.add_material(Material::with_density(900.0)).unwrap();
    world.set_material_kinematic_viscosity(oil, 1e-4).unwrap();
    assert_eq!(world.material(oil).unwrap().kinematic_viscosity, 1e-4);
    world.set_material_kinematic_viscosity(0, 1e-6).unwrap();
    assert_eq!(world.params().kinematic_viscosity, 1e-6);
    assert_eq!(world.material(0).unwrap().kinematic_viscosity, 1e-6);
    for bad in [-1e-3, f64::NAN, f64::INFINITY] {
        let e = world
            .set_material_kinematic_viscosity(oil, bad)
            .unwrap_err();
        assert!(e.to_string().contains("kinematic_viscosity"), "{e}");
        assert_eq!(world.material(oil).unwrap().kinematic_viscosity, 1e-4);
    }
    let e = world.set_material_kinematic_viscosity(7, 1e-3).unwrap_err();
    assert!(e.to_string().contains("material"), "{e}");
    let bad = Material {
        rest_density: 1200.0,
        kinematic_viscosity: -1.0,
        surface_tension: 0.0,
    };
    assert!(world.add_material(bad).is_err());
    assert_eq!(world.material_count(), 2);
}
