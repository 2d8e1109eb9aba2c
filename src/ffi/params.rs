//! `PfParams`, the C mirror of [`Params`], with its enums and `pf_params_default`.

use super::checked::Args;
use super::status::{Failure, PfStatus, status_call};
use crate::Backend;
use crate::params::{ChebyshevParams, Omega2Rule, Params, ProjectionWeight, SolverKind};
use std::ffi::c_int;
use std::ptr;

/// The global solver run in each outer iteration.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[allow(non_camel_case_types)]
pub enum PfSolver {
    /// One Jacobi sweep plus Chebyshev extrapolation over the outer iterations (the default).
    PF_SOLVER_CHEBYSHEV = 0,
    /// Exactly one Jacobi sweep per outer iteration.
    PF_SOLVER_JACOBI1 = 1,
    /// Jacobi sweeps until the residual drops by 1e-10 or 100 sweeps.
    PF_SOLVER_JACOBI = 2,
    /// Conjugate gradients until the residual drops by 1e-10 or 100 iterations.
    PF_SOLVER_CG = 3,
    /// Exactly one conjugate-gradient (steepest-descent) iteration per outer iteration.
    PF_SOLVER_CG1 = 4,
    /// Sparse LDLT factorisation once per time step, one direct solve per outer iteration.
    PF_SOLVER_LDLT = 5,
}

/// How the first Chebyshev weight ω₂ is chosen.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[allow(non_camel_case_types)]
pub enum PfOmega2Rule {
    /// ω₂ = 2/(2 − ρ²), the Chebyshev-polynomial start (Wang 2015).
    PF_OMEGA2_CHEBYSHEV = 0,
    /// ω₂ = 4/(4 − ρ²), as Sommer et al. (2020) state it (the default).
    PF_OMEGA2_PAPER = 1,
}

/// Weight of a particle's share of a local projection.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[allow(non_camel_case_types)]
pub enum PfProjectionWeight {
    /// w = fluid neighbour count + 1 (the default).
    PF_WEIGHT_NEIGHBOR_COUNT = 0,
    /// w = 1.
    PF_WEIGHT_UNIT = 1,
    /// w = the stencil size at rest density for every particle (conservative forces).
    PF_WEIGHT_UNIFORM = 2,
}

/// The values of `PfParams.backend`, a `uint32_t`: where a world's steps run.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[allow(non_camel_case_types)]
pub enum PfBackend {
    /// The world's own threads, in double precision (the default).
    PF_BACKEND_CPU = 0,
    /// A graphics card through Vulkan compute shaders, in single precision: only in a
    /// library built with the `gpu` feature, on a machine with a Vulkan adapter.
    PF_BACKEND_GPU = 1,
}

// Enum fields are read from C memory as plain ints before they are checked.
const _: () = assert!(size_of::<PfSolver>() == size_of::<c_int>());
const _: () = assert!(size_of::<PfOmega2Rule>() == size_of::<c_int>());
const _: () = assert!(size_of::<PfProjectionWeight>() == size_of::<c_int>());

/// Every setting of a world (SI units: metres, seconds, kilograms). Fill it with
/// `pf_params_default`, change what you need, and pass it to `pf_world_create`, which
/// validates it. The struct is plain data owned by the caller; the library copies it.
/// Fields added in later versions are appended at its end (`kinematic_viscosity` and
/// `no_slip` in ABI version 4, `backend` in 5, `vorticity_confinement` in 6,
/// `surface_tension` and `wall_adhesion` in 7), and each addition raises `PF_ABI_VERSION`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PfParams {
    /// Particle radius r (m); lattice spacing 2r, support radius 4r. Default 0.025.
    pub particle_radius: f64,
    /// Rest density ρ0 (kg/m³). Default 1000.
    pub rest_density: f64,
    /// Particle mass as a fraction of ρ0·(2r)³ (dimensionless). Default ≈ 1.0000275, at which
    /// a cubic lattice of spacing 2r starts at ρ0; 0.8 is the convention of other SPH codes.
    pub mass_factor: f64,
    /// Constraint stiffness k (N/m). Default 1e6.
    pub stiffness: f64,
    /// Gravitational acceleration (m/s²). Default (0, −9.81, 0).
    pub gravity: [f64; 3],
    /// The global solver. Default `PF_SOLVER_CHEBYSHEV`.
    pub solver: PfSolver,
    /// Rule for the first Chebyshev weight. Default `PF_OMEGA2_PAPER`.
    pub omega2_rule: PfOmega2Rule,
    /// Estimated spectral radius ρ_c for Chebyshev acceleration, in [0, 1); with
    /// `chebyshev_auto_rho` = 1 only the value used until the first estimate. Default 0.99.
    pub chebyshev_rho: f64,
    /// Outer iterations (≥ 1) before Chebyshev extrapolation starts. Default 1.
    pub chebyshev_delay: u32,
    /// Under-relaxation γ of the Chebyshev step, in (0, 1]. Default 1.
    pub chebyshev_gamma: f64,
    /// 1: estimate ρ_c online during the run (`chebyshev_rho` is then only the starting
    /// value); 0: use `chebyshev_rho` throughout. Default 0.
    pub chebyshev_auto_rho: u32,
    /// Weighting of the local projection. Default `PF_WEIGHT_NEIGHBOR_COUNT`.
    pub projection_weight: PfProjectionWeight,
    /// Outer stopping threshold η on the average density error (dimensionless, in [0, 1);
    /// 0 turns the rule off): stop when the mean over the fluid of max(ρ_i/ρ0 − 1, 0) is at
    /// most η and the last outer iteration moved no particle farther than
    /// 10·`displacement_tolerance`. Default 3e-4.
    pub density_tolerance: f64,
    /// Outer stopping threshold τ (m): stop when no particle moved more than τ in one
    /// outer iteration. Default 3e-3·r.
    pub displacement_tolerance: f64,
    /// Share f of the last step's support a step starts from, in [0, 1) (0: every step
    /// starts from its prediction s): particles that active constraints moved in the last
    /// step start the outer iteration from s + f·Δt²·a, a being that step's displacement from
    /// its prediction per Δt² (m/s², at most 2|g|); the start of particles the iteration finds
    /// under-dense is withdrawn. Not used in worlds with bodies; 0 in the calm settings.
    /// Default 0.
    pub warm_start: f64,
    /// 1: correct the start of every step's outer iteration on a coarse lattice, moving the
    /// whole fluid at once by the displacement that removes its compression on cells of two
    /// support radii, so that deep water needs far fewer outer iterations; 0: off. Not used
    /// in worlds with bodies nor in the calm settings. Default 0.
    pub coarse_correction: u32,
    /// Smallest number of outer iterations per step (≥ 1). Default 1.
    pub min_outer_iterations: u32,
    /// Largest number of outer iterations per step (≤ 100000). Default 100. Where Chebyshev's
    /// extrapolation reaches it, the step starts over without extrapolation for at most as
    /// many again (unless it equals `min_outer_iterations`).
    pub max_outer_iterations: u32,
    /// CFL factor λ in Δt = λ·0.4·2r/v_max. Default 1.25.
    pub cfl_factor: f64,
    /// Smallest CFL step (s). Default 1e-4.
    pub dt_min: f64,
    /// Largest CFL step (s). Default 5e-3.
    pub dt_max: f64,
    /// CFL step size of the first step (s), at most the step over which gravity alone moves a
    /// particle r/4 (docs/method.md §8). Default 1e-3.
    pub dt_initial: f64,
    /// XSPH viscosity coefficient in [0, 1] (0 = off). Default 0.01.
    pub viscosity: f64,
    /// Worker threads of the world's own thread pool (0 = one per core, at most 1024).
    /// Default 0.
    pub threads: u32,
    /// Kinematic viscosity ν (m²/s) of the implicit physical viscosity solve, finite and
    /// ≥ 0 (0 = off): water is 1e-6, olive oil about 1e-4, honey 1e-2 and more. Stable at
    /// every value and step size. Independent of the XSPH `viscosity`. Default 0.
    pub kinematic_viscosity: f64,
    /// 1: under the physical viscosity the walls, static obstacles and static bodies hold the
    /// fluid with no slip; 0: it slides along them (free slip). Moving bodies and walls built
    /// as fields let it slide either way; no effect while `kinematic_viscosity` is 0.
    /// Default 1.
    pub no_slip: u32,
    /// Where the world's steps run, a `PfBackend` value: `PF_BACKEND_CPU` (0) or
    /// `PF_BACKEND_GPU` (1; single precision, in a library built with the `gpu` feature, on
    /// a machine with a Vulkan adapter). `pf_world_create` opens the GPU and fails, making
    /// no world, where it cannot be had; `pf_params_validate` checks only the value. A world
    /// on the GPU refuses bodies, walls built as fields, surface tension, wall adhesion and
    /// solvers other than `PF_SOLVER_CHEBYSHEV` and `PF_SOLVER_JACOBI1`. Default
    /// `PF_BACKEND_CPU`.
    pub backend: u32,
    /// Vorticity confinement coefficient ε in [0, 10] (dimensionless; 0 = off): an
    /// acceleration ε·H·|ω|·(N × ω) that gives back rotation the solver and XSPH damp
    /// (docs/method.md §15); 0.1–1 is a useful range. Default 0.
    pub vorticity_confinement: f64,
    /// Surface tension σ (N/m) of the world's own fluid (material 0), finite and ≥ 0 (0 =
    /// off, costing nothing): water against air is 0.0728. Other materials have their own
    /// (`pf_world_set_material_surface_tension`). A world with surface tension limits its
    /// steps by the capillary rule (docs/method.md §8); the GPU backend refuses it. Default 0.
    pub surface_tension: f64,
    /// Work of adhesion W (N/m) between every fluid and the walls, static obstacles and
    /// bodies, finite and ≥ 0 (0 = off): with a fluid of surface tension σ the contact angle
    /// θ follows cos θ = W/σ − 1 (W = 2σ wets fully). The GPU backend refuses it. Default 0.
    pub wall_adhesion: f64,
}

impl From<&Params> for PfParams {
    fn from(p: &Params) -> Self {
        let small = |n: usize| u32::try_from(n).unwrap_or(u32::MAX);
        Self {
            particle_radius: p.particle_radius,
            rest_density: p.rest_density,
            mass_factor: p.mass_factor,
            stiffness: p.stiffness,
            gravity: p.gravity,
            solver: match p.solver {
                SolverKind::Chebyshev => PfSolver::PF_SOLVER_CHEBYSHEV,
                SolverKind::Jacobi1 => PfSolver::PF_SOLVER_JACOBI1,
                SolverKind::Jacobi => PfSolver::PF_SOLVER_JACOBI,
                SolverKind::Cg => PfSolver::PF_SOLVER_CG,
                SolverKind::Cg1 => PfSolver::PF_SOLVER_CG1,
                SolverKind::Ldlt => PfSolver::PF_SOLVER_LDLT,
            },
            omega2_rule: match p.chebyshev.omega2_rule {
                Omega2Rule::Chebyshev => PfOmega2Rule::PF_OMEGA2_CHEBYSHEV,
                Omega2Rule::Paper => PfOmega2Rule::PF_OMEGA2_PAPER,
            },
            chebyshev_rho: p.chebyshev.rho,
            chebyshev_delay: small(p.chebyshev.delay),
            chebyshev_gamma: p.chebyshev.gamma,
            chebyshev_auto_rho: u32::from(p.chebyshev.auto_rho),
            projection_weight: match p.projection_weight {
                ProjectionWeight::NeighborCount => PfProjectionWeight::PF_WEIGHT_NEIGHBOR_COUNT,
                ProjectionWeight::Unit => PfProjectionWeight::PF_WEIGHT_UNIT,
                ProjectionWeight::Uniform => PfProjectionWeight::PF_WEIGHT_UNIFORM,
            },
            density_tolerance: p.density_tolerance,
            displacement_tolerance: p.displacement_tolerance,
            warm_start: p.warm_start,
            coarse_correction: u32::from(p.coarse_correction),
            min_outer_iterations: small(p.min_outer_iterations),
            max_outer_iterations: small(p.max_outer_iterations),
            cfl_factor: p.cfl_factor,
            dt_min: p.dt_min,
            dt_max: p.dt_max,
            dt_initial: p.dt_initial,
            viscosity: p.viscosity,
            threads: small(p.threads),
            kinematic_viscosity: p.kinematic_viscosity,
            no_slip: u32::from(p.no_slip),
            backend: match p.backend {
                Backend::Cpu => PfBackend::PF_BACKEND_CPU as u32,
                Backend::Gpu => PfBackend::PF_BACKEND_GPU as u32,
            },
            vorticity_confinement: p.vorticity_confinement,
            surface_tension: p.surface_tension,
            wall_adhesion: p.wall_adhesion,
        }
    }
}

/// Reads `*raw` into validated [`Params`]. Enum fields are read as ints and checked first,
/// so any bit pattern the caller stored is handled without undefined behaviour.
///
/// # Safety
/// `raw` must be non-NULL, aligned and point to `size_of::<PfParams>()` readable bytes.
pub(crate) unsafe fn read_params(raw: *const PfParams) -> Result<Params, Failure> {
    macro_rules! field {
        ($name:ident) => {
            // SAFETY: the caller guarantees `raw` points to a readable PfParams.
            unsafe { ptr::addr_of!((*raw).$name).read() }
        };
    }
    macro_rules! code {
        ($name:ident) => {
            // SAFETY: as above; the field is read as the int it is in C, not as a Rust enum.
            unsafe { ptr::addr_of!((*raw).$name).cast::<c_int>().read() }
        };
    }
    let solver = match code!(solver) {
        0 => SolverKind::Chebyshev,
        1 => SolverKind::Jacobi1,
        2 => SolverKind::Jacobi,
        3 => SolverKind::Cg,
        4 => SolverKind::Cg1,
        5 => SolverKind::Ldlt,
        n => {
            return Err(Failure::invalid(format!(
                "params->solver must be a PfSolver, got {n}"
            )));
        }
    };
    let omega2_rule = match code!(omega2_rule) {
        0 => Omega2Rule::Chebyshev,
        1 => Omega2Rule::Paper,
        n => {
            return Err(Failure::invalid(format!(
                "params->omega2_rule must be a PfOmega2Rule, got {n}"
            )));
        }
    };
    let projection_weight = match code!(projection_weight) {
        0 => ProjectionWeight::NeighborCount,
        1 => ProjectionWeight::Unit,
        2 => ProjectionWeight::Uniform,
        n => {
            return Err(Failure::invalid(format!(
                "params->projection_weight must be a PfProjectionWeight, got {n}"
            )));
        }
    };
    // A 0/1 field named `name`.
    let switch = |value: u32, name: &str| match value {
        0 => Ok(false),
        1 => Ok(true),
        n => Err(Failure::invalid(format!(
            "params->{name} must be 0 or 1, got {n}"
        ))),
    };
    let auto_rho = switch(field!(chebyshev_auto_rho), "chebyshev_auto_rho")?;
    let coarse_correction = switch(field!(coarse_correction), "coarse_correction")?;
    let no_slip = switch(field!(no_slip), "no_slip")?;
    let backend = match field!(backend) {
        0 => Backend::Cpu,
        1 => Backend::Gpu,
        n => {
            return Err(Failure::invalid(format!(
                "params->backend must be PF_BACKEND_CPU (0) or PF_BACKEND_GPU (1), got {n}"
            )));
        }
    };
    let count = |n: u32| n as usize;
    let params = Params {
        particle_radius: field!(particle_radius),
        rest_density: field!(rest_density),
        mass_factor: field!(mass_factor),
        stiffness: field!(stiffness),
        gravity: field!(gravity),
        solver,
        chebyshev: ChebyshevParams {
            rho: field!(chebyshev_rho),
            delay: count(field!(chebyshev_delay)),
            omega2_rule,
            gamma: field!(chebyshev_gamma),
            auto_rho,
        },
        density_tolerance: field!(density_tolerance),
        displacement_tolerance: field!(displacement_tolerance),
        warm_start: field!(warm_start),
        coarse_correction,
        min_outer_iterations: count(field!(min_outer_iterations)),
        max_outer_iterations: count(field!(max_outer_iterations)),
        projection_weight,
        cfl_factor: field!(cfl_factor),
        dt_min: field!(dt_min),
        dt_max: field!(dt_max),
        dt_initial: field!(dt_initial),
        viscosity: field!(viscosity),
        kinematic_viscosity: field!(kinematic_viscosity),
        vorticity_confinement: field!(vorticity_confinement),
        surface_tension: field!(surface_tension),
        wall_adhesion: field!(wall_adhesion),
        no_slip,
        threads: count(field!(threads)),
        backend,
    };
    params
        .validate()
        .map_err(|e| Failure::invalid(format!("params->{e}")))?;
    Ok(params)
}

/// Fills `*out` with the default parameters (particle radius 0.025 m, water, Chebyshev
/// solver; see each field). Returns `PF_ERROR_NULL_POINTER` when `out` is NULL.
///
/// # Safety
/// `out` must be NULL or point to a writable `PfParams`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_params_default(out: *mut PfParams) -> PfStatus {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call("pf_params_default", || {
        args.write(out, PfParams::from(&Params::default()), "out")
    })
}

/// Turns `*params` into the calm settings in place (uniform projection weighting, Chebyshev
/// at a fixed ρ = 0.99 with γ = 0.5, the density rule off (η = 0), τ = 3e-4 times its
/// particle radius, no warm start and no coarse correction), under which a
/// settled tank stays at rest at 2–4 times the outer iterations of the defaults. Every other
/// field is kept. Errors: `PF_ERROR_NULL_POINTER`; `PF_ERROR_INVALID_ARGUMENT` when `*params`
/// does not validate, leaving it unchanged.
///
/// # Safety
/// `params` must be NULL or point to a readable and writable `PfParams`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_params_calm(params: *mut PfParams) -> PfStatus {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call("pf_params_calm", || {
        let calm = args.params(params, "params")?.calm();
        args.write(params, PfParams::from(&calm), "params")
    })
}

/// Checks `*params` without creating a world: `PF_OK` when every field holds a valid value,
/// otherwise `PF_ERROR_INVALID_ARGUMENT` with a message naming the first bad field. Whether
/// `backend = PF_BACKEND_GPU` can be had (the library's `gpu` feature, a Vulkan adapter, a
/// solver the GPU runs) is known only when `pf_world_create` opens it.
///
/// # Safety
/// `params` must be NULL or point to a readable `PfParams`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn pf_params_validate(params: *const PfParams) -> PfStatus {
    // SAFETY: the caller keeps the contract above.
    let args = unsafe { Args::trusted() };
    status_call("pf_params_validate", || {
        args.params(params, "params").map(drop)
    })
}
