//! Exclusive prefix sums of counts on the device (shaders/scan.wgsl): a cell's first slot
//! from the cells' counts, a particle's first list entry from the neighbour counts
//! (docs/method.md §6). Integer sums, so the result does not depend on the order.

use super::context::{Context, Kernel, Slot, dispatch_groups};
use bytemuck::{Pod, Zeroable};

/// Entries one workgroup scans (256 threads, 4 each).
const BLOCK: u32 = 1024;

/// The scan's kernels (one module, shared by every [`Scan`]).
pub(super) fn kernel(ctx: &Context) -> Kernel {
    let slots = [Slot::Uniform, Slot::Storage, Slot::Storage, Slot::Storage];
    let entries = ["block_sums", "scan_sums", "scan_blocks"];
    ctx.kernel("scan", include_str!("shaders/scan.wgsl"), &slots, &entries)
}

/// `ScanParams` in shaders/scan.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct ScanParams {
    len: u32,
    blocks: u32,
    pad: [u32; 2],
}

/// The scan of one array of `len` counts into an array of `len + 1` offsets (the total
/// last), with its block sums and bind group.
pub(super) struct Scan {
    blocks: u32,
    _params: wgpu::Buffer,
    _sums: wgpu::Buffer,
    group: wgpu::BindGroup,
}

impl Scan {
    /// The scan of the `len` counts in `input` into `output`.
    pub fn new(
        ctx: &Context,
        kernel: &Kernel,
        len: u32,
        input: &wgpu::Buffer,
        output: &wgpu::Buffer,
    ) -> Self {
        let blocks = len.div_ceil(BLOCK).max(1);
        let params = ctx.uniform(
            "scan",
            &ScanParams {
                len,
                blocks,
                pad: [0; 2],
            },
        );
        let sums = ctx.storage("scan sums", u64::from(blocks) * 4);
        let group = ctx.bind(kernel, &[&params, input, output, &sums]);
        Scan {
            blocks,
            _params: params,
            _sums: sums,
            group,
        }
    }

    /// Records the three passes.
    pub fn record(&self, pass: &mut wgpu::ComputePass, kernel: &Kernel) {
        let [block_sums, scan_sums, scan_blocks] = &kernel.pipelines[..] else {
            unreachable!("the scan module has three entry points");
        };
        dispatch_groups(pass, block_sums, &self.group, self.blocks);
        dispatch_groups(pass, scan_sums, &self.group, 1);
        dispatch_groups(pass, scan_blocks, &self.group, self.blocks);
    }
}
