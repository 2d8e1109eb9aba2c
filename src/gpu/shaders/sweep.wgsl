// The global step on the diagonal system (docs/method.md §3.1, §3.6) fused with the gather
// of the local step's corrections and Chebyshev's extrapolation (§3.7), as
// src/solver/sweep.rs: X^(k+1) replaces X^(k−1) in place, and |X^(k+1) − X^(k)| goes to
// values.y for the displacement rule (§4). The iterates' fourth component carries the
// particle's pressure through the same recurrence (src/step/carry.rs, §10.1): Λ_j scaled by
// −ρ0·μ_j/(Δt²·c_j), constant within a step, so that the result holds p_j = −k·λ_j·μ_j/V.
// ω and whether to extrapolate are the schedule's
// for the iteration k (control.wgsl). Nothing is written once the outer iteration has stopped,
// nor where the local step found its pool of kept corrections full (project.wgsl): the host
// then grows the pool and takes the outer iteration again.

struct IterParams {
    // Chebyshev's γ, and whether the densities of the last local step are those of the
    // result (0/1, finish.wgsl).
    gamma: f32,
    densities_known: u32,
    pad0: u32,
    pad1: u32,
}

@group(0) @binding(0) var<uniform> P: StepParams;
@group(0) @binding(1) var<uniform> I: IterParams;
@group(0) @binding(2) var<storage, read_write> current: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> previous: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read_write> s: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read_write> fluid_offset: array<u32>;
@group(0) @binding(6) var<storage, read_write> fluid_list: array<u32>;
@group(0) @binding(7) var<storage, read_write> projection: array<vec4<f32>>;
@group(0) @binding(8) var<storage, read_write> flags: array<u32>;
@group(0) @binding(9) var<storage, read_write> kept: Pool;
@group(0) @binding(10) var<storage, read_write> values: array<vec4<f32>>;
@group(0) @binding(11) var<storage, read_write> material: array<u32>;
// ω_k and whether to extrapolate (1/0) of every outer iteration k.
@group(0) @binding(12) var<storage, read_write> schedule: array<vec4<f32>>;

// Σ_{i: j∈N̄_i} (P_{i,j} − X_j): every correction the local step made to particle j (m),
// gathered from its own and its neighbours' projections (src/constraint/gather.rs).
fn gathered(j: u32, xj: vec3<f32>, count: u32) -> vec3<f32> {
    let first = fluid_offset[j];
    var moved = vec3<f32>(0.0);
    var near_kept = false;
    for (var e = first; e < first + count; e++) {
        let i = fluid_list[e];
        let lambda = projection[i].w;
        if flags[i] != 0u {
            near_kept = true;
        } else if lambda != 0.0 {
            let r = xj - current[i].xyz;
            moved += r * (grad_coefficient(length(r)) * lambda);
        }
    }
    let w_j = weight(count, material[j]);
    var sum = projection[j].xyz + moved * (w_j * P.mass / P.rest_density);
    if near_kept {
        for (var e = first; e < first + count; e++) {
            let i = fluid_list[e];
            if flags[i] != 0u {
                // j's place in i's list (the lists are symmetric), after i's own correction
                // at the start of its segment (flags[i] − 1).
                let start = fluid_offset[i];
                for (var f = start; f < fluid_offset[i + 1u]; f++) {
                    if fluid_list[f] == j {
                        sum += kept.entries[flags[i] + f - start].xyz;
                        break;
                    }
                }
            }
        }
    }
    return sum;
}

@compute @workgroup_size(256)
fn sweep(@builtin(workgroup_id) wid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
         @builtin(local_invocation_index) lid: u32) {
    let j = item(wid, nwg, lid);
    if j >= P.n {
        return;
    }
    if kept.stopped != 0u || atomicLoad(&kept.overflow) != 0u {
        return;
    }
    let x = current[j].xyz;
    let count = fluid_offset[j + 1u] - fluid_offset[j];
    let members = membership(count);
    var scale = members / f32(count + 1u);
    if P.weight_mode == 2u {
        scale = 1.0;
    }
    let diagonal = P.mass + P.dt2k * members;
    // X + (b − Â X)/Â with b − Â X = m(s − X) + Δt²k·scale·gathered, which keeps single
    // precision where b and Â X nearly cancel.
    let residual = P.mass * (s[j].xyz - x) + gathered(j, x, count) * (P.dt2k * scale);
    let dt = P.gravity.w;
    let source = -projection[j].w * P.rest_density * members / (dt * dt);
    let here = vec4<f32>(x, current[j].w);
    var plain = vec4<f32>(x + residual / diagonal, P.dt2k * (members * here.w + source) / diagonal);
    let before = previous[j];
    let step = schedule[kept.k];
    let omega = step.x;
    if step.y != 0.0 {
        if I.gamma == 1.0 {
            plain = plain + (plain - before) * (omega - 1.0);
        } else {
            plain = before + ((plain - here) * I.gamma + here - before) * omega;
        }
    }
    previous[j] = plain;
    values[j].y = length(plain.xyz - x);
}
