// Shared by every shader of the GPU step (src/gpu/): the step's constants, the cubic
// spline kernel (docs/method.md §2.1), the grid's cells (§6) and the thread index.
// Single precision; positions are relative to the grid's centre (src/gpu/buffers.rs).

struct StepParams {
    // Fluid particles, boundary particles, grid cells, projection weighting
    // (0 neighbour count, 1 unit, 2 uniform; docs/method.md §2.5).
    n: u32,
    boundary_n: u32,
    cells: u32,
    weight_mode: u32,
    // Cells along x, y, z.
    dims: vec4<u32>,
    // The grid's lowest corner (m) and, in w, 1/cell size (1/m).
    origin: vec4<f32>,
    // g (m/s²) and, in w, Δt (s).
    gravity: vec4<f32>,
    // H (m), 1/H (1/m), σ = 8/(πH³) (1/m³), 48/(πH⁴) (1/m⁴).
    h: f32,
    inv_h: f32,
    sigma: f32,
    grad_factor: f32,
    // m (kg), ρ0 (kg/m³), Δt²k (kg), the membership floor (docs/method.md §3.1).
    mass: f32,
    rest_density: f32,
    dt2k: f32,
    membership_floor: f32,
    // XSPH c_X, the rest stencil size c, the Newton step limit H/4 (m), the vorticity
    // confinement's ε (docs/method.md §15; 0 = off).
    viscosity: f32,
    rest_stencil: f32,
    newton_limit: f32,
    vorticity: f32,
    // m/m_k = ρ0/ρ0_k of every material k, four to an entry (docs/method.md §14): the
    // factor that divides a particle's projection weight by its mass ratio.
    inverse_ratio: array<vec4<f32>, 64>,
}

const WORKGROUP: u32 = 256u;

// W(r), 1/m³, without branches (docs/method.md §2.1).
fn kernel_w(r: f32) -> f32 {
    let q = r * P.inv_h;
    let outer = max(1.0 - q, 0.0);
    let inner = max(0.5 - q, 0.0);
    return P.sigma * (2.0 * outer * outer * outer - 8.0 * inner * inner * inner);
}

// c with ∇W(r) = c·r for an offset of length `len` (m), 1/m⁵; 0 at or below 1e-9 m.
fn grad_coefficient(len: f32) -> f32 {
    let q = len * P.inv_h;
    let outer = max(1.0 - q, 0.0);
    let inner = max(0.5 - q, 0.0);
    let shape = 4.0 * inner * inner - outer * outer;
    return select(0.0, P.grad_factor * shape / len, len > 1e-9);
}

fn grad_w(r: vec3<f32>) -> vec3<f32> {
    return r * grad_coefficient(length(r));
}

// The cell of a position, clamped into the grid: a particle outside it shares the edge
// cells, which keeps every neighbour within one cell of it (docs/method.md §6).
fn cell_coords(p: vec3<f32>) -> vec3<i32> {
    let top = vec3<f32>(P.dims.xyz) - 1.0;
    let c = clamp(floor((p - P.origin.xyz) * P.origin.w), vec3<f32>(0.0), top);
    return vec3<i32>(c);
}

fn cell_index(c: vec3<i32>) -> u32 {
    return u32(c.x) + P.dims.x * (u32(c.y) + P.dims.y * u32(c.z));
}

// The thread's item in a dispatch of workgroups laid out over x and y (a dispatch has at
// most 65535 workgroups along one axis).
fn item(wid: vec3<u32>, nwg: vec3<u32>, lid: u32) -> u32 {
    return (wid.y * nwg.x + wid.x) * WORKGROUP + lid;
}

// The projection weight of a particle with `count` fluid neighbours before its material's
// mass ratio enters (docs/method.md §2.5).
fn plain_weight(count: u32) -> f32 {
    switch P.weight_mode {
        case 1u: { return 1.0; }
        case 2u: { return P.rest_stencil; }
        default: { return f32(count + 1u); }
    }
}

// The projection weight w_j of a particle with `count` fluid neighbours, of material
// `material`: the plain weight divided by the material's mass ratio m_k/m, so that a heavier
// liquid yields less to the same constraint (docs/method.md §14; 1 for the world's own fluid,
// which leaves the weight's bits as they are).
fn weight(count: u32, material: u32) -> f32 {
    return plain_weight(count) * P.inverse_ratio[material >> 2u][material & 3u];
}

// μ_j, the stencils the global step counts particle j in (docs/method.md §3.1).
fn membership(count: u32) -> f32 {
    if P.weight_mode == 2u {
        return P.rest_stencil;
    }
    return max(f32(count + 1u), P.membership_floor);
}
