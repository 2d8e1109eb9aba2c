//! Frames as legacy VTK files, readable by ParaView and VisIt: `DATASET POLYDATA` with the
//! simulated time as a `TIME` field (which ParaView and VisIt read as the frame's time), the
//! particle centres as `POINTS`, one vertex cell per particle (so the points render), and
//! per-point `velocity` (m/s), `density` (kg/m³) and, where the frame has several liquids,
//! `material` (`int`). Binary files store big-endian `float`s and `int`s (the time as a
//! `double`); ASCII files write the same values as text.

use super::Frame;
use crate::{Error, Vec3};
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;

/// How a VTK file stores its numbers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VtkEncoding {
    /// Big-endian binary: compact and exact to f32 (the time to f64).
    Binary,
    /// Text: readable by any tool, the same values printed as decimals.
    Ascii,
}

/// Writes `frame` in binary: positions, velocities and densities stored as big-endian 32-bit
/// floats, materials (where it has them) as 32-bit integers. Creates or truncates `path`.
/// Errors name the path, or the field whose length differs from the positions', or a time
/// that is not finite.
pub fn write_vtk(path: &Path, frame: &Frame) -> Result<(), Error> {
    write_vtk_encoded(path, VtkEncoding::Binary, frame)
}

/// [`write_vtk`] with the numbers stored as `encoding` says.
pub fn write_vtk_encoded(path: &Path, encoding: VtkEncoding, frame: &Frame) -> Result<(), Error> {
    frame.check()?;
    let n = frame.positions.len();
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
    let mut writer = Writer {
        w: &mut w,
        encoding,
    };
    writer.write(frame).map_err(fail)?;
    w.flush().map_err(fail)
}

/// A frame being written in one encoding.
struct Writer<'a, W: Write> {
    w: &'a mut W,
    encoding: VtkEncoding,
}

impl<W: Write> Writer<'_, W> {
    /// The file's bytes, in order.
    fn write(&mut self, frame: &Frame) -> std::io::Result<()> {
        let (time, positions) = (frame.time, frame.positions);
        let n = positions.len();
        let name = match self.encoding {
            VtkEncoding::Binary => "BINARY",
            VtkEncoding::Ascii => "ASCII",
        };
        write!(
            self.w,
            "# vtk DataFile Version 3.0\nprojfluid frame\n{name}\nDATASET POLYDATA\n\
             FIELD FieldData 1\nTIME 1 1 double\n"
        )?;
        match self.encoding {
            VtkEncoding::Binary => self.w.write_all(&time.to_be_bytes())?,
            VtkEncoding::Ascii => write!(self.w, "{time:e}")?,
        }
        write!(self.w, "\nPOINTS {n} float\n")?;
        self.vectors(positions)?;
        write!(self.w, "\nVERTICES {n} {}\n", 2 * n)?;
        for i in 0..n as i32 {
            self.int(1)?;
            self.int(i)?;
            self.separate()?;
        }
        write!(self.w, "\nPOINT_DATA {n}\nVECTORS velocity float\n")?;
        self.vectors(frame.velocities)?;
        write!(self.w, "\nSCALARS density float 1\nLOOKUP_TABLE default\n")?;
        for &d in frame.densities {
            self.float(d)?;
            self.separate()?;
        }
        if !frame.materials.is_empty() {
            write!(self.w, "\nSCALARS material int 1\nLOOKUP_TABLE default\n")?;
            for &m in frame.materials {
                self.int(i32::from(m))?;
                self.separate()?;
            }
        }
        writeln!(self.w)
    }

    /// Three floats per vector.
    fn vectors(&mut self, vectors: &[Vec3]) -> std::io::Result<()> {
        for v in vectors {
            for &c in v.iter() {
                self.float(c)?;
            }
            self.separate()?;
        }
        Ok(())
    }

    /// One value as an f32.
    fn float(&mut self, value: f64) -> std::io::Result<()> {
        let value = value as f32;
        match self.encoding {
            VtkEncoding::Binary => self.w.write_all(&value.to_be_bytes()),
            VtkEncoding::Ascii => write!(self.w, "{value:e} "),
        }
    }

    /// One 32-bit integer.
    fn int(&mut self, value: i32) -> std::io::Result<()> {
        match self.encoding {
            VtkEncoding::Binary => self.w.write_all(&value.to_be_bytes()),
            VtkEncoding::Ascii => write!(self.w, "{value} "),
        }
    }

    /// In ASCII, ends a record's line.
    fn separate(&mut self) -> std::io::Result<()> {
        match self.encoding {
            VtkEncoding::Binary => Ok(()),
            VtkEncoding::Ascii => writeln!(self.w),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::Frame;
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
        let (positions, velocities, densities) = super::super::sample_frame();
        let path = temp_path("frame.vtk");
        let time = 0.1 + 0.2;
        write_vtk(
            &path,
            &Frame::new(time, &positions, &velocities, &densities),
        )
        .unwrap();
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
        assert_eq!(r.line(), "FIELD FieldData 1");
        assert_eq!(r.line(), "TIME 1 1 double");
        let bytes: [u8; 8] = r.bytes[r.at..r.at + 8].try_into().unwrap();
        r.at += 8;
        assert_eq!(f64::from_be_bytes(bytes), time);
        assert_eq!(r.line(), "");
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
        let err = write_vtk(
            &temp_path("bad.vtk"),
            &Frame::new(0.0, &p, &p[..1], &[0.0; 2]),
        )
        .unwrap_err();
        assert_eq!(
            err.to_string(),
            "velocities must have one entry per position (2), got 1"
        );
        let err = write_vtk(
            &temp_path("bad.vtk"),
            &Frame::new(f64::NAN, &p, &p, &[0.0; 2]),
        )
        .unwrap_err();
        assert_eq!(err.to_string(), "time must be finite, got NaN");
    }

    #[test]
    fn unwritable_path_is_named() {
        let path = Path::new("/nonexistent-dir/frame.vtk");
        let err = write_vtk(path, &Frame::new(0.0, &[], &[], &[])).unwrap_err();
        assert!(
            err.to_string().contains("/nonexistent-dir/frame.vtk"),
            "{err}"
        );
    }

    /// An ASCII frame holds the same sections with the values as text: the time exactly,
    /// the rest as the f32 the binary file stores.
    #[test]
    fn ascii_frame_reads_back() {
        let positions = vec![Vec3::new(0.1, 0.2, 0.3), Vec3::new(-1.5, 2.25, 1e-7)];
        let velocities = vec![Vec3::new(1.0, -2.0, 0.5), Vec3::zeros()];
        let densities = vec![1000.0, 998.25];
        let path = temp_path("ascii.vtk");
        let time = 1.0 / 3.0;
        let encoding = VtkEncoding::Ascii;
        write_vtk_encoded(
            &path,
            encoding,
            &Frame::new(time, &positions, &velocities, &densities),
        )
        .unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        std::fs::remove_file(&path).unwrap();
        let mut lines = text.lines().filter(|l| !l.trim().is_empty());
        let mut expect = |wanted: &str| assert_eq!(lines.next(), Some(wanted));
        expect("# vtk DataFile Version 3.0");
        expect("projfluid frame");
        expect("ASCII");
        expect("DATASET POLYDATA");
        expect("FIELD FieldData 1");
        expect("TIME 1 1 double");
        let rest: Vec<&str> = lines.collect();
        assert_eq!(rest[0].parse::<f64>(), Ok(time));
        assert_eq!(rest[1], "POINTS 2 float");
        let numbers = |line: &str| -> Vec<f32> {
            line.split_whitespace()
                .map(|v| v.parse().unwrap())
                .collect()
        };
        let as_f32 = |v: &Vec3| v.iter().map(|&c| c as f32).collect::<Vec<_>>();
        assert_eq!(numbers(rest[2]), as_f32(&positions[0]));
        assert_eq!(numbers(rest[3]), as_f32(&positions[1]));
        assert_eq!(rest[4], "VERTICES 2 4");
        assert_eq!(rest[5].trim(), "1 0");
        assert_eq!(rest[6].trim(), "1 1");
        assert_eq!(rest[7], "POINT_DATA 2");
        assert_eq!(rest[8], "VECTORS velocity float");
        assert_eq!(numbers(rest[9]), as_f32(&velocities[0]));
        assert_eq!(numbers(rest[10]), as_f32(&velocities[1]));
        assert_eq!(rest[11], "SCALARS density float 1");
        assert_eq!(rest[12], "LOOKUP_TABLE default");
        assert_eq!(numbers(rest[13]), [1000.0]);
        assert_eq!(numbers(rest[14]), [998.25]);
        assert_eq!(rest.len(), 15);
    }

    /// A frame with materials ends with an `int` scalar `material`, one per point.
    #[test]
    fn materials_follow_the_densities() {
        let positions = vec![Vec3::zeros(), Vec3::new(1.0, 0.0, 0.0)];
        let path = temp_path("materials.vtk");
        let frame = Frame::new(0.0, &positions, &positions, &[1000.0, 800.0]);
        write_vtk_encoded(&path, VtkEncoding::Ascii, &frame.with_materials(&[0, 1])).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        std::fs::remove_file(&path).unwrap();
        let lines: Vec<&str> = text.lines().filter(|l| !l.trim().is_empty()).collect();
        let at = lines
            .iter()
            .position(|l| *l == "SCALARS material int 1")
            .expect("a material array");
        assert_eq!(lines[at + 1], "LOOKUP_TABLE default");
        assert_eq!((lines[at + 2].trim(), lines[at + 3].trim()), ("0", "1"));
        assert_eq!(lines.len(), at + 4);
    }
}
