//! The uniform grid: cells of edge H ranked in Z-order (Morton order), and the counting sort
//! of points by cell into a [`CellTable`] (docs/method.md §6).

use super::PointsByComponent;
use crate::Vec3;
use crate::reserve::{copy_reusing, reserve_total};
use rayon::prelude::*;
use std::collections::TryReserveError;

/// Largest number of cells a grid may have; beyond it the grid stops growing and particles
/// outside are clamped into its border cells (still correct, only slower).
const MAX_CELLS: usize = 1 << 22;

/// A uniform grid over an axis-aligned domain. Points outside the domain are clamped into
/// the border cells, which keeps every pair closer than the cell size in adjacent cells.
#[derive(Clone, Debug)]
pub struct UniformGrid {
    origin: Vec3,
    pub(super) cell_size: f64,
    pub(super) dims: [usize; 3],
    /// Z-order rank of each cell, indexed by its linear (x-fastest) index.
    z_rank: Vec<u32>,
}

impl UniformGrid {
    /// A grid of cells of edge `cell_size` (metres) covering `[min, max]` plus one cell of margin
    /// on every side. The cell count is capped; an oversized domain gets a clamped grid.
    /// Errors when memory for the grid's table of cell ranks (4 bytes a cell, and 16 a cell
    /// while it is built) cannot be had.
    pub fn covering(min: Vec3, max: Vec3, cell_size: f64) -> Result<Self, TryReserveError> {
        let origin = min - Vec3::repeat(cell_size);
        let mut dims = [0usize; 3];
        for axis in 0..3 {
            let extent = (max[axis] - min[axis]).max(0.0) + 2.0 * cell_size;
            dims[axis] = ((extent / cell_size).floor() as usize + 1).clamp(1, 1 << 20);
        }
        while dims.iter().product::<usize>() > MAX_CELLS {
            let largest = (0..3).max_by_key(|&a| dims[a]).unwrap_or(0);
            dims[largest] = dims[largest].div_ceil(2);
        }
        Self::from_parts(origin, cell_size, dims)
    }

    /// The grid with lower corner `origin` (m), cells of edge `cell_size` (m) and `dims`
    /// cells per axis (each at least 1, product at most the cell limit), e.g. as returned by
    /// [`UniformGrid::parts`]; `None` for parts no grid has, `Some(Err)` when memory for it
    /// cannot be had.
    pub(crate) fn from_parts_checked(
        origin: Vec3,
        cell_size: f64,
        dims: [usize; 3],
    ) -> Option<Result<Self, TryReserveError>> {
        let valid = origin.iter().all(|c| c.is_finite())
            && cell_size.is_finite()
            && cell_size > 0.0
            && dims.iter().all(|&d| (1..=1 << 20).contains(&d))
            && dims.iter().product::<usize>() <= MAX_CELLS;
        valid.then(|| Self::from_parts(origin, cell_size, dims))
    }

    /// Origin (m), cell size (m) and cells per axis: what [`UniformGrid::from_parts_checked`]
    /// needs to rebuild this grid exactly.
    pub(crate) fn parts(&self) -> (Vec3, f64, [usize; 3]) {
        (self.origin, self.cell_size, self.dims)
    }

    fn from_parts(origin: Vec3, cell_size: f64, dims: [usize; 3]) -> Result<Self, TryReserveError> {
        let count = dims.iter().product::<usize>();
        let mut by_morton: Vec<(u64, u32)> = Vec::new();
        by_morton.try_reserve_exact(count)?;
        by_morton.extend((0..count).map(|linear| {
            let x = linear % dims[0];
            let y = (linear / dims[0]) % dims[1];
            let z = linear / (dims[0] * dims[1]);
            (morton_code(x as u32, y as u32, z as u32), linear as u32)
        }));
        by_morton.sort_unstable();
        let mut z_rank = Vec::new();
        z_rank.try_reserve_exact(count)?;
        z_rank.resize(count, 0u32);
        for (rank, &(_, linear)) in by_morton.iter().enumerate() {
            z_rank[linear as usize] = rank as u32;
        }
        Ok(Self {
            origin,
            cell_size,
            dims,
            z_rank,
        })
    }

    /// Number of cells.
    pub fn cell_count(&self) -> usize {
        self.z_rank.len()
    }

    /// True when every point lies inside the grid's domain, i.e. no point needs clamping.
    pub fn covers(&self, points: &[Vec3]) -> bool {
        let domain = self.domain();
        points.par_iter().all(|p| inside(p, &domain))
    }

    /// The lower and upper corner of the grid's domain (m).
    fn domain(&self) -> (Vec3, Vec3) {
        (self.origin, self.upper_corner())
    }

    fn upper_corner(&self) -> Vec3 {
        self.origin
            + Vec3::new(
                self.dims[0] as f64,
                self.dims[1] as f64,
                self.dims[2] as f64,
            ) * self.cell_size
    }

    /// Integer cell coordinates of `p`, clamped into the grid.
    #[inline]
    pub(super) fn cell_of(&self, p: &Vec3) -> [usize; 3] {
        let mut c = [0usize; 3];
        for axis in 0..3 {
            let f = ((p[axis] - self.origin[axis]) / self.cell_size).floor();
            // NaN maps to cell 0; `as` saturates, the clamp keeps it in range.
            c[axis] = (f.max(0.0) as usize).min(self.dims[axis] - 1);
        }
        c
    }

    #[inline]
    pub(super) fn rank(&self, c: [usize; 3]) -> usize {
        self.z_rank[c[0] + self.dims[0] * (c[1] + self.dims[1] * c[2])] as usize
    }

    /// Counting sort of `points` by cell in Z-order. Writes `order` (sorted slot → input index,
    /// stable) and the table of cell ranges. Returns whether every point lies inside the
    /// grid's domain ([`UniformGrid::covers`]), from the same pass; or, changing nothing,
    /// an error when memory for `order` and the table (4 bytes a point twice, 4 a cell)
    /// cannot be had.
    pub fn sort(
        &self,
        points: &[Vec3],
        order: &mut Vec<u32>,
        table: &mut CellTable,
    ) -> Result<bool, TryReserveError> {
        self.sort_with(points.len(), |i| points[i], order, table)
    }

    /// [`UniformGrid::sort`] of points held by component.
    pub fn sort_by_component(
        &self,
        points: &PointsByComponent,
        order: &mut Vec<u32>,
        table: &mut CellTable,
    ) -> Result<bool, TryReserveError> {
        self.sort_with(points.len(), |i| points.at(i), order, table)
    }

    /// [`UniformGrid::sort`] of the `count` points `at(0)`, `at(1)`, … (m).
    fn sort_with(
        &self,
        count: usize,
        at: impl Fn(usize) -> Vec3 + Sync,
        order: &mut Vec<u32>,
        table: &mut CellTable,
    ) -> Result<bool, TryReserveError> {
        table.try_reserve(count, self.cell_count())?;
        reserve_total(order, count)?;
        let ranks = &mut table.ranks;
        ranks.resize(count, 0);
        let domain = self.domain();
        let covered = ranks
            .par_iter_mut()
            .enumerate()
            .map(|(i, r)| {
                let p = at(i);
                *r = self.rank(self.cell_of(&p)) as u32;
                inside(&p, &domain)
            })
            .reduce(|| true, |a, b| a && b);
        let starts = &mut table.cell_start;
        starts.clear();
        starts.resize(self.cell_count() + 1, 0);
        for &r in ranks.iter() {
            starts[r as usize + 1] += 1;
        }
        for c in 0..self.cell_count() {
            starts[c + 1] += starts[c];
        }
        order.clear();
        order.resize(count, 0);
        // Each cell's start serves as its cursor, which leaves it at the cell's end, the
        // next cell's start; shifting by one cell restores the starts.
        for (i, &r) in ranks.iter().enumerate() {
            let slot = &mut starts[r as usize];
            order[*slot as usize] = i as u32;
            *slot += 1;
        }
        starts.copy_within(..self.cell_count(), 1);
        starts[0] = 0;
        Ok(covered)
    }
}

/// Cell ranges produced by [`UniformGrid::sort`]: the points of the cell with Z-rank `c` are
/// the sorted slots `cell_start[c]..cell_start[c + 1]`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CellTable {
    pub(super) cell_start: Vec<u32>,
    /// Scratch of the sort: the cell of every point.
    ranks: Vec<u32>,
}

impl CellTable {
    /// The number of points sorted.
    pub(super) fn point_count(&self) -> usize {
        self.cell_start.last().map_or(0, |&n| n as usize)
    }

    /// Reserves the sort's scratch for `points` points and the ranges of `cells` cells.
    pub(crate) fn try_reserve(
        &mut self,
        points: usize,
        cells: usize,
    ) -> Result<(), TryReserveError> {
        reserve_total(&mut self.ranks, points)?;
        reserve_total(&mut self.cell_start, cells.saturating_add(1))
    }

    /// Frees the sort's scratch, for a table that is sorted once and kept (the boundary's).
    pub(crate) fn release_scratch(&mut self) {
        self.ranks = Vec::new();
    }

    /// Makes this table a copy of `other`'s cell ranges (not of its scratch), reusing this
    /// one's storage; errors when memory for them cannot be had (the table is then empty).
    pub(crate) fn try_copy_from(&mut self, other: &CellTable) -> Result<(), TryReserveError> {
        copy_reusing(&mut self.cell_start, &other.cell_start)
    }
}

/// True when `p` lies in the box `[lo, hi)` (false for a NaN coordinate).
#[inline]
fn inside(p: &Vec3, (lo, hi): &(Vec3, Vec3)) -> bool {
    (0..3).all(|a| p[a] >= lo[a] && p[a] < hi[a])
}

/// Interleaves the low 21 bits of x, y, z into a 63-bit Morton code.
fn morton_code(x: u32, y: u32, z: u32) -> u64 {
    fn spread(v: u32) -> u64 {
        let mut v = v as u64 & 0x1f_ffff;
        v = (v | v << 32) & 0x1f_0000_0000_ffff;
        v = (v | v << 16) & 0x1f_0000_ff00_00ff;
        v = (v | v << 8) & 0x100f_00f0_0f00_f00f;
        v = (v | v << 4) & 0x10c3_0c30_c30c_30c3;
        v = (v | v << 2) & 0x1249_2492_4924_9249;
        v
    }
    spread(x) | spread(y) << 1 | spread(z) << 2
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::neighbors::test_points::random_points;

    #[test]
    fn morton_interleaves_bits() {
        assert_eq!(morton_code(1, 0, 0), 1);
        assert_eq!(morton_code(0, 1, 0), 2);
        assert_eq!(morton_code(0, 0, 1), 4);
        assert_eq!(morton_code(3, 3, 3), 63);
        assert_eq!(morton_code(0x1f_ffff, 0, 0), 0x1249_2492_4924_9249);
    }

    #[test]
    fn sort_is_a_stable_permutation_in_z_order() {
        let pts = random_points(3000, 7, 1.0);
        let grid = UniformGrid::covering(Vec3::zeros(), Vec3::repeat(1.0), 0.1).unwrap();
        let mut table = CellTable::default();
        let mut order = Vec::new();
        grid.sort(&pts, &mut order, &mut table).unwrap();
        let mut seen = order.clone();
        seen.sort_unstable();
        assert!(seen.iter().enumerate().all(|(i, &v)| i as u32 == v));
        let ranks: Vec<usize> = order
            .iter()
            .map(|&i| grid.rank(grid.cell_of(&pts[i as usize])))
            .collect();
        for w in 0..order.len() - 1 {
            assert!(
                ranks[w] < ranks[w + 1] || (ranks[w] == ranks[w + 1] && order[w] < order[w + 1])
            );
        }
    }
}
