//! Water-height gauges: the free surface of the water column on a vertical line, where the SPH
//! fluid fraction first falls below ½ going up from the gauge's bottom, or the water content
//! of the line, the depth all the water on it would have if it stood on the bottom
//! (docs/method.md §10.3).

use crate::boundary::Aabb;
use crate::neighbors::NeighborLists;
use crate::world::Snapshot;
use crate::{Error, Vec3, World};
use serde::{Deserialize, Serialize};

/// A water-height gauge: the vertical line at (`x`, `z`), y being up.
///
/// It reads the height (m) above `bottom` of the free surface of the water column standing
/// on the bottom: going up the line from `bottom`, the first height at which the fluid
/// fraction φ (the SPH sum of the particles' volumes, walls included, docs/method.md §10.3)
/// falls below ½. Water above that height — spray, droplets, a sheet over an air pocket — is
/// not counted. A bottom that is dry (φ < ½ there) reads 0; a column that reaches `top`
/// reads `top − bottom`. With [`GaugeMeasure::Content`] it reads instead all the water on
/// the line above `bottom`, standing or not.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Gauge {
    /// Name: the CSV column `NAME_m`.
    pub name: String,
    /// The line's x (m).
    pub x: f64,
    /// The line's z (m).
    pub z: f64,
    /// Where the line starts, and heights are measured from (m, along y); `None`: the floor
    /// (lower y face) of the lowest container whose x–z extent holds the line.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bottom: Option<f64>,
    /// Where the line ends (m, along y, above `bottom`); `None`: no end, the line goes up
    /// until the fluid fraction falls below ½.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub top: Option<f64>,
    /// What the gauge reads (m): the surface of the standing column (the default), or the
    /// line's water content.
    #[serde(default, skip_serializing_if = "GaugeMeasure::is_surface")]
    pub measure: GaugeMeasure,
}

/// What a [`Gauge`] reads, in metres above its bottom.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum GaugeMeasure {
    /// The free surface of the water column standing on the bottom: the height at which the
    /// fluid fraction, going up the line, first falls below ½. What a gauge that sees the
    /// water's surface (an acoustic or optical one) reads.
    #[default]
    Surface,
    /// The water content of the line: Σ_j (m/ρ0)·W̄(d_j) over the fluid particles j above the
    /// bottom (and below the top), d_j their horizontal distance from the line and W̄ the
    /// kernel summed along the line ([`CubicKernel::line_integral`]). It is the depth the water
    /// on the line would have if it stood on the bottom: the surface height for a column
    /// standing there, and more than 0 for water falling or flying over a dry bottom. Closer
    /// to what a wire gauge reads, whose signal follows its wetted length wherever the water
    /// touches it.
    ///
    /// [`CubicKernel::line_integral`]: crate::kernel::CubicKernel::line_integral
    Content,
}

impl GaugeMeasure {
    /// Whether this is the default, [`GaugeMeasure::Surface`].
    fn is_surface(&self) -> bool {
        *self == Self::Surface
    }
}

impl Gauge {
    /// A gauge called `name` at (`x`, `z`) (m) standing on the container floor under it,
    /// with no top.
    pub fn new(name: &str, x: f64, z: f64) -> Self {
        Self {
            name: name.to_string(),
            x,
            z,
            bottom: None,
            top: None,
            measure: GaugeMeasure::Surface,
        }
    }

    /// Finite coordinates, and the bottom below the top; errors name `key.field`.
    pub(super) fn validate(&self, key: &str) -> Result<(), Error> {
        let given = [("x", Some(self.x)), ("z", Some(self.z))];
        let bounds = [("bottom", self.bottom), ("top", self.top)];
        for (field, value) in given.into_iter().chain(bounds) {
            if let Some(v) = value.filter(|v| !v.is_finite()) {
                return Err(Error::invalid(
                    format!("{key}.{field}"),
                    v,
                    "must be a finite coordinate (m)",
                ));
            }
        }
        if let (Some(bottom), Some(top)) = (self.bottom, self.top)
            && bottom >= top
        {
            return Err(Error::invalid(
                format!("{key}.bottom"),
                bottom,
                &format!("must lie below top ({top})"),
            ));
        }
        Ok(())
    }

    /// The bottom (m): the given one, else the floor of the lowest of `containers` whose x–z
    /// extent holds the line; `None` without either.
    pub(super) fn bottom_in(&self, containers: &[Aabb]) -> Option<f64> {
        self.bottom.or_else(|| {
            containers
                .iter()
                .filter(|c| {
                    (c.min.x..=c.max.x).contains(&self.x) && (c.min.z..=c.max.z).contains(&self.z)
                })
                .map(|c| c.min.y)
                .min_by(f64::total_cmp)
        })
    }

    /// The line to scan, its bottom resolved in `containers`.
    pub(super) fn line(&self, containers: &[Aabb]) -> Option<Line> {
        Some(Line {
            x: self.x,
            z: self.z,
            bottom: self.bottom_in(containers)?,
            top: self.top,
            measure: self.measure,
        })
    }
}

/// The fluid fraction at which the water ends.
const SURFACE_FRACTION: f64 = 0.5;

/// Distance between the points at which the fraction is evaluated along a line, in lattice
/// spacings d; the crossing is interpolated linearly between them.
const SCAN_STEP_SPACINGS: f64 = 0.25;

/// Points evaluated per neighbour search along a line.
const SCAN_BATCH: usize = 32;

/// A gauge's line with its bottom resolved (m).
pub(super) struct Line {
    x: f64,
    z: f64,
    bottom: f64,
    top: Option<f64>,
    measure: GaugeMeasure,
}

/// The readings (m) of `lines` in `snapshot` of `world`, in their order; `lists` are scratch
/// for the neighbour searches.
pub(super) fn read_all(
    lines: &[Line],
    world: &World,
    snapshot: &Snapshot,
    lists: &mut (NeighborLists, NeighborLists),
) -> Vec<f64> {
    lines
        .iter()
        .map(|line| line.reading(world, snapshot, lists))
        .collect()
}

impl Line {
    /// The gauge's reading (m) in `snapshot` of `world`, by its [`GaugeMeasure`]. `lists` are
    /// scratch for the neighbour searches (fluid, boundary). Runs on the caller's thread pool.
    pub(super) fn reading(
        &self,
        world: &World,
        snapshot: &Snapshot,
        lists: &mut (NeighborLists, NeighborLists),
    ) -> f64 {
        match self.measure {
            GaugeMeasure::Surface => self.surface_height(world, snapshot, lists),
            GaugeMeasure::Content => self.water_content(world, snapshot),
        }
    }

    /// The line's water content (m), [`GaugeMeasure::Content`]: summed in the snapshot's
    /// order, so the same for any thread count.
    fn water_content(&self, world: &World, snapshot: &Snapshot) -> f64 {
        let c = &world.constraint;
        let volume = c.mass / c.rest_density;
        let top = self.top.unwrap_or(f64::INFINITY);
        snapshot
            .fluid
            .iter()
            .filter(|p| p.y >= self.bottom && p.y <= top)
            .map(|p| c.kernel.line_integral((p.x - self.x).hypot(p.z - self.z)))
            .sum::<f64>()
            * volume
    }

    /// The height of the standing column's surface (m), [`GaugeMeasure::Surface`].
    fn surface_height(
        &self,
        world: &World,
        snapshot: &Snapshot,
        lists: &mut (NeighborLists, NeighborLists),
    ) -> f64 {
        let step = SCAN_STEP_SPACINGS * world.params().spacing();
        // Without a top the scan ends at the latest where no particle's kernel reaches.
        let ceiling = || {
            let highest = (snapshot
                .fluid
                .iter()
                .copied()
                .chain(snapshot.boundary.iter())
                .chain(snapshot.walls.iter().map(|w| w.container().max)))
            .map(|p| p.y)
            .fold(f64::NEG_INFINITY, f64::max);
            highest + world.params().support_radius()
        };
        let end = self.top.unwrap_or_else(ceiling).max(self.bottom);
        let at = |k: usize| (self.bottom + k as f64 * step).min(end);
        let last = ((end - self.bottom) / step).ceil().max(0.0) as usize;
        let mut below = (
            self.bottom,
            fraction(world, snapshot, &[self.at(self.bottom)], lists)[0],
        );
        if below.1 < SURFACE_FRACTION {
            return 0.0;
        }
        let mut first = 1;
        while first <= last {
            let batch_end = first.saturating_add(SCAN_BATCH - 1).min(last);
            let points: Vec<Vec3> = (first..=batch_end).map(|k| self.at(at(k))).collect();
            let phi = fraction(world, snapshot, &points, lists);
            for (k, phi) in (first..=batch_end).zip(phi) {
                let y = at(k);
                if phi < SURFACE_FRACTION {
                    let (y0, phi0) = below;
                    let crossing = y0 + (y - y0) * (phi0 - SURFACE_FRACTION) / (phi0 - phi);
                    return crossing - self.bottom;
                }
                below = (y, phi);
            }
            if batch_end == last {
                break;
            }
            first = batch_end + 1;
        }
        end - self.bottom
    }

    /// The point of the line at height `y` (m).
    fn at(&self, y: f64) -> Vec3 {
        Vec3::new(self.x, y, self.z)
    }
}

/// The fluid fraction φ(p) = Σ_j (m/ρ0)·W(p − x_j) + Σ_b (ψ_b/ρ0)·W(p − x_b) at each of
/// `points`, over the fluid and boundary particles of `snapshot` (and the walls that are
/// fields, by what they add to a density): 1 inside water at rest
/// density and next to walls, ½ at a flat free surface, 0 in air (docs/method.md §10.3).
fn fraction(
    world: &World,
    snapshot: &Snapshot,
    points: &[Vec3],
    (fluid_lists, boundary_lists): &mut (NeighborLists, NeighborLists),
) -> Vec<f64> {
    let c = &world.constraint;
    let (kernel, h) = (&c.kernel, world.params().support_radius());
    let volume = c.mass / c.rest_density;
    let s = snapshot;
    s.fluid_near(points, h, fluid_lists);
    s.boundary_near(points, h, boundary_lists);
    points
        .iter()
        .enumerate()
        .map(|(k, p)| {
            let fluid: f64 = (fluid_lists.of(k).iter())
                .map(|&j| kernel.w((p - s.fluid[j as usize]).norm()))
                .sum();
            let walls: f64 = (boundary_lists.of(k).iter())
                .map(|&b| s.psi[b as usize] * kernel.w((p - s.boundary.at(b as usize)).norm()))
                .sum::<f64>()
                + c.walls_at(*p, &s.walls).density;
            volume * fluid + walls / c.rest_density
        })
        .collect()
}
