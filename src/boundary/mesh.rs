//! Static triangle meshes as boundaries: [`TriangleMesh`], a validated mesh, and the
//! Poisson-disk sampling of its surface with boundary particles ([`sample_poisson_disk`],
//! in `mesh/poisson_disk.rs`).

use crate::{Error, Vec3};

mod poisson_disk;

/// Checks of a sampling's spacing and coverage, for tests elsewhere in the crate.
#[cfg(test)]
pub(crate) use poisson_disk::checks as sampling_checks;
pub use poisson_disk::{sample_count_bound, sample_poisson_disk};

/// A validated triangle mesh in metres: vertex positions and triangles as vertex indices.
/// Every triangle has three distinct in-range vertices and a positive area; winding and
/// connectivity do not matter (open surfaces, separate pieces and mixed winding are fine).
#[derive(Clone, Debug, PartialEq)]
pub struct TriangleMesh {
    vertices: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
}

impl TriangleMesh {
    /// A mesh from `vertices` (m) and `triangles` (indices into `vertices`), validated:
    /// at least one triangle, finite vertices, indices below the vertex count, and no
    /// degenerate triangle (a repeated index, or collinear corners giving zero area).
    /// Errors name the offending vertex or triangle, e.g. `triangles[4][2]` for the third
    /// index of triangle 4.
    pub fn new(vertices: Vec<Vec3>, triangles: Vec<[u32; 3]>) -> Result<Self, Error> {
        if triangles.is_empty() {
            return Err(Error::invalid(
                "triangles",
                "none",
                "must contain at least one triangle",
            ));
        }
        if let Some(i) = vertices
            .iter()
            .position(|v| !v.iter().all(|c| c.is_finite()))
        {
            return Err(Error::invalid(
                format!("vertices[{i}]"),
                format!("{:?}", vertices[i].as_slice()),
                "must be finite",
            ));
        }
        let n = vertices.len();
        for (t, tri) in triangles.iter().enumerate() {
            if let Some(k) = tri.iter().position(|&i| i as usize >= n) {
                return Err(Error::invalid(
                    format!("triangles[{t}][{k}]"),
                    tri[k],
                    &format!("must be a vertex index below the vertex count {n}"),
                ));
            }
            if tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2] {
                return Err(Error::invalid(
                    format!("triangles[{t}]"),
                    format!("{tri:?}"),
                    "is degenerate: it must have three distinct vertices",
                ));
            }
            let [a, b, c] = tri.map(|i| vertices[i as usize]);
            let area = triangle_area(&a, &b, &c);
            let longest = [(b - a), (c - b), (a - c)]
                .iter()
                .map(|e| e.norm_squared())
                .fold(0.0, f64::max);
            if !(area.is_finite() && longest.is_finite()) {
                return Err(Error::invalid(
                    format!("triangles[{t}]"),
                    format!("{tri:?} with area {area:.3e} m²"),
                    "is too large: its area or an edge length overflows",
                ));
            }
            // Zero up to rounding: the height over the longest edge is below 1e-12 of it
            // (both sides are finite here, checked just above).
            if area <= 0.5e-12 * longest {
                return Err(Error::invalid(
                    format!("triangles[{t}]"),
                    format!("{tri:?} with area {area:.3e} m²"),
                    "is degenerate: its corners must not be collinear (zero area)",
                ));
            }
        }
        Ok(Self {
            vertices,
            triangles,
        })
    }

    /// The vertex positions (m).
    pub fn vertices(&self) -> &[Vec3] {
        &self.vertices
    }

    /// The triangles, as three indices into [`TriangleMesh::vertices`] each.
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// The corners of triangle `t` (m); `t` must be below the triangle count.
    pub(crate) fn corners(&self, t: usize) -> [Vec3; 3] {
        self.triangles[t].map(|i| self.vertices[i as usize])
    }

    /// The total surface area (m²).
    pub fn area(&self) -> f64 {
        (0..self.triangles.len())
            .map(|t| {
                let [a, b, c] = self.corners(t);
                triangle_area(&a, &b, &c)
            })
            .sum()
    }

    /// The smallest axis-aligned box holding every vertex (m).
    pub fn bounds(&self) -> super::Aabb {
        // The constructor guarantees at least one triangle, hence at least three vertices.
        super::Aabb::around(&self.vertices).unwrap_or(super::Aabb {
            min: Vec3::zeros(),
            max: Vec3::zeros(),
        })
    }
}

/// The area of triangle (a, b, c) in m².
fn triangle_area(a: &Vec3, b: &Vec3, c: &Vec3) -> f64 {
    0.5 * (b - a).cross(&(c - a)).norm()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn invalid(vertices: Vec<Vec3>, triangles: Vec<[u32; 3]>) -> (String, String) {
        match TriangleMesh::new(vertices, triangles) {
            Err(Error::InvalidArgument { field, message }) => (field, message),
            other => panic!("expected an invalid-argument error, got {other:?}"),
        }
    }

    #[test]
    fn invalid_meshes_are_rejected_with_named_errors() {
        let square = || {
            vec![
                Vec3::zeros(),
                Vec3::new(1.0, 0.0, 0.0),
                Vec3::new(1.0, 1.0, 0.0),
                Vec3::new(0.0, 1.0, 0.0),
            ]
        };
        let (field, message) = invalid(square(), vec![]);
        assert_eq!(field, "triangles");
        assert!(message.contains("at least one triangle"), "{message}");

        let mut v = square();
        v[2].y = f64::NAN;
        let (field, message) = invalid(v, vec![[0, 1, 2]]);
        assert_eq!(field, "vertices[2]");
        assert!(message.contains("finite"), "{message}");
        let mut v = square();
        v[3].z = f64::NEG_INFINITY;
        assert_eq!(invalid(v, vec![[0, 1, 2]]).0, "vertices[3]");

        let (field, message) = invalid(square(), vec![[0, 1, 2], [0, 2, 4]]);
        assert_eq!(field, "triangles[1][2]");
        assert!(
            message.contains("got 4") && message.contains("4"),
            "{message}"
        );
        let (field, _) = invalid(square(), vec![[0, 1, 2], [2, 3, 0], [7, 0, 1]]);
        assert_eq!(field, "triangles[2][0]");
        assert_eq!(invalid(vec![], vec![[0, 1, 2]]).0, "triangles[0][0]");

        let (field, message) = invalid(square(), vec![[0, 1, 2], [3, 3, 0]]);
        assert_eq!(field, "triangles[1]");
        assert!(message.contains("distinct"), "{message}");

        let mut v = square();
        v.push(Vec3::new(2.0, 0.0, 0.0));
        let (field, message) = invalid(v, vec![[0, 1, 2], [2, 3, 0], [0, 1, 4]]);
        assert_eq!(field, "triangles[2]");
        assert!(message.contains("collinear"), "{message}");

        let v = vec![
            Vec3::zeros(),
            Vec3::new(1e300, 0.0, 0.0),
            Vec3::new(0.0, 1e300, 0.0),
        ];
        let (field, message) = invalid(v, vec![[0, 1, 2]]);
        assert_eq!(field, "triangles[0]");
        assert!(message.contains("too large"), "{message}");
    }
}
