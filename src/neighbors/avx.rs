//! The AVX2 and AVX-512 builds of the block search: the AVX2 build compiles the portable
//! loops for AVX2; the AVX-512 build tests the candidates where they lie, eight lanes wide,
//! and compresses the neighbours found into the lists. Every build finds the same lists.

#[cfg(target_arch = "x86_64")]
use super::PointsByComponent;
use super::search::Block;
use crate::Vec3;
use std::collections::TryReserveError;

impl Block<'_> {
    crate::simd::avx2_dispatch! {
        /// [`Block::search`] without AVX-512: the AVX2 build where the processor has it.
        pub(super) fn search_avx2_or_portable / search_avx2(
            &self,
            queries: &[Vec3],
            starts: &mut Vec<u32>,
            found: &mut Vec<u32>,
        ) -> Result<(), TryReserveError> where true => search_portable
    }

    /// The AVX-512 build of [`Block::search`]. A point set searched among itself (a
    /// fluid's) yields a neighbour in about one candidate of seven; a search among another
    /// set (a boundary's wall points, which crowd the cells next to the fluid) in about one
    /// of sixty, and skips candidates by groups ([`push_within_avx512`]).
    ///
    /// # Safety
    /// The processor must support what [`crate::simd::has_avx512`] checks.
    #[cfg(target_arch = "x86_64")]
    pub(super) unsafe fn search_avx512(
        &self,
        queries: &[Vec3],
        starts: &mut Vec<u32>,
        found: &mut Vec<u32>,
    ) -> Result<(), TryReserveError> {
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
    ) -> Result<(), TryReserveError> {
        self.search_with::<true, SPARSE>(queries, starts, found)
    }
}

/// [`push_within_portable`] for the points of `ranges` of `points` (ascending and
/// disjoint), tested where they lie, eight at a time: the same operations in the same
/// order (so the same tests, bit for bit) into a mask, and the indices that pass
/// compressed to the front of a vector that is stored whole at the end of `found` (which
/// has room for every point of the ranges and one vector more, made by the caller so that
/// it can fail; the entries past the indices kept are overwritten by the next store or
/// left beyond the length). Point `own` is left out. With `SPARSE` the masks
/// of four batches are formed first and a group of 32 points none of which passes is
/// skipped: worth its branch where few candidates pass (about one in sixty of the
/// boundary's), not where one in seven does (the fluid's); see [`Block::search_avx512`].
///
/// # Safety
/// The processor must support what [`crate::simd::has_avx512`] checks; the ranges lie
/// within `points`, whose indices fit in `u32`; `found` has spare capacity for the points
/// of the ranges and eight more.
///
/// [`push_within_portable`]: super::search::push_within_portable
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,avx512f,avx512vl,avx512dq,avx512bw,popcnt")]
#[inline]
pub(super) unsafe fn push_within_avx512<const SPARSE: bool>(
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
    // A check, not a reservation (the caller reserved): the stores below rely on the room.
    assert!(
        found.capacity() - found.len() >= total + WIDTH,
        "no room for the neighbours"
    );
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::neighbors::search::Searched;
    use crate::neighbors::test_points::{random_points, sorted_copy};
    use crate::neighbors::{CellTable, PointsByComponent, UniformGrid};

    /// Every build of the block search (portable, AVX2, AVX-512, as far as the processor
    /// has them) finds the same lists, with and without skipping the query itself, among
    /// points by component and as vectors, on points with dense clumps (several vectors and
    /// a partial one per candidate run).
    #[test]
    fn search_builds_find_the_same_lists() {
        let radius = 0.1;
        let mut pts = random_points(3000, 21, 1.0);
        pts.extend(
            random_points(250, 4, 0.05)
                .into_iter()
                .map(|p| p + Vec3::repeat(0.31)),
        );
        let grid = UniformGrid::covering(Vec3::zeros(), Vec3::repeat(1.0), radius).unwrap();
        let mut table = CellTable::default();
        let sorted = sorted_copy(&grid, &pts, &mut table);
        let mut points = PointsByComponent::default();
        points.fill(&sorted).unwrap();
        let forms = [Searched::Components(&points), Searched::Vectors(&sorted)];
        let mut lists = Vec::new();
        for (exclude_self, points) in [None, Some(0)]
            .into_iter()
            .flat_map(|e| forms.map(|p| (e, p)))
        {
            let block = Block {
                grid: &grid,
                table: &table,
                points,
                r2: radius * radius,
                exclude_self,
            };
            let run = |build: &dyn Fn(&mut Vec<u32>, &mut Vec<u32>)| {
                let (mut starts, mut found) = (Vec::new(), Vec::new());
                build(&mut starts, &mut found);
                (starts, found)
            };
            let reference = run(&|c, f| block.search_portable(&sorted, c, f).unwrap());
            assert!(reference.1.len() > 20_000, "{} pairs", reference.1.len());
            #[cfg(target_arch = "x86_64")]
            {
                if std::arch::is_x86_feature_detected!("avx2") {
                    // SAFETY: the processor has AVX2.
                    let avx2 = run(&|c, f| unsafe { block.search_avx2(&sorted, c, f).unwrap() });
                    assert_eq!(avx2, reference, "AVX2 build");
                }
                if crate::simd::has_avx512() && matches!(points, Searched::Components(_)) {
                    // SAFETY: the processor has the AVX-512 subsets.
                    let avx512 =
                        run(&|c, f| unsafe { block.search_avx512(&sorted, c, f).unwrap() });
                    assert_eq!(avx512, reference, "AVX-512 build");
                }
            }
            lists.push(reference);
        }
        assert_eq!(lists[0], lists[1], "points by component and as vectors");
        assert_eq!(lists[2], lists[3], "points by component and as vectors");
    }
}
