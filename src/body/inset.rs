//! Boundary particles set back into a body (docs/method.md §11.1): the fluid keeps about one
//! particle radius r from boundary particles, so a body sampled on its surface would displace
//! its mesh grown by r. Moving each surface sample inward by r makes the fluid meet the mesh
//! itself, so that a body displaces its own volume.

use crate::Vec3;
use crate::boundary::mesh::TriangleMesh;
use crate::boundary::winding::is_closed_and_oriented;
use nalgebra::Matrix3;
use rayon::prelude::*;
use std::collections::HashMap;

/// A sample lies on a triangle when it is closer than this, relative to the inset depth.
const ON_SURFACE: f64 = 1e-6;
/// Two face normals at a sample count as one when their dot product exceeds this.
const SAME_NORMAL: f64 = 1.0 - 1e-9;
/// The inward offset of a sample at a sharp edge or corner is at most this many depths.
const MAX_STRETCH: f64 = 3.0;
/// A moved sample is kept when no face is nearer than its own depth, to this relative margin.
const CLEARANCE_TOLERANCE: f64 = 1e-6;

/// The samples (m, on the surface of `mesh`) moved inward by `depth` (m): a sample on a face
/// moves along the face's inward normal; one on an edge or a corner moves to where every face
/// through it is `depth` away (at most 3·`depth`), as on the inset copy of the surface. Where
/// the body is thinner than twice that, a sample moves only half way through it, so that the
/// two sides meet in the middle. A sample that lands nearer to another face than it moved
/// from its own (within `depth` of an edge, on the wrong side of the inset surface's end) is
/// dropped. A mesh that is not closed and consistently oriented has no
/// inside: its samples are returned as they are.
///
/// Cost: each sample looks only at the triangles near it (a grid of cells of 3·`depth`).
pub(crate) fn inset(mesh: &TriangleMesh, samples: &[Vec3], depth: f64) -> Vec<Vec3> {
    if depth.is_nan() || depth <= 0.0 || !is_closed_and_oriented(mesh) {
        return samples.to_vec();
    }
    let outward = if signed_volume(mesh) >= 0.0 {
        1.0
    } else {
        -1.0
    };
    let index = TriangleGrid::new(mesh, 2.0 * MAX_STRETCH * depth);
    samples
        .par_iter()
        .filter_map(|p| {
            let near = index.near(p);
            let touching: Vec<usize> = near
                .iter()
                .copied()
                .filter(|&t| distance_to_triangle(p, &mesh.corners(t)) <= ON_SURFACE * depth)
                .collect();
            let mut normals: Vec<Vec3> = Vec::new();
            for &t in &touching {
                let n = unit_normal(&mesh.corners(t)) * outward;
                if n.iter().all(|c| c.is_finite())
                    && normals.iter().all(|m| m.dot(&n) < SAME_NORMAL)
                {
                    normals.push(n);
                }
            }
            let Some(offset) = inward_offset(&normals) else {
                return Some(*p);
            };
            let stretch = offset.norm();
            let direction = offset / stretch;
            let reach = stretch * depth;
            let thickness = near
                .iter()
                .filter(|t| !touching.contains(t))
                .filter_map(|&t| ray_hit(p, &direction, &mesh.corners(t)))
                .fold(f64::INFINITY, f64::min);
            let moved = reach.min(0.5 * thickness);
            let q = p + direction * moved;
            // Near an edge or a corner, a sample can land closer to another face than to its
            // own: that part of the surface has no counterpart on the inset surface.
            let clearance = near
                .iter()
                .map(|&t| distance_to_triangle(&q, &mesh.corners(t)))
                .fold(f64::INFINITY, f64::min);
            (clearance >= moved / stretch * (1.0 - CLEARANCE_TOLERANCE)).then_some(q)
        })
        .collect()
}

/// The offset (in units of the depth) that moves a point one unit inward from every plane
/// with outward unit normal in `normals`: the least-squares solution of n·δ = −1, at most
/// [`MAX_STRETCH`] long. `None` without normals.
fn inward_offset(normals: &[Vec3]) -> Option<Vec3> {
    match normals {
        [] => None,
        [n] => Some(-n),
        _ => {
            let ntn: Matrix3<f64> = normals.iter().map(|n| n * n.transpose()).sum();
            let rhs: Vec3 = -normals.iter().sum::<Vec3>();
            let delta = ntn.svd(true, true).solve(&rhs, 1e-9).ok()?;
            let len = delta.norm();
            if len.is_nan() || len <= 0.0 {
                return Some(-normals[0]);
            }
            Some(delta * (len.min(MAX_STRETCH) / len))
        }
    }
}

/// The signed volume enclosed by a closed mesh (m³; negative when its normals point in).
fn signed_volume(mesh: &TriangleMesh) -> f64 {
    (0..mesh.triangles().len())
        .map(|t| {
            let [a, b, c] = mesh.corners(t);
            a.dot(&b.cross(&c)) / 6.0
        })
        .sum()
}

/// The unit normal of a triangle by its winding (NaN for a degenerate one).
fn unit_normal([a, b, c]: &[Vec3; 3]) -> Vec3 {
    (b - a).cross(&(c - a)).normalize()
}

/// The distance (m) from `p` to where the ray p + t·d first meets the triangle, for t > 0.
fn ray_hit(p: &Vec3, d: &Vec3, [a, b, c]: &[Vec3; 3]) -> Option<f64> {
    // Möller–Trumbore.
    let (e1, e2) = (b - a, c - a);
    let h = d.cross(&e2);
    let det = e1.dot(&h);
    if det.abs() < 1e-300 {
        return None;
    }
    let s = p - a;
    let u = s.dot(&h) / det;
    let q = s.cross(&e1);
    let v = d.dot(&q) / det;
    let t = e2.dot(&q) / det;
    (u >= 0.0 && v >= 0.0 && u + v <= 1.0 && t > 0.0).then_some(t)
}

/// The distance (m) from `p` to the closest point of a triangle (Ericson, "Real-Time
/// Collision Detection", §5.1.5).
fn distance_to_triangle(p: &Vec3, [a, b, c]: &[Vec3; 3]) -> f64 {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(&ap), ac.dot(&ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return ap.norm();
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(&bp), ac.dot(&bp));
    if d3 >= 0.0 && d4 <= d3 {
        return bp.norm();
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return (p - (a + ab * (d1 / (d1 - d3)))).norm();
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(&cp), ac.dot(&cp));
    if d6 >= 0.0 && d5 <= d6 {
        return cp.norm();
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return (p - (a + ac * (d2 / (d2 - d6)))).norm();
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (p - (b + (c - b) * w)).norm();
    }
    let denom = 1.0 / (va + vb + vc);
    let (v, w) = (vb * denom, vc * denom);
    (p - (a + ab * v + ac * w)).norm()
}

/// The triangles of a mesh binned by cells of a given size: every cell lists the triangles
/// whose bounding box, grown by one cell, overlaps it.
struct TriangleGrid {
    cell: f64,
    cells: HashMap<[i64; 3], Vec<usize>>,
}

impl TriangleGrid {
    fn new(mesh: &TriangleMesh, cell: f64) -> Self {
        let mut cells: HashMap<[i64; 3], Vec<usize>> = HashMap::new();
        let key = |x: f64| (x / cell).floor() as i64;
        for t in 0..mesh.triangles().len() {
            let corners = mesh.corners(t);
            let lo = corners
                .iter()
                .fold(Vec3::repeat(f64::INFINITY), |m, c| m.inf(c));
            let hi = corners
                .iter()
                .fold(Vec3::repeat(f64::NEG_INFINITY), |m, c| m.sup(c));
            let (lo, hi) = (lo.map(|x| key(x) - 1), hi.map(|x| key(x) + 1));
            for i in lo.x..=hi.x {
                for j in lo.y..=hi.y {
                    for k in lo.z..=hi.z {
                        cells.entry([i, j, k]).or_default().push(t);
                    }
                }
            }
        }
        TriangleGrid { cell, cells }
    }

    /// The triangles whose bounding box lies within one cell of `p`, in index order.
    fn near(&self, p: &Vec3) -> &[usize] {
        let key = p.map(|x| (x / self.cell).floor() as i64);
        self.cells
            .get(&[key.x, key.y, key.z])
            .map_or(&[], |v| v.as_slice())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::body::Shape;
    use crate::boundary::mesh::sample_poisson_disk;

    /// Every sample of a box ends `depth` inside each face it was on, so all lie on the
    /// surface of the box shrunk by `depth`.
    #[test]
    fn a_box_is_set_back_onto_its_inset_box() {
        let half = Vec3::new(0.3, 0.2, 0.1);
        let mesh = Shape::Box { half_extents: half }.mesh(0.05).unwrap();
        let samples = sample_poisson_disk(&mesh, 0.02);
        let depth = 0.025;
        let moved = inset(&mesh, &samples, depth);
        let inner = half - Vec3::repeat(depth);
        for p in &moved {
            let outside = (0..3)
                .map(|a| p[a].abs() - inner[a])
                .fold(f64::MIN, f64::max);
            assert!(
                outside.abs() < 1e-9,
                "{p:?} is {outside} m off the inset box"
            );
        }
    }

    /// A plate thinner than twice the depth closes onto its middle plane.
    #[test]
    fn a_thin_plate_closes_onto_its_middle() {
        let half = Vec3::new(0.3, 0.3, 0.01);
        let mesh = Shape::Box { half_extents: half }.mesh(0.05).unwrap();
        let samples = sample_poisson_disk(&mesh, 0.02);
        let moved = inset(&mesh, &samples, 0.025);
        assert!(moved.iter().all(|p| p.z.abs() < 1e-9));
        assert!(moved.iter().any(|p| p.x.abs() > 0.28));
    }

    /// A sphere's samples move onto the sphere of radius R − depth.
    #[test]
    fn a_sphere_shrinks_by_the_depth() {
        let mesh = Shape::Sphere { radius: 0.2 }.mesh(0.01).unwrap();
        let samples = sample_poisson_disk(&mesh, 0.02);
        let moved = inset(&mesh, &samples, 0.025);
        for (p, q) in samples.iter().zip(&moved) {
            assert!(
                ((p.norm() - q.norm()) - 0.025).abs() < 2e-3,
                "{p:?} → {q:?}"
            );
        }
    }

    /// A mesh with a hole is left as it is.
    #[test]
    fn an_open_mesh_keeps_its_samples() {
        let mesh =
            TriangleMesh::new(vec![Vec3::zeros(), Vec3::x(), Vec3::y()], vec![[0, 1, 2]]).unwrap();
        let samples = sample_poisson_disk(&mesh, 0.1);
        assert_eq!(inset(&mesh, &samples, 0.025), samples);
    }
}
