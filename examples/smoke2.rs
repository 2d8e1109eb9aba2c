use projfluid::{boundary::Aabb, *};
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let visc: f64 = args.get(1).map(|s| s.parse().unwrap()).unwrap_or(0.01);
    let mut p = Params::default();
    p.solver = SolverKind::Jacobi1;
    p.viscosity = visc;
    let mut w = World::new(p).unwrap();
    w.add_container(
        Aabb {
            min: Vec3::zeros(),
            max: Vec3::new(2.0, 1.5, 0.65),
        },
        1,
    )
    .unwrap();
    w.add_fluid_block(Vec3::repeat(0.05), [16, 20, 12], Vec3::zeros())
        .unwrap();
    let e0 = w.kinetic_energy() + w.potential_energy();
    let mut prev = e0;
    while w.time() < 1.0 {
        let s = w.step().unwrap().clone();
        let e = w.kinetic_energy() + w.potential_energy();
        if e > prev || s.density_error_max > 0.02 || s.hit_max_iterations {
            println!(
                "step {} t={:.4} dt={:.5} outer={} hit={} dmax={:.3}% E={:.4} dE={:.4}",
                w.steps(),
                w.time(),
                s.dt,
                s.outer_iterations,
                s.hit_max_iterations,
                s.density_error_max * 100.0,
                e,
                e - prev
            );
        }
        prev = e;
    }
}
