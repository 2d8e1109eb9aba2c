//! Container walls without particles: each wall of a box as the smooth field of a uniform
//! layer of boundary mass, the lateral average of a wall sampled with particles
//! (docs/method.md §7).

use super::Aabb;
use crate::Vec3;
use crate::kernel::CubicKernel;

/// The six walls of a container box as fields. Each wall stands for one layer of boundary
/// particles `spacing` apart with their Akinci masses ψ (docs/method.md §2.6), spread evenly
/// over the wall's plane: at signed distance z from the plane it adds A·P(z) to a particle's
/// density, with A = ψ/spacing² the layer's mass per area and P the kernel summed over the
/// plane ([`CubicKernel::plane_integral`]). That is the sampled wall's density averaged over
/// where the particle sits along the wall, without the bumps between its particles and
/// without the particles' cost in every density evaluation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WallField {
    /// The box whose faces are the walls (m).
    container: Aabb,
    /// A, the layer's mass per area (kg/m²).
    areal_mass: f64,
    /// H (m).
    support: f64,
}

/// What a container's walls add at one point: the density, its gradient with respect to the
/// point, and a bound on its curvature.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct WallContribution {
    /// The walls' share of the density (kg/m³).
    pub density: f64,
    /// The gradient of that share with respect to the point (kg/m⁴).
    pub gradient: Vec3,
    /// A bound on the second derivative of that share along any direction (kg/m⁵), within
    /// H of the point: the density at the point moved by δ, |δ| < H, is at most
    /// density + gradient·δ + ½·curvature·|δ|².
    pub curvature: f64,
}

impl WallField {
    /// The walls of `container` (m) standing for boundary particles `spacing` (m) apart, for
    /// a fluid of rest density `rest_density` (kg/m³) with `kernel`.
    pub fn new(container: Aabb, spacing: f64, kernel: &CubicKernel, rest_density: f64) -> Self {
        let h = kernel.support_radius();
        let cells = (h / spacing).ceil() as i64 + 1;
        // The Akinci volume of a particle inside a plane lattice: 1 / Σ_k W(|k|·spacing).
        let lattice_sum: f64 = (-cells..=cells)
            .flat_map(|i| (-cells..=cells).map(move |j| (i, j)))
            .map(|(i, j)| kernel.w(((i * i + j * j) as f64).sqrt() * spacing))
            .sum();
        let psi = rest_density / lattice_sum;
        Self {
            container,
            areal_mass: psi / (spacing * spacing),
            support: h,
        }
    }

    /// The box whose faces are the walls (m).
    pub fn container(&self) -> &Aabb {
        &self.container
    }

    /// What the walls add at `x` (m): every wall whose plane lies within H of `x`, for points
    /// within H of the box. The curvature counts every wall within 2H, which a move shorter
    /// than H may bring within reach.
    #[inline(always)]
    pub fn at(&self, x: Vec3, kernel: &CubicKernel) -> WallContribution {
        let (low, high) = (x - self.container.min, self.container.max - x);
        // Most particles lie deep inside the box.
        if low.min().min(high.min()) >= 2.0 * self.support {
            WallContribution::default()
        } else {
            self.near(x, kernel)
        }
    }

    /// [`WallField::at`] for a point within 2H of a wall's plane, or outside the box.
    #[inline(never)]
    fn near(&self, x: Vec3, kernel: &CubicKernel) -> WallContribution {
        let mut out = WallContribution::default();
        let h = self.support;
        if !self.container.contains(&x, 2.0 * h) {
            return out;
        }
        let a = self.areal_mass;
        for axis in 0..3 {
            let below = x[axis] - self.container.min[axis];
            let above = self.container.max[axis] - x[axis];
            for (z, sign) in [(below, 1.0), (above, -1.0)] {
                if z.abs() < 2.0 * h {
                    out.curvature += a * PLANE_CURVATURE * kernel.w_zero();
                }
                if z.abs() < h {
                    out.density += a * kernel.plane_integral(z);
                    out.gradient[axis] += sign * a * kernel.plane_integral_slope(z);
                }
            }
        }
        out
    }
}

/// |P''| ≤ 2π·σ: P'' = −2πσ(f(q) + q·f'(q)) with f = W/σ, and |f + q·f'| ≤ 1 (at q = 0).
const PLANE_CURVATURE: f64 = 2.0 * std::f64::consts::PI;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::boundary::sample_box_walls;

    /// Far from the box's edges, a wall field adds what the sampled wall it stands for adds,
    /// averaged over where a particle sits along the wall: the density at several distances
    /// from the floor, averaged over a grid of positions across one cell of the sampling,
    /// matches the particles' sum within 0.1 % of ρ0; and its gradient is the derivative of
    /// its density.
    #[test]
    fn a_wall_field_is_the_sampled_wall_averaged_along_it() {
        let (r, rho0) = (0.025, 1000.0);
        let kernel = CubicKernel::new(4.0 * r);
        let container = Aabb {
            min: Vec3::zeros(),
            max: Vec3::new(1.0, 1.0, 1.0),
        };
        let field = WallField::new(container, r, &kernel, rho0);
        let all = sample_box_walls(&container, r, 1);
        // The wall particles that reach the points below, with their Akinci volumes.
        let walls: Vec<Vec3> = all
            .iter()
            .filter(|b| (*b - Vec3::new(0.5, 0.5, 0.0)).norm() < 0.2)
            .copied()
            .collect();
        let volumes: Vec<f64> = walls
            .iter()
            .map(|b| 1.0 / all.iter().map(|c| kernel.w((b - c).norm())).sum::<f64>())
            .collect();
        for z in [0.3 * r, r, 1.5 * r, 2.0 * r, 3.0 * r] {
            let mut average = 0.0;
            let n = 8;
            for (u, v) in (0..n).flat_map(|u| (0..n).map(move |v| (u, v))) {
                let x = Vec3::new(
                    0.5 + r * u as f64 / n as f64,
                    0.5 + r * v as f64 / n as f64,
                    z,
                );
                let particles: f64 = walls
                    .iter()
                    .zip(&volumes)
                    .map(|(b, v)| rho0 * v * kernel.w((x - b).norm()))
                    .sum();
                average += particles / (n * n) as f64;
            }
            let here = field.at(Vec3::new(0.5, 0.5, z), &kernel);
            assert!(
                (here.density - average).abs() < 1e-3 * rho0,
                "z = {z}: field {} against particles {average}",
                here.density
            );
            let e = 1e-7;
            let up = field.at(Vec3::new(0.5, 0.5, z + e), &kernel).density;
            let down = field.at(Vec3::new(0.5, 0.5, z - e), &kernel).density;
            let slope = (up - down) / (2.0 * e);
            assert!((here.gradient.z - slope).abs() < 1e-6 * rho0 / r, "z = {z}");
            assert_eq!((here.gradient.x, here.gradient.y), (0.0, 0.0));
        }
        // Beyond H of every wall, and far outside the box: nothing.
        assert_eq!(field.at(Vec3::repeat(0.5), &kernel), WallContribution::default());
        assert_eq!(field.at(Vec3::repeat(3.0), &kernel), WallContribution::default());
    }

    /// The curvature bound holds: along random moves shorter than H from points near a
    /// corner, the density stays below its second-order bound.
    #[test]
    fn the_curvature_bound_majorises_the_change() {
        let (r, rho0) = (0.025, 1000.0);
        let kernel = CubicKernel::new(4.0 * r);
        let container = Aabb {
            min: Vec3::zeros(),
            max: Vec3::new(1.0, 1.0, 1.0),
        };
        let field = WallField::new(container, r, &kernel, rho0);
        let mut rng = crate::random::SplitMix64(3);
        let mut coordinate = |scale: f64| (rng.next_f64() - 0.5) * scale;
        for _ in 0..2000 {
            let x = Vec3::new(
                0.06 + coordinate(0.12),
                0.06 + coordinate(0.12),
                0.06 + coordinate(0.12),
            );
            let delta = Vec3::new(coordinate(0.1), coordinate(0.1), coordinate(0.1));
            let here = field.at(x, &kernel);
            let there = field.at(x + delta, &kernel).density;
            let bound =
                here.density + here.gradient.dot(&delta) + 0.5 * here.curvature * delta.norm_squared();
            assert!(delta.norm() < kernel.support_radius());
            assert!(there <= bound + 1e-9 * rho0, "{x:?} by {delta:?}: {there} > {bound}");
        }
    }
}
