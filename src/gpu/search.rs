//! The neighbour phase on the device (docs/method.md §1.3 steps 1–2, §6): the prediction
//! s, the counting sort of the fluid by cell (shaders/sort.wgsl, then every array, the
//! particles' materials too, gathered into the sort's order, shaders/permute.wgsl) and the
//! fluid and boundary neighbour lists on s (shaders/neighbors.wgsl), counted, laid out by
//! prefix sums (scan.rs) and filled, without waiting on the device: where the lists turn
//! out too short, the outer iteration stops before its first step (control.rs) and the
//! host grows them and fills them again.

use super::buffers::Buffers;
use super::context::{Context, Kernel, Slot, dispatch};
use super::scan::{self, Scan};
use super::timer::{Stage, Timer};

/// The kernels and bind groups of the neighbour phase.
pub(super) struct Search {
    sort: Kernel,
    permute: Kernel,
    neighbors: Kernel,
    scan: Kernel,
    groups: Option<Groups>,
}

struct Groups {
    sort: wgpu::BindGroup,
    permute: wgpu::BindGroup,
    neighbors: wgpu::BindGroup,
    cells: Scan,
    fluid: Scan,
    boundary: Scan,
}

impl Search {
    pub fn new(ctx: &Context) -> Self {
        let storage =
            |n| std::iter::once(Slot::Uniform).chain(std::iter::repeat_n(Slot::Storage, n));
        let sort_slots: Vec<_> = storage(8).collect();
        let permute_slots: Vec<_> = storage(11).collect();
        let neighbor_slots: Vec<_> = storage(10).collect();
        Search {
            sort: ctx.kernel(
                "sort",
                with_common!("shaders/sort.wgsl"),
                &sort_slots,
                &["clear", "predict", "scatter", "sort_cells"],
            ),
            permute: ctx.kernel(
                "permute",
                with_common!("shaders/permute.wgsl"),
                &permute_slots,
                &["permute"],
            ),
            neighbors: ctx.kernel(
                "neighbors",
                with_common!("shaders/neighbors.wgsl"),
                &neighbor_slots,
                &["count", "fill"],
            ),
            scan: scan::kernel(ctx),
            groups: None,
        }
    }

    /// Makes the bind groups again for the buffers of `b` (after the lists grew).
    pub fn bind(&mut self, ctx: &Context, b: &Buffers) {
        self.groups = Some(Groups {
            sort: ctx.bind(
                &self.sort,
                &[
                    &b.params,
                    &b.x,
                    &b.v,
                    &b.s,
                    &b.cell_of,
                    &b.counts,
                    &b.cursor,
                    &b.order,
                    &b.cell_start,
                ],
            ),
            permute: ctx.bind(
                &self.permute,
                &[
                    &b.params,
                    &b.order,
                    &b.x,
                    &b.v,
                    &b.s,
                    &b.ids,
                    &b.x_out,
                    &b.v_out,
                    &b.s_out,
                    &b.ids_out,
                    &b.material,
                    &b.material_out,
                ],
            ),
            neighbors: ctx.bind(
                &self.neighbors,
                &[
                    &b.params,
                    &b.s,
                    &b.cell_start,
                    &b.boundary,
                    &b.boundary_start,
                    &b.fluid_count,
                    &b.boundary_count,
                    &b.fluid_offset,
                    &b.boundary_offset,
                    &b.fluid_list,
                    &b.boundary_list,
                ],
            ),
            cells: Scan::new(ctx, &self.scan, b.cells, &b.counts, &b.cell_start),
            fluid: Scan::new(ctx, &self.scan, b.n, &b.fluid_count, &b.fluid_offset),
            boundary: Scan::new(ctx, &self.scan, b.n, &b.boundary_count, &b.boundary_offset),
        });
    }

    fn groups(&self) -> &Groups {
        self.groups
            .as_ref()
            .expect("Search::bind runs before a step")
    }

    /// Records the prediction, the sort of the fluid into its cells, the gather of its
    /// arrays into that order and the count of every particle's neighbours with their
    /// prefix sums: the lists' lengths, which the stopping rules check against the lists'
    /// room before the first outer iteration (control.rs), end the fluid and the boundary
    /// offsets.
    pub fn record_sort_and_count(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut Timer,
        b: &Buffers,
    ) {
        let g = self.groups();
        {
            let mut pass = timer.pass(encoder, Stage::Search);
            let [clear, predict, scatter, sort_cells] = &self.sort.pipelines[..] else {
                unreachable!("the sort module has four entry points");
            };
            dispatch(&mut pass, clear, &g.sort, b.cells + 1);
            dispatch(&mut pass, predict, &g.sort, b.n);
            g.cells.record(&mut pass, &self.scan);
            dispatch(&mut pass, scatter, &g.sort, b.n);
            dispatch(&mut pass, sort_cells, &g.sort, b.cells);
            dispatch(&mut pass, &self.permute.pipelines[0], &g.permute, b.n);
        }
        let bytes = |n: u32, size: u64| u64::from(n) * size;
        encoder.copy_buffer_to_buffer(&b.x_out, 0, &b.x, 0, bytes(b.n, 16));
        encoder.copy_buffer_to_buffer(&b.v_out, 0, &b.v, 0, bytes(b.n, 16));
        encoder.copy_buffer_to_buffer(&b.s_out, 0, &b.s, 0, bytes(b.n, 16));
        encoder.copy_buffer_to_buffer(&b.ids_out, 0, &b.ids, 0, bytes(b.n, 4));
        encoder.copy_buffer_to_buffer(&b.material_out, 0, &b.material, 0, bytes(b.n, 4));
        let mut pass = timer.pass(encoder, Stage::Search);
        dispatch(&mut pass, &self.neighbors.pipelines[0], &g.neighbors, b.n);
        g.fluid.record(&mut pass, &self.scan);
        g.boundary.record(&mut pass, &self.scan);
    }

    /// Records the lists' fill (after [`Search::record_sort_and_count`]). Where the lists
    /// have too little room, what it writes is not used: the stopping rules find it before
    /// the first outer iteration, and the lists are grown and filled again.
    pub fn record_fill(&self, pass: &mut wgpu::ComputePass, b: &Buffers) {
        dispatch(
            pass,
            &self.neighbors.pipelines[1],
            &self.groups().neighbors,
            b.n,
        );
    }
}
