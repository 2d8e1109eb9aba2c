//! Container walls without particles: each wall of a box as the smooth field of a uniform
//! layer of boundary mass, the lateral average of a wall sampled with particles
//! (docs/method.md §7).

use super::Aabb;
use crate::Vec3;
use crate::kernel::CubicKernel;

mod edge;

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
    /// The spacing of the particles the layer stands for (m).
    spacing: f64,
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
    /// [`SHORT_MOVE`]·H of the point: the density at the point moved by δ,
    /// |δ| < [`SHORT_MOVE`]·H, is at most density + gradient·δ + ½·curvature·|δ|².
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
            spacing,
            support: h,
        }
    }

    /// The box whose faces are the walls (m).
    pub fn container(&self) -> &Aabb {
        &self.container
    }

    /// The particles the wall through `x` (m) stands for within `radius` (m) of `x`: a
    /// square lattice of the field's spacing through `x`, each point with the Akinci mass ψ
    /// (kg) of a wall particle; empty unless `x` lies within `tolerance` (m) of a wall's
    /// plane, inside the box's extent along it. For readings that are defined on particles,
    /// such as the load on a patch of wall.
    pub fn particles_near(&self, x: Vec3, radius: f64, tolerance: f64) -> Vec<(Vec3, f64)> {
        let c = &self.container;
        let inside = |p: &Vec3, a: usize| p[a] >= c.min[a] && p[a] <= c.max[a];
        let Some(normal) = (0..3).find(|&a| {
            let on = (x[a] - c.min[a]).abs() <= tolerance || (c.max[a] - x[a]).abs() <= tolerance;
            on && (0..3).filter(|&b| b != a).all(|b| inside(&x, b))
        }) else {
            return Vec::new();
        };
        let (u, v) = ((normal + 1) % 3, (normal + 2) % 3);
        let n = (radius / self.spacing).floor() as i64;
        let psi = self.areal_mass * self.spacing * self.spacing;
        let mut out = Vec::new();
        for (i, j) in (-n..=n).flat_map(|i| (-n..=n).map(move |j| (i, j))) {
            let mut p = x;
            p[u] += i as f64 * self.spacing;
            p[v] += j as f64 * self.spacing;
            if (p - x).norm() <= radius && inside(&p, u) && inside(&p, v) {
                out.push((p, psi));
            }
        }
        out
    }

    /// What the walls add at `x` (m): every wall whose plane lies within H of `x`, for points
    /// within H of the box. The curvature counts every wall and edge a short move may bring
    /// within reach.
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
        let c = &self.container;
        if !c.contains(&x, 2.0 * h) {
            return out;
        }
        let a = self.areal_mass;
        let reach = h + SHORT_MOVE * h;
        for axis in 0..3 {
            for (z, sign) in [(x[axis] - c.min[axis], 1.0), (c.max[axis] - x[axis], -1.0)] {
                if z.abs() >= reach {
                    continue;
                }
                let edges = (0..3)
                    .filter(|&b| b != axis)
                    .flat_map(|b| [x[b] - c.min[b], c.max[b] - x[b]])
                    .filter(|&e| e < reach)
                    .count();
                let bound = if edges == 0 {
                    PLANE_CURVATURE
                } else {
                    EDGE_CURVATURE
                };
                out.curvature += a * bound * kernel.w_zero();
                if z.abs() < h {
                    let (density, gradient) = self.wall(axis, z, sign, x, kernel);
                    out.density += a * density;
                    out.gradient += gradient * a;
                }
            }
        }
        out
    }

    /// The kernel summed over one wall, in 1/m, and its gradient with respect to the point
    /// `x` (m), in 1/m²: the wall normal to `axis` at signed distance `z` (m) from `x`
    /// (`sign` +1 for the box's lower wall, −1 for its upper one). The plane's integral P less
    /// what lies beyond each of the wall's four edges, B = G or P − G, plus, for two edges
    /// that meet, what lies beyond both, which the two B took off twice: B₁·B₂/P, exact for a
    /// kernel that factorises along the plane (a Gaussian) and for a point on the corner.
    #[inline(always)]
    fn wall(&self, axis: usize, z: f64, sign: f64, x: Vec3, kernel: &CubicKernel) -> (f64, Vec3) {
        let (h, c) = (self.support, &self.container);
        let table = edge::table();
        let depth = z.abs();
        let inverse = 1.0 / h;
        let p = kernel.plane_integral(depth);
        let p_depth = kernel.plane_integral_slope(depth);
        let others = [(axis + 1) % 3, (axis + 2) % 3];
        // What lies beyond each edge: B, ∂B/∂depth and ∂B/∂x along the edge's axis.
        let mut beyond = [[Share::default(); 2]; 2];
        for (k, &other) in others.iter().enumerate() {
            for (l, (e, s)) in [
                (x[other] - c.min[other], 1.0),
                (c.max[other] - x[other], -1.0),
            ]
            .into_iter()
            .enumerate()
            {
                if e >= h {
                    continue;
                }
                let t = table.beyond(depth * inverse, e.abs() * inverse);
                let (g, g_depth) = (t.g * inverse, t.g_z * inverse * inverse);
                // Beyond an edge the foot has passed, the wall's share is P − G; taken as
                // 2G(z, 0) − G, which is that up to the table's accuracy and meets G at the
                // edge with its slope (G(z, 0) = P/2).
                let (value, along_depth) = if e >= 0.0 {
                    (g, g_depth)
                } else {
                    let half = table.beyond(depth * inverse, 0.0);
                    (
                        2.0 * half.g * inverse - g,
                        2.0 * half.g_z * inverse * inverse - g_depth,
                    )
                };
                beyond[k][l] = Share {
                    value,
                    depth: along_depth,
                    across: t.g_c * inverse * inverse * s,
                };
            }
        }
        let mut density = p;
        let mut d_depth = p_depth;
        let mut gradient = Vec3::zeros();
        for (k, &other) in others.iter().enumerate() {
            for b in &beyond[k] {
                density -= b.value;
                d_depth -= b.depth;
                gradient[other] -= b.across;
            }
        }
        // B₁·B₂/P is ill-conditioned where P and both B vanish together, H from the plane:
        // there the interpolated B are not as small as P (tested). P + ε in its place changes
        // the term by at most ε there and nothing where it matters, next to the corner.
        let q = corner_denominator(p, kernel);
        for b1 in &beyond[0] {
            for b2 in &beyond[1] {
                let both = b1.value * b2.value;
                if both == 0.0 {
                    continue;
                }
                density += both / q;
                d_depth +=
                    (b1.depth * b2.value + b1.value * b2.depth) / q - both * p_depth / (q * q);
                gradient[others[0]] += b1.across * b2.value / q;
                gradient[others[1]] += b1.value * b2.across / q;
            }
        }
        // depth = |z| and z = sign·(x − plane).
        let outward = if z < 0.0 { -1.0 } else { 1.0 };
        gradient[axis] += d_depth * outward * sign;
        (density, gradient)
    }
}

/// What lies beyond one edge of a wall (1/m) and its derivatives along the wall's normal
/// depth and across the edge (1/m²).
#[derive(Clone, Copy, Default)]
struct Share {
    value: f64,
    depth: f64,
    across: f64,
}

/// ε of the corner term B₁·B₂/(P + ε), relative to P(0).
const CORNER_REGULARIZATION: f64 = 1e-3;

/// P + ε, the corner term's denominator, for the plane's integral `p` (1/m).
#[inline(always)]
fn corner_denominator(p: f64, kernel: &CubicKernel) -> f64 {
    p + CORNER_REGULARIZATION * kernel.plane_integral(0.0)
}

/// The moves, in H, for which [`WallContribution::curvature`] bounds the walls' curvature.
pub const SHORT_MOVE: f64 = 0.25;

/// |P''| ≤ 2π·σ for a wall without an edge in reach: P'' = −2πσ(f(q) + q·f'(q)) with
/// f = W/σ, and |f + q·f'| ≤ 1 (at q = 0).
const PLANE_CURVATURE: f64 = 2.0 * std::f64::consts::PI;

/// A bound on the curvature of a wall with edges in reach, over σ: the kernel summed over
/// any region of a plane curves at most ∫ ‖Hess W‖ dA over the disc of radius H, with
/// ‖Hess W‖ ≤ M = 6σ/H² ([`CubicKernel::curvature_bound`]), so 6π; with the corner terms
/// the moves of the test below needed at most half of it.
const EDGE_CURVATURE: f64 = 6.0 * std::f64::consts::PI;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::boundary::sample_box_walls;

    /// r (m), ρ0 (kg/m³), the kernel, a 1 m box and its walls as a field.
    fn unit_box() -> (f64, f64, CubicKernel, Aabb, WallField) {
        let (r, rho0) = (0.025, 1000.0);
        let kernel = CubicKernel::new(4.0 * r);
        let container = Aabb {
            min: Vec3::zeros(),
            max: Vec3::repeat(1.0),
        };
        let field = WallField::new(container, r, &kernel, rho0);
        (r, rho0, kernel, container, field)
    }

    /// Far from the box's edges, a wall field adds what the sampled wall it stands for adds,
    /// averaged over where a particle sits along the wall: the density at several distances
    /// from the floor, averaged over a grid of positions across one cell of the sampling,
    /// matches the particles' sum within 0.1 % of ρ0; and its gradient is the derivative of
    /// its density.
    #[test]
    fn a_wall_field_is_the_sampled_wall_averaged_along_it() {
        let (r, rho0, kernel, container, field) = unit_box();
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
        assert_eq!(
            field.at(Vec3::repeat(0.5), &kernel),
            WallContribution::default()
        );
        assert_eq!(
            field.at(Vec3::repeat(3.0), &kernel),
            WallContribution::default()
        );
    }

    /// A number in (0, 1) from a source of numbers in (−½, ½).
    fn rng_fraction(coordinate: &mut impl FnMut(f64) -> f64) -> f64 {
        0.5 + coordinate(0.999)
    }

    /// The curvature bound holds: along random short moves from points near a corner, the
    /// density stays below its second-order bound; and the gradient is the derivative of the
    /// density there.
    #[test]
    fn the_curvature_bound_majorises_the_change() {
        let (r, rho0, kernel, _, field) = unit_box();
        let mut rng = crate::random::SplitMix64(3);
        let mut coordinate = |scale: f64| (rng.next_f64() - 0.5) * scale;
        let short = SHORT_MOVE * kernel.support_radius();
        let mut needed: f64 = 0.0;
        for _ in 0..20_000 {
            // Near the lower corner, or (every other point) the upper one, some points outside
            // the box (a particle pushed through).
            let mut x = Vec3::new(
                0.06 + coordinate(0.16),
                0.06 + coordinate(0.16),
                0.06 + coordinate(0.16),
            );
            if coordinate(1.0) > 0.0 {
                x = Vec3::repeat(1.0) - x;
            }
            let mut delta = Vec3::new(coordinate(1.0), coordinate(1.0), coordinate(1.0));
            delta *= short * rng_fraction(&mut coordinate) / delta.norm();
            let here = field.at(x, &kernel);
            let there = field.at(x + delta, &kernel).density;
            let linear = here.density + here.gradient.dot(&delta);
            let bound = linear + 0.5 * here.curvature * delta.norm_squared();
            assert!(delta.norm() < short);
            assert!(
                there <= bound + 1e-9 * rho0,
                "{x:?} by {delta:?}: {there} > {bound}"
            );
            if here.curvature > 0.0 {
                needed =
                    needed.max((there - linear) / (0.5 * here.curvature * delta.norm_squared()));
            }
            // The gradient is the density's derivative.
            let e = 1e-7;
            for axis in 0..3 {
                let mut step = Vec3::zeros();
                step[axis] = e;
                let slope = (field.at(x + step, &kernel).density
                    - field.at(x - step, &kernel).density)
                    / (2.0 * e);
                assert!(
                    (slope - here.gradient[axis]).abs() < 1e-4 * rho0 / r,
                    "{x:?}, axis {axis}: {} against {slope}",
                    here.gradient[axis]
                );
            }
        }
        eprintln!("the largest share of the curvature bound a move needed: {needed}");
    }

    /// The corner term B₁·B₂/(P + ε) never adds more than the smaller of the two shares it
    /// corrects for, at any depth up to the reach H and any two distances from the edges:
    /// near H the interpolated B undershoot or overshoot the vanishing P (|B|/P reaches
    /// about 1,900 there), and without ε the term exceeds them (by up to 10⁻⁷·P(0): small,
    /// but a term that should correct a share would outgrow it).
    #[test]
    fn the_corner_term_stays_below_the_shares_it_corrects() {
        let (_, _, kernel, _, _) = unit_box();
        let h = kernel.support_radius();
        let table = edge::table();
        let p0 = kernel.plane_integral(0.0);
        let mut excess: f64 = 0.0;
        for i in 0..4000 {
            let depth = h * i as f64 / 4000.0;
            let b: Vec<f64> = (0..=100)
                .map(|j| table.beyond(depth / h, j as f64 / 100.0).g / h)
                .collect();
            let q = corner_denominator(kernel.plane_integral(depth), &kernel);
            for (b1, b2) in b.iter().flat_map(|b1| b.iter().map(move |b2| (b1, b2))) {
                excess = excess.max((b1 * b2).abs() / q - b1.abs().min(b2.abs()));
            }
        }
        assert!(
            excess <= 1e-12 * p0,
            "the corner term exceeds a share by {excess}"
        );
    }

    /// In a corner of the box and out to the reach H of its walls, where a wall's share and
    /// what lies beyond its edges vanish together, the field stays smooth: its gradient is
    /// nowhere larger than twice the steepest slope of a whole plane's.
    #[test]
    fn the_field_stays_smooth_where_a_wall_leaves_reach() {
        let (_, _, kernel, _, field) = unit_box();
        let h = kernel.support_radius();
        let steepest = (0..=1000)
            .map(|k| kernel.plane_integral_slope(h * k as f64 / 1000.0).abs())
            .fold(0.0, f64::max)
            * field.areal_mass;
        // From on the walls at a corner to beyond their reach.
        let n = 60;
        let at = |k: usize| 1.2 * h * k as f64 / n as f64;
        for (i, j, k) in
            (0..=n).flat_map(|i| (0..=n).flat_map(move |j| (0..=n).map(move |k| (i, j, k))))
        {
            let x = Vec3::new(at(i), at(j), at(k));
            let g = field.at(x, &kernel).gradient;
            assert!(
                g.norm() <= 2.0 * steepest,
                "{x:?}: {g:?} against {steepest}"
            );
        }
    }
}
