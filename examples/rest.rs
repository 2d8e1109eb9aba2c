//! Resting-column experiment (README, Known limitations): RMS velocity, centre of mass and
//! outer iterations over time for the 12 × 16 × 12 column of the physics tests.
//!
//! `cargo run --release --example rest -- TAU_PER_R SOLVER RHO SECONDS PRINT_EVERY GAP_PER_R`
//! (defaults 3e-3 chebyshev 0.85 2 0.1 2.25). Environment: `SETTLE=s` first runs s seconds with
//! velocities scaled by `DAMP` (default 0) after every step; `XSPH`, `DTMAX`, `K`, `GAMMA`,
//! `DELAY` override the viscosity, Δt_max, stiffness and Chebyshev's γ and delay;
//! `WEIGHT=neighbor_count|unit|uniform` the projection weighting; `FCC=1` fills the tank with a face-centred
//! cubic packing at rest density (wall gap `FCCGAP`, m) instead of the cubic lattice;
//! `MINIT`, `MAXIT` set the least and most outer iterations per step (equal: a fixed count);
//! `RELEASE_IT=K` fixes K outer iterations per step after the settle; `SMOOTH` splits the
//! RMS velocity into its kernel average over 2d and the rest;
//! `LAYERS`, `DISP`, `DUMP` print velocity by region, displacement per initial layer and the
//! last step's δ_k; `NY` sets the column's height in particles (default 16).
//! `SAVE=FILE` writes the settled state (positions, then velocities, f64) and `LOAD=FILE`
//! starts from such a file instead of the lattice; `KDAMP=1` settles by stopping every
//! particle whenever the kinetic energy has peaked instead of scaling; `BDUMP=FILE` writes the
//! boundary positions (for `tools/rest_reference.py`).
use projfluid::{boundary::Aabb, *};
fn main() {
    let a: Vec<String> = std::env::args().collect();
    let arg = |i: usize, d: &str| a.get(i).cloned().unwrap_or(d.to_string());
    let tau_r: f64 = arg(1, "3e-3").parse().unwrap();
    let solver = SolverKind::from_name(&arg(2, "chebyshev")).unwrap();
    let rho: f64 = arg(3, "0.85").parse().unwrap();
    let secs: f64 = arg(4, "2").parse().unwrap();
    let mut params = Params {
        mass_factor: 1.0,
        solver,
        ..Params::default()
    };
    params.chebyshev.rho = rho;
    params.chebyshev.auto_rho = false;
    if let Ok(v) = std::env::var("WEIGHT") {
        params.projection_weight = ProjectionWeight::from_name(&v).expect("WEIGHT");
    }
    if let Ok(v) = std::env::var("GAMMA") {
        params.chebyshev.gamma = v.parse().unwrap();
    }
    if let Ok(v) = std::env::var("DELAY") {
        params.chebyshev.delay = v.parse().unwrap();
    }
    if let Ok(v) = std::env::var("XSPH") {
        params.viscosity = v.parse().unwrap();
    }
    if let Ok(v) = std::env::var("DTMAX") {
        params.dt_max = v.parse().unwrap();
    }
    if let Ok(v) = std::env::var("K") {
        params.stiffness = v.parse().unwrap();
    }
    if let Ok(v) = std::env::var("MINIT") {
        params.min_outer_iterations = v.parse().unwrap();
    }
    if let Ok(v) = std::env::var("MAXIT") {
        params.max_outer_iterations = v.parse().unwrap();
    }
    params.displacement_tolerance = tau_r * params.particle_radius;
    let (r, d) = (params.particle_radius, params.spacing());
    let mut world = World::new(params).unwrap();
    let n = [
        12usize,
        std::env::var("NY")
            .map(|v| v.parse().unwrap())
            .unwrap_or(16),
        12,
    ];
    let gap_r: f64 = arg(6, "2.25").parse().unwrap();
    let gap = gap_r * r;
    let floor = d - gap;
    let inner = |c: usize| (c - 1) as f64 * d + 2.0 * gap;
    if std::env::var("FCC").is_ok() {
        let s: f64 = 0.05607;
        let h = s / 2f64.sqrt();
        let g: f64 = std::env::var("FCCGAP")
            .map(|v| v.parse().unwrap())
            .unwrap_or(0.04);
        let (nx, layers) = (11usize, 20usize);
        let mut pts = Vec::new();
        for l in 0..layers {
            let odd = l % 2 == 1;
            let m = if odd { nx - 1 } else { nx };
            let off = if odd { s / 2.0 } else { 0.0 };
            for i in 0..m {
                for k in 0..m {
                    pts.push(Vec3::new(
                        g + off + i as f64 * s,
                        g + l as f64 * h,
                        g + off + k as f64 * s,
                    ));
                }
            }
        }
        let w = (nx - 1) as f64 * s + 2.0 * g;
        world
            .add_container(
                Aabb {
                    min: Vec3::zeros(),
                    max: Vec3::new(w, 1.5, w),
                },
                1,
            )
            .unwrap();
        let v = vec![Vec3::zeros(); pts.len()];
        world.add_fluid_particles(&pts, Some(&v)).unwrap();
    } else {
        world
            .add_container(
                Aabb {
                    min: Vec3::repeat(floor),
                    max: Vec3::new(floor + inner(n[0]), 1.5, floor + inner(n[2])),
                },
                1,
            )
            .unwrap();
        if let Ok(path) = std::env::var("LOAD") {
            let state = read_vec3s(&path);
            let (pts, vel) = state.split_at(state.len() / 2);
            world.add_fluid_particles(pts, Some(vel)).unwrap();
        } else {
            world
                .add_fluid_block(Vec3::repeat(d), n, Vec3::zeros())
                .unwrap();
        }
    }
    if let Ok(path) = std::env::var("BDUMP") {
        write_vec3s(&path, world.boundary_positions());
    }
    let step_out: f64 = arg(5, "0.1").parse().unwrap();
    let initial = world.positions();
    let settle: f64 = std::env::var("SETTLE")
        .map(|v| v.parse().unwrap())
        .unwrap_or(0.0);
    let kinetic_damping = std::env::var("KDAMP").is_ok();
    let mut last_ek = 0.0;
    while world.time() < settle - 1e-9 {
        world.step().unwrap();
        if kinetic_damping {
            // Dynamic relaxation: stop every particle when the kinetic energy has peaked.
            let ek = world.kinetic_energy();
            if ek < last_ek {
                world
                    .set_velocities(&vec![Vec3::zeros(); world.fluid_count()])
                    .unwrap();
                last_ek = 0.0;
            } else {
                last_ek = ek;
            }
            continue;
        }
        let f: f64 = std::env::var("DAMP")
            .map(|v| v.parse().unwrap())
            .unwrap_or(0.0);
        let z: Vec<Vec3> = world.velocities().iter().map(|v| v * f).collect();
        world.set_velocities(&z).unwrap();
    }
    if let Ok(path) = std::env::var("SAVE") {
        write_vec3s(&path, &[world.positions(), world.velocities()].concat());
    }
    if let Ok(v) = std::env::var("RELEASE_IT") {
        let k: usize = v.parse().unwrap();
        world.set_outer_iterations(k, k).unwrap();
    }
    let secs = secs + settle;
    println!(
        "settled {settle} s, ycom {:.6}",
        world.positions().iter().map(|p| p.y).sum::<f64>() / world.fluid_count() as f64
    );
    let mut next = settle + step_out;
    let (mut it, mut steps) = (0usize, 0usize);
    while world.time() < secs - 1e-9 {
        let s = world.step().unwrap().clone();
        it += s.outer_iterations;
        steps += 1;
        if world.time() >= next - 1e-9 {
            let dl = world.last_displacements();
            let k = dl.len();
            let ratio = if k >= 3 {
                dl[k - 1] / dl[k - 2]
            } else {
                f64::NAN
            };
            let vy: f64 =
                world.velocities().iter().map(|v| v.y).sum::<f64>() / world.fluid_count() as f64;
            let ycom: f64 =
                world.positions().iter().map(|p| p.y).sum::<f64>() / world.fluid_count() as f64;
            print!("ycom {:.6} epot {:.3} ", ycom, world.potential_energy());
            println!(
                "t {:.2} rms {:.4} vy_mean {:+.5} dt {:.4} it/step {:.1} last_ratio {:.3} err {:.4}% ek {:.3e}",
                world.time(),
                world.rms_velocity(),
                vy,
                s.dt,
                it as f64 / steps as f64,
                ratio,
                s.density_error_avg * 100.0,
                world.kinetic_energy()
            );
            next += step_out;
            if std::env::var("LAYERS").is_ok() {
                let (ps, vs) = (world.positions(), world.velocities());
                let top = ps.iter().map(|p| p.y).fold(f64::MIN, f64::max);
                let mut acc = [[0.0f64; 3]; 3];
                for (p, v) in ps.iter().zip(vs.iter()) {
                    let c = if p.y > top - 0.08 {
                        0
                    } else if p.y < 0.1 {
                        2
                    } else {
                        1
                    };
                    acc[c][0] += v.x * v.x + v.z * v.z;
                    acc[c][1] += v.y * v.y;
                    acc[c][2] += 1.0;
                }
                for (c, name) in ["top", "bulk", "bottom"].iter().enumerate() {
                    print!(
                        "  {name}: horiz {:.4} vert {:.4} n {}",
                        (acc[c][0] / acc[c][2]).sqrt(),
                        (acc[c][1] / acc[c][2]).sqrt(),
                        acc[c][2]
                    );
                }
                println!();
            }
            if std::env::var("DISP").is_ok() {
                let ps = world.positions();
                let mut acc = vec![(0.0f64, 0.0f64, 0usize); 16];
                for (p, p0) in ps.iter().zip(initial.iter()) {
                    let l = ((p0.y - d) / d).round() as usize;
                    let dp = p - p0;
                    acc[l].0 += dp.y;
                    acc[l].1 += (dp.x * dp.x + dp.z * dp.z).sqrt();
                    acc[l].2 += 1;
                }
                for (l, a) in acc.iter().enumerate() {
                    print!(
                        "L{l}: dy {:+.4} dh {:.4} | ",
                        a.0 / a.2 as f64,
                        a.1 / a.2 as f64
                    );
                    if l % 4 == 3 {
                        println!();
                    }
                }
            }
            if std::env::var("SMOOTH").is_ok() {
                // Split the velocity into its kernel average over 2d and the rest.
                let (ps, vs) = (world.positions(), world.velocities());
                let h = 2.0 * d;
                let (mut coh, mut jit) = (0.0, 0.0);
                for i in 0..ps.len() {
                    let (mut sw, mut sv) = (0.0, Vec3::zeros());
                    for j in 0..ps.len() {
                        let q = (ps[i] - ps[j]).norm() / h;
                        if q < 1.0 {
                            let w = (1.0 - q) * (1.0 - q);
                            sw += w;
                            sv += vs[j] * w;
                        }
                    }
                    let avg = sv / sw;
                    coh += avg.norm_squared();
                    jit += (vs[i] - avg).norm_squared();
                }
                let n = ps.len() as f64;
                println!(
                    "  coherent {:.4} jitter {:.4}",
                    (coh / n).sqrt(),
                    (jit / n).sqrt()
                );
            }
            if std::env::var("DUMP").is_ok() {
                println!(
                    "{:?}",
                    world
                        .last_displacements()
                        .iter()
                        .map(|x| format!("{:.2e}", x))
                        .collect::<Vec<_>>()
                );
            }
            it = 0;
            steps = 0;
        }
    }
}
/// Writes `points` to `path` as little-endian f64 triples.
fn write_vec3s(path: &str, points: &[Vec3]) {
    let raw: Vec<u8> = points
        .iter()
        .flat_map(|p| p.iter().flat_map(|c| c.to_le_bytes()).collect::<Vec<u8>>())
        .collect();
    std::fs::write(path, raw).unwrap();
}

/// Reads the points [`write_vec3s`] wrote.
fn read_vec3s(path: &str) -> Vec<Vec3> {
    let raw = std::fs::read(path).unwrap();
    let f: Vec<f64> = raw
        .chunks(8)
        .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
        .collect();
    f.chunks(3).map(|c| Vec3::new(c[0], c[1], c[2])).collect()
}
