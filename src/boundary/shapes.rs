//! Closed, outward-oriented triangle meshes of simple solids, to build obstacles from: swept
//! tubes (a cross-section moved along a path, capped at both ends), geodesic spheres and
//! boxes. Each [`Shapes::add_*`] adds one closed shell; shells may touch or overlap.

use super::mesh::TriangleMesh;
use crate::{Error, Vec3};

/// One position along a swept tube: the centre of the cross-section and the two axes
/// (unit, perpendicular to each other) of its plane, scaled by `size`.
#[derive(Clone, Copy, Debug)]
pub struct Frame {
    /// Centre of the cross-section (m).
    pub centre: Vec3,
    /// First axis of the cross-section's plane (unit).
    pub u: Vec3,
    /// Second axis of the cross-section's plane (unit).
    pub v: Vec3,
    /// Half-extent of the cross-section along u and along v (m).
    pub size: [f64; 2],
}

/// A growing set of closed shells.
#[derive(Clone, Debug, Default)]
pub struct Shapes {
    vertices: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
}

impl Shapes {
    /// No shells yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds a tube: the closed 2-D `section` (points (a, b), each placed at
    /// centre + a·size₀·u + b·size₁·v, counter-clockwise or not) swept through `frames` (at
    /// least two), with flat caps at both ends.
    pub fn add_sweep(&mut self, section: &[[f64; 2]], frames: &[Frame]) {
        let first = self.vertices.len();
        let n = section.len() as u32;
        for f in frames {
            self.vertices.extend(
                section
                    .iter()
                    .map(|&[a, b]| f.centre + f.u * (a * f.size[0]) + f.v * (b * f.size[1])),
            );
        }
        let ring = |k: usize, i: u32| (first + k * n as usize) as u32 + i % n;
        let start = self.triangles.len();
        for k in 0..frames.len() - 1 {
            for i in 0..n {
                let (a, b) = (ring(k, i), ring(k, i + 1));
                let (c, d) = (ring(k + 1, i + 1), ring(k + 1, i));
                self.triangles.push([a, b, c]);
                self.triangles.push([a, c, d]);
            }
        }
        for (k, flip) in [(0, true), (frames.len() - 1, false)] {
            let centre = self.vertices.len() as u32;
            self.vertices.push(frames[k].centre);
            for i in 0..n {
                let (a, b) = (ring(k, i), ring(k, i + 1));
                self.triangles
                    .push(if flip { [centre, b, a] } else { [centre, a, b] });
            }
        }
        self.orient_outward(start);
    }

    /// Adds a geodesic sphere: an icosahedron subdivided `levels` times (20·4^levels
    /// triangles), its vertices pushed onto the sphere.
    pub fn add_sphere(&mut self, centre: Vec3, radius: f64, levels: u32) {
        let t = (1.0 + 5f64.sqrt()) / 2.0;
        let mut points: Vec<Vec3> = [
            [-1.0, t, 0.0],
            [1.0, t, 0.0],
            [-1.0, -t, 0.0],
            [1.0, -t, 0.0],
            [0.0, -1.0, t],
            [0.0, 1.0, t],
            [0.0, -1.0, -t],
            [0.0, 1.0, -t],
            [t, 0.0, -1.0],
            [t, 0.0, 1.0],
            [-t, 0.0, -1.0],
            [-t, 0.0, 1.0],
        ]
        .iter()
        .map(|p| Vec3::from(*p).normalize())
        .collect();
        let mut faces: Vec<[u32; 3]> = vec![
            [0, 11, 5],
            [0, 5, 1],
            [0, 1, 7],
            [0, 7, 10],
            [0, 10, 11],
            [1, 5, 9],
            [5, 11, 4],
            [11, 10, 2],
            [10, 7, 6],
            [7, 1, 8],
            [3, 9, 4],
            [3, 4, 2],
            [3, 2, 6],
            [3, 6, 8],
            [3, 8, 9],
            [4, 9, 5],
            [2, 4, 11],
            [6, 2, 10],
            [8, 6, 7],
            [9, 8, 1],
        ];
        for _ in 0..levels {
            let mut midpoints = std::collections::HashMap::new();
            let mut midpoint = |a: u32, b: u32, points: &mut Vec<Vec3>| {
                *midpoints.entry((a.min(b), a.max(b))).or_insert_with(|| {
                    points.push(((points[a as usize] + points[b as usize]) * 0.5).normalize());
                    points.len() as u32 - 1
                })
            };
            faces = faces
                .iter()
                .flat_map(|&[a, b, c]| {
                    let ab = midpoint(a, b, &mut points);
                    let bc = midpoint(b, c, &mut points);
                    let ca = midpoint(c, a, &mut points);
                    [[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]
                })
                .collect();
        }
        let first = self.vertices.len() as u32;
        let start = self.triangles.len();
        self.vertices
            .extend(points.iter().map(|p| centre + p * radius));
        self.triangles
            .extend(faces.iter().map(|f| f.map(|i| i + first)));
        self.orient_outward(start);
    }

    /// Adds an axis-aligned box from `min` to `max` (m).
    pub fn add_box(&mut self, min: Vec3, max: Vec3) {
        let half = (max - min) * 0.5;
        let centre = (min + max) * 0.5;
        let frame = |y: f64| Frame {
            centre: Vec3::new(centre.x, y, centre.z),
            u: Vec3::x(),
            v: Vec3::z(),
            size: [half.x, half.z],
        };
        self.add_sweep(&square(), &[frame(min.y), frame(max.y)]);
    }

    /// Flips the triangles from `start` on (one closed shell) if they enclose a negative
    /// volume, so that their normals (right-hand rule) point outward.
    fn orient_outward(&mut self, start: usize) {
        let volume: f64 = self.triangles[start..]
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| self.vertices[i as usize]);
                a.dot(&b.cross(&c))
            })
            .sum();
        if volume < 0.0 {
            for t in &mut self.triangles[start..] {
                t.swap(1, 2);
            }
        }
    }

    /// The shells as one validated mesh.
    pub fn into_mesh(self) -> Result<TriangleMesh, Error> {
        TriangleMesh::new(self.vertices, self.triangles)
    }
}

/// A cross-section: `n` points on the unit circle, counter-clockwise.
pub fn circle(n: usize) -> Vec<[f64; 2]> {
    (0..n)
        .map(|i| {
            let a = std::f64::consts::TAU * i as f64 / n as f64;
            [a.cos(), a.sin()]
        })
        .collect()
}

/// A cross-section: the square [−1, 1]², counter-clockwise.
pub fn square() -> Vec<[f64; 2]> {
    vec![[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]]
}
