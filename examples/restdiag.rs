//! Diagnostic: distance of one default step from a (nearly) converged step on a settled column.
use projfluid::{boundary::Aabb, *};
fn build(settle: f64) -> World {
    let mut params = Params {
        mass_factor: 1.0,
        ..Params::default()
    };
    params.viscosity = 0.2;
    let (r, d) = (params.particle_radius, params.spacing());
    let mut world = World::new(params).unwrap();
    let n = [12usize, 16, 12];
    let gap = 2.25 * r;
    let floor = d - gap;
    let inner = |c: usize| (c - 1) as f64 * d + 2.0 * gap;
    world
        .add_container(
            Aabb {
                min: Vec3::repeat(floor),
                max: Vec3::new(floor + inner(n[0]), 1.5, floor + inner(n[2])),
            },
            1,
        )
        .unwrap();
    world
        .add_fluid_block(Vec3::repeat(d), n, Vec3::zeros())
        .unwrap();
    while world.time() < settle - 1e-9 {
        world.step().unwrap();
    }
    world
}
fn main() {
    let settle: f64 = std::env::var("SETTLE")
        .map(|v| v.parse().unwrap())
        .unwrap_or(2.0);
    let kmax: usize = std::env::var("KMAX")
        .map(|v| v.parse().unwrap())
        .unwrap_or(3000);
    let mut a = build(settle);
    let mut b = build(settle);
    println!("rms v {:.4}", a.rms_velocity());
    let x0 = a.positions();
    let sa = a.step().unwrap().clone();
    b.set_outer_iterations(kmax, kmax).unwrap();
    if std::env::var("BJAC").is_ok() {
        let c = b.params().chebyshev;
        b.set_solver(SolverKind::Jacobi1, c).unwrap();
    }
    let sb = b.step().unwrap().clone();
    let dl = b.last_displacements();
    let k = dl.len();
    println!(
        "A: {} its, B: {} its, B tail δ {:.2e} {:.2e} {:.2e} ratio {:.5}",
        sa.outer_iterations,
        sb.outer_iterations,
        dl[k / 2],
        dl[k - 2],
        dl[k - 1],
        (dl[k - 1] / dl[k / 2]).powf(1.0 / (k - 1 - k / 2) as f64)
    );
    let (xa, xb) = (a.positions(), b.positions());
    let dt = sa.dt;
    let mut acc = vec![(0.0f64, 0.0f64, 0usize); 20];
    let (mut s2, mut mx, mut dy) = (0.0, 0.0f64, 0.0);
    for i in 0..xa.len() {
        let e = xa[i] - xb[i];
        s2 += e.norm_squared();
        mx = mx.max(e.norm());
        dy += e.y;
        let l = ((x0[i].y) / 0.05).floor().clamp(0.0, 19.0) as usize;
        acc[l].0 += e.norm_squared();
        acc[l].1 += e.y;
        acc[l].2 += 1;
    }
    let n = xa.len() as f64;
    println!(
        "error rms {:.3e} max {:.3e} mean dy {:+.3e}; as velocity rms {:.4} m/s; vA rms {:.4} vB rms {:.4}",
        (s2 / n).sqrt(),
        mx,
        dy / n,
        (s2 / n).sqrt() / dt,
        a.rms_velocity(),
        b.rms_velocity()
    );
    for (l, q) in acc.iter().enumerate() {
        if q.2 > 0 {
            print!(
                "L{l}: rms {:.1e} dy {:+.1e} | ",
                (q.0 / q.2 as f64).sqrt(),
                q.1 / q.2 as f64
            );
        }
    }
    println!();
}
