//! Frames as legacy VTK files (binary, big-endian `float`), readable by ParaView and VisIt:
//! `DATASET POLYDATA` with the particle centres as `POINTS`, one vertex cell per particle (so
//! the points render), and per-point `velocity` (m/s) and `density` (kg/m³).

use crate::{Error, Vec3};
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;

/// Writes one frame: `positions` (m), `velocities` (m/s) and `densities` (kg/m³), one entry
/// per particle, stored as big-endian 32-bit floats. Creates or truncates `path`.
/// Errors name the path, or the argument whose length differs from `positions`.
pub fn write_vtk(
    path: &Path,
    positions: &[Vec3],
    velocities: &[Vec3],
    densities: &[f64],
) -> Result<(), Error> {
    let n = positions.len();
    super::check_lengths(n, velocities, densities)?;
    if n > (i32::MAX / 2) as usize {
        return Err(Error::invalid(
            "positions",
            n,
            "must number at most 2^30 for a VTK file",
        ));
    }
    let fail = |e: std::io::Error| Error::Io(format!("cannot write {}: {e}", path.display()));
    let file = File::create(path).map_err(fail)?;
    let mut w = BufWriter::new(file);
    write_frame(&mut w, positions, velocities, densities).map_err(fail)?;
    w.flush().map_err(fail)
}

/// The file's bytes, in order.
fn write_frame(
    w: &mut impl Write,
    positions: &[Vec3],
    velocities: &[Vec3],
    densities: &[f64],
) -> std::io::Result<()> {
    let n = positions.len();
    write!(
        w,
        "# vtk DataFile Version 3.0\nprojfluid frame\nBINARY\nDATASET POLYDATA\nPOINTS {n} float\n"
    )?;
    write_vectors(w, positions)?;
    write!(w, "\nVERTICES {n} {}\n", 2 * n)?;
    for i in 0..n as i32 {
        w.write_all(&1i32.to_be_bytes())?;
        w.write_all(&i.to_be_bytes())?;
    }
    write!(w, "\nPOINT_DATA {n}\nVECTORS velocity float\n")?;
    write_vectors(w, velocities)?;
    write!(w, "\nSCALARS density float 1\nLOOKUP_TABLE default\n")?;
    for &d in densities {
        w.write_all(&(d as f32).to_be_bytes())?;
    }
    writeln!(w)
}

/// Three big-endian f32 per vector.
fn write_vectors(w: &mut impl Write, vectors: &[Vec3]) -> std::io::Result<()> {
    for v in vectors {
        for c in v.iter() {
            w.write_all(&(*c as f32).to_be_bytes())?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;

    /// A reader for exactly the files `write_vtk` writes.
    struct Reader {
        bytes: Vec<u8>,
        at: usize,
    }

    impl Reader {
        fn line(&mut self) -> String {
            let end = self.bytes[self.at..]
                .iter()
                .position(|&b| b == b'\n')
                .expect("newline")
                + self.at;
            let line = String::from_utf8(self.bytes[self.at..end].to_vec()).unwrap();
            self.at = end + 1;
            line
        }

        fn word4(&mut self) -> [u8; 4] {
            let w = self.bytes[self.at..self.at + 4].try_into().unwrap();
            self.at += 4;
            w
        }

        fn floats(&mut self, count: usize) -> Vec<f32> {
            (0..count)
                .map(|_| f32::from_be_bytes(self.word4()))
                .collect()
        }

        fn ints(&mut self, count: usize) -> Vec<i32> {
            (0..count)
                .map(|_| i32::from_be_bytes(self.word4()))
                .collect()
        }
    }

    fn temp_path(name: &str) -> PathBuf {
        std::env::temp_dir().join(format!("projfluid-vtk-{}-{name}", std::process::id()))
    }

    #[test]
    fn frame_reads_back_exactly() {
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
        let densities = vec![1000.0, 998.25, 1012.5];
        let path = temp_path("frame.vtk");
        write_vtk(&path, &positions, &velocities, &densities).unwrap();
        let mut r = Reader {
            bytes: std::fs::read(&path).unwrap(),
            at: 0,
        };
        std::fs::remove_file(&path).unwrap();
        let as_f32 = |vs: &[Vec3]| -> Vec<f32> {
            vs.iter()
                .flat_map(|v| v.iter().map(|&c| c as f32))
                .collect()
        };
        assert_eq!(r.line(), "# vtk DataFile Version 3.0");
        assert_eq!(r.line(), "projfluid frame");
        assert_eq!(r.line(), "BINARY");
        assert_eq!(r.line(), "DATASET POLYDATA");
        assert_eq!(r.line(), "POINTS 3 float");
        assert_eq!(r.floats(9), as_f32(&positions));
        assert_eq!(r.line(), "");
        assert_eq!(r.line(), "VERTICES 3 6");
        assert_eq!(r.ints(6), vec![1, 0, 1, 1, 1, 2]);
        assert_eq!(r.line(), "");
        assert_eq!(r.line(), "POINT_DATA 3");
        assert_eq!(r.line(), "VECTORS velocity float");
        assert_eq!(r.floats(9), as_f32(&velocities));
        assert_eq!(r.line(), "");
        assert_eq!(r.line(), "SCALARS density float 1");
        assert_eq!(r.line(), "LOOKUP_TABLE default");
        assert_eq!(r.floats(3), vec![1000.0f32, 998.25, 1012.5]);
        assert_eq!(r.line(), "");
        assert_eq!(r.at, r.bytes.len());
    }

    #[test]
    fn mismatched_lengths_are_rejected() {
        let p = [Vec3::zeros(); 2];
        let err = write_vtk(&temp_path("bad.vtk"), &p, &p[..1], &[0.0; 2]).unwrap_err();
        assert_eq!(
            err.to_string(),
            "velocities must have one entry per position (2), got 1"
        );
    }

    #[test]
    fn unwritable_path_is_named() {
        let path = Path::new("/nonexistent-dir/frame.vtk");
        let err = write_vtk(path, &[], &[], &[]).unwrap_err();
        assert!(
            err.to_string().contains("/nonexistent-dir/frame.vtk"),
            "{err}"
        );
    }
}
