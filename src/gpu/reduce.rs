//! Reductions on the device in a fixed tree (shaders/reduce.wgsl): per-particle vec4 values
//! whose x and w are summed and y and z maximised, 1024 to one per pass, until one remains.
//! The stopping rules (docs/method.md §4), the step's density errors (§10) and the CFL rule
//! (§8) read their results; the order of every addition is fixed, so repeated runs agree
//! to the bit.

use super::context::{Context, Kernel, Slot, dispatch_groups};
use bytemuck::{Pod, Zeroable};

/// Values one workgroup reduces.
const BLOCK: u32 = 1024;

/// `ReduceParams` in shaders/reduce.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct ReduceParams {
    len: u32,
    pad: [u32; 3],
}

/// One pass: its output's length in workgroups and its bind group.
struct Pass {
    groups: u32,
    _params: wgpu::Buffer,
    group: wgpu::BindGroup,
}

/// The reduction of a buffer of `len` vec4 values to one, in `result`.
pub(super) struct Reduction {
    kernel: Kernel,
    passes: Vec<Pass>,
    _partials: Vec<wgpu::Buffer>,
    /// The reduced value: (Σx, max y, max z, Σw).
    pub result: wgpu::Buffer,
}

impl Reduction {
    /// The reduction's kernel, compiled.
    pub fn compile(ctx: &Context) -> Kernel {
        let slots = [Slot::Uniform, Slot::Storage, Slot::Storage];
        ctx.kernel(
            "reduce",
            include_str!("shaders/reduce.wgsl"),
            &slots,
            &["reduce"],
        )
    }

    /// The passes of `kernel` ([`Reduction::compile`]) that reduce the `len` values in
    /// `input`.
    pub fn new(ctx: &Context, kernel: Kernel, len: u32, input: &wgpu::Buffer) -> Self {
        let mut passes = Vec::new();
        let mut partials: Vec<wgpu::Buffer> = Vec::new();
        let mut len = len.max(1);
        loop {
            let groups = len.div_ceil(BLOCK);
            let output = ctx.storage("partial sums", u64::from(groups) * 16);
            let params = ctx.uniform("reduce", &ReduceParams { len, pad: [0; 3] });
            let source = partials.last().unwrap_or(input);
            let group = ctx.bind(&kernel, &[&params, source, &output]);
            passes.push(Pass {
                groups,
                _params: params,
                group,
            });
            partials.push(output);
            if groups == 1 {
                break;
            }
            len = groups;
        }
        let result = partials.last().expect("one pass at least").clone();
        Reduction {
            kernel,
            passes,
            _partials: partials,
            result,
        }
    }

    /// The kernel, for a reduction of other values.
    pub fn into_kernel(self) -> Kernel {
        self.kernel
    }

    /// Records the passes; the value is in [`Reduction::result`] after them.
    pub fn record(&self, pass: &mut wgpu::ComputePass) {
        for p in &self.passes {
            dispatch_groups(pass, &self.kernel.pipelines[0], &p.group, p.groups);
        }
    }
}
