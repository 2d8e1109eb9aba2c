//! The dam break's setup: resolution, duration, gravity, the obstacle, viscosity and solver,
//! and the scene they make (the shipped `scenes/kleefsman_obstacle.json` is the default one).

use super::{
    BOX_MAX, BOX_MIN, GAUGE_X, GAUGE_Y, GAUGES, RESERVOIR_X, TANK, WATER_DEPTH, world_point,
};
use projfluid::body::Shape;
use projfluid::boundary::Transform;
use projfluid::probe::{Gauge, GaugeMeasure, ProbeSet};
use projfluid::scene::{
    ContainerSpec, ContainerWalls, FluidBlock, MeshSource, ObstacleSpec, OutputSpec, Scene,
};
use projfluid::{Error, Params, SolverKind, Vec3};

/// Name of the default scene, shipped as `scenes/kleefsman_obstacle.json`.
pub const SCENE_NAME: &str = "kleefsman_obstacle";

/// Gauge readings per simulated second in the scene's `probes` (1/s): the measurements' rate.
pub const PROBE_RATE: f64 = 100.0;

/// How the dam break is set up and how long it runs.
#[derive(Clone, Debug, PartialEq)]
pub struct Setup {
    /// Particle radius r (m); the lattice spacing is d = 2r.
    pub particle_radius: f64,
    /// Simulated time (s).
    pub duration: f64,
    /// Whether the box stands in the tank (the experiment) or not (a check that the
    /// comparison sees it).
    pub obstacle: bool,
    /// Magnitude of gravity g (m/s²), along −y.
    pub gravity: f64,
    /// XSPH viscosity coefficient c_X (dimensionless, [0, 1]).
    pub viscosity: f64,
    /// Outer stopping threshold τ (m); `None` for the default 3·10⁻³·r.
    pub tolerance: Option<f64>,
    /// Global solver.
    pub solver: SolverKind,
    /// Worker threads (0 = one per core).
    pub threads: usize,
    /// What the tank's walls are (default: particles, as in scenes).
    pub walls: ContainerWalls,
    /// Whether the outer iteration starts from the coarse correction (docs/method.md §3.8;
    /// off, as by default).
    pub coarse_correction: bool,
}

impl Default for Setup {
    /// r = 12.5 mm (d = 25 mm: 22 particles over the depth, 43,120 in all), 2 s, the box,
    /// g = 9.81 m/s², and the library's defaults for everything else.
    fn default() -> Self {
        let defaults = Params::default();
        Self {
            particle_radius: 0.0125,
            duration: 2.0,
            obstacle: true,
            gravity: 9.81,
            viscosity: defaults.viscosity,
            tolerance: None,
            solver: defaults.solver,
            threads: 0,
            walls: ContainerWalls::Particles,
            coarse_correction: defaults.coarse_correction,
        }
    }
}

impl Setup {
    /// Checks every field; the error names the bad one (`radius`, `duration`, `gravity`,
    /// `viscosity`, `tau`).
    pub fn validate(&self) -> Result<(), Error> {
        let r = self.particle_radius;
        if !(r.is_finite() && (0.004..=0.05).contains(&r)) {
            return Err(Error::invalid(
                "radius",
                r,
                "must lie between 0.004 and 0.05 m",
            ));
        }
        if !(self.duration.is_finite() && self.duration > 0.0 && self.duration <= 10.0) {
            return Err(Error::invalid(
                "duration",
                self.duration,
                "must lie in (0, 10] seconds",
            ));
        }
        if !(self.gravity.is_finite() && self.gravity > 0.0 && self.gravity <= 100.0) {
            return Err(Error::invalid(
                "gravity",
                self.gravity,
                "must lie in (0, 100] m/s²",
            ));
        }
        if !(self.viscosity.is_finite() && (0.0..=1.0).contains(&self.viscosity)) {
            return Err(Error::invalid(
                "viscosity",
                self.viscosity,
                "must lie in [0, 1]",
            ));
        }
        if let Some(tau) = self.tolerance.filter(|t| !(t.is_finite() && *t > 0.0)) {
            return Err(Error::invalid(
                "tau",
                tau,
                "must be a positive finite number of metres",
            ));
        }
        Ok(())
    }

    /// Lattice spacing d = 2r (m).
    pub fn spacing(&self) -> f64 {
        2.0 * self.particle_radius
    }

    /// Fluid particles along the reservoir's length, depth and width (the world's x, y and z):
    /// the nearest whole numbers of spacings, the width's rounded down so that the block fits
    /// between the walls.
    pub fn fluid_count(&self) -> [usize; 3] {
        let d = self.spacing();
        let length = ((RESERVOIR_X[1] - RESERVOIR_X[0]) / d).round().max(1.0);
        let depth = (WATER_DEPTH / d).round().max(1.0);
        let width = (TANK[1] / d + 1e-9).floor().max(1.0);
        [length as usize, depth as usize, width as usize]
    }

    /// The scene, in the world frame ([`world_point`]). Every solid face of the experiment
    /// has its particles r behind it (the water ends r in front of a particle plane), the
    /// container's r/4 further still (docs/method.md §7); the fluid lattice starts with its
    /// particles' cubes flush with the floor, the end wall and the gate, centred across the
    /// tank. Gauges stand on the experiment's floor (y = 0), a quarter radius above the
    /// floor's particles.
    pub fn scene(&self) -> Scene {
        let r = self.particle_radius;
        let d = self.spacing();
        let defaults = Params::with_radius(r);
        let params = Params {
            gravity: [0.0, -self.gravity, 0.0],
            viscosity: self.viscosity,
            displacement_tolerance: self.tolerance.unwrap_or(defaults.displacement_tolerance),
            solver: self.solver,
            threads: self.threads,
            coarse_correction: self.coarse_correction,
            ..defaults
        };
        let wall = tidy(1.25 * r);
        let container = ContainerSpec {
            min: [-wall; 3],
            max: world_point(TANK.map(|l| tidy(l + wall))),
            walls: self.walls,
            layers: 1,
            spacing: None,
        };
        // World frame: length along x, depth along y, width along z.
        let [nx, ny, nz] = self.fluid_count();
        let fluid = FluidBlock {
            start: [
                RESERVOIR_X[1] - r - (nx - 1) as f64 * d,
                r,
                0.5 * TANK[1] - 0.5 * (nz - 1) as f64 * d,
            ]
            .map(tidy),
            count: [nx, ny, nz],
            velocity: [0.0; 3],
            material: None,
        };
        let obstacles = if self.obstacle {
            // The sampled box: r inside every face the water meets, its bottom on the floor's
            // particle plane.
            let min = [BOX_MIN[0] + r, BOX_MIN[1] + r, -wall];
            let max = [BOX_MAX[0] - r, BOX_MAX[1] - r, BOX_MAX[2] - r];
            let centre: [f64; 3] = std::array::from_fn(|a| tidy(0.5 * (min[a] + max[a])));
            let half: [f64; 3] = std::array::from_fn(|a| tidy(0.5 * (max[a] - min[a])));
            vec![ObstacleSpec {
                mesh: MeshSource::Primitive(Shape::Box {
                    half_extents: Vec3::from(world_point(half)),
                }),
                transform: Transform {
                    translate: world_point(centre),
                    ..Transform::default()
                },
            }]
        } else {
            Vec::new()
        };
        // The surface at every gauge, then the water content of the same lines.
        let gauge = |name: &str, x: f64, measure: GaugeMeasure| {
            let [x, _, z] = world_point([x, GAUGE_Y, 0.0]);
            Gauge {
                bottom: Some(0.0),
                measure,
                ..Gauge::new(name, x, z)
            }
        };
        let surfaces =
            (GAUGES.iter().zip(GAUGE_X)).map(|(name, x)| gauge(name, x, GaugeMeasure::Surface));
        let contents = (GAUGES.iter().zip(GAUGE_X))
            .map(|(name, x)| gauge(&format!("{name}_content"), x, GaugeMeasure::Content));
        let gauges = surfaces.chain(contents).collect();
        Scene {
            name: SCENE_NAME.to_string(),
            description: format!(
                "The MARIN dam break with a box (Kleefsman et al. 2005, SPHERIC Test 2): a \
                 1.228 m long, 0.55 m deep reservoir released in a 3.22 x 1 x 1 m tank, past \
                 a 0.161 x 0.403 x 0.161 m box. y is up (the experiment's z), z across. Solid \
                 faces lie r in front of their particles; gauges H1-H4 as in the experiment. \
                 Compared with the measurements by `projfluid validate kleefsman` \
                 (docs/validation.md). r = {r} m, {} particles.",
                nx * ny * nz
            ),
            params,
            containers: vec![container],
            obstacles,
            bodies: Vec::new(),
            materials: Vec::new(),
            fluid_blocks: vec![fluid],
            emitters: Vec::new(),
            sinks: Vec::new(),
            domain: None,
            duration: self.duration,
            output: OutputSpec::default(),
            probes: Some(ProbeSet {
                rate: PROBE_RATE,
                gauges,
                pressure: Vec::new(),
            }),
        }
    }
}

/// `x` (m) rounded to 0.1 µm, so that the scene file reads `0.068`, not
/// `0.06800000000000006`.
fn tidy(x: f64) -> f64 {
    (x * 1e7).round() / 1e7
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_scene_holds_the_reservoir_and_the_box() {
        let setup = Setup::default();
        assert_eq!(setup.fluid_count(), [49, 22, 40]);
        let scene = setup.scene();
        scene.validate().unwrap();
        assert!(!scene.params.coarse_correction);
        let corrected = Setup {
            coarse_correction: true,
            ..Setup::default()
        };
        assert!(corrected.scene().params.coarse_correction);
        let block = &scene.fluid_blocks[0];
        // World frame: x along, y up (22 particles over the depth), z across (40).
        assert_eq!(block.count, [49, 22, 40]);
        let (r, d) = (0.0125, 0.025);
        assert!((block.start[1] - r).abs() < 1e-12);
        let last_x = block.start[0] + 48.0 * d;
        assert!((last_x - (3.22 - r)).abs() < 1e-12);
        let c = &scene.containers[0];
        // Every fluid centre at least d + r/4 from the container's particle planes.
        for a in 0..3 {
            let hi = block.start[a] + (block.count[a] - 1) as f64 * d;
            assert!(
                block.start[a] - c.min[a] >= d + 0.25 * r - 1e-12,
                "axis {a}"
            );
            assert!(c.max[a] - hi >= d + 0.25 * r - 1e-12 || a == 1, "axis {a}");
        }
        assert_eq!(scene.obstacles.len(), 1);
        let probes = scene.probes.as_ref().unwrap();
        // The four surfaces, then the water content of the same four lines.
        assert_eq!(probes.gauges.len(), 8);
        assert_eq!((probes.gauges[0].x, probes.gauges[0].z), (0.496, 0.5));
        for (surface, content) in probes.gauges[..4].iter().zip(&probes.gauges[4..]) {
            assert_eq!(
                (surface.measure, content.measure),
                (GaugeMeasure::Surface, GaugeMeasure::Content)
            );
            assert_eq!((surface.x, surface.z), (content.x, content.z));
            assert_eq!(content.name, format!("{}_content", surface.name));
        }
        let without = Setup {
            obstacle: false,
            ..Setup::default()
        };
        assert!(without.scene().obstacles.is_empty());
    }

    #[test]
    fn bad_setups_are_rejected_naming_the_field() {
        let cases = [
            (
                "radius",
                Setup {
                    particle_radius: 0.001,
                    ..Setup::default()
                },
            ),
            (
                "duration",
                Setup {
                    duration: f64::NAN,
                    ..Setup::default()
                },
            ),
            (
                "gravity",
                Setup {
                    gravity: -1.0,
                    ..Setup::default()
                },
            ),
            (
                "viscosity",
                Setup {
                    viscosity: 2.0,
                    ..Setup::default()
                },
            ),
            (
                "tau",
                Setup {
                    tolerance: Some(0.0),
                    ..Setup::default()
                },
            ),
        ];
        for (field, setup) in cases {
            match setup.validate() {
                Err(Error::InvalidArgument { field: f, .. }) => assert_eq!(f, field),
                other => panic!("{field}: {other:?}"),
            }
        }
        Setup::default().validate().unwrap();
    }
}
