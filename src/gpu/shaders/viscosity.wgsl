// The physical viscosity (docs/method.md §13, as src/forces/viscosity.rs): after the update
// and before the vorticity confinement and XSPH (finish.wgsl), the velocities solve
//
//   V_i v_i + c V_i Σ_j ν_ij g_ij r (r·(v_i − v_j)) = V_i v*_i,   r = x_i − x_j,
//
// a wall's v_j being 0 (no slip), by conjugate gradients with the inverse 3×3 diagonal
// blocks as preconditioner. g_ij = ½(κ_i + κ_j) V_j w(r) towards a fluid neighbour and
// κ_i (ψ_b/ρ0) w(r) towards a wall, with w(r) = −∇W-coefficient/(|r|² + ε) and κ_i each
// particle's calibration; ν_ij is the harmonic mean of the two materials' ν.
//
// Every sum is gathered by its particle in the order of its neighbour lists; the solve's
// inner products are reduced in a fixed tree (reduce.wgsl) from `values` into `reduced`,
// and its scalars (α, β, r·z, the stop flag) are computed on the device by one thread, so
// the host reads back only whether the solve has stopped. Once it has, every kernel of
// the iteration leaves the state as it is.
//
// `work` holds, in vec4 slots: the scalars (2), then n slots each of the particles'
// volume and ν, their calibrations, r, z, p, A·p and the two halves of the inverse blocks.

struct ViscosityParams {
    // c = 2(d + 2)Δt (s), ε = 0.01 H² (m²), 1 for no-slip walls, the stopping rule's
    // tolerance on ‖r‖/‖b‖ squared.
    coupling: f32,
    epsilon: f32,
    no_slip: u32,
    tolerance2: f32,
    // The calibration's exact value 2/(2(d + 2)), its largest factor, the most iterations.
    exact: f32,
    most_calibration: f32,
    max_iterations: f32,
    pad: f32,
    // ν (m²/s) of every material, four to an entry.
    nu: array<vec4<f32>, 64>,
}

@group(0) @binding(0) var<uniform> P: StepParams;
@group(0) @binding(1) var<uniform> V: ViscosityParams;
@group(0) @binding(2) var<storage, read_write> x: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> velocity: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read_write> material: array<u32>;
@group(0) @binding(5) var<storage, read_write> density: array<f32>;
@group(0) @binding(6) var<storage, read_write> fluid_offset: array<u32>;
@group(0) @binding(7) var<storage, read_write> fluid_list: array<u32>;
@group(0) @binding(8) var<storage, read_write> boundary_offset: array<u32>;
@group(0) @binding(9) var<storage, read_write> boundary_list: array<u32>;
@group(0) @binding(10) var<storage, read_write> boundary: array<vec4<f32>>;
@group(0) @binding(11) var<storage, read_write> work: array<vec4<f32>>;
@group(0) @binding(12) var<storage, read_write> values: array<vec4<f32>>;
// The last reduction of `values`: (Σx, max y, max z, Σw).
@group(0) @binding(13) var<storage, read_write> reduced: array<vec4<f32>>;

// work[0] = (r·z, α, β, stopped), work[1] = (r·r, b·b, iterations, 0).
const SCALARS: u32 = 2u;

// The first slot of region `k` of the particles' regions.
fn region(k: u32) -> u32 {
    return SCALARS + k * P.n;
}

// (V_i, ν_i), κ_i, the residual, the preconditioned residual, the direction, A·p, the
// inverse block's (m00, m11, m22, m01) and (m02, m12).
fn state(i: u32) -> vec4<f32> { return work[region(0u) + i]; }
fn kappa(i: u32) -> f32 { return work[region(1u) + i].x; }
const R: u32 = 2u;
const Z: u32 = 3u;
const D: u32 = 4u;
const Q: u32 = 5u;
const M0: u32 = 6u;
const M1: u32 = 7u;

fn stopped() -> bool {
    return work[0].w != 0.0;
}

// w(r) ≥ 0 (1/m⁷): the pair's Laplacian term is w·r (r·v_ij) before volumes and ν.
fn pair_weight(r: vec3<f32>) -> f32 {
    let len2 = dot(r, r);
    return -grad_coefficient(sqrt(len2)) / (len2 + V.epsilon);
}

fn material_nu(i: u32) -> f32 {
    let k = material[i];
    return V.nu[k >> 2u][k & 3u];
}

// ν_ij: the harmonic mean of two materials' ν, either where both are equal.
fn pair_nu(a: f32, b: f32) -> f32 {
    if a == b {
        return a;
    }
    return select(0.0, 2.0 * a * b / (a + b), a + b > 0.0);
}

// ν_ij g_ij of particle i and fluid neighbour j at offset r.
fn fluid_coupling(i: u32, j: u32, r: vec3<f32>, si: vec4<f32>, ki: f32) -> f32 {
    let sj = state(j);
    let g = 0.5 * (ki + kappa(j)) * pair_weight(r) * sj.x;
    return g * pair_nu(si.y, sj.y);
}

// ν_i g_ib of particle i and boundary particle b (position, ψ in w).
fn wall_coupling(b: vec4<f32>, r: vec3<f32>, si: vec4<f32>, ki: f32) -> f32 {
    return ki * pair_weight(r) * (b.w / P.rest_density) * si.y;
}

// (A u)_i for u in region `k`, or in `velocity` where `k` is 0.
fn apply(i: u32, k: u32) -> vec3<f32> {
    let p = x[i].xyz;
    let si = state(i);
    let ki = kappa(i);
    let ui = select(work[region(k) + i].xyz, velocity[i].xyz, k == 0u);
    var sum = vec3<f32>(0.0);
    for (var e = fluid_offset[i]; e < fluid_offset[i + 1u]; e++) {
        let j = fluid_list[e];
        let r = p - x[j].xyz;
        let uj = select(work[region(k) + j].xyz, velocity[j].xyz, k == 0u);
        sum += r * (fluid_coupling(i, j, r, si, ki) * dot(r, ui - uj));
    }
    if V.no_slip != 0u {
        for (var e = boundary_offset[i]; e < boundary_offset[i + 1u]; e++) {
            let b = boundary[boundary_list[e]];
            let r = p - b.xyz;
            sum += r * (wall_coupling(b, r, si, ki) * dot(r, ui));
        }
    }
    return si.x * (ui + sum * V.coupling);
}

// The inverse block times `u`.
fn precondition(i: u32, u: vec3<f32>) -> vec3<f32> {
    let a = work[region(M0) + i];
    let b = work[region(M1) + i];
    return vec3<f32>(
        a.x * u.x + a.w * u.y + b.x * u.z,
        a.w * u.x + a.y * u.y + b.y * u.z,
        b.x * u.x + b.y * u.y + a.z * u.z,
    );
}

fn particle(wid: vec3<u32>, nwg: vec3<u32>, lid: u32) -> u32 {
    return item(wid, nwg, lid);
}

// V_i = m/ρ_i and ν_i.
@compute @workgroup_size(256)
fn volumes(@builtin(workgroup_id) wid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
           @builtin(local_invocation_index) lid: u32) {
    let i = particle(wid, nwg, lid);
    if i >= P.n {
        return;
    }
    work[region(0u) + i] = vec4<f32>(P.mass / density[i], material_nu(i), 0.0, 0.0);
}

// κ_i = exact/S_i with S_i = Σ g_ij ⟨r_a² r_b²⟩ (the mean over the coordinate planes, g
// uncalibrated), at most the largest factor.
@compute @workgroup_size(256)
fn calibrate(@builtin(workgroup_id) wid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
             @builtin(local_invocation_index) lid: u32) {
    let i = particle(wid, nwg, lid);
    if i >= P.n {
        return;
    }
    let p = x[i].xyz;
    var moment = 0.0;
    for (var e = fluid_offset[i]; e < fluid_offset[i + 1u]; e++) {
        let j = fluid_list[e];
        let r = p - x[j].xyz;
        let r2 = r * r;
        moment += pair_weight(r) * state(j).x * (r2.x * r2.y + r2.y * r2.z + r2.z * r2.x) / 3.0;
    }
    if V.no_slip != 0u {
        for (var e = boundary_offset[i]; e < boundary_offset[i + 1u]; e++) {
            let b = boundary[boundary_list[e]];
            let r = p - b.xyz;
            let r2 = r * r;
            let g = pair_weight(r) * b.w / P.rest_density;
            moment += g * (r2.x * r2.y + r2.y * r2.z + r2.z * r2.x) / 3.0;
        }
    }
    let k = select(V.most_calibration, V.exact / moment, moment * V.most_calibration > V.exact);
    work[region(1u) + i] = vec4<f32>(k, 0.0, 0.0, 0.0);
}

// The inverse diagonal block, the residual r = V v* − A v* of the start v*, z = M r, p = z,
// and (r·z, r·r) to reduce.
@compute @workgroup_size(256)
fn begin(@builtin(workgroup_id) wid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
         @builtin(local_invocation_index) lid: u32) {
    let i = particle(wid, nwg, lid);
    if i >= P.n {
        return;
    }
    let p = x[i].xyz;
    let si = state(i);
    let ki = kappa(i);
    // Σ ν_ij g r rᵀ: xx, yy, zz, xy, xz, yz.
    var d = vec3<f32>(0.0);
    var o = vec3<f32>(0.0);
    for (var e = fluid_offset[i]; e < fluid_offset[i + 1u]; e++) {
        let j = fluid_list[e];
        let r = p - x[j].xyz;
        let c = fluid_coupling(i, j, r, si, ki);
        d += c * r * r;
        o += c * vec3<f32>(r.x * r.y, r.x * r.z, r.y * r.z);
    }
    if V.no_slip != 0u {
        for (var e = boundary_offset[i]; e < boundary_offset[i + 1u]; e++) {
            let b = boundary[boundary_list[e]];
            let r = p - b.xyz;
            let c = wall_coupling(b, r, si, ki);
            d += c * r * r;
            o += c * vec3<f32>(r.x * r.y, r.x * r.z, r.y * r.z);
        }
    }
    let m = mat3x3<f32>(
        vec3<f32>(1.0 + V.coupling * d.x, V.coupling * o.x, V.coupling * o.y),
        vec3<f32>(V.coupling * o.x, 1.0 + V.coupling * d.y, V.coupling * o.z),
        vec3<f32>(V.coupling * o.y, V.coupling * o.z, 1.0 + V.coupling * d.z),
    ) * si.x;
    let det = determinant(m);
    var inv = mat3x3<f32>(
        vec3<f32>(1.0 / si.x, 0.0, 0.0),
        vec3<f32>(0.0, 1.0 / si.x, 0.0),
        vec3<f32>(0.0, 0.0, 1.0 / si.x),
    );
    // The adjugate over the determinant; the plain 1/V_i where the block is singular.
    if det != 0.0 && abs(det) < 3.0e38 {
        let c0 = cross(m[1], m[2]);
        let c1 = cross(m[2], m[0]);
        let c2 = cross(m[0], m[1]);
        inv = transpose(mat3x3<f32>(c0, c1, c2)) * (1.0 / det);
    }
    work[region(M0) + i] = vec4<f32>(inv[0].x, inv[1].y, inv[2].z, inv[1].x);
    work[region(M1) + i] = vec4<f32>(inv[2].x, inv[2].y, 0.0, 0.0);
    let residual = si.x * velocity[i].xyz - apply(i, 0u);
    let z = precondition(i, residual);
    work[region(R) + i] = vec4<f32>(residual, 0.0);
    work[region(Z) + i] = vec4<f32>(z, 0.0);
    work[region(D) + i] = vec4<f32>(z, 0.0);
    values[i] = vec4<f32>(dot(residual, z), 0.0, 0.0, dot(residual, residual));
}

// |V_i v*_i|² to reduce into b·b.
@compute @workgroup_size(256)
fn right_side(@builtin(workgroup_id) wid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
              @builtin(local_invocation_index) lid: u32) {
    let i = particle(wid, nwg, lid);
    if i >= P.n {
        return;
    }
    let b = state(i).x * velocity[i].xyz;
    values[i] = vec4<f32>(0.0, 0.0, 0.0, dot(b, b));
}

// One thread: r·z and r·r of the start, from the reduction of `begin`'s values.
@compute @workgroup_size(1)
fn start() {
    let s = reduced[0];
    work[0] = vec4<f32>(s.x, 0.0, 0.0, 0.0);
    work[1] = vec4<f32>(s.w, 0.0, 0.0, 0.0);
}

// One thread: b·b from the reduction of `right_side`'s values; the solve stops at once
// where b is 0 or the start already meets the tolerance.
@compute @workgroup_size(1)
fn check() {
    let bb = reduced[0].w;
    let rr = work[1].x;
    work[1].y = bb;
    if bb == 0.0 || rr <= V.tolerance2 * bb {
        work[0].w = 1.0;
    }
}

// q = A p and p·q to reduce.
@compute @workgroup_size(256)
fn product(@builtin(workgroup_id) wid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
           @builtin(local_invocation_index) lid: u32) {
    let i = particle(wid, nwg, lid);
    if i >= P.n || stopped() {
        return;
    }
    let q = apply(i, D);
    work[region(Q) + i] = vec4<f32>(q, 0.0);
    values[i] = vec4<f32>(dot(work[region(D) + i].xyz, q), 0.0, 0.0, 0.0);
}

// One thread: α = r·z / p·q; the solve stops where the curvature p·q is not positive.
@compute @workgroup_size(1)
fn step_size() {
    if stopped() {
        return;
    }
    let curvature = reduced[0].x;
    if !(curvature > 0.0 && curvature < 3.0e38) {
        work[0].w = 1.0;
        return;
    }
    work[0].y = work[0].x / curvature;
}

// v += α p, r −= α q, z = M r, and (r·z, r·r) to reduce.
@compute @workgroup_size(256)
fn advance(@builtin(workgroup_id) wid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
           @builtin(local_invocation_index) lid: u32) {
    let i = particle(wid, nwg, lid);
    if i >= P.n || stopped() {
        return;
    }
    let alpha = work[0].y;
    velocity[i] = vec4<f32>(velocity[i].xyz + work[region(D) + i].xyz * alpha, 0.0);
    let residual = work[region(R) + i].xyz - work[region(Q) + i].xyz * alpha;
    let z = precondition(i, residual);
    work[region(R) + i] = vec4<f32>(residual, 0.0);
    work[region(Z) + i] = vec4<f32>(z, 0.0);
    values[i] = vec4<f32>(dot(residual, z), 0.0, 0.0, dot(residual, residual));
}

// One thread: β = (r·z)new / (r·z)old; the solve stops once ‖r‖ ≤ tolerance·‖b‖ or after
// the most iterations.
@compute @workgroup_size(1)
fn next_direction() {
    if stopped() {
        return;
    }
    let s = reduced[0];
    let iterations = work[1].z + 1.0;
    work[0] = vec4<f32>(s.x, work[0].y, s.x / work[0].x, 0.0);
    work[1] = vec4<f32>(s.w, work[1].y, iterations, 0.0);
    if s.w <= V.tolerance2 * work[1].y || iterations >= V.max_iterations {
        work[0].w = 1.0;
    }
}

// p = z + β p.
@compute @workgroup_size(256)
fn direction(@builtin(workgroup_id) wid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
             @builtin(local_invocation_index) lid: u32) {
    let i = particle(wid, nwg, lid);
    if i >= P.n || stopped() {
        return;
    }
    let p = work[region(Z) + i].xyz + work[region(D) + i].xyz * work[0].z;
    work[region(D) + i] = vec4<f32>(p, 0.0);
}
