//! What a wall's edges change in its plane integral, tabulated once for a kernel of unit
//! support (docs/method.md §7).
//!
//! For a point at distance z from a wall's plane whose foot lies c inside one of the wall's
//! edges, G(z, c) = ∫_{u > c} ∫ W(√(u² + v² + z²)) dv du, the kernel summed over the half
//! plane beyond that edge: a wall that ends there adds P(z) − G(z, c) instead of the whole
//! plane's P(z). With the line integral ℓ(d) = ∫ W(√(d² + s²)) ds,
//! G = ∫_c^∞ ℓ(√(u² + z²)) du, ∂G/∂c = −ℓ(√(c² + z²)) and ∂G/∂z = ∫_c^∞ ℓ'(ρ)·z/ρ du with
//! ρ = √(u² + z²).
//!
//! Next to an edge a wall's particles also see the other wall's, so their Akinci masses are
//! smaller (§2.6). For the continuous wall, at a point e inside the edge that sum is
//! S(e) = P(0) − G(0, e) + P(e)/2 (its own wall cut at the edge, and the other wall, whose
//! plane lies e away, up to the edge), and the mass per area is that of the open wall times
//! 1 − δ(e), δ = 1 − P(0)/S(e). What the shrinking takes from a point's density is
//! K(z, c) = ∫_0^1 δ(e) ℓ(√((e − c)² + z²)) de, tabulated for c from −1 to 2.
//!
//! A kernel of support H scales both: G_H(z, c) = G(z/H, c/H)/H, and so K.

use crate::kernel::CubicKernel;
use std::sync::OnceLock;

/// Intervals per unit of z and c in the tables of G and K.
const STEPS: usize = 64;
/// Intervals per unit of d in the table of ℓ.
const LINE_STEPS: usize = 1024;
/// Simpson panels (an even number) of each integral.
const PANELS: usize = 128;
/// The range of c in the table of K: from −1 (a foot one support beyond the edge) to 2.
const SHRINK_FROM: f64 = -1.0;
const SHRINK_TO: f64 = 2.0;

/// A function of (z, c) and its derivatives on a grid, interpolated by bicubic Hermite
/// polynomials, so that it and its gradient are continuous and the gradient is the
/// interpolant's own.
struct HermiteGrid {
    /// [f, ∂f/∂z, ∂f/∂c, ∂²f/∂z∂c] at each node, row by row in z.
    nodes: Vec<[f64; 4]>,
    /// Nodes per row (along c).
    row: usize,
    /// The c of the first column.
    c_from: f64,
}

impl HermiteGrid {
    /// The grid over z in [0, 1] and c in [`c_from`, `c_from` + `columns`/[`STEPS`]], with
    /// `node(z, c)` at each node.
    fn build(c_from: f64, columns: usize, node: impl Fn(f64, f64) -> [f64; 4]) -> Self {
        let unit = |k: usize| k as f64 / STEPS as f64;
        let nodes = (0..=STEPS)
            .flat_map(|zi| (0..=columns).map(move |ci| (zi, ci)))
            .map(|(zi, ci)| node(unit(zi), c_from + unit(ci)))
            .collect();
        HermiteGrid {
            nodes,
            row: columns + 1,
            c_from,
        }
    }

    /// f, ∂f/∂z and ∂f/∂c at (z, c); zero outside the grid.
    #[inline]
    fn at(&self, z: f64, c: f64) -> [f64; 3] {
        let (sz, sc) = (z * STEPS as f64, (c - self.c_from) * STEPS as f64);
        if !(0.0..STEPS as f64).contains(&sz) || !(0.0..(self.row - 1) as f64).contains(&sc) {
            return [0.0; 3];
        }
        let (zi, ci) = (sz as usize, sc as usize);
        let (t, u) = (sz - zi as f64, sc - ci as f64);
        let step = 1.0 / STEPS as f64;
        // The cubic Hermite basis on [0, 1] and its derivative: values at 0 and 1, then
        // slopes at 0 and 1.
        let basis = |t: f64| {
            let (t2, t3) = (t * t, t * t * t);
            [
                2.0 * t3 - 3.0 * t2 + 1.0,
                -2.0 * t3 + 3.0 * t2,
                t3 - 2.0 * t2 + t,
                t3 - t2,
            ]
        };
        let slope = |t: f64| {
            let t2 = t * t;
            [
                6.0 * t2 - 6.0 * t,
                -6.0 * t2 + 6.0 * t,
                3.0 * t2 - 4.0 * t + 1.0,
                3.0 * t2 - 2.0 * t,
            ]
        };
        let (bz, dz, bc, dc) = (basis(t), slope(t), basis(u), slope(u));
        let (mut f, mut f_z, mut f_c) = (0.0, 0.0, 0.0);
        for a in 0..2 {
            for b in 0..2 {
                let [v, v_z, v_c, v_zc] = self.nodes[(zi + a) * self.row + ci + b];
                // The node's value and its slopes scaled to the unit cell.
                let terms = [
                    (a, b, v),
                    (a + 2, b, v_z * step),
                    (a, b + 2, v_c * step),
                    (a + 2, b + 2, v_zc * step * step),
                ];
                for (i, j, w) in terms {
                    f += bz[i] * bc[j] * w;
                    f_z += dz[i] * bc[j] * w;
                    f_c += bz[i] * dc[j] * w;
                }
            }
        }
        [f, f_z / step, f_c / step]
    }
}

/// The tables of G and K, and ℓ and ℓ' on a fine grid of d in [0, 1], for the kernel of
/// support 1.
pub(super) struct EdgeTable {
    beyond: HermiteGrid,
    shrink: HermiteGrid,
    line: Vec<f64>,
    line_slope: Vec<f64>,
}

/// The table, built on first use (a few tens of milliseconds).
pub(super) fn table() -> &'static EdgeTable {
    static TABLE: OnceLock<EdgeTable> = OnceLock::new();
    TABLE.get_or_init(EdgeTable::build)
}

/// A function of (z, c) at one point, for the kernel of support 1: its value and its
/// derivatives along z and c.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) struct Beyond {
    pub g: f64,
    pub g_z: f64,
    pub g_c: f64,
}

impl EdgeTable {
    fn build() -> Self {
        let kernel = CubicKernel::new(1.0);
        let at = |k: usize| k as f64 / LINE_STEPS as f64;
        let line: Vec<f64> = (0..=LINE_STEPS)
            .map(|k| kernel.line_integral(at(k)))
            .collect();
        let e = 1e-6;
        let line_slope: Vec<f64> = (0..=LINE_STEPS)
            .map(|k| {
                let d = at(k);
                (kernel.line_integral(d + e) - kernel.line_integral((d - e).abs())) / (2.0 * e)
            })
            .collect();
        let empty = || HermiteGrid {
            nodes: Vec::new(),
            row: 1,
            c_from: 0.0,
        };
        let mut table = EdgeTable {
            beyond: empty(),
            shrink: empty(),
            line,
            line_slope,
        };
        table.beyond = HermiteGrid::build(0.0, STEPS, |z, c| {
            let corner = (z * z + c * c).sqrt();
            // ∂G/∂c = −ℓ(√(z² + c²)), and its derivative along z.
            let g_c = -table.line_at(corner);
            let g_zc = -table.line_slope_at(corner) * ratio(z, corner);
            let top = (1.0 - z * z).max(0.0).sqrt();
            if c >= top {
                return [0.0, 0.0, g_c, g_zc];
            }
            let rho = |u: f64| (u * u + z * z).sqrt();
            let g = simpson(c, top, |u| table.line_at(rho(u)));
            let g_z = simpson(c, top, |u| table.line_slope_at(rho(u)) * ratio(z, rho(u)));
            [g, g_z, g_c, g_zc]
        });
        // δ(e) on [0, 1], from G at z = 0 and P.
        let p = |z: f64| kernel.plane_integral(z);
        let delta = |e: f64| {
            let sum = p(0.0) - table.beyond.at(0.0, e)[0] + 0.5 * p(e);
            1.0 - p(0.0) / sum
        };
        let integrals = |z: f64, c: f64| {
            let rho = |e: f64| ((e - c) * (e - c) + z * z).sqrt();
            let k = simpson(0.0, 1.0, |e| delta(e) * table.line_at(rho(e)));
            let k_z = simpson(0.0, 1.0, |e| {
                delta(e) * table.line_slope_at(rho(e)) * ratio(z, rho(e))
            });
            let k_c = simpson(0.0, 1.0, |e| {
                delta(e) * table.line_slope_at(rho(e)) * ratio(c - e, rho(e))
            });
            [k, k_z, k_c]
        };
        let columns = ((SHRINK_TO - SHRINK_FROM) * STEPS as f64).round() as usize;
        table.shrink = HermiteGrid::build(SHRINK_FROM, columns, |z, c| {
            let [k, k_z, k_c] = integrals(z, c);
            let h = 1e-4;
            let k_zc = (integrals(z, c + h)[1] - integrals(z, c - h)[1]) / (2.0 * h);
            [k, k_z, k_c, k_zc]
        });
        table
    }

    /// ℓ(d) for 0 ≤ d (0 at and beyond 1), by cubic Hermite interpolation of ℓ and ℓ'.
    #[inline]
    pub(super) fn line_at(&self, d: f64) -> f64 {
        let s = d * LINE_STEPS as f64;
        if s >= LINE_STEPS as f64 {
            return 0.0;
        }
        let k = s as usize;
        let t = s - k as f64;
        let h = 1.0 / LINE_STEPS as f64;
        let (p0, p1) = (self.line[k], self.line[k + 1]);
        let (m0, m1) = (self.line_slope[k] * h, self.line_slope[k + 1] * h);
        let (t2, t3) = (t * t, t * t * t);
        (2.0 * t3 - 3.0 * t2 + 1.0) * p0
            + (t3 - 2.0 * t2 + t) * m0
            + (-2.0 * t3 + 3.0 * t2) * p1
            + (t3 - t2) * m1
    }

    /// ℓ'(d) for 0 ≤ d, linearly interpolated.
    fn line_slope_at(&self, d: f64) -> f64 {
        let s = d * LINE_STEPS as f64;
        if s >= LINE_STEPS as f64 {
            return 0.0;
        }
        let k = s as usize;
        let t = s - k as f64;
        self.line_slope[k] * (1.0 - t) + self.line_slope[k + 1] * t
    }

    /// G, ∂G/∂z and ∂G/∂c at `z` ≥ 0 and `c` ≥ 0 (both relative to the support); 0 at and
    /// beyond 1.
    #[inline]
    pub(super) fn beyond(&self, z: f64, c: f64) -> Beyond {
        let [g, g_z, g_c] = self.beyond.at(z, c);
        Beyond { g, g_z, g_c }
    }

    /// K, ∂K/∂z and ∂K/∂c at `z` ≥ 0 and `c` (both relative to the support): what the smaller
    /// masses next to an edge take from the density of a point whose foot lies c inside it;
    /// 0 for c at or beyond 2 and at or below −1.
    #[inline]
    pub(super) fn shrink(&self, z: f64, c: f64) -> Beyond {
        let [g, g_z, g_c] = self.shrink.at(z, c);
        Beyond { g, g_z, g_c }
    }
}

/// a/b, 0 where b is 0.
fn ratio(a: f64, b: f64) -> f64 {
    if b > 0.0 { a / b } else { 0.0 }
}

/// ∫_a^b f by Simpson's rule on [`PANELS`] panels.
fn simpson(a: f64, b: f64, f: impl Fn(f64) -> f64) -> f64 {
    let step = (b - a) / PANELS as f64;
    let inner: f64 = (1..PANELS)
        .map(|k| f(a + k as f64 * step) * if k % 2 == 1 { 4.0 } else { 2.0 })
        .sum();
    (f(a) + inner + f(b)) * step / 3.0
}

#[cfg(test)]
mod tests {
    use super::*;

    /// G is the kernel summed over the half plane beyond the edge (a brute-force sum over a
    /// fine lattice), half the plane integral at the edge itself, and its tabulated
    /// derivatives are its derivatives.
    #[test]
    fn the_edge_table_is_the_half_plane_integral() {
        let kernel = CubicKernel::new(1.0);
        let t = table();
        let step = 1.0 / 400.0;
        let cells = 401i64;
        for (z, c) in [
            (0.0, 0.0),
            (0.3, 0.0),
            (0.2, 0.25),
            (0.5, 0.1),
            (0.05, 0.6),
            (0.7, 0.3),
        ] {
            let brute: f64 = (-cells..=cells)
                .flat_map(|i| (-cells..=cells).map(move |j| (i, j)))
                .map(|(i, j)| {
                    let (u, v) = ((i as f64 + 0.5) * step, j as f64 * step);
                    if u > c {
                        kernel.w((u * u + v * v + z * z).sqrt()) * step * step
                    } else {
                        0.0
                    }
                })
                .sum();
            let b = t.beyond(z, c);
            let scale = kernel.plane_integral(0.0);
            assert!(
                (b.g - brute).abs() < 2e-3 * scale,
                "G({z}, {c}) = {} against {brute}",
                b.g
            );
            if z == 0.0 || c == 0.0 {
                // G is even in z and c; the derivatives are checked away from 0.
                continue;
            }
            let e = 1e-4;
            let dz = (t.beyond(z + e, c).g - t.beyond(z - e, c).g) / (2.0 * e);
            let dc = (t.beyond(z, c + e).g - t.beyond(z, c - e).g) / (2.0 * e);
            assert!(
                (b.g_z - dz).abs() < 2e-2 * scale,
                "∂G/∂z({z}, {c}): {} against {dz}",
                b.g_z
            );
            assert!(
                (b.g_c - dc).abs() < 2e-2 * scale,
                "∂G/∂c({z}, {c}): {} against {dc}",
                b.g_c
            );
        }
        for z in [0.0, 0.2, 0.6] {
            let half = t.beyond(z, 0.0).g;
            let exact = 0.5 * kernel.plane_integral(z);
            assert!(
                (half - exact).abs() < 1e-3 * kernel.plane_integral(0.0),
                "z {z}: {half} against {exact}"
            );
        }
        assert_eq!(t.beyond(0.1, 1.0).g, 0.0);
    }
}
