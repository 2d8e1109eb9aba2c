//! Two immiscible liquids (docs/validation.md, "Two liquids"; docs/method.md §14): a lighter
//! liquid over water at rest, whose pressure must follow the two-slope hydrostatic profile,
//! and water put over the lighter liquid, which must overturn (the Rayleigh–Taylor
//! instability).
//!
//! At rest: a tank n × 1.6n × n particles, the upper half of the lighter liquid, settles with
//! the calm settings (damped relaxation, then a free run); the pressure is then read from the
//! constraint forces (docs/method.md §10.1) as the hydrostatic validation reads it
//! ([`layer_profile`]), averaged over layers one spacing thick away from the side walls.
//!
//! Overturning: a tank 1.2n × 2n × 6 particles, water over the lighter liquid, the interface
//! bent by one cosine across the tank of amplitude 0.2n spacings, runs at the defaults; the
//! two liquids' mean heights are followed until they cross.

mod report;

pub use report::{ReportFiles, write_report};

use super::fit::least_squares_slope;
use super::hydrostatic::{Layer, READING_TOLERANCE_PER_RADIUS, layer_profile};
use projfluid::boundary::Aabb;
use projfluid::{Error, Material, MaterialId, Params, SolverKind, Vec3, World};

/// The runs: resolution, the lighter liquid, durations and solver.
#[derive(Clone, Debug)]
pub struct Setup {
    /// Particles across the tank at rest (x and z); see the module docs for both tanks.
    pub across: usize,
    /// Particle radius r (m).
    pub particle_radius: f64,
    /// Rest density of the lighter liquid (kg/m³); the heavier one is the world's water,
    /// 1000 kg/m³.
    pub light_density: f64,
    /// Damped relaxation of the tank at rest (s) before its free run.
    pub relax: f64,
    /// Free run of the tank at rest (s) before the pressure is read.
    pub settle: f64,
    /// Longest simulated time of the overturning run (s).
    pub overturn_duration: f64,
    /// Global solver.
    pub solver: SolverKind,
    /// Worker threads (0 = one per core).
    pub threads: usize,
}

impl Default for Setup {
    fn default() -> Self {
        Self {
            across: 12,
            particle_radius: 0.025,
            light_density: 800.0,
            relax: 2.0,
            settle: 0.5,
            overturn_duration: 4.0,
            solver: SolverKind::Chebyshev,
            threads: 0,
        }
    }
}

impl Setup {
    /// Checks the setup, naming the field at fault.
    pub fn validate(&self) -> Result<(), Error> {
        if !(6..=40).contains(&self.across) {
            return Err(Error::invalid(
                "resolution",
                self.across,
                "must lie in 6–40",
            ));
        }
        if !(self.light_density.is_finite()
            && self.light_density >= 100.0
            && self.light_density < 1000.0)
        {
            return Err(Error::invalid(
                "light-density",
                self.light_density,
                "must lie in [100, 1000) kg/m³, lighter than the water",
            ));
        }
        for (name, value) in [
            ("relax", self.relax),
            ("settle", self.settle),
            ("duration", self.overturn_duration),
        ] {
            if !(value.is_finite() && (0.0..=20.0).contains(&value)) {
                return Err(Error::invalid(name, value, "must lie in [0, 20] seconds"));
            }
        }
        Ok(())
    }

    /// Fluid particles along x, y and z of the tank at rest.
    pub fn rest_count(&self) -> [usize; 3] {
        [self.across, self.across * 8 / 5, self.across]
    }

    /// Fluid particles along x, y and z of the overturning tank.
    pub fn overturn_count(&self) -> [usize; 3] {
        [self.across * 6 / 5, 2 * self.across, 6]
    }

    fn params(&self) -> Params {
        Params {
            solver: self.solver,
            threads: self.threads,
            ..Params::with_radius(self.particle_radius)
        }
    }
}

/// The tank at rest.
#[derive(Clone, Debug)]
pub struct Rest {
    /// Fluid particles.
    pub particles: usize,
    /// The interface's height as placed (m), and the free surface's: half a spacing above
    /// the highest particle at the reading (m).
    pub interface: f64,
    /// See `interface` (m).
    pub surface: f64,
    /// The lowest particle of the lighter liquid and the highest of the water, as heights
    /// above the interface (m): within two spacings, the layers kept their order.
    pub lowest_light: f64,
    /// See `lowest_light` (m).
    pub highest_water: f64,
    /// The mean density each liquid reads below its surface layers (kg/m³): water, lighter.
    pub densities: (f64, f64),
    /// The layers from the floor up.
    pub layers: Vec<Layer>,
    /// RMS of the layers' pressure minus the two-slope profile, from one support radius above
    /// the floor to one below the surface, over the profile's pressure one support radius
    /// above the floor.
    pub profile_error: f64,
    /// −dp/dy in the water, over ρ_w·g, and in the lighter liquid, over ρ_l·g (least squares
    /// over the layers half a support radius or more from the interface and one from the
    /// floor and the surface).
    pub slopes: (f64, f64),
}

/// The overturning run.
#[derive(Clone, Debug)]
pub struct Overturn {
    /// Fluid particles.
    pub particles: usize,
    /// Time (s), the water's and the lighter liquid's mean heights (m), every 0.05 s.
    pub heights: Vec<(f64, f64, f64)>,
    /// When the water's mean height first fell below the lighter liquid's (s).
    pub overturned_at: Option<f64>,
    /// Particles that left the tank or became NaN.
    pub lost: usize,
}

/// Both runs of a setup.
#[derive(Clone, Debug)]
pub struct Report {
    /// The setup run.
    pub setup: Setup,
    /// The tank at rest.
    pub rest: Rest,
    /// The overturning run.
    pub overturn: Overturn,
}

/// Runs both tanks of `setup`.
pub fn simulate(setup: &Setup) -> Result<Report, Error> {
    setup.validate()?;
    Ok(Report {
        setup: setup.clone(),
        rest: at_rest(setup)?,
        overturn: overturn(setup)?,
    })
}

/// A tank holding the lattice of `count` particles one spacing plus r/4 from its walls,
/// 1.5 times as tall as the fluid, with `params`; the particles for which `light` holds are
/// of the lighter liquid. Returns the world, its box, the lighter liquid's material and the
/// lattice's first height (m).
fn tank(
    setup: &Setup,
    params: Params,
    count: [usize; 3],
    light: impl Fn([usize; 3]) -> bool,
) -> Result<(World, Aabb, MaterialId, f64), Error> {
    let (r, d) = (params.particle_radius, params.spacing());
    let gap = d + 0.25 * r;
    let extent = |c: usize| (c - 1) as f64 * d + 2.0 * gap;
    let mut world = World::new(params)?;
    let tank = Aabb {
        min: Vec3::zeros(),
        max: Vec3::new(extent(count[0]), 1.5 * extent(count[1]), extent(count[2])),
    };
    world.add_container(tank, 1)?;
    let (mut water, mut lighter) = (Vec::new(), Vec::new());
    for k in 0..count[2] {
        for j in 0..count[1] {
            for i in 0..count[0] {
                let p = Vec3::new(i as f64, j as f64, k as f64) * d + Vec3::repeat(gap);
                if light([i, j, k]) {
                    lighter.push(p)
                } else {
                    water.push(p)
                }
            }
        }
    }
    world.add_fluid_particles(&water, None)?;
    let material = world.add_material(Material::with_density(setup.light_density))?;
    world.set_fluid_material(material)?;
    world.add_fluid_particles(&lighter, None)?;
    Ok((world, tank, material, gap))
}

fn at_rest(setup: &Setup) -> Result<Rest, Error> {
    let params = setup.params().calm();
    let (r, d, h) = (
        params.particle_radius,
        params.spacing(),
        params.support_radius(),
    );
    let g = -params.gravity[1];
    let count = setup.rest_count();
    let half = count[1] / 2;
    let (mut world, tank, light, gap) = tank(setup, params, count, |[_, j, _]| j >= half)?;
    let interface = gap + (half as f64 - 0.5) * d;
    world.relax(setup.relax, 4.0)?;
    world.advance(setup.settle)?;

    let (x, materials) = (world.positions(), world.particle_materials());
    let heights_of = |m: MaterialId| {
        x.iter()
            .zip(&materials)
            .filter(move |(_, k)| **k == m)
            .map(|(p, _)| p.y)
    };
    let lowest_light = heights_of(light).fold(f64::MAX, f64::min) - interface;
    let highest_water = heights_of(0).fold(f64::MIN, f64::max) - interface;
    let top = x.iter().map(|p| p.y).fold(f64::MIN, f64::max);
    let densities = world.densities();
    let mean_density = |m: MaterialId| {
        let inner: Vec<f64> = (0..x.len())
            .filter(|&i| materials[i] == m && x[i].y < top - 4.0 * r)
            .map(|i| densities[i])
            .collect();
        inner.iter().sum::<f64>() / inner.len().max(1) as f64
    };

    let surface = top + 0.5 * d;
    let (rho_w, rho_l) = (world.params().rest_density, setup.light_density);
    let hydrostatic = |y: f64| {
        if y > interface {
            rho_l * g * (surface - y)
        } else {
            rho_l * g * (surface - interface) + rho_w * g * (interface - y)
        }
    };
    let tolerance = READING_TOLERANCE_PER_RADIUS * r;
    let layers = layer_profile(&mut world, &tank, tolerance, hydrostatic, |_, _| {})?;
    let within = |low: f64, high: f64| -> Vec<(f64, f64)> {
        layers
            .iter()
            .filter(|l| l.height > low && l.height < high)
            .map(|l| (l.height, l.pressure))
            .collect()
    };
    let inner = within(h, top - h);
    if inner.len() < 4 {
        return Err(Error::invalid(
            "resolution",
            setup.across,
            "leaves too few layers to read the profile",
        ));
    }
    let squares: f64 = inner
        .iter()
        .map(|&(y, p)| (p - hydrostatic(y)).powi(2))
        .sum();
    let profile_error = (squares / inner.len() as f64).sqrt() / hydrostatic(h);
    let slopes = (
        -least_squares_slope(&within(h, interface - 0.5 * h)) / (rho_w * g),
        -least_squares_slope(&within(interface + 0.5 * h, top - h)) / (rho_l * g),
    );
    Ok(Rest {
        particles: world.fluid_count(),
        interface,
        surface,
        lowest_light,
        highest_water,
        densities: (mean_density(0), mean_density(light)),
        layers,
        profile_error,
        slopes,
    })
}

fn overturn(setup: &Setup) -> Result<Overturn, Error> {
    let count = setup.overturn_count();
    let (half, amplitude) = ((count[1] / 2) as f64, 0.2 * setup.across as f64);
    let bend = |i: usize| (std::f64::consts::PI * i as f64 / (count[0] - 1) as f64).cos();
    let (mut world, _, light, _) = tank(setup, setup.params(), count, |[i, j, _]| {
        (j as f64) < half - amplitude * bend(i)
    })?;
    let mean_heights = |world: &World| {
        let (x, m) = (world.positions(), world.particle_materials());
        let mut sums = [(0.0, 0usize); 2];
        for (p, k) in x.iter().zip(&m) {
            let s = &mut sums[usize::from(*k == light)];
            *s = (s.0 + p.y, s.1 + 1);
        }
        (sums[0].0 / sums[0].1 as f64, sums[1].0 / sums[1].1 as f64)
    };
    let (water, lighter) = mean_heights(&world);
    let mut heights = vec![(0.0, water, lighter)];
    let mut overturned_at = None;
    while world.time() < setup.overturn_duration - 1e-9 {
        world.advance(0.05)?;
        let (water, lighter) = mean_heights(&world);
        heights.push((world.time(), water, lighter));
        if water < lighter && overturned_at.is_none() {
            overturned_at = Some(world.time());
        }
    }
    Ok(Overturn {
        particles: world.fluid_count(),
        heights,
        overturned_at,
        lost: world.escaped_count() + world.nan_count(),
    })
}
