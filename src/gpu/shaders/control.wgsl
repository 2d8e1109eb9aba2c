// The stopping rules of the outer iteration on the device (docs/method.md §4, as
// src/step/iterate.rs and src/gpu/control.rs): one thread, after each outer iteration's local
// and global steps and their reduction, decides whether the iteration goes on, so that the
// host submits several iterations at once and reads back only where they stopped. Once the
// pool's `stopped` is set, the local and global steps of the iterations after it leave
// everything as it is (project.wgsl, sweep.wgsl).
//
// `stopped`: 0 going on, 1 a rule held, 2 the local step found the pool of kept corrections
// full (the host grows it and takes iteration k again, which left nothing changed), 3 the
// iteration reached its most iterations, 4 the neighbour lists the search counted do not fit
// their room (`lists`, before the first iteration: the host grows and fills them again).

struct ControlParams {
    // The fewest and most outer iterations, and the fluid particles.
    min_iterations: u32,
    max_iterations: u32,
    n: u32,
    pad3: u32,
    // The displacement rule's τ, the density rule's motion bound 10τ (m) and its bound on
    // Σ max(ρ_i/ρ0 − 1, 0), each the largest single-precision value the host's
    // double-precision comparison accepts.
    tau: f32,
    motion: f32,
    compression: f32,
    pad0: f32,
}

struct Control {
    // Outer iterations taken, the iterate buffer holding X^(k), whether a rule held and
    // whether the last local step's densities are the result's (0/1).
    outer: u32,
    current: u32,
    converged: u32,
    densities_known: u32,
    // The largest move of the last outer iteration (m; f32 max before the first); the
    // entries of kept corrections the local step that found the pool full asked for (the
    // pool's cursor is cleared before the iterations recorded after it), or the fluid and
    // boundary list entries the search counted where they did not fit.
    displacement: f32,
    asked: u32,
    asked_boundary: u32,
    pad1: u32,
    // δ_k of every outer iteration (m).
    displacements: array<f32>,
}

@group(0) @binding(0) var<uniform> C: ControlParams;
@group(0) @binding(1) var<storage, read_write> reduced: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read_write> kept: Pool;
@group(0) @binding(3) var<storage, read_write> control: Control;
@group(0) @binding(4) var<storage, read_write> fluid_offset: array<u32>;
@group(0) @binding(5) var<storage, read_write> boundary_offset: array<u32>;
@group(0) @binding(6) var<storage, read_write> fluid_list: array<u32>;
@group(0) @binding(7) var<storage, read_write> boundary_list: array<u32>;

// Before the first outer iteration: stops it where the neighbour lists' lengths, at the
// end of their offsets, exceed their room.
@compute @workgroup_size(1)
fn lists() {
    let fluid = fluid_offset[C.n];
    let boundary = boundary_offset[C.n];
    if fluid > arrayLength(&fluid_list) || boundary > arrayLength(&boundary_list) {
        control.asked = fluid;
        control.asked_boundary = boundary;
        kept.stopped = 4u;
    }
}

@compute @workgroup_size(1)
fn decide() {
    if kept.stopped != 0u {
        return;
    }
    if atomicLoad(&kept.overflow) != 0u {
        control.asked = atomicLoad(&kept.cursor);
        kept.stopped = 2u;
        return;
    }
    let k = kept.k;
    let compression = reduced[0].x;
    let moved = reduced[0].y;
    // The density rule at X^(k), with the motion of the iteration before; the global step
    // taken with it is dropped.
    if k >= C.min_iterations && control.displacement < C.motion && compression <= C.compression {
        control.converged = 1u;
        control.densities_known = 1u;
        kept.stopped = 1u;
        return;
    }
    control.displacement = moved;
    control.displacements[control.outer] = moved;
    control.outer += 1u;
    control.current = 1u - control.current;
    kept.k = k + 1u;
    if k + 1u >= C.min_iterations && moved < C.tau {
        control.converged = 1u;
        kept.stopped = 1u;
        return;
    }
    if k + 1u == C.max_iterations {
        kept.stopped = 3u;
    }
}
