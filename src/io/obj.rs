//! Wavefront OBJ meshes as [`TriangleMesh`]es, read with the `tobj` crate.
//!
//! Only vertex positions (`v`) and faces (`f`) matter; polygons are split into triangle fans,
//! and points, lines, normals, texture coordinates and materials are ignored. Every error
//! names the file and, where one line is at fault, the line: a face that does not parse or
//! has fewer than three vertices, an index out of range, a degenerate triangle, or a line
//! `tobj` rejects.

use crate::Error;
use crate::Vec3;
use crate::boundary::mesh::TriangleMesh;
use std::cell::Cell;
use std::io::{BufRead, Read};
use std::path::Path;
use std::rc::Rc;

/// Reads the OBJ file at `path` into a validated triangle mesh (coordinates taken as metres).
/// Errors (as [`Error::InvalidArgument`] with field `obj`, or [`Error::Io`] when the file
/// cannot be read) start with `PATH:LINE:` when a line is at fault, else with `PATH:`.
pub fn load_obj(path: &Path) -> Result<TriangleMesh, Error> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| Error::Io(format!("cannot read OBJ file {}: {e}", path.display())))?;
    parse_obj(&text, &path.display().to_string())
}

/// Writes `mesh` as an OBJ file at `path`: a `#` comment line per entry of `comments`, then
/// one `v` line per vertex (coordinates in metres, printed so that they read back exactly)
/// and one `f` line per triangle. Errors name the path.
pub fn write_obj(path: &Path, mesh: &TriangleMesh, comments: &[&str]) -> Result<(), Error> {
    use std::fmt::Write as _;
    let mut text = String::new();
    for c in comments {
        let _ = writeln!(text, "# {c}");
    }
    for v in mesh.vertices() {
        let _ = writeln!(text, "v {} {} {}", v.x, v.y, v.z);
    }
    for t in mesh.triangles() {
        let _ = writeln!(text, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    std::fs::write(path, text)
        .map_err(|e| Error::Io(format!("cannot write OBJ file {}: {e}", path.display())))
}

/// Parses OBJ `text`; `origin` (usually the file name) starts every error message.
pub fn parse_obj(text: &str, origin: &str) -> Result<TriangleMesh, Error> {
    let at = |line: usize, what: String| Error::InvalidArgument {
        field: "obj".to_string(),
        message: format!("{origin}:{line}: {what}"),
    };
    let faces = scan_faces(text).map_err(|(line, what)| at(line, what))?;

    let mut reader = LineReader::new(text.as_bytes());
    let line = reader.line.clone();
    let options = tobj::LoadOptions {
        triangulate: true,
        ignore_points: true,
        ignore_lines: true,
        ..tobj::LoadOptions::default()
    };
    let (models, _) = tobj::load_obj_buf(&mut reader, &options, |_| {
        Ok((Vec::new(), Default::default()))
    })
    .map_err(|e| at(line.get(), format!("{e}")))?;

    let mut vertices = Vec::new();
    let mut triangles = Vec::new();
    for model in &models {
        let mesh = &model.mesh;
        let base = vertices.len() as u32;
        vertices.extend(
            mesh.positions
                .chunks_exact(3)
                .map(|p| Vec3::new(p[0], p[1], p[2])),
        );
        triangles.extend(
            mesh.indices
                .chunks_exact(3)
                .map(|t| [base + t[0], base + t[1], base + t[2]]),
        );
    }
    // The triangle fans of the faces, in file order: the line of every triangle.
    let lines: Vec<usize> = faces
        .iter()
        .flat_map(|&(line, corners)| std::iter::repeat_n(line, corners - 2))
        .collect();
    TriangleMesh::new(vertices, triangles).map_err(|e| {
        let Error::InvalidArgument { field, message } = &e else {
            return e;
        };
        let triangle = field
            .strip_prefix("triangles[")
            .and_then(|rest| rest.split(']').next())
            .and_then(|t| t.parse::<usize>().ok());
        match triangle.and_then(|t| lines.get(t).copied()) {
            Some(line) => {
                // "triangles[t] RULE, got VALUE": keep the rule, show the face as written.
                let rule = message.trim_start_matches(field.as_str()).trim();
                let rule = rule.rfind(", got ").map_or(rule, |i| &rule[..i]);
                let face = text.lines().nth(line - 1).unwrap_or("").trim();
                at(line, format!("face `{face}` {rule}"))
            }
            None if field == "triangles" => Error::InvalidArgument {
                field: "obj".to_string(),
                message: format!("{origin}: has no faces (at least one triangle is needed)"),
            },
            None => Error::InvalidArgument {
                field: "obj".to_string(),
                message: format!("{origin}: {message}"),
            },
        }
    })
}

/// Checks every face line, so that errors can name their line, and returns (line number,
/// number of corners) of each face in file order. Accepts `v`, `v/t`, `v//n` and `v/t/n`
/// corners with positive (1-based) or negative (relative) position indices; every index
/// must refer to a vertex of the file (forward references are allowed, as `tobj` does).
fn scan_faces(text: &str) -> Result<Vec<(usize, usize)>, (usize, String)> {
    let mut faces = Vec::new();
    // (line, absolute 1-based index, as written) of every corner, checked once all `v` are known.
    let mut corners = Vec::new();
    let mut vertex_count = 0i64;
    for (number, line) in text.lines().enumerate() {
        let number = number + 1;
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => vertex_count += 1,
            Some("f") => {
                let mut count = 0;
                for word in words {
                    let first = word.split('/').next().unwrap_or("");
                    let index: i64 = first.parse().map_err(|_| {
                        (
                            number,
                            format!(
                                "malformed face: corner `{word}` does not start with a vertex index"
                            ),
                        )
                    })?;
                    let absolute = match index {
                        0 => {
                            return Err((
                                number,
                                "malformed face: vertex index 0 (OBJ indices start at 1)"
                                    .to_string(),
                            ));
                        }
                        i if i < 0 => vertex_count + 1 + i,
                        i => i,
                    };
                    corners.push((number, absolute, index));
                    count += 1;
                }
                if count < 3 {
                    return Err((
                        number,
                        format!("malformed face: {count} vertices, at least 3 are needed"),
                    ));
                }
                faces.push((number, count));
            }
            _ => {}
        }
    }
    for (number, absolute, written) in corners {
        if absolute < 1 || absolute > vertex_count {
            return Err((
                number,
                format!(
                    "face vertex index {written} is out of range: the file has {vertex_count} vertices"
                ),
            ));
        }
    }
    Ok(faces)
}

/// A reader that hands out at most one line per `fill_buf`, counting the lines started,
/// so that when `tobj` (which reads line by line) fails, the count is the failing line.
struct LineReader<'a> {
    rest: &'a [u8],
    /// Bytes of the current line not yet consumed.
    in_line: usize,
    /// Number of the line being read (1-based; 0 before the first).
    line: Rc<Cell<usize>>,
}

impl<'a> LineReader<'a> {
    fn new(bytes: &'a [u8]) -> Self {
        Self {
            rest: bytes,
            in_line: 0,
            line: Rc::new(Cell::new(0)),
        }
    }
}

impl Read for LineReader<'_> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let available = self.fill_buf()?;
        let n = available.len().min(buf.len());
        buf[..n].copy_from_slice(&available[..n]);
        self.consume(n);
        Ok(n)
    }
}

impl BufRead for LineReader<'_> {
    fn fill_buf(&mut self) -> std::io::Result<&[u8]> {
        if self.in_line == 0 && !self.rest.is_empty() {
            self.in_line = self
                .rest
                .iter()
                .position(|&b| b == b'\n')
                .map_or(self.rest.len(), |i| i + 1);
            self.line.set(self.line.get() + 1);
        }
        Ok(&self.rest[..self.in_line])
    }

    fn consume(&mut self, amount: usize) {
        let amount = amount.min(self.in_line);
        self.rest = &self.rest[amount..];
        self.in_line -= amount;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const TETRA: &str = "# a tetrahedron\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n\
                         f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";

    fn error(text: &str) -> String {
        match parse_obj(text, "test.obj") {
            Ok(_) => panic!("expected an error for {text:?}"),
            Err(e) => e.to_string(),
        }
    }

    #[test]
    fn a_tetrahedron_loads() {
        let mesh = parse_obj(TETRA, "t.obj").unwrap();
        assert_eq!(mesh.vertices().len(), 4);
        assert_eq!(mesh.triangles().len(), 4);
        assert!((mesh.area() - (1.5 + 3f64.sqrt() / 2.0)).abs() < 1e-12);
    }

    #[test]
    fn polygons_become_fans_and_extras_are_ignored() {
        let text = "o square\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\nvt 0 0\n\
                    usemtl none\nf 1/1/1 2/1/1 3/1/1 4/1/1\nl 1 2\ng other\nf -4 -3 -1\n";
        let mesh = parse_obj(text, "q.obj").unwrap();
        assert_eq!(mesh.triangles().len(), 3);
        assert!((mesh.area() - 1.5).abs() < 1e-12);
    }

    #[test]
    fn coordinates_are_read_exactly() {
        let mesh = parse_obj(
            "v 0.1 0.2 0.30000000000000004\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
            "x",
        )
        .unwrap();
        assert_eq!(mesh.vertices()[0], Vec3::new(0.1, 0.2, 0.30000000000000004));
    }

    #[test]
    fn malformed_faces_name_the_line() {
        let text = TETRA.replace("f 1 2 4", "f 1 two 4");
        assert_eq!(
            error(&text),
            "test.obj:7: malformed face: corner `two` does not start with a vertex index"
        );
        let text = TETRA.replace("f 1 4 3", "f 1 4");
        assert_eq!(
            error(&text),
            "test.obj:8: malformed face: 2 vertices, at least 3 are needed"
        );
        let text = TETRA.replace("f 2 3 4", "f 0 3 4");
        assert!(error(&text).starts_with("test.obj:9: malformed face: vertex index 0"));
    }

    #[test]
    fn indices_out_of_range_name_the_line() {
        let text = TETRA.replace("f 1 4 3", "f 1 5 3");
        assert_eq!(
            error(&text),
            "test.obj:8: face vertex index 5 is out of range: the file has 4 vertices"
        );
        let text = TETRA.replace("f 1 3 2", "f -5 1 2");
        assert!(error(&text).starts_with("test.obj:6: face vertex index -5 is out of range"));
    }

    #[test]
    fn degenerate_triangles_name_the_line() {
        let text = TETRA.replace("f 1 4 3", "f 1 4 4");
        let msg = error(&text);
        assert_eq!(
            msg,
            "test.obj:8: face `f 1 4 4` is degenerate: it must have three distinct vertices"
        );
        // Collinear corners: vertex 5 lies on the edge from 1 to 2.
        let text = format!("{TETRA}v 0.5 0 0\nf 1 2 5\n");
        let msg = error(&text);
        assert_eq!(
            msg,
            "test.obj:11: face `f 1 2 5` is degenerate: its corners must not be collinear (zero area)"
        );
        // The second triangle of a quad's fan.
        let text = format!("{TETRA}v 0 2 0\nf 1 2 3 5\n");
        assert!(error(&text).starts_with("test.obj:11: face `f 1 2 3 5` is degenerate"));
    }

    #[test]
    fn written_meshes_read_back_exactly() {
        let mesh = parse_obj(TETRA, "t.obj").unwrap();
        let moved = crate::boundary::Transform {
            rotate_deg: [10.0, 20.0, 30.0],
            ..Default::default()
        }
        .apply(&mesh)
        .unwrap();
        let path = std::env::temp_dir().join(format!("projfluid-obj-{}.obj", std::process::id()));
        write_obj(&path, &moved, &["a tetrahedron", "rotated"]).unwrap();
        let back = load_obj(&path).unwrap();
        std::fs::remove_file(&path).unwrap();
        assert_eq!(back, moved);
    }

    #[test]
    fn lines_tobj_rejects_are_named() {
        let text = TETRA.replace("v 0 1 0", "v 0 one 0");
        assert_eq!(error(&text), "test.obj:4: position parse error");
    }

    #[test]
    fn empty_and_missing_files_are_named() {
        assert_eq!(
            error("v 0 0 0\n"),
            "test.obj: has no faces (at least one triangle is needed)"
        );
        let msg = load_obj(Path::new("/nonexistent/mesh.obj"))
            .unwrap_err()
            .to_string();
        assert!(
            msg.starts_with("cannot read OBJ file /nonexistent/mesh.obj:"),
            "{msg}"
        );
    }
}
