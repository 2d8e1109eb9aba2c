//! Poisson-disk sampling of a triangle mesh's surface (Bowers et al. 2010, "Parallel Poisson
//! disk sampling with spectrum analysis on surfaces", as used by SPlisHSPlasH) followed by a
//! gap-filling pass, so that obstacles of any shape become boundary particles spaced about
//! one particle radius apart.

use super::{TriangleMesh, triangle_area};
use crate::Vec3;
use crate::random::{SplitMix64, mix64};
use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

/// An upper bound on the number of points [`sample_poisson_disk`] returns for `mesh` and
/// `min_distance` (m), computed without sampling: the points made on one triangle are at
/// least `min_distance` apart (to a relative 10⁻⁶), so discs of half that radius around them
/// are disjoint
/// and lie within the triangle grown by that radius. Use it to refuse absurd requests
/// before sampling; the actual count is typically about half of it for large triangles.
/// Infinite when `min_distance` is not positive and finite.
pub fn sample_count_bound(mesh: &TriangleMesh, min_distance: f64) -> f64 {
    if !(min_distance > 0.0 && min_distance.is_finite()) {
        return f64::INFINITY;
    }
    // Samples may be closer than min_distance by a relative 10⁻⁶ (see `insert_if_free`).
    let r = 0.5 * min_distance * (1.0 - 1e-6);
    let disc = std::f64::consts::PI * r * r;
    (0..mesh.triangles.len())
        .map(|t| {
            let [a, b, c] = mesh.corners(t);
            let perimeter = (b - a).norm() + (c - b).norm() + (a - c).norm();
            (triangle_area(&a, &b, &c) + perimeter * r + disc) / disc
        })
        .sum()
}

/// Random candidates per disc of radius `min_distance` (Bowers et al. use about 40).
const CANDIDATES_PER_DISC: f64 = 40.0;
/// Rounds over the 27 phase groups in which each cell tries its next candidate.
const ROUNDS: usize = 10;
/// Fixed seed of the candidate generator, so that sampling is reproducible.
const SEED: u64 = 0x5eed_5eed_9e37_79b9;

/// Poisson-disk samples of the surface of `mesh`: points on its triangles, no two closer
/// than `min_distance` (m; to a relative 10⁻⁶), and every surface point within about
/// 1.4·`min_distance` of a sample (the sampling is maximal on a lattice of spacing
/// `min_distance`/3).
///
/// Method: first every sharp edge (see `feature_edges`: an open border, or a fold of more
/// than 30°) is sampled evenly at a spacing of at most `min_distance`, so that a fold such
/// as a thin wall's rim leaves no gap for fluid to squeeze through. Then (Bowers et al.
/// 2010, as in SPlisHSPlasH) about 40·area/(π·min_distance²) random
/// candidates are drawn (triangles chosen with probability proportional to area, uniform
/// barycentric coordinates, a fixed-seed generator), binned into cells of size
/// min_distance/√3, and the cells are visited in 27 phase groups (cell index mod 3 per
/// axis) for 10 rounds, each cell trying its next candidate, which is accepted when no
/// accepted sample lies closer than `min_distance`. A final pass walks every triangle on a
/// lattice of spacing at most `min_distance`/3 (its corners included) and accepts every
/// lattice point that is at least `min_distance` from all samples, which fills the gaps
/// the random candidates missed, e.g. on triangles thinner than `min_distance`.
///
/// The result is deterministic: the same mesh and distance always give the same points in
/// the same order, whatever the thread count. Time and memory grow with
/// area/min_distance² (about 32 bytes per candidate); check [`sample_count_bound`] first
/// for inputs that may be absurd. Returns no points when `min_distance` is not positive
/// and finite.
pub fn sample_poisson_disk(mesh: &TriangleMesh, min_distance: f64) -> Vec<Vec3> {
    if !(min_distance > 0.0 && min_distance.is_finite()) {
        return Vec::new();
    }
    let mut samples = SampleGrid::new(mesh.bounds().min, min_distance);

    // Sharp edges first, evenly at a spacing of at most `min_distance`, so that the fluid
    // finds no gap where the surface folds (random and lattice samples alone can leave
    // about 1.4·min_distance of an edge uncovered).
    for (a, b) in feature_edges(mesh) {
        // Lengths a whole multiple of the distance, read in f32 or f64, give the same count.
        let n = steps((b - a).norm() * (1.0 - 1e-6), min_distance);
        for i in 0..=n {
            samples.insert_if_free(a + (b - a) * (i as f64 / n as f64));
        }
    }

    // Candidates, sorted by cell (stable, so equal cells keep their drawing order).
    let mut candidates = random_candidates(mesh, min_distance);
    candidates.sort_by_key(|&(key, _)| key);
    // Runs of candidates sharing a cell key, grouped by the phase of their cell.
    let mut phases: [Vec<(usize, usize)>; 27] = std::array::from_fn(|_| Vec::new());
    let mut start = 0;
    while start < candidates.len() {
        let key = candidates[start].0;
        let len = candidates[start..].partition_point(|&(k, _)| k == key);
        let phase = samples.phase(&candidates[start].1);
        phases[phase].push((start, start + len));
        start += len;
    }
    for round in 0..ROUNDS {
        for group in &phases {
            for &(start, end) in group {
                if start + round < end {
                    samples.insert_if_free(candidates[start + round].1);
                }
            }
        }
    }
    drop(candidates);

    // Fill the gaps: a lattice on every triangle, rows parallel to its longest edge.
    let spacing = min_distance / 3.0;
    for t in 0..mesh.triangles.len() {
        let [a, b, c] = mesh.corners(t);
        // Base (p0, p1) is the longest edge, so both base angles are acute and any point
        // of the triangle projects onto the next row towards the base inside the triangle.
        let (p0, p1, apex) = [(a, b, c), (b, c, a), (c, a, b)]
            .into_iter()
            .max_by(|x, y| (x.1 - x.0).norm().total_cmp(&(y.1 - y.0).norm()))
            .unwrap_or((a, b, c));
        let base = (p1 - p0).norm();
        let height = 2.0 * triangle_area(&a, &b, &c) / base;
        let rows = steps(height, spacing);
        for k in 0..=rows {
            let s = k as f64 / rows as f64;
            let (q0, q1) = (p0 + (apex - p0) * s, p1 + (apex - p1) * s);
            let n = steps((1.0 - s) * base, spacing);
            for i in 0..=n {
                samples.insert_if_free(q0 + (q1 - q0) * (i as f64 / n as f64));
            }
        }
    }
    samples.points
}

/// Cosine of the smallest dihedral fold that counts as a sharp edge: faces meeting at more
/// than 30° from flat (a box's edges, a cup's rim), while finely tessellated curved
/// surfaces have much smaller folds.
const SHARP_FOLD_COS: f64 = 0.866_025_403_784_438_6;

/// The mesh's feature edges as pairs of corner positions (m), in a deterministic order:
/// edges (by vertex index) used by only one triangle, by three or more, or by two whose
/// normals differ by more than 30°.
fn feature_edges(mesh: &TriangleMesh) -> Vec<(Vec3, Vec3)> {
    let mut faces: HashMap<(u32, u32), Vec<usize>> = HashMap::new();
    for (t, tri) in mesh.triangles.iter().enumerate() {
        for k in 0..3 {
            let (i, j) = (tri[k], tri[(k + 1) % 3]);
            faces.entry((i.min(j), i.max(j))).or_default().push(t);
        }
    }
    let normal = |t: usize| {
        let [a, b, c] = mesh.corners(t);
        (b - a).cross(&(c - a)).normalize()
    };
    let mut edges: Vec<(u32, u32)> = faces
        .iter()
        .filter(|(_, ts)| match ts.as_slice() {
            // Winding may be mixed, so a fold is measured without the normals' signs.
            [s, t] => normal(*s).dot(&normal(*t)).abs() < SHARP_FOLD_COS,
            _ => true,
        })
        .map(|(&e, _)| e)
        .collect();
    edges.sort_unstable();
    edges
        .into_iter()
        .map(|(i, j)| (mesh.vertices[i as usize], mesh.vertices[j as usize]))
        .collect()
}

/// The number of equal steps of at most `spacing` that cover `length` (at least 1).
fn steps(length: f64, spacing: f64) -> usize {
    ((length / spacing).ceil() as usize).max(1)
}

/// About 40·area/(π·min_distance²) random points on `mesh`, each with its cell key.
fn random_candidates(mesh: &TriangleMesh, min_distance: f64) -> Vec<(u64, Vec3)> {
    let cumulative: Vec<f64> = (0..mesh.triangles.len())
        .scan(0.0, |sum, t| {
            let [a, b, c] = mesh.corners(t);
            *sum += triangle_area(&a, &b, &c);
            Some(*sum)
        })
        .collect();
    let total = cumulative.last().copied().unwrap_or(0.0);
    let count = (CANDIDATES_PER_DISC * total / (std::f64::consts::PI * min_distance * min_distance))
        .round() as usize;
    let grid = SampleGrid::new(mesh.bounds().min, min_distance);
    let mut rng = SplitMix64(SEED);
    let mut out = Vec::with_capacity(count.min(1 << 24));
    for _ in 0..count {
        let target = rng.next_f64() * total;
        let t = cumulative
            .partition_point(|&c| c <= target)
            .min(cumulative.len() - 1);
        let [a, b, c] = mesh.corners(t);
        let (mut u, mut v) = (rng.next_f64(), rng.next_f64());
        if u + v > 1.0 {
            (u, v) = (1.0 - u, 1.0 - v);
        }
        let p = a + (b - a) * u + (c - a) * v;
        out.push((grid.key(&grid.cell(&p)), p));
    }
    out
}

/// Hashes a `u64` cell key with [`mix64`].
#[derive(Default)]
struct KeyHasher(u64);

impl Hasher for KeyHasher {
    fn finish(&self) -> u64 {
        mix64(self.0)
    }

    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = self.0.rotate_left(8) ^ u64::from(b);
        }
    }

    fn write_u64(&mut self, key: u64) {
        self.0 ^= key;
    }
}

/// Bits of each axis in a cell key; cell indices wrap around modulo 2^21 per axis, which
/// only makes far-apart cells share a bucket (distances are always checked exactly).
const KEY_BITS: u32 = 21;
/// Marks the end of a bucket's chain.
const NONE: u32 = u32::MAX;

/// Accepted samples in a hash grid of cells of size min_distance/√3: each cell key maps to
/// the newest sample in it, and `next` chains to the older ones.
struct SampleGrid {
    origin: Vec3,
    cell_size: f64,
    min_distance_squared: f64,
    heads: HashMap<u64, u32, BuildHasherDefault<KeyHasher>>,
    next: Vec<u32>,
    points: Vec<Vec3>,
}

impl SampleGrid {
    fn new(origin: Vec3, min_distance: f64) -> Self {
        Self {
            origin,
            cell_size: min_distance / 3f64.sqrt(),
            min_distance_squared: min_distance * min_distance * (1.0 - 2e-6),
            heads: HashMap::default(),
            next: Vec::new(),
            points: Vec::new(),
        }
    }

    /// The cell holding `p` (clamped far beyond any realistic mesh, so that the arithmetic
    /// on neighbour cells cannot overflow).
    fn cell(&self, p: &Vec3) -> [i64; 3] {
        let limit = (1u64 << 60) as f64;
        [0, 1, 2].map(|a| {
            ((p[a] - self.origin[a]) / self.cell_size)
                .floor()
                .clamp(-limit, limit) as i64
        })
    }

    /// The hash key of `cell`: each index modulo 2^21, packed into 63 bits.
    fn key(&self, cell: &[i64; 3]) -> u64 {
        let mask = (1u64 << KEY_BITS) - 1;
        cell.iter()
            .fold(0, |key, &i| (key << KEY_BITS) | (i as u64 & mask))
    }

    /// The phase group (0–26) of the cell holding `p`: its indices modulo 3.
    fn phase(&self, p: &Vec3) -> usize {
        let cell = self.cell(p);
        cell.iter()
            .fold(0, |phase, &i| 3 * phase + i.rem_euclid(3) as usize)
    }

    /// Adds `p` unless an accepted sample lies closer than the minimum distance by more than
    /// a relative 10⁻⁶ (so that points exactly the minimum distance apart, such as samples
    /// along an edge, are kept whether the mesh came in f32 or f64), or, beyond any
    /// realistic use, the sample indices are exhausted.
    fn insert_if_free(&mut self, p: Vec3) {
        if self.points.len() >= NONE as usize {
            return;
        }
        let cell = self.cell(&p);
        // Cells more than two away are at least 2·min_distance/√3 > min_distance away.
        for dx in -2..=2 {
            for dy in -2..=2 {
                for dz in -2..=2 {
                    let near = [cell[0] + dx, cell[1] + dy, cell[2] + dz];
                    let mut i = self.heads.get(&self.key(&near)).copied().unwrap_or(NONE);
                    while i != NONE {
                        if (self.points[i as usize] - p).norm_squared() < self.min_distance_squared
                        {
                            return;
                        }
                        i = self.next[i as usize];
                    }
                }
            }
        }
        let index = self.points.len() as u32;
        self.points.push(p);
        self.next
            .push(self.heads.insert(self.key(&cell), index).unwrap_or(NONE));
    }
}

/// Checks of a sampling's spacing and coverage, shared by the tests here and elsewhere, and
/// the sampler's tests.
#[cfg(test)]
#[path = "poisson_disk_tests.rs"]
mod test_checks;
#[cfg(test)]
pub(crate) use test_checks::checks;
