//! Honey beside water (tests/viscosity.rs, tests/gpu.rs): two 8 × 16 × 8 columns
//! (r = 2.5 cm) at the two ends of one 3 m tank, collapsing towards each other: water
//! (material 0) and a material of 1420 kg/m³ with a kinematic viscosity of its own.

use projfluid::boundary::Aabb;
use projfluid::{Material, MaterialId, Params, Vec3, World};

/// The tank's length (m).
const LENGTH: f64 = 3.0;

/// The tank with its two columns, the second of 1420 kg/m³ and kinematic viscosity
/// `honey_nu` (m²/s); and that material's id.
pub fn honey_beside_water(honey_nu: f64) -> (World, MaterialId) {
    let params = Params::default();
    let (r, d) = (params.particle_radius, params.spacing());
    let mut world = World::new(params).unwrap();
    let gap = 0.25 * r;
    world
        .add_container(
            Aabb {
                min: Vec3::repeat(-gap),
                max: Vec3::new(LENGTH + gap, 1.2 + gap, 8.0 * d + gap),
            },
            1,
        )
        .unwrap();
    world
        .add_fluid_block(Vec3::repeat(r), [8, 16, 8], Vec3::zeros())
        .unwrap();
    let honey = world
        .add_material(Material {
            rest_density: 1420.0,
            kinematic_viscosity: honey_nu,
            surface_tension: 0.0,
        })
        .unwrap();
    world.set_fluid_material(honey).unwrap();
    let far = Vec3::new(LENGTH - r - 7.0 * d, r, r);
    world
        .add_fluid_block(far, [8, 16, 8], Vec3::zeros())
        .unwrap();
    (world, honey)
}

/// How far (m) the water's and the honey's fronts have run from their columns: the 99th
/// percentile of each liquid's reach towards the other.
pub fn fronts(world: &World, honey: MaterialId) -> (f64, f64) {
    let start = 8.0 * world.params().spacing();
    let materials = world.particle_materials();
    let x: Vec<f64> = world.positions().iter().map(|p| p.x).collect();
    let run_of = |m: MaterialId, reach: &dyn Fn(f64) -> f64| {
        let mut run: Vec<f64> = x
            .iter()
            .zip(&materials)
            .filter(|(_, k)| **k == m)
            .map(|(&x, _)| reach(x))
            .collect();
        run.sort_by(f64::total_cmp);
        run[run.len() * 99 / 100] - start
    };
    (run_of(0, &|x| x), run_of(honey, &|x| LENGTH - x))
}
