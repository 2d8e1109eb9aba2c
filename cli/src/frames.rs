//! Reading frames back: the particle positions and the time of the frames projfluid writes
//! (`--format vtp`, the default, `vtk` or `vtk-ascii`) and of other solvers that write legacy
//! VTK, such as SPlisHSPlasH, so that the probes can be read on them
//! ([`projfluid::probe::ProbeSet::read_frame`]).
//!
//! Only what the probes need is read: the points and, where the file has one, its `TIME`
//! field. Legacy VTK: `POINTS` as `float` or `double`, binary big-endian or ASCII. VTK XML
//! PolyData (`.vtp`): `Points` and `TIME` as `Float32` or `Float64` arrays, inline `binary`
//! (base64, a UInt32 or UInt64 byte count first, little-endian) or `ascii`; appended or
//! compressed data are refused with the reason.

use base64::Engine;
use base64::engine::general_purpose::STANDARD;
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

/// Reads the points and time of the frame at `path`, a legacy VTK file (`.vtk`) or a VTK
/// XML PolyData file (`.vtp`) by its extension. Errors name the path and what is wrong.
pub fn read_frame_points(path: &Path) -> Result<FramePoints, Error> {
    if path.extension().is_some_and(|x| x == "vtp") {
        let bytes = std::fs::read(path)
            .map_err(|e| Error::Io(format!("cannot read {}: {e}", path.display())))?;
        parse_vtp(&String::from_utf8_lossy(&bytes))
            .map_err(|why| Error::Io(format!("{}: {why}", path.display())))
    } else {
        read_vtk_points(path)
    }
}

/// The frame in the VTK XML PolyData `text`, or why it cannot be read.
fn parse_vtp(text: &str) -> Result<FramePoints, String> {
    let root = start_tag(text, "VTKFile").ok_or("not a VTK XML file")?;
    if attribute(root, "type") != Some("PolyData") {
        return Err("not a PolyData file".into());
    }
    if attribute(root, "compressor").is_some() {
        return Err("compressed data are not read".into());
    }
    if text.contains("<AppendedData") {
        return Err("appended data are not read (only inline arrays)".into());
    }
    if attribute(root, "byte_order").is_some_and(|o| o != "LittleEndian") {
        return Err("big-endian data are not read".into());
    }
    let header = match attribute(root, "header_type").unwrap_or("UInt32") {
        "UInt32" => 4,
        "UInt64" => 8,
        other => return Err(format!("header type `{other}`")),
    };
    let time = match text.find("<FieldData") {
        Some(at) => named_array(&text[at..], "TIME")
            .map(|array| array.values(header, 1).map(|v| v[0]))
            .transpose()?,
        None => None,
    };
    let piece = start_tag(text, "Piece").ok_or("no Piece")?;
    let n: usize = attribute(piece, "NumberOfPoints")
        .and_then(|n| n.parse().ok())
        .ok_or("no number of points")?;
    let at = text.find("<Points").ok_or("no Points")?;
    let array = first_array(&text[at..]).ok_or("no Points array")?;
    let xyz = array.values(header, 3 * n)?;
    let positions = xyz
        .chunks_exact(3)
        .map(|c| Vec3::new(c[0], c[1], c[2]))
        .collect();
    Ok(FramePoints { time, positions })
}

/// One `DataArray` element of a VTK XML file: its start tag and its text.
struct XmlArray<'a> {
    tag: &'a str,
    body: &'a str,
}

impl XmlArray<'_> {
    /// `count` values of the array (`Float32` or `Float64`; `binary` with byte counts of
    /// `header` bytes, or `ascii`), each finite.
    fn values(&self, header: usize, count: usize) -> Result<Vec<f64>, String> {
        let kind = attribute(self.tag, "type").unwrap_or("");
        let width = match kind {
            "Float32" => 4,
            "Float64" => 8,
            _ => {
                return Err(format!(
                    "an array of type `{kind}` (not Float32 or Float64)"
                ));
            }
        };
        let values: Vec<f64> = match attribute(self.tag, "format") {
            Some("binary") => {
                let bytes = STANDARD
                    .decode(self.body.split_whitespace().collect::<String>())
                    .map_err(|e| format!("bad base64: {e}"))?;
                let data = bytes.get(header..).unwrap_or_default();
                if data.len() < count * width {
                    return Err("an array ends before its values do".into());
                }
                decode(&data[..count * width], width, false)
            }
            Some("ascii") => {
                let words: Vec<&str> = self.body.split_whitespace().take(count).collect();
                if words.len() < count {
                    return Err("an array ends before its values do".into());
                }
                words
                    .iter()
                    .map(|w| w.parse().map_err(|_| format!("`{w}` is not a number")))
                    .collect::<Result<_, _>>()?
            }
            other => return Err(format!("array format {other:?} (not binary or ascii)")),
        };
        finite(values, kind)
    }
}

/// The start tag (between `<` and `>`) of the first element `name` in `text`.
fn start_tag<'a>(text: &'a str, name: &str) -> Option<&'a str> {
    let at = text.find(&format!("<{name}"))?;
    let end = text[at..].find('>')?;
    Some(&text[at + 1..at + end])
}

/// The first `DataArray` in `text`.
fn first_array(text: &str) -> Option<XmlArray<'_>> {
    let tag = start_tag(text, "DataArray")?;
    let start = text.find(tag)? + tag.len() + 1;
    let end = start + text[start..].find("</DataArray>")?;
    Some(XmlArray {
        tag,
        body: &text[start..end],
    })
}

/// The first `DataArray` in `text` whose `Name` is `name`.
fn named_array<'a>(mut text: &'a str, name: &str) -> Option<XmlArray<'a>> {
    loop {
        let array = first_array(text)?;
        if attribute(array.tag, "Name") == Some(name) {
            return Some(array);
        }
        let next = text.find("</DataArray>")? + "</DataArray>".len();
        text = &text[next..];
    }
}

/// The value of attribute `name` in the start tag `tag`.
fn attribute<'a>(tag: &'a str, name: &str) -> Option<&'a str> {
    let key = format!(" {name}=\"");
    let at = tag.find(&key)? + key.len();
    let end = tag[at..].find('"')?;
    Some(&tag[at..at + end])
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
            decode(raw, width, true)
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
        finite(values, kind)
    }
}

/// The `width`-byte floats (4 or 8) of `raw`, big- or little-endian, widened to f64.
fn decode(raw: &[u8], width: usize, big_endian: bool) -> Vec<f64> {
    let value = |c: &[u8]| match (width, big_endian) {
        (4, true) => f64::from(f32::from_be_bytes(c.try_into().expect("four bytes"))),
        (4, false) => f64::from(f32::from_le_bytes(c.try_into().expect("four bytes"))),
        (_, true) => f64::from_be_bytes(c.try_into().expect("eight bytes")),
        (_, false) => f64::from_le_bytes(c.try_into().expect("eight bytes")),
    };
    raw.chunks_exact(width).map(value).collect()
}

/// `values`, or an error naming the first that is not finite, of the type `kind`.
fn finite(values: Vec<f64>, kind: &str) -> Result<Vec<f64>, String> {
    match values.iter().position(|v| !v.is_finite()) {
        Some(i) => Err(format!("value {i} of {kind}s is not finite")),
        None => Ok(values),
    }
}

/// The frames in `dir`: its `.vtk` files or its `.vtp` files, in the order of the last number
/// in their names (`frame_00012.vtp`, `ParticleData_Fluid_12.vtk`), names without one last.
/// Errors name the directory when it cannot be read, holds neither kind or holds both.
pub fn frame_files(dir: &Path) -> Result<Vec<PathBuf>, Error> {
    let entries = std::fs::read_dir(dir)
        .map_err(|e| Error::Io(format!("cannot read directory {}: {e}", dir.display())))?;
    let paths: Vec<PathBuf> = entries.filter_map(|e| e.ok().map(|e| e.path())).collect();
    let of_kind = |kind: &str| -> Vec<(Option<u64>, PathBuf)> {
        (paths.iter())
            .filter(|p| p.extension().is_some_and(|x| x == kind))
            .map(|p| (last_number(p), p.clone()))
            .collect()
    };
    let mut files = match (of_kind("vtk"), of_kind("vtp")) {
        (vtk, vtp) if vtk.is_empty() && vtp.is_empty() => {
            return Err(Error::Io(format!(
                "no .vtk or .vtp frames in {}",
                dir.display()
            )));
        }
        (vtk, vtp) if vtp.is_empty() => vtk,
        (vtk, vtp) if vtk.is_empty() => vtp,
        _ => {
            return Err(Error::Io(format!(
                "{} holds both .vtk and .vtp frames: keep one kind",
                dir.display()
            )));
        }
    };
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

    /// What projfluid writes as VTK XML reads back through [`read_frame_points`]: the time
    /// exactly, the points as f32 rounds them. An ASCII file with a UInt32 header type reads;
    /// compressed, appended and big-endian files are refused with the reason.
    #[test]
    fn vtp_frames_read_back() {
        let dir = std::env::temp_dir().join(format!("pf_vtp_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let x = points();
        let (v, rho) = (vec![Vec3::zeros(); 3], vec![1000.0; 3]);
        let path = dir.join("frame_00003.vtp");
        projfluid::io::write_vtp(&path, &Frame::new(1.625, &x, &v, &rho)).unwrap();
        let frame = read_frame_points(&path).unwrap();
        assert_eq!(frame.time, Some(1.625));
        let rounded: Vec<Vec3> = x.iter().map(|p| p.map(|c| c as f32 as f64)).collect();
        assert_eq!(frame.positions, rounded);
        std::fs::remove_dir_all(&dir).unwrap();

        let ascii = "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"1.0\">\n\
                     <PolyData><Piece NumberOfPoints=\"2\"><Points>\n\
                     <DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n\
                     0.5 1 1.5\n-2 0 4.25\n</DataArray></Points></Piece></PolyData></VTKFile>\n";
        let frame = parse_vtp(ascii).unwrap();
        assert_eq!(frame.time, None);
        let expected = [Vec3::new(0.5, 1.0, 1.5), Vec3::new(-2.0, 0.0, 4.25)];
        assert_eq!(frame.positions, expected);
        let refused = [
            (
                "type=\"PolyData\"",
                "type=\"PolyData\" compressor=\"vtkZLibDataCompressor\"",
                "compressed",
            ),
            ("<PolyData>", "<PolyData><AppendedData/>", "appended"),
            (
                "version=\"1.0\"",
                "version=\"1.0\" byte_order=\"BigEndian\"",
                "big-endian",
            ),
            ("-2 0 4.25", "-2 0", "ends before"),
            ("Float64", "Int32", "`Int32`"),
            ("<Points>", "<Dots>", "no Points"),
        ];
        for (from, to, why) in refused {
            let e = parse_vtp(&ascii.replace(from, to)).unwrap_err();
            assert!(e.contains(why), "{to}: {e}");
        }
        assert!(parse_vtp("<html/>").unwrap_err().contains("not a VTK XML"));
    }

    /// Files sort by the last number in their names, not as text; a directory of both kinds
    /// is refused.
    #[test]
    fn files_sort_by_their_numbers() {
        let dir = std::env::temp_dir().join(format!("pf_frame_order_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        for name in ["F_10.vtk", "F_2.vtk", "F_1.vtk", "notes.txt", "extra.vtk"] {
            std::fs::write(dir.join(name), "").unwrap();
        }
        let names: Vec<String> = frame_files(&dir)
            .unwrap()
            .iter()
            .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
            .collect();
        assert_eq!(names, ["F_1.vtk", "F_2.vtk", "F_10.vtk", "extra.vtk"]);
        std::fs::write(dir.join("F_3.vtp"), "").unwrap();
        let e = frame_files(&dir).unwrap_err().to_string();
        assert!(e.contains("both .vtk and .vtp"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
        assert!(frame_files(&dir).is_err());
    }
}
