//! Points by component: the form in which the neighbour search reads the points it searches
//! among, and in which the boundary keeps its particles.

use crate::Vec3;
use crate::reserve::{copy_reusing, reserve_total};
use rayon::prelude::*;
use std::collections::TryReserveError;

/// Points by component (m): a structure of arrays, so that the distance tests of a cell's
/// points run several lanes wide.
#[derive(Clone, Debug, Default)]
pub struct PointsByComponent {
    pub(super) x: Vec<f64>,
    pub(super) y: Vec<f64>,
    pub(super) z: Vec<f64>,
}

impl PointsByComponent {
    /// Replaces the contents with the points of `ranges` of `points` (`total` in all), in
    /// that order; errors when memory for them cannot be had (the contents are then
    /// unspecified).
    pub(super) fn copy_ranges(
        &mut self,
        points: &PointsByComponent,
        ranges: &[std::ops::Range<usize>],
        total: usize,
    ) -> Result<(), TryReserveError> {
        for (out, from) in [
            (&mut self.x, &points.x),
            (&mut self.y, &points.y),
            (&mut self.z, &points.z),
        ] {
            out.clear();
            reserve_total(out, total)?;
            for range in ranges {
                out.extend_from_slice(&from[range.clone()]);
            }
        }
        Ok(())
    }

    /// [`PointsByComponent::copy_ranges`] of points held as vectors (m).
    pub(super) fn copy_vector_ranges(
        &mut self,
        points: &[Vec3],
        ranges: &[std::ops::Range<usize>],
        total: usize,
    ) -> Result<(), TryReserveError> {
        self.clear();
        self.try_reserve(total)?;
        for range in ranges {
            let points = &points[range.clone()];
            self.x.extend(points.iter().map(|p| p.x));
            self.y.extend(points.iter().map(|p| p.y));
            self.z.extend(points.iter().map(|p| p.z));
        }
        Ok(())
    }

    /// Removes every point, keeping the storage.
    pub(crate) fn clear(&mut self) {
        for c in [&mut self.x, &mut self.y, &mut self.z] {
            c.clear();
        }
    }

    /// Point `i` (m).
    #[inline]
    pub fn at(&self, i: usize) -> Vec3 {
        Vec3::new(self.x[i], self.y[i], self.z[i])
    }

    /// The x, y and z components of the points (m), three slices of one length: indexing
    /// all three at a point checks its index once.
    #[inline]
    pub fn components(&self) -> (&[f64], &[f64], &[f64]) {
        let n = self.x.len();
        (&self.x, &self.y[..n], &self.z[..n])
    }

    /// The points in order (m).
    pub fn iter(&self) -> impl ExactSizeIterator<Item = Vec3> + '_ {
        (0..self.len()).map(|i| self.at(i))
    }

    /// The points in order, as vectors (m).
    pub fn to_vec(&self) -> Vec<Vec3> {
        self.iter().collect()
    }

    /// Replaces point `i` by `p` (m).
    #[inline]
    pub(crate) fn set(&mut self, i: usize, p: Vec3) {
        (self.x[i], self.y[i], self.z[i]) = (p.x, p.y, p.z);
    }

    /// Swaps points `a` and `b`.
    #[inline]
    pub(crate) fn swap(&mut self, a: usize, b: usize) {
        for c in [&mut self.x, &mut self.y, &mut self.z] {
            c.swap(a, b);
        }
    }

    /// Appends `p` (m), within the room reserved or growing (infallibly: for storage the
    /// caller reserved).
    pub(crate) fn push(&mut self, p: Vec3) {
        self.x.push(p.x);
        self.y.push(p.y);
        self.z.push(p.z);
    }

    /// Appends `points` (m), as [`PointsByComponent::push`].
    pub(crate) fn extend_from_slice(&mut self, points: &[Vec3]) {
        for p in points {
            self.push(*p);
        }
    }

    /// Keeps the first `len` points.
    pub(crate) fn truncate(&mut self, len: usize) {
        for c in [&mut self.x, &mut self.y, &mut self.z] {
            c.truncate(len);
        }
    }

    /// Replaces the contents with the points of `from` in the order `order`: point k becomes
    /// `from`'s point `order[k]`. Errors, with the contents unspecified, when memory for them
    /// cannot be had.
    pub(crate) fn try_permuted_from(
        &mut self,
        from: &PointsByComponent,
        order: &[u32],
    ) -> Result<(), TryReserveError> {
        for (out, from) in [
            (&mut self.x, &from.x),
            (&mut self.y, &from.y),
            (&mut self.z, &from.z),
        ] {
            out.clear();
            reserve_total(out, order.len())?;
            out.extend(order.iter().map(|&i| from[i as usize]));
        }
        Ok(())
    }

    /// The number of points.
    pub fn len(&self) -> usize {
        self.x.len()
    }

    /// True when there are no points.
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    /// Makes these points a copy of `other`, reusing this one's storage; errors when memory
    /// for them cannot be had (the contents are then unspecified).
    pub(crate) fn try_copy_from(
        &mut self,
        other: &PointsByComponent,
    ) -> Result<(), TryReserveError> {
        copy_reusing(&mut self.x, &other.x)?;
        copy_reusing(&mut self.y, &other.y)?;
        copy_reusing(&mut self.z, &other.z)
    }

    /// Reserves room for `points` points in all (as [`Vec::try_reserve`], with room to grow).
    pub(crate) fn try_reserve(&mut self, points: usize) -> Result<(), TryReserveError> {
        for c in [&mut self.x, &mut self.y, &mut self.z] {
            reserve_total(c, points)?;
        }
        Ok(())
    }

    /// Replaces the contents with `points` (m), in one parallel pass; or, changing nothing,
    /// errors when memory for them (24 bytes a point) cannot be had.
    pub fn fill(&mut self, points: &[Vec3]) -> Result<(), TryReserveError> {
        self.try_reserve(points.len())?;
        for out in [&mut self.x, &mut self.y, &mut self.z] {
            out.resize(points.len(), 0.0);
        }
        (&mut self.x[..], &mut self.y[..], &mut self.z[..], points)
            .into_par_iter()
            .for_each(|(x, y, z, p)| (*x, *y, *z) = (p.x, p.y, p.z));
        Ok(())
    }
}
