//! Checks of Poisson-disk samples (spacing, coverage) shared by the tests, and the
//! sampler's tests.

use super::*;

pub(crate) mod checks {
    use super::*;

    /// The particle radius the checks and tests sample with (m).
    pub(crate) const R: f64 = 0.025;

    /// Finds the nearest sample to a point by a bucket grid of cell size `cell`.
    pub(super) struct Nearest {
        cell: f64,
        buckets: HashMap<[i64; 3], Vec<Vec3>>,
    }

    impl Nearest {
        pub(super) fn new(points: &[Vec3], cell: f64) -> Self {
            let mut buckets: HashMap<[i64; 3], Vec<Vec3>> = HashMap::new();
            for p in points {
                buckets
                    .entry(p.map(|c| (c / cell).floor() as i64).into())
                    .or_default()
                    .push(*p);
            }
            Self { cell, buckets }
        }

        /// The distance to the nearest point within `reach` cells, or infinity.
        pub(super) fn distance(&self, p: &Vec3, reach: i64) -> f64 {
            let c = p.map(|x| (x / self.cell).floor() as i64);
            let mut best = f64::INFINITY;
            for dx in -reach..=reach {
                for dy in -reach..=reach {
                    for dz in -reach..=reach {
                        if let Some(b) = self.buckets.get(&[c.x + dx, c.y + dy, c.z + dz]) {
                            for q in b {
                                best = best.min((q - p).norm());
                            }
                        }
                    }
                }
            }
            best
        }
    }

    /// Every point of a fine lattice on each triangle (spacing `spacing`).
    fn surface_lattice(mesh: &TriangleMesh, spacing: f64) -> Vec<Vec3> {
        let mut out = Vec::new();
        for t in 0..mesh.triangles().len() {
            let [a, b, c] = mesh.corners(t);
            let n = steps((b - a).norm().max((c - a).norm()), spacing);
            for i in 0..=n {
                for j in 0..=n - i {
                    let (u, v) = (i as f64 / n as f64, j as f64 / n as f64);
                    out.push(a + (b - a) * u + (c - a) * v);
                }
            }
        }
        out
    }

    /// Samples `mesh` at [`R`] and checks the result: no two samples closer than r, every
    /// surface point within 1.5·r of one, every sample within the mesh's bounds.
    pub(crate) fn check_spacing_and_coverage(mesh: &TriangleMesh) -> Vec<Vec3> {
        let samples = sample_poisson_disk(mesh, R);
        assert!(!samples.is_empty());
        let nearest = Nearest::new(&samples, R);
        // No two samples closer than r (pairs closer than r share or neighbour a grid cell).
        let mut min_pair = f64::INFINITY;
        for (cell, bucket) in &nearest.buckets {
            for p in bucket {
                for dx in -1..=1 {
                    for dy in -1..=1 {
                        for dz in -1..=1 {
                            let key = [cell[0] + dx, cell[1] + dy, cell[2] + dz];
                            for q in nearest.buckets.get(&key).into_iter().flatten() {
                                if p != q {
                                    min_pair = min_pair.min((p - q).norm());
                                }
                            }
                        }
                    }
                }
            }
        }
        assert!(
            min_pair >= R * (1.0 - 1e-6),
            "two samples are {min_pair} m apart, closer than r = {R}"
        );
        // Every surface point lies within 1.5 r of a sample.
        let mut worst = 0.0f64;
        for p in surface_lattice(mesh, R / 5.0) {
            worst = worst.max(nearest.distance(&p, 2));
        }
        assert!(
            worst <= 1.5 * R,
            "a surface point is {worst} m from every sample (1.5 r = {})",
            1.5 * R
        );
        // Samples lie on the surface: within the bounds, on some triangle's plane.
        let bounds = mesh.bounds();
        assert!(samples.iter().all(|p| bounds.contains(p, 1e-12)));
        samples
    }
}

mod tests {
    use super::checks::{Nearest, R, check_spacing_and_coverage};
    use super::*;
    use crate::{Params, World};

    /// A closed axis-aligned box from `min` to `max` as 8 vertices and 12 triangles, with
    /// mixed winding on purpose.
    fn box_mesh(min: Vec3, max: Vec3) -> TriangleMesh {
        let vertices: Vec<Vec3> = (0..8)
            .map(|i| {
                Vec3::new(
                    if i & 1 == 0 { min.x } else { max.x },
                    if i & 2 == 0 { min.y } else { max.y },
                    if i & 4 == 0 { min.z } else { max.z },
                )
            })
            .collect();
        let quads = [
            [0, 1, 3, 2],
            [4, 6, 7, 5],
            [0, 4, 5, 1],
            [2, 3, 7, 6],
            [0, 2, 6, 4],
            [1, 5, 7, 3],
        ];
        let triangles = quads
            .iter()
            .flat_map(|q| [[q[0], q[1], q[2]], [q[2], q[3], q[0]]])
            .collect();
        TriangleMesh::new(vertices, triangles).unwrap()
    }

    fn unit_cube() -> TriangleMesh {
        box_mesh(Vec3::zeros(), Vec3::repeat(1.0))
    }

    /// A closed plate 0.6 m × 5 mm × 0.4 m: four of its sides are much thinner than r.
    fn thin_plate() -> TriangleMesh {
        box_mesh(Vec3::new(0.1, 0.2, -0.1), Vec3::new(0.7, 0.205, 0.3))
    }

    #[test]
    fn unit_cube_samples_are_spaced_and_cover_the_surface() {
        let mesh = unit_cube();
        let samples = check_spacing_and_coverage(&mesh);
        // Every sample lies on a face of the cube.
        for p in &samples {
            assert!(
                (0..3).any(|a| p[a].abs() < 1e-12 || (p[a] - 1.0).abs() < 1e-12),
                "{p:?} is off the surface"
            );
        }
        // Maximal Poisson disk sampling reaches roughly 0.6–0.75 samples per r² on a plane.
        let density = samples.len() as f64 * R * R / mesh.area();
        assert!((0.55..0.85).contains(&density), "density {density}");
        assert!(samples.len() as f64 <= sample_count_bound(&mesh, R));
    }

    /// Sharp edges are sampled evenly: every corner is a sample and every point of the
    /// twelve edges of a box lies within r/2 of one, while a flat diagonal is not an edge.
    #[test]
    fn box_edges_and_corners_are_sampled_evenly() {
        let (min, max) = (Vec3::new(0.1, 0.2, 0.3), Vec3::new(0.5, 0.3, 0.45));
        let mesh = box_mesh(min, max);
        assert_eq!(feature_edges(&mesh).len(), 12);
        let nearest = Nearest::new(&sample_poisson_disk(&mesh, R), R);
        let corners = mesh.vertices().to_vec();
        for a in &corners {
            assert!(
                nearest.distance(a, 1) < 1e-12,
                "corner {a:?} is not a sample"
            );
            for b in &corners {
                let along = (b - a).map(|c| (c.abs() > 1e-12) as u8).sum();
                if along != 1 {
                    continue;
                }
                for i in 0..=100 {
                    let p = a + (b - a) * (i as f64 / 100.0);
                    let d = nearest.distance(&p, 2);
                    assert!(
                        d <= 0.5 * R * (1.0 + 1e-6),
                        "{p:?} on an edge is {d} m from every sample"
                    );
                }
            }
        }
    }

    #[test]
    fn thin_plate_samples_are_spaced_and_cover_the_thin_sides() {
        let mesh = thin_plate();
        let samples = check_spacing_and_coverage(&mesh);
        assert!(samples.len() as f64 <= sample_count_bound(&mesh, R));
        // The thin sides (5 mm wide) are covered too: points along the middle of a long
        // thin side are within r-ish of a sample.
        let nearest = Nearest::new(&samples, R);
        for i in 0..=60 {
            let p = Vec3::new(0.1 + 0.6 * i as f64 / 60.0, 0.2025, -0.1);
            assert!(nearest.distance(&p, 2) <= 1.5 * R);
        }
    }

    #[test]
    fn sample_count_scales_with_area() {
        let small = sample_poisson_disk(&unit_cube(), R).len() as f64;
        let large = sample_poisson_disk(&box_mesh(Vec3::zeros(), Vec3::repeat(2.0)), R).len();
        let ratio = large as f64 / small;
        assert!((ratio / 4.0 - 1.0).abs() < 0.15, "ratio {ratio}");
        let plate = sample_poisson_disk(&thin_plate(), R).len() as f64;
        let plate2 = sample_poisson_disk(
            &box_mesh(Vec3::new(0.2, 0.4, -0.2), Vec3::new(1.4, 0.41, 0.6)),
            R,
        )
        .len() as f64;
        assert!(
            (plate2 / plate / 4.0 - 1.0).abs() < 0.15,
            "ratio {}",
            plate2 / plate
        );
    }

    #[test]
    fn sampling_is_deterministic_and_independent_of_threads() {
        let mesh = thin_plate();
        let first = sample_poisson_disk(&mesh, R);
        for threads in [1, 3] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let again = pool.install(|| sample_poisson_disk(&mesh, R));
            assert!(first == again, "{threads} threads gave different samples");
        }
    }

    #[test]
    fn a_single_thin_triangle_is_covered_along_its_length() {
        // 2 m long, 1 mm wide: the random candidates alone would leave gaps.
        let mesh = TriangleMesh::new(
            vec![
                Vec3::zeros(),
                Vec3::new(2.0, 0.0, 0.0),
                Vec3::new(1.0, 0.001, 0.0),
            ],
            vec![[0, 1, 2]],
        )
        .unwrap();
        let samples = sample_poisson_disk(&mesh, R);
        let nearest = Nearest::new(&samples, R);
        for i in 0..=400 {
            let p = Vec3::new(2.0 * i as f64 / 400.0, 0.0, 0.0);
            assert!(nearest.distance(&p, 2) <= 1.5 * R, "gap at {p:?}");
        }
        assert!(
            samples.len() >= 40 && samples.len() <= 81,
            "{}",
            samples.len()
        );
    }

    #[test]
    fn bad_distances_give_no_samples() {
        for d in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert!(sample_poisson_disk(&unit_cube(), d).is_empty());
            assert_eq!(sample_count_bound(&unit_cube(), d), f64::INFINITY);
        }
    }

    #[test]
    fn world_adds_a_mesh_as_boundary_particles() {
        let mut world = World::new(Params {
            threads: 2,
            ..Params::default()
        })
        .unwrap();
        let r = world.params().particle_radius;
        let mesh = box_mesh(Vec3::repeat(0.2), Vec3::repeat(0.4));
        world.add_boundary_mesh(&mesh).unwrap();
        let expected = sample_poisson_disk(&mesh, r);
        assert_eq!(world.boundary_count(), expected.len());
        assert!(world.boundary_positions() == expected.as_slice());

        // Absurd sizes are refused, leaving the world unchanged.
        let huge = box_mesh(Vec3::zeros(), Vec3::repeat(1000.0));
        let err = world.add_boundary_mesh(&huge).unwrap_err();
        assert!(err.to_string().contains("mesh"), "{err}");
        let far = TriangleMesh::new(
            vec![
                Vec3::zeros(),
                Vec3::new(0.1, 0.0, 0.0),
                Vec3::new(0.0, 0.1, 0.0),
                Vec3::new(1e6, 0.0, 0.0),
                Vec3::new(1e6 + 0.1, 0.0, 0.0),
                Vec3::new(1e6, 0.1, 0.0),
            ],
            vec![[0, 1, 2], [3, 4, 5]],
        )
        .unwrap();
        assert!(world.add_boundary_mesh(&far).is_err());
        assert_eq!(world.boundary_count(), expected.len());
    }
}
