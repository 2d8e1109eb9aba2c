//! A drop's capillary oscillation against Rayleigh's (1879) frequency (docs/validation.md,
//! "An oscillating drop"). A cube of liquid without gravity relaxes, its velocities damped,
//! into a sphere under its surface tension alone; a small velocity field of the n = 2 mode,
//! v = ε(x, −y/2, −z/2) about the centre of mass, then sets it oscillating freely between a
//! prolate and an oblate spheroid. The drop is kicked both ways from the same relaxed state,
//! and the response of its second moment Q = ⟨x²⟩ − (⟨y²⟩ + ⟨z²⟩)/2 is half the difference
//! of the two runs. The period fitted to it ([`fit_period`]) is compared with Rayleigh's for
//! the mode n of a drop of radius R, ω² = n(n − 1)(n + 2)σ/(ρR³), that is ω² = 8σ/(ρR³)
//! for n = 2, where ρR³ = 3M/(4π) for the drop's mass M.

mod report;

pub use report::{ReportFiles, write_report};

use projfluid::{Error, Params, Vec3, World};
use std::f64::consts::PI;

/// The run: the drop, its surface tensions and how it is set oscillating.
#[derive(Clone, Debug)]
pub struct Setup {
    /// Surface tensions σ to run (N/m), one run each.
    pub tensions: Vec<f64>,
    /// Particles along the cube's edge.
    pub across: usize,
    /// The cube's edge (m).
    pub edge: f64,
    /// The n = 2 velocity field's rate ε, as a fraction of Rayleigh's ω (dimensionless): the
    /// drop's axes then swing by about this fraction of its radius.
    pub amplitude: f64,
    /// Rayleigh periods the cube relaxes for before it is set oscillating.
    pub relax_periods: f64,
    /// Rayleigh periods the oscillation is followed for and fitted over: the two kicked
    /// runs' difference is the kick's linear response only until their own motions, which
    /// the relaxation left, part ways, after about a period.
    pub periods: f64,
    /// The liquid's kinematic viscosity ν (m²/s), which damps the mode at Lamb's rate
    /// (n − 1)(2n + 1)ν/R² = 5ν/R² and the particles' own jitter far faster.
    pub kinematic_viscosity: f64,
    /// Worker threads (0 = one per core).
    pub threads: usize,
}

impl Default for Setup {
    fn default() -> Self {
        Self {
            tensions: vec![0.0182, 0.0728],
            across: 16,
            edge: 0.01,
            amplitude: 0.1,
            relax_periods: 2.0,
            periods: 1.25,
            kinematic_viscosity: 1e-5,
            threads: 0,
        }
    }
}

impl Setup {
    /// Checks the setup, naming the field at fault.
    pub fn validate(&self) -> Result<(), Error> {
        if self.tensions.is_empty() {
            return Err(Error::invalid(
                "surface-tension",
                "none",
                "give at least one",
            ));
        }
        if let Some(sigma) = self
            .tensions
            .iter()
            .find(|s| !(s.is_finite() && **s > 0.0 && **s <= 10.0))
        {
            return Err(Error::invalid(
                "surface-tension",
                sigma,
                "must lie in (0, 10] N/m",
            ));
        }
        if !(6..=48).contains(&self.across) {
            return Err(Error::invalid(
                "resolution",
                self.across,
                "must lie in 6–48",
            ));
        }
        let positive = [
            ("edge", self.edge),
            ("amplitude", self.amplitude),
            ("relax_periods", self.relax_periods),
            ("periods", self.periods),
        ];
        for (name, value) in positive {
            if !(value.is_finite() && value > 0.0 && value <= 100.0) {
                return Err(Error::invalid(name, value, "must lie in (0, 100]"));
            }
        }
        if self.periods < 1.1 {
            return Err(Error::invalid(
                "periods",
                self.periods,
                "must be at least 1.1 for the fit to span a period",
            ));
        }
        Ok(())
    }

    /// The particle radius r (m): the cube's edge holds `across` spacings of 2r.
    pub fn particle_radius(&self) -> f64 {
        self.edge / (2.0 * self.across as f64)
    }
}

/// One surface tension's result.
#[derive(Clone, Debug)]
pub struct Run {
    /// σ (N/m).
    pub surface_tension: f64,
    /// The drop's radius R (m), from its volume M/ρ0.
    pub radius: f64,
    /// Rayleigh's period 2π/ω of the n = 2 mode (s).
    pub rayleigh: f64,
    /// The simulated period (s), fitted to the response ([`fit_period`]).
    pub period: f64,
    /// Simulated over Rayleigh's period, minus one.
    pub error: f64,
    /// The response ΔQ = (Q₊ − Q₋)/2 of the drops kicked either way, over time since the
    /// kick: (t (s), ΔQ (m²)).
    pub history: Vec<(f64, f64)>,
    /// The drop's largest over its smallest extent along the axes at the kick, minus one: how
    /// round the relaxed drop was.
    pub asphericity: f64,
    /// Steps taken, the relaxation's included.
    pub steps: usize,
}

/// Every run of a setup.
#[derive(Clone, Debug)]
pub struct Report {
    /// The setup run.
    pub setup: Setup,
    /// Fluid particles per run.
    pub particles: usize,
    /// One per surface tension, in the setup's order.
    pub runs: Vec<Run>,
}

/// Rayleigh's angular frequency ω (1/s) of mode `n` of a drop of radius `radius` (m),
/// density `density` (kg/m³) and surface tension `sigma` (N/m):
/// ω² = n(n − 1)(n + 2)σ/(ρR³).
pub fn rayleigh_frequency(n: u32, sigma: f64, density: f64, radius: f64) -> f64 {
    let n = f64::from(n);
    (n * (n - 1.0) * (n + 2.0) * sigma / (density * radius.powi(3))).sqrt()
}

/// Runs every surface tension of `setup`, calling `progress` with each finished run.
pub fn simulate(setup: &Setup, mut progress: impl FnMut(&Run)) -> Result<Report, Error> {
    setup.validate()?;
    let mut runs = Vec::new();
    let mut particles = 0;
    for &sigma in &setup.tensions {
        let (run, n) = simulate_one(setup, sigma)?;
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

/// The centre of mass (m) of equal-mass particles at `x`.
fn centre(x: &[Vec3]) -> Vec3 {
    x.iter().sum::<Vec3>() / x.len() as f64
}

/// Q = ⟨x²⟩ − (⟨y²⟩ + ⟨z²⟩)/2 about the centre of mass (m²): positive for a drop drawn out
/// along x.
fn second_moment(x: &[Vec3]) -> f64 {
    let c = centre(x);
    let n = x.len() as f64;
    x.iter()
        .map(|p| {
            let d = p - c;
            d.x * d.x - 0.5 * (d.y * d.y + d.z * d.z)
        })
        .sum::<f64>()
        / n
}

fn simulate_one(setup: &Setup, sigma: f64) -> Result<(Run, usize), Error> {
    let params = Params {
        gravity: [0.0; 3],
        viscosity: 0.0,
        kinematic_viscosity: setup.kinematic_viscosity,
        surface_tension: sigma,
        // The capillary limit, not dt_min, sets the step (docs/method.md §8).
        dt_min: 1e-6,
        threads: setup.threads,
        ..Params::with_radius(setup.particle_radius())
    };
    let r = params.particle_radius;
    let mut world = World::new(params.clone())?;
    let n = setup.across;
    world.add_fluid_block(Vec3::repeat(r), [n, n, n], Vec3::zeros())?;
    let mass = world.particle_mass() * world.fluid_count() as f64;
    let radius = (3.0 * mass / (4.0 * PI * params.rest_density)).cbrt();
    let omega = rayleigh_frequency(2, sigma, params.rest_density, radius);
    let rayleigh = 2.0 * PI / omega;
    // Critical damping of the n = 2 mode: the cube settles within a period or two.
    let mut steps = world.relax(setup.relax_periods * rayleigh, 2.0 * omega)?;
    let x = world.positions();
    let c = centre(&x);
    let extent = |axis: usize| {
        let (low, high) = x
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), p| {
                (l.min(p[axis]), h.max(p[axis]))
            });
        high - low
    };
    let extents = [extent(0), extent(1), extent(2)];
    let asphericity = extents.iter().cloned().fold(0.0, f64::max)
        / extents.iter().cloned().fold(f64::INFINITY, f64::min)
        - 1.0;
    // The drop is kicked both ways from the same relaxed state and the response is half
    // the difference of the two: what the kick does, without the motion the relaxation left.
    let relaxed = world.export_state();
    let mut responses = Vec::new();
    for sign in [1.0, -1.0] {
        world.import_state(relaxed.clone())?;
        let rate = sign * setup.amplitude * omega;
        let kicked: Vec<Vec3> = x
            .iter()
            .map(|p| {
                let d = p - c;
                Vec3::new(d.x, -0.5 * d.y, -0.5 * d.z) * rate
            })
            .collect();
        world.set_velocities(&kicked)?;
        let start = world.time();
        let mut q = vec![(0.0, second_moment(&x))];
        steps += world.advance_with(setup.periods * rayleigh, |w| {
            q.push((w.time() - start, second_moment(&w.positions())));
            Ok(())
        })?;
        responses.push(q);
    }
    let history: Vec<(f64, f64)> = responses[0]
        .iter()
        .filter_map(|&(t, up)| {
            let down = super::interpolate(&responses[1], t)?;
            Some((t, 0.5 * (up - down)))
        })
        .collect();
    let period = fit_period(&history, rayleigh).ok_or_else(|| {
        Error::invalid(
            "periods",
            setup.periods,
            "gave too short a response to fit a period to",
        )
    })?;
    let run = Run {
        surface_tension: sigma,
        radius,
        rayleigh,
        period,
        error: period / rayleigh - 1.0,
        history,
        asphericity,
        steps,
    };
    Ok((run, world.fluid_count()))
}

/// The period (s) of the oscillation sampled in `q` (t (s), value), sorted by t: the
/// 2π/ω whose least-squares fit a cos ωt + b sin ωt + c + e t leaves the smallest residual,
/// ω searched from a quarter to four times 2π/`guess` in steps of 0.1 % (a periodogram with
/// a drifting baseline). `None` for fewer than 8 samples or a span shorter than `guess`.
pub fn fit_period(q: &[(f64, f64)], guess: f64) -> Option<f64> {
    let span = q.last()?.0 - q.first()?.0;
    if q.len() < 8 || span.is_nan() || span < guess {
        return None;
    }
    let centre = 2.0 * PI / guess;
    let mut best = (f64::INFINITY, f64::NAN);
    let mut omega = 0.25 * centre;
    while omega <= 4.0 * centre {
        let residual = fit_residual(q, omega);
        if residual < best.0 {
            best = (residual, omega);
        }
        omega *= 1.001;
    }
    best.1.is_finite().then(|| 2.0 * PI / best.1)
}

/// The sum of squared residuals of the least-squares fit of a cos ωt + b sin ωt + c + e t
/// to `q` at angular frequency `omega` (1/s): the normal equations, solved by Gaussian
/// elimination with partial pivoting.
fn fit_residual(q: &[(f64, f64)], omega: f64) -> f64 {
    let basis = |t: f64| [(omega * t).cos(), (omega * t).sin(), 1.0, t];
    let mut a = [[0.0f64; 5]; 4];
    for &(t, y) in q {
        let b = basis(t);
        for i in 0..4 {
            for j in 0..4 {
                a[i][j] += b[i] * b[j];
            }
            a[i][4] += b[i] * y;
        }
    }
    for col in 0..4 {
        let pivot = (col..4)
            .max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))
            .unwrap_or(col);
        a.swap(col, pivot);
        if a[col][col] == 0.0 {
            return f64::INFINITY;
        }
        let pivot_row = a[col];
        for (row, values) in a.iter_mut().enumerate() {
            if row != col {
                let factor = values[col] / pivot_row[col];
                for (value, p) in values.iter_mut().zip(&pivot_row).skip(col) {
                    *value -= factor * p;
                }
            }
        }
    }
    let coefficients: Vec<f64> = (0..4).map(|i| a[i][4] / a[i][i]).collect();
    q.iter()
        .map(|&(t, y)| {
            let fit: f64 = basis(t).iter().zip(&coefficients).map(|(b, c)| b * c).sum();
            (y - fit).powi(2)
        })
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The fitted period of a sampled damped cosine on a drifting baseline, with noise, is
    /// its own; too short a sample gives none.
    #[test]
    fn the_period_of_a_sampled_cosine_is_read_back() {
        let (period, damping) = (0.37, 0.8);
        let omega = 2.0 * PI / period;
        let q: Vec<(f64, f64)> = (0..400)
            .map(|k| {
                let t = k as f64 * 0.004;
                let wiggle = 0.05 * (97.0 * t).sin();
                (
                    t,
                    3.0 + 0.2 * t + (-damping * t).exp() * (omega * t + 0.3).cos() + wiggle,
                )
            })
            .collect();
        let found = fit_period(&q, 0.3).unwrap();
        assert!((found / period - 1.0).abs() < 0.01, "{found}");
        assert_eq!(fit_period(&q[..50], 0.3), None);
    }

    /// Rayleigh's n = 2 frequency of a 1 cm water drop: ω² = 8σ/(ρR³).
    #[test]
    fn rayleighs_frequency() {
        let omega = rayleigh_frequency(2, 0.0728, 1000.0, 0.01);
        assert!((omega - (8.0 * 0.0728 / (1000.0 * 1e-6f64)).sqrt()).abs() < 1e-12);
        assert_eq!(rayleigh_frequency(1, 0.0728, 1000.0, 0.01), 0.0);
    }
}
