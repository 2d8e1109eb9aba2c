//! Probes: water-height gauges and pressure probes, read from the world between steps at a
//! set rate (docs/method.md §10.3).
//!
//! A [`Gauge`] is a vertical line; it reads the height of the free surface of the water
//! column standing on its bottom, found where the SPH fluid fraction along the line first
//! falls below ½ (so spray above the column is not water height). A [`PressureProbe`] is a
//! point; in the fluid it reads the Shepard-normalised SPH interpolation of the particles'
//! pressures estimated from the constraint forces ([`World::constraint_pressures`]), NaN where
//! no fluid lies within the kernel support; on a wall, the load those constraint forces put on
//! the wall around it, per unit area.
//!
//! ```
//! use projfluid::probe::{Gauge, PressureProbe, ProbeSet};
//! use projfluid::{Params, Vec3, World, boundary::Aabb};
//! let mut world = World::new(Params::default()).unwrap();
//! world.add_container(Aabb { min: Vec3::zeros(), max: Vec3::new(0.6, 0.6, 0.6) }, 1).unwrap();
//! world.add_fluid_block(Vec3::repeat(0.05), [6, 4, 6], Vec3::zeros()).unwrap();
//! let probes = ProbeSet {
//!     rate: 100.0,
//!     gauges: vec![Gauge::new("H1", 0.3, 0.3)],
//!     pressure: vec![PressureProbe::new("P1", [0.3, 0.1, 0.3])],
//! };
//! let reading = probes.read(&world).unwrap();
//! assert!(reading.heights[0] > 0.15 && reading.heights[0] < 0.25);
//! assert_eq!(probes.columns(), ["H1_m", "P1_Pa"]);
//! ```

mod gauge;
mod point;
#[cfg(test)]
mod tests;

pub use gauge::{Gauge, GaugeMeasure};
pub use point::PressureProbe;

use crate::boundary::Aabb;
use crate::neighbors::NeighborLists;
use crate::{Error, Vec3, World};
use serde::{Deserialize, Serialize};
use std::collections::HashSet;

/// The probes of a run and how often they are read: the scene key `probes`
/// (docs/scene-format.md).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProbeSet {
    /// Readings per simulated second (1/s): one at every multiple of 1/`rate` seconds,
    /// t = 0 included.
    pub rate: f64,
    /// Water-height gauges (may be empty).
    #[serde(default)]
    pub gauges: Vec<Gauge>,
    /// Pressure probes (may be empty).
    #[serde(default)]
    pub pressure: Vec<PressureProbe>,
}

/// One reading of a [`ProbeSet`].
#[derive(Clone, Debug, PartialEq)]
pub struct ProbeReading {
    /// Simulated time of the reading (s).
    pub time: f64,
    /// Each gauge's reading above its bottom (m), by its [`GaugeMeasure`], in the order of
    /// the gauges.
    pub heights: Vec<f64>,
    /// Each pressure probe's pressure (Pa; NaN with no fluid within the kernel support), in
    /// the order of the probes.
    pub pressures: Vec<f64>,
}

impl ProbeReading {
    /// The heights (m) then the pressures (Pa): the order of [`ProbeSet::columns`].
    pub fn values(&self) -> impl Iterator<Item = f64> + '_ {
        self.heights.iter().chain(&self.pressures).copied()
    }
}

/// The longest probe name, in bytes.
const MAX_NAME_LENGTH: usize = 64;

impl ProbeSet {
    /// The column name of every probe, gauges first, each with its unit: `NAME_m` for a
    /// gauge's height, `NAME_Pa` for a pressure.
    pub fn columns(&self) -> Vec<String> {
        let heights = self.gauges.iter().map(|g| format!("{}_m", g.name));
        let pressures = self.pressure.iter().map(|p| format!("{}_Pa", p.name));
        heights.chain(pressures).collect()
    }

    /// Checks the set on its own: a positive finite rate, at least one probe, finite
    /// coordinates, a gauge's bottom below its top, and names that are non-empty, unique
    /// across both kinds and made of letters, digits, `_`, `-` and `.` (they become CSV
    /// column names). Errors name the key, e.g. `probes.gauges[1].bottom`.
    pub fn validate(&self) -> Result<(), Error> {
        if !(self.rate.is_finite() && self.rate > 0.0) {
            return Err(Error::invalid(
                "probes.rate",
                self.rate,
                "must be a positive finite number of readings per second",
            ));
        }
        if self.gauges.is_empty() && self.pressure.is_empty() {
            return Err(Error::invalid(
                "probes",
                "no probes",
                "must hold at least one gauge or pressure probe",
            ));
        }
        let mut seen = HashSet::new();
        let names = (self.gauges.iter().enumerate())
            .map(|(i, g)| (format!("probes.gauges[{i}]"), &g.name))
            .chain(
                (self.pressure.iter().enumerate())
                    .map(|(i, p)| (format!("probes.pressure[{i}]"), &p.name)),
            );
        for (key, name) in names {
            check_name(&key, name)?;
            if !seen.insert(name.as_str()) {
                return Err(Error::invalid(
                    format!("{key}.name"),
                    format!("`{name}`"),
                    "must be unique among the probes (each names a CSV column)",
                ));
            }
        }
        for (i, g) in self.gauges.iter().enumerate() {
            g.validate(&format!("probes.gauges[{i}]"))?;
        }
        for (i, p) in self.pressure.iter().enumerate() {
            p.validate(&format!("probes.pressure[{i}]"))?;
        }
        Ok(())
    }

    /// Checks the set ([`ProbeSet::validate`]) against a world's gravity (`[x, y, z]`, m/s²)
    /// and containers: gauges measure along y, so gravity must point along −y, and a gauge
    /// without a bottom needs a container under it.
    pub fn validate_for(&self, gravity: [f64; 3], containers: &[Aabb]) -> Result<(), Error> {
        self.validate()?;
        if self.gauges.is_empty() {
            return Ok(());
        }
        if !(gravity[0] == 0.0 && gravity[2] == 0.0 && gravity[1] < 0.0) {
            return Err(Error::invalid(
                "probes.gauges",
                format!("gravity {gravity:?}"),
                "measure heights along y, so gravity must point along -y",
            ));
        }
        for (i, g) in self.gauges.iter().enumerate() {
            g.bottom_in(containers).ok_or_else(|| {
                Error::invalid(
                    format!("probes.gauges[{i}].bottom"),
                    "none",
                    &format!(
                        "must be given where no container's floor lies under the gauge at \
                         x = {}, z = {}",
                        g.x, g.z
                    ),
                )
            })?;
        }
        Ok(())
    }

    /// Reads every probe of the set in `world` as it stands (docs/method.md §10.3). The
    /// pressures are read from the constraint forces at the current positions, which carry
    /// the water's weight only as accurately as the outer iteration converged (a tight τ
    /// and η = 0 for a reading within a few per cent, docs/method.md §10.3). Deterministic for
    /// any thread count. Errors: the checks of [`ProbeSet::validate_for`] with the world's
    /// gravity and containers. Panics when the memory for the reading cannot be had.
    pub fn read(&self, world: &World) -> Result<ProbeReading, Error> {
        let lines = self.lines(world)?;
        let (heights, pressures) = world.pool.install(|| {
            let Some(snapshot) = world.snapshot() else {
                return (vec![0.0; lines.len()], vec![f64::NAN; self.pressure.len()]);
            };
            let mut lists = (NeighborLists::default(), NeighborLists::default());
            let heights = gauge::read_all(&lines, world, &snapshot, &mut lists);
            let pressures = if self.pressure.is_empty() {
                Vec::new()
            } else {
                let (field, _) = world.pressure_field(&snapshot);
                point::read(&self.pressure, world, &snapshot, &field, &mut lists)
            };
            (heights, pressures)
        });
        Ok(ProbeReading {
            time: world.time(),
            heights,
            pressures,
        })
    }

    /// Reads the set's gauges on the fluid positions `fluid` (m) in place of `world`'s own
    /// fluid, with the world's boundary, containers and particle size: a frame written
    /// earlier, or a frame of another solver on the same geometry. The reading carries `time`
    /// (s). Pressure probes read NaN, since they need the constraint forces of the world's own
    /// fluid. Deterministic for any thread count. Errors: the checks of
    /// [`ProbeSet::validate_for`], and a position that is not finite (naming its index).
    /// Panics when the memory for the reading cannot be had.
    pub fn read_frame(
        &self,
        world: &World,
        fluid: &[Vec3],
        time: f64,
    ) -> Result<ProbeReading, Error> {
        let lines = self.lines(world)?;
        if let Some(i) = fluid.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
            return Err(Error::invalid(
                format!("fluid[{i}]"),
                format!("{:?}", fluid[i].as_slice()),
                "must be a finite position",
            ));
        }
        let heights = world.pool.install(|| {
            let Some(snapshot) = world.snapshot_of(fluid, 0.0, false) else {
                return vec![0.0; lines.len()];
            };
            let mut lists = (NeighborLists::default(), NeighborLists::default());
            gauge::read_all(&lines, world, &snapshot, &mut lists)
        });
        Ok(ProbeReading {
            time,
            heights,
            pressures: vec![f64::NAN; self.pressure.len()],
        })
    }

    /// Every gauge's line in `world`, after the checks of [`ProbeSet::validate_for`].
    fn lines(&self, world: &World) -> Result<Vec<gauge::Line>, Error> {
        self.validate_for(world.params().gravity, world.containers())?;
        Ok(self
            .gauges
            .iter()
            .map(|g| g.line(world.containers()))
            .collect::<Option<_>>()
            .expect("validate_for found a bottom for every gauge"))
    }
}

/// A probe name at JSON key `key`: non-empty, at most [`MAX_NAME_LENGTH`] bytes of ASCII
/// letters, digits, `_`, `-` and `.`, so that it is a CSV column name as it stands.
fn check_name(key: &str, name: &str) -> Result<(), Error> {
    let allowed = |c: char| c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.');
    if name.is_empty() || name.len() > MAX_NAME_LENGTH || !name.chars().all(allowed) {
        return Err(Error::invalid(
            format!("{key}.name"),
            format!("{name:?}"),
            &format!(
                "must be 1 to {MAX_NAME_LENGTH} ASCII letters, digits, `_`, `-` or `.` \
                 (it names a CSV column)"
            ),
        ));
    }
    Ok(())
}
