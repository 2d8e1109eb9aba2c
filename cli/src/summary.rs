//! A run's summary, accumulated from the core's per-step statistics: what the CLI prints and
//! writes as `--stats` JSON.

use projfluid::stats::StepStats;
use projfluid::{SolverKind, World};
use serde::Serialize;

/// A run's summary; field names are the stable keys of the `--stats` JSON.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct RunSummary {
    /// Scene name.
    pub scene: String,
    /// Global solver name.
    pub solver: String,
    /// Where the steps ran: `cpu` or `gpu` ([`projfluid::Backend::name`]).
    pub backend: String,
    /// Chebyshev ρ_c (reported for every solver; used by `chebyshev` only); with `rho_auto`,
    /// the mean online estimate over the steps that extrapolated.
    pub rho: f64,
    /// ρ_c was estimated online (`--rho auto`).
    pub rho_auto: bool,
    /// Outer stopping threshold η on the average density error (a fraction; 0 = off).
    pub eta: f64,
    /// Outer stopping threshold τ (m).
    pub tau: f64,
    /// The coarse correction of each step's outer iteration was on (it is not used in worlds
    /// with bodies).
    pub coarse_correction: bool,
    /// Kinematic viscosity ν of the physical viscosity solve (m²/s; 0 = off).
    pub kinematic_viscosity: f64,
    /// Walls, static obstacles and static bodies held the fluid with no slip under the
    /// physical viscosity (false: free slip; no effect while `kinematic_viscosity` is 0).
    pub no_slip: bool,
    /// Vorticity confinement ε (dimensionless; 0 = off).
    pub vorticity_confinement: f64,
    /// Surface tension σ of the scene's own fluid (N/m; 0 = off).
    pub surface_tension: f64,
    /// Worker threads.
    pub threads: usize,
    /// Fluid particles.
    pub particles: usize,
    /// Boundary particles.
    pub boundary_particles: usize,
    /// Steps taken.
    pub steps: u64,
    /// Simulated time covered by the run (s).
    pub sim_time: f64,
    /// Mean wall-clock time per step (ms).
    pub wall_ms_per_step: f64,
    /// Mean processor time per step, summed over all threads of the process (ms); less
    /// sensitive than wall time to other programs on a shared machine. `None` where the
    /// platform does not report it.
    pub cpu_ms_per_step: Option<f64>,
    /// Mean outer iterations per step.
    pub outer_iterations_mean: f64,
    /// Mean inner (linear-solver) iterations per step: Jacobi sweeps, CG iterations or direct
    /// solves, summed over the step's outer iterations.
    pub inner_iterations_mean: f64,
    /// Steps whose outer loop ended at its iteration limit instead of the displacement rule.
    pub max_iteration_hits: u64,
    /// Mean over steps of the mean compression (percent).
    pub density_error_avg_percent: f64,
    /// Largest compression of any particle in any step (percent).
    pub density_error_max_percent: f64,
    /// Fluid particles outside the container at the end.
    pub escaped: usize,
    /// Fluid particles with a non-finite position or velocity at the end.
    pub nan: usize,
    /// Hex SHA-256 of the final positions' bit patterns.
    pub positions_hash: String,
    /// Mean milliseconds per step in neighbour search / local step / global step / rest.
    pub ms_per_step_breakdown: [f64; 4],
    /// Total energy (kinetic plus potential, see [`RunAccumulator::record_energy`]) at the
    /// start of the run (J).
    pub energy_initial: f64,
    /// Largest total energy at the start or after any step (J).
    pub energy_max: f64,
    /// Total energy after the last step (J).
    pub energy_final: f64,
}

impl RunSummary {
    /// How far the total energy rose above its initial value at its highest, as a fraction of
    /// the initial value: 0 when it never rose, `None` when the initial energy is not positive.
    pub fn energy_rise(&self) -> Option<f64> {
        (self.energy_initial > 0.0)
            .then(|| (self.energy_max - self.energy_initial) / self.energy_initial)
    }
}

/// Accumulates step statistics into a [`RunSummary`].
#[derive(Clone, Debug, Default)]
pub struct RunAccumulator {
    steps: u64,
    sim_time: f64,
    wall_seconds: f64,
    cpu_seconds: Option<f64>,
    outer: u64,
    inner: u64,
    max_iteration_hits: u64,
    energy: Option<EnergyRecord>,
    density_avg_sum: f64,
    density_max: f64,
    rho_sum: f64,
    rho_steps: u64,
    breakdown: [f64; 4],
}

impl RunAccumulator {
    /// Adds one step that took `wall_seconds` of wall-clock time.
    pub fn add(&mut self, step: &StepStats, wall_seconds: f64) {
        self.steps += 1;
        self.sim_time += step.dt;
        self.wall_seconds += wall_seconds;
        self.outer += step.outer_iterations as u64;
        if step.rho > 0.0 {
            self.rho_sum += step.rho;
            self.rho_steps += 1;
        }
        self.inner += step.inner_iterations as u64;
        self.max_iteration_hits += u64::from(step.hit_max_iterations);
        self.density_avg_sum += step.density_error_avg;
        self.density_max = self.density_max.max(step.density_error_max);
        let t = &step.timings;
        for (acc, v) in self
            .breakdown
            .iter_mut()
            .zip([t.neighbors, t.local, t.global, t.rest])
        {
            *acc += v;
        }
    }

    /// Adds the processor time (s, all threads) of the steps added since the last call.
    pub fn add_cpu_time(&mut self, seconds: f64) {
        *self.cpu_seconds.get_or_insert(0.0) += seconds;
    }

    /// Records the total energy (J) at the start of the run (first call) or after a step.
    /// The run driver measures it above a datum fixed at the start, see
    /// [`crate::driver::total_energy`].
    pub fn record_energy(&mut self, joules: f64) {
        let e = self.energy.get_or_insert(EnergyRecord {
            initial: joules,
            max: joules,
            last: joules,
        });
        e.max = e.max.max(joules);
        e.last = joules;
    }

    /// Steps added so far.
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// The summary of the steps added so far, with the world's final state.
    pub fn summary(&self, scene: &str, world: &World) -> RunSummary {
        let n = self.steps.max(1) as f64;
        let p = world.params();
        let energy = self.energy.unwrap_or_default();
        RunSummary {
            scene: scene.to_string(),
            solver: p.solver.name().to_string(),
            backend: world.backend().name().to_string(),
            rho: if p.chebyshev.auto_rho && p.solver == SolverKind::Chebyshev && self.rho_steps > 0
            {
                self.rho_sum / self.rho_steps as f64
            } else {
                p.chebyshev.rho
            },
            rho_auto: p.chebyshev.auto_rho,
            eta: p.density_tolerance,
            tau: p.displacement_tolerance,
            coarse_correction: p.coarse_correction,
            kinematic_viscosity: p.kinematic_viscosity,
            no_slip: p.no_slip,
            vorticity_confinement: p.vorticity_confinement,
            surface_tension: p.surface_tension,
            threads: world.thread_count(),
            particles: world.fluid_count(),
            boundary_particles: world.boundary_count(),
            steps: self.steps,
            sim_time: self.sim_time,
            wall_ms_per_step: self.wall_seconds * 1e3 / n,
            cpu_ms_per_step: self.cpu_seconds.map(|s| s * 1e3 / n),
            outer_iterations_mean: self.outer as f64 / n,
            inner_iterations_mean: self.inner as f64 / n,
            max_iteration_hits: self.max_iteration_hits,
            density_error_avg_percent: self.density_avg_sum * 100.0 / n,
            density_error_max_percent: self.density_max * 100.0,
            escaped: world.escaped_count(),
            nan: world.nan_count(),
            positions_hash: world.positions_hash(),
            ms_per_step_breakdown: self.breakdown.map(|s| s * 1e3 / n),
            energy_initial: energy.initial,
            energy_max: energy.max,
            energy_final: energy.last,
        }
    }
}

/// Total energy at the start, its maximum and its latest value (J).
#[derive(Clone, Copy, Debug, Default)]
struct EnergyRecord {
    initial: f64,
    max: f64,
    last: f64,
}
