//! The neighbour phase on the device (docs/method.md §1.3 steps 1–2, §6): the prediction
//! s, the counting sort of the fluid by cell (shaders/sort.wgsl, then every array, the
//! particles' materials too, gathered into the sort's order, shaders/permute.wgsl) and the
//! fluid and boundary neighbour lists on s (shaders/neighbors.wgsl), counted, laid out by
//! prefix sums (scan.rs) and filled. The lists' total is read back once per step to size
//! them.

use super::buffers::Buffers;
use super::context::{Context, Kernel, Slot, dispatch};
use super::scan::{self, Scan};
use crate::Error;

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

    /// Predicts, sorts the fluid into its cells, gathers its arrays into that order and
    /// counts every particle's neighbours; returns the fluid and boundary list lengths
    /// the step needs.
    pub fn sort_and_count(&self, ctx: &Context, b: &Buffers) -> Result<(u64, u64), Error> {
        let g = self.groups();
        let mut encoder = ctx.encoder();
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
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
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            dispatch(&mut pass, &self.neighbors.pipelines[0], &g.neighbors, b.n);
            g.fluid.record(&mut pass, &self.scan);
            g.boundary.record(&mut pass, &self.scan);
        }
        // The totals sit after the n offsets of each array; they are read back through
        // `cell_of`, free once the scatter ran.
        let last = u64::from(b.n) * 4;
        encoder.copy_buffer_to_buffer(&b.fluid_offset, last, &b.cell_of, 0, 4);
        encoder.copy_buffer_to_buffer(&b.boundary_offset, last, &b.cell_of, 4, 4);
        let totals = super::context::words(&ctx.read(encoder, &b.cell_of, 8)?);
        Ok((u64::from(totals[0]), u64::from(totals[1])))
    }

    /// Records the lists' fill (after [`Search::sort_and_count`], into room for them).
    pub fn record_fill(&self, pass: &mut wgpu::ComputePass, b: &Buffers) {
        dispatch(
            pass,
            &self.neighbors.pipelines[1],
            &self.groups().neighbors,
            b.n,
        );
    }
}
