//! Viscous flow down a duct against its analytic solution (docs/validation.md, "Flow down
//! a duct"). A column of fluid fills the cross-section of a tall vertical duct of
//! rectangular section and falls, held back by the friction of the no-slip walls alone: its
//! free ends keep the pressure at zero, so the weight ρg drives the flow as a pressure
//! gradient drives Poiseuille flow. Within a few viscous times the speed across the section
//! takes the duct's Poiseuille profile, whatever the column's length.

mod report;

pub use report::{ReportFiles, write_report};

use projfluid::boundary::Aabb;
use projfluid::{Error, Params, SolverKind, Vec3, World};

/// The run: duct, fluid, viscosities and solver.
#[derive(Clone, Debug)]
pub struct Setup {
    /// Kinematic viscosities ν to run (m²/s), one run each.
    pub viscosities: Vec<f64>,
    /// Particles across the duct's narrow side (x); its wide side (z) holds 3/2 as many and
    /// the column is twice as long as the narrow side is wide.
    pub across: usize,
    /// Particle radius r (m).
    pub particle_radius: f64,
    /// Simulated time per run (s).
    pub duration: f64,
    /// Global solver.
    pub solver: SolverKind,
    /// Worker threads (0 = one per core).
    pub threads: usize,
}

impl Default for Setup {
    fn default() -> Self {
        Self {
            viscosities: vec![1e-2, 1e-1],
            across: 16,
            particle_radius: 0.00125,
            duration: 0.1,
            solver: SolverKind::Chebyshev,
            threads: 0,
        }
    }
}

impl Setup {
    /// Checks the setup, naming the field at fault.
    pub fn validate(&self) -> Result<(), Error> {
        if self.viscosities.is_empty() {
            return Err(Error::invalid("viscosity", "none", "give at least one"));
        }
        if let Some(nu) = self
            .viscosities
            .iter()
            .find(|nu| !(nu.is_finite() && **nu > 0.0))
        {
            return Err(Error::invalid("viscosity", nu, "must be positive (m²/s)"));
        }
        if !(4..=64).contains(&self.across) {
            return Err(Error::invalid(
                "resolution",
                self.across,
                "must lie in 4–64",
            ));
        }
        if !(self.duration.is_finite() && self.duration > 0.0 && self.duration <= 10.0) {
            return Err(Error::invalid(
                "duration",
                self.duration,
                "must lie in (0, 10] seconds",
            ));
        }
        Ok(())
    }

    /// Fluid particles along x, y and z.
    pub fn count(&self) -> [usize; 3] {
        [self.across, 2 * self.across, self.across * 3 / 2]
    }
}

/// One viscosity's result.
#[derive(Clone, Debug)]
pub struct Run {
    /// ν (m²/s).
    pub viscosity: f64,
    /// Particles compared (the middle third of the column's length).
    pub compared: usize,
    /// RMS over the compared particles of simulated minus analytic speed, over the largest
    /// analytic speed (dimensionless).
    pub error: f64,
    /// The largest analytic speed (m/s).
    pub peak: f64,
    /// Mean simulated over mean analytic speed of the compared particles.
    pub flux_ratio: f64,
    /// The profile across the narrow side at mid-depth: x from the duct's axis (m),
    /// simulated and analytic mean speeds (m/s) of the particles in each layer.
    pub profile: Vec<(f64, f64, f64)>,
    /// Steps taken.
    pub steps: usize,
}

/// Every run of a setup.
#[derive(Clone, Debug)]
pub struct Report {
    /// The setup run.
    pub setup: Setup,
    /// Fluid particles per run.
    pub particles: usize,
    /// One per viscosity, in the setup's order.
    pub runs: Vec<Run>,
}

/// Fully developed downward speed (m/s) of flow driven by the weight (gravity `g`, m/s²)
/// down a duct of section [−a, a] × [−b, b] (m) with no-slip walls, for kinematic viscosity
/// `nu` (m²/s), at (x, z) from the duct's axis (m): the Fourier series of Poiseuille flow in
/// a rectangle.
pub fn duct_speed(g: f64, nu: f64, a: f64, b: f64, x: f64, z: f64) -> f64 {
    let pi = std::f64::consts::PI;
    let mut sum = 0.0;
    for k in 0..200 {
        let n = (2 * k + 1) as f64;
        let sign = if k % 2 == 0 { 1.0 } else { -1.0 };
        let m = n * pi / (2.0 * a);
        // cosh(mz)/cosh(mb), written so that it does not overflow for large m.
        let decay =
            ((m * (z.abs() - b)).exp() + (-m * (z.abs() + b)).exp()) / (1.0 + (-2.0 * m * b).exp());
        sum += sign / n.powi(3) * (1.0 - decay) * (m * x).cos();
    }
    16.0 * a * a * g / (nu * pi.powi(3)) * sum
}

/// Runs every viscosity of `setup`, calling `progress` with each finished run.
pub fn simulate(setup: &Setup, mut progress: impl FnMut(&Run)) -> Result<Report, Error> {
    setup.validate()?;
    let mut runs = Vec::new();
    let mut particles = 0;
    for &nu in &setup.viscosities {
        let (run, n) = simulate_one(setup, nu)?;
        progress(&run);
        runs.push(run);
        particles = n;
    }
    Ok(Report {
        setup: setup.clone(),
        particles,
        runs,
    })
}

fn simulate_one(setup: &Setup, nu: f64) -> Result<(Run, usize), Error> {
    let params = Params {
        kinematic_viscosity: nu,
        solver: setup.solver,
        threads: setup.threads,
        ..Params::with_radius(setup.particle_radius)
    };
    let (r, d) = (params.particle_radius, params.spacing());
    let g = -params.gravity[1];
    let n = setup.count();
    let width = |count: usize| count as f64 * d;
    // The walls' particle planes lie r/4 beyond the fluid's extent (the cube of edge d each
    // particle stands for), as in the built-in scenes; the duct is long enough for the
    // column to fall for the whole run.
    let gap = 0.25 * r;
    let fall = 0.6 * g * setup.duration * setup.duration + width(n[1]);
    let length = width(n[1]) + fall + 8.0 * d;
    let mut world = World::new(params)?;
    world.add_container(
        Aabb {
            min: Vec3::new(-gap, 0.0, -gap),
            max: Vec3::new(width(n[0]) + gap, length, width(n[2]) + gap),
        },
        1,
    )?;
    let top = length - width(n[1]) - 4.0 * d;
    world.add_fluid_block(Vec3::new(r, top, r), n, Vec3::zeros())?;
    let mut steps = 0;
    while world.time() < setup.duration {
        world.step()?;
        steps += 1;
    }
    let (x, v) = (world.positions(), world.velocities());
    let (a, b) = (width(n[0]) / 2.0, width(n[2]) / 2.0);
    let (low, high) = x
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), p| {
            (l.min(p.y), h.max(p.y))
        });
    let third = (high - low) / 3.0;
    let mut layers = vec![(0.0, 0.0, 0usize); n[0]];
    let (mut squares, mut simulated, mut exact_sum, mut compared, mut peak) =
        (0.0, 0.0, 0.0, 0, 0.0f64);
    for (p, v) in x.iter().zip(&v) {
        if p.y < low + third || p.y > high - third {
            continue;
        }
        let exact = duct_speed(g, nu, a, b, p.x - a, p.z - b);
        let speed = -v.y;
        peak = peak.max(exact);
        squares += (speed - exact).powi(2);
        simulated += speed;
        exact_sum += exact;
        compared += 1;
        if (p.z - b).abs() <= d {
            let k = ((p.x / d).max(0.0) as usize).min(n[0] - 1);
            layers[k].0 += speed;
            layers[k].1 += exact;
            layers[k].2 += 1;
        }
    }
    if compared == 0 || peak <= 0.0 {
        return Err(Error::invalid(
            "duration",
            setup.duration,
            "let the column leave the duct",
        ));
    }
    let profile = layers
        .iter()
        .enumerate()
        .filter(|(_, l)| l.2 > 0)
        .map(|(k, l)| {
            let centre = (k as f64 + 0.5) * d - a;
            (centre, l.0 / l.2 as f64, l.1 / l.2 as f64)
        })
        .collect();
    let run = Run {
        viscosity: nu,
        compared,
        error: (squares / compared as f64).sqrt() / peak,
        peak,
        flux_ratio: simulated / exact_sum,
        profile,
        steps,
    };
    Ok((run, world.fluid_count()))
}
