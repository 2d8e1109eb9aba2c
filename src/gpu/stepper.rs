//! [`GpuStepper`]: one time step of a world's fluid and static boundary on the device
//! (docs/method.md §1.3), stage by stage as src/step/ takes it on the CPU: the neighbour
//! phase (search.rs), the outer iteration of local steps (local.rs) and global steps with
//! Chebyshev's extrapolation (global.rs) until a stopping rule holds (§4, applied on the
//! device by control.rs, read back once per batch of outer iterations), and the end of the
//! step (finish.rs).
//!
//! Several materials (§14) enter through the projection weights, as on the CPU: every slot
//! holds its particle's material, permuted with it, and [`StepParams::inverse_ratio`] the
//! materials' m/m_k. Vorticity confinement (§15) runs in the end of the step where its ε is
//! set.
//!
//! Left out for now, as CPU-only extras that are off by default: the warm start (§4.1) and
//! the coarse correction (§3.8); a GPU step always starts from s.

use super::buffers::{Buffers, Grid, IterParams, MATERIAL_SLOTS, Statics, StepParams};
use super::context::{Context, Kernel, floats, words};
use super::control::{BATCH, Control, Stop};
use super::finish::{Finish, next_step_size};
use super::global::GlobalStep;
use super::local::LocalStep;
use super::reduce::Reduction;
use super::search::Search;
use super::timer::{Stage, Timer};
use super::viscosity::{ViscositySolve, ViscousStep};
use crate::boundary::Aabb;
use crate::material::MaterialId;
use crate::params::{Params, ProjectionWeight, SolverKind};
use crate::solver::Chebyshev;
use crate::stats::{StepStats, StepTimings};
use crate::{Error, Vec3};
use std::time::Instant;

/// What a [`GpuStepper`] is made from: a world's fluid and static boundary and its settings.
#[derive(Clone, Copy)]
pub(crate) struct Scene<'a> {
    /// Fluid positions (m) and velocities (m/s).
    pub positions: &'a [Vec3],
    pub velocities: &'a [Vec3],
    /// Static boundary particles (m) and their Akinci masses ψ (kg).
    pub boundary: &'a [Vec3],
    pub psi: &'a [f64],
    pub params: &'a Params,
    /// The containers the fluid is kept inside (m; docs/method.md §7).
    pub containers: &'a [Aabb],
    /// Every fluid particle's material, in the order of `positions`.
    pub materials: &'a [MaterialId],
    /// Every material's mass ratio m_k/m = ρ0_k/ρ0 (dimensionless), by id.
    pub mass_ratios: &'a [f64],
    /// Fluid particle mass m (kg).
    pub mass: f64,
    /// The fewest stencils the global step counts a particle in (docs/method.md §3.1).
    pub membership_floor: f64,
    /// The caller's device and queue, or `None` for a device the stepper opens.
    pub device: Option<&'a (wgpu::Device, wgpu::Queue)>,
}

/// The fluid's state read back from the device, in the device's order.
pub(crate) struct Readback {
    /// Positions (m), velocities (m/s) and densities (kg/m³).
    pub positions: Vec<Vec3>,
    pub velocities: Vec<Vec3>,
    pub densities: Vec<f64>,
    /// The pressure each particle's constraint carried through the step's iteration (Pa,
    /// docs/method.md §10.1).
    pub pressures: Vec<f64>,
    /// The index, in the arrays last uploaded, of the particle in each slot.
    pub order: Vec<u32>,
}

/// The fluid of a world on the device, stepped there.
pub(crate) struct GpuStepper {
    ctx: Context,
    grid: Grid,
    buffers: Buffers,
    stages: Stages,
    reduction: Reduction,
    params: Params,
    constants: StepParams,
    chebyshev: Chebyshev,
    /// The host's copies of what [`GpuStepper::upload`] writes, kept between steps.
    staging: Staging,
    /// Whether the schedule on the device is Chebyshev's and for which ρ (its bits).
    schedule: Option<(bool, u64)>,
}

/// Per-particle values in device form on their way to the device: reused by every upload,
/// which allocates only when the fluid grows.
#[derive(Default)]
struct Staging {
    /// Positions or velocities, four floats each.
    vectors: Vec<[f32; 4]>,
    /// Slot indices or materials.
    words: Vec<u32>,
}

impl GpuStepper {
    /// Opens the device and uploads `scene`. Errors when there is no usable adapter, or when
    /// the scene has more particles than the device's indices reach.
    pub fn new(scene: Scene) -> Result<Self, Error> {
        let n = device_count(&scene)?;
        let ctx = match scene.device {
            Some((device, queue)) => Context::on(device.clone(), queue.clone())?,
            None => Context::new()?,
        };
        let scope = ctx.scope();
        let confine = scene.params.vorticity_confinement > 0.0;
        let stages = Stages {
            search: Search::new(&ctx),
            local: LocalStep::new(&ctx),
            global: GlobalStep::new(&ctx),
            finish: Finish::new(&ctx, confine),
            control: Control::new(&ctx),
            viscosity: None,
            timer: Timer::new(&ctx),
        };
        let reduce = Reduction::compile(&ctx);
        let chebyshev = Chebyshev::new(scene.params.chebyshev);
        scope.close(Self::assemble(ctx, stages, reduce, chebyshev, n, scene))
    }

    /// The stepper for `scene`, a world with another number of fluid or boundary particles,
    /// of materials or other parameters, on this stepper's device: its kernels are compiled
    /// again only where vorticity confinement was turned on or off, and the Chebyshev
    /// iteration keeps what it has learnt of ρ unless the solver or its settings changed.
    /// Errors as [`GpuStepper::new`], when the device fails.
    pub fn remake(self, scene: Scene) -> Result<Self, Error> {
        let n = device_count(&scene)?;
        let scope = self.ctx.scope();
        let GpuStepper {
            ctx,
            mut stages,
            reduction,
            mut chebyshev,
            params,
            ..
        } = self;
        let new = scene.params;
        let confine = new.vorticity_confinement > 0.0;
        if confine != (params.vorticity_confinement > 0.0) {
            stages.finish = Finish::new(&ctx, confine);
        }
        if (new.solver, new.chebyshev) != (params.solver, params.chebyshev) {
            chebyshev = Chebyshev::new(new.chebyshev);
        }
        let remade = Self::assemble(ctx, stages, reduction.into_kernel(), chebyshev, n, scene);
        scope.close(remade)
    }

    /// The stepper of `n` fluid particles from `scene` on `ctx`, with its compiled `stages`
    /// and reduction kernel `reduce`, and the iteration `chebyshev`; uploads the fluid.
    fn assemble(
        ctx: Context,
        stages: Stages,
        reduce: Kernel,
        chebyshev: Chebyshev,
        n: u32,
        scene: Scene,
    ) -> Result<Self, Error> {
        let params = scene.params.clone();
        let h = params.support_radius();
        let bounds = [Aabb::around(scene.positions), Aabb::around(scene.boundary)]
            .into_iter()
            .flatten()
            .reduce(|a, b| a.union(&b))
            .unwrap_or(Aabb {
                min: Vec3::zeros(),
                max: Vec3::zeros(),
            });
        let grid = Grid::covering(bounds, h);
        let (boundary, boundary_start) = sort_boundary(&grid, scene.boundary, scene.psi);
        let clearance = crate::step::contain::WALL_CLEARANCE * params.particle_radius;
        let containers = container_table(&grid, scene.containers, clearance);
        let confine = params.vorticity_confinement > 0.0;
        let cells = grid.cells();
        let iterations = params.max_outer_iterations as u64;
        let buffers = Buffers::new(
            &ctx,
            n,
            cells,
            &Statics {
                boundary: &boundary,
                boundary_start: &boundary_start,
                containers: &containers,
            },
            iterations,
            confine,
        );
        let constants = constants(&params, &grid, scene, boundary.len() as u32);
        let reduction = Reduction::new(&ctx, reduce, n, &buffers.values);
        let mut stepper = GpuStepper {
            stages,
            reduction,
            chebyshev,
            params,
            constants,
            grid,
            staging: Staging::default(),
            schedule: None,
            buffers,
            ctx,
        };
        stepper.bind();
        let (ctx, b) = (&stepper.ctx, &stepper.buffers);
        stepper.stages.control.set_rules(ctx, &stepper.params, b.n);
        stepper.upload(scene.positions, scene.velocities, scene.materials)?;
        Ok(stepper)
    }

    /// The number of fluid particles.
    pub fn len(&self) -> usize {
        self.buffers.n as usize
    }

    /// The parameters the stepper steps with.
    pub fn params(&self) -> &Params {
        &self.params
    }

    fn bind(&mut self) {
        let (ctx, b) = (&self.ctx, &self.buffers);
        self.stages.search.bind(ctx, b);
        self.stages.local.bind(ctx, b);
        self.stages.global.bind(ctx, b);
        self.stages.finish.bind(ctx, b);
        self.stages.control.bind(ctx, b, &self.reduction);
        if let Some(viscosity) = &mut self.stages.viscosity {
            viscosity.bind(ctx, b, &self.reduction);
        }
    }

    /// Replaces the fluid's positions (m), velocities (m/s) and materials, as many as the
    /// stepper has; each slot's particle index restarts from its place in these arrays.
    pub fn upload(
        &mut self,
        positions: &[Vec3],
        velocities: &[Vec3],
        materials: &[MaterialId],
    ) -> Result<(), Error> {
        let scope = self.ctx.scope();
        let (b, s, grid) = (&self.buffers, &mut self.staging, &self.grid);
        s.vectors.clear();
        s.vectors
            .extend(positions.iter().map(|&p| grid.device_position(p)));
        self.ctx
            .queue
            .write_buffer(&b.x, 0, bytemuck::cast_slice(&s.vectors));
        s.vectors.clear();
        s.vectors.extend(
            velocities
                .iter()
                .map(|v| [v.x as f32, v.y as f32, v.z as f32, 0.0]),
        );
        self.ctx
            .queue
            .write_buffer(&b.v, 0, bytemuck::cast_slice(&s.vectors));
        s.words.clear();
        s.words.extend(0..b.n);
        self.ctx
            .queue
            .write_buffer(&b.ids, 0, bytemuck::cast_slice(&s.words));
        s.words.clear();
        s.words.extend(materials.iter().map(|&m| u32::from(m)));
        self.ctx
            .queue
            .write_buffer(&b.material, 0, bytemuck::cast_slice(&s.words));
        scope.close(self.ctx.check())
    }

    /// The device's position buffer after the last step, in the device's order of the
    /// particles ([`Readback::order`]), with their count and the point the positions are
    /// measured from (m, world frame): one `vec4<f32>` per particle, x, y, z in metres from
    /// that point and w the pressure the step carried (Pa).
    pub fn positions(&self) -> (&wgpu::Buffer, u32, Vec3) {
        (&self.buffers.x, self.buffers.n, self.grid.centre)
    }

    /// The fluid's state as read back in `parts`: positions, velocities, densities and
    /// each slot's particle, as [`GpuStepper::step`] reads them from the device.
    fn readback(&self, parts: &[Vec<u8>]) -> Readback {
        let grid = &self.grid;
        Readback {
            positions: floats(&parts[0])
                .chunks_exact(4)
                .map(|p| grid.world_position([p[0], p[1], p[2], p[3]]))
                .collect(),
            velocities: floats(&parts[1])
                .chunks_exact(4)
                .map(|v| Vec3::new(v[0].into(), v[1].into(), v[2].into()))
                .collect(),
            densities: floats(&parts[2]).into_iter().map(f64::from).collect(),
            pressures: floats(&parts[0])
                .chunks_exact(4)
                .map(|p| f64::from(p[3]))
                .collect(),
            order: words(&parts[3]),
        }
    }

    /// Advances the fluid by one step of `dt` seconds, each material k of the kinematic
    /// viscosity `viscosities[k]` (m²/s; the physical viscosity is solved where one is
    /// positive); returns what the step did, the size of the next step by the CFL rule (s)
    /// and the fluid's state after it, read back with the step's statistics. Errors when
    /// the device fails; the fluid's state on the device is then undefined.
    pub fn step(
        &mut self,
        dt: f64,
        viscosities: &[f64],
    ) -> Result<(StepStats, f64, Readback), Error> {
        let scope = self.ctx.scope();
        let mut timer = std::mem::take(&mut self.stages.timer);
        timer.start();
        let taken = self.advance(&mut timer, dt, viscosities);
        self.stages.timer = timer;
        scope.close(taken)
    }

    /// [`GpuStepper::step`] within its error scopes, its passes timed by `timer`.
    fn advance(
        &mut self,
        timer: &mut Timer,
        dt: f64,
        viscosities: &[f64],
    ) -> Result<(StepStats, f64, Readback), Error> {
        let viscous = viscosities.iter().any(|&nu| nu > 0.0);
        if viscous && self.stages.viscosity.is_none() {
            let mut solve = ViscositySolve::new(&self.ctx);
            solve.bind(&self.ctx, &self.buffers, &self.reduction);
            self.stages.viscosity = Some(solve);
        }
        let started = Instant::now();
        let params = &self.params;
        let mut constants = self.constants;
        constants.gravity[3] = dt as f32;
        constants.dt2k = (dt * dt * params.stiffness) as f32;
        self.ctx
            .queue
            .write_buffer(&self.buffers.params, 0, bytemuck::bytes_of(&constants));

        let mut encoder = self.ctx.encoder();
        self.stages
            .search
            .record_sort_and_count(&mut encoder, timer, &self.buffers);
        self.record_fill_and_start(&mut encoder, timer);
        self.ctx.queue.submit([encoder.finish()]);
        let mut timings = StepTimings {
            neighbors: started.elapsed().as_secs_f64(),
            ..StepTimings::default()
        };

        let iterated = Instant::now();
        let outcome = self.iterate(timer)?;
        timings.global = iterated.elapsed().as_secs_f64();

        let finished = Instant::now();
        let iter = IterParams {
            gamma: self.params.chebyshev.gamma as f32,
            densities_known: u32::from(outcome.densities_known),
            ..IterParams::default()
        };
        let b = &self.buffers;
        self.ctx
            .queue
            .write_buffer(&b.iter, 0, bytemuck::bytes_of(&iter));
        let mut encoder = self.ctx.encoder();
        self.stages
            .finish
            .record_update(&mut encoder, timer, b, outcome.result);
        if let Some(solve) = self.stages.viscosity.as_ref().filter(|_| viscous) {
            self.ctx.queue.submit([encoder.finish()]);
            let step = ViscousStep {
                params: &self.params,
                viscosities,
                dt,
            };
            solve.solve(&self.ctx, timer, b, &self.reduction, &step)?;
            encoder = self.ctx.encoder();
        }
        self.stages
            .finish
            .record_filters(&mut encoder, timer, b, outcome.result);
        {
            let mut pass = timer.pass(&mut encoder, Stage::End);
            self.reduction.record(&mut pass);
        }
        let n = u64::from(b.n);
        let mut sources = vec![
            (&self.reduction.result, 16),
            (&b.x, n * 16),
            (&b.v, n * 16),
            (&b.density, n * 4),
            (&b.ids, n * 4),
        ];
        let timed = timer.resolve(&mut encoder);
        sources.extend(timed);
        let parts = self.ctx.read_many(encoder, &sources)?;
        let [error_sum, error_max, fastest, _] = <[f32; 4]>::try_from(floats(&parts[0]))
            .map_err(|_| crate::world::gpu_error("a statistics read-back fell short"))?;
        let back = self.readback(&parts[1..5]);
        timings.rest = finished.elapsed().as_secs_f64();
        if let Some(stamps) = parts.get(5) {
            // The device's own times, where it has timestamps.
            let [search, iteration, end] = timer.seconds(stamps);
            (timings.neighbors, timings.global, timings.rest) = (search, iteration, end);
        }
        let stats = StepStats {
            dt,
            outer_iterations: outcome.outer,
            inner_iterations: outcome.outer,
            hit_max_iterations: !outcome.converged,
            rho: outcome.rho,
            last_displacement: outcome.displacement,
            density_error_avg: f64::from(error_sum) / f64::from(b.n.max(1)),
            density_error_max: f64::from(error_max),
            timings,
        };
        Ok((
            stats,
            next_step_size(&self.params, f64::from(fastest)),
            back,
        ))
    }

    /// Records the neighbour lists' fill and X^(0) = X^(−1) = s.
    fn record_fill_and_start(&self, encoder: &mut wgpu::CommandEncoder, timer: &mut Timer) {
        {
            let mut pass = timer.pass(encoder, Stage::Search);
            self.stages.search.record_fill(&mut pass, &self.buffers);
        }
        self.start_from_prediction(encoder);
    }

    /// Records X^(0) = X^(−1) = s.
    fn start_from_prediction(&self, encoder: &mut wgpu::CommandEncoder) {
        let b = &self.buffers;
        for iterate in &b.iterates {
            encoder.copy_buffer_to_buffer(&b.s, 0, iterate, 0, u64::from(b.n) * 16);
        }
    }

    /// The outer iteration (docs/method.md §1.3 step 4, §4), as src/step/iterate.rs: from
    /// X^(0) = X^(−1) = s, a local step, the density rule, a global step with the
    /// extrapolation and the displacement rule, until a rule holds or K_max; a step whose
    /// extrapolation reaches K_max starts over from s without it. Chebyshev's weights are
    /// laid out for every k in advance, and [`BATCH`] outer iterations go to the device at
    /// once, the device applying the rules after each (control.rs); the host reads back
    /// where they stopped, grows the pool of kept corrections where a local step found it
    /// full and takes that iteration again, and restarts for the fallback.
    fn iterate(&mut self, timer: &mut Timer) -> Result<Outcome, Error> {
        let params = self.params.clone();
        let max = params.max_outer_iterations;
        self.chebyshev.reset();
        let mut accelerate = params.solver == SolverKind::Chebyshev;
        let rho = if accelerate {
            self.chebyshev.rho()
        } else {
            0.0
        };
        self.write_schedule(accelerate);
        let iter = IterParams {
            gamma: params.chebyshev.gamma as f32,
            ..IterParams::default()
        };
        let (ctx, b) = (&self.ctx, &self.buffers);
        ctx.queue
            .write_buffer(&b.iter, 0, bytemuck::bytes_of(&iter));
        self.stages.control.start(ctx, b, 0);
        // The next outer iteration to record, the last whose pool was found full, and
        // whether the neighbour lists are yet to be checked against their room.
        let (mut next, mut full_at, mut check_lists) = (0, None, true);
        let standing = loop {
            let mut encoder = self.ctx.encoder();
            if check_lists {
                let mut pass = timer.pass(&mut encoder, Stage::Iteration);
                self.stages.control.record_lists(&mut pass);
            }
            let last = (next + BATCH).min(max);
            for k in next..last {
                self.record_outer_iteration(&mut encoder, timer, k % 2);
            }
            let standing = self
                .stages
                .control
                .read(&self.ctx, &self.buffers, encoder)?;
            check_lists = matches!(standing.stop, Stop::ListsFull { .. });
            match standing.stop {
                Stop::Going if last < max => next = last,
                Stop::Going => {
                    return Err(crate::world::gpu_error(
                        "the outer iteration passed its most iterations on the device",
                    ));
                }
                Stop::Converged => break standing,
                Stop::ListsFull { fluid, boundary } => {
                    if !self.buffers.grow_lists(&self.ctx, fluid, boundary) {
                        return Err(crate::world::gpu_error(
                            "the neighbour lists did not fit the room made for them",
                        ));
                    }
                    self.bind();
                    let mut encoder = self.ctx.encoder();
                    self.record_fill_and_start(&mut encoder, timer);
                    self.ctx.queue.submit([encoder.finish()]);
                    self.stages.control.start(&self.ctx, &self.buffers, 0);
                    next = 0;
                }
                Stop::PoolFull { entries } => {
                    if full_at == Some(standing.k) {
                        return Err(Error::OutOfMemory(format!(
                            "the GPU {} could not make room for the kept corrections of \
                             the local step",
                            self.ctx.adapter
                        )));
                    }
                    full_at = Some(standing.k);
                    self.buffers.grow_pool(&self.ctx, entries);
                    self.bind();
                    self.stages
                        .control
                        .resume(&self.ctx, &self.buffers, standing.k);
                    next = standing.k;
                }
                Stop::Exhausted => {
                    if !accelerate || params.min_outer_iterations >= max {
                        break standing;
                    }
                    // docs/method.md §4, "Fallback".
                    self.learn_rho(standing.k)?;
                    accelerate = false;
                    self.write_schedule(accelerate);
                    let mut encoder = self.ctx.encoder();
                    self.start_from_prediction(&mut encoder);
                    self.ctx.queue.submit([encoder.finish()]);
                    self.stages
                        .control
                        .start(&self.ctx, &self.buffers, standing.outer);
                    (next, full_at) = (0, None);
                }
            }
        };
        if accelerate {
            self.learn_rho(standing.k)?;
        }
        Ok(Outcome {
            outer: standing.outer,
            displacement: standing.displacement,
            rho,
            converged: standing.stop == Stop::Converged,
            densities_known: standing.densities_known,
            result: standing.current,
        })
    }

    /// Lets Chebyshev's online estimate learn from the `k` extrapolated iterations just
    /// taken (docs/method.md §5.3), their displacements read back from the device; nothing
    /// is read where ρ is fixed.
    fn learn_rho(&mut self, k: usize) -> Result<(), Error> {
        if self.params.chebyshev.auto_rho {
            let control = &self.stages.control;
            let displacements = control.displacements(&self.ctx, &self.buffers, k)?;
            self.chebyshev.finish_step(&displacements);
        }
        Ok(())
    }

    /// Writes the schedule of the outer iteration: Chebyshev's ω_k and whether to
    /// extrapolate for every k where `accelerate`, else plain iterations; unless the device
    /// holds it already (the weights depend on ρ alone).
    fn write_schedule(&mut self, accelerate: bool) {
        let key = (accelerate, self.chebyshev.rho().to_bits());
        if self.schedule == Some(key) {
            return;
        }
        self.schedule = Some(key);
        let schedule: Vec<(f64, bool)> = (0..self.params.max_outer_iterations)
            .map(|k| {
                if accelerate {
                    let omega = self.chebyshev.next_weight(k);
                    (omega, self.chebyshev.changes(omega))
                } else {
                    (1.0, false)
                }
            })
            .collect();
        self.stages
            .control
            .set_schedule(&self.ctx, &self.buffers, &schedule);
    }

    /// Records one outer iteration from X^(k) in `b.iterates[current]`: the local and
    /// global steps, their reduction and the stopping rules' decision (control.rs).
    fn record_outer_iteration(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut Timer,
        current: usize,
    ) {
        let b = &self.buffers;
        b.clear_pool(encoder);
        let mut pass = timer.pass(encoder, Stage::Iteration);
        self.stages.local.record(&mut pass, b, current);
        self.stages.global.record(&mut pass, b, current);
        self.reduction.record(&mut pass);
        self.stages.control.record(&mut pass);
    }
}

/// The compiled stages of a step and the timer of their passes, kept when a stepper is
/// remade.
struct Stages {
    search: Search,
    local: LocalStep,
    global: GlobalStep,
    finish: Finish,
    /// The stopping rules of the outer iteration.
    control: Control,
    /// The physical viscosity's solve, compiled at the first step that needs it.
    viscosity: Option<ViscositySolve>,
    timer: Timer,
}

/// The number of fluid particles of `scene` on the device. Errors when the fluid or the
/// boundary has more particles than the device's indices reach.
fn device_count(scene: &Scene) -> Result<u32, Error> {
    let too_many = |what: &str, count: usize| {
        Error::invalid(what, count, "must be fewer than 2³² on the GPU backend")
    };
    let n = u32::try_from(scene.positions.len())
        .map_err(|_| too_many("fluid particles", scene.positions.len()))?;
    u32::try_from(scene.boundary.len())
        .map_err(|_| too_many("boundary particles", scene.boundary.len()))?;
    Ok(n)
}

/// How the outer iteration ended.
struct Outcome {
    outer: usize,
    /// Largest displacement of the last outer iteration (m).
    displacement: f64,
    /// ρ_c of the step (0 without extrapolation).
    rho: f64,
    converged: bool,
    /// The last local step evaluated the densities at the result.
    densities_known: bool,
    /// The iterate buffer that holds the result.
    result: usize,
}

/// The step's constants but Δt and Δt²k, which [`GpuStepper::step`] sets.
fn constants(params: &Params, grid: &Grid, scene: Scene, boundary_n: u32) -> StepParams {
    let h = params.support_radius();
    let kernel = crate::kernel::CubicKernel::new(h);
    let g = params.gravity;
    // m/m_k of every material (at most MATERIAL_SLOTS, as a world holds no more).
    let mut inverse_ratio = [[0.0f32; 4]; MATERIAL_SLOTS / 4];
    for (slot, ratio) in inverse_ratio
        .as_flattened_mut()
        .iter_mut()
        .zip(scene.mass_ratios)
    {
        *slot = (1.0 / ratio) as f32;
    }
    StepParams {
        n: scene.positions.len() as u32,
        boundary_n,
        cells: grid.cells(),
        weight_mode: match params.projection_weight {
            ProjectionWeight::NeighborCount => 0,
            ProjectionWeight::Unit => 1,
            ProjectionWeight::Uniform => 2,
        },
        dims: [grid.dims[0], grid.dims[1], grid.dims[2], 0],
        origin: [
            grid.origin[0],
            grid.origin[1],
            grid.origin[2],
            grid.inverse_cell,
        ],
        gravity: [g[0] as f32, g[1] as f32, g[2] as f32, 0.0],
        kernel: [
            h as f32,
            (1.0 / h) as f32,
            kernel.w_zero() as f32,
            (48.0 / (std::f64::consts::PI * h.powi(4))) as f32,
        ],
        mass: scene.mass as f32,
        rest_density: params.rest_density as f32,
        dt2k: 0.0,
        membership_floor: scene.membership_floor as f32,
        viscosity: params.viscosity as f32,
        rest_stencil: params.rest_stencil_size() as f32,
        newton_limit: (0.25 * h) as f32,
        vorticity: params.vorticity_confinement as f32,
        inverse_ratio,
    }
}

/// The containers in device form (`containers` in shaders/finish.wgsl): a header of their
/// count and the clearance (m), then each container's lowest and highest corner relative to
/// the grid's centre (m).
fn container_table(grid: &Grid, containers: &[Aabb], clearance: f64) -> Vec<[f32; 4]> {
    let mut table = vec![[containers.len() as f32, clearance as f32, 0.0, 0.0]];
    for c in containers {
        table.push(grid.device_position(c.min));
        table.push(grid.device_position(c.max));
    }
    table
}

/// The boundary particles at `points` (m) with masses `psi` (kg) in device form, sorted by
/// the cell of `grid` they lie in (by index within a cell), and each cell's first slot
/// (cells + 1 entries).
fn sort_boundary(grid: &Grid, points: &[Vec3], psi: &[f64]) -> (Vec<[f32; 4]>, Vec<u32>) {
    let device: Vec<[f32; 4]> = points
        .iter()
        .zip(psi)
        .map(|(&p, &psi)| {
            let mut d = grid.device_position(p);
            d[3] = psi as f32;
            d
        })
        .collect();
    let cells: Vec<u32> = device.iter().map(|&p| grid.cell_of(p)).collect();
    let mut order: Vec<u32> = (0..points.len() as u32).collect();
    order.sort_by_key(|&k| cells[k as usize]);
    let mut start = vec![0u32; grid.cells() as usize + 1];
    for &c in &cells {
        start[c as usize + 1] += 1;
    }
    for c in 0..grid.cells() as usize {
        start[c + 1] += start[c];
    }
    let sorted = order.iter().map(|&k| device[k as usize]).collect();
    (sorted, start)
}
