//! Containment (docs/method.md §7): a fluid particle that starts a step inside a container
//! ends it at least [`WALL_CLEARANCE`]·r inside that container's walls.
//!
//! A wall one layer thick holds the fluid only while the fluid stays off its plane: a particle
//! the step's solve brings to within a small fraction of r of the plane has the wall's
//! particles beside it rather than below it, and the fluid above then pushes it through. In
//! flows the solve resolves, no particle comes that close (the 30k dam break keeps every
//! particle at least 1.01·r from its walls over 2 s), so the clearance changes nothing there;
//! where the solve would push a particle through, it keeps it in.

use crate::Vec3;
use crate::boundary::Aabb;
use rayon::prelude::*;

/// The least distance, in particle radii r, between a contained particle's position at the end
/// of a step and the plane of any wall of its container: half of the distance at which the
/// fluid rests against a wall.
pub(crate) const WALL_CLEARANCE: f64 = 0.5;

/// The containers and the clearance a step keeps its fluid to.
#[derive(Clone, Copy)]
pub(super) struct Containment<'a> {
    /// The world's containers (m).
    pub containers: &'a [Aabb],
    /// The least distance from a wall's plane (m), [`WALL_CLEARANCE`]·r.
    pub clearance: f64,
}

impl Containment<'_> {
    /// Moves each end-of-step position in `x` (m) whose particle started the step inside a
    /// container, at the same index of `start` (m), to at least the clearance inside that
    /// container's walls (the first container that holds it); other positions stay as they are.
    pub fn keep_inside(&self, start: &[Vec3], x: &mut [Vec3]) {
        if self.containers.is_empty() {
            return;
        }
        let clearance = self.clearance;
        x.par_iter_mut().zip(start.par_iter()).for_each(|(x, s)| {
            if let Some(c) = self.containers.iter().find(|c| c.contains(s, 0.0)) {
                for a in 0..3 {
                    x[a] = x[a].max(c.min[a] + clearance).min(c.max[a] - clearance);
                }
            }
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A particle pushed through a wall comes back to the clearance; one that stays clear of
    /// the walls, and one that started outside every container, are left where they are.
    #[test]
    fn only_particles_pushed_past_the_clearance_move() {
        let unit = Aabb {
            min: Vec3::zeros(),
            max: Vec3::repeat(1.0),
        };
        let containment = Containment {
            containers: &[unit],
            clearance: 0.1,
        };
        let start = [
            Vec3::new(0.5, 0.5, 0.2),
            Vec3::new(0.5, 0.5, 0.2),
            Vec3::new(0.5, 0.5, 1.5),
        ];
        let mut x = [
            Vec3::new(0.5, 1.2, -0.3),
            Vec3::new(0.3, 0.4, 0.15),
            Vec3::new(0.5, 0.5, 1.4),
        ];
        containment.keep_inside(&start, &mut x);
        assert_eq!(x[0], Vec3::new(0.5, 0.9, 0.1));
        assert_eq!(x[1], Vec3::new(0.3, 0.4, 0.15));
        assert_eq!(x[2], Vec3::new(0.5, 0.5, 1.4));
    }
}
