//! The Martin & Moyce (1952) column collapse: a water column of width a and height n²·a
//! released at t = 0 in a long tank, as a thin 3D slab between two free-slip walls.
//!
//! Tracked quantities (per step):
//! * the surge front z(t): distance from the back wall of the farthest fluid particle near the
//!   floor (centre within 2.5 spacings of the floor plane) that is connected to the back wall
//!   through such particles: sorted by x, no two consecutive ones farther apart than the
//!   kernel support H = 2d. A splash that lands ahead of the front, or a droplet above it,
//!   does not count until the front reaches it;
//! * the residual height h(t): the same rule upwards among particles within 2.5 spacings of
//!   the back wall, from the floor.
//!
//! Distances are measured from the wall planes (the boundary particles) to particle centres.
//! Fluid centres rest one spacing d from a wall plane and each particle stands for a cube of
//! edge d, so the water's surface lies d/2 beyond the outermost centre and its back face d/2
//! in front of the wall plane: centre-to-plane is the water's extent.
//! Scalings are those of the data (`data/validation/README.md`): Z = z/a against
//! T = n·t·√(g/a), H = h/(n²a) against τ = t·√(g/a).
//!
//! Submodules hold the setup ([`Setup`]), the tracking ([`front_position`],
//! [`column_height`]), the comparison with the measurements ([`compare`]) and the report
//! ([`write_report`]); the collapse itself runs in [`simulate`].

mod compare;
mod measure;
mod report;
mod setup;

pub use compare::{Alignment, Comparison, Row, compare};
pub use measure::{column_height, front_position};
pub use report::{ReportFiles, write_report};
pub use setup::Setup;

use super::reference::COLUMN_WIDTH;
use measure::sample;
use projfluid::{Error, Vec3};

/// The front position Z at which simulation and experiment are aligned in time.
pub const ALIGNMENT_LEVEL: f64 = 1.44;

/// One tracked state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    /// Time since release (s).
    pub time: f64,
    /// Front distance z from the back wall (m).
    pub front: f64,
    /// Residual height h at the back wall (m).
    pub height: f64,
    /// Largest compression max(ρ/ρ0 − 1) of the step (dimensionless).
    pub density_error_max: f64,
}

/// A finished collapse: the setup and the tracked history.
#[derive(Clone, Debug)]
pub struct Run {
    /// What was run.
    pub setup: Setup,
    /// One sample at t = 0 and one after every step.
    pub samples: Vec<Sample>,
    /// Fluid particles.
    pub particles: usize,
    /// Boundary particles.
    pub boundary_particles: usize,
    /// Fluid particles that left the tank by the end.
    pub escaped: usize,
    /// Magnitude of gravity g (m/s²).
    pub gravity: f64,
}

/// Runs the collapse for `setup.duration`, tracking front and height after every step;
/// `progress` receives the fraction done after each step. Errors on a bad setup, a failed
/// step, or NaN positions.
pub fn simulate(setup: &Setup, mut progress: impl FnMut(f64)) -> Result<Run, Error> {
    let (mut world, tank) = setup.build()?;
    let d = setup.spacing();
    let g = Vec3::from(world.params().gravity).norm();
    let end = setup.duration * (COLUMN_WIDTH / g).sqrt();
    let mut samples = vec![sample(&world, &tank, d)?];
    world.advance_with(end, |world| {
        if world.nan_count() > 0 {
            return Err(Error::invalid(
                "simulation",
                format!("t = {:.4} s", world.time()),
                "produced non-finite particle positions",
            ));
        }
        samples.push(sample(world, &tank, d)?);
        progress(world.time() / end);
        Ok(())
    })?;
    Ok(Run {
        setup: setup.clone(),
        samples,
        particles: world.fluid_count(),
        boundary_particles: world.boundary_count(),
        escaped: world.escaped_count(),
        gravity: g,
    })
}

impl Run {
    /// √(g/a) (1/s): multiplies seconds into τ.
    fn rate(&self) -> f64 {
        (self.gravity / COLUMN_WIDTH).sqrt()
    }

    /// The simulated front as (T, Z) with T = n·t·√(g/a), Z = z/a.
    pub fn front_curve(&self) -> Vec<(f64, f64)> {
        let (n, rate) = (self.setup.n(), self.rate());
        let a = COLUMN_WIDTH;
        self.samples
            .iter()
            .map(|s| (n * s.time * rate, s.front / a))
            .collect()
    }

    /// The simulated residual height as (τ, H) with τ = t·√(g/a), H = h/(n²a).
    pub fn height_curve(&self) -> Vec<(f64, f64)> {
        let column = f64::from(self.setup.n2) * COLUMN_WIDTH;
        let rate = self.rate();
        self.samples
            .iter()
            .map(|s| (s.time * rate, s.height / column))
            .collect()
    }

    /// Largest compression over the run (dimensionless).
    pub fn density_error_max(&self) -> f64 {
        self.samples
            .iter()
            .map(|s| s.density_error_max)
            .fold(0.0, f64::max)
    }
}
