//! Readers and writers: VTK and PLY frames, OBJ meshes.

pub mod obj;
pub mod ply;
pub mod vtk;

pub use obj::load_obj;
pub use ply::write_ply;
pub use vtk::{VtkEncoding, write_vtk, write_vtk_encoded};

use crate::{Error, Vec3};

/// Checks that a frame's simulated `time` (s) is finite and that it has one velocity and one
/// density per position (`n` of them); errors name the argument at fault.
fn check_frame(time: f64, n: usize, velocities: &[Vec3], densities: &[f64]) -> Result<(), Error> {
    if !time.is_finite() {
        return Err(Error::invalid("time", time, "must be finite"));
    }
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
