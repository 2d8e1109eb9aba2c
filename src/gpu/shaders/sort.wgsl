// The prediction and the counting sort of the fluid by grid cell (docs/method.md §1.3
// steps 1–2, §6): count per cell with integer atomics (the counts do not depend on the
// order), an exclusive prefix sum (scan.wgsl), a scatter, then every cell's particles
// sorted by their index, so that the order is the same on every run.

@group(0) @binding(0) var<uniform> P: StepParams;
@group(0) @binding(1) var<storage, read_write> x: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read_write> v: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> s: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read_write> cell_of: array<u32>;
@group(0) @binding(5) var<storage, read_write> counts: array<atomic<u32>>;
@group(0) @binding(6) var<storage, read_write> cursor: array<atomic<u32>>;
@group(0) @binding(7) var<storage, read_write> order: array<u32>;
@group(0) @binding(8) var<storage, read_write> cell_start: array<u32>;

@compute @workgroup_size(256)
fn clear(@builtin(workgroup_id) wid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
         @builtin(local_invocation_index) lid: u32) {
    let c = item(wid, nwg, lid);
    if c < P.cells {
        atomicStore(&counts[c], 0u);
        atomicStore(&cursor[c], 0u);
    }
}

// s = x + Δt·v + Δt²·g, and the count of its cell.
@compute @workgroup_size(256)
fn predict(@builtin(workgroup_id) wid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
           @builtin(local_invocation_index) lid: u32) {
    let i = item(wid, nwg, lid);
    if i >= P.n {
        return;
    }
    let dt = P.gravity.w;
    let p = x[i].xyz + v[i].xyz * dt + P.gravity.xyz * (dt * dt);
    s[i] = vec4<f32>(p, 0.0);
    let c = cell_index(cell_coords(p));
    cell_of[i] = c;
    atomicAdd(&counts[c], 1u);
}

// Each particle into a free slot of its cell (in no particular order within the cell).
@compute @workgroup_size(256)
fn scatter(@builtin(workgroup_id) wid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
           @builtin(local_invocation_index) lid: u32) {
    let i = item(wid, nwg, lid);
    if i >= P.n {
        return;
    }
    let c = cell_of[i];
    order[cell_start[c] + atomicAdd(&cursor[c], 1u)] = i;
}

// Every cell's particles by ascending index (insertion sort: a cell holds a few).
@compute @workgroup_size(256)
fn sort_cells(@builtin(workgroup_id) wid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
              @builtin(local_invocation_index) lid: u32) {
    let c = item(wid, nwg, lid);
    if c >= P.cells {
        return;
    }
    let start = cell_start[c];
    let end = cell_start[c + 1u];
    for (var k = start + 1u; k < end; k++) {
        let key = order[k];
        var m = k;
        while m > start && order[m - 1u] > key {
            order[m] = order[m - 1u];
            m--;
        }
        order[m] = key;
    }
}
