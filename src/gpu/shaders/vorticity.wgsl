// Vorticity confinement (docs/method.md §15, as src/forces/vorticity.rs): after the update
// and before XSPH (finish.wgsl), at the new positions with the step's neighbour lists,
//
//   ω_i = Σ_j V ∇W(x_i − x_j) × (v_j − v_i)          (1/s), V = m/ρ0
//   η_i = Σ_j (|ω_j| − |ω_i|) ∇W(x_i − x_j)           (its direction N_i alone is used)
//   v_i ← v_i + Δt·ε·H·|ω_i|·(N_i × ω_i)
//
// in two passes: `vorticity` writes every ω_i, `confine` reads them and changes each particle's
// own velocity in place (no thread reads another's velocity in that pass). Both sums are
// gathered by the particle in the order of its neighbour list.

@group(0) @binding(0) var<uniform> P: StepParams;
@group(0) @binding(1) var<storage, read_write> x: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read_write> velocity: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> fluid_offset: array<u32>;
@group(0) @binding(4) var<storage, read_write> fluid_list: array<u32>;
// ω_i (1/s) and |ω_i| in w.
@group(0) @binding(5) var<storage, read_write> omega: array<vec4<f32>>;

@compute @workgroup_size(256)
fn vorticity(@builtin(workgroup_id) wid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
             @builtin(local_invocation_index) lid: u32) {
    let i = item(wid, nwg, lid);
    if i >= P.n {
        return;
    }
    let p = x[i].xyz;
    let vi = velocity[i].xyz;
    var sum = vec3<f32>(0.0);
    for (var e = fluid_offset[i]; e < fluid_offset[i + 1u]; e++) {
        let j = fluid_list[e];
        sum += cross(grad_w(p - x[j].xyz), velocity[j].xyz - vi);
    }
    let w = sum * (P.mass / P.rest_density);
    omega[i] = vec4<f32>(w, length(w));
}

@compute @workgroup_size(256)
fn confine(@builtin(workgroup_id) wid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
           @builtin(local_invocation_index) lid: u32) {
    let i = item(wid, nwg, lid);
    if i >= P.n {
        return;
    }
    let p = x[i].xyz;
    let wi = omega[i];
    var eta = vec3<f32>(0.0);
    for (var e = fluid_offset[i]; e < fluid_offset[i + 1u]; e++) {
        let j = fluid_list[e];
        eta += grad_w(p - x[j].xyz) * (omega[j].w - wi.w);
    }
    // η scaled by its largest component first, so that its direction survives where its
    // length would underflow in single precision.
    let largest = max(max(abs(eta.x), abs(eta.y)), abs(eta.z));
    if largest > 0.0 && wi.w > 0.0 {
        let n = normalize(eta / largest);
        let scale = P.vorticity * P.h * P.gravity.w * wi.w;
        velocity[i] = vec4<f32>(velocity[i].xyz + cross(n, wi.xyz) * scale, 0.0);
    }
}
