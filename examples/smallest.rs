//! The smallest simulation: a box, a block of water, half a second of CFL-limited steps.
//!
//! `cargo run --release --example smallest`

use projfluid::boundary::Aabb;
use projfluid::{Params, Vec3, World};

fn main() -> Result<(), projfluid::Error> {
    // r = 0.025 m, water (ρ0 = 1000 kg/m³), the Chebyshev solver with ρ estimated online.
    let mut world = World::new(Params::default())?;
    // A closed 0.6 m box, its walls one layer of boundary particles.
    world.add_container(
        Aabb {
            min: Vec3::zeros(),
            max: Vec3::new(0.6, 0.6, 0.6),
        },
        1,
    )?;
    // 8 × 8 × 8 particles on the 2r lattice, the first centred at (0.05, 0.05, 0.05) m, at rest.
    world.add_fluid_block(Vec3::repeat(0.05), [8, 8, 8], Vec3::zeros())?;
    let steps = world.advance(0.5)?;
    let last = world.last_step().expect("advance took at least one step");
    println!(
        "{} particles, {steps} steps to t = {:.3} s; last step: Δt = {:.2} ms, {} outer iterations, \
         {:.4} % average compression; {} escaped",
        world.fluid_count(),
        world.time(),
        1e3 * last.dt,
        last.outer_iterations,
        100.0 * last.density_error_avg,
        world.escaped_count(),
    );
    Ok(())
}
