use projfluid::{boundary::Aabb, *};
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let solver =
        SolverKind::from_name(args.get(1).map(|s| s.as_str()).unwrap_or("jacobi1")).unwrap();
    let rho: f64 = args.get(2).map(|s| s.parse().unwrap()).unwrap_or(0.9);
    let delay: usize = args.get(3).map(|s| s.parse().unwrap()).unwrap_or(3);
    let dur: f64 = args.get(4).map(|s| s.parse().unwrap()).unwrap_or(1.0);
    let mut p = Params::default();
    p.solver = solver;
    p.chebyshev.rho = rho;
    p.chebyshev.delay = delay;
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
    let t0 = std::time::Instant::now();
    let mut acc = projfluid::stats::RunAccumulator::default();
    let mut emax: f64 = e0;
    while w.time() < dur {
        let t = std::time::Instant::now();
        let s = w.step().unwrap().clone();
        acc.add(&s, t.elapsed().as_secs_f64());
        let e = w.kinetic_energy() + w.potential_energy();
        emax = emax.max(e);
        if w.steps() % 50 == 0 {
            println!(
                "t={:.3} dt={:.4} outer={} err avg {:.4}% max {:.3}% E={:.2} esc={}",
                w.time(),
                s.dt,
                s.outer_iterations,
                s.density_error_avg * 100.0,
                s.density_error_max * 100.0,
                e,
                w.escaped_count()
            );
        }
    }
    let sm = acc.summary("smoke", &w);
    println!("{}", serde_json::to_string_pretty(&sm).unwrap());
    println!("E0 {e0} Emax {emax} wall {:?}", t0.elapsed());
}
