//! Where a world's steps run: on the CPU (the default) or, in builds with the `gpu`
//! feature, on a graphics card ([`Backend::Gpu`], src/gpu/), chosen by
//! [`Params::backend`](crate::Params::backend) when the world is made or by
//! [`World::set_backend`] later. The GPU backend steps the fluid and the static boundary
//! (container walls and obstacles as particles); what it does not reach yet is refused with
//! an error naming it, when it is added to a world on the GPU or when a world holding it is
//! switched there.

use super::World;
use crate::Error;
use crate::params::SolverKind;

/// The hardware a world's time steps run on.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Backend {
    /// The world's own thread pool, in double precision (the default).
    #[default]
    Cpu,
    /// A graphics card through Vulkan compute shaders, in single precision (feature `gpu`),
    /// with several materials, the physical viscosity, vorticity confinement, emitters, sinks
    /// and the domain as on the CPU. Not yet with bodies or walls built as fields; the
    /// solver is Chebyshev's or one Jacobi sweep. The warm start and the coarse correction are left out on it
    /// (docs/method.md §4.1, §3.8).
    Gpu,
}

impl Backend {
    /// Every backend.
    pub const ALL: [Backend; 2] = [Backend::Cpu, Backend::Gpu];

    /// Every backend's name, in the order of [`Backend::ALL`].
    pub const NAMES: [&'static str; 2] = ["cpu", "gpu"];

    /// The backend's name, as `"cpu"` or `"gpu"` (the scene key `backend`, the CLI's
    /// `--backend`).
    pub fn name(self) -> &'static str {
        Self::NAMES[self as usize]
    }

    /// Parses a backend's name (see [`Backend::name`]).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|b| b.name() == name)
    }
}

/// An error of the GPU backend, [`Error::InvalidArgument`] for the field `backend`, its
/// message `backend gpu: ` and what went wrong or is missing.
pub(crate) fn gpu_error(what: &str) -> Error {
    Error::InvalidArgument {
        field: "backend".into(),
        message: format!("backend gpu: {what}"),
    }
}

/// The GPU backend's refusal of `what`, which it does not step yet.
fn unsupported(what: &str) -> Error {
    gpu_error(&format!("does not support {what} yet; use the CPU backend"))
}

/// How a refusal names surface tension, which the GPU backend does not step.
pub(super) const SURFACE_TENSION: &str = "surface tension (surface_tension)";

/// How a refusal names the adhesion to walls, which the GPU backend does not step.
#[cfg(feature = "gpu")]
pub(super) const WALL_ADHESION: &str = "the adhesion to walls (wall_adhesion)";

/// Whether the GPU backend steps with the global solver `kind`.
fn gpu_solver(kind: SolverKind) -> bool {
    matches!(kind, SolverKind::Chebyshev | SolverKind::Jacobi1)
}

impl World {
    /// The backend the world steps on.
    pub fn backend(&self) -> Backend {
        #[cfg(feature = "gpu")]
        if self.gpu.is_some() {
            return Backend::Gpu;
        }
        Backend::Cpu
    }

    /// Chooses where the world's steps run, and sets
    /// [`Params::backend`](crate::Params::backend) to it. [`Backend::Gpu`] opens the first
    /// Vulkan adapter at once; the fluid is uploaded at the next step. Errors, changing
    /// nothing, naming the backend and what is missing: a build without the `gpu` feature,
    /// no Vulkan loader or adapter, or a world with what the GPU backend does not step yet.
    pub fn set_backend(&mut self, backend: Backend) -> Result<(), Error> {
        match backend {
            Backend::Cpu => {
                #[cfg(feature = "gpu")]
                {
                    self.gpu = None;
                }
            }
            Backend::Gpu => self.open_gpu()?,
        }
        self.params.backend = backend;
        Ok(())
    }

    /// Errors, naming `what`, when the world steps on the GPU, which does not step `what`
    /// yet: the refusal of a call that would add it.
    pub(super) fn refuse_on_gpu(&self, what: &str) -> Result<(), Error> {
        match self.backend() {
            Backend::Gpu => Err(unsupported(what)),
            Backend::Cpu => Ok(()),
        }
    }

    /// Errors, naming the solver, when the world steps on the GPU and `kind` is a global
    /// solver the GPU backend does not run.
    pub(super) fn refuse_solver_on_gpu(&self, kind: SolverKind) -> Result<(), Error> {
        if gpu_solver(kind) {
            return Ok(());
        }
        self.refuse_on_gpu(&format!("the {} solver", kind.name()))
    }

    #[cfg(not(feature = "gpu"))]
    fn open_gpu(&mut self) -> Result<(), Error> {
        Err(gpu_error(
            "not available: this build of projfluid has no `gpu` feature",
        ))
    }

    #[cfg(feature = "gpu")]
    fn open_gpu(&mut self) -> Result<(), Error> {
        self.check_gpu_world()?;
        if self.gpu.is_none() {
            self.gpu = Some(Box::new(GpuSlot::on(None)));
            // The device is opened now, so that a missing adapter is reported here.
            if let Err(e) = crate::gpu::probe() {
                self.gpu = None;
                return Err(e);
            }
        }
        Ok(())
    }

    /// Errors, naming the feature, when the world holds what the GPU backend does not step.
    #[cfg(feature = "gpu")]
    pub(super) fn check_gpu_world(&self) -> Result<(), Error> {
        let refuse = |what: &str| Err(unsupported(what));
        if !gpu_solver(self.params.solver) {
            return refuse(&format!("the {} solver", self.params.solver.name()));
        }
        if !self.bodies.is_empty() {
            return refuse("bodies");
        }
        if !self.boundary.walls.is_empty() {
            return refuse("container walls built as fields");
        }
        if self.materials.tense() {
            return refuse(SURFACE_TENSION);
        }
        if self.params.wall_adhesion > 0.0 {
            return refuse(WALL_ADHESION);
        }
        Ok(())
    }

    /// One step of `dt` seconds on the device, after [`World::prepare_steps`]: the emitters
    /// insert their due layers on the host, the fluid is uploaded (the stepper made again
    /// on the same device where the particles or the materials changed in number or the
    /// parameters changed), stepped
    /// and read back, then sinks and the domain remove what left. Errors, the emission
    /// undone, when the device fails or the emission needs more memory than can be had.
    #[cfg(feature = "gpu")]
    pub(super) fn take_gpu_step(&mut self, dt: f64) -> Result<&crate::stats::StepStats, Error> {
        self.check_gpu_world()?;
        self.start_step()
            .map_err(|_| Error::out_of_memory("the working storage of a time step"))?;
        let taken = self.gpu_step(dt);
        self.end_step(taken, dt)
    }

    /// The device's part of [`World::take_gpu_step`]: uploads, steps and reads back the
    /// fluid, and returns the step's statistics with the next step's size (s), the CFL rule
    /// counting the emitters' inflow as the CPU's does. A world without fluid only moves
    /// its clock.
    #[cfg(feature = "gpu")]
    fn gpu_step(&mut self, dt: f64) -> Result<(crate::stats::StepStats, f64), Error> {
        let inflow = self.inflow_speed(self.time + dt);
        if self.fluid.len() == 0 {
            let stats = crate::stats::StepStats::idle(dt);
            return Ok((stats, crate::step::cfl_step(&self.params, inflow)));
        }
        let fluid_len = self.fluid.len();
        let boundary_len = self.boundary.len();
        let slot = self.gpu.as_deref_mut().expect("the GPU backend is chosen");
        let material_count = self.materials.len();
        let stale = slot.boundary_len != boundary_len
            || slot.material_count != material_count
            || slot
                .context
                .as_ref()
                .is_none_or(|s| s.len() != fluid_len || s.params() != &self.params);
        if stale {
            let device = slot.device.clone();
            let (points, psi) = self.static_boundary()?;
            let scene = crate::gpu::Scene {
                positions: &self.fluid.positions,
                velocities: &self.fluid.velocities,
                boundary: &points,
                psi: &psi,
                materials: &self.fluid.materials,
                mass_ratios: &self.materials.mass_ratios,
                params: &self.params,
                containers: &self.containers,
                mass: self.constraint.mass,
                membership_floor: self.constraint.membership_floor,
                device: device.as_ref(),
            };
            let slot = self.gpu.as_deref_mut().expect("the GPU backend is chosen");
            let stepper = match slot.context.take() {
                Some(stepper) => stepper.remake(scene)?,
                None => crate::gpu::GpuStepper::new(scene)?,
            };
            slot.context = Some(stepper);
            slot.boundary_len = boundary_len;
            slot.material_count = material_count;
        } else if let Some(stepper) = slot.context.as_mut() {
            let fluid = &self.fluid;
            stepper.upload(&fluid.positions, &fluid.velocities, &fluid.materials)?;
        }
        let slot = self.gpu.as_deref_mut().expect("the GPU backend is chosen");
        let stepper = slot.context.as_mut().expect("made above");
        let (stats, next_dt, back) = stepper.step(dt, &self.materials.viscosities)?;
        let fluid = &mut self.fluid;
        // The device's order: every per-particle array the world keeps follows it (the
        // materials of a world of one are all 0 already).
        let ids: Vec<u64> = back.order.iter().map(|&k| fluid.ids[k as usize]).collect();
        if !self.materials.single() {
            let materials = back.order.iter().map(|&k| fluid.materials[k as usize]);
            fluid.materials = materials.collect();
        }
        fluid.ids = ids;
        fluid.positions = back.positions;
        fluid.velocities = back.velocities;
        fluid.densities = back.densities;
        fluid.supports.clear();
        fluid.pressures = back.pressures;
        let inflow_dt = crate::step::cfl_step(&self.params, inflow);
        Ok((stats, next_dt.min(inflow_dt)))
    }

    /// The static boundary particles (m) with their Akinci masses ψ (kg), computed here
    /// where no CPU step has yet.
    #[cfg(feature = "gpu")]
    fn static_boundary(&self) -> Result<(Vec<crate::Vec3>, Vec<f64>), Error> {
        let points = self.boundary.positions.to_vec();
        if !self.boundary.dirty && self.boundary.psi.len() == points.len() {
            return Ok((points, self.boundary.psi.clone()));
        }
        let Some(bounds) = crate::boundary::Aabb::around(&points) else {
            return Ok((points, Vec::new()));
        };
        let h = self.params.support_radius();
        let pad = crate::Vec3::repeat(2.0 * h);
        let oom = |_| Error::out_of_memory("the boundary's masses");
        let grid = crate::neighbors::UniformGrid::covering(bounds.min - pad, bounds.max + pad, h)
            .map_err(oom)?;
        let psi = self.static_masses(&grid, &points).map_err(oom)?;
        Ok((points, psi))
    }
}

/// The GPU backend's state in a world: the stepper, made at the first step and again when
/// the particles or the materials change in number.
#[cfg(feature = "gpu")]
pub(crate) struct GpuSlot {
    pub(super) context: Option<crate::gpu::GpuStepper>,
    /// The caller's device and queue ([`World::set_gpu_device`]), or `None` for one the
    /// stepper opens.
    pub(super) device: Option<(wgpu::Device, wgpu::Queue)>,
    /// Boundary particles the stepper was made with.
    pub(super) boundary_len: usize,
    /// Materials the stepper was made with (their mass ratios are among its constants).
    pub(super) material_count: usize,
}

#[cfg(feature = "gpu")]
impl GpuSlot {
    /// A slot whose stepper is made at the next step, on `device` (the caller's device and
    /// queue) or on one it opens.
    pub(super) fn on(device: Option<(wgpu::Device, wgpu::Queue)>) -> Self {
        Self {
            context: None,
            device,
            boundary_len: usize::MAX,
            material_count: 0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Params;

    /// Worlds are made on the CPU unless their parameters say otherwise, and
    /// [`World::set_backend`] keeps `params.backend` in step with the backend.
    #[test]
    fn the_cpu_is_the_default_and_params_follow_set_backend() {
        assert_eq!(Params::default().backend, Backend::Cpu);
        let mut world = World::new(Params::default()).unwrap();
        assert_eq!(
            (world.backend(), world.params().backend),
            (Backend::Cpu, Backend::Cpu)
        );
        world.set_backend(Backend::Cpu).unwrap();
        assert_eq!(world.params().backend, Backend::Cpu);
        for backend in Backend::ALL {
            assert_eq!(Backend::from_name(backend.name()), Some(backend));
        }
        assert_eq!(Backend::from_name("GPU"), None);
    }

    /// In a build without the `gpu` feature a world asked for on the GPU is not made, and a
    /// world on the CPU asked to switch stays there, unchanged, its parameters too; the
    /// error names the backend and the missing feature.
    #[cfg(not(feature = "gpu"))]
    #[test]
    fn the_gpu_is_refused_where_the_build_lacks_it() {
        let expected = Error::InvalidArgument {
            field: "backend".into(),
            message: "backend gpu: not available: this build of projfluid has no `gpu` feature"
                .into(),
        };
        let gpu = Params {
            backend: Backend::Gpu,
            ..Params::default()
        };
        gpu.validate().unwrap();
        assert_eq!(World::new(gpu.clone()).err(), Some(expected.clone()));
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        assert_eq!(World::with_pool(gpu, pool).err(), Some(expected.clone()));
        let mut world = World::new(Params::default()).unwrap();
        world
            .add_fluid_block(crate::Vec3::zeros(), [2, 2, 2], crate::Vec3::zeros())
            .unwrap();
        let before = world.positions_hash();
        assert_eq!(world.set_backend(Backend::Gpu), Err(expected));
        assert_eq!(
            (world.backend(), world.params().backend),
            (Backend::Cpu, Backend::Cpu)
        );
        assert_eq!(world.positions_hash(), before);
        world.step().unwrap();
    }
}
