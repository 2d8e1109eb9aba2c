//! A closed tank of water left to settle: compression, residual motion, water height against
//! N·V/area, and the pressure profile against ρ0·g·(H − y) (docs/method.md §10.1).
//!
//! Pressure. The density constraint has no pressure field, but its multiplier has the role of
//! one. The force constraint i exerts on neighbour j at the converged iterate is
//! f_ij = k·(P_ij − x_j) = k·λ_i·w_j·∇_{x_j}C_i = −k·λ_i·w_j·(m/ρ0)·∇W(x_i − x_j)
//! (from M(x − s)/Δt² = k·Σ_i (P_i − x), the global step at its fixed point). The symmetric SPH
//! pressure force particle i's pressure p_i exerts on j is m²·(p_i/ρ0²)·∇W(x_i − x_j). Equating
//! the two gives p_i = −k·λ_i·w_j/V with V = m/ρ0; with w_j ≈ w_i = n_i + 1 this is the
//! per-particle estimate p_i = −k·λ_i·(n_i + 1)/V used here, λ_i = −C_i/(|∇C_i|² + ε) being the
//! local step's multiplier at the final positions. It is a reading of the constraint forces
//! (their magnitude is set by the force balance, not by an equation of state), so it measures
//! whether the constraints carry the weight of the water the way a pressure field would.
//!
//! Reading forces from positions needs a tighter solve than moving the water does. An iterate
//! δ from the fixed point changes the global step's force on a particle by about
//! (m + Δt²·k·w)·δ/Δt², at Δt = 5 ms and w = c = 33.5 about 1.4 times its weight per
//! micrometre, so the τ = 3·10⁻⁴·r (7.5 µm) that keeps the tank at rest leaves the mean
//! vertical constraint force at 1.3–1.9 times the weight. The
//! pressure is therefore read over [`READING_WINDOW`] more seconds solved to
//! [`READING_TOLERANCE_PER_RADIUS`]·r, after the motion and density have been measured.
//!
//! Submodules hold the setup ([`Setup`]) and the report ([`Report::text`], [`write_report`]);
//! the tank runs and is measured in [`simulate`].

mod report;
mod setup;

pub use report::{ReportFiles, write_report};
pub use setup::Setup;

use super::fit::{correlation, least_squares_slope};
use projfluid::boundary::Aabb;
use projfluid::pressure::ConstraintPressures;
use projfluid::{Error, Vec3, World};

/// Length of the pressure reading after the free run (s).
pub const READING_WINDOW: f64 = 0.25;
/// τ of the pressure reading as a multiple of the particle radius: the force balance is
/// within 3 % of the weight at 1e-5, 14 % off at 3e-5 (docs/validation.md).
pub const READING_TOLERANCE_PER_RADIUS: f64 = 1e-5;

/// Mean estimated pressure of the particles in one horizontal layer of thickness d, over the
/// steps of a reading ([`layer_profile`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Layer {
    /// Mean height of the layer's particles above the floor plane (m).
    pub height: f64,
    /// Mean pressure estimate of its particles (Pa).
    pub pressure: f64,
    /// The hydrostatic pressure at the layer's mean height (Pa): ρ0·g·(H − y) for one liquid.
    pub hydrostatic: f64,
    /// Particle samples averaged (particles times steps).
    pub particles: usize,
}

/// What the settled tank shows.
#[derive(Clone, Debug)]
pub struct Report {
    /// What was run.
    pub setup: Setup,
    /// Fluid particles.
    pub particles: usize,
    /// Lattice spacing d (m).
    pub spacing: f64,
    /// Average compression of the free run's last step (dimensionless).
    pub density_error_avg: f64,
    /// Largest compression of the free run's last step (dimensionless).
    pub density_error_max: f64,
    /// Largest per-step average compression over the free settling (dimensionless).
    pub density_error_avg_worst: f64,
    /// RMS speed at the end of the free run (m/s).
    pub rms_velocity: f64,
    /// Water height H above the floor plane: the mean top-layer centre plus d/2, less the
    /// d/2 between the floor plane and the water's bottom face (m).
    pub height: f64,
    /// N·V/area with V = m/ρ0 and the area the water covers, (L_x − d)(L_z − d) (m).
    pub expected_height: f64,
    /// Fluid particles outside the tank or non-finite.
    pub escaped: usize,
    /// Outer stopping threshold τ of the pressure reading (m).
    pub reading_tolerance: f64,
    /// (height above the floor plane (m), pressure estimate (Pa)) of every particle after the
    /// last step.
    pub pressures: Vec<(f64, f64)>,
    /// Layer means over particles at least one support radius from the side walls, averaged
    /// over the steps of the reading window.
    pub profile: Vec<Layer>,
    /// Least-squares slope −dp/dy of the layer means at least one support radius from the
    /// surface and the floor, where particle pressures under-read (Pa/m); ρ0·g for a
    /// hydrostatic column.
    pub slope: f64,
    /// ρ0·g (Pa/m).
    pub hydrostatic_slope: f64,
    /// Pearson correlation of the layer means with ρ0·g·(H − y) over the same layers: the
    /// shape of the profile, whatever its scale (1 for a linear profile).
    pub shape_correlation: f64,
    /// Mean vertical constraint force per particle, Σ_i k·(P_ij − x_j), evaluated at the end of
    /// each step of the reading window, over the particle weight m·g: 1 when the constraints
    /// are at the fixed point that holds the water up, larger when the outer iteration stopped
    /// short of it.
    pub force_balance: f64,
}

/// The water height in `tank` (m) and the height its volume N·V (V = m/ρ0) implies.
///
/// Wall particles keep fluid centres one spacing d from the wall planes and each particle owns
/// a cube of edge d, so the fluid body ends d/2 from every wall: it fills (L_x − d)(L_z − d)
/// and starts d/2 above the floor. The measured top is the mean height of the particles within
/// d/2 of the highest one, plus d/2.
pub fn water_height(world: &World, tank: &Aabb) -> (f64, f64) {
    let d = world.params().spacing();
    let positions = world.positions();
    let top = positions.iter().map(|p| p.y).fold(f64::MIN, f64::max);
    let surface: Vec<f64> = positions
        .iter()
        .map(|p| p.y)
        .filter(|&y| y > top - 0.5 * d)
        .collect();
    let surface_y = surface.iter().sum::<f64>() / surface.len().max(1) as f64 + 0.5 * d;
    let height = surface_y - (tank.min.y + 0.5 * d);
    let volume = world.fluid_count() as f64 * world.particle_mass() / world.params().rest_density;
    let size = tank.max - tank.min;
    (height, volume / ((size.x - d) * (size.z - d)))
}

/// Relaxes the tank for `setup.relax` seconds, lets it settle freely for `setup.settle`
/// seconds and measures it, then reads the pressure over [`READING_WINDOW`] more seconds
/// solved to `setup.reading_tolerance`; `progress` receives the fraction done as the run goes.
pub fn simulate(setup: &Setup, mut progress: impl FnMut(f64)) -> Result<Report, Error> {
    let (mut world, tank) = setup.build()?;
    let end = setup.relax + setup.settle + READING_WINDOW;
    // The relaxation in slices of at most a quarter second, for the progress report, to
    // within dt_min (the shortest span a world advances by).
    while setup.relax - world.time() >= world.params().dt_min {
        world.relax((setup.relax - world.time()).min(0.25), setup.damping)?;
        progress(world.time() / end);
    }
    let mut worst: f64 = 0.0;
    world.advance_with(setup.settle, |w| {
        worst = worst.max(w.last_step().map_or(0.0, |s| s.density_error_avg));
        progress(w.time() / end);
        Ok(())
    })?;
    let (density_error_avg, density_error_max) = world
        .last_step()
        .map_or((0.0, 0.0), |s| (s.density_error_avg, s.density_error_max));
    let rms_velocity = world.rms_velocity();
    let (height, expected_height) = water_height(&world, &tank);
    let escaped = world.escaped_count() + world.nan_count();

    let d = world.params().spacing();
    let h_support = world.params().support_radius();
    let reading_tolerance = setup
        .reading_tolerance
        .unwrap_or(READING_TOLERANCE_PER_RADIUS * setup.particle_radius);
    // The water's top face is the pressure datum: H above the floor plane is height + d/2.
    let datum = height + 0.5 * d;
    let (rho0, g) = (
        world.params().rest_density,
        Vec3::from(world.params().gravity).norm(),
    );
    let (mut support_sum, mut sampled_steps) = (0.0, 0usize);
    let mut estimates = Vec::new();
    let hydrostatic = |y: f64| rho0 * g * (datum - y);
    let profile = layer_profile(&mut world, &tank, reading_tolerance, hydrostatic, |w, p| {
        estimates.clone_from(&p.samples);
        support_sum += p.mean_vertical_force;
        sampled_steps += 1;
        progress(w.time() / end);
    })?;
    let floor = tank.min.y;
    let pressures: Vec<(f64, f64)> = estimates.iter().map(|(p, v)| (p.y - floor, *v)).collect();
    let support = support_sum / sampled_steps.max(1) as f64;
    let fitted: Vec<(f64, f64)> = profile
        .iter()
        .filter(|l| l.height >= h_support && l.height <= datum - h_support)
        .map(|l| (l.height, l.pressure))
        .collect();
    let shape: Vec<(f64, f64)> = profile
        .iter()
        .filter(|l| l.height >= h_support && l.height <= datum - h_support)
        .map(|l| (l.pressure, l.hydrostatic))
        .collect();
    Ok(Report {
        setup: setup.clone(),
        particles: world.fluid_count(),
        spacing: d,
        density_error_avg,
        density_error_max,
        density_error_avg_worst: worst,
        rms_velocity,
        height,
        expected_height,
        escaped,
        reading_tolerance,
        pressures,
        profile,
        slope: -least_squares_slope(&fitted),
        shape_correlation: correlation(&shape),
        hydrostatic_slope: rho0 * g,
        force_balance: support / (world.particle_mass() * g),
    })
}

/// Reads the constraint pressure (docs/method.md §10.1) of `world` over [`READING_WINDOW`] more
/// seconds, each step solved to the displacement tolerance `tolerance` (m) alone, and averages
/// it over horizontal layers one spacing thick of the particles at least one support radius
/// from the side walls of `tank`, one step's multipliers being noisy; `hydrostatic` gives the
/// pressure to compare with (Pa) at a height above the floor plane (m), and `each` sees every
/// step's reading. The layers from the floor up.
pub(crate) fn layer_profile(
    world: &mut World,
    tank: &Aabb,
    tolerance: f64,
    hydrostatic: impl Fn(f64) -> f64,
    mut each: impl FnMut(&World, &ConstraintPressures),
) -> Result<Vec<Layer>, Error> {
    let d = world.params().spacing();
    let h = world.params().support_radius();
    // The reading solves the force balance to τ alone: the density rule would end the
    // iteration as soon as the compression is small, long before the forces balance.
    world.set_density_tolerance(0.0)?;
    world.set_displacement_tolerance(tolerance)?;
    let inner = |p: &Vec3| {
        p.x - tank.min.x >= h
            && tank.max.x - p.x >= h
            && p.z - tank.min.z >= h
            && tank.max.z - p.z >= h
    };
    // Layer sums: pressure, height, particles.
    let layers = ((tank.max.y - tank.min.y) / d).ceil() as usize + 1;
    let mut sums = vec![(0.0, 0.0, 0usize); layers];
    world.advance_with(READING_WINDOW, |w| {
        let pressures = w.constraint_pressures();
        for (p, v) in pressures.samples.iter().filter(|(p, _)| inner(p)) {
            let y = p.y - tank.min.y;
            let i = ((y / d).max(0.0) as usize).min(layers - 1);
            sums[i].0 += v;
            sums[i].1 += y;
            sums[i].2 += 1;
        }
        each(w, &pressures);
        Ok(())
    })?;
    Ok(sums
        .iter()
        .filter(|s| s.2 > 0)
        .map(|s| {
            let y = s.1 / s.2 as f64;
            Layer {
                height: y,
                pressure: s.0 / s.2 as f64,
                hydrostatic: hydrostatic(y),
                particles: s.2,
            }
        })
        .collect())
}
