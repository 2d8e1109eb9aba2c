//! Reading frames back: the particle positions and the time of legacy VTK files, those
//! projfluid writes (`--format vtk` or `vtk-ascii`, docs/method.md §10) and those of other
//! solvers such as SPlisHSPlasH, so that the probes can be read on them
//! ([`projfluid::probe::ProbeSet::read_frame`]).
//!
//! Only what the probes need is read: `POINTS` (as `float` or `double`, binary big-endian or
//! ASCII) and, where the file has one, the `TIME` field of its field data.

use projfluid::{Error, Vec3};
use std::path::{Path, PathBuf};

/// The positions and time of one frame.
#[derive(Clone, Debug, PartialEq)]
pub struct FramePoints {
    /// The frame's simulated time (s), where its file has a `TIME` field.
    pub time: Option<f64>,
    /// The particle centres (m).
    pub positions: Vec<Vec3>,
}

/// Reads the points and time of the legacy VTK file at `path`. Errors name the path and what
/// is wrong: not a legacy VTK file, no `POINTS`, a scalar type other than `float` or
/// `double`, a file that ends before its points do, or a value that is not a finite number.
pub fn read_vtk_points(path: &Path) -> Result<FramePoints, Error> {
    let bytes = std::fs::read(path)
        .map_err(|e| Error::Io(format!("cannot read {}: {e}", path.display())))?;
    parse(&bytes).map_err(|why| Error::Io(format!("{}: {why}", path.display())))
}

/// The frame in `bytes`, or why it cannot be read.
fn parse(bytes: &[u8]) -> Result<FramePoints, String> {
    let mut cursor = Cursor { bytes, at: 0 };
    if !cursor.line()?.starts_with("# vtk DataFile") {
        return Err("not a legacy VTK file".into());
    }
    cursor.line()?; // the title
    let binary = match cursor.line()?.trim() {
        "BINARY" => true,
        "ASCII" => false,
        other => return Err(format!("unknown encoding `{other}`")),
    };
    let mut time = None;
    loop {
        let line = cursor.line()?;
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.as_slice() {
            ["TIME", "1", "1", kind] => {
                time = Some(cursor.values(binary, kind, 1)?[0]);
            }
            ["POINTS", count, kind] => {
                let n: usize = count
                    .parse()
                    .map_err(|_| format!("bad point count `{count}`"))?;
                let xyz = cursor.values(binary, kind, 3 * n)?;
                let positions = xyz
                    .chunks_exact(3)
                    .map(|c| Vec3::new(c[0], c[1], c[2]))
                    .collect();
                return Ok(FramePoints { time, positions });
            }
            _ => {}
        }
    }
}

/// A read position in a file's bytes.
struct Cursor<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl Cursor<'_> {
    /// The next line, without its end; an error at the end of the file.
    fn line(&mut self) -> Result<String, String> {
        if self.at >= self.bytes.len() {
            return Err("no POINTS before the end of the file".into());
        }
        let rest = &self.bytes[self.at..];
        let end = rest.iter().position(|&b| b == b'\n').unwrap_or(rest.len());
        self.at += (end + 1).min(rest.len());
        Ok(String::from_utf8_lossy(&rest[..end]).into_owned())
    }

    /// `count` values of the scalar type `kind` (`float` or `double`), big-endian binary or
    /// whitespace-separated text; each must be finite.
    fn values(&mut self, binary: bool, kind: &str, count: usize) -> Result<Vec<f64>, String> {
        let width = match kind {
            "float" => 4,
            "double" => 8,
            _ => return Err(format!("points of type `{kind}` (not float or double)")),
        };
        let values = if binary {
            let end = count
                .checked_mul(width)
                .and_then(|n| n.checked_add(self.at))
                .filter(|&end| end <= self.bytes.len())
                .ok_or("the file ends before its values do")?;
            let raw = &self.bytes[self.at..end];
            self.at = end;
            let value = |c: &[u8]| match width {
                4 => f64::from(f32::from_be_bytes(c.try_into().expect("four bytes"))),
                _ => f64::from_be_bytes(c.try_into().expect("eight bytes")),
            };
            raw.chunks_exact(width).map(value).collect::<Vec<f64>>()
        } else {
            let mut values = Vec::with_capacity(count.min(1 << 24));
            while values.len() < count {
                let line = self
                    .line()
                    .map_err(|_| "the file ends before its values do")?;
                for word in line.split_whitespace() {
                    values.push(
                        word.parse::<f64>()
                            .map_err(|_| format!("`{word}` is not a number"))?,
                    );
                }
            }
            values.truncate(count);
            values
        };
        match values.iter().position(|v| !v.is_finite()) {
            Some(i) => Err(format!("value {i} of {kind}s is not finite")),
            None => Ok(values),
        }
    }
}

/// The legacy VTK files (`*.vtk`) in `dir`, in the order of the last number in their names
/// (`frame_00012.vtk`, `ParticleData_Fluid_12.vtk`), names without one last. Errors name the
/// directory when it cannot be read or holds no such file.
pub fn vtk_files(dir: &Path) -> Result<Vec<PathBuf>, Error> {
    let entries = std::fs::read_dir(dir)
        .map_err(|e| Error::Io(format!("cannot read directory {}: {e}", dir.display())))?;
    let mut files: Vec<(Option<u64>, PathBuf)> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "vtk"))
        .map(|p| (last_number(&p), p))
        .collect();
    if files.is_empty() {
        return Err(Error::Io(format!("no .vtk files in {}", dir.display())));
    }
    files.sort_by(|a, b| match (a.0, b.0) {
        (Some(x), Some(y)) => x.cmp(&y).then_with(|| a.1.cmp(&b.1)),
        (Some(_), None) => std::cmp::Ordering::Less,
        (None, Some(_)) => std::cmp::Ordering::Greater,
        (None, None) => a.1.cmp(&b.1),
    });
    Ok(files.into_iter().map(|(_, p)| p).collect())
}

/// The last run of digits in the file name of `path`, without its extension.
fn last_number(path: &Path) -> Option<u64> {
    let stem = path.file_stem()?.to_str()?;
    let end = stem.rfind(|c: char| c.is_ascii_digit())? + 1;
    let start = stem[..end]
        .rfind(|c: char| !c.is_ascii_digit())
        .map_or(0, |i| i + 1);
    stem[start..end].parse().ok()
}

#[cfg(test)]
mod tests {
    use super::*;
    use projfluid::io::{Frame, VtkEncoding, write_vtk_encoded};

    fn points() -> Vec<Vec3> {
        vec![
            Vec3::new(0.125, -1.5, 2.0),
            Vec3::new(3.0, 0.0625, -0.25),
            Vec3::new(1e-3, 2e-3, 3e-3),
        ]
    }

    /// What projfluid writes, binary and ASCII, reads back: the points as f32 rounds them and
    /// the time exactly.
    #[test]
    fn projfluid_frames_read_back() {
        let dir = std::env::temp_dir().join(format!("pf_frames_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let x = points();
        let (v, rho) = (vec![Vec3::zeros(); 3], vec![1000.0; 3]);
        for (name, encoding) in [
            ("b.vtk", VtkEncoding::Binary),
            ("a.vtk", VtkEncoding::Ascii),
        ] {
            let path = dir.join(name);
            write_vtk_encoded(&path, encoding, &Frame::new(0.375, &x, &v, &rho)).unwrap();
            let frame = read_vtk_points(&path).unwrap();
            assert_eq!(frame.time, Some(0.375), "{name}");
            let rounded: Vec<Vec3> = x.iter().map(|p| p.map(|c| c as f32 as f64)).collect();
            if encoding == VtkEncoding::Binary {
                assert_eq!(frame.positions, rounded);
            } else {
                let close = frame.positions.iter().zip(&rounded);
                assert!(
                    close.clone().all(|(a, b)| (a - b).norm() < 1e-6),
                    "{frame:?}"
                );
            }
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// A file in SPlisHSPlasH's layout (no time, an unstructured grid, points then cells)
    /// reads; bad files are refused with the reason.
    #[test]
    fn other_layouts_and_bad_files() {
        let mut bytes = b"# vtk DataFile Version 4.1\nSPlisHSPlasH particle data\nBINARY\n\
                          DATASET UNSTRUCTURED_GRID\nPOINTS 2 double\n"
            .to_vec();
        for c in [0.5f64, 1.0, 1.5, -2.0, 0.0, 4.25] {
            bytes.extend(c.to_be_bytes());
        }
        bytes.extend(b"\nCELLS 2 4\n");
        let frame = parse(&bytes).unwrap();
        assert_eq!(frame.time, None);
        let expected = [Vec3::new(0.5, 1.0, 1.5), Vec3::new(-2.0, 0.0, 4.25)];
        assert_eq!(frame.positions, expected);
        let cut = &bytes[..bytes.len() - 20];
        assert!(parse(cut).unwrap_err().contains("ends before"));
        let mut nan = bytes.clone();
        let at = nan.len() - 11 - 8;
        nan[at..at + 8].copy_from_slice(&f64::NAN.to_be_bytes());
        assert!(parse(&nan).unwrap_err().contains("not finite"));
        assert!(parse(b"hello\n").unwrap_err().contains("not a legacy VTK"));
        let ints = b"# vtk DataFile Version 3.0\nt\nASCII\nDATASET POLYDATA\nPOINTS 1 int\n1 2 3\n";
        assert!(parse(ints).unwrap_err().contains("`int`"));
        let none = b"# vtk DataFile Version 3.0\nt\nASCII\nDATASET POLYDATA\n";
        assert!(parse(none).unwrap_err().contains("no POINTS"));
    }

    /// Files sort by the last number in their names, not as text.
    #[test]
    fn files_sort_by_their_numbers() {
        let dir = std::env::temp_dir().join(format!("pf_frame_order_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        for name in ["F_10.vtk", "F_2.vtk", "F_1.vtk", "notes.txt", "extra.vtk"] {
            std::fs::write(dir.join(name), "").unwrap();
        }
        let names: Vec<String> = vtk_files(&dir)
            .unwrap()
            .iter()
            .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
            .collect();
        assert_eq!(names, ["F_1.vtk", "F_2.vtk", "F_10.vtk", "extra.vtk"]);
        std::fs::remove_dir_all(&dir).unwrap();
        assert!(vtk_files(&dir).is_err());
    }
}
