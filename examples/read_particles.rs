//! Reading the particles of a running simulation: positions, velocities and densities in the
//! order the particles were added, and copies into a caller's f32 buffer as an engine would
//! upload them to the GPU. Writes the last state as a VTK frame for ParaView.
//!
//! `cargo run --release --example read_particles [OUT.vtk]`

use projfluid::boundary::Aabb;
use projfluid::{Params, Vec3, World};

fn main() -> Result<(), projfluid::Error> {
    let mut world = World::new(Params::default())?;
    world.add_container(
        Aabb {
            min: Vec3::zeros(),
            max: Vec3::new(0.8, 0.6, 0.4),
        },
        1,
    )?;
    // A column against the x = 0 wall: it collapses into a small dam break.
    world.add_fluid_block(Vec3::repeat(0.05), [6, 10, 6], Vec3::zeros())?;

    for _ in 0..5 {
        world.advance(0.1)?;
        let positions = world.positions(); // m
        let velocities = world.velocities(); // m/s
        let densities = world.densities(); // kg/m³
        let front = positions.iter().map(|x| x.x).fold(f64::MIN, f64::max);
        let fastest = velocities.iter().map(|v| v.norm()).fold(0.0, f64::max);
        let densest = densities.iter().copied().fold(0.0, f64::max);
        println!(
            "t = {:.2} s: front at x = {front:.3} m, fastest {fastest:.2} m/s, densest {densest:.1} kg/m³",
            world.time()
        );
    }

    // An engine's vertex buffer: x, y, z of each particle as f32, in the order they were added.
    let mut buffer = vec![0.0f32; 3 * world.fluid_count()];
    world
        .write_positions_f32(&mut buffer)
        .expect("the buffer holds 3 floats per particle");
    println!(
        "first particle at ({:.3}, {:.3}, {:.3}) m",
        buffer[0], buffer[1], buffer[2]
    );

    if let Some(path) = std::env::args().nth(1) {
        let (x, v, rho) = (world.positions(), world.velocities(), world.densities());
        let frame = projfluid::io::Frame::new(world.time(), &x, &v, &rho);
        projfluid::io::write_vtk(std::path::Path::new(&path), &frame)?;
        println!("wrote {path}");
    }
    Ok(())
}
