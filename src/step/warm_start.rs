//! The warm start of the outer iteration (docs/method.md §4.1). A step starts every
//! particle that active constraints moved in the last step from its inertial prediction plus
//! a share of the support they gave it then, X^(0) = s + f·Δt²·a, rather than from s: a
//! column at rest then need not be lifted off its floor anew in every step, a front of
//! compression climbing the column a few support radii per outer iteration. Particles no
//! active constraint touched start from s, so that nothing holds up a particle that left
//! the fluid. Where the fluid needs less support than the start gave, the start is
//! withdrawn during the iteration ([`release`]): a particle whose density falls below ρ0
//! gives back part of what remains of its start after every outer iteration.

use super::search::Prediction;
use crate::Vec3;
use crate::constraint::{Corrections, Projection};
use crate::neighbors::NeighborLists;
use crate::reserve::reserve_total;
use rayon::prelude::*;
use std::collections::TryReserveError;

/// The most support a particle keeps, in multiples of |g|: enough to hold a column up
/// (a = −g at rest), while the far larger accelerations of an impact, which a start would
/// repeat after the impact is over, are cut (docs/method.md §4.1).
pub(super) const SUPPORT_LIMIT: f64 = 2.0;

/// The share of what remains of a particle's start that it gives back after an outer
/// iteration in which its density lay at least [`RELEASE_SCALE`] below ρ0 (docs/method.md
/// §4.1).
pub(super) const RELEASE_RATE: f64 = 0.5;

/// The relative under-density 1 − ρ_i/ρ0 at which a particle gives back its start at the full
/// [`RELEASE_RATE`]; less under-dense particles give back proportionally less, and particles
/// at or above ρ0 keep theirs.
pub(super) const RELEASE_SCALE: f64 = 1e-3;

/// Moves the prediction s in `x` (the sort's order) to the warm start s + f·Δt²·a, a being
/// the support (m/s²) in `supports` (the fluid's order) of the particle `order[k]` in slot
/// k, f = `share` and Δt = `dt` (s). No particle starts farther than `reach` (m) from s.
/// Writes each slot's start X^(0) − s (m) into `offsets`, which [`release`] then withdraws.
/// Errors, changing nothing, when `offsets` cannot grow to the particle count.
pub(super) fn start(
    x: &mut [Vec3],
    offsets: &mut Vec<Vec3>,
    supports: &[Vec3],
    order: &[u32],
    share: f64,
    dt: f64,
    reach: f64,
) -> Result<(), TryReserveError> {
    reserve_total(offsets, x.len())?;
    let scale = share * dt * dt;
    offsets.clear();
    offsets.par_extend(
        order
            .par_iter()
            .map(|&o| bounded(supports[o as usize] * scale, reach)),
    );
    x.par_iter_mut()
        .zip(offsets.par_iter())
        .for_each(|(x, offset)| *x += offset);
    Ok(())
}

/// Withdraws the start where the fluid no longer needs it, after an outer iteration whose
/// local step found the densities in `projections` (the sort's order, kg/m³): every particle
/// k with ρ_k < ρ0 = `rest_density` moves back towards s by the share
/// [`RELEASE_RATE`]·min(1, (1 − ρ_k/ρ0)/[`RELEASE_SCALE`]) of its remaining start
/// `offsets[k]` (m), which shrinks by as much. The move shifts both X^(k+1) (`current`) and
/// X^(k) (`previous`), so that Chebyshev's extrapolation does not carry it on as momentum.
///
/// Without the withdrawal a start that exceeds the support a particle needs stays in the
/// result: constraints only push, so nothing pulls an over-lifted, under-dense particle
/// back, and the excess becomes velocity (docs/method.md §4.1).
pub(super) fn release(
    current: &mut [Vec3],
    previous: &mut [Vec3],
    offsets: &mut [Vec3],
    projections: &[Projection],
    rest_density: f64,
) {
    current
        .par_iter_mut()
        .zip(previous.par_iter_mut())
        .zip(offsets.par_iter_mut())
        .zip(projections.par_iter())
        .for_each(|(((x, x_previous), offset), p)| {
            let under = 1.0 - p.density / rest_density;
            if under > 0.0 {
                let back = *offset * (RELEASE_RATE * (under / RELEASE_SCALE).min(1.0));
                *x -= back;
                *x_previous -= back;
                *offset -= back;
            }
        });
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
