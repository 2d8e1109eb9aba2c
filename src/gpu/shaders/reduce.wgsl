// Reductions of per-particle vec4 values in a fixed tree (docs/method.md §4, §8, §10):
// x and w are summed, y and z take the maximum. Each pass reduces blocks of 1024 into one
// value per block, in the same order on every run; no floating-point atomics.

struct ReduceParams {
    len: u32,
    pad0: u32,
    pad1: u32,
    pad2: u32,
}

@group(0) @binding(0) var<uniform> R: ReduceParams;
@group(0) @binding(1) var<storage, read_write> input: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read_write> output: array<vec4<f32>>;

var<workgroup> partial: array<vec4<f32>, 256>;

fn combine(a: vec4<f32>, b: vec4<f32>) -> vec4<f32> {
    return vec4<f32>(a.x + b.x, max(a.y, b.y), max(a.z, b.z), a.w + b.w);
}

@compute @workgroup_size(256)
fn reduce(@builtin(workgroup_id) wid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
          @builtin(local_invocation_index) lid: u32) {
    let b = wid.y * nwg.x + wid.x;
    var acc = vec4<f32>(0.0);
    for (var k = 0u; k < 4u; k++) {
        let e = b * 1024u + k * 256u + lid;
        if e < R.len {
            acc = combine(acc, input[e]);
        }
    }
    partial[lid] = acc;
    for (var stride = 128u; stride > 0u; stride /= 2u) {
        workgroupBarrier();
        if lid < stride {
            partial[lid] = combine(partial[lid], partial[lid + stride]);
        }
    }
    if lid == 0u && b * 1024u < R.len {
        output[b] = partial[0];
    }
}
