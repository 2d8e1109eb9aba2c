//! Solid boundaries as static particles (Akinci et al. 2012): sampling of container walls and
//! of triangle meshes ([`mesh`]), and the boundary volumes ψ_b/ρ0 (docs/method.md §2.6, §7).

use crate::Vec3;
use crate::kernel::CubicKernel;
use crate::neighbors::{CellTable, NeighborLists, PointsByComponent, UniformGrid};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::collections::TryReserveError;

mod field;
pub mod mesh;
mod particles;
pub mod shapes;
pub mod transform;
mod undo;
pub mod winding;

pub use field::{SHORT_MOVE, WallContribution, WallField};
pub(crate) use particles::Boundary;
pub use transform::Transform;
pub(crate) use undo::BoundaryCopy;

/// The owner index of boundary particles that belong to walls and static obstacles rather
/// than to a body.
pub(crate) const WALLS: u32 = u32::MAX;

/// What a container's walls are (docs/method.md §7).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ContainerWalls {
    /// Each wall a smooth field: what a wall of boundary particles r apart adds to the
    /// fluid's density, averaged along the wall, with no particles to search or sum over.
    Field,
    /// Each wall sampled with boundary particles (`layers`, `spacing`).
    #[default]
    Particles,
}

/// An axis-aligned box, corners in metres.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Lower corner (m).
    pub min: Vec3,
    /// Upper corner (m).
    pub max: Vec3,
}

impl Aabb {
    /// The smallest box holding every point, or `None` for no points.
    pub fn around(points: &[Vec3]) -> Option<Self> {
        Self::enclosing(points.iter().copied())
    }

    /// [`Aabb::around`] the points (m) an iterator yields.
    pub fn enclosing(points: impl IntoIterator<Item = Vec3>) -> Option<Self> {
        let mut points = points.into_iter();
        let first = points.next()?;
        Some(points.fold(
            Aabb {
                min: first,
                max: first,
            },
            |b, p| Aabb {
                min: b.min.inf(&p),
                max: b.max.sup(&p),
            },
        ))
    }

    /// The smallest box holding both boxes.
    pub fn union(&self, other: &Aabb) -> Aabb {
        Aabb {
            min: self.min.inf(&other.min),
            max: self.max.sup(&other.max),
        }
    }

    /// True when `p` lies no farther than `margin` (m) outside the box.
    pub fn contains(&self, p: &Vec3, margin: f64) -> bool {
        (0..3).all(|a| p[a] >= self.min[a] - margin && p[a] <= self.max[a] + margin)
    }
}

/// The default spacing of a container wall's boundary particles, in particle radii r: half
/// the fluid lattice's spacing (docs/method.md §7).
pub const WALL_SPACING: f64 = 1.0;

/// The sparsest container wall allowed, in particle radii r: sparser walls let fluid
/// particles through.
pub const MAX_WALL_SPACING: f64 = 2.0;

/// The densest container wall allowed, in particle radii r.
pub const MIN_WALL_SPACING: f64 = 0.25;

/// `spacing` (m) as a container wall's spacing for particle radius `r` (m): within
/// [`MIN_WALL_SPACING`]·r to [`MAX_WALL_SPACING`]·r, where a value off by single-precision
/// rounding (a relative 10⁻⁶, as a C caller's `float` 2r) counts as the limit; `None` outside
/// the range or not finite.
pub fn wall_spacing(spacing: f64, r: f64) -> Option<f64> {
    let (low, high) = (MIN_WALL_SPACING * r, MAX_WALL_SPACING * r);
    let slack = 1e-6;
    ((low * (1.0 - slack))..=(high * (1.0 + slack)))
        .contains(&spacing)
        .then(|| spacing.clamp(low, high))
}

/// Samples the six faces of `container` with square grids of spacing at most `spacing` (m),
/// edges and corners once. Each extra layer is the same box grown outward by `spacing`.
pub fn sample_box_walls(container: &Aabb, spacing: f64, layers: usize) -> Vec<Vec3> {
    let mut points = Vec::new();
    sample_box_walls_into(container, spacing, layers, &mut points);
    points
}

/// [`sample_box_walls`], appending to `points` (whose capacity the caller may reserve).
pub(crate) fn sample_box_walls_into(
    container: &Aabb,
    spacing: f64,
    layers: usize,
    points: &mut Vec<Vec3>,
) {
    for layer in 0..layers {
        let grow = Vec3::repeat(layer as f64 * spacing);
        let (min, max) = (container.min - grow, container.max + grow);
        let extent = max - min;
        let n = extent.map(|e| ((e / spacing).ceil() as usize).max(1));
        let step = Vec3::new(
            extent.x / n.x as f64,
            extent.y / n.y as f64,
            extent.z / n.z as f64,
        );
        let at = |i: usize, j: usize, k: usize| {
            min + Vec3::new(i as f64 * step.x, j as f64 * step.y, k as f64 * step.z)
        };
        for k in 0..=n.z {
            for j in 0..=n.y {
                if k == 0 || k == n.z || j == 0 || j == n.y {
                    points.extend((0..=n.x).map(|i| at(i, j, k)));
                } else {
                    points.push(at(0, j, k));
                    points.push(at(n.x, j, k));
                }
            }
        }
    }
}

/// Akinci volumes V_b = 1/Σ_{b'} W(x_b − x_b') (self included) for boundary particles
/// `points` (m) sorted by `table` on `grid`, in m³. The neighbours are searched
/// [`VOLUME_BATCH`] particles at a time, so that only one batch's lists are held (a whole
/// boundary's were once the largest allocation of a world). Errors when memory for the
/// volumes or a batch's lists cannot be had.
pub fn akinci_volumes(
    grid: &UniformGrid,
    table: &CellTable,
    points: &PointsByComponent,
    kernel: &CubicKernel,
) -> Result<Vec<f64>, TryReserveError> {
    volumes_in_batches(grid, table, points, kernel, VOLUME_BATCH)
}

/// How many boundary particles [`akinci_volumes`] searches at a time.
const VOLUME_BATCH: usize = 1 << 14;

/// [`akinci_volumes`], searching `batch` particles at a time.
fn volumes_in_batches(
    grid: &UniformGrid,
    table: &CellTable,
    points: &PointsByComponent,
    kernel: &CubicKernel,
    batch: usize,
) -> Result<Vec<f64>, TryReserveError> {
    let (mut lists, mut queries) = (NeighborLists::default(), Vec::new());
    let mut volumes = Vec::new();
    volumes.try_reserve_exact(points.len())?;
    queries.try_reserve_exact(batch.min(points.len()))?;
    let h = kernel.support_radius();
    for first in (0..points.len()).step_by(batch) {
        queries.clear();
        queries
            .extend((first..first.saturating_add(batch).min(points.len())).map(|i| points.at(i)));
        grid.search_from(table, points, &queries, Some(first), h, &mut lists)?;
        volumes.par_extend(queries.par_iter().enumerate().map(|(k, x)| {
            let sum: f64 = lists
                .of(k)
                .iter()
                .map(|&c| kernel.w((x - points.at(c as usize)).norm()))
                .sum();
            1.0 / (kernel.w_zero() + sum)
        }));
    }
    Ok(volumes)
}

/// Akinci masses ψ = ρ0·V (kg) of `points` (m) computed over these points alone, in their
/// order: the masses of a body's particles in its own frame. Errors when memory for the
/// grid, the sort or the search cannot be had.
pub(crate) fn own_masses(
    points: &[Vec3],
    kernel: &CubicKernel,
    rest_density: f64,
) -> Result<Vec<f64>, TryReserveError> {
    let Some(bounds) = Aabb::around(points) else {
        return Ok(Vec::new());
    };
    let grid = UniformGrid::covering(bounds.min, bounds.max, kernel.support_radius())?;
    let (mut order, mut table) = (Vec::new(), CellTable::default());
    grid.sort(points, &mut order, &mut table)?;
    let sorted: Vec<Vec3> = order.iter().map(|&i| points[i as usize]).collect();
    let mut by_component = PointsByComponent::default();
    by_component.fill(&sorted)?;
    let volumes = akinci_volumes(&grid, &table, &by_component, kernel)?;
    let mut psi = vec![0.0; points.len()];
    for (&i, v) in order.iter().zip(volumes) {
        psi[i as usize] = v * rest_density;
    }
    Ok(psi)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn box_walls_are_sampled_once_and_densely() {
        let container = Aabb {
            min: Vec3::zeros(),
            max: Vec3::new(1.0, 0.5, 0.3),
        };
        let spacing = 0.025;
        let pts = sample_box_walls(&container, spacing, 1);
        // 41 × 21 × 13 lattice, surface points only.
        assert_eq!(pts.len(), 41 * 21 * 13 - 39 * 19 * 11);
        for p in &pts {
            let on_face = (0..3).any(|a| {
                (p[a] - container.min[a]).abs() < 1e-12 || (p[a] - container.max[a]).abs() < 1e-12
            });
            assert!(on_face, "{p:?} is not on a wall");
        }
        let mut keys: Vec<[i64; 3]> = pts
            .iter()
            .map(|p| [0, 1, 2].map(|a| (p[a] / spacing * 8.0).round() as i64))
            .collect();
        keys.sort_unstable();
        keys.dedup();
        assert_eq!(keys.len(), pts.len(), "duplicate samples on shared edges");
        let two = sample_box_walls(&container, spacing, 2);
        assert!(
            two.iter()
                .skip(pts.len())
                .all(|p| !container.contains(p, 0.02))
        );
    }

    #[test]
    fn akinci_volume_of_a_plane_matches_its_area_density() {
        // A flat square lattice of spacing s: the centre particle's V_b·Σ W ≡ 1 by definition,
        // and V_b must be close to s²·(effective thickness) — check it against direct summation.
        let kernel = CubicKernel::new(0.1);
        let s = 0.025;
        let pts: Vec<Vec3> = (0..41)
            .flat_map(|i| (0..41).map(move |k| Vec3::new(i as f64 * s, 0.0, k as f64 * s)))
            .collect();
        let grid = UniformGrid::covering(Vec3::zeros(), Vec3::new(1.0, 0.0, 1.0), 0.1).unwrap();
        let mut table = CellTable::default();
        let mut order = Vec::new();
        grid.sort(&pts, &mut order, &mut table).unwrap();
        let sorted: Vec<Vec3> = order.iter().map(|&i| pts[i as usize]).collect();
        let mut by_component = PointsByComponent::default();
        by_component.fill(&sorted).unwrap();
        let volumes = akinci_volumes(&grid, &table, &by_component, &kernel).unwrap();
        let centre = sorted
            .iter()
            .position(|p| (p - Vec3::new(0.5, 0.0, 0.5)).norm() < 1e-9)
            .unwrap();
        let direct: f64 = pts
            .iter()
            .map(|p| kernel.w((p - sorted[centre]).norm()))
            .sum();
        assert!((volumes[centre] - 1.0 / direct).abs() < 1e-15);
        // A corner particle has fewer neighbours, hence a larger volume.
        let corner = sorted.iter().position(|p| p.norm() < 1e-9).unwrap();
        assert!(volumes[corner] > 2.0 * volumes[centre]);
        // Searched in batches of any size (one point, a few, or more than a cell's), every
        // volume comes out bit for bit as from one search of all points.
        let whole = volumes_in_batches(&grid, &table, &by_component, &kernel, usize::MAX).unwrap();
        assert_eq!(volumes, whole);
        for batch in [1, 7, 100, 1000] {
            let parts = volumes_in_batches(&grid, &table, &by_component, &kernel, batch).unwrap();
            assert_eq!(parts, whole, "batches of {batch}");
        }
    }
}
