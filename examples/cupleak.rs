//! The no-leak scene of `tests/obstacles.rs` (water poured over a cup with 2 cm walls), run
//! with one solver setting, printing every particle found inside the cup's walls after a step
//! (time, position, velocity, distance to the nearest boundary particle).
//!
//! `cargo run --release --example cupleak -- SOLVER` with SOLVER a solver name or `auto`
//! (Chebyshev with `--rho auto`). The default solver prints nothing; `jacobi1` and `auto`
//! print one particle slipping ≈ 1 mm into a rim corner (README, Known limitations).

use projfluid::boundary::Aabb;
use projfluid::boundary::mesh::TriangleMesh;
use projfluid::boundary::shapes::Shapes;
use projfluid::boundary::winding::is_inside;
use projfluid::{Params, Vec3, World};

/// A square cup standing on y = 0: a floor slab and four walls, all `wall` metres thick,
/// outer size 0.3 × 0.25 × 0.3 m, centred on x = z = 0.4. Closed shells that touch.
fn thin_walled_cup(wall: f64) -> TriangleMesh {
    let (lo, hi, top) = (0.25, 0.55, 0.25);
    let mut shapes = Shapes::new();
    shapes.add_box(Vec3::new(lo, 0.0, lo), Vec3::new(hi, wall, hi));
    shapes.add_box(Vec3::new(lo, wall, lo), Vec3::new(lo + wall, top, hi));
    shapes.add_box(Vec3::new(hi - wall, wall, lo), Vec3::new(hi, top, hi));
    shapes.add_box(
        Vec3::new(lo + wall, wall, lo),
        Vec3::new(hi - wall, top, lo + wall),
    );
    shapes.add_box(
        Vec3::new(lo + wall, wall, hi - wall),
        Vec3::new(hi - wall, top, hi),
    );
    shapes.into_mesh().unwrap()
}

/// A block of water falls onto a cup whose walls are 2 cm thick (less than r = 2.5 cm and a
/// fifth of the kernel support): part of it lands in the cup, the rest splashes around it.
/// After every step no particle centre may lie inside the walls or outside the tank. Steps
/// move particles at most 0.2·2r = 1 cm (CFL), so a particle crossing a wall would be seen
fn main() {
    let cup = thin_walled_cup(0.02);
    let solver = std::env::args().nth(1).unwrap_or("jacobi1".into());
    let mut params = Params {
        threads: 2,
        ..Params::default()
    };
    if solver == "auto" {
        params.chebyshev.auto_rho = true;
    } else {
        params.solver = projfluid::SolverKind::from_name(&solver).unwrap();
    }
    let mut world = World::new(params).unwrap();
    let tank = Aabb {
        min: Vec3::repeat(-0.00625),
        max: Vec3::new(0.80625, 0.90625, 0.80625),
    };
    world.add_container(tank, 1).unwrap();
    world.add_boundary_mesh(&cup).unwrap();
    world
        .add_fluid_block(Vec3::new(0.125, 0.35, 0.125), [12, 6, 12], Vec3::zeros())
        .unwrap();
    let b = world.boundary_positions().to_vec();
    while world.time() < 0.8 {
        let s = world.step().unwrap().clone();
        let (ps, vs) = (world.positions(), world.velocities());
        for (i, p) in ps.iter().enumerate() {
            if is_inside(&cup, p) {
                let dmin = b.iter().map(|q| (q - p).norm()).fold(f64::MAX, f64::min);
                println!(
                    "t {:.4} particle {i} at {:.4?} v {:.3?} nearest boundary {:.4} dt {:.5} its {}",
                    world.time(),
                    p,
                    vs[i],
                    dmin,
                    s.dt,
                    s.outer_iterations
                );
            }
        }
    }
}
