// Gathers the fluid's arrays (positions, velocities, predictions, particle indices and
// materials) into the order of the sort (sort.wgsl): slot k receives particle order[k]. The
// results go to spare buffers, copied back after.

@group(0) @binding(0) var<uniform> P: StepParams;
@group(0) @binding(1) var<storage, read_write> order: array<u32>;
@group(0) @binding(2) var<storage, read_write> x: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> v: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read_write> s: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read_write> ids: array<u32>;
@group(0) @binding(6) var<storage, read_write> x_out: array<vec4<f32>>;
@group(0) @binding(7) var<storage, read_write> v_out: array<vec4<f32>>;
@group(0) @binding(8) var<storage, read_write> s_out: array<vec4<f32>>;
@group(0) @binding(9) var<storage, read_write> ids_out: array<u32>;
@group(0) @binding(10) var<storage, read_write> material: array<u32>;
@group(0) @binding(11) var<storage, read_write> material_out: array<u32>;

@compute @workgroup_size(256)
fn permute(@builtin(workgroup_id) wid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
           @builtin(local_invocation_index) lid: u32) {
    let k = item(wid, nwg, lid);
    if k >= P.n {
        return;
    }
    let i = order[k];
    x_out[k] = x[i];
    v_out[k] = v[i];
    s_out[k] = s[i];
    ids_out[k] = ids[i];
    material_out[k] = material[i];
}
