//! The tank's setup: lattice, radius, relaxation, free settling, solver settings, and the
//! world they build.

use projfluid::boundary::Aabb;
use projfluid::scene::ContainerWalls;
use projfluid::{Error, Params, SolverKind, Vec3, World};

/// How the tank is set up, how it is brought to its equilibrium and how long it then runs
/// freely.
#[derive(Clone, Debug, PartialEq)]
pub struct Setup {
    /// Fluid lattice (x, y, z) in particles; y is up.
    pub count: [usize; 3],
    /// Particle radius r (m).
    pub particle_radius: f64,
    /// Relaxation time (s): the lattice is stepped this long with damped velocities
    /// ([`World::relax`]) to find its equilibrium packing; 0 releases the lattice as built.
    pub relax: f64,
    /// Velocity damping rate of the relaxation (1/s).
    pub damping: f64,
    /// Free settling time after the relaxation (s): the measured part of the run.
    pub settle: f64,
    /// Global solver.
    pub solver: SolverKind,
    /// Use the calm settings ([`Params::calm`]) rather than the defaults.
    pub calm: bool,
    /// Outer stopping threshold τ (m); `None` for that of the settings chosen by `calm`.
    pub tolerance: Option<f64>,
    /// τ of the pressure reading (m); `None` for
    /// [`READING_TOLERANCE_PER_RADIUS`](super::READING_TOLERANCE_PER_RADIUS)·r.
    pub reading_tolerance: Option<f64>,
    /// Worker threads (0 = one per core).
    pub threads: usize,
    /// What the tank's walls are (default: particles, as in scenes).
    pub walls: ContainerWalls,
}

impl Default for Setup {
    /// 12 × 16 × 12 particles of radius 0.025 m with the calm settings, relaxed for 10 s at
    /// 4/s (every velocity scaled by ≈ 0.98 per 5 ms step), then settling freely for 2 s.
    fn default() -> Self {
        Self {
            count: [12, 16, 12],
            particle_radius: projfluid::params::DEFAULT_PARTICLE_RADIUS,
            relax: 10.0,
            damping: 4.0,
            settle: 2.0,
            solver: SolverKind::Chebyshev,
            calm: true,
            tolerance: None,
            reading_tolerance: None,
            threads: 0,
            walls: ContainerWalls::Particles,
        }
    }
}

impl Setup {
    /// Checks every field; the error names the bad one.
    pub fn validate(&self) -> Result<(), Error> {
        if self.count.iter().any(|&c| !(2..=100).contains(&c)) {
            let c = format!("{:?}", self.count);
            return Err(Error::invalid(
                "count",
                c,
                "must lie between 2 and 100 per axis",
            ));
        }
        if !(self.settle.is_finite() && self.settle > 0.0 && self.settle <= 60.0) {
            return Err(Error::invalid(
                "settle",
                self.settle,
                "must lie in (0, 60] seconds",
            ));
        }
        if !(self.relax.is_finite() && (0.0..=60.0).contains(&self.relax)) {
            return Err(Error::invalid(
                "relax",
                self.relax,
                "must lie in [0, 60] seconds",
            ));
        }
        if !(self.damping.is_finite() && self.damping >= 0.0) {
            return Err(Error::invalid(
                "damping",
                self.damping,
                "must be a non-negative finite rate (1/s)",
            ));
        }
        for (name, tau) in [
            ("tau", self.tolerance),
            ("reading-tau", self.reading_tolerance),
        ] {
            if let Some(tau) = tau.filter(|t| !(t.is_finite() && *t > 0.0)) {
                return Err(Error::invalid(
                    name,
                    tau,
                    "must be a positive finite number of metres",
                ));
            }
        }
        Ok(())
    }

    /// The tank at t = 0: the block at rest density (the default mass factor) with its centres one
    /// spacing plus r/4 from the walls, and a lid well above it.
    pub fn build(&self) -> Result<(World, Aabb), Error> {
        self.validate()?;
        let mut defaults = Params::with_radius(self.particle_radius);
        if self.calm {
            defaults = defaults.calm();
        }
        let params = Params {
            solver: self.solver,
            threads: self.threads,
            displacement_tolerance: self.tolerance.unwrap_or(defaults.displacement_tolerance),
            ..defaults
        };
        let (r, d) = (params.particle_radius, params.spacing());
        let mut world = World::new(params)?;
        let gap = d + 0.25 * r;
        let extent = |c: usize| (c - 1) as f64 * d + 2.0 * gap;
        let tank = Aabb {
            min: Vec3::zeros(),
            max: Vec3::new(
                extent(self.count[0]),
                1.5 * extent(self.count[1]),
                extent(self.count[2]),
            ),
        };
        world.add_container_with(tank, self.walls)?;
        world.add_fluid_block(Vec3::repeat(gap), self.count, Vec3::zeros())?;
        Ok((world, tank))
    }
}
