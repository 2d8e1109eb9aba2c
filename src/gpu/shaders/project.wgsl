// The local step (docs/method.md §2.5): every active density constraint projected on a
// private copy p of its stencil by Newton-like steps, as src/constraint/projection.rs does.
// A projection that ends after its first step is kept as λ_i alone (the gather recomputes
// its corrections); a longer one takes a segment of the pool `kept`, writes its stencil's
// corrections P_{i,j} − x_j there (own correction first, then one per fluid neighbour in list
// order) and flags itself with the segment's start + 1. Few projections take more than one
// step, so the pool holds far fewer entries than the lists: a segment is taken with an
// atomic cursor (where it lies does not change what it holds), and a projection that finds
// the pool full sets its overflow flag and stops; the host then grows the pool and takes
// the outer iteration again, which the global step leaves undone (sweep.wgsl). ρ_i at the iterate goes to `density`, max(ρ_i/ρ0 − 1, 0) to values.x for the
// density rule (§4). The constraint is the same for every material (its densities are in the
// world's fluid's terms, §14); a particle's material enters through its weight alone.

@group(0) @binding(0) var<uniform> P: StepParams;
@group(0) @binding(1) var<storage, read_write> x: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read_write> fluid_offset: array<u32>;
@group(0) @binding(3) var<storage, read_write> fluid_list: array<u32>;
@group(0) @binding(4) var<storage, read_write> boundary_offset: array<u32>;
@group(0) @binding(5) var<storage, read_write> boundary_list: array<u32>;
@group(0) @binding(6) var<storage, read_write> boundary: array<vec4<f32>>;
@group(0) @binding(7) var<storage, read_write> projection: array<vec4<f32>>;
@group(0) @binding(8) var<storage, read_write> density: array<f32>;
@group(0) @binding(9) var<storage, read_write> flags: array<u32>;
@group(0) @binding(10) var<storage, read_write> kept: Pool;
@group(0) @binding(11) var<storage, read_write> values: array<vec4<f32>>;
@group(0) @binding(12) var<storage, read_write> material: array<u32>;

// The projection stops once C_i ≤ this (as on the CPU; in single precision it means the
// constraint reads no compression at all).
const CONSTRAINT_GOAL: f32 = 1e-14;
const MAX_PROJECTION_STEPS: u32 = 100u;
// ε of λ = −C/(|∇C|² + ε), m⁻².
const REGULARIZATION: f32 = 1e-6;

// w_j of fluid particle j (docs/method.md §2.5, §14).
fn weight_of(j: u32) -> f32 {
    return weight(fluid_offset[j + 1u] - fluid_offset[j], material[j]);
}

// What moves member s (list entry e) of the stencil: 0 at the iterate (mode 0), the first
// step λ·w_j·g_j (mode 1, `lambda`), or the kept correction (mode 2, segment `seg`).
fn member_offset(i: u32, e: u32, s: u32, mode: u32, lambda: f32, seg: u32) -> vec3<f32> {
    let j = fluid_list[e];
    if mode == 1u {
        let g = -grad_w(x[i].xyz - x[j].xyz) * (P.mass / P.rest_density);
        return g * (lambda * weight_of(j));
    }
    if mode == 2u {
        return kept.entries[seg + 1u + s].xyz;
    }
    return vec3<f32>(0.0);
}

// ρ_i with particle i at `pi` and its fluid neighbours moved as `member_offset` says.
fn density_at(i: u32, pi: vec3<f32>, mode: u32, lambda: f32, seg: u32) -> f32 {
    let first = fluid_offset[i];
    var fluid = 0.0;
    for (var e = first; e < fluid_offset[i + 1u]; e++) {
        let pj = x[fluid_list[e]].xyz + member_offset(i, e, e - first, mode, lambda, seg);
        fluid += kernel_w(length(pi - pj));
    }
    var walls = 0.0;
    for (var e = boundary_offset[i]; e < boundary_offset[i + 1u]; e++) {
        let b = boundary[boundary_list[e]];
        walls += b.w * kernel_w(length(pi - b.xyz));
    }
    return P.mass * (P.sigma + fluid) + walls;
}

struct Gradients {
    // ∇_{p_i} C_i (1/m).
    own: vec3<f32>,
    // Σ_j |∇_{p_j} C_i|² over the fluid members, i included (1/m²).
    denominator: f32,
    // max_j |∇_{p_j} C_i|·w_j over the neighbours (1/m).
    largest: f32,
    // max_j |∇_{p_j} C_i|·w_j/(n_j + 1) over the neighbours (1/m): the share of the move
    // the global step makes of a correction.
    largest_share: f32,
}

// n_j + 1: how many corrections the global step averages for particle j.
fn shares(j: u32) -> f32 {
    return f32(fluid_offset[j + 1u] - fluid_offset[j] + 1u);
}

fn gradients(i: u32, pi: vec3<f32>, mode: u32, lambda: f32, seg: u32) -> Gradients {
    let scale = P.mass / P.rest_density;
    var walls = vec3<f32>(0.0);
    for (var e = boundary_offset[i]; e < boundary_offset[i + 1u]; e++) {
        let b = boundary[boundary_list[e]];
        walls += grad_w(pi - b.xyz) * b.w;
    }
    var own = walls / P.rest_density;
    var denominator = 0.0;
    var largest = 0.0;
    var largest_share = 0.0;
    let first = fluid_offset[i];
    for (var e = first; e < fluid_offset[i + 1u]; e++) {
        let j = fluid_list[e];
        let pj = x[j].xyz + member_offset(i, e, e - first, mode, lambda, seg);
        let g = grad_w(pi - pj) * scale;
        own += g;
        denominator += dot(g, g);
        largest = max(largest, length(g) * weight_of(j));
        largest_share = max(largest_share, length(g) * weight_of(j) / shares(j));
    }
    return Gradients(own, denominator + dot(own, own), largest, largest_share);
}

@compute @workgroup_size(256)
fn project(@builtin(workgroup_id) wid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
           @builtin(local_invocation_index) lid: u32) {
    let i = item(wid, nwg, lid);
    if i >= P.n || kept.stopped != 0u {
        return;
    }
    let xi = x[i].xyz;
    let first = fluid_offset[i];
    let members = fluid_offset[i + 1u] - first;
    // Segment of i in the pool, once taken: its own correction, then one per neighbour.
    var seg = 0u;
    let w_i = weight(members, material[i]);
    var own = vec3<f32>(0.0);
    var first_lambda = 0.0;
    // The sum of every step's λ: the multiplier the step carries (sweep.wgsl).
    var total_lambda = 0.0;
    var materialized = false;
    for (var step = 0u; step < MAX_PROJECTION_STEPS; step++) {
        let pi = xi + own;
        var mode = 0u;
        if step > 0u {
            mode = select(1u, 2u, materialized);
        }
        let rho = density_at(i, pi, mode, first_lambda, seg);
        if step == 0u {
            density[i] = rho;
            values[i] = vec4<f32>(max(rho / P.rest_density - 1.0, 0.0), 0.0, 0.0, 0.0);
        }
        let c = max(rho / P.rest_density - 1.0, 0.0);
        if step > 0u && !materialized && c > CONSTRAINT_GOAL {
            // A second step is needed: the first step's corrections are written out, into a
            // segment of the pool.
            seg = atomicAdd(&kept.cursor, members + 1u);
            if seg + members + 1u > arrayLength(&kept.entries) {
                atomicStore(&kept.overflow, 1u);
                break;
            }
            kept.entries[seg] = vec4<f32>(own, 0.0);
            for (var e = first; e < first + members; e++) {
                kept.entries[seg + 1u + e - first] = vec4<f32>(member_offset(i, e, e - first, 1u, first_lambda, seg), 0.0);
            }
            materialized = true;
            mode = 2u;
        }
        if c <= CONSTRAINT_GOAL {
            break;
        }
        // The first step's gradients are those at the iterate.
        let at = select(pi, xi, step == 0u);
        let g = gradients(i, at, select(0u, 2u, materialized), first_lambda, seg);
        if g.denominator == 0.0 {
            break;
        }
        var lambda = -c / (g.denominator + REGULARIZATION);
        // Steps after the first move no member farther than H/4, and the first step's share
        // of the global step's move none farther either (docs/method.md §2.5).
        var largest = max(length(g.own) * w_i / shares(i), g.largest_share) * abs(lambda);
        if materialized {
            largest = max(length(g.own) * w_i, g.largest) * abs(lambda);
        }
        if largest > P.newton_limit {
            lambda *= P.newton_limit / largest;
        }
        if materialized {
            let scale = P.mass / P.rest_density;
            // The members' gradients at p before this step's move of p_i.
            for (var e = first; e < first + members; e++) {
                let j = fluid_list[e];
                let slot = seg + 1u + e - first;
                let pj = x[j].xyz + kept.entries[slot].xyz;
                let gj = -grad_w(pi - pj) * scale;
                kept.entries[slot] = vec4<f32>(kept.entries[slot].xyz + gj * (lambda * weight_of(j)), 0.0);
            }
        } else {
            first_lambda = lambda;
        }
        own += g.own * (lambda * w_i);
        total_lambda += lambda;
        if materialized {
            kept.entries[seg] = vec4<f32>(own, 0.0);
        }
    }
    projection[i] = vec4<f32>(own, total_lambda);
    flags[i] = select(0u, seg + 1u, materialized);
}
