//! The world: fluid particles, static boundary particles, parameters, the state of time
//! stepping and the world's own thread pool. The CLI and the C API are thin shells over it.
//! Its methods are grouped by what they do: [`fill`] adds particles, containers and meshes,
//! [`emitters`] and [`sinks`] add and remove fluid as the run goes, [`read`] reports
//! particles and measures, [`stepping`] advances time, [`state`] exports and imports the
//! exact state, and [`snapshot`] sorts the particles for the readings taken between steps.

mod backend;
mod bodies;
mod emitters;
mod fill;
#[cfg(feature = "gpu")]
mod gpu_device;
mod materials;
mod placement;
mod read;
mod sinks;
mod snapshot;
mod state;
mod stepping;
#[cfg(test)]
mod tests;

pub use backend::Backend;
#[cfg(feature = "gpu")]
pub(crate) use backend::gpu_error;
pub use bodies::BodyId;
pub use emitters::EmitterId;
#[cfg(feature = "gpu")]
pub use gpu_device::GpuPositions;
pub use sinks::SinkId;
pub(crate) use snapshot::Snapshot;
pub use state::{GridParts, WorldState};

use crate::body::Body;
use crate::boundary::mesh::TriangleMesh;
use crate::boundary::{Aabb, Boundary};
use crate::constraint::{DensityConstraint, MEMBERSHIP_FLOOR};
use crate::emitter::Emitter;
use crate::fluid::Fluid;
use crate::forces::{self, NonPressureForce};
use crate::kernel::CubicKernel;
use crate::material::Materials;
use crate::params::{Params, SolverKind};
use crate::solver::{Chebyshev, GlobalSolver, linear_solver};
use crate::stats::StepStats;
use crate::step::{Load, SearchGrid, StepBuffers};
use crate::{Error, Vec3};

/// A fluid simulation: particles, boundaries, parameters and the state of time stepping.
pub struct World {
    pub(crate) params: Params,
    pub(crate) constraint: DensityConstraint,
    pub(crate) pool: rayon::ThreadPool,
    pub(crate) fluid: Fluid,
    /// The fluid's materials (docs/method.md §14).
    pub(crate) materials: Materials,
    pub(crate) boundary: Boundary,
    /// Container boxes; fluid outside all of them counts as escaped.
    pub(crate) containers: Vec<Aabb>,
    /// How many fluid particles the last call that adds fluid made (the rest lay inside a
    /// solid).
    pub(crate) last_added: usize,
    /// The static obstacles' meshes that are closed, whose inside no fluid is placed in.
    pub(crate) obstacles: Vec<TriangleMesh>,
    /// Sink boxes: fluid in them at the end of a step is removed.
    pub(crate) sinks: Vec<Aabb>,
    /// Fluid outside the domain at the end of a step is removed.
    pub(crate) domain: Option<Aabb>,
    /// Emitters, in the order they were added.
    pub(crate) emitters: Vec<Emitter>,
    pub(crate) grid: SearchGrid,
    /// Rigid bodies, in the order they were added.
    pub(crate) bodies: Vec<Body>,
    /// The fluid's load on the walls and static obstacles in the last step.
    pub(crate) wall_load: Load,
    pub(crate) solver: Box<dyn GlobalSolver>,
    pub(crate) chebyshev: Chebyshev,
    /// Viscosity and the other non-pressure forces, in the order they apply.
    pub(crate) forces: Vec<Box<dyn NonPressureForce>>,
    pub(crate) buffers: StepBuffers,
    pub(crate) time: f64,
    pub(crate) next_dt: f64,
    pub(crate) steps: u64,
    pub(crate) last: Option<StepStats>,
    /// The GPU backend's stepper, while the world steps on the device ([`Backend::Gpu`]).
    #[cfg(feature = "gpu")]
    pub(crate) gpu: Option<Box<backend::GpuSlot>>,
}

impl World {
    /// An empty world with the given parameters (validated), on the backend
    /// `params.backend` names (see [`World::with_pool`]).
    pub fn new(params: Params) -> Result<Self, Error> {
        params.validate()?;
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(params.threads)
            .build()
            .map_err(|e| {
                Error::invalid("threads", params.threads, &format!("could not start: {e}"))
            })?;
        Self::with_pool(params, pool)
    }

    /// An empty world with the given parameters (validated) that runs on `pool`, which the
    /// caller built (e.g. to join its threads after dropping the world, as the C API does).
    /// `params.threads` is kept as given; the pool's own size decides the parallelism.
    /// With [`Backend::Gpu`] in `params.backend` the GPU is opened here, and the errors of
    /// [`World::set_backend`] (no `gpu` feature, no Vulkan adapter, a solver or viscosity
    /// the GPU backend does not run) are this function's: no world is made.
    pub fn with_pool(params: Params, pool: rayon::ThreadPool) -> Result<Self, Error> {
        params.validate()?;
        let backend = params.backend;
        let mut world = Self {
            constraint: DensityConstraint {
                kernel: CubicKernel::new(params.support_radius()),
                mass: params.particle_mass(),
                rest_density: params.rest_density,
                weight: params.projection_weight,
                rest_stencil_size: params.rest_stencil_size(),
                membership_floor: MEMBERSHIP_FLOOR,
                materialize_all: false,
                portable: false,
                evaluate_first_step: false,
            },
            pool,
            fluid: Fluid::default(),
            materials: Materials::new(params.kinematic_viscosity, params.surface_tension),
            boundary: Boundary::default(),
            containers: Vec::new(),
            obstacles: Vec::new(),
            last_added: 0,
            sinks: Vec::new(),
            domain: None,
            emitters: Vec::new(),
            grid: SearchGrid::default(),
            bodies: Vec::new(),
            wall_load: Load::default(),
            solver: linear_solver(params.solver),
            chebyshev: Chebyshev::new(params.chebyshev),
            forces: forces::of_world(
                &params,
                &Materials::new(params.kinematic_viscosity, params.surface_tension),
            ),
            buffers: StepBuffers::default(),
            time: 0.0,
            next_dt: (params.dt_initial)
                .min(crate::step::weight_step(&params))
                .clamp(params.dt_min, params.dt_max),
            steps: 0,
            last: None,
            #[cfg(feature = "gpu")]
            gpu: None,
            params,
        };
        if backend == Backend::Gpu {
            world.set_backend(backend)?;
        }
        Ok(world)
    }

    /// The world's parameters.
    pub fn params(&self) -> &Params {
        &self.params
    }

    /// Switches the global solver (and Chebyshev settings) between steps. Errors, changing
    /// nothing, on settings [`Params::validate`] rejects, and on a world on the GPU for a
    /// solver the GPU backend does not run (it runs Chebyshev's and one Jacobi sweep).
    pub fn set_solver(
        &mut self,
        kind: SolverKind,
        chebyshev: crate::params::ChebyshevParams,
    ) -> Result<(), Error> {
        let mut params = self.params.clone();
        params.solver = kind;
        params.chebyshev = chebyshev;
        params.validate()?;
        self.refuse_solver_on_gpu(kind)?;
        self.params = params;
        self.solver = linear_solver(kind);
        self.chebyshev = Chebyshev::new(chebyshev);
        Ok(())
    }

    /// Changes the outer loop's iteration limits between steps: at least `min` and at most
    /// `max` outer iterations per step (min = max forces a fixed count, as ρ estimation
    /// needs). Rejects values that [`Params::validate`] rejects, changing nothing.
    pub fn set_outer_iterations(&mut self, min: usize, max: usize) -> Result<(), Error> {
        self.change_params(|p| {
            p.min_outer_iterations = min;
            p.max_outer_iterations = max;
        })
    }

    /// Changes the outer stopping threshold τ (m) between steps. Rejects values that
    /// [`Params::validate`] rejects, changing nothing.
    pub fn set_displacement_tolerance(&mut self, tolerance: f64) -> Result<(), Error> {
        self.change_params(|p| p.displacement_tolerance = tolerance)
    }

    /// Changes the outer stopping threshold η on the average density error (dimensionless,
    /// 0 = off) between steps. Rejects values that [`Params::validate`] rejects, changing
    /// nothing.
    pub fn set_density_tolerance(&mut self, tolerance: f64) -> Result<(), Error> {
        self.change_params(|p| p.density_tolerance = tolerance)
    }

    /// Applies `change` to a copy of the parameters and keeps it if it validates.
    fn change_params(&mut self, change: impl FnOnce(&mut Params)) -> Result<(), Error> {
        let mut params = self.params.clone();
        change(&mut params);
        params.validate()?;
        self.params = params;
        Ok(())
    }

    /// Number of fluid particles.
    pub fn fluid_count(&self) -> usize {
        self.fluid.positions.len()
    }

    /// How many fluid particles the last [`World::add_fluid_block`] or
    /// [`World::add_fluid_particles`] made: those asked for less the ones that lay inside a
    /// solid (0 before any such call).
    pub fn last_added_count(&self) -> usize {
        self.last_added
    }

    /// Number of boundary particles.
    pub fn boundary_count(&self) -> usize {
        self.boundary.len()
    }

    /// Simulated time (s).
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Steps taken so far.
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// The time step (s) the next CFL-limited step will use: the CFL rule's, at most the
    /// capillary limit where the world has surface tension or wall adhesion
    /// (docs/method.md §8).
    pub fn next_dt(&self) -> f64 {
        self.next_dt
            .min(self.materials.capillary_step(&self.params))
    }

    /// Statistics of the last step, if any step was taken.
    pub fn last_step(&self) -> Option<&StepStats> {
        self.last.as_ref()
    }

    /// δ_k, the largest particle displacement (m) of each outer iteration of the last step.
    pub fn last_displacements(&self) -> &[f64] {
        &self.buffers.displacements
    }

    /// The container boxes added so far.
    pub fn containers(&self) -> &[Aabb] {
        &self.containers
    }

    /// Fluid particle mass m (kg).
    pub fn particle_mass(&self) -> f64 {
        self.constraint.mass
    }

    /// Worker threads of the world's pool.
    pub fn thread_count(&self) -> usize {
        self.pool.current_num_threads()
    }
}

fn check_finite(field: &str, values: &[Vec3]) -> Result<(), Error> {
    match values.iter().position(|v| !v.iter().all(|c| c.is_finite())) {
        Some(i) => Err(Error::invalid(
            format!("{field}[{i}]"),
            format!("{:?}", values[i].as_slice()),
            "must be finite",
        )),
        None => Ok(()),
    }
}

/// Most particles of one kind (fluid or boundary) a world holds; indices must fit in u32 with room.
const MAX_PARTICLES: usize = u32::MAX as usize / 64;

/// The number of samples [`sample_box_walls`] makes for `container` (computed in f64, so that
/// absurd boxes are rejected before anything is allocated).
fn box_wall_sample_count(container: &Aabb, spacing: f64, layers: usize) -> f64 {
    (0..layers)
        .map(|layer| {
            let extent = container.max - container.min + Vec3::repeat(2.0 * layer as f64 * spacing);
            let n = extent.map(|e| (e / spacing).ceil().max(1.0));
            let outer = (n.x + 1.0) * (n.y + 1.0) * (n.z + 1.0);
            let inner = (n.x - 1.0) * (n.y - 1.0) * (n.z - 1.0);
            outer - inner
        })
        .sum()
}
