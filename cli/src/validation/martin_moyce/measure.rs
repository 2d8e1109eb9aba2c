//! The tracked quantities: the surge front and the residual height, each the extent of the
//! fluid connected to a wall (see the module docs of [`super`]).

use super::Sample;
use projfluid::boundary::Aabb;
use projfluid::{Error, Vec3, World};

/// Particles whose centres lie within this many spacings of the floor (back wall) count for the
/// front (the residual height).
const BAND_SPACINGS: f64 = 2.5;

/// Distance from `start` to the end of the run of `values` that begins at the smallest value
/// and in which consecutive sorted values lie at most `gap` apart.
fn connected_extent(mut values: Vec<f64>, start: f64, gap: f64) -> Option<f64> {
    values.sort_by(f64::total_cmp);
    let first = *values.first()?;
    let end = values
        .windows(2)
        .find(|w| w[1] - w[0] > gap)
        .map_or(values[values.len() - 1], |w| w[0]);
    Some(end.max(first) - start)
}

/// Front distance z (m) from the back wall plane at x = `back`: see the module docs.
pub fn front_position(positions: &[Vec3], back: f64, floor: f64, spacing: f64) -> Option<f64> {
    let near_floor = positions
        .iter()
        .filter(|p| p.y - floor <= BAND_SPACINGS * spacing)
        .map(|p| p.x)
        .collect();
    connected_extent(near_floor, back, 2.0 * spacing)
}

/// Residual height h (m) above the floor plane at y = `floor` next to the back wall: see the
/// module docs.
pub fn column_height(positions: &[Vec3], back: f64, floor: f64, spacing: f64) -> Option<f64> {
    let near_wall = positions
        .iter()
        .filter(|p| p.x - back <= BAND_SPACINGS * spacing)
        .map(|p| p.y)
        .collect();
    connected_extent(near_wall, floor, 2.0 * spacing)
}

/// The tracked state of `world` in `tank` (lattice spacing `spacing`).
pub(super) fn sample(world: &World, tank: &Aabb, spacing: f64) -> Result<Sample, Error> {
    let positions = world.positions();
    let lost = || Error::invalid("fluid", "no particles", "left near the floor and back wall");
    let front = front_position(&positions, tank.min.x, tank.min.y, spacing).ok_or_else(lost)?;
    let height = column_height(&positions, tank.min.x, tank.min.y, spacing).ok_or_else(lost)?;
    Ok(Sample {
        time: world.time(),
        front,
        height,
        density_error_max: world.last_step().map_or(0.0, |s| s.density_error_max),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn front_ignores_detached_splashes_and_high_droplets() {
        let d = 0.01;
        let mut p: Vec<Vec3> = (0..10)
            .map(|i| Vec3::new(0.01 + i as f64 * d, 0.01, 0.0))
            .collect();
        // A droplet above the front, and a splash on the floor beyond the kernel support.
        p.push(Vec3::new(0.5, 0.2, 0.0));
        p.push(Vec3::new(0.10 + 2.5 * d, 0.01, 0.0));
        assert!((front_position(&p, 0.0, 0.0, d).unwrap() - 0.10).abs() < 1e-12);
        // Once the front reaches the splash (within 2d), it counts.
        p.push(Vec3::new(0.11, 0.02, 0.0));
        let z = front_position(&p, 0.0, 0.0, d).unwrap();
        assert!((z - (0.10 + 2.5 * d)).abs() < 1e-12, "{z}");
        assert_eq!(front_position(&[], 0.0, 0.0, d), None);
    }

    #[test]
    fn height_is_the_connected_top_next_to_the_back_wall() {
        let d = 0.01;
        let mut p: Vec<Vec3> = (0..8)
            .map(|j| Vec3::new(0.01, 0.01 + j as f64 * d, 0.0))
            .collect();
        p.push(Vec3::new(0.01, 0.5, 0.0)); // a droplet far above
        p.push(Vec3::new(0.2, 0.3, 0.0)); // far from the wall
        assert!((column_height(&p, 0.0, 0.0, d).unwrap() - 0.08).abs() < 1e-12);
    }
}
