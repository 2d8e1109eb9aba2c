//! The iterate in single precision, from which the local step and the gather read the offsets
//! x_i − x_j of a stencil's fluid members (docs/method.md §2.5, "Precision"): positions relative to the
//! centre of the iterate's bounding box, so that half as many bytes are read per neighbour
//! and the arithmetic on a stencil runs eight lanes wide.

use crate::Vec3;
use crate::reserve::reserve_total;
use rayon::prelude::*;
use std::collections::TryReserveError;

/// The iterate is kept in single precision while every position lies within this many
/// support radii H of the bounding box's centre (per component). A position is then rounded
/// by at most 2⁻²⁴·64H ≈ 4·10⁻⁶H, and a density by about 10⁻⁵ of itself at the most, 3 % of
/// the default density tolerance η (docs/method.md §2.5, "Precision"). Wider fluids read
/// their offsets from the double-precision iterate and round each offset instead.
pub const SINGLE_PRECISION_REACH: f64 = 64.0;

/// The positions of the iterate, relative to the centre of their bounding box (m), in single
/// precision; empty when the fluid reaches farther than [`SINGLE_PRECISION_REACH`].
#[derive(Clone, Debug, Default)]
pub struct SinglePositions {
    points: Vec<[f32; 3]>,
    within_reach: bool,
}

impl SinglePositions {
    /// Rounds the iterate `x` (m) to single precision relative to the centre of its bounding
    /// box, if no position lies farther than `reach` (m) from it in any component; otherwise
    /// keeps nothing. Errors when memory for the positions cannot be had.
    pub(super) fn update(&mut self, x: &[Vec3], reach: f64) -> Result<(), TryReserveError> {
        let far = Vec3::repeat(f64::INFINITY);
        // Minima and maxima are exact, so the box is the same for every thread count.
        let (lo, hi) = x
            .par_iter()
            .fold(|| (far, -far), |(lo, hi), p| (lo.inf(p), hi.sup(p)))
            .reduce(|| (far, -far), |a, b| (a.0.inf(&b.0), a.1.sup(&b.1)));
        let origin = (lo + hi) * 0.5;
        self.within_reach = x.is_empty() || ((hi - lo) * 0.5).max() <= reach;
        self.points.clear();
        if self.within_reach {
            reserve_total(&mut self.points, x.len())?;
            self.points.par_extend(x.par_iter().map(|p| {
                let r = p - origin;
                [r.x as f32, r.y as f32, r.z as f32]
            }));
        }
        Ok(())
    }

    /// The rounded positions (m, relative to the bounding box's centre), when the iterate
    /// lies within reach.
    #[inline]
    pub(super) fn points(&self) -> Option<&[[f32; 3]]> {
        self.within_reach.then_some(&self.points[..])
    }
}

/// The iterate a local step projects (m): in double precision, and in single precision where
/// [`SinglePositions`] holds it.
#[derive(Clone, Copy)]
pub(super) struct Iterate<'a> {
    pub(super) x: &'a [Vec3],
    pub(super) single: Option<&'a [[f32; 3]]>,
}

/// The offsets x_i − x_j (m) from particle i to its neighbours j, from the rounded
/// positions `points` of [`SinglePositions`].
#[inline(always)]
pub(super) fn single_offsets(points: &[[f32; 3]], i: usize) -> impl Fn(u32) -> [f32; 3] + '_ {
    let xi = points[i];
    move |j| {
        let xj = &points[j as usize];
        [xi[0] - xj[0], xi[1] - xj[1], xi[2] - xj[2]]
    }
}

/// The offsets x_i − x_j (m) from a particle at `xi` to its neighbours j at `x`, each
/// computed in double precision and rounded.
#[inline(always)]
pub(super) fn double_offsets(x: &[Vec3], xi: Vec3) -> impl Fn(u32) -> [f32; 3] + '_ {
    move |j| {
        let r = xi - x[j as usize];
        [r.x as f32, r.y as f32, r.z as f32]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Within reach the rounded offsets agree with the double-precision ones to the rounding
    /// of a position at the reach; beyond it nothing is kept. The bounding box, not the
    /// coordinates' size, decides: a fluid 10 km from the origin is kept.
    #[test]
    fn offsets_agree_within_reach() {
        let far = Vec3::new(1e4, -2e4, 3e3);
        let x: Vec<Vec3> = (0..1000)
            .map(|k| {
                far + Vec3::new((k % 10) as f64, (k / 10 % 10) as f64, (k / 100) as f64) * 0.37
            })
            .collect();
        let (mut single, reach) = (SinglePositions::default(), 2.0);
        single.update(&x, reach).unwrap();
        let points = single.points().expect("within reach");
        for i in [0, 17, 555, 999] {
            let (s, d) = (single_offsets(points, i), double_offsets(&x, x[i]));
            for j in [1, 42, 500, 998] {
                let (a, b) = (s(j), d(j));
                for c in 0..3 {
                    let bound = 4.0 * reach as f32 * f32::EPSILON;
                    assert!((a[c] - b[c]).abs() <= bound, "{a:?} {b:?}");
                }
            }
        }
        single.update(&x, 1.6).unwrap();
        assert!(single.points().is_none());
        single.update(&[], 0.0).unwrap();
        assert_eq!(single.points(), Some(&[][..]));
    }
}
