// The end of a step (docs/method.md §1.3 steps 5–8): the new positions, kept inside their
// containers (§7), v = (x^{n+1} − x^n)/Δt, the densities at the new positions (unless the
// last local step evaluated them there), the XSPH filter (Monaghan 1989) into
// `velocity_out`, and per particle the values the step's statistics and the CFL rule reduce:
// max(ρ_i/ρ0 − 1, 0) in x and y, |v_i + Δt·g|² in z. The vorticity confinement
// (vorticity.wgsl), where it is on, runs between `update` and `xsph`.

struct IterParams {
    gamma: f32,
    densities_known: u32,
    pad0: u32,
    pad1: u32,
}

@group(0) @binding(0) var<uniform> P: StepParams;
@group(0) @binding(1) var<uniform> I: IterParams;
@group(0) @binding(2) var<storage, read_write> result: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> x: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read_write> velocity: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read_write> velocity_out: array<vec4<f32>>;
@group(0) @binding(6) var<storage, read_write> density: array<f32>;
@group(0) @binding(7) var<storage, read_write> fluid_offset: array<u32>;
@group(0) @binding(8) var<storage, read_write> fluid_list: array<u32>;
@group(0) @binding(9) var<storage, read_write> boundary_offset: array<u32>;
@group(0) @binding(10) var<storage, read_write> boundary_list: array<u32>;
@group(0) @binding(11) var<storage, read_write> boundary: array<vec4<f32>>;
@group(0) @binding(12) var<storage, read_write> values: array<vec4<f32>>;
// The containers' count and clearance (m), then each one's lowest and highest corner (m).
@group(0) @binding(13) var<storage, read_write> containers: array<vec4<f32>>;

// `p` kept at least the clearance inside the walls of the first container that holds `start`
// (docs/method.md §7); unchanged where none does.
fn contained(start: vec3<f32>, p: vec3<f32>) -> vec3<f32> {
    let count = u32(containers[0].x);
    let clearance = containers[0].y;
    for (var c = 0u; c < count; c++) {
        let low = containers[1u + 2u * c].xyz;
        let high = containers[2u + 2u * c].xyz;
        if all(start >= low) && all(start <= high) {
            return min(max(p, low + clearance), high - clearance);
        }
    }
    return p;
}

@compute @workgroup_size(256)
fn update(@builtin(workgroup_id) wid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
          @builtin(local_invocation_index) lid: u32) {
    let i = item(wid, nwg, lid);
    if i >= P.n {
        return;
    }
    let p = contained(x[i].xyz, result[i].xyz);
    velocity[i] = vec4<f32>((p - x[i].xyz) / P.gravity.w, 0.0);
    // The pressure the iteration carried (sweep.wgsl) rides along in x's fourth component.
    x[i] = vec4<f32>(p, result[i].w);
    if I.densities_known == 0u {
        var fluid = 0.0;
        for (var e = fluid_offset[i]; e < fluid_offset[i + 1u]; e++) {
            fluid += kernel_w(length(p - result[fluid_list[e]].xyz));
        }
        var walls = 0.0;
        for (var e = boundary_offset[i]; e < boundary_offset[i + 1u]; e++) {
            let b = boundary[boundary_list[e]];
            walls += b.w * kernel_w(length(p - b.xyz));
        }
        density[i] = P.mass * (P.sigma + fluid) + walls;
    }
}

@compute @workgroup_size(256)
fn xsph(@builtin(workgroup_id) wid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
        @builtin(local_invocation_index) lid: u32) {
    let i = item(wid, nwg, lid);
    if i >= P.n {
        return;
    }
    let vi = velocity[i].xyz;
    var out = vi;
    if P.viscosity != 0.0 {
        let p = x[i].xyz;
        var sum = vec3<f32>(0.0);
        for (var e = fluid_offset[i]; e < fluid_offset[i + 1u]; e++) {
            let j = fluid_list[e];
            let w = kernel_w(length(p - x[j].xyz));
            sum += (velocity[j].xyz - vi) * (P.mass / density[j] * w);
        }
        out = vi + sum * P.viscosity;
    }
    velocity_out[i] = vec4<f32>(out, 0.0);
    let error = max(density[i] / P.rest_density - 1.0, 0.0);
    let ahead = out + P.gravity.xyz * P.gravity.w;
    values[i] = vec4<f32>(error, error, dot(ahead, ahead), 0.0);
}
