// The pool of kept corrections of multi-step projections (project.wgsl, sweep.wgsl): the
// entries taken so far in this local step (also those that did not fit) and whether one did
// not fit, which the host clears before every local step; whether the outer iteration has
// stopped and its k (control.wgsl); then the entries (m).
struct Pool {
    cursor: atomic<u32>,
    overflow: atomic<u32>,
    stopped: u32,
    k: u32,
    entries: array<vec4<f32>>,
}
