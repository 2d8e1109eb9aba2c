//! Neighbour search on a uniform grid (docs/method.md §6): cells of edge H, a counting sort of the
//! particles by cell in Z-order (Morton order), and compressed (CSR) neighbour lists built in
//! parallel. Every output depends only on the input positions, never on the thread count.
//!
//! [`UniformGrid`] sorts points by cell into a [`CellTable`] (`grid`) and searches them, held
//! by component ([`PointsByComponent`], `points`), (`search`, with the AVX2 and AVX-512
//! builds in `avx`) into [`NeighborLists`] (`lists`).

mod avx;
mod grid;
mod lists;
mod points;
mod search;

pub use grid::{CellTable, UniformGrid};
pub use lists::{NeighborLists, par_segments_zip_mut};
pub use points::PointsByComponent;

/// Queries handled per parallel task; fixed so results never depend on the thread count.
const BLOCK: usize = 256;

/// Random points and sorted copies, for the tests of the sort and the search.
#[cfg(test)]
mod test_points {
    use super::*;
    use crate::Vec3;

    pub(super) fn random_points(n: usize, seed: u64, extent: f64) -> Vec<Vec3> {
        let mut rng = crate::random::SplitMix64(seed);
        let mut next = move || rng.next_f64();
        (0..n)
            .map(|_| Vec3::new(next(), next(), next()) * extent)
            .collect()
    }

    pub(super) fn sorted_copy(
        grid: &UniformGrid,
        pts: &[Vec3],
        table: &mut CellTable,
    ) -> Vec<Vec3> {
        let mut order = Vec::new();
        grid.sort(pts, &mut order, table).unwrap();
        order.iter().map(|&i| pts[i as usize]).collect()
    }
}
