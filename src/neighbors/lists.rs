//! Neighbour lists in compressed (CSR) form, kept per block of queries, and the parallel
//! walk over CSR segments.

use super::BLOCK;
use crate::reserve::reserve_total;
use rayon::prelude::*;
use std::collections::TryReserveError;

/// Neighbour lists in compressed form, kept per block: the queries are taken in blocks of
/// 256, and block b's lists are concatenated in `blocks[b]`, each list ascending, in
/// storage of about their size.
#[derive(Clone, Debug, Default)]
pub struct NeighborLists {
    /// The number of queries.
    pub(super) queries: usize,
    /// Per block of queries: where each query's list starts in the block's concatenated
    /// lists (one more entry than queries), and those lists.
    pub(super) blocks: Vec<(Vec<u32>, Vec<u32>)>,
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

    /// The number of neighbours of all queries together (pairs found).
    pub fn pairs(&self) -> usize {
        self.blocks.iter().map(|(_, found)| found.len()).sum()
    }

    /// The largest number of neighbours of any query (0 without queries).
    pub fn most(&self) -> usize {
        let blocks = &self.blocks[..self.queries.div_ceil(BLOCK)];
        blocks
            .par_iter()
            .map(|(starts, _)| starts.windows(2).map(|w| w[1] - w[0]).max().unwrap_or(0))
            .max()
            .unwrap_or(0) as usize
    }

    /// Frees the lists and their reservation, e.g. after a search that ran out of memory
    /// part-way, so that what it grew is given back.
    pub(crate) fn release(&mut self) {
        self.queries = 0;
        self.blocks = Vec::new();
    }

    /// Reserves room for the blocks of a search of `queries` points and their starts. The
    /// lists themselves are sized by the search, to what it finds.
    pub(crate) fn try_reserve(&mut self, queries: usize) -> Result<(), TryReserveError> {
        let blocks = queries.div_ceil(BLOCK);
        reserve_total(&mut self.blocks, blocks)?;
        while self.blocks.len() < blocks {
            self.blocks.push(Default::default());
        }
        for (starts, _) in &mut self.blocks[..blocks] {
            reserve_total(starts, BLOCK + 1)?;
        }
        Ok(())
    }
}

/// Runs `f(i, segment_i, &mut items[i])` in parallel over the CSR segments
/// `data[offsets[i]..offsets[i + 1]]` together with one item per segment. Errors, having
/// run nothing, when memory for the list of blocks cannot be had.
pub fn par_segments_zip_mut<T: Send, U: Send>(
    offsets: &[u32],
    data: &mut [T],
    items: &mut [U],
    f: impl Fn(usize, &mut [T], &mut U) + Sync,
) -> Result<(), TryReserveError> {
    let n = offsets.len().saturating_sub(1);
    assert_eq!(items.len(), n, "one item per segment");
    let mut pieces = Vec::new();
    pieces.try_reserve_exact(n.div_ceil(BLOCK))?;
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
    Ok(())
}
