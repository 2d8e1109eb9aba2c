//! The part of a wall's plane integral that lies beyond one edge of the wall, tabulated once
//! for a kernel of unit support (docs/method.md §7).
//!
//! For a point at distance z from a wall's plane whose foot lies c inside one of the wall's
//! edges, G(z, c) = ∫_{u > c} ∫ W(√(u² + v² + z²)) dv du, the kernel summed over the half
//! plane beyond that edge: a wall that ends there adds P(z) − G(z, c) instead of the whole
//! plane's P(z). With the line integral ℓ(d) = ∫ W(√(d² + s²)) ds,
//! G = ∫_c^∞ ℓ(√(u² + z²)) du, ∂G/∂c = −ℓ(√(c² + z²)) and ∂G/∂z = ∫_c^∞ ℓ'(ρ)·z/ρ du with
//! ρ = √(u² + z²). A kernel of support H scales them: G_H(z, c) = G(z/H, c/H)/H.

use crate::kernel::CubicKernel;
use std::sync::OnceLock;

/// Intervals per unit of z and c in the tables of G and ∂G/∂z.
const STEPS: usize = 64;
/// Intervals per unit of d in the table of ℓ.
const LINE_STEPS: usize = 1024;
/// Simpson panels (an even number) of each integral over u.
const PANELS: usize = 128;

/// G and its derivatives ∂G/∂z, ∂G/∂c and ∂²G/∂z∂c on a grid of (z, c) in [0, 1]², and ℓ and
/// ℓ' on a fine grid of d in [0, 1], for the kernel of support 1. G is interpolated between
/// the grid's nodes by bicubic Hermite polynomials, so that it and its gradient are
/// continuous and the gradient is the interpolant's own.
pub(super) struct EdgeTable {
    /// [G, ∂G/∂z, ∂G/∂c, ∂²G/∂z∂c] at each node, row by row in z.
    nodes: Vec<[f64; 4]>,
    line: Vec<f64>,
    line_slope: Vec<f64>,
}

/// The table, built on first use (a few milliseconds).
pub(super) fn table() -> &'static EdgeTable {
    static TABLE: OnceLock<EdgeTable> = OnceLock::new();
    TABLE.get_or_init(EdgeTable::build)
}

/// What lies beyond one edge, for the kernel of support 1: G, ∂G/∂z and ∂G/∂c.
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
        let mut table = EdgeTable {
            nodes: Vec::new(),
            line,
            line_slope,
        };
        let unit = |k: usize| k as f64 / STEPS as f64;
        let mut nodes = Vec::with_capacity((STEPS + 1) * (STEPS + 1));
        for zi in 0..=STEPS {
            for ci in 0..=STEPS {
                let (z, c) = (unit(zi), unit(ci));
                let corner = (z * z + c * c).sqrt();
                // ∂G/∂c = −ℓ(√(z² + c²)), and its derivative along z.
                let g_c = -table.line_at(corner);
                let g_zc = if corner > 0.0 {
                    -table.line_slope_at(corner) * z / corner
                } else {
                    0.0
                };
                let top = (1.0 - z * z).max(0.0).sqrt();
                if c >= top {
                    nodes.push([0.0, 0.0, g_c, g_zc]);
                    continue;
                }
                let rho = |u: f64| (u * u + z * z).sqrt();
                let g = simpson(c, top, |u| table.line_at(rho(u)));
                let g_z = simpson(c, top, |u| {
                    let r = rho(u);
                    if r > 0.0 {
                        table.line_slope_at(r) * z / r
                    } else {
                        0.0
                    }
                });
                nodes.push([g, g_z, g_c, g_zc]);
            }
        }
        table.nodes = nodes;
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

    /// G, ∂G/∂z and ∂G/∂c at `z` ≥ 0 and `c` ≥ 0 (both relative to the support), by bicubic
    /// Hermite interpolation of the nodes around (z, c); 0 at and beyond 1.
    #[inline]
    pub(super) fn beyond(&self, z: f64, c: f64) -> Beyond {
        let (sz, sc) = (z * STEPS as f64, c * STEPS as f64);
        if sz >= STEPS as f64 || sc >= STEPS as f64 {
            return Beyond::default();
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
        let row = STEPS + 1;
        let (mut g, mut g_z, mut g_c) = (0.0, 0.0, 0.0);
        for a in 0..2 {
            for b in 0..2 {
                let [v, v_z, v_c, v_zc] = self.nodes[(zi + a) * row + ci + b];
                // The node's value and its slopes scaled to the unit cell.
                let terms = [
                    (a, b, v),
                    (a + 2, b, v_z * step),
                    (a, b + 2, v_c * step),
                    (a + 2, b + 2, v_zc * step * step),
                ];
                for (i, j, w) in terms {
                    g += bz[i] * bc[j] * w;
                    g_z += dz[i] * bc[j] * w;
                    g_c += bz[i] * dc[j] * w;
                }
            }
        }
        Beyond {
            g,
            g_z: g_z / step,
            g_c: g_c / step,
        }
    }
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
