//! Stencil storage: the members of one projection by component, in arrays padded to whole
//! vectors of [`LANES`] lanes, the per-thread buffers that hold them, and sums over them in
//! one fixed order.

use crate::Vec3;
use crate::boundary::WallContribution;
use crate::reserve::reserve_total;
use std::cell::RefCell;
use std::collections::TryReserveError;

/// A stencil's members are kept in arrays padded to a multiple of this many entries, so
/// that every loop over them runs in whole vectors of four lanes with no remainder.
const LANES: usize = 4;
/// The offset (m) of a padding member from its stencil's centre: far outside any kernel
/// support, so its kernel value, gradient and weight are exactly 0 (and, being finite,
/// 0 times it stays 0).
const FAR: f64 = 1e10;

/// Per-thread buffers of one projection: its corrections when they are not kept; its fluid
/// members ([`Members`]) and boundary members ([`BoundaryMembers`]) at the iterate, both kept
/// by the first density evaluation for the first gradient evaluation and the density after
/// the first step; and the gradients of a later step.
#[derive(Default)]
pub(super) struct Scratch {
    /// The stencil corrections of a projection whose segment is not kept.
    pub(super) dp: Vec<Vec3>,
    pub(super) members: Members,
    pub(super) boundary: BoundaryMembers,
    pub(super) grads: Vec<Vec3>,
    /// The iterate x_i of the last [`DensityConstraint::first_density`] and what the
    /// container walls without particles add there.
    pub(super) wall_at: Vec3,
    pub(super) wall: WallContribution,
}

thread_local! {
    pub(super) static SCRATCH: RefCell<Scratch> = RefCell::new(Scratch::default());
}

impl Scratch {
    /// Reserves room for stencils of up to `fluid` fluid and `boundary` boundary members,
    /// as the projections, densities and filters grow the buffers for them (with the
    /// padding of [`pad_each`]), so that they then allocate nothing.
    pub(super) fn try_reserve(
        &mut self,
        fluid: usize,
        boundary: usize,
    ) -> Result<(), TryReserveError> {
        reserve_total(&mut self.dp, fluid + 1)?;
        reserve_total(&mut self.grads, fluid)?;
        let m = &mut self.members;
        for v in [
            &mut m.rx,
            &mut m.ry,
            &mut m.rz,
            &mut m.len,
            &mut m.gx,
            &mut m.gy,
            &mut m.gz,
            &mut m.weights,
            &mut m.values,
        ] {
            reserve_total(v, padded_room(fluid))?;
        }
        let b = &mut self.boundary;
        for v in [
            &mut b.rx,
            &mut b.ry,
            &mut b.rz,
            &mut b.len,
            &mut b.psi,
            &mut b.values,
        ] {
            reserve_total(v, padded_room(boundary))?;
        }
        Ok(())
    }
}

/// The boundary members of one stencil by component, as [`Members`]: offsets r = x_i − x_b
/// (m), their lengths (m), the masses ψ_b (kg), and one value per member for
/// [`ordered_sum`] and [`ordered_dot`]; padded as [`Members`] (padding: offsets [`FAR`],
/// ψ = 0).
#[derive(Default)]
pub(super) struct BoundaryMembers {
    /// The number of members; the arrays are used up to [`padded`]`(n)`.
    pub(super) n: usize,
    pub(super) rx: Vec<f64>,
    pub(super) ry: Vec<f64>,
    pub(super) rz: Vec<f64>,
    pub(super) len: Vec<f64>,
    pub(super) psi: Vec<f64>,
    pub(super) values: Vec<f64>,
}

impl BoundaryMembers {
    /// Makes room for `n` members and pads them to [`padded`]`(n)`.
    #[inline(always)]
    pub(super) fn resize(&mut self, n: usize) {
        self.n = n;
        let padding = [
            (&mut self.rx, FAR),
            (&mut self.ry, FAR),
            (&mut self.rz, FAR),
            (&mut self.psi, 0.0),
        ];
        pad_each(padding, [&mut self.len, &mut self.values], n);
    }
}

/// The entries [`pad_each`] grows an array to for `n` members: `n` and one whole vector.
#[inline(always)]
pub(super) fn padded_room(n: usize) -> usize {
    n + LANES
}

/// `n` rounded up to a multiple of [`LANES`].
#[inline(always)]
pub(super) fn padded(n: usize) -> usize {
    n.next_multiple_of(LANES)
}

/// Grows the arrays of a structure of arrays to at least `n` + [`LANES`] entries (within the
/// room [`Scratch::try_reserve`] and [`reserve_scratch`](super::reserve_scratch) make for a
/// step's stencils) (more than
/// [`padded`]`(n)`) and writes each `padding` array's value into its entries
/// `n..n + LANES`, one whole vector, which covers the padding `n..padded(n)` (the
/// `computed` arrays are written over the padded range before they are read). The arrays
/// never shrink, so that stencils of varying size write no new entries.
#[inline(always)]
pub(super) fn pad_each<const P: usize, const C: usize>(
    padding: [(&mut Vec<f64>, f64); P],
    computed: [&mut Vec<f64>; C],
    n: usize,
) {
    let room = padded_room(n);
    let grow = |v: &mut Vec<f64>| {
        if v.len() < room {
            v.resize(room, 0.0);
        }
    };
    for (v, pad) in padding {
        grow(v);
        v[n..room].copy_from_slice(&[pad; LANES]);
    }
    computed.into_iter().for_each(grow);
}

/// The fluid members of one stencil, in stencil order and by component (a structure of
/// arrays, so that the loops over them vectorise): offsets r = x_i − x_j (m) and their
/// lengths (m); the gradients ∇_{x_j}C_i (1/m) and weights w_j of the first step; and one
/// value per member (kernel values or squared gradients) for [`ordered_sum`]. The arrays
/// are used up to [`padded`]`(n)`: the padding members sit [`FAR`] away with weight 0, so
/// they add exact zeros to every sum.
#[derive(Default)]
pub(super) struct Members {
    /// The number of members.
    pub(super) n: usize,
    pub(super) rx: Vec<f64>,
    pub(super) ry: Vec<f64>,
    pub(super) rz: Vec<f64>,
    pub(super) len: Vec<f64>,
    pub(super) gx: Vec<f64>,
    pub(super) gy: Vec<f64>,
    pub(super) gz: Vec<f64>,
    pub(super) weights: Vec<f64>,
    pub(super) values: Vec<f64>,
}

impl Members {
    /// Makes room for `n` members and pads them to [`padded`]`(n)`.
    #[inline(always)]
    pub(super) fn resize(&mut self, n: usize) {
        self.n = n;
        let padding = [
            (&mut self.rx, FAR),
            (&mut self.ry, FAR),
            (&mut self.rz, FAR),
            (&mut self.weights, 0.0),
        ];
        let computed = [
            &mut self.len,
            &mut self.gx,
            &mut self.gy,
            &mut self.gz,
            &mut self.values,
        ];
        pad_each(padding, computed, n);
    }

    /// ∇_{x_j}C_i of the s-th member (1/m).
    #[inline]
    pub(super) fn gradient(&self, s: usize) -> Vec3 {
        Vec3::new(self.gx[s], self.gy[s], self.gz[s])
    }
}

/// The sum of `values` in one fixed order, in four interleaved partial sums (so that it
/// vectorises and does not wait on one addition after another).
#[inline(always)]
fn ordered_sum(values: &[f64]) -> f64 {
    let mut partial = [0.0; 4];
    let chunks = values.chunks_exact(4);
    let rest: f64 = chunks.remainder().iter().sum();
    for chunk in chunks {
        for (p, v) in partial.iter_mut().zip(chunk) {
            *p += v;
        }
    }
    (partial[0] + partial[1]) + (partial[2] + partial[3]) + rest
}

/// [`ordered_sum`] of the first [`padded`]`(n)` entries of a padded member array.
#[inline(always)]
pub(super) fn members_sum(values: &[f64], n: usize) -> f64 {
    ordered_sum(&values[..padded(n)])
}

/// The sum of `a[k]·b[k]` in one fixed order, in four interleaved partial sums (as
/// [`ordered_sum`]); `b` is at least as long as `a`.
#[inline(always)]
pub(super) fn ordered_dot(a: &[f64], b: &[f64]) -> f64 {
    let mut partial = [0.0; 4];
    let (chunks, rest) = (a.chunks_exact(4), a.len() / 4 * 4);
    let tail: f64 = a[rest..].iter().zip(&b[rest..]).map(|(a, b)| a * b).sum();
    for (chunk, other) in chunks.zip(b.chunks_exact(4)) {
        for ((p, a), b) in partial.iter_mut().zip(chunk).zip(other) {
            *p += a * b;
        }
    }
    (partial[0] + partial[1]) + (partial[2] + partial[3]) + tail
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::constraint::DensityConstraint;
    use crate::constraint::test_cluster::{cluster, test_constraint};

    /// The stencil evaluations that run over padded arrays (densities, the first gradients,
    /// the XSPH filter) equal direct sums over every particle of the cluster, fluid and
    /// boundary, within the support: the padding members add nothing. The cluster's stencils
    /// have from a handful to ~40 fluid members and 0 to ~30 boundary members, so every
    /// remainder modulo four occurs, on both the portable and the AVX2 path.
    #[test]
    fn padded_stencil_sums_equal_direct_sums() {
        let r = 0.025;
        for portable in [true, false] {
            let constraint = DensityConstraint {
                portable,
                ..test_constraint(r)
            };
            let cluster = cluster(&constraint, 2.0 * r * 0.999);
            let (x, fl, bx, psi, nb) = (
                &cluster.x,
                &cluster.fl,
                &cluster.bx,
                &cluster.psi,
                cluster.nb(),
            );
            let (k, h) = (&constraint.kernel, constraint.kernel.support_radius());
            let v: Vec<Vec3> = (0..x.len())
                .map(|i| Vec3::new((i % 7) as f64, (i % 5) as f64, (i % 3) as f64) * 0.1)
                .collect();
            let mut rho = Vec::new();
            constraint.densities(x, &nb, &mut rho);
            let volumes: Vec<f64> = rho.iter().map(|r| constraint.mass / r).collect();
            let mut remainders = [0usize; 4];
            let mut scratch = Scratch::default();
            for i in 0..x.len() {
                remainders[fl.count(i) % 4] += 1;
                let within = |p: &Vec3| (x[i] - p).norm() < h;
                let fluid: Vec<usize> = (0..x.len()).filter(|&j| within(&x[j])).collect();
                let walls: Vec<usize> = (0..bx.len()).filter(|&b| within(&bx[b])).collect();
                let direct = fluid
                    .iter()
                    .map(|&j| constraint.mass * k.w((x[i] - x[j]).norm()))
                    .sum::<f64>()
                    + walls
                        .iter()
                        .map(|&b| psi[b] * k.w((x[i] - bx[b]).norm()))
                        .sum::<f64>();
                assert!((rho[i] - direct).abs() <= 1e-12 * direct, "ρ_{i}");

                let grad_direct = (fluid.iter().filter(|&&j| j != i))
                    .map(|&j| k.grad_w(&(x[i] - x[j])) * constraint.mass)
                    .sum::<Vec3>()
                    + walls
                        .iter()
                        .map(|&b| k.grad_w(&(x[i] - bx[b])) * psi[b])
                        .sum::<Vec3>();
                let grad_direct = grad_direct / constraint.rest_density;
                constraint.first_density(i, x[i], x, &nb, &mut scratch);
                let (grad_i, _) = constraint.first_gradients(i, &nb, &mut scratch);
                assert!(
                    (grad_i - grad_direct).norm() <= 1e-12 * grad_direct.norm().max(1.0),
                    "∇C_{i}: {grad_i:?} against {grad_direct:?}"
                );

                let xsph_direct = v[i]
                    + (fluid.iter())
                        .map(|&j| {
                            (v[j] - v[i]) * (constraint.mass / rho[j] * k.w((x[i] - x[j]).norm()))
                        })
                        .sum::<Vec3>()
                        * 0.1;
                let xsph = constraint.xsph_velocity(0.1, i, (x, &v, &volumes), &nb);
                assert!((xsph - xsph_direct).norm() <= 1e-12, "XSPH v_{i}");
            }
            assert!(remainders.iter().all(|&n| n > 0), "{remainders:?}");
        }
    }
}
