//! Simulation parameters with their defaults (docs/method.md Appendix A) and validation.

mod validate;

use crate::Backend;

/// Which global solver runs in each outer iteration (docs/method.md §3).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SolverKind {
    /// One Jacobi sweep plus Chebyshev extrapolation over the outer iterations
    /// (docs/method.md §3.7).
    Chebyshev,
    /// Exactly one Jacobi sweep per outer iteration (exact for the diagonal formulation F1).
    Jacobi1,
    /// Jacobi sweeps until ‖b − Ax‖ ≤ 1e-10‖b‖ or 100 sweeps.
    Jacobi,
    /// Conjugate gradients until ‖b − Ax‖ ≤ 1e-10‖b‖ or 100 iterations.
    Cg,
    /// Exactly one conjugate-gradient iteration (a steepest-descent step with exact line
    /// search) per outer iteration; not exact, so it changes the result.
    Cg1,
    /// Sparse LDLᵀ factorisation once per time step, one direct solve per outer iteration.
    Ldlt,
}

impl SolverKind {
    /// Every solver, in the order the CLI lists them.
    pub const ALL: [SolverKind; 6] = [
        SolverKind::Chebyshev,
        SolverKind::Jacobi1,
        SolverKind::Jacobi,
        SolverKind::Cg,
        SolverKind::Cg1,
        SolverKind::Ldlt,
    ];

    /// Every solver's name, in the order of [`SolverKind::ALL`].
    pub const NAMES: [&'static str; 6] = {
        let mut names = [""; 6];
        let mut i = 0;
        while i < names.len() {
            names[i] = Self::ALL[i].name();
            i += 1;
        }
        names
    };

    /// The solver's name as used by the CLI, scenes and statistics.
    pub const fn name(self) -> &'static str {
        match self {
            SolverKind::Chebyshev => "chebyshev",
            SolverKind::Jacobi1 => "jacobi1",
            SolverKind::Jacobi => "jacobi",
            SolverKind::Cg => "cg",
            SolverKind::Cg1 => "cg1",
            SolverKind::Ldlt => "ldlt",
        }
    }

    /// Parses a solver name (see [`SolverKind::name`]).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|k| k.name() == name)
    }
}

/// Scene files write a parameter enum as its `name()` and read it back with `from_name`; an
/// unknown name is an error listing the known ones (`NAMES`).
macro_rules! serde_by_name {
    ($t:ty) => {
        impl serde::Serialize for $t {
            fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
                serializer.serialize_str(self.name())
            }
        }

        impl<'de> serde::Deserialize<'de> for $t {
            fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
                let name = String::deserialize(deserializer)?;
                Self::from_name(&name)
                    .ok_or_else(|| serde::de::Error::unknown_variant(&name, &Self::NAMES))
            }
        }
    };
}

serde_by_name!(SolverKind);
serde_by_name!(Backend);

/// How ω₂, the first Chebyshev weight, is chosen (docs/method.md §3.7).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Omega2Rule {
    /// ω₂ = 2/(2 − ρ²), the Chebyshev-polynomial start (Wang 2015).
    Chebyshev,
    /// ω₂ = 4/(4 − ρ²), as Sommer et al. (2020) state it (the default).
    Paper,
}

impl Omega2Rule {
    /// Every rule.
    pub const ALL: [Omega2Rule; 2] = [Omega2Rule::Chebyshev, Omega2Rule::Paper];

    /// Every rule's name, in the order of [`Omega2Rule::ALL`].
    pub const NAMES: [&'static str; 2] = ["chebyshev", "paper"];

    /// The rule's name in scenes and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Omega2Rule::Chebyshev => "chebyshev",
            Omega2Rule::Paper => "paper",
        }
    }

    /// Parses a rule name (see [`Omega2Rule::name`]).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|r| r.name() == name)
    }
}

serde_by_name!(Omega2Rule);

/// Weight w_j applied to a particle's share of a local projection (docs/method.md §2.5).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ProjectionWeight {
    /// w_j = n_j + 1, the fluid neighbour count plus one (the reference behaviour).
    NeighborCount,
    /// w_j = 1, a true projection.
    Unit,
    /// w_j = c for every particle, with c = ρ0·(4/3)πH³/m the stencil size of a fluid at rest
    /// density, and the global step counts every particle as a member of c stencils (its own
    /// ones plus inactive "stay" terms). The converged step's constraint forces are then
    /// k·c·Σ_i λ_i ∇_{x_j}C_i, the gradient of one energy, and conserve momentum; with
    /// `NeighborCount` they are scaled per particle by n_j + 1, which is not conservative
    /// (docs/solvers.md, "Projection weighting"). Experimental: it keeps a resting column calmer, but
    /// splashing flows gain energy with it unless Chebyshev's γ is 0.8 or less.
    Uniform,
}

impl ProjectionWeight {
    /// Every weighting.
    pub const ALL: [ProjectionWeight; 3] = [
        ProjectionWeight::NeighborCount,
        ProjectionWeight::Unit,
        ProjectionWeight::Uniform,
    ];

    /// Every weighting's name, in the order of [`ProjectionWeight::ALL`].
    pub const NAMES: [&'static str; 3] = ["neighbor_count", "unit", "uniform"];

    /// The weighting's name in scenes (`solver.projection_weight`).
    pub fn name(self) -> &'static str {
        match self {
            ProjectionWeight::NeighborCount => "neighbor_count",
            ProjectionWeight::Unit => "unit",
            ProjectionWeight::Uniform => "uniform",
        }
    }

    /// Parses a weighting's name (see [`ProjectionWeight::name`]).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|w| w.name() == name)
    }
}

serde_by_name!(ProjectionWeight);

/// Settings of Chebyshev's semi-iterative acceleration (docs/method.md §3.7).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChebyshevParams {
    /// Estimated spectral radius ρ_c of the outer iteration, in [0, 1).
    pub rho: f64,
    /// Delay S ≥ 1: outer iterations with ω = 1 before extrapolation starts.
    pub delay: usize,
    /// Rule for the first weight ω₂.
    pub omega2_rule: Omega2Rule,
    /// Under-relaxation γ in (0, 1].
    pub gamma: f64,
    /// Estimate ρ_c online instead of using `rho` (docs/solvers.md, "Choosing ρ"): every step of five
    /// or more outer iterations estimates the plain iteration's contraction μ from how fast
    /// its own extrapolated iterates contracted, and ρ_c = 0.97·μ (smoothed, clamped to
    /// [0.5, 0.925]); `rho` is only the value used until the first estimate. Off by default:
    /// the estimate follows the iteration's late, asymptotic contraction, while the density
    /// rule ends most steps within a few iterations, where a larger fixed ρ pays
    /// (docs/method.md §5.3).
    pub auto_rho: bool,
}

/// Chosen by measurement with the density rule at the rest-density start (docs/method.md
/// §5.1): fewer outer iterations than 0.95–0.98 on `dam_break_30k` and on `obstacle_298k`,
/// without a step at K_max; also the starting value of the online estimate.
pub const DEFAULT_CHEBYSHEV_RHO: f64 = 0.99;
/// Chosen by measurement on `dam_break_30k` (docs/method.md §4).
pub const DEFAULT_CHEBYSHEV_DELAY: usize = 1;

impl Default for ChebyshevParams {
    fn default() -> Self {
        Self {
            rho: DEFAULT_CHEBYSHEV_RHO,
            delay: DEFAULT_CHEBYSHEV_DELAY,
            omega2_rule: Omega2Rule::Paper,
            gamma: 1.0,
            auto_rho: false,
        }
    }
}

/// Every setting of a world. Lengths in metres, times in seconds, densities in kg/m³.
#[derive(Clone, Debug, PartialEq)]
pub struct Params {
    /// Particle radius r (m); the lattice spacing is 2r and the support radius H = 4r.
    pub particle_radius: f64,
    /// Rest density ρ0 (kg/m³).
    pub rest_density: f64,
    /// Particle mass as a fraction of ρ0·(2r)³ (dimensionless). The default,
    /// [`rest_mass_factor`], makes a lattice block start at ρ0;
    /// [`REFERENCE_MASS_FACTOR`] (0.8) is the convention of other SPH codes.
    pub mass_factor: f64,
    /// Constraint stiffness k (N/m).
    pub stiffness: f64,
    /// Gravitational acceleration (m/s²).
    pub gravity: [f64; 3],
    /// The global solver.
    pub solver: SolverKind,
    /// Chebyshev settings (used by [`SolverKind::Chebyshev`]).
    pub chebyshev: ChebyshevParams,
    /// Outer stopping threshold η on the average density error (dimensionless, 0 = off):
    /// stop when Σ_i max(ρ_i/ρ0 − 1, 0)/N at the iterate is at most η and the last outer
    /// iteration moved no particle farther than 10τ (docs/method.md §4).
    pub density_tolerance: f64,
    /// Outer stopping threshold τ (m): stop when no particle moved more than τ in an iteration.
    pub displacement_tolerance: f64,
    /// Share f of the last step's support a step starts from (dimensionless, in [0, 1); 0, the
    /// default, starts every step from its prediction s): particles that active constraints
    /// moved in the last step start the outer iteration from s + f·Δt²·a, a being that
    /// step's displacement from its own s per Δt², at most 2|g|; the iteration withdraws the
    /// start of particles it finds under-dense (docs/method.md §4.1). Not used in worlds with
    /// bodies nor in the calm settings.
    pub warm_start: f64,
    /// Correct the start of every step's outer iteration on a coarse lattice (default off):
    /// the whole fluid moves at once by the displacement that removes its compression on
    /// cells of two support radii, so that deep water needs far fewer outer iterations
    /// (docs/method.md §3.8). It still changes some flows by a few per cent, hence off. Not
    /// used in worlds with bodies nor in the calm settings.
    pub coarse_correction: bool,
    /// Smallest number of outer iterations per step (≥ 1).
    pub min_outer_iterations: usize,
    /// Largest number of outer iterations per step.
    pub max_outer_iterations: usize,
    /// Weighting of the local projection.
    pub projection_weight: ProjectionWeight,
    /// CFL factor λ in Δt = λ·0.4·2r/v_max.
    pub cfl_factor: f64,
    /// Smallest time step (s), in (0, [`MAX_STEP`]]; also the shortest duration
    /// [`crate::World::advance`] accepts.
    pub dt_min: f64,
    /// Largest time step (s), in [`dt_min`](Params::dt_min), [`MAX_STEP`]].
    pub dt_max: f64,
    /// Time step of the first step (s), in (0, [`MAX_STEP`]]: clamped to [dt_min, dt_max], and
    /// at most the step over which gravity alone moves a particle r/4 (docs/method.md §8).
    pub dt_initial: f64,
    /// XSPH viscosity coefficient c_X (dimensionless, 0 = off).
    pub viscosity: f64,
    /// Kinematic viscosity ν (m²/s) of the implicit viscosity solve (docs/method.md §13):
    /// 0, the default, leaves it out; water is 1e-6, olive oil about 1e-4, honey 1e-2 and
    /// more. Stable at every value and step size. It is the world's own fluid's (material 0),
    /// which [`crate::World::set_material_kinematic_viscosity`] may change later; other
    /// materials have their own ([`crate::Material::kinematic_viscosity`]).
    pub kinematic_viscosity: f64,
    /// Surface tension coefficient σ (N/m) of the world's own fluid (material 0; docs/method.md
    /// §17), at most [`crate::material::MAX_SURFACE_TENSION`]: 0, the default, leaves it out
    /// and costs nothing; water against air is 0.0728.
    /// [`crate::World::set_material_surface_tension`] may change it later; other materials
    /// have their own ([`crate::Material::surface_tension`]). A world with surface tension
    /// also limits its steps by the capillary rule (docs/method.md §8).
    pub surface_tension: f64,
    /// Work of adhesion W (N/m, energy per wetted area) between every fluid and the walls,
    /// static obstacles and bodies (docs/method.md §17.2): 0, the default, leaves the
    /// attraction out. With a fluid of surface tension σ, Young and Dupré's relation
    /// cos θ = W/σ − 1 gives the contact angle θ it aims at: W = 2σ wets fully, W = σ
    /// makes θ = 90°. At most twice [`crate::material::MAX_SURFACE_TENSION`].
    pub wall_adhesion: f64,
    /// Vorticity confinement coefficient ε (dimensionless, docs/method.md §15): 0, the
    /// default, leaves it out; 0.1–1 gives back rotation that the iteration and XSPH damp.
    pub vorticity_confinement: f64,
    /// Whether the walls, static obstacles and static bodies hold the fluid with no slip under
    /// the physical viscosity (true, the default) or let it slide (free slip). Moving bodies
    /// and walls built as fields let it slide either way.
    pub no_slip: bool,
    /// Worker threads of the world's own pool (0 = one per core).
    pub threads: usize,
    /// Where the world's steps run: [`Backend::Cpu`], the default, or [`Backend::Gpu`]
    /// (feature `gpu`), which [`crate::World::new`] opens, failing where the build has no
    /// `gpu` feature or the machine no Vulkan adapter. [`crate::World::set_backend`]
    /// changes it.
    pub backend: Backend,
}

/// The largest vorticity confinement coefficient ε a world accepts (dimensionless): beyond it
/// the confinement's acceleration outgrows the rotation it confines within a step.
pub const MAX_VORTICITY_CONFINEMENT: f64 = 10.0;

/// The longest time step (s) a world takes: the bound on `dt_min`, `dt_max` and
/// `dt_initial` and on an explicit step's size, checked by one rule ([`check_step`]).
pub const MAX_STEP: f64 = 1.0;

/// Checks a time step size `dt` (s) named `field`: positive, finite and at most
/// [`MAX_STEP`]. Both [`Params::validate`] (for `dt_min`, `dt_max`, `dt_initial`) and
/// [`crate::World::step_with_dt`] use it, so that parameters that validate can be stepped.
pub fn check_step(field: &str, dt: f64) -> Result<(), crate::Error> {
    if dt.is_finite() && dt > 0.0 && dt <= MAX_STEP {
        Ok(())
    } else {
        Err(crate::Error::invalid(
            field,
            dt,
            &format!("must be a positive finite number of seconds (at most {MAX_STEP})"),
        ))
    }
}

/// Default η: an average density error of 0.03 %, the accuracy target itself, which the
/// density rule holds in every step it ends (docs/method.md §4).
pub const DEFAULT_DENSITY_TOLERANCE: f64 = 3e-4;

/// The default [`Params::warm_start`]: off. A start saves outer iterations (at f = 0.99, a
/// quarter on `dam_break_30k` and 44 % on `dam_break_88k`) but still changes some flows: it
/// throws particles off the top of a deep column in the step that first holds it up, and
/// slows a narrow column's surge by a few per cent (docs/method.md §4.1).
pub const DEFAULT_WARM_START: f64 = 0.0;
/// Default CFL factor λ, chosen by measurement on `dam_break_30k` (docs/method.md §8): at
/// 1.25 a particle moves at most r per step, and the outer iterations per simulated second
/// are about those of shorter steps, so a simulated second takes fewer steps.
pub const DEFAULT_CFL_FACTOR: f64 = 1.25;

/// Default particle radius (m).
pub const DEFAULT_PARTICLE_RADIUS: f64 = 0.025;
/// Default τ as a multiple of the particle radius: chosen by measurement on `dam_break_30k`
/// (docs/method.md §4); docs/method.md §4 suggests 1e-3.
pub const DEFAULT_TOLERANCE_PER_RADIUS: f64 = 3e-3;

/// τ of [`Params::calm`] as a multiple of the particle radius, ten times tighter than the
/// default: a step that stops with its last displacement just under τ leaves a velocity error
/// of order τ/Δt, which a tank at rest keeps (docs/validation.md, "Tank at rest").
pub const CALM_TOLERANCE_PER_RADIUS: f64 = 3e-4;

/// The mass factor of SPH codes that take a particle's volume as 0.8·(2r)³ (SPlisHSPlasH
/// among them): a lattice block then starts at 0.8·ρ0 and settles about 7 % lower than it
/// was built (docs/method.md §2.2). Offered for comparison with such codes.
pub const REFERENCE_MASS_FACTOR: f64 = 0.8;

/// The mass factor at which a cubic lattice of spacing 2r has density ρ0 in its interior:
/// 1/((2r)³·Σ_j W(x_j)) over the lattice points within H = 4r (≈ 1.0000275 for the cubic
/// spline; docs/method.md §2.2). The sum is scale free, so it is evaluated at 2r = 1.
pub fn rest_mass_factor() -> f64 {
    let kernel = crate::kernel::CubicKernel::new(2.0);
    // Plain loops over the 5³ points in x-major order: valgrind reads the nested range
    // adaptors' compiled code as branching on uninitialised memory.
    let mut sum = 0.0;
    for i in -2i32..3 {
        for j in -2i32..3 {
            for k in -2i32..3 {
                sum += kernel.w(f64::from(i * i + j * j + k * k).sqrt());
            }
        }
    }
    1.0 / sum
}

impl Default for Params {
    fn default() -> Self {
        Self::with_radius(DEFAULT_PARTICLE_RADIUS)
    }
}

impl Params {
    /// Default parameters for particle radius `r` (m), with τ = 3e-3·r.
    pub fn with_radius(r: f64) -> Self {
        Self {
            particle_radius: r,
            rest_density: 1000.0,
            mass_factor: rest_mass_factor(),
            stiffness: 1e6,
            gravity: [0.0, -9.81, 0.0],
            solver: SolverKind::Chebyshev,
            chebyshev: ChebyshevParams::default(),
            density_tolerance: DEFAULT_DENSITY_TOLERANCE,
            displacement_tolerance: DEFAULT_TOLERANCE_PER_RADIUS * r,
            warm_start: DEFAULT_WARM_START,
            coarse_correction: false,
            min_outer_iterations: 1,
            max_outer_iterations: 100,
            projection_weight: ProjectionWeight::NeighborCount,
            cfl_factor: DEFAULT_CFL_FACTOR,
            dt_min: 1e-4,
            dt_max: 5e-3,
            dt_initial: 1e-3,
            viscosity: 0.01,
            kinematic_viscosity: 0.0,
            surface_tension: 0.0,
            wall_adhesion: 0.0,
            vorticity_confinement: 0.0,
            no_slip: true,
            threads: 0,
            backend: Backend::Cpu,
        }
    }

    /// These parameters with the calm settings (docs/solvers.md, "A tank at rest: the calm settings"):
    /// the [`ProjectionWeight::Uniform`] weighting, whose converged constraint forces derive
    /// from one energy; τ = [`CALM_TOLERANCE_PER_RADIUS`]·r; Chebyshev at a fixed ρ = 0.99
    /// with γ = 0.5, which keeps the iteration convergent in fully compressed fluid (where the
    /// summed projections overshoot by up to ≈ 3.8); and every step from its prediction (no
    /// warm start, whose start would carry part of the weight outside the constraints, and no
    /// coarse correction, whose moves a converged tank need not make). A
    /// settled tank stays at rest under them; they cost 2–4× the outer iterations of the
    /// defaults.
    pub fn calm(self) -> Self {
        Self {
            projection_weight: ProjectionWeight::Uniform,
            density_tolerance: 0.0,
            displacement_tolerance: CALM_TOLERANCE_PER_RADIUS * self.particle_radius,
            warm_start: 0.0,
            coarse_correction: false,
            chebyshev: ChebyshevParams {
                rho: 0.99,
                gamma: 0.5,
                auto_rho: false,
                ..self.chebyshev
            },
            ..self
        }
    }

    /// Lattice spacing d = 2r (m).
    pub fn spacing(&self) -> f64 {
        2.0 * self.particle_radius
    }

    /// Support radius H = 4r (m).
    pub fn support_radius(&self) -> f64 {
        4.0 * self.particle_radius
    }

    /// Fluid particle mass m = mass_factor·ρ0·(2r)³ (kg).
    pub fn particle_mass(&self) -> f64 {
        self.mass_factor * self.rest_density * self.spacing().powi(3)
    }

    /// Stencil size of a fluid at rest density: the number of particles of mass m within
    /// the support radius H, c = ρ0·(4/3)πH³/m (33.5 at the default mass factor, 41.9 at
    /// 0.8).
    pub fn rest_stencil_size(&self) -> f64 {
        self.rest_density * 4.0 / 3.0 * std::f64::consts::PI * self.support_radius().powi(3)
            / self.particle_mass()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A warm start's share lies in [0, 1): others are refused, naming the field.
    #[test]
    fn a_warm_start_share_outside_zero_to_one_is_refused() {
        for share in [0.0, 0.45, 0.99] {
            let p = Params {
                warm_start: share,
                ..Params::default()
            };
            p.validate().unwrap();
        }
        for share in [-0.1, 1.0, 2.0, f64::NAN, f64::INFINITY] {
            let p = Params {
                warm_start: share,
                ..Params::default()
            };
            let message = p.validate().unwrap_err().to_string();
            assert!(message.contains("warm_start"), "{share}: {message}");
        }
    }

    /// The calm settings change the weighting, τ (scaled by the radius), the Chebyshev
    /// settings, the warm start and the coarse correction, keep every other field (the
    /// backend among them), and validate.
    #[test]
    fn calm_changes_only_the_solver_settings() {
        let base = Params {
            solver: SolverKind::Jacobi1,
            threads: 3,
            warm_start: 0.5,
            backend: Backend::Gpu,
            ..Params::with_radius(0.01)
        };
        let calm = base.clone().calm();
        assert_eq!(calm.projection_weight, ProjectionWeight::Uniform);
        assert_eq!(
            calm.displacement_tolerance,
            CALM_TOLERANCE_PER_RADIUS * 0.01
        );
        assert_eq!(
            (
                calm.chebyshev.rho,
                calm.chebyshev.gamma,
                calm.chebyshev.auto_rho
            ),
            (0.99, 0.5, false)
        );
        assert_eq!(calm.density_tolerance, 0.0);
        assert_eq!(calm.warm_start, 0.0);
        assert!(!calm.coarse_correction);
        let restored = Params {
            projection_weight: base.projection_weight,
            density_tolerance: base.density_tolerance,
            warm_start: base.warm_start,
            coarse_correction: base.coarse_correction,
            displacement_tolerance: base.displacement_tolerance,
            chebyshev: base.chebyshev,
            ..calm.clone()
        };
        assert_eq!(restored, base);
        calm.validate().unwrap();
    }
}
