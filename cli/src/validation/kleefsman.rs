//! The MARIN dam break with a box (Kleefsman et al. 2005; SPHERIC benchmark Test 2): a 0.55 m
//! deep reservoir at one end of a 3.22 m tank is released at t = 0 and its surge runs past a
//! box standing on the floor, hits the far wall and comes back. Four gauges measure the water
//! height; the simulation reads the same gauges ([`projfluid::probe::Gauge`], docs/method.md
//! §10.3) after every step.
//!
//! Geometry, in the experiment's frame (x along the tank from the wall at the box end, y
//! across, z up; `data/validation/README.md`): tank 3.22 × 1 × 1 m, water x ∈ [1.992, 3.22]
//! over the full width, box x ∈ [0.6635, 0.8245], y ∈ [0.2985, 0.7015], z ∈ [0, 0.161], gauges
//! H1–H4 at x = 0.496, 0.992, 1.488, 2.638 on the centre line y = 0.5. projfluid's gravity is −y
//! and its gauges measure along y, so the simulation runs in the frame (x, z, y): a point
//! (x, y, z) of the experiment is (x, z, y) in the world ([`world_point`]).
//!
//! Where solid faces are: the fluid's particles stay one spacing d = 2r from a wall's particle
//! plane, and each stands for a cube of edge d, so the water ends d/2 = r in front of the
//! plane, which is where the solid face is. Every sampled surface is therefore set back r
//! behind the experiment's face, the container's walls by a further r/4 so that no particle
//! starts compressed in a corner (docs/method.md §7), and the fluid lattice fills the
//! reservoir from its faces ([`Setup::scene`]).
//!
//! Submodules hold the setup ([`Setup`]), the measurements ([`Measurements`]), the reference
//! solver's run of the same geometry ([`Reference`]), the comparison ([`compare`]) and the
//! report ([`write_report`]); the run itself is [`simulate`].

mod compare;
mod measured;
mod reference;
mod report;
mod setup;

pub use compare::{
    ARRIVAL_GAUGES, ARRIVAL_LEVEL, Arrival, Comparison, LEE_GAUGE, RESERVOIR_GAUGE,
    RESERVOIR_TIMES, ReferenceComparison, ReservoirLevel, Tolerances, Verdict, compare,
};
pub use measured::{DATA_FILE, Measurements, SOURCE_COLUMNS};
pub use reference::{REFERENCE_FILE, REFERENCE_LABEL, Reference};
pub use report::{ReportFiles, write_report};
pub use setup::{PROBE_RATE, SCENE_NAME, Setup};

use projfluid::Error;

/// Tank length, width and height in the experiment's frame (m).
pub const TANK: [f64; 3] = [3.22, 1.0, 1.0];
/// The reservoir's x range (m): from the gate to the end wall.
pub const RESERVOIR_X: [f64; 2] = [1.992, 3.22];
/// Initial water depth (m).
pub const WATER_DEPTH: f64 = 0.55;
/// The box's lower corner in the experiment's frame (m).
pub const BOX_MIN: [f64; 3] = [0.6635, 0.2985, 0.0];
/// The box's upper corner in the experiment's frame (m); the flow hits the face x = 0.8245.
pub const BOX_MAX: [f64; 3] = [0.8245, 0.7015, 0.161];
/// Gauge names, SPHERIC's numbering from the box end.
pub const GAUGES: [&str; 4] = ["H1", "H2", "H3", "H4"];
/// The gauges' x (m); all stand at y = [`GAUGE_Y`]. H1 is behind the box, H4 in the reservoir.
pub const GAUGE_X: [f64; 4] = [0.496, 0.992, 1.488, 2.638];
/// The gauges' y across the tank (m): the centre line.
pub const GAUGE_Y: f64 = 0.5;

/// The world point of the experiment's point (x, y, z) (m): y and z swap, so that up is +y.
pub fn world_point([x, y, z]: [f64; 3]) -> [f64; 3] {
    [x, z, y]
}

/// One reading of the gauges.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    /// Time since release (s).
    pub time: f64,
    /// Water height at each gauge of [`GAUGES`] (m): the standing water's surface.
    pub heights: [f64; 4],
    /// Water content of each gauge's line (m): the depth all the water on it would have
    /// standing on the floor, falling and flying water included
    /// ([`projfluid::probe::GaugeMeasure::Content`]).
    pub contents: [f64; 4],
}

/// A finished run: the setup and the gauge history.
#[derive(Clone, Debug)]
pub struct Run {
    /// What was run.
    pub setup: Setup,
    /// One reading at t = 0 and one after every step.
    pub samples: Vec<Sample>,
    /// Fluid particles.
    pub particles: usize,
    /// Boundary particles.
    pub boundary_particles: usize,
    /// Fluid particles that left the tank by the end.
    pub escaped: usize,
    /// Steps taken.
    pub steps: usize,
    /// Outer iterations over all steps.
    pub outer_iterations: usize,
    /// Largest compression max(ρ/ρ0 − 1) of any step (dimensionless).
    pub density_error_max: f64,
    /// Largest per-step average compression (dimensionless).
    pub density_error_avg_max: f64,
}

impl Run {
    /// Gauge `g`'s history as (time (s), height (m)).
    pub fn heights(&self, g: usize) -> Vec<(f64, f64)> {
        self.samples
            .iter()
            .map(|s| (s.time, s.heights[g]))
            .collect()
    }

    /// The water content of gauge `g`'s line as (time (s), content (m)).
    pub fn contents(&self, g: usize) -> Vec<(f64, f64)> {
        self.samples
            .iter()
            .map(|s| (s.time, s.contents[g]))
            .collect()
    }

    /// The simulated time covered (s).
    pub fn end(&self) -> f64 {
        self.samples.last().map_or(0.0, |s| s.time)
    }
}

/// Runs the dam break for `setup.duration`, reading the gauges at t = 0 and after every step;
/// `progress` receives the fraction done after each step. Errors on a bad setup, a failed
/// step, or NaN positions.
pub fn simulate(setup: &Setup, mut progress: impl FnMut(f64)) -> Result<Run, Error> {
    let scene = setup.scene();
    let mut world = scene.build_world()?;
    let probes = scene.probes.as_ref().expect("the scene has its gauges");
    let read = |world: &projfluid::World| -> Result<Sample, Error> {
        // The scene's gauges: the four surfaces, then the four contents.
        let reading = probes.read(world)?;
        let (mut heights, mut contents) = ([0.0; 4], [0.0; 4]);
        heights.copy_from_slice(&reading.heights[..4]);
        contents.copy_from_slice(&reading.heights[4..]);
        Ok(Sample {
            time: reading.time,
            heights,
            contents,
        })
    };
    let mut samples = vec![read(&world)?];
    let (mut outer, mut worst, mut worst_avg) = (0, 0.0f64, 0.0f64);
    let steps = world.advance_with(setup.duration, |world| {
        if world.nan_count() > 0 {
            return Err(Error::invalid(
                "simulation",
                format!("t = {:.4} s", world.time()),
                "produced non-finite particle positions",
            ));
        }
        if let Some(s) = world.last_step() {
            outer += s.outer_iterations;
            worst = worst.max(s.density_error_max);
            worst_avg = worst_avg.max(s.density_error_avg);
        }
        samples.push(read(world)?);
        progress(world.time() / setup.duration);
        Ok(())
    })?;
    Ok(Run {
        setup: setup.clone(),
        samples,
        particles: world.fluid_count(),
        boundary_particles: world.boundary_count(),
        escaped: world.escaped_count(),
        steps,
        outer_iterations: outer,
        density_error_max: worst,
        density_error_avg_max: worst_avg,
    })
}
