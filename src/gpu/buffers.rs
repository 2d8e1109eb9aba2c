//! The particle state on the device, in single precision: the fluid's arrays in the order
//! of the last sort, the static boundary sorted by cell once, the grid, the neighbour lists
//! (CSR, grown as a step needs) and the iterates of the outer iteration; with the uniform
//! constants the kernels read ([`StepParams`], [`IterParams`]).
//!
//! Positions on the device are relative to the grid's centre, so that single precision
//! keeps its resolution wherever the scene lies.

use super::context::Context;
use crate::Vec3;
use crate::boundary::Aabb;
use bytemuck::{Pod, Zeroable};

/// The most grid cells: a larger domain gets larger cells (still at least H, so the search
/// stays correct, only slower).
const MAX_CELLS: f64 = (1u64 << 24) as f64;
/// Cells are this much wider than H, so that rounding never puts two particles within H
/// of each other two cells apart.
const CELL_SLACK: f64 = 1.0 + 1e-4;
/// The neighbour lists and the pool of kept corrections are grown to this multiple of what
/// a step needs.
const LIST_GROWTH: f64 = 1.25;
/// Fluid and boundary list entries per particle the lists start with, below what a fluid at
/// rest needs (about 30 fluid neighbours), so that they grow to what the first step needs.
const INITIAL_FLUID_ROOM: u64 = 24;
const INITIAL_BOUNDARY_ROOM: u64 = 4;
/// Entries the pool of kept corrections starts with: one (a binding of it holds one at
/// least), as few projections take more than one step (shaders/project.wgsl); the pool
/// grows to what the local steps ask for.
const INITIAL_POOL: u64 = 1;
/// The pool's header (cursor and overflow flag), in vec4 slots.
const POOL_HEADER: u64 = 1;

/// Entries of the material table in [`StepParams`] (`inverse_ratio` in shaders/common.wgsl):
/// one for every material a world can hold.
pub(super) const MATERIAL_SLOTS: usize = 256;
const _: () = assert!(crate::material::MAX_MATERIALS <= MATERIAL_SLOTS);

/// The step's constants as the shaders read them (`StepParams` in shaders/common.wgsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub(super) struct StepParams {
    pub n: u32,
    pub boundary_n: u32,
    pub cells: u32,
    /// 0 neighbour count, 1 unit, 2 uniform (docs/method.md §2.5).
    pub weight_mode: u32,
    pub dims: [u32; 4],
    /// The grid's lowest corner (m, relative to its centre) and 1/cell size (1/m).
    pub origin: [f32; 4],
    /// g (m/s²) and Δt (s).
    pub gravity: [f32; 4],
    /// H (m), 1/H (1/m), σ (1/m³), 48/(πH⁴) (1/m⁴).
    pub kernel: [f32; 4],
    /// m (kg), ρ0 (kg/m³), Δt²k (kg), the membership floor.
    pub mass: f32,
    pub rest_density: f32,
    pub dt2k: f32,
    pub membership_floor: f32,
    /// XSPH c_X, the rest stencil size c, the Newton step limit H/4 (m), the vorticity
    /// confinement's ε (dimensionless, 0 = off; docs/method.md §15).
    pub viscosity: f32,
    pub rest_stencil: f32,
    pub newton_limit: f32,
    pub vorticity: f32,
    /// m/m_k = ρ0/ρ0_k of every material k (dimensionless; 0 past the world's materials),
    /// four to an entry: what divides a particle's projection weight by its mass ratio
    /// (docs/method.md §14).
    pub inverse_ratio: [[f32; 4]; MATERIAL_SLOTS / 4],
}

/// The outer iteration's constants besides its schedule (`IterParams` in
/// shaders/sweep.wgsl, finish.wgsl; ω_k and whether to extrapolate are in
/// [`Buffers::schedule`]).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub(super) struct IterParams {
    /// Chebyshev's γ.
    pub gamma: f32,
    /// 1 when the last local step's densities are the result's.
    pub densities_known: u32,
    pub pad: [u32; 2],
}

/// A uniform grid of cells at least H wide over a fixed box; particles outside it are
/// counted in its edge cells (docs/method.md §6).
#[derive(Clone, Copy, Debug)]
pub(super) struct Grid {
    /// Where device positions are measured from (m, world frame).
    pub centre: Vec3,
    /// The lowest corner relative to `centre` (m) in single precision, and 1/cell size.
    pub origin: [f32; 3],
    pub inverse_cell: f32,
    pub dims: [u32; 3],
}

impl Grid {
    /// A grid over `bounds` (m) padded by two support radii `h` (m) and a tenth of its
    /// extent, with cells of H or, in a very large box, wider.
    pub fn covering(bounds: Aabb, h: f64) -> Self {
        let pad = Vec3::repeat(2.0 * h) + (bounds.max - bounds.min) * 0.1;
        let (min, max) = (bounds.min - pad, bounds.max + pad);
        let extent = max - min;
        let mut cell = h * CELL_SLACK;
        let count = |cell: f64| extent.map(|e| (e / cell).ceil().max(1.0));
        let cells = count(cell);
        let total = cells.x * cells.y * cells.z;
        if total > MAX_CELLS {
            cell *= (total / MAX_CELLS).cbrt() * CELL_SLACK;
        }
        let cells = count(cell);
        let centre = (min + max) * 0.5;
        let origin = min - centre;
        Grid {
            centre,
            origin: [origin.x as f32, origin.y as f32, origin.z as f32],
            inverse_cell: (1.0 / cell) as f32,
            dims: [cells.x as u32, cells.y as u32, cells.z as u32],
        }
    }

    /// The number of cells.
    pub fn cells(&self) -> u32 {
        self.dims[0] * self.dims[1] * self.dims[2]
    }

    /// A world position (m) as the device holds it.
    pub fn device_position(&self, p: Vec3) -> [f32; 4] {
        let r = p - self.centre;
        [r.x as f32, r.y as f32, r.z as f32, 0.0]
    }

    /// A device position back in the world frame (m).
    pub fn world_position(&self, p: [f32; 4]) -> Vec3 {
        Vec3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2])) + self.centre
    }

    /// The cell of a device position, in the very arithmetic of `cell_coords` in
    /// shaders/common.wgsl.
    pub fn cell_of(&self, p: [f32; 4]) -> u32 {
        let c: [u32; 3] = std::array::from_fn(|k| {
            let top = self.dims[k] as f32 - 1.0;
            let c = ((p[k] - self.origin[k]) * self.inverse_cell).floor();
            c.clamp(0.0, top) as u32
        });
        c[0] + self.dims[0] * (c[1] + self.dims[1] * c[2])
    }
}

/// Every buffer of the step on the device.
pub(super) struct Buffers {
    /// Fluid particles.
    pub n: u32,
    pub cells: u32,
    /// x^n (m, relative), v (m/s), s (m), each slot's particle (its index at upload) and
    /// its material (an index into [`StepParams::inverse_ratio`]).
    pub x: wgpu::Buffer,
    pub v: wgpu::Buffer,
    pub s: wgpu::Buffer,
    pub ids: wgpu::Buffer,
    pub material: wgpu::Buffer,
    /// The permutation's targets, then the XSPH filter's velocities.
    pub x_out: wgpu::Buffer,
    pub v_out: wgpu::Buffer,
    pub s_out: wgpu::Buffer,
    pub ids_out: wgpu::Buffer,
    pub material_out: wgpu::Buffer,
    /// The sort: each particle's cell, per cell its count and fill cursor, the order and
    /// each cell's first slot (cells + 1).
    pub cell_of: wgpu::Buffer,
    pub counts: wgpu::Buffer,
    pub cursor: wgpu::Buffer,
    pub order: wgpu::Buffer,
    pub cell_start: wgpu::Buffer,
    /// Boundary particles sorted by cell (position and ψ (kg) in w) and each cell's first.
    pub boundary: wgpu::Buffer,
    pub boundary_start: wgpu::Buffer,
    /// The containers' count and clearance, then their corners (m, relative).
    pub containers: wgpu::Buffer,
    /// Neighbour counts, offsets (n + 1) and lists.
    pub fluid_count: wgpu::Buffer,
    pub boundary_count: wgpu::Buffer,
    pub fluid_offset: wgpu::Buffer,
    pub boundary_offset: wgpu::Buffer,
    pub fluid_list: wgpu::Buffer,
    pub boundary_list: wgpu::Buffer,
    /// The pool of kept corrections of multi-step projections (`Pool` in
    /// shaders/common.wgsl): a header, then the entries (m).
    pub kept: wgpu::Buffer,
    /// Entries the lists and the pool have room for.
    pub fluid_room: u64,
    pub boundary_room: u64,
    pub kept_room: u64,
    /// X^(k) and X^(k−1), exchanging roles every outer iteration (m).
    pub iterates: [wgpu::Buffer; 2],
    /// The local step's own correction and λ, ρ_i (kg/m³) and multi-step flag.
    pub projection: wgpu::Buffer,
    pub density: wgpu::Buffer,
    pub flags: wgpu::Buffer,
    /// Per particle values to reduce (reduce.wgsl).
    pub values: wgpu::Buffer,
    /// ω_k and whether to extrapolate of every outer iteration, and where the outer
    /// iteration stands with its displacements (shaders/control.wgsl).
    pub schedule: wgpu::Buffer,
    pub control: wgpu::Buffer,
    /// Every particle's vorticity ω_i (1/s) and |ω_i| in w, where the vorticity confinement
    /// is on (shaders/vorticity.wgsl; 16 bytes otherwise).
    pub vorticity: wgpu::Buffer,
    pub params: wgpu::Buffer,
    pub iter: wgpu::Buffer,
}

/// Bytes of a `vec4<f32>` and of a `u32`.
const VEC4: u64 = 16;
const WORD: u64 = 4;

/// What stays fixed for a stepper's life, in device form: the boundary sorted by cell
/// (positions relative to the grid's centre, ψ in w) with each cell's first slot (cells + 1
/// entries), and the containers' table (`container_table` in stepper.rs).
#[derive(Clone, Copy)]
pub(super) struct Statics<'a> {
    pub boundary: &'a [[f32; 4]],
    pub boundary_start: &'a [u32],
    pub containers: &'a [[f32; 4]],
}

impl Buffers {
    /// The buffers for `n` fluid particles and what stays fixed, `statics`, over `cells` cells,
    /// for outer iterations of at most `iterations` iterations; with room for the
    /// vorticities where `vorticity` (the confinement is on).
    pub fn new(
        ctx: &Context,
        n: u32,
        cells: u32,
        statics: &Statics,
        iterations: u64,
        vorticity: bool,
    ) -> Self {
        let Statics {
            boundary,
            boundary_start,
            containers,
        } = *statics;
        let particles = u64::from(n);
        let vec4 = |label| ctx.storage(label, particles * VEC4);
        let word = |label, count: u64| ctx.storage(label, count * WORD);
        let cell_words = u64::from(cells) + 1;
        let fluid_room = particles * INITIAL_FLUID_ROOM;
        let boundary_room = particles * INITIAL_BOUNDARY_ROOM;
        let buffers = Buffers {
            n,
            cells,
            x: vec4("x"),
            v: vec4("v"),
            s: vec4("s"),
            ids: word("ids", particles),
            material: word("material", particles),
            x_out: vec4("x_out"),
            v_out: vec4("v_out"),
            s_out: vec4("s_out"),
            ids_out: word("ids_out", particles),
            material_out: word("material_out", particles),
            cell_of: word("cell_of", particles),
            counts: word("counts", cell_words),
            cursor: word("cursor", cell_words),
            order: word("order", particles),
            cell_start: word("cell_start", cell_words),
            boundary: ctx.storage("boundary", boundary.len() as u64 * VEC4),
            boundary_start: word("boundary_start", cell_words),
            containers: ctx.storage("containers", containers.len() as u64 * VEC4),
            fluid_count: word("fluid_count", particles),
            boundary_count: word("boundary_count", particles),
            fluid_offset: word("fluid_offset", particles + 1),
            boundary_offset: word("boundary_offset", particles + 1),
            fluid_list: word("fluid_list", fluid_room),
            boundary_list: word("boundary_list", boundary_room),
            kept: ctx.storage("kept", (POOL_HEADER + INITIAL_POOL) * VEC4),
            fluid_room,
            boundary_room,
            kept_room: INITIAL_POOL,
            iterates: [vec4("iterate_a"), vec4("iterate_b")],
            projection: vec4("projection"),
            density: word("density", particles),
            flags: word("flags", particles),
            values: vec4("values"),
            schedule: ctx.storage("schedule", iterations * VEC4),
            control: ctx.storage("control", 2 * VEC4 + iterations * WORD),
            vorticity: ctx.storage("vorticity", if vorticity { particles * VEC4 } else { 0 }),
            params: ctx.uniform("params", &StepParams::zeroed()),
            iter: ctx.uniform("iter", &IterParams::default()),
        };
        ctx.queue
            .write_buffer(&buffers.boundary, 0, bytemuck::cast_slice(boundary));
        ctx.queue.write_buffer(
            &buffers.boundary_start,
            0,
            bytemuck::cast_slice(boundary_start),
        );
        ctx.queue
            .write_buffer(&buffers.containers, 0, bytemuck::cast_slice(containers));
        buffers
    }

    /// Makes the lists room for `fluid` and `boundary` entries; true when they were
    /// replaced (the bind groups that hold them must then be made again).
    pub fn grow_lists(&mut self, ctx: &Context, fluid: u64, boundary: u64) -> bool {
        let mut grown = false;
        if fluid > self.fluid_room {
            self.fluid_room = (fluid as f64 * LIST_GROWTH) as u64;
            self.fluid_list = ctx.storage("fluid_list", self.fluid_room * WORD);
            grown = true;
        }
        if boundary > self.boundary_room {
            self.boundary_room = (boundary as f64 * LIST_GROWTH) as u64;
            self.boundary_list = ctx.storage("boundary_list", self.boundary_room * WORD);
            grown = true;
        }
        grown
    }

    /// Makes the pool of kept corrections room for `entries` entries, which a local step
    /// asked for; the bind groups that hold it must then be made again.
    pub fn grow_pool(&mut self, ctx: &Context, entries: u64) {
        self.kept_room = ((entries as f64 * LIST_GROWTH) as u64).max(INITIAL_POOL);
        self.kept = ctx.storage("kept", (POOL_HEADER + self.kept_room) * VEC4);
    }

    /// Records the reset of the pool's cursor and overflow flag (the first two words of its
    /// header), before a local step.
    pub fn clear_pool(&self, encoder: &mut wgpu::CommandEncoder) {
        encoder.clear_buffer(&self.kept, 0, Some(2 * WORD));
    }
}
