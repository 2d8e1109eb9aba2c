//! The warm start of the outer iteration (docs/method.md §4.1). A step starts every
//! particle that active constraints moved in the last step from its inertial prediction plus
//! a share of the support they gave it then, X^(0) = s + f·Δt²·a, rather than from s: a
//! column at rest then need not be lifted off its floor anew in every step, a front of
//! compression climbing the column a few support radii per outer iteration. Particles no
//! active constraint touched start from s, so that nothing holds up a particle that left
//! the fluid.

use super::search::Prediction;
use crate::Vec3;
use crate::constraint::Corrections;
use crate::neighbors::NeighborLists;
use rayon::prelude::*;

/// The most support a particle keeps, in multiples of |g|: enough to hold a column up
/// (a = −g at rest), while the far larger accelerations of an impact, which a start would
/// repeat after the impact is over, are cut (docs/method.md §4.1).
pub(super) const SUPPORT_LIMIT: f64 = 2.0;

/// Moves the prediction s in `x` (the sort's order) to the warm start s + f·Δt²·a, a being
/// the support (m/s²) in `supports` (the fluid's order) of the particle `order[k]` in slot
/// k, f = `share` and Δt = `dt` (s). No particle starts farther than `reach` (m) from s.
pub(super) fn start(
    x: &mut [Vec3],
    supports: &[Vec3],
    order: &[u32],
    share: f64,
    dt: f64,
    reach: f64,
) {
    let scale = share * dt * dt;
    x.par_iter_mut()
        .zip(order.par_iter())
        .for_each(|(x, &o)| *x += bounded(supports[o as usize] * scale, reach));
}

/// `v` shortened to length `reach` where it is longer (m).
#[inline]
fn bounded(v: Vec3, reach: f64) -> Vec3 {
    let len = v.norm();
    if len > reach { v * (reach / len) } else { v }
}

/// Writes into `supports` the support of every particle in the step just iterated
/// (the sort's order): a_k = (X_k − s_k)/Δt² (m/s²), shortened to `limit` (m/s²), where the
/// last local step found particle k's own constraint or one of its fluid neighbours' active,
/// else zero.
pub(super) fn record(
    supports: &mut Vec<Vec3>,
    x: &[Vec3],
    predicted: &Prediction,
    dt: f64,
    lists: &NeighborLists,
    corrections: &Corrections,
    limit: f64,
) {
    let active = |i: usize| corrections.lambda(i) != 0.0;
    let per_dt2 = 1.0 / (dt * dt);
    supports.clear();
    supports.par_extend((0..x.len()).into_par_iter().map(|k| {
        let touched = active(k) || lists.of(k).iter().any(|&i| active(i as usize));
        if touched {
            bounded((x[k] - predicted.at(k)) * per_dt2, limit)
        } else {
            Vec3::zeros()
        }
    }));
}
