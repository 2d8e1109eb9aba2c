//! Readers and writers: frames ([`Frame`]) as VTK XML (`.vtp`, with a `.pvd` collection for
//! the time series), legacy VTK and PLY; OBJ meshes.

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

use crate::{Error, MaterialId, Vec3};
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

/// One frame's particles: what the frame writers ([`write_vtp`], [`write_vtk`],
/// [`write_ply`]) store.
#[derive(Clone, Copy, Debug)]
pub struct Frame<'a> {
    /// Simulated time (s).
    pub time: f64,
    /// Particle centres (m).
    pub positions: &'a [Vec3],
    /// Velocities (m/s), one per position.
    pub velocities: &'a [Vec3],
    /// Densities (kg/m³), one per position.
    pub densities: &'a [f64],
    /// Each particle's material (docs/method.md §14), one per position; empty leaves the
    /// `material` array out of the file, as a world of one liquid does.
    pub materials: &'a [MaterialId],
}

impl<'a> Frame<'a> {
    /// A frame of one liquid at simulated time `time` (s).
    pub fn new(
        time: f64,
        positions: &'a [Vec3],
        velocities: &'a [Vec3],
        densities: &'a [f64],
    ) -> Self {
        Self {
            time,
            positions,
            velocities,
            densities,
            materials: &[],
        }
    }

    /// The frame with each particle's material.
    pub fn with_materials(self, materials: &'a [MaterialId]) -> Self {
        Self { materials, ..self }
    }

    /// Checks that the time is finite and that there is one velocity, one density and (where
    /// given) one material per position; errors name the field at fault.
    fn check(&self) -> Result<(), Error> {
        if !self.time.is_finite() {
            return Err(Error::invalid("time", self.time, "must be finite"));
        }
        let n = self.positions.len();
        for (name, len) in [
            ("velocities", self.velocities.len()),
            ("densities", self.densities.len()),
            (
                "materials",
                if self.materials.is_empty() {
                    n
                } else {
                    self.materials.len()
                },
            ),
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
