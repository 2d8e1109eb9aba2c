//! The cubic B-spline SPH kernel (Monaghan's M4 spline written over its support radius H),
//! docs/method.md §2.1.

use crate::Vec3;
use std::f64::consts::PI;

/// Distances at or below this length (metres) have a zero kernel gradient, so coincident
/// particles never produce a NaN direction.
const GRADIENT_CUTOFF: f64 = 1e-9;

/// The 3D cubic spline kernel W(r) with support radius H (W = 0 for |r| > H).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CubicKernel {
    support_radius: f64,
    /// 1/H, in 1/m.
    inverse_support: f64,
    /// Normalisation σ = 8/(πH³), in 1/m³; also W(0).
    sigma: f64,
    /// 48/(πH⁴), the gradient's prefactor, in 1/m⁴.
    gradient_factor: f64,
}

impl CubicKernel {
    /// A kernel with support radius `support_radius` (H, metres; must be positive).
    pub fn new(support_radius: f64) -> Self {
        let h3 = support_radius.powi(3);
        Self {
            support_radius,
            inverse_support: 1.0 / support_radius,
            sigma: 8.0 / (PI * h3),
            gradient_factor: 48.0 / (PI * h3 * support_radius),
        }
    }

    /// The support radius H in metres.
    pub fn support_radius(&self) -> f64 {
        self.support_radius
    }

    /// W(0) = σ, in 1/m³.
    pub fn w_zero(&self) -> f64 {
        self.sigma
    }

    /// W at distance `r` (metres), in 1/m³.
    ///
    /// Evaluated without branches as σ·(2·(1 − q)₊³ − 8·(½ − q)₊³), q = r/H, which is
    /// σ·(6q³ − 6q² + 1) for q ≤ ½ and σ·2(1 − q)³ for ½ < q ≤ 1: the neighbours of a
    /// particle fall on both sides of q = ½ in no predictable order, and this is the inner
    /// loop of every density evaluation.
    #[inline]
    pub fn w(&self, r: f64) -> f64 {
        let q = r * self.inverse_support;
        let outer = (1.0 - q).max(0.0);
        let inner = (0.5 - q).max(0.0);
        self.sigma * (2.0 * outer * outer * outer - 8.0 * inner * inner * inner)
    }

    /// The kernel summed along a straight line at distance `d` (m) from its centre,
    /// ∫ W(√(d² + s²)) ds over the whole line, in 1/m²: what a particle adds to the water
    /// content of a vertical gauge line at horizontal distance d (docs/method.md §10.3). Zero
    /// at and beyond H; it integrates to 1 over the plane (tested).
    ///
    /// By Simpson's rule on both sides of the kink of W at q = ½, each piece a smooth function
    /// of s (within 10⁻⁶ of W̄(0) of a brute-force sum, tested).
    pub fn line_integral(&self, d: f64) -> f64 {
        let h = self.support_radius;
        let d = d.abs();
        if d >= h {
            return 0.0;
        }
        let at = |s: f64| self.w((d * d + s * s).sqrt());
        let simpson = |a: f64, b: f64| {
            const PANELS: usize = 64;
            let step = (b - a) / PANELS as f64;
            let inner: f64 = (1..PANELS)
                .map(|k| at(a + k as f64 * step) * if k % 2 == 1 { 4.0 } else { 2.0 })
                .sum();
            (at(a) + inner + at(b)) * step / 3.0
        };
        let end = (h * h - d * d).sqrt();
        let half = 0.5 * h;
        let one_side = if d < half {
            let kink = (half * half - d * d).sqrt();
            simpson(0.0, kink) + simpson(kink, end)
        } else {
            simpson(0.0, end)
        };
        2.0 * one_side
    }

    /// The kernel summed over a whole plane at distance `z` (m) from its centre,
    /// P(z) = ∫ W dA = 2π ∫_|z|^H W(u) u du, in 1/m: what a uniform layer of unit mass per
    /// area adds to the density at distance z (docs/method.md §7). Zero at and beyond H; it
    /// integrates to 1 over z (tested). In closed form, with a = |z|/H, T = (1 − a)₊ and
    /// T' = (½ − a)₊: P = 2πσH²·(T⁴/2 − 2T⁵/5 − T'⁴ + 8T'⁵/5).
    #[inline]
    pub fn plane_integral(&self, z: f64) -> f64 {
        let a = z.abs() * self.inverse_support;
        let outer = (1.0 - a).max(0.0);
        let inner = (0.5 - a).max(0.0);
        let (o4, i4) = (outer.powi(4), inner.powi(4));
        let shape = 0.5 * o4 - 0.4 * o4 * outer - i4 + 1.6 * i4 * inner;
        2.0 * PI * self.sigma * shape / (self.inverse_support * self.inverse_support)
    }

    /// The derivative dP/dz of [`CubicKernel::plane_integral`] at signed distance `z` (m),
    /// −2πW(|z|)·z, in 1/m²; its magnitude is at most 2πσH/4 and its second derivative
    /// at most 2πσ in magnitude.
    #[inline]
    pub fn plane_integral_slope(&self, z: f64) -> f64 {
        -2.0 * PI * self.w(z.abs()) * z
    }

    /// The largest curvature of W, in 1/m⁵: a bound M on every eigenvalue of the Hessian of
    /// W(|r|) over all offsets r, M = 6σ/H². With f(q) = W/σ the eigenvalues are f''(q)/H²
    /// along r and f'(q)/(qH²) across it; f'' = 36q − 12 for q ≤ ½ and 12(1 − q) beyond, at
    /// most 6 (at q = ½), and f'/q < 0. So W(r + δ) ≤ W(r) + ∇W(r)·δ + ½M|δ|² for every r
    /// and δ (Taylor's theorem with the remainder's integral form; W is twice differentiable).
    pub fn curvature_bound(&self) -> f64 {
        6.0 * self.sigma * self.inverse_support * self.inverse_support
    }

    /// ∇W with respect to the first argument of W(x_i − x_j), given `r = x_i − x_j` (metres),
    /// in 1/m⁴.
    #[inline]
    pub fn grad_w(&self, r: &Vec3) -> Vec3 {
        self.grad_w_at(r, r.norm())
    }

    /// [`CubicKernel::grad_w`] for `r` whose length `len` = |r| (m) is already known.
    ///
    /// The shape q(3q − 2) for q ≤ ½ and −(1 − q)² for ½ < q ≤ 1 is evaluated without
    /// branches as 4·(½ − q)₊² − (1 − q)₊², as in [`CubicKernel::w`].
    #[inline]
    pub fn grad_w_at(&self, r: &Vec3, len: f64) -> Vec3 {
        r * self.grad_w_coefficient(len)
    }

    /// The factor c with ∇W(r) = c·r for an offset of length `len` (m), in 1/m⁵: zero at
    /// or below the cutoff and beyond H. Written as a select, so loops over many lengths
    /// vectorise.
    #[inline]
    pub fn grad_w_coefficient(&self, len: f64) -> f64 {
        let q = len * self.inverse_support;
        let outer = (1.0 - q).max(0.0);
        let inner = (0.5 - q).max(0.0);
        let shape = 4.0 * inner * inner - outer * outer;
        let c = self.gradient_factor * shape / len;
        if len > GRADIENT_CUTOFF { c } else { 0.0 }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integrates_to_one() {
        let h = 0.1;
        let kernel = CubicKernel::new(h);
        // Radial integral ∫ 4π r² W(r) dr by the composite Simpson rule.
        let n = 2000;
        let dr = h / n as f64;
        let f = |r: f64| 4.0 * PI * r * r * kernel.w(r);
        let mut sum = f(0.0) + f(h);
        for i in 1..n {
            sum += f(i as f64 * dr) * if i % 2 == 1 { 4.0 } else { 2.0 };
        }
        let integral = sum * dr / 3.0;
        assert!((integral - 1.0).abs() < 1e-6, "integral {integral}");
    }

    /// W(r + δ) ≤ W(r) + ∇W(r)·δ + ½M|δ|² with M = [`CubicKernel::curvature_bound`], for
    /// offsets across the whole support and steps in every direction; and the bound is
    /// nearly attained, so M is not loose.
    #[test]
    fn curvature_bound_majorises_the_second_order_remainder() {
        let h = 0.1;
        let kernel = CubicKernel::new(h);
        let m = kernel.curvature_bound();
        let mut rng = crate::random::SplitMix64(12345);
        let mut uniform = || rng.next_f64() * 2.0 - 1.0;
        let mut worst: f64 = 0.0;
        for _ in 0..200_000 {
            let r = Vec3::new(uniform(), uniform(), uniform()) * (1.1 * h);
            let delta = Vec3::new(uniform(), uniform(), uniform()) * (0.2 * h * uniform().abs());
            let bound = 0.5 * m * delta.norm_squared();
            if bound == 0.0 {
                continue;
            }
            let remainder =
                kernel.w((r + delta).norm()) - kernel.w(r.norm()) - kernel.grad_w(&r).dot(&delta);
            assert!(
                remainder <= bound * (1.0 + 1e-9) + 1e-12,
                "r {r:?} delta {delta:?}"
            );
            worst = worst.max(remainder / bound);
        }
        assert!(worst > 0.9, "largest remainder / bound {worst}");
        // The radial second derivative at q = ½ is M exactly.
        let e = 1e-5 * h;
        let second =
            (kernel.w(0.5 * h + e) - 2.0 * kernel.w(0.5 * h) + kernel.w(0.5 * h - e)) / (e * e);
        assert!((second / m - 1.0).abs() < 1e-3, "W''(H/2) {second}, M {m}");
    }

    /// The line integral is the kernel's projection onto a plane: it integrates to 1 over
    /// the plane, matches a brute-force sum along the line on both sides of H/2, falls with
    /// distance and vanishes at H.
    #[test]
    fn line_integral_integrates_to_one_over_the_plane() {
        let h = 0.1;
        let kernel = CubicKernel::new(h);
        let n = 4000;
        let dd = h / n as f64;
        let f = |d: f64| 2.0 * PI * d * kernel.line_integral(d);
        let mut sum = f(0.0) + f(h);
        for i in 1..n {
            sum += f(i as f64 * dd) * if i % 2 == 1 { 4.0 } else { 2.0 };
        }
        let integral = sum * dd / 3.0;
        assert!((integral - 1.0).abs() < 1e-6, "plane integral {integral}");
        // Against a brute-force midpoint sum along the line, at distances on both sides of H/2.
        for d in [0.0, 0.013, 0.049, 0.05, 0.071, 0.0999] {
            let m = 200_000;
            let ds = 2.0 * h / m as f64;
            let brute: f64 = (0..m)
                .map(|k| {
                    let s = -h + (k as f64 + 0.5) * ds;
                    kernel.w((d * d + s * s).sqrt()) * ds
                })
                .sum();
            let value = kernel.line_integral(d);
            assert!(
                (value - brute).abs() <= 1e-6 * kernel.line_integral(0.0),
                "d = {d}: {value} against {brute}"
            );
        }
        assert!(kernel.line_integral(0.02) < kernel.line_integral(0.01));
        assert_eq!(kernel.line_integral(h), 0.0);
        assert_eq!(kernel.line_integral(-0.2), 0.0);
    }

    /// The plane integral integrates to 1 over the distance, is the brute-force sum of W over
    /// a fine lattice in the plane, and its slope is its derivative.
    #[test]
    fn plane_integral_is_the_kernel_summed_over_a_plane() {
        let h = 0.1;
        let k = CubicKernel::new(h);
        let n = 4000;
        let dz = 2.0 * h / n as f64;
        let total: f64 = (0..n)
            .map(|i| k.plane_integral(-h + (i as f64 + 0.5) * dz) * dz)
            .sum();
        assert!((total - 1.0).abs() < 1e-6, "∫P dz = {total}");
        let step = h / 200.0;
        for z in [0.0, 0.013, 0.05, 0.071, 0.099] {
            let cells = (h / step) as i64 + 1;
            let brute: f64 = (-cells..=cells)
                .flat_map(|i| (-cells..=cells).map(move |j| (i, j)))
                .map(|(i, j)| {
                    let (u, v) = (i as f64 * step, j as f64 * step);
                    k.w((u * u + v * v + z * z).sqrt()) * step * step
                })
                .sum();
            let p = k.plane_integral(z);
            assert!(
                (p - brute).abs() < 1e-3 * k.plane_integral(0.0),
                "z {z}: {p} against {brute}"
            );
            assert_eq!(p, k.plane_integral(-z));
            let e = 1e-7;
            let numeric = (k.plane_integral(z + e) - k.plane_integral(z - e)) / (2.0 * e);
            let slope = k.plane_integral_slope(z);
            assert!(
                (numeric - slope).abs() < 1e-5 * k.plane_integral(0.0) / h,
                "z {z}"
            );
        }
        assert_eq!(k.plane_integral(h), 0.0);
        assert_eq!(k.plane_integral(1.5 * h), 0.0);
    }

    #[test]
    fn lattice_sum_is_one() {
        // Σ_j W(x_i − x_j) d³ over a cubic lattice of spacing d = H/2 (docs/method.md §2.2: 0.99997).
        let h = 0.1;
        let d = h / 2.0;
        let kernel = CubicKernel::new(h);
        let mut sum = 0.0;
        for i in -3..=3 {
            for j in -3..=3 {
                for k in -3..=3 {
                    let r = Vec3::new(i as f64, j as f64, k as f64) * d;
                    sum += kernel.w(r.norm());
                }
            }
        }
        assert!(
            (sum * d * d * d - 0.99997).abs() < 5e-5,
            "{}",
            sum * d * d * d
        );
    }

    #[test]
    fn value_at_zero_and_support() {
        let kernel = CubicKernel::new(0.1);
        assert_eq!(kernel.w(0.0), 8.0 / (PI * 1e-3));
        assert_eq!(kernel.w_zero(), kernel.w(0.0));
        assert_eq!(kernel.w(0.1), 0.0);
        assert_eq!(kernel.w(0.1000001), 0.0);
        // Continuous at q = 1/2: both branches give σ/4.
        assert!((kernel.w(0.05) - kernel.w_zero() / 4.0).abs() < 1e-9);
    }

    /// The branch-free forms equal the piecewise definitions of docs/method.md §2.1, on both
    /// sides of q = ½, at q = ½ and 1 exactly, and beyond the support.
    #[test]
    fn branch_free_forms_match_the_piecewise_spline() {
        let h = 0.1;
        let k = CubicKernel::new(h);
        let sigma = 8.0 / (PI * h * h * h);
        for step in 0..=1300 {
            let q = step as f64 / 1000.0;
            let (w, shape) = if q <= 0.5 {
                (6.0 * q * q * q - 6.0 * q * q + 1.0, q * (3.0 * q - 2.0))
            } else if q <= 1.0 {
                (2.0 * (1.0 - q).powi(3), -(1.0 - q).powi(2))
            } else {
                (0.0, 0.0)
            };
            let r = q * h;
            assert!((k.w(r) - sigma * w).abs() <= 1e-12 * sigma, "W at q = {q}");
            let grad = k.grad_w_at(&Vec3::new(r, 0.0, 0.0), r).x;
            let expected = if step == 0 {
                0.0
            } else {
                48.0 / (PI * h.powi(4)) * shape
            };
            assert!(
                (grad - expected).abs() <= 1e-10 * 48.0 / (PI * h.powi(4)),
                "∇W at q = {q}: {grad} against {expected}"
            );
        }
    }

    #[test]
    fn gradient_matches_finite_differences() {
        let kernel = CubicKernel::new(0.1);
        let eps = 1e-7;
        for r in [
            Vec3::new(0.01, 0.002, -0.003),
            Vec3::new(0.03, -0.02, 0.01),
            Vec3::new(-0.06, 0.04, 0.02),
            Vec3::new(0.0, 0.0, 0.09),
        ] {
            let g = kernel.grad_w(&r);
            for axis in 0..3 {
                let mut plus = r;
                let mut minus = r;
                plus[axis] += eps;
                minus[axis] -= eps;
                let fd = (kernel.w(plus.norm()) - kernel.w(minus.norm())) / (2.0 * eps);
                assert!(
                    (fd - g[axis]).abs() <= 1e-5 * g.norm().max(1.0),
                    "axis {axis} r {r:?}: fd {fd} analytic {}",
                    g[axis]
                );
            }
        }
        assert_eq!(kernel.grad_w(&Vec3::zeros()), Vec3::zeros());
        assert_eq!(kernel.grad_w(&Vec3::new(0.2, 0.0, 0.0)), Vec3::zeros());
    }
}
