//! The search: for every query, the points within the radius among those of its cell and
//! the adjacent cells, in blocks of queries searched in parallel, by the portable build or
//! the AVX2 or AVX-512 build the processor runs (docs/method.md §6).

#[cfg(target_arch = "x86_64")]
use super::avx::push_within_avx512;
use super::{BLOCK, CellTable, NeighborLists, PointsByComponent, UniformGrid};
use crate::Vec3;
use crate::reserve::reserve_total;
use rayon::prelude::*;
use std::collections::TryReserveError;

/// Room for one more vector of indices past a query's candidates, which the AVX-512 build
/// stores whole ([`push_within_avx512`]).
const STORE_SLACK: usize = 8;

/// The points a search looks among, in the order of its table.
#[derive(Clone, Copy)]
pub(super) enum Searched<'a> {
    /// Held by component: tested where they lie by the AVX-512 build (points searched many
    /// times, such as the boundary's).
    Components(&'a PointsByComponent),
    /// Held as vectors: copied by component a cell's neighbourhood at a time (points searched
    /// once, such as the fluid's prediction, which then needs no copy of its own).
    Vectors(&'a [Vec3]),
}

impl Searched<'_> {
    fn len(&self) -> usize {
        match self {
            Searched::Components(p) => p.len(),
            Searched::Vectors(p) => p.len(),
        }
    }
}

impl UniformGrid {
    /// For every query point, the indices of `points` (already in the order of `table`) within
    /// `radius` (≤ cell size), sorted ascending. With `exclude_self`, query i skips point i.
    ///
    /// The lists reuse the storage `out` had and grow, through fallible reservations, where
    /// it is short: when memory runs out the search stops with the error, and `out` then
    /// answers for no query until it is searched again.
    ///
    /// # Panics
    /// If `points` and `table` differ in length, or `radius` exceeds the cell size.
    pub fn search(
        &self,
        table: &CellTable,
        points: &[Vec3],
        queries: &[Vec3],
        radius: f64,
        exclude_self: bool,
        out: &mut NeighborLists,
    ) -> Result<(), TryReserveError> {
        let (points, first) = (Searched::Vectors(points), exclude_self.then_some(0));
        self.search_among(table, points, queries, first, radius, out)
    }

    /// [`UniformGrid::search`] among `points` held by component (for points searched many
    /// times, such as the boundary's, which the AVX-512 build tests where they lie).
    ///
    /// # Panics
    /// As [`UniformGrid::search`].
    pub fn search_in(
        &self,
        table: &CellTable,
        points: &PointsByComponent,
        queries: &[Vec3],
        radius: f64,
        exclude_self: bool,
        out: &mut NeighborLists,
    ) -> Result<(), TryReserveError> {
        let first = exclude_self.then_some(0);
        self.search_from(table, points, queries, first, radius, out)
    }

    /// [`UniformGrid::search_in`] for a run of the points themselves: with `Some(first)` the
    /// queries are the points `first..first + queries.len()` and each skips itself (so that
    /// a large set can be searched among itself a part at a time); with `None` no query
    /// skips anything. List k belongs to query k.
    pub(crate) fn search_from(
        &self,
        table: &CellTable,
        points: &PointsByComponent,
        queries: &[Vec3],
        first_self: Option<usize>,
        radius: f64,
        out: &mut NeighborLists,
    ) -> Result<(), TryReserveError> {
        let points = Searched::Components(points);
        self.search_among(table, points, queries, first_self, radius, out)
    }

    /// The search of [`UniformGrid::search_from`] among points in either form.
    fn search_among(
        &self,
        table: &CellTable,
        points: Searched,
        queries: &[Vec3],
        first_self: Option<usize>,
        radius: f64,
        out: &mut NeighborLists,
    ) -> Result<(), TryReserveError> {
        assert!(
            radius <= self.cell_size,
            "search radius exceeds the cell size"
        );
        assert_eq!(
            points.len(),
            table.point_count(),
            "search: not the points the table sorted"
        );
        let r2 = radius * radius;
        let blocks = queries.len().div_ceil(BLOCK);
        // Until the blocks are searched the lists answer for no query.
        out.queries = 0;
        reserve_total(&mut out.blocks, blocks)?;
        out.blocks.resize_with(blocks, Default::default);
        // Each block grows only its own lists, so what they hold does not depend on the
        // thread count; a block that runs out of memory fails the whole search. A block is
        // searched into its thread's buffer, which has room for every candidate of a query,
        // and only the neighbours found are kept in the block's lists.
        out.blocks
            .par_iter_mut()
            .enumerate()
            .try_for_each(|(b, (starts, found))| {
                let first = b * BLOCK;
                let queries = &queries[first..(first + BLOCK).min(queries.len())];
                let block = Block {
                    grid: self,
                    table,
                    points,
                    r2,
                    exclude_self: first_self.map(|own| own + first),
                };
                let mut searched = FOUND.take();
                let kept = block
                    .search(queries, starts, &mut searched)
                    .and_then(|()| keep(&searched, found));
                if searched.capacity() > FOUND_KEPT {
                    searched = Vec::new();
                }
                FOUND.set(searched);
                kept
            })?;
        out.queries = queries.len();
        Ok(())
    }
}

/// One block of queries of [`UniformGrid::search`].
pub(super) struct Block<'a> {
    pub(super) grid: &'a UniformGrid,
    pub(super) table: &'a CellTable,
    pub(super) points: Searched<'a>,
    /// Squared search radius (m²).
    pub(super) r2: f64,
    /// With `Some(first)`, query k of the block is point `first + k` and skips itself.
    pub(super) exclude_self: Option<usize>,
}

impl Block<'_> {
    /// Replaces `found` with the neighbours of every query, one list after another, and
    /// `starts` with where each list starts there (and, last, where the last one ends): eight
    /// distance tests per instruction in the AVX-512 build (among points by component), four
    /// in the AVX2 build, the same lists from every build (tested). Errors when the lists
    /// need more memory than can be had.
    fn search(
        &self,
        queries: &[Vec3],
        starts: &mut Vec<u32>,
        found: &mut Vec<u32>,
    ) -> Result<(), TryReserveError> {
        #[cfg(target_arch = "x86_64")]
        if matches!(self.points, Searched::Components(_)) && crate::simd::has_avx512() {
            // SAFETY: the processor supports the build's features, checked just above.
            return unsafe { self.search_avx512(queries, starts, found) };
        }
        self.search_avx2_or_portable(queries, starts, found)
    }

    /// The body of [`Block::search`] with the portable distance tests, inlined into the
    /// portable and the AVX2 build.
    #[inline(always)]
    pub(super) fn search_portable(
        &self,
        queries: &[Vec3],
        starts: &mut Vec<u32>,
        found: &mut Vec<u32>,
    ) -> Result<(), TryReserveError> {
        self.search_with::<false, false>(queries, starts, found)
    }

    /// The body of [`Block::search`]. With `AVX512` (only instantiated so by
    /// [`Block::search_avx512`], for points by component) the candidates are tested where
    /// they lie, eight lanes wide, and the neighbours found are compressed into `found` a
    /// vector at a time, skipping candidates by groups with `SPARSE` ([`push_within_avx512`]);
    /// without, they are first copied into one run.
    ///
    /// A query finds at most its candidates, the points of its cell and the adjacent ones;
    /// room for that many (and one vector more) is made before each query, fallibly, so
    /// that the pushes never reallocate. Where the lists had room, that is one comparison
    /// per query.
    #[inline(always)]
    pub(super) fn search_with<const AVX512: bool, const SPARSE: bool>(
        &self,
        queries: &[Vec3],
        starts: &mut Vec<u32>,
        found: &mut Vec<u32>,
    ) -> Result<(), TryReserveError> {
        let grid = self.grid;
        // The points the AVX-512 build tests where they lie.
        let in_place = match self.points {
            Searched::Components(p) if AVX512 => Some(p),
            _ => None,
        };
        starts.clear();
        reserve_total(starts, queries.len() + 1)?;
        starts.push(0);
        found.clear();
        // The points of the previous query's cell and its neighbour cells, in ascending
        // Z-rank of the cells (so their indices ascend and no list needs sorting): the
        // ranges of the cells, and (without `AVX512`) their points copied into one run that
        // every query of the cell tests in long loops.
        let mut cached: Option<[usize; 3]> = None;
        // At most the 27 cells around a query's, held on the stack: a search allocates
        // nothing but its lists (fallibly).
        let mut near: [std::ops::Range<usize>; 27] = std::array::from_fn(|_| 0..0);
        let mut ranges = 0;
        // The number of points in `ranges`.
        let mut total = 0;
        // The thread's buffers for that run, kept from block to block (they only grow;
        // the AVX-512 build, which tests the ranges in place, leaves them empty).
        let (mut candidates, mut ids) = CANDIDATES.take();
        // A plain loop rather than an iterator's closure, which would be compiled apart from
        // (and without the instruction sets of) the builds that inline this body.
        let searched = 'search: {
            for (k, q) in queries.iter().enumerate() {
                let c = grid.cell_of(q);
                if cached != Some(c) {
                    cached = Some(c);
                    ranges = 0;
                    for z in c[2].saturating_sub(1)..=(c[2] + 1).min(grid.dims[2] - 1) {
                        for y in c[1].saturating_sub(1)..=(c[1] + 1).min(grid.dims[1] - 1) {
                            for x in c[0].saturating_sub(1)..=(c[0] + 1).min(grid.dims[0] - 1) {
                                let rank = grid.rank([x, y, z]);
                                let cells = &self.table.cell_start;
                                let (start, end) = (cells[rank] as usize, cells[rank + 1] as usize);
                                // Empty cells are left out (most cells of the boundary's table).
                                if start < end {
                                    near[ranges] = start..end;
                                    ranges += 1;
                                }
                            }
                        }
                    }
                    near[..ranges].sort_unstable_by_key(|r| r.start);
                    total = near[..ranges].iter().map(|r| r.len()).sum();
                    if AVX512 {
                        // Tested where they lie: cells adjacent in Z-order make one run.
                        let mut runs = 0;
                        for i in 0..ranges {
                            if runs > 0 && near[runs - 1].end == near[i].start {
                                near[runs - 1].end = near[i].end;
                            } else {
                                near[runs] = near[i].clone();
                                runs += 1;
                            }
                        }
                        ranges = runs;
                    } else {
                        let near = &near[..ranges];
                        let copied = match self.points {
                            Searched::Components(p) => candidates.copy_ranges(p, near, total),
                            Searched::Vectors(p) => candidates.copy_vector_ranges(p, near, total),
                        };
                        if let Err(e) = copied {
                            break 'search Err(e);
                        }
                        ids.clear();
                        if let Err(e) = reserve_total(&mut ids, total) {
                            break 'search Err(e);
                        }
                        for r in &near[..ranges] {
                            ids.extend(r.start as u32..r.end as u32);
                        }
                    }
                }
                if found.capacity() - found.len() < total + STORE_SLACK
                    && let Err(e) = grow(found, total + STORE_SLACK)
                {
                    break 'search Err(e);
                }
                #[cfg(target_arch = "x86_64")]
                if AVX512 {
                    let Some(p) = in_place else {
                        unreachable!("the AVX-512 build searches points by component only")
                    };
                    let own = self.exclude_self.map(|first| first + k);
                    let ranges = &near[..ranges];
                    // SAFETY: `AVX512` is set only by `search_avx512`, which runs where the
                    // processor has AVX-512; the ranges lie within the table's points, and
                    // `found` has room for their `total` points and one vector more.
                    unsafe { push_within_avx512::<SPARSE>(q, p, ranges, own, self.r2, found) };
                    starts.push(found.len() as u32);
                    continue;
                }
                let own = self
                    .exclude_self
                    .and_then(|first| ids.binary_search(&((first + k) as u32)).ok());
                push_within_portable(q, &candidates, &ids, own, self.r2, found);
                starts.push(found.len() as u32);
            }
            Ok(())
        };
        CANDIDATES.set((candidates, ids));
        searched
    }
}

/// Makes `lists` a copy of a block's `found` lists, in storage of about their size: grown
/// when it is short, with [`LIST_HEADROOM`] to spare, and replaced when it is more than
/// twice that (and than two lists per query), so that the lists hold little more than what
/// the last search found.
/// Errors, leaving `lists` empty, when memory for them cannot be had.
fn keep(found: &[u32], lists: &mut Vec<u32>) -> Result<(), TryReserveError> {
    lists.clear();
    let room = found.len() + found.len() / LIST_HEADROOM;
    if lists.capacity() < found.len() || lists.capacity() > 2 * room.max(BLOCK) {
        let mut exact = Vec::new();
        exact.try_reserve_exact(room)?;
        *lists = exact;
    }
    lists.extend_from_slice(found);
    Ok(())
}

/// A block's lists are stored with room for 1/`LIST_HEADROOM` more neighbours than found,
/// so that a block whose particles gain a few neighbours keeps its storage.
const LIST_HEADROOM: usize = 16;

/// Makes room in `found` for `additional` more neighbours: out of the search's loop, which
/// only compares the room left with what a query may need.
#[cold]
#[inline(never)]
fn grow(found: &mut Vec<u32>, additional: usize) -> Result<(), TryReserveError> {
    found.try_reserve(additional)
}

/// Appends to `found`, in order, the `ids` of the `candidates` within √`r2` (m) of `q`,
/// except the candidate at index `own`.
#[inline(always)]
pub(super) fn push_within_portable(
    q: &Vec3,
    candidates: &PointsByComponent,
    ids: &[u32],
    own: Option<usize>,
    r2: f64,
    found: &mut Vec<u32>,
) {
    let cand = candidates;
    // The caller made room for every candidate: the neighbours are written into it without
    // a check of the capacity per neighbour.
    let room = found.spare_capacity_mut();
    assert!(room.len() >= ids.len(), "no room for the neighbours");
    let mut kept = 0;
    for lo in (0..ids.len()).step_by(64) {
        // The distance tests of up to 64 points into the bits of a mask (they vectorise),
        // then one store per set bit (no branch per candidate).
        let hi = (lo + 64).min(ids.len());
        let mut mask = 0u64;
        for (bit, ((x, y), z)) in cand.x[lo..hi]
            .iter()
            .zip(&cand.y[lo..hi])
            .zip(&cand.z[lo..hi])
            .enumerate()
        {
            let (dx, dy, dz) = (x - q.x, y - q.y, z - q.z);
            mask |= u64::from(dx * dx + dy * dy + dz * dz <= r2) << bit;
        }
        if let Some(own) = own.filter(|own| (lo..hi).contains(own)) {
            mask &= !(1 << (own - lo));
        }
        while mask != 0 {
            room[kept].write(ids[lo + mask.trailing_zeros() as usize]);
            kept += 1;
            mask &= mask - 1;
        }
    }
    // SAFETY: the first `kept` entries past the length were written just above.
    unsafe { found.set_len(found.len() + kept) };
}

thread_local! {
    /// The candidate points of a block's current cell and their indices, per thread.
    static CANDIDATES: std::cell::Cell<(PointsByComponent, Vec<u32>)> = Default::default();
    /// The neighbours a block found, before [`keep`] copies them into its lists, per
    /// thread.
    static FOUND: std::cell::Cell<Vec<u32>> = Default::default();
}

/// The most neighbours (and room for candidates) a thread's [`FOUND`] buffer keeps between
/// blocks: more, grown for a block of crowded particles, is given back after it.
const FOUND_KEPT: usize = 1 << 16;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::neighbors::test_points::{random_points, sorted_copy};

    #[test]
    fn search_equals_brute_force() {
        let radius = 0.1;
        // Some points deliberately outside the grid's domain to exercise clamping.
        let mut pts = random_points(4000, 42, 1.0);
        pts.extend(
            random_points(200, 9, 3.0)
                .into_iter()
                .map(|p| p - Vec3::repeat(1.0)),
        );
        // A dense clump: cells holding more than 64 points are tested in several chunks.
        pts.extend(
            random_points(300, 5, 0.06)
                .into_iter()
                .map(|p| p + Vec3::repeat(0.52)),
        );
        let grid = UniformGrid::covering(Vec3::zeros(), Vec3::repeat(1.0), radius).unwrap();
        let mut table = CellTable::default();
        let sorted = sorted_copy(&grid, &pts, &mut table);
        let mut lists = NeighborLists::default();
        grid.search(&table, &sorted, &sorted, radius, true, &mut lists)
            .unwrap();
        assert_eq!(lists.len(), sorted.len());
        let mut total = 0;
        for (i, p) in sorted.iter().enumerate() {
            let brute: Vec<u32> = (0..sorted.len() as u32)
                .filter(|&j| j as usize != i && (sorted[j as usize] - p).norm() <= radius)
                .collect();
            assert_eq!(lists.of(i), brute.as_slice(), "query {i}");
            total += brute.len();
        }
        assert!(
            total > 10_000,
            "test should exercise many pairs, got {total}"
        );

        // Queries against a second point set copied by component once (as the boundary's),
        // searched twice with different queries.
        let others = random_points(1500, 3, 1.0);
        let sorted_others = sorted_copy(&grid, &others, &mut table);
        let mut prepared = PointsByComponent::default();
        prepared.fill(&sorted_others).unwrap();
        for queries in [&sorted, &random_points(700, 8, 1.0)] {
            grid.search_in(&table, &prepared, queries, radius, false, &mut lists)
                .unwrap();
            assert_eq!(lists.len(), queries.len());
            for (i, p) in queries.iter().enumerate() {
                let brute: Vec<u32> = (0..sorted_others.len() as u32)
                    .filter(|&j| (sorted_others[j as usize] - p).norm() <= radius)
                    .collect();
                assert_eq!(lists.of(i), brute.as_slice());
            }
        }
    }

    /// A point set that is not the one the table sorted is refused with a clear message,
    /// not searched out of bounds.
    #[test]
    #[should_panic(expected = "not the points the table sorted")]
    fn search_rejects_points_of_another_table() {
        let grid = UniformGrid::covering(Vec3::zeros(), Vec3::repeat(1.0), 0.1).unwrap();
        let mut table = CellTable::default();
        let sorted = sorted_copy(&grid, &random_points(50, 1, 1.0), &mut table);
        let mut prepared = PointsByComponent::default();
        prepared.fill(&sorted[..40]).unwrap();
        grid.search_in(
            &table,
            &prepared,
            &sorted,
            0.1,
            false,
            &mut NeighborLists::default(),
        )
        .unwrap();
    }

    #[test]
    fn results_do_not_depend_on_thread_count() {
        let pts = random_points(5000, 11, 1.0);
        let grid = UniformGrid::covering(Vec3::zeros(), Vec3::repeat(1.0), 0.1).unwrap();
        let run = |threads| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| {
                let mut table = CellTable::default();
                let sorted = sorted_copy(&grid, &pts, &mut table);
                let mut lists = NeighborLists::default();
                grid.search(&table, &sorted, &sorted, 0.1, true, &mut lists)
                    .unwrap();
                (0..lists.len())
                    .map(|i| lists.of(i).to_vec())
                    .collect::<Vec<_>>()
            })
        };
        assert_eq!(run(1), run(3));
    }
}
