//! Runs N steps of the small dam break on one thread (for instruction-count profiling).
use projfluid::{boundary::Aabb, *};
fn main() {
    let n: usize = std::env::args()
        .nth(1)
        .map(|s| s.parse().unwrap())
        .unwrap_or(20);
    let p = Params {
        solver: SolverKind::Jacobi1,
        threads: 1,
        ..Params::default()
    };
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
    w.advance(0.2).unwrap();
    let mut outer = 0;
    for _ in 0..n {
        outer += w.step().unwrap().outer_iterations;
    }
    println!("outer {outer} hash {}", w.positions_hash());
}
