//! Neighbour search on a uniform grid (docs/method.md §6): cells of edge H, a counting sort of the
//! particles by cell in Z-order (Morton order), and compressed (CSR) neighbour lists built in
//! parallel. Every output depends only on the input positions, never on the thread count.

use crate::Vec3;
use rayon::prelude::*;

/// Queries handled per parallel task; fixed so results never depend on the thread count.
const BLOCK: usize = 256;
/// Largest number of cells a grid may have; beyond it the grid stops growing and particles
/// outside are clamped into its border cells (still correct, only slower).
const MAX_CELLS: usize = 1 << 22;

/// A uniform grid over an axis-aligned domain. Points outside the domain are clamped into
/// the border cells, which keeps every pair closer than the cell size in adjacent cells.
#[derive(Clone, Debug)]
pub struct UniformGrid {
    origin: Vec3,
    cell_size: f64,
    dims: [usize; 3],
    /// Z-order rank of each cell, indexed by its linear (x-fastest) index.
    z_rank: Vec<u32>,
}

impl UniformGrid {
    /// A grid of cells of edge `cell_size` (metres) covering `[min, max]` plus one cell of margin
    /// on every side. The cell count is capped; an oversized domain gets a clamped grid.
    pub fn covering(min: Vec3, max: Vec3, cell_size: f64) -> Self {
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
    /// [`UniformGrid::parts`]; `None` for parts no grid has.
    pub(crate) fn from_parts_checked(
        origin: Vec3,
        cell_size: f64,
        dims: [usize; 3],
    ) -> Option<Self> {
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

    fn from_parts(origin: Vec3, cell_size: f64, dims: [usize; 3]) -> Self {
        let count = dims.iter().product::<usize>();
        let mut by_morton: Vec<(u64, u32)> = (0..count)
            .map(|linear| {
                let x = linear % dims[0];
                let y = (linear / dims[0]) % dims[1];
                let z = linear / (dims[0] * dims[1]);
                (morton_code(x as u32, y as u32, z as u32), linear as u32)
            })
            .collect();
        by_morton.sort_unstable();
        let mut z_rank = vec![0u32; count];
        for (rank, &(_, linear)) in by_morton.iter().enumerate() {
            z_rank[linear as usize] = rank as u32;
        }
        Self {
            origin,
            cell_size,
            dims,
            z_rank,
        }
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
    fn cell_of(&self, p: &Vec3) -> [usize; 3] {
        let mut c = [0usize; 3];
        for axis in 0..3 {
            let f = ((p[axis] - self.origin[axis]) / self.cell_size).floor();
            // NaN maps to cell 0; `as` saturates, the clamp keeps it in range.
            c[axis] = (f.max(0.0) as usize).min(self.dims[axis] - 1);
        }
        c
    }

    #[inline]
    fn rank(&self, c: [usize; 3]) -> usize {
        self.z_rank[c[0] + self.dims[0] * (c[1] + self.dims[1] * c[2])] as usize
    }

    /// Counting sort of `points` by cell in Z-order. Writes `order` (sorted slot → input index,
    /// stable) and the table of cell ranges. Returns whether every point lies inside the
    /// grid's domain ([`UniformGrid::covers`]), from the same pass.
    pub fn sort(&self, points: &[Vec3], order: &mut Vec<u32>, table: &mut CellTable) -> bool {
        let ranks = &mut table.ranks;
        ranks.resize(points.len(), 0);
        let domain = self.domain();
        let covered = ranks
            .par_iter_mut()
            .zip(points.par_iter())
            .map(|(r, p)| {
                *r = self.rank(self.cell_of(p)) as u32;
                inside(p, &domain)
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
        order.resize(points.len(), 0);
        // Each cell's start serves as its cursor, which leaves it at the cell's end, the
        // next cell's start; shifting by one cell restores the starts.
        for (i, &r) in ranks.iter().enumerate() {
            let slot = &mut starts[r as usize];
            order[*slot as usize] = i as u32;
            *slot += 1;
        }
        starts.copy_within(..self.cell_count(), 1);
        starts[0] = 0;
        covered
    }

    /// For every query point, the indices of `points` (already in the order of `table`) within
    /// `radius` (≤ cell size), sorted ascending. With `exclude_self`, query i skips point i.
    pub fn search(
        &self,
        table: &CellTable,
        points: &[Vec3],
        queries: &[Vec3],
        radius: f64,
        exclude_self: bool,
        out: &mut NeighborLists,
    ) {
        let mut coordinates = std::mem::take(&mut out.coordinates);
        coordinates.fill(points);
        self.search_in(table, &coordinates, queries, radius, exclude_self, out);
        out.coordinates = coordinates;
    }

    /// [`UniformGrid::search`] among `points` already copied by component (for points that
    /// do not move, such as the boundary's, copied once): they must be the points `table`
    /// sorted, in its order.
    ///
    /// # Panics
    /// If `points` and `table` differ in length, or `radius` exceeds the cell size.
    pub fn search_in(
        &self,
        table: &CellTable,
        points: &PointsByComponent,
        queries: &[Vec3],
        radius: f64,
        exclude_self: bool,
        out: &mut NeighborLists,
    ) {
        let first = exclude_self.then_some(0);
        self.search_from(table, points, queries, first, radius, out);
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
    ) {
        assert!(
            radius <= self.cell_size,
            "search radius exceeds the cell size"
        );
        assert_eq!(
            points.x.len(),
            table.point_count(),
            "search: not the points the table sorted"
        );
        let r2 = radius * radius;
        let blocks = queries.len().div_ceil(BLOCK);
        out.blocks.resize_with(blocks, Default::default);
        out.blocks
            .par_iter_mut()
            .enumerate()
            .for_each(|(b, (starts, found))| {
                let first = b * BLOCK;
                let queries = &queries[first..(first + BLOCK).min(queries.len())];
                let block = Block {
                    grid: self,
                    table,
                    points,
                    r2,
                    exclude_self: first_self.map(|own| own + first),
                };
                block.search(queries, starts, found);
            });
        out.queries = queries.len();
    }
}

/// Cell ranges produced by [`UniformGrid::sort`]: the points of the cell with Z-rank `c` are
/// the sorted slots `cell_start[c]..cell_start[c + 1]`.
#[derive(Clone, Debug, Default)]
pub struct CellTable {
    cell_start: Vec<u32>,
    /// Scratch of the sort: the cell of every point.
    ranks: Vec<u32>,
}

impl CellTable {
    /// The number of points sorted.
    fn point_count(&self) -> usize {
        self.cell_start.last().map_or(0, |&n| n as usize)
    }

    /// Frees the sort's scratch, for a table that is sorted once and kept (the boundary's).
    pub(crate) fn release_scratch(&mut self) {
        self.ranks = Vec::new();
    }
}

/// Neighbour lists in compressed form, kept where the search wrote them: the queries are
/// taken in blocks of 256, and block b's lists are concatenated in `blocks[b]`, each list
/// ascending.
#[derive(Clone, Debug, Default)]
pub struct NeighborLists {
    /// The number of queries.
    queries: usize,
    /// Per block of queries: where each query's list starts in the block's concatenated
    /// lists (one more entry than queries), and those lists.
    blocks: Vec<(Vec<u32>, Vec<u32>)>,
    /// The searched points by component, for [`UniformGrid::search`].
    coordinates: PointsByComponent,
}

impl NeighborLists {
    /// The neighbours of query `i`.
    #[inline]
    pub fn of(&self, i: usize) -> &[u32] {
        let (starts, found) = &self.blocks[i / BLOCK];
        let k = i % BLOCK;
        &found[starts[k] as usize..starts[k + 1] as usize]
    }

    /// The number of neighbours of query `i`.
    #[inline]
    pub fn count(&self, i: usize) -> usize {
        let starts = &self.blocks[i / BLOCK].0;
        let k = i % BLOCK;
        (starts[k + 1] - starts[k]) as usize
    }

    /// Number of queries.
    pub fn len(&self) -> usize {
        self.queries
    }

    /// True when there are no queries.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The points searched by the last [`UniformGrid::search`] into these lists, by
    /// component (m).
    pub fn searched_points(&self) -> &PointsByComponent {
        &self.coordinates
    }

    /// The number of neighbours of all queries together (pairs found).
    pub fn pairs(&self) -> usize {
        self.blocks.iter().map(|(_, found)| found.len()).sum()
    }
}

/// Runs `f(i, segment_i, &mut items[i])` in parallel over the CSR segments
/// `data[offsets[i]..offsets[i + 1]]` together with one item per segment.
pub fn par_segments_zip_mut<T: Send, U: Send>(
    offsets: &[u32],
    data: &mut [T],
    items: &mut [U],
    f: impl Fn(usize, &mut [T], &mut U) + Sync,
) {
    let n = offsets.len().saturating_sub(1);
    assert_eq!(items.len(), n, "one item per segment");
    let mut pieces = Vec::with_capacity(n.div_ceil(BLOCK));
    let (mut rest, mut rest_items) = (data, items);
    for b in 0..n.div_ceil(BLOCK) {
        let (lo, hi) = (b * BLOCK, ((b + 1) * BLOCK).min(n));
        let (head, tail) = rest.split_at_mut((offsets[hi] - offsets[lo]) as usize);
        let (head_items, tail_items) = rest_items.split_at_mut(hi - lo);
        pieces.push((lo, head, head_items));
        rest = tail;
        rest_items = tail_items;
    }
    pieces.into_par_iter().for_each(|(lo, chunk, chunk_items)| {
        let base = offsets[lo] as usize;
        for (k, item) in chunk_items.iter_mut().enumerate() {
            let i = lo + k;
            let (a, b) = (offsets[i] as usize - base, offsets[i + 1] as usize - base);
            f(i, &mut chunk[a..b], item);
        }
    });
}

/// Points by component (m): a structure of arrays, so that the distance tests of a cell's
/// points run several lanes wide.
#[derive(Clone, Debug, Default)]
pub struct PointsByComponent {
    x: Vec<f64>,
    y: Vec<f64>,
    z: Vec<f64>,
}

impl PointsByComponent {
    /// Replaces the contents with the points of `ranges` of `points`, in that order.
    fn copy_ranges(&mut self, points: &PointsByComponent, ranges: &[std::ops::Range<usize>]) {
        for (out, from) in [
            (&mut self.x, &points.x),
            (&mut self.y, &points.y),
            (&mut self.z, &points.z),
        ] {
            out.clear();
            for range in ranges {
                out.extend_from_slice(&from[range.clone()]);
            }
        }
    }

    /// Point `i` (m).
    #[inline]
    pub fn at(&self, i: usize) -> Vec3 {
        Vec3::new(self.x[i], self.y[i], self.z[i])
    }

    /// The number of points.
    pub fn len(&self) -> usize {
        self.x.len()
    }

    /// True when there are no points.
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    /// Replaces the contents with `points` (m), in one parallel pass.
    pub fn fill(&mut self, points: &[Vec3]) {
        for out in [&mut self.x, &mut self.y, &mut self.z] {
            out.resize(points.len(), 0.0);
        }
        (&mut self.x[..], &mut self.y[..], &mut self.z[..], points)
            .into_par_iter()
            .for_each(|(x, y, z, p)| (*x, *y, *z) = (p.x, p.y, p.z));
    }
}

/// One block of queries of [`UniformGrid::search`].
struct Block<'a> {
    grid: &'a UniformGrid,
    table: &'a CellTable,
    points: &'a PointsByComponent,
    /// Squared search radius (m²).
    r2: f64,
    /// With `Some(first)`, query k of the block is point `first + k` and skips itself.
    exclude_self: Option<usize>,
}

impl Block<'_> {
    /// Replaces `found` with the neighbours of every query, one list after another, and
    /// `starts` with where each list starts there (and, last, where the last one ends): eight
    /// distance tests per instruction in the AVX-512 build, four in the AVX2 build, the same
    /// lists from every build (tested).
    fn search(&self, queries: &[Vec3], starts: &mut Vec<u32>, found: &mut Vec<u32>) {
        #[cfg(target_arch = "x86_64")]
        if crate::simd::has_avx512() {
            // SAFETY: the processor supports the build's features, checked just above.
            return unsafe { self.search_avx512(queries, starts, found) };
        }
        self.search_avx2_or_portable(queries, starts, found)
    }

    crate::simd::avx2_dispatch! {
        /// [`Block::search`] without AVX-512: the AVX2 build where the processor has it.
        fn search_avx2_or_portable / search_avx2(
            &self,
            queries: &[Vec3],
            starts: &mut Vec<u32>,
            found: &mut Vec<u32>,
        ) where true => search_portable
    }

    /// The body of [`Block::search`] with the portable distance tests, inlined into the
    /// portable and the AVX2 build.
    #[inline(always)]
    fn search_portable(&self, queries: &[Vec3], starts: &mut Vec<u32>, found: &mut Vec<u32>) {
        self.search_with::<false, false>(queries, starts, found)
    }

    /// The AVX-512 build of [`Block::search`]. A point set searched among itself (a
    /// fluid's) yields a neighbour in about one candidate of seven; a search among another
    /// set (a boundary's wall points, which crowd the cells next to the fluid) in about one
    /// of sixty, and skips candidates by groups ([`push_within_avx512`]).
    ///
    /// # Safety
    /// The processor must support what [`crate::simd::has_avx512`] checks.
    #[cfg(target_arch = "x86_64")]
    unsafe fn search_avx512(&self, queries: &[Vec3], starts: &mut Vec<u32>, found: &mut Vec<u32>) {
        // SAFETY: as this function's.
        unsafe {
            if self.exclude_self.is_some() {
                self.search_avx512_with::<false>(queries, starts, found)
            } else {
                self.search_avx512_with::<true>(queries, starts, found)
            }
        }
    }

    /// [`Block::search_avx512`] for one kind of search, compiled on its own.
    ///
    /// # Safety
    /// The processor must support what [`crate::simd::has_avx512`] checks.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,avx512f,avx512vl,avx512dq,avx512bw,popcnt")]
    #[inline(never)]
    unsafe fn search_avx512_with<const SPARSE: bool>(
        &self,
        queries: &[Vec3],
        starts: &mut Vec<u32>,
        found: &mut Vec<u32>,
    ) {
        self.search_with::<true, SPARSE>(queries, starts, found)
    }

    /// The body of [`Block::search`]. With `AVX512` (only instantiated so by
    /// [`Block::search_avx512`]) the candidates are tested where they lie, eight lanes wide,
    /// and the neighbours found are compressed into `found` a vector at a time, skipping
    /// candidates by groups with `SPARSE` ([`push_within_avx512`]); without, they are first
    /// copied into one run.
    #[inline(always)]
    fn search_with<const AVX512: bool, const SPARSE: bool>(
        &self,
        queries: &[Vec3],
        starts: &mut Vec<u32>,
        found: &mut Vec<u32>,
    ) {
        let grid = self.grid;
        let p = self.points;
        starts.clear();
        starts.push(0);
        found.clear();
        // The points of the previous query's cell and its neighbour cells, in ascending
        // Z-rank of the cells (so their indices ascend and no list needs sorting): the
        // ranges of the cells, and (without `AVX512`) their points copied into one run that
        // every query of the cell tests in long loops.
        let mut cached: Option<[usize; 3]> = None;
        let mut ranges: Vec<std::ops::Range<usize>> = Vec::with_capacity(27);
        // The thread's buffers for that run, kept from block to block (they only grow;
        // the AVX-512 build, which tests the ranges in place, leaves them empty).
        let (mut candidates, mut ids) = CANDIDATES.take();
        for (k, q) in queries.iter().enumerate() {
            let c = grid.cell_of(q);
            if cached != Some(c) {
                cached = Some(c);
                ranges.clear();
                for z in c[2].saturating_sub(1)..=(c[2] + 1).min(grid.dims[2] - 1) {
                    for y in c[1].saturating_sub(1)..=(c[1] + 1).min(grid.dims[1] - 1) {
                        for x in c[0].saturating_sub(1)..=(c[0] + 1).min(grid.dims[0] - 1) {
                            let rank = grid.rank([x, y, z]);
                            let cells = &self.table.cell_start;
                            let (start, end) = (cells[rank] as usize, cells[rank + 1] as usize);
                            // Empty cells are left out (most cells of the boundary's table).
                            if start < end {
                                ranges.push(start..end);
                            }
                        }
                    }
                }
                ranges.sort_unstable_by_key(|r| r.start);
                if AVX512 {
                    // Tested where they lie: cells adjacent in Z-order make one run.
                    ranges.dedup_by(|next, run| {
                        let adjacent = run.end == next.start;
                        if adjacent {
                            run.end = next.end;
                        }
                        adjacent
                    });
                } else {
                    candidates.copy_ranges(p, &ranges);
                    ids.clear();
                    for r in &ranges {
                        ids.extend(r.start as u32..r.end as u32);
                    }
                }
            }
            #[cfg(target_arch = "x86_64")]
            if AVX512 {
                let own = self.exclude_self.map(|first| first + k);
                // SAFETY: `AVX512` is set only by `search_avx512`, which runs where the
                // processor has AVX-512; the ranges lie within the table's points.
                unsafe { push_within_avx512::<SPARSE>(q, p, &ranges, own, self.r2, found) };
                starts.push(found.len() as u32);
                continue;
            }
            let own = self
                .exclude_self
                .and_then(|first| ids.binary_search(&((first + k) as u32)).ok());
            push_within_portable(q, &candidates, &ids, own, self.r2, found);
            starts.push(found.len() as u32);
        }
        CANDIDATES.set((candidates, ids));
    }
}

/// Appends to `found`, in order, the `ids` of the `candidates` within √`r2` (m) of `q`,
/// except the candidate at index `own`.
#[inline(always)]
fn push_within_portable(
    q: &Vec3,
    candidates: &PointsByComponent,
    ids: &[u32],
    own: Option<usize>,
    r2: f64,
    found: &mut Vec<u32>,
) {
    let cand = candidates;
    for lo in (0..ids.len()).step_by(64) {
        // The distance tests of up to 64 points into the bits of a mask (they vectorise),
        // then one push per set bit (no branch per candidate).
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
            found.push(ids[lo + mask.trailing_zeros() as usize]);
            mask &= mask - 1;
        }
    }
}

/// [`push_within_portable`] for the points of `ranges` of `points` (ascending and
/// disjoint), tested where they lie, eight at a time: the same operations in the same
/// order (so the same tests, bit for bit) into a mask, and the indices that pass
/// compressed to the front of a vector that is stored whole at the end of `found` (room for
/// one more vector is reserved; the entries past the indices kept are overwritten by the
/// next store or left beyond the length). Point `own` is left out. With `SPARSE` the masks
/// of four batches are formed first and a group of 32 points none of which passes is
/// skipped: worth its branch where few candidates pass (about one in sixty of the
/// boundary's), not where one in seven does (the fluid's); see [`Block::search_avx512`].
///
/// # Safety
/// The processor must support what [`crate::simd::has_avx512`] checks; the ranges lie
/// within `points`, whose indices fit in `u32`.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,avx512f,avx512vl,avx512dq,avx512bw,popcnt")]
#[inline]
unsafe fn push_within_avx512<const SPARSE: bool>(
    q: &Vec3,
    points: &PointsByComponent,
    ranges: &[std::ops::Range<usize>],
    own: Option<usize>,
    r2: f64,
    found: &mut Vec<u32>,
) {
    use std::arch::x86_64::*;
    const WIDTH: usize = 8;
    let total: usize = ranges.iter().map(|r| r.len()).sum();
    debug_assert!(ranges.iter().all(|r| r.end <= points.x.len()));
    found.reserve(total + WIDTH);
    let mut len = found.len();
    let out = found.as_mut_ptr();
    let (qx, qy, qz) = (
        _mm512_set1_pd(q.x),
        _mm512_set1_pd(q.y),
        _mm512_set1_pd(q.z),
    );
    let r2 = _mm512_set1_pd(r2);
    let (x, y, z) = (points.x.as_ptr(), points.y.as_ptr(), points.z.as_ptr());
    let lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    for range in ranges {
        let end = range.end;
        // The lanes of the batch at `at` that hold points of the range.
        let lanes = |at: usize| -> __mmask8 {
            let rest = end - at;
            if rest >= WIDTH {
                0xff
            } else {
                (1u8 << rest) - 1
            }
        };
        // SAFETY: masked loads read only lanes below the range's end, within the arrays.
        let within = |at: usize| unsafe {
            let lanes = lanes(at);
            let dx = _mm512_sub_pd(_mm512_maskz_loadu_pd(lanes, x.add(at)), qx);
            let dy = _mm512_sub_pd(_mm512_maskz_loadu_pd(lanes, y.add(at)), qy);
            let dz = _mm512_sub_pd(_mm512_maskz_loadu_pd(lanes, z.add(at)), qz);
            let d2 = _mm512_add_pd(
                _mm512_add_pd(_mm512_mul_pd(dx, dx), _mm512_mul_pd(dy, dy)),
                _mm512_mul_pd(dz, dz),
            );
            let mut within = _mm512_mask_cmp_pd_mask::<_CMP_LE_OQ>(lanes, d2, r2);
            if let Some(own) = own.filter(|own| (at..at + WIDTH).contains(own)) {
                within &= !(1u8 << (own - at));
            }
            within
        };
        // SAFETY: the store writes `WIDTH` indices at `len` ≤ the old length + the points
        // tested so far, within the reserved room.
        let mut store = |at: usize, kept: __mmask8| unsafe {
            let indices = _mm256_add_epi32(_mm256_set1_epi32(at as i32), lane);
            let packed = _mm256_maskz_compress_epi32(kept, indices);
            _mm256_storeu_si256(out.add(len).cast(), packed);
            len += kept.count_ones() as usize;
        };
        if SPARSE {
            const GROUP: usize = 4 * WIDTH;
            for lo in range.clone().step_by(GROUP) {
                let batches = (lo..(lo + GROUP).min(end)).step_by(WIDTH);
                if batches.clone().all(|at| within(at) == 0) {
                    continue;
                }
                batches.for_each(|at| store(at, within(at)));
            }
        } else {
            for at in range.clone().step_by(WIDTH) {
                store(at, within(at));
            }
        }
    }
    // SAFETY: the first `len` entries are initialised (the old ones, then the kept ids).
    unsafe { found.set_len(len) };
}

thread_local! {
    /// The candidate points of a block's current cell and their indices, per thread.
    static CANDIDATES: std::cell::Cell<(PointsByComponent, Vec<u32>)> = Default::default();
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

    fn random_points(n: usize, seed: u64, extent: f64) -> Vec<Vec3> {
        let mut rng = crate::random::SplitMix64(seed);
        let mut next = move || rng.next_f64();
        (0..n)
            .map(|_| Vec3::new(next(), next(), next()) * extent)
            .collect()
    }

    fn sorted_copy(grid: &UniformGrid, pts: &[Vec3], table: &mut CellTable) -> Vec<Vec3> {
        let mut order = Vec::new();
        grid.sort(pts, &mut order, table);
        order.iter().map(|&i| pts[i as usize]).collect()
    }

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
        let grid = UniformGrid::covering(Vec3::zeros(), Vec3::repeat(1.0), 0.1);
        let mut table = CellTable::default();
        let mut order = Vec::new();
        grid.sort(&pts, &mut order, &mut table);
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
        let grid = UniformGrid::covering(Vec3::zeros(), Vec3::repeat(1.0), radius);
        let mut table = CellTable::default();
        let sorted = sorted_copy(&grid, &pts, &mut table);
        let mut lists = NeighborLists::default();
        grid.search(&table, &sorted, &sorted, radius, true, &mut lists);
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
        prepared.fill(&sorted_others);
        for queries in [&sorted, &random_points(700, 8, 1.0)] {
            grid.search_in(&table, &prepared, queries, radius, false, &mut lists);
            assert_eq!(lists.len(), queries.len());
            for (i, p) in queries.iter().enumerate() {
                let brute: Vec<u32> = (0..sorted_others.len() as u32)
                    .filter(|&j| (sorted_others[j as usize] - p).norm() <= radius)
                    .collect();
                assert_eq!(lists.of(i), brute.as_slice());
            }
        }
    }

    /// Every build of the block search (portable, AVX2, AVX-512, as far as the processor
    /// has them) finds the same lists, with and without skipping the query itself, on
    /// points with dense clumps (several vectors and a partial one per candidate run).
    #[test]
    fn search_builds_find_the_same_lists() {
        let radius = 0.1;
        let mut pts = random_points(3000, 21, 1.0);
        pts.extend(
            random_points(250, 4, 0.05)
                .into_iter()
                .map(|p| p + Vec3::repeat(0.31)),
        );
        let grid = UniformGrid::covering(Vec3::zeros(), Vec3::repeat(1.0), radius);
        let mut table = CellTable::default();
        let sorted = sorted_copy(&grid, &pts, &mut table);
        let mut points = PointsByComponent::default();
        points.fill(&sorted);
        for exclude_self in [None, Some(0)] {
            let block = Block {
                grid: &grid,
                table: &table,
                points: &points,
                r2: radius * radius,
                exclude_self,
            };
            let run = |build: &dyn Fn(&mut Vec<u32>, &mut Vec<u32>)| {
                let (mut starts, mut found) = (Vec::new(), Vec::new());
                build(&mut starts, &mut found);
                (starts, found)
            };
            let reference = run(&|c, f| block.search_portable(&sorted, c, f));
            assert!(reference.1.len() > 20_000, "{} pairs", reference.1.len());
            #[cfg(target_arch = "x86_64")]
            {
                if std::arch::is_x86_feature_detected!("avx2") {
                    // SAFETY: the processor has AVX2.
                    let avx2 = run(&|c, f| unsafe { block.search_avx2(&sorted, c, f) });
                    assert_eq!(avx2, reference, "AVX2 build");
                }
                if crate::simd::has_avx512() {
                    // SAFETY: the processor has the AVX-512 subsets.
                    let avx512 = run(&|c, f| unsafe { block.search_avx512(&sorted, c, f) });
                    assert_eq!(avx512, reference, "AVX-512 build");
                }
            }
        }
    }

    /// A point set that is not the one the table sorted is refused with a clear message,
    /// not searched out of bounds.
    #[test]
    #[should_panic(expected = "not the points the table sorted")]
    fn search_rejects_points_of_another_table() {
        let grid = UniformGrid::covering(Vec3::zeros(), Vec3::repeat(1.0), 0.1);
        let mut table = CellTable::default();
        let sorted = sorted_copy(&grid, &random_points(50, 1, 1.0), &mut table);
        let mut prepared = PointsByComponent::default();
        prepared.fill(&sorted[..40]);
        grid.search_in(
            &table,
            &prepared,
            &sorted,
            0.1,
            false,
            &mut NeighborLists::default(),
        );
    }

    #[test]
    fn results_do_not_depend_on_thread_count() {
        let pts = random_points(5000, 11, 1.0);
        let grid = UniformGrid::covering(Vec3::zeros(), Vec3::repeat(1.0), 0.1);
        let run = |threads| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| {
                let mut table = CellTable::default();
                let sorted = sorted_copy(&grid, &pts, &mut table);
                let mut lists = NeighborLists::default();
                grid.search(&table, &sorted, &sorted, 0.1, true, &mut lists);
                (0..lists.len())
                    .map(|i| lists.of(i).to_vec())
                    .collect::<Vec<_>>()
            })
        };
        assert_eq!(run(1), run(3));
    }
}
