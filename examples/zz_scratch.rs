use projfluid::body::*;
use projfluid::boundary::Aabb;
use projfluid::{Params, Vec3, World};

fn tank(nx: usize, ny: usize, nz: usize) -> World {
    let p = Params { mass_factor: 1.0, ..Params::default() };
    let mut w = World::new(p).unwrap();
    let d = 0.05;
    let size = Vec3::new(nx as f64 * d, ny as f64 * d * 2.0, nz as f64 * d);
    w.add_container(Aabb { min: Vec3::zeros(), max: size }, 1).unwrap();
    w.add_fluid_block(Vec3::repeat(d / 2.0), [nx, ny, nz], Vec3::zeros()).unwrap();
    w
}

fn main() {
    let which = std::env::args().nth(1).unwrap_or_default();
    if which == "weight" {
        let mut w = tank(16, 10, 16);
        let t = std::time::Instant::now();
        w.relax(2.0, 6.0).unwrap();
        let weight = w.fluid_count() as f64 * w.particle_mass() * 9.81;
        let tau: f64 = std::env::args().nth(2).map(|s| s.parse().unwrap()).unwrap_or(7.5e-5);
        w.set_displacement_tolerance(tau).unwrap();
        w.set_outer_iterations(1, 1000).unwrap();
        let mut sum = Vec3::zeros();
        let mut time = 0.0;
        for _ in 0..40 {
            let s = w.step().unwrap().dt;
            sum += w.wall_force() * s;
            time += s;
            let l = w.last_step().unwrap();
            println!("  it {} wall {:.1} dt {:.4}", l.outer_iterations, w.wall_force().y / weight, l.dt);
        }
        println!("weight {weight:.3} N, wall force avg {:?} ({:.4}), {:.1}s", (sum / time).as_slice(), (sum/time).y / weight, t.elapsed().as_secs_f64());
    }
    if which == "static" {
        let p = Params { mass_factor: 1.0, ..Params::default() };
        let mut w = World::new(p).unwrap();
        let d = 0.05;
        let (lx, lz) = (1.0, 1.0);
        w.add_container(Aabb { min: Vec3::zeros(), max: Vec3::new(lx, 1.2, lz) }, 1).unwrap();
        let half = Vec3::new(0.15, 0.15, 0.15);
        let centre = Vec3::new(0.5, 0.5, 0.5);
        let mut xs = Vec::new();
        for i in 0..20 { for j in 0..10 { for k in 0..20 {
            let x = Vec3::new(d/2.0 + i as f64*d, d/2.0 + j as f64*d, d/2.0 + k as f64*d);
            if (0..3).all(|a| (x[a]-centre[a]).abs() < half[a] + d/2.0) { continue; }
            xs.push(x);
        }}}
        w.add_fluid_particles(&xs, None).unwrap();
        let mesh = Shape::Box { half_extents: half }.mesh(0.025).unwrap();
        let id = w.add_body(BodySpec { kind: BodyKind::Static, mesh, mass: None, pose: Pose { position: centre, rotation: Rotation::identity() }, velocity: Velocity::default(), motion: None }).unwrap();
        w.relax(2.0, 6.0).unwrap();
        if let Some(t) = std::env::args().nth(2) { w.set_displacement_tolerance(t.parse().unwrap()).unwrap(); w.set_outer_iterations(1, 1000).unwrap(); }
        let (mut sum, mut wall) = (Vec3::zeros(), Vec3::zeros()); let mut time = 0.0;
        let nsteps: usize = std::env::var("NSTEPS").map(|s| s.parse().unwrap()).unwrap_or(300); for _ in 0..nsteps { let s = w.step().unwrap().dt; sum += w.body(id).unwrap().force() * s; wall += w.wall_force()*s; time += s; }
        let pos = w.positions();
        let inside = pos.iter().filter(|x| (0..3).all(|a| (x[a]-centre[a]).abs() < half[a])).count();
        let far: Vec<&Vec3> = pos.iter().filter(|x| ((x.x - 0.5).abs() > 0.3 || (x.z-0.5).abs() > 0.3) && x.y < 1.0).collect();
        let mut ys: Vec<f64> = far.iter().map(|x| x.y).collect();
        ys.sort_by(|a,b| a.partial_cmp(b).unwrap());
        let top = ys[ys.len()*99/100];
        let n = w.fluid_count() as f64;
        let level_vol = (n * d*d*d + 0.3*0.3*0.3f64.min(0.0)) ; 
        // water volume + submerged = level * area
        let level_geo = (n*d*d*d + 0.09*0.15) / (lx*lz); // assume submerged 0.15 first guess
        let fb = (sum/time).y;
        println!("inside {inside}, force {:?}, wall {:?}, weight {:.2}, top99 {top:.4}, level_geo {level_geo:.4} {level_vol}", (sum/time).as_slice(), (wall/time).as_slice(), n*w.particle_mass()*9.81);
        for lev in [top, top + 0.025] {
            let s = (lev - (centre.y - half.y)).clamp(0.0, 0.3);
            println!("  level {lev:.4}: rho g V = {:.3} ratio {:.4}", 1000.0*9.81*0.09*s, fb/(1000.0*9.81*0.09*s));
        }
    }
}
