//! Pressure probes: in the fluid, the particles' constraint pressures interpolated at a point
//! (Shepard normalised); on a wall, the load the constraint forces put on the wall's
//! particles around it, per unit area (docs/method.md §10.3).

use crate::neighbors::NeighborLists;
use crate::world::Snapshot;
use crate::{Error, Vec3, World};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// A pressure probe at a fixed point, in the fluid or on a wall.
///
/// In the fluid (`wall` false) it reads p(x) = Σ_j p_j·W(x − x_j) / Σ_j W(x − x_j) over the
/// fluid particles j within the kernel support H of x, p_j being each particle's pressure
/// estimate from the constraint forces ([`World::constraint_pressures`]). The normalisation by
/// the kernel sum makes a probe whose support the fluid only partly fills read the mean of the
/// particles it sees rather than a fraction of it. With no fluid particle within H the
/// pressure is undefined and reads NaN.
///
/// On a wall (`wall` true; the point on the surface through the wall's innermost particles,
/// at least H from the wall's edges) it reads the normal stress the fluid puts on the wall
/// there: |Σ_b f_b·ω(x − x_b)| over the boundary particles b within H, f_b being the force the
/// constraint forces exert on b and ω the cubic spline normalised over a plane, so that the
/// sum is force per area. A dry wall reads 0; a point with no boundary particle within H reads
/// NaN. The particle pressures next to a wall are not used there: they read about 1.5 times
/// the hydrostatic pressure, because the wall's whole reaction on a particle passes through
/// that particle's own constraint (docs/method.md §10.3).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PressureProbe {
    /// Name: the CSV column `NAME_Pa`.
    pub name: String,
    /// The point `[x, y, z]` (m).
    pub position: [f64; 3],
    /// Whether the point lies on a wall, whose load the probe then reads (default: in the
    /// fluid).
    #[serde(default, skip_serializing_if = "is_false")]
    pub wall: bool,
}

fn is_false(b: &bool) -> bool {
    !*b
}

impl PressureProbe {
    /// A probe in the fluid called `name` at `position` (m).
    pub fn new(name: &str, position: [f64; 3]) -> Self {
        Self {
            name: name.to_string(),
            position,
            wall: false,
        }
    }

    /// A probe on a wall called `name` at `position` (m), on the surface through the wall's
    /// innermost particles.
    pub fn on_wall(name: &str, position: [f64; 3]) -> Self {
        Self {
            wall: true,
            ..Self::new(name, position)
        }
    }

    /// A finite position; errors name `key.position`.
    pub(super) fn validate(&self, key: &str) -> Result<(), Error> {
        if self.position.iter().any(|c| !c.is_finite()) {
            return Err(Error::invalid(
                format!("{key}.position"),
                format!("{:?}", self.position),
                "must be a finite point (m)",
            ));
        }
        Ok(())
    }
}

/// Every probe's reading (Pa, NaN where undefined), given the pressure estimate of every fluid
/// particle of `snapshot` (`pressures`, in its order). `lists` is scratch for the neighbour
/// searches in the snapshot's grid. Runs on the caller's thread pool.
pub(super) fn read(
    probes: &[PressureProbe],
    world: &World,
    snapshot: &Snapshot,
    pressures: &[f64],
    lists: &mut (NeighborLists, NeighborLists),
) -> Vec<f64> {
    let field = Field {
        world,
        snapshot,
        pressures,
    };
    probes
        .iter()
        .map(|p| {
            let x = Vec3::from(p.position);
            if p.wall {
                field.wall_stress(x, lists)
            } else {
                field.interpolated(x, &mut lists.0)
            }
        })
        .collect()
}

/// The particle pressures of a snapshot and what reading them needs.
struct Field<'a> {
    world: &'a World,
    snapshot: &'a Snapshot,
    /// Pressure estimate of each fluid particle of `snapshot`, in its order (Pa).
    pressures: &'a [f64],
}

impl Field<'_> {
    /// The Shepard-normalised interpolation of the particle pressures at `x` (Pa; NaN without
    /// fluid within H).
    fn interpolated(&self, x: Vec3, lists: &mut NeighborLists) -> f64 {
        let (s, kernel) = (self.snapshot, &self.world.constraint.kernel);
        let h = kernel.support_radius();
        s.fluid_near(&[x], h, lists);
        let (weighted, total) = lists
            .of(0)
            .iter()
            .fold((0.0, 0.0), |(weighted, total), &j| {
                let w = kernel.w((x - s.fluid[j as usize]).norm());
                (weighted + w * self.pressures[j as usize], total + w)
            });
        if total > 0.0 {
            weighted / total
        } else {
            f64::NAN
        }
    }

    /// The normal stress (Pa) the fluid puts on the wall at `x`: the constraint forces'
    /// load on the boundary particles within H, spread over the wall with the planar spline
    /// (NaN without boundary particles within H).
    ///
    /// Constraint j's correction of its own centre has the boundary part
    /// k·λ_j·w_j·(1/ρ0)·Σ_b ψ_b·∇W(x_j − x_b) (docs/method.md §11.3); its reaction on b, with
    /// k·λ_j·w_j = −p_j·V (docs/method.md §10.1), is f_b = Σ_j p_j·V·(ψ_b/ρ0)·∇W(x_j − x_b).
    ///
    /// On a wall that is a field, the same over the particles it stands for
    /// ([`crate::boundary::WallField::particles_near`]), `x` within r/2 of the wall's plane.
    fn wall_stress(&self, x: Vec3, (fluid, boundary): &mut (NeighborLists, NeighborLists)) -> f64 {
        let (s, c) = (self.snapshot, &self.world.constraint);
        let h = c.kernel.support_radius();
        let tolerance = 0.5 * self.world.params().particle_radius;
        let mut near: Vec<(Vec3, f64)> = (s.walls.iter())
            .flat_map(|w| w.particles_near(x, h, tolerance))
            .collect();
        if near.is_empty() {
            s.boundary_near(&[x], h, boundary);
            let particles = boundary.of(0).iter().map(|&b| b as usize);
            near = particles.map(|b| (s.boundary.at(b), s.psi[b])).collect();
        }
        if near.is_empty() {
            return f64::NAN;
        }
        let at: Vec<Vec3> = near.iter().map(|&(xb, _)| xb).collect();
        s.fluid_near(&at, h, fluid);
        let volume = c.mass / c.rest_density;
        let stress: Vec3 = near
            .iter()
            .enumerate()
            .map(|(k, &(xb, psi))| {
                let force: Vec3 = (fluid.of(k).iter())
                    .map(|&j| {
                        let xj = s.fluid[j as usize];
                        self.pressures[j as usize] * c.kernel.grad_w(&(xj - xb))
                    })
                    .sum();
                force * (volume * psi / c.rest_density) * planar_weight((x - xb).norm(), h)
            })
            .sum();
        stress.norm()
    }
}

/// The cubic spline of support `h` (m) normalised over a plane, at distance `r` (m):
/// σ₂·(2(1 − q)₊³ − 8(½ − q)₊³) with q = r/h and σ₂ = 40/(7π·h²), so that its integral over a
/// plane through its centre is 1 (1/m²).
fn planar_weight(r: f64, h: f64) -> f64 {
    let q = r / h;
    let outer = (1.0 - q).max(0.0);
    let inner = (0.5 - q).max(0.0);
    40.0 / (7.0 * PI * h * h) * (2.0 * outer.powi(3) - 8.0 * inner.powi(3))
}

#[cfg(test)]
mod tests {
    use super::planar_weight;

    /// Summed over a fine square lattice in a plane through its centre, times the area of a
    /// lattice cell, the planar weight is 1.
    #[test]
    fn planar_weight_integrates_to_one_over_a_plane() {
        let (h, a): (f64, f64) = (0.1, 0.001);
        let n = (h / a).ceil() as i64 + 1;
        let sum: f64 = (-n..=n)
            .flat_map(|i| (-n..=n).map(move |j| (i as f64 * a, j as f64 * a)))
            .map(|(u, v)| planar_weight((u * u + v * v).sqrt(), h) * a * a)
            .sum();
        assert!((sum - 1.0).abs() < 1e-4, "{sum}");
        assert_eq!(planar_weight(h, h), 0.0);
    }
}
