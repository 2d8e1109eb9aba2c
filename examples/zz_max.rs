use projfluid::scene::Scene;
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let mut scene = Scene::resolve(&args[1]).unwrap();
    if args.len() > 2 { scene.params.density_tolerance = args[2].parse().unwrap(); }
    if args.len() > 3 { scene.params.chebyshev.rho = args[3].parse().unwrap(); }
    let dur: f64 = args.get(4).map(|s| s.parse().unwrap()).unwrap_or(scene.duration);
    let mut w = scene.build_world().unwrap();
    let mut worst = 0.0;
    let mut n = 0; let mut over1 = 0;
    while w.time() < dur - 1e-9 {
        let s = w.step().unwrap().clone();
        n += 1;
        if s.density_error_max > 0.01 { over1 += 1; }
        if s.density_error_max > worst {
            worst = s.density_error_max;
            let d = w.densities(); let p = w.positions();
            let (i, _) = d.iter().enumerate().fold((0, 0.0), |a, (i, &r)| if r > a.1 { (i, r) } else { a });
            println!("t {:.3} step {n} max {:.3}% at {:?} outer {} avg {:.4}%", w.time(), 100.0*s.density_error_max, p[i], s.outer_iterations, 100.0*s.density_error_avg);
        }
    }
    println!("steps {n}, steps with max > 1%: {over1}");
}
