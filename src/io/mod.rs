//! Readers and writers: VTK and PLY frames, OBJ meshes.

pub mod obj;
pub mod ply;
pub mod vtk;

pub use obj::load_obj;
pub use ply::write_ply;
pub use vtk::write_vtk;

use crate::{Error, Vec3};

/// Checks that a frame has one velocity and one density per position (`n` of them);
/// errors name the argument whose length differs.
fn check_lengths(n: usize, velocities: &[Vec3], densities: &[f64]) -> Result<(), Error> {
    for (name, len) in [
        ("velocities", velocities.len()),
        ("densities", densities.len()),
    ] {
        if len != n {
            return Err(Error::invalid(
                name,
                len,
                &format!("must have one entry per position ({n})"),
            ));
        }
    }
    Ok(())
}
