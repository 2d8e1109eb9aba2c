//! Frames as PLY point clouds (binary little-endian), readable by Blender, MeshLab and
//! CloudCompare: the simulated time in a header comment `comment time T` (s, printed so that
//! it reads back exactly), and one `vertex` element per particle with `float` properties
//! `x y z` (m), `vx vy vz` (m/s) and `density` (kg/m³), and a `ushort` property `material`
//! where the frame has several liquids.

use super::Frame;
use crate::Error;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;

/// Writes `frame`: positions, velocities and densities as little-endian 32-bit floats, and
/// materials (where it has them) as 16-bit unsigned integers. Creates or truncates `path`.
/// Errors name the path, or the field whose length differs from the positions', or a time
/// that is not finite.
pub fn write_ply(path: &Path, frame: &Frame) -> Result<(), Error> {
    frame.check()?;
    let fail = |e: std::io::Error| Error::Io(format!("cannot write {}: {e}", path.display()));
    let mut w = BufWriter::new(File::create(path).map_err(fail)?);
    let with_materials = !frame.materials.is_empty();
    write!(
        w,
        "ply\nformat binary_little_endian 1.0\ncomment projfluid frame\ncomment time {}\n\
         element vertex {}\n\
         property float x\nproperty float y\nproperty float z\n\
         property float vx\nproperty float vy\nproperty float vz\n\
         property float density\n{}end_header\n",
        frame.time,
        frame.positions.len(),
        if with_materials {
            "property ushort material\n"
        } else {
            ""
        }
    )
    .map_err(fail)?;
    let records = frame
        .positions
        .iter()
        .zip(frame.velocities)
        .zip(frame.densities);
    for (k, ((x, v), &rho)) in records.enumerate() {
        let mut record = [0u8; 28];
        let values = [x.x, x.y, x.z, v.x, v.y, v.z, rho];
        for (chunk, value) in record.chunks_exact_mut(4).zip(values) {
            chunk.copy_from_slice(&(value as f32).to_le_bytes());
        }
        w.write_all(&record).map_err(fail)?;
        if with_materials {
            w.write_all(&frame.materials[k].to_le_bytes())
                .map_err(fail)?;
        }
    }
    w.flush().map_err(fail)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Vec3;

    /// Reads exactly the files `write_ply` writes: the header lines and the records.
    fn read_ply(bytes: &[u8]) -> (Vec<String>, Vec<[f32; 7]>) {
        let end = b"end_header\n";
        let split = bytes
            .windows(end.len())
            .position(|w| w == end)
            .expect("end_header")
            + end.len();
        let header: Vec<String> = std::str::from_utf8(&bytes[..split])
            .unwrap()
            .lines()
            .map(str::to_string)
            .collect();
        let body = &bytes[split..];
        assert_eq!(body.len() % 28, 0, "records of 7 floats");
        let records = body
            .chunks_exact(28)
            .map(|r| {
                std::array::from_fn(|k| f32::from_le_bytes(r[4 * k..4 * k + 4].try_into().unwrap()))
            })
            .collect();
        (header, records)
    }

    #[test]
    fn frame_reads_back_exactly() {
        let positions = vec![Vec3::new(0.1, 0.2, 0.3), Vec3::new(-1.5, 2.25, 1e-7)];
        let velocities = vec![Vec3::new(1.0, -2.0, 0.5), Vec3::new(0.333, 1e3, -7.0)];
        let densities = vec![1000.0, 998.25];
        let path = std::env::temp_dir().join(format!("projfluid-ply-{}.ply", std::process::id()));
        let time = 0.1 + 0.2;
        write_ply(
            &path,
            &Frame::new(time, &positions, &velocities, &densities),
        )
        .unwrap();
        let bytes = std::fs::read(&path).unwrap();
        std::fs::remove_file(&path).unwrap();
        let (header, records) = read_ply(&bytes);
        assert_eq!(
            header,
            [
                "ply",
                "format binary_little_endian 1.0",
                "comment projfluid frame",
                "comment time 0.30000000000000004",
                "element vertex 2",
                "property float x",
                "property float y",
                "property float z",
                "property float vx",
                "property float vy",
                "property float vz",
                "property float density",
                "end_header"
            ]
        );
        assert_eq!(header[3]["comment time ".len()..].parse::<f64>(), Ok(time));
        assert_eq!(records.len(), 2);
        for i in 0..2 {
            let (x, v) = (positions[i], velocities[i]);
            let expected = [x.x, x.y, x.z, v.x, v.y, v.z, densities[i]].map(|c| c as f32);
            assert_eq!(records[i], expected);
        }
    }

    #[test]
    fn bad_lengths_and_paths_are_named() {
        let p = [Vec3::zeros(); 2];
        let err = write_ply(Path::new("/tmp/x.ply"), &Frame::new(0.0, &p, &p, &[0.0])).unwrap_err();
        assert_eq!(
            err.to_string(),
            "densities must have one entry per position (2), got 1"
        );
        let err = write_ply(
            Path::new("/nonexistent/f.ply"),
            &Frame::new(0.0, &[], &[], &[]),
        )
        .unwrap_err();
        assert!(err.to_string().contains("/nonexistent/f.ply"), "{err}");
    }

    /// A frame with materials adds a `ushort material` property after `density`.
    #[test]
    fn materials_are_a_property_of_each_vertex() {
        let positions = vec![Vec3::new(0.1, 0.2, 0.3), Vec3::new(-1.5, 2.25, 1e-7)];
        let path = std::env::temp_dir().join(format!("projfluid-ply-m-{}.ply", std::process::id()));
        let frame = Frame::new(0.0, &positions, &positions, &[1000.0, 800.0]);
        write_ply(&path, &frame.with_materials(&[3, 1])).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        std::fs::remove_file(&path).unwrap();
        let end = b"end_header\n";
        let split = bytes.windows(end.len()).position(|w| w == end).unwrap() + end.len();
        let header = std::str::from_utf8(&bytes[..split]).unwrap();
        assert!(header.ends_with("property float density\nproperty ushort material\nend_header\n"));
        let body = &bytes[split..];
        assert_eq!(body.len(), 2 * 30);
        assert_eq!(u16::from_le_bytes([body[28], body[29]]), 3);
        assert_eq!(u16::from_le_bytes([body[58], body[59]]), 1);
    }
}
