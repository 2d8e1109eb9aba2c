//! One time step (docs/method.md §1.3), as four phases over an explicit [`StepContext`]:
//! [`search`] predicts s = x + Δt·v + Δt²·g, sorts the particles into Z-order and finds
//! neighbours on s; [`iterate`] alternates local projections and global solves (with
//! Chebyshev's extrapolation) until the displacement rule stops; [`finish`] updates the
//! velocities, evaluates densities, applies the non-pressure forces and measures the step;
//! [`next_step_size`] chooses the next Δt by the CFL rule (docs/method.md §8).
//!
//! A step that runs out of memory for what only it can size — neighbour lists beyond their
//! reservation, a rebuilt grid, kept corrections, the body coupling's slots, a factorisation
//! — fails before it moves the fluid, and puts back what it changed until then ([`undo`]).

mod carry;
mod coarse;
pub(crate) mod contain;
mod couple;
mod finish;
pub(crate) mod iterate;
mod search;
mod undo;
mod warm_start;

pub(crate) use couple::{Coupling, Load};
pub(crate) use search::SearchGrid;
pub(crate) use undo::Undo;

use crate::body::Body;
use crate::boundary::{Aabb, Boundary};
use crate::constraint::{Corrections, DensityConstraint, Projection};
use crate::fluid::Fluid;
use crate::forces::NonPressureForce;
use crate::material::Materials;
use crate::neighbors::{CellTable, NeighborLists};
use crate::params::Params;
use crate::solver::{Chebyshev, DiagonalSystem, GlobalSolver};
use crate::stats::{StepStats, StepTimings};
use crate::{Vec3, reduce};
use std::collections::TryReserveError;
use std::time::Instant;

/// Buffers reused by every step, so that a step allocates nothing once sizes are stable.
#[derive(Clone, Debug, Default)]
pub(crate) struct StepBuffers {
    /// X^(k−1), X^(k), X^(k+1) of the outer iteration (m). `current` receives the prediction
    /// s at the start of a step; `previous` also serves the reordering and the non-pressure
    /// forces as scratch. The fused sweep of single-sweep solvers writes X^(k+1) over X^(k−1),
    /// so `next` is used (and filled) only by the other solvers.
    previous: Vec<Vec3>,
    current: Vec<Vec3>,
    next: Vec<Vec3>,
    /// Right-hand side b of the global step (kg·m), for the solvers that are not one
    /// Jacobi sweep (the sweep's is formed a chunk at a time).
    rhs: Vec<Vec3>,
    /// Local-step results per constraint.
    projections: Vec<Projection>,
    /// Corrections P_{i,j} − X_j of multi-step projections (m).
    pub(crate) corrections: Corrections,
    order: Vec<u32>,
    table: CellTable,
    pub(crate) fluid_lists: NeighborLists,
    boundary_lists: NeighborLists,
    /// The projection weight w_j of every fluid particle.
    weights: Vec<f64>,
    system: DiagonalSystem,
    /// δ_k of every outer iteration of the last step (m).
    pub(crate) displacements: Vec<f64>,
    /// The boundary's share of the fluid's displacement, in worlds with bodies.
    coupling: Coupling,
    /// The fluid's load on each body and, last, on the walls.
    loads: Vec<Load>,
    /// What the step changed before it could still fail.
    pub(crate) undo: Undo,
    /// What remains of every slot's warm start X^(0) − s (m), withdrawn as the iteration finds
    /// the fluid under-dense; empty in steps that start from s (docs/method.md §4.1).
    start_offsets: Vec<Vec3>,
    /// The stencil sizes (fluid, boundary members) that every thread's buffers of the local
    /// step have room for ([`crate::constraint::reserve_scratch`]).
    scratch_room: (usize, usize),
    /// The coarse correction's lattice, kept from step to step (docs/method.md §3.8).
    coarse: coarse::CoarseCorrection,
    /// Every slot's mass m_i = ρ0_i·V (kg), from its material (docs/method.md §14).
    masses: Vec<f64>,
    /// The multipliers carried through the iteration, for the step's pressures
    /// (docs/method.md §10.1).
    carry: carry::Carry,
}

/// Everything one time step reads and writes, borrowed from the world that owns it.
pub(crate) struct StepContext<'a> {
    pub params: &'a Params,
    pub constraint: &'a DensityConstraint,
    pub pool: &'a rayon::ThreadPool,
    pub fluid: &'a mut Fluid,
    pub boundary: &'a mut Boundary,
    pub grid: &'a mut SearchGrid,
    pub solver: &'a mut dyn GlobalSolver,
    pub chebyshev: &'a mut Chebyshev,
    pub forces: &'a mut [Box<dyn NonPressureForce>],
    pub buffers: &'a mut StepBuffers,
    pub bodies: &'a mut [Body],
    /// The containers, which keep dynamic bodies inside (docs/method.md §11.4).
    pub containers: &'a [Aabb],
    /// The fluid's load on the walls and static obstacles (written).
    pub wall_load: &'a mut Load,
    /// The fluid's materials: their mass ratios and viscosities (docs/method.md §14).
    pub materials: &'a Materials,
    /// Simulated time at the start of the step (s).
    pub time: f64,
    /// The fastest emitter still emitting after the step (m/s; 0 without any), which the
    /// CFL rule counts like a fluid particle (docs/method.md §12.2).
    pub inflow_speed: f64,
}

/// Advances the fluid by one step of `dt` seconds (positive, finite, checked by the
/// caller) and returns what the step did with the size the next step should take (s).
/// Errors when the step needs more memory than can be had (for neighbour lists, a rebuilt
/// grid, the boundary's sort, kept corrections, the body coupling, the solver's
/// factorisation), having changed nothing: the fluid moves only once the step can no longer
/// fail, and the rest is put back.
pub(crate) fn take_step(ctx: StepContext, dt: f64) -> Result<(StepStats, f64), TryReserveError> {
    let started = Instant::now();
    let StepContext {
        params,
        constraint,
        pool,
        fluid,
        boundary,
        grid,
        solver,
        chebyshev,
        forces,
        buffers,
        bodies,
        containers,
        wall_load,
        materials,
        time,
        inflow_speed,
    } = ctx;
    let gravity = Vec3::from(params.gravity);
    buffers.undo.start(bodies, &buffers.displacements);
    advance_poses(bodies, containers, params.particle_radius, dt, time);
    search::predict(pool, fluid, dt, gravity, &mut buffers.current);
    let mut timings = StepTimings::default();
    let couple = !bodies.is_empty();
    // In worlds with bodies every particle starts from s: a body's load is read from the
    // corrections the iteration makes (docs/method.md §11.3), which a start would bypass.
    let warm = params.warm_start > 0.0 && !couple;
    let iterated = pool.install(|| {
        let grid = grid.sorted(pool, params, &constraint.kernel, boundary, buffers)?;
        if boundary.has_moving() {
            boundary.save(&mut buffers.undo.boundary)?;
            boundary.place_moving(grid, moving_particles(bodies))?;
        }
        search::search(grid, boundary, params.support_radius(), buffers)?;
        // Room for the pressures the step's end writes (docs/method.md §10.1).
        let n = fluid.len();
        crate::reserve::reserve_total(&mut fluid.pressures, n)?;
        slot_masses(
            constraint.mass,
            &materials.mass_ratios,
            &fluid.materials,
            buffers,
        )?;
        reserve_scratch(pool, buffers)?;
        timings.neighbors = started.elapsed().as_secs_f64();
        if couple {
            buffers.coupling.start(
                constraint,
                boundary,
                &buffers.boundary_lists,
                &buffers.current,
                bodies.len(),
            )?;
        }
        iterate::iterate(
            iterate::Iteration {
                params,
                constraint,
                boundary,
                fluid,
                gravity,
                solver,
                chebyshev,
                dt,
                couple,
                warm,
                coarse: params.coarse_correction && !couple,
            },
            buffers,
            &mut timings,
        )
    });
    let outcome = match iterated {
        Ok(outcome) => outcome,
        Err(e) => {
            let displacements = &mut buffers.displacements;
            buffers.undo.restore(grid, boundary, bodies, displacements);
            buffers.release_lists();
            return Err(e);
        }
    };
    buffers.undo.discard();
    let stats = pool.install(|| {
        let t = Instant::now();
        search::permute_fluid(fluid, buffers);
        timings.neighbors += t.elapsed().as_secs_f64();
        // The fluid is in the sort's order now, its positions and velocities still those
        // the step started from. Without the warm start no supports are kept.
        let mut supports = std::mem::take(&mut fluid.supports);
        if warm {
            let predicted = &search::Prediction::new(fluid, None, dt, gravity);
            let (lists, corrections) = (&buffers.fluid_lists, &buffers.corrections);
            let x = &buffers.current;
            let limit = warm_start::SUPPORT_LIMIT * gravity.norm();
            warm_start::record(&mut supports, x, predicted, dt, lists, corrections, limit);
            fluid.supports = supports;
        }
        let lists = &buffers.fluid_lists;
        (buffers.carry).pressures(constraint, lists, dt, &mut fluid.pressures);
        if couple {
            let loads = &mut buffers.loads;
            let predicted = &search::Prediction::new(fluid, None, dt, gravity);
            buffers
                .coupling
                .loads(&buffers.masses, predicted, &buffers.current, dt, loads);
            for (body, load) in bodies.iter_mut().zip(loads.iter()) {
                body.force = load.force;
                body.torque = load.torque_about(&body.centre_of_mass());
                body.accelerate(dt, gravity);
            }
            *wall_load = loads[bodies.len()];
        }
        finish::finish(
            finish::Finish {
                constraint,
                boundary,
                forces,
                viscosities: &materials.viscosities,
                dt,
                containment: contain::Containment {
                    containers,
                    clearance: contain::WALL_CLEARANCE * params.particle_radius,
                },
            },
            fluid,
            buffers,
            outcome,
            &mut timings,
        )
    });
    let speed = fastest_inflow(bodies, inflow_speed);
    let next_dt = pool.install(|| next_step_size(params, &fluid.velocities, gravity, dt, speed));
    Ok((stats, next_dt))
}

/// Every slot's mass (kg) in `b.masses`, in the sort's order: the world's particle mass
/// `mass` (kg) times its material's entry of `ratios` (docs/method.md §14).
fn slot_masses(
    mass: f64,
    ratios: &[f64],
    materials: &[crate::material::MaterialId],
    b: &mut StepBuffers,
) -> Result<(), TryReserveError> {
    crate::reserve::reserve_total(&mut b.masses, b.order.len())?;
    b.masses.clear();
    b.masses.extend(
        b.order
            .iter()
            .map(|&o| mass * ratios[materials[o as usize] as usize]),
    );
    Ok(())
}

/// Makes every thread's buffers of the local step, the gather and the densities room for
/// the largest stencils of the step's lists, when they have less.
fn reserve_scratch(pool: &rayon::ThreadPool, b: &mut StepBuffers) -> Result<(), TryReserveError> {
    let most = (b.fluid_lists.most(), b.boundary_lists.most());
    if most.0 > b.scratch_room.0 || most.1 > b.scratch_room.1 {
        let room = (most.0.max(b.scratch_room.0), most.1.max(b.scratch_room.1));
        crate::constraint::reserve_scratch(pool, room.0, room.1)?;
        b.scratch_room = room;
    }
    Ok(())
}

/// A step of `dt` seconds without fluid particles (all removed, the emitters not yet due,
/// docs/method.md §12.3): the bodies move on without loads, and the statistics are zero
/// apart from Δt. Returns them with the size of the next step (s).
pub(crate) fn idle_step(ctx: StepContext, dt: f64) -> (StepStats, f64) {
    let StepContext {
        params,
        pool,
        bodies,
        containers,
        wall_load,
        time,
        inflow_speed,
        ..
    } = ctx;
    let gravity = Vec3::from(params.gravity);
    advance_poses(bodies, containers, params.particle_radius, dt, time);
    for body in bodies.iter_mut() {
        body.force = Vec3::zeros();
        body.torque = Vec3::zeros();
        body.accelerate(dt, gravity);
    }
    *wall_load = Load::default();
    let speed = fastest_inflow(bodies, inflow_speed);
    let stats = StepStats::idle(dt);
    let next_dt = pool.install(|| next_step_size(params, &[], gravity, dt, speed));
    (stats, next_dt)
}

/// How close (in particle radii r) a dynamic body's particles may come to a container wall:
/// room for one layer of fluid between them, so that a body landing on the floor cannot
/// squeeze the last layer of water through the wall (docs/method.md §11.4).
const CONTACT_CLEARANCE: f64 = 4.0;

/// Moves every body to its pose at the end of a step of `dt` seconds that starts at `time` (s),
/// keeping each dynamic body's particles at least [`CONTACT_CLEARANCE`] particle radii `r` (m)
/// inside the container that holds its centre of mass.
fn advance_poses(bodies: &mut [Body], containers: &[Aabb], r: f64, dt: f64, time: f64) {
    let clearance = CONTACT_CLEARANCE * r;
    for body in bodies.iter_mut() {
        body.advance_pose(dt, time + dt);
        let centre = body.centre_of_mass();
        if let Some(container) = containers.iter().find(|c| c.contains(&centre, 0.0)) {
            body.keep_inside(container, clearance);
        }
    }
}

/// The fastest body particle or emitter inflow `inflow_speed` (m/s), for the CFL rule.
fn fastest_inflow(bodies: &[Body], inflow_speed: f64) -> f64 {
    bodies
        .iter()
        .map(|b| b.max_particle_speed())
        .fold(inflow_speed, f64::max)
}

/// The moving bodies' particles at their poses: position (m), ψ (kg) and owner.
fn moving_particles(bodies: &[Body]) -> impl Iterator<Item = (Vec3, f64, u32)> + '_ {
    bodies
        .iter()
        .enumerate()
        .filter(|(_, b)| b.moves())
        .flat_map(|(o, b)| {
            b.samples
                .iter()
                .zip(&b.psi)
                .map(move |(s, &psi)| (b.pose.apply(s), psi, o as u32))
        })
}

/// The CFL rule (docs/method.md §8, §11, §12.2): Δt = λ·0.4·2r / v_max, clamped to
/// [Δt_min, Δt_max] (s), where v_max is the larger of max|v + Δt g| over the fluid and
/// `body_speed`, the fastest body particle or emitter (m/s), so that no body moves more than
/// a fraction of a particle spacing per step and no inflow arrives too fast.
fn next_step_size(
    params: &Params,
    velocities: &[Vec3],
    gravity: Vec3,
    dt: f64,
    body_speed: f64,
) -> f64 {
    let v_max = reduce::max(velocities, |v| (v + gravity * dt).norm_squared());
    cfl_step(params, v_max.sqrt().max(body_speed))
}

/// The CFL rule's step for the fastest speed `v_max` (m/s, at least √10⁻⁹ counted):
/// λ·0.4·2r / v_max, at most [`weight_step`], clamped to [Δt_min, Δt_max] (s), Δt_min where
/// it is not finite. The CPU and GPU backends both end their steps with it
/// (docs/method.md §8).
pub(crate) fn cfl_step(params: &Params, v_max: f64) -> f64 {
    let v_max = v_max.max(1e-9f64.sqrt());
    let cfl = (cfl_move(params) / v_max).min(weight_step(params));
    if cfl.is_finite() {
        cfl.clamp(params.dt_min, params.dt_max)
    } else {
        params.dt_min
    }
}

/// The farthest the CFL rule lets a particle move in one step, λ·0.4·2r (m).
fn cfl_move(params: &Params) -> f64 {
    params.cfl_factor * 0.4 * params.spacing()
}

/// The longest step (s) over which gravity alone moves a particle from rest at most a quarter
/// of the CFL rule's move: |g|·Δt² ≤ λ·0.4·2r/4 (docs/method.md §8); infinite without
/// gravity. With the default Δt_max it binds only for particles smaller than about a
/// millimetre, where longer steps let the weight of a column at rest push its bottom layer
/// into a wall one layer thick faster than the solve lifts it back.
pub(crate) fn weight_step(params: &Params) -> f64 {
    let g = Vec3::from(params.gravity).norm();
    (0.25 * cfl_move(params) / g).sqrt()
}
