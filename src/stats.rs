//! Per-step statistics: what one time step did and where its time went.

/// Wall-clock seconds spent in the parts of one step. On the GPU backend they are the
/// device's own times, from timestamps it writes around its work where it has them (else the
/// host's clock between waits), and the local projections count with the global step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StepTimings {
    /// Prediction, sorting and neighbour search (s).
    pub neighbors: f64,
    /// Local projections (s; 0 on the GPU backend).
    pub local: f64,
    /// Right-hand side, global solves and extrapolation (s; with the local projections on
    /// the GPU backend).
    pub global: f64,
    /// Velocity update, densities, the non-pressure forces, XSPH and statistics (s).
    pub rest: f64,
}

/// What one step did.
#[derive(Clone, Debug, PartialEq)]
pub struct StepStats {
    /// Step size (s).
    pub dt: f64,
    /// Outer (local/global) iterations, of both passes where the extrapolation fell back
    /// (docs/method.md §4), so up to twice the iteration limit.
    pub outer_iterations: usize,
    /// Inner iterations of the linear solver, summed over the outer iterations.
    pub inner_iterations: usize,
    /// The outer loop ended at its iteration limit instead of a stopping rule (in its
    /// fallback pass, for Chebyshev).
    pub hit_max_iterations: bool,
    /// Chebyshev's ρ_c in this step (the online estimate with `auto_rho`); 0 for the other
    /// solvers. A step that fell back to the plain iteration reports the ρ_c its first pass
    /// extrapolated with.
    pub rho: f64,
    /// Largest particle displacement in the last outer iteration (m).
    pub last_displacement: f64,
    /// Mean compression max(ρ/ρ0 − 1, 0) over fluid particles after the step (fraction).
    pub density_error_avg: f64,
    /// Largest compression after the step (fraction).
    pub density_error_max: f64,
    /// Where the time went.
    pub timings: StepTimings,
}

impl StepStats {
    /// A step of `dt` seconds (s) without fluid to move: no iteration, no error.
    pub(crate) fn idle(dt: f64) -> Self {
        Self {
            dt,
            outer_iterations: 0,
            inner_iterations: 0,
            hit_max_iterations: false,
            rho: 0.0,
            last_displacement: 0.0,
            density_error_avg: 0.0,
            density_error_max: 0.0,
            timings: StepTimings::default(),
        }
    }
}
