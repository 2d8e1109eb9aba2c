//! Readers and writers: frames as VTK XML (`.vtp`, with a `.pvd` collection for the time
//! series), legacy VTK and PLY; OBJ meshes.

pub mod obj;
pub mod ply;
pub mod pvd;
pub mod vtk;
pub mod vtp;

pub use obj::load_obj;
pub use ply::write_ply;
pub use pvd::{PvdDataSet, write_pvd};
pub use vtk::{VtkEncoding, write_vtk, write_vtk_encoded};
pub use vtp::write_vtp;

use crate::{Error, Vec3};
use std::ffi::OsString;
use std::path::Path;

/// Replaces the contents of `path` with `bytes` all at once: writes them to `path` with
/// `.tmp` appended to its name, then renames that file over `path`. A rename within one
/// directory replaces the target atomically (POSIX `rename`; Rust's `std::fs::rename`
/// replaces an existing file on Windows too), so a reader, or a run stopped at any point,
/// sees the old contents or the new ones, never a part. Errors name `path`.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<(), Error> {
    let fail = |e: std::io::Error| Error::Io(format!("cannot write {}: {e}", path.display()));
    let Some(name) = path.file_name() else {
        return Err(Error::invalid("path", path.display(), "must name a file"));
    };
    let mut temporary = OsString::from(name);
    temporary.push(".tmp");
    let temporary = path.with_file_name(temporary);
    std::fs::write(&temporary, bytes).map_err(fail)?;
    std::fs::rename(&temporary, path).map_err(|e| {
        // Best effort: the error that matters is the rename's.
        let _ = std::fs::remove_file(&temporary);
        fail(e)
    })
}

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

/// A frame of three particles whose values exercise signs, zeros and small magnitudes, for the
/// writers' read-back tests: positions (m), velocities (m/s) and densities (kg/m³).
#[cfg(test)]
fn sample_frame() -> (Vec<Vec3>, Vec<Vec3>, Vec<f64>) {
    let positions = vec![
        Vec3::new(0.1, 0.2, 0.3),
        Vec3::new(-1.5, 2.25, 1e-7),
        Vec3::new(3.0, 0.0, -0.125),
    ];
    let velocities = vec![
        Vec3::new(1.0, -2.0, 0.5),
        Vec3::zeros(),
        Vec3::new(0.333, 1e3, -7.0),
    ];
    (positions, velocities, vec![1000.0, 998.25, 1012.5])
}
