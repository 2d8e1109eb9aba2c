//! Frames as VTK XML PolyData (`.vtp`), the format ParaView's PVD time-series reader opens
//! (the legacy `.vtk` format it does not). The layout follows "VTK File Formats", XML file
//! formats (docs.vtk.org): a `PolyData` file of version 1.0 with `header_type="UInt64"` and
//! `byte_order="LittleEndian"`, every `DataArray` in the inline `binary` format, that is the
//! base64 of one stream holding the array's byte count (a UInt64) and then its bytes.
//!
//! A frame holds the simulated time twice as field data, both one Float64 tuple: `TIME`, the
//! name the legacy frames use, and `TimeValue`, the name VTK's XML readers (8.2 and later)
//! take as the data set's time ("Field Data as Time Meta-Data in VTK XML File Formats",
//! docs.vtk.org), so that a series of these files opened without its `.pvd` still has true
//! times. Then the particle centres as Float32 `Points` (m), one vertex cell per particle
//! (Int32 `Verts` connectivity and offsets, so that the points render), and per-point Float32
//! `velocity` (m/s, three components) and `density` (kg/m³), and UInt16 `material` where the
//! frame has several liquids: the arrays of the legacy frames.

use super::Frame;
use crate::{Error, Vec3};
use base64::engine::general_purpose::STANDARD;
use base64::write::EncoderWriter;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;

/// Writes `frame`: positions, velocities, densities and materials (where it has them)
/// stored as little-endian 32-bit floats (the materials as 16-bit unsigned integers), the time
/// as a 64-bit float. The same frame gives the same bytes. Creates or truncates `path`.
/// Errors name the path, or the field whose length differs from the positions', or a time
/// that is not finite.
pub fn write_vtp(path: &Path, frame: &Frame) -> Result<(), Error> {
    frame.check()?;
    let n = frame.positions.len();
    // The vertex offsets run to n and are stored as Int32.
    if n > i32::MAX as usize {
        return Err(Error::invalid(
            "positions",
            n,
            "must number at most 2^31 - 1 for a VTP file",
        ));
    }
    let fail = |e: std::io::Error| Error::Io(format!("cannot write {}: {e}", path.display()));
    let mut w = BufWriter::new(File::create(path).map_err(fail)?);
    write_frame(&mut w, frame).map_err(fail)?;
    w.flush().map_err(fail)
}

/// The file's text and data, in order.
fn write_frame<W: Write>(w: &mut W, frame: &Frame) -> std::io::Result<()> {
    let (positions, velocities, densities) = (frame.positions, frame.velocities, frame.densities);
    let n = positions.len();
    write!(
        w,
        "<?xml version=\"1.0\"?>\n\
         <VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\" \
         header_type=\"UInt64\">\n  <PolyData>\n    <FieldData>\n"
    )?;
    let time = frame.time.to_le_bytes();
    for name in ["TIME", "TimeValue"] {
        let attributes = format!("type=\"Float64\" Name=\"{name}\" NumberOfTuples=\"1\"");
        data_array(w, FIELD, &attributes, &time)?;
    }
    write!(
        w,
        "    </FieldData>\n    <Piece NumberOfPoints=\"{n}\" NumberOfVerts=\"{n}\" \
         NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\"0\">\n      \
         <PointData Scalars=\"density\" Vectors=\"velocity\">\n"
    )?;
    let vector = "NumberOfComponents=\"3\"";
    let attributes = format!("type=\"Float32\" Name=\"velocity\" {vector}");
    data_array(w, PIECE, &attributes, &f32_bytes(components(velocities)))?;
    let attributes = "type=\"Float32\" Name=\"density\"";
    data_array(w, PIECE, attributes, &f32_bytes(densities.iter().copied()))?;
    if !frame.materials.is_empty() {
        let bytes: Vec<u8> = frame
            .materials
            .iter()
            .flat_map(|m| m.to_le_bytes())
            .collect();
        data_array(w, PIECE, "type=\"UInt16\" Name=\"material\"", &bytes)?;
    }
    write!(w, "      </PointData>\n      <Points>\n")?;
    let attributes = format!("type=\"Float32\" Name=\"Points\" {vector}");
    data_array(w, PIECE, &attributes, &f32_bytes(components(positions)))?;
    write!(w, "      </Points>\n      <Verts>\n")?;
    // Cell i is the vertex on point i: connectivity 0, 1, …, n − 1; each cell ends one
    // further on, so the offsets (ends, not starts, in the XML format) are 1, 2, …, n.
    let (cells, ends) = (0..n as i32, 1..=n as i32);
    data_array(
        w,
        PIECE,
        "type=\"Int32\" Name=\"connectivity\"",
        &i32_bytes(cells),
    )?;
    data_array(
        w,
        PIECE,
        "type=\"Int32\" Name=\"offsets\"",
        &i32_bytes(ends),
    )?;
    write!(
        w,
        "      </Verts>\n    </Piece>\n  </PolyData>\n</VTKFile>\n"
    )
}

/// Indentation of a `DataArray` in `FieldData`, two spaces per level.
const FIELD: &str = "      ";

/// Indentation of a `DataArray` in a `Piece`.
const PIECE: &str = "        ";

/// One `DataArray` element, indented by `indent`, with `attributes` and `format="binary"`:
/// on its own line the base64 of the byte count of `bytes` (UInt64, little-endian) followed
/// by `bytes`, one stream with padding only at its end, as VTK's reader decodes an
/// uncompressed array.
fn data_array<W: Write>(
    w: &mut W,
    indent: &str,
    attributes: &str,
    bytes: &[u8],
) -> std::io::Result<()> {
    write!(
        w,
        "{indent}<DataArray {attributes} format=\"binary\">\n{indent}  "
    )?;
    let mut encoder = EncoderWriter::new(w, &STANDARD);
    encoder.write_all(&(bytes.len() as u64).to_le_bytes())?;
    encoder.write_all(bytes)?;
    let w = encoder.finish()?;
    write!(w, "\n{indent}</DataArray>\n")
}

/// The components of `vectors`, x, y, z of each in turn.
fn components(vectors: &[Vec3]) -> impl Iterator<Item = f64> + '_ {
    vectors.iter().flat_map(|v| [v.x, v.y, v.z])
}

/// `values` as little-endian 32-bit floats.
fn f32_bytes(values: impl Iterator<Item = f64>) -> Vec<u8> {
    values.flat_map(|v| (v as f32).to_le_bytes()).collect()
}

/// `values` as little-endian 32-bit integers.
fn i32_bytes(values: impl Iterator<Item = i32>) -> Vec<u8> {
    values.flat_map(i32::to_le_bytes).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::Frame;
    use base64::Engine;
    use std::path::PathBuf;

    fn temp_path(name: &str) -> PathBuf {
        std::env::temp_dir().join(format!("projfluid-vtp-{}-{name}", std::process::id()))
    }

    /// The bytes of the `DataArray` named `name` under the element `parent`, checked to be
    /// a `binary` array whose UInt64 header counts the bytes that follow it.
    fn array_bytes(doc: &roxmltree::Document, parent: &str, name: &str) -> Vec<u8> {
        let node = doc
            .descendants()
            .filter(|n| n.has_tag_name("DataArray") && n.attribute("Name") == Some(name))
            .find(|n| n.parent().is_some_and(|p| p.has_tag_name(parent)))
            .unwrap_or_else(|| panic!("a DataArray {name} in {parent}"));
        assert_eq!(node.attribute("format"), Some("binary"));
        let bytes = STANDARD.decode(node.text().unwrap().trim()).unwrap();
        let count = u64::from_le_bytes(bytes[..8].try_into().unwrap());
        assert_eq!(
            count as usize,
            bytes.len() - 8,
            "{name}: header counts the data"
        );
        bytes[8..].to_vec()
    }

    fn f32s(bytes: &[u8]) -> Vec<f32> {
        let words = bytes.chunks_exact(4);
        words
            .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
            .collect()
    }

    fn i32s(bytes: &[u8]) -> Vec<i32> {
        let words = bytes.chunks_exact(4);
        words
            .map(|c| i32::from_le_bytes(c.try_into().unwrap()))
            .collect()
    }

    fn as_f32(vectors: &[Vec3]) -> Vec<f32> {
        components(vectors).map(|c| c as f32).collect()
    }

    /// Parsed as XML and decoded from base64, a frame gives back its time exactly, every
    /// position, velocity and density as the f32 it stores, and one vertex per point.
    #[test]
    fn frame_reads_back_exactly() {
        let (positions, velocities, densities) = super::super::sample_frame();
        let path = temp_path("frame.vtp");
        let time = 0.1 + 0.2;
        write_vtp(
            &path,
            &Frame::new(time, &positions, &velocities, &densities),
        )
        .unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        std::fs::remove_file(&path).unwrap();
        let doc = roxmltree::Document::parse(&text).unwrap();

        let root = doc.root_element();
        assert_eq!(root.tag_name().name(), "VTKFile");
        for (key, value) in [
            ("type", "PolyData"),
            ("version", "1.0"),
            ("byte_order", "LittleEndian"),
            ("header_type", "UInt64"),
        ] {
            assert_eq!(root.attribute(key), Some(value), "{key}");
        }
        for name in ["TIME", "TimeValue"] {
            let bytes = array_bytes(&doc, "FieldData", name);
            assert_eq!(f64::from_le_bytes(bytes[..].try_into().unwrap()), time);
        }
        let piece = doc.descendants().find(|n| n.has_tag_name("Piece")).unwrap();
        assert_eq!(piece.attribute("NumberOfPoints"), Some("3"));
        assert_eq!(piece.attribute("NumberOfVerts"), Some("3"));

        assert_eq!(
            f32s(&array_bytes(&doc, "Points", "Points")),
            as_f32(&positions)
        );
        let velocity = array_bytes(&doc, "PointData", "velocity");
        assert_eq!(f32s(&velocity), as_f32(&velocities));
        let density = array_bytes(&doc, "PointData", "density");
        assert_eq!(f32s(&density), [1000.0, 998.25, 1012.5]);
        assert_eq!(i32s(&array_bytes(&doc, "Verts", "connectivity")), [0, 1, 2]);
        assert_eq!(i32s(&array_bytes(&doc, "Verts", "offsets")), [1, 2, 3]);

        // The point data are those of the legacy frames, and no more.
        let point_data = doc.descendants().find(|n| n.has_tag_name("PointData"));
        let names: Vec<&str> = point_data
            .unwrap()
            .children()
            .filter_map(|n| n.attribute("Name"))
            .collect();
        assert_eq!(names, ["velocity", "density"]);
        for node in doc.descendants().filter(|n| n.has_tag_name("DataArray")) {
            let components = node.attribute("NumberOfComponents").unwrap_or("1");
            let vector = ["velocity", "Points"].contains(&node.attribute("Name").unwrap());
            assert_eq!(components, if vector { "3" } else { "1" });
        }
    }

    /// A frame with materials holds them as a UInt16 `material` array after `density`; one
    /// material too few is refused, naming the field.
    #[test]
    fn materials_are_an_array_of_their_own() {
        let (positions, velocities, densities) = super::super::sample_frame();
        let path = temp_path("materials.vtp");
        let frame = Frame::new(0.5, &positions, &velocities, &densities);
        write_vtp(&path, &frame.with_materials(&[0, 2, 1])).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        let doc = roxmltree::Document::parse(&text).unwrap();
        let bytes = array_bytes(&doc, "PointData", "material");
        let ids: Vec<u16> = bytes
            .chunks_exact(2)
            .map(|b| u16::from_le_bytes([b[0], b[1]]))
            .collect();
        assert_eq!(ids, [0, 2, 1]);
        let err = write_vtp(&path, &frame.with_materials(&[0, 1])).unwrap_err();
        std::fs::remove_file(&path).unwrap();
        assert!(err.to_string().contains("materials"), "{err}");
    }

    /// Two writes of the same frame give the same bytes; a frame without particles is still
    /// a valid file with empty arrays.
    #[test]
    fn frames_are_deterministic_and_may_be_empty() {
        let positions = [Vec3::new(0.5, 0.25, 0.125), Vec3::new(1.0, 2.0, 3.0)];
        let (a, b) = (temp_path("a.vtp"), temp_path("b.vtp"));
        for path in [&a, &b] {
            write_vtp(path, &Frame::new(2.5, &positions, &positions, &[1.0, 2.0])).unwrap();
        }
        let (bytes_a, bytes_b) = (std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
        assert_eq!(bytes_a, bytes_b);

        write_vtp(&a, &Frame::new(0.0, &[], &[], &[])).unwrap();
        let text = std::fs::read_to_string(&a).unwrap();
        for path in [&a, &b] {
            std::fs::remove_file(path).unwrap();
        }
        let doc = roxmltree::Document::parse(&text).unwrap();
        assert!(array_bytes(&doc, "Points", "Points").is_empty());
        assert!(array_bytes(&doc, "Verts", "offsets").is_empty());
        let time = array_bytes(&doc, "FieldData", "TIME");
        assert_eq!(f64::from_le_bytes(time[..].try_into().unwrap()), 0.0);
    }

    #[test]
    fn bad_lengths_times_and_paths_are_named() {
        let p = [Vec3::zeros(); 2];
        let path = temp_path("bad.vtp");
        let err = write_vtp(&path, &Frame::new(0.0, &p, &p[..1], &[0.0; 2])).unwrap_err();
        assert_eq!(
            err.to_string(),
            "velocities must have one entry per position (2), got 1"
        );
        let err = write_vtp(&path, &Frame::new(f64::INFINITY, &p, &p, &[0.0; 2])).unwrap_err();
        assert_eq!(err.to_string(), "time must be finite, got inf");
        assert!(!path.exists(), "a rejected frame writes nothing");
        let err = write_vtp(
            Path::new("/nonexistent-dir/f.vtp"),
            &Frame::new(0.0, &[], &[], &[]),
        );
        let message = err.unwrap_err().to_string();
        assert!(message.contains("/nonexistent-dir/f.vtp"), "{message}");
    }
}
