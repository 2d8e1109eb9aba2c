// The neighbour search on the prediction s (docs/method.md §6): every fluid particle's
// fluid neighbours (j ≠ i, |s_i − s_j| ≤ H) and boundary neighbours, counted in one pass
// and written in a second into lists laid out by the prefix sums of the counts (CSR). A
// list follows the 27 cells in a fixed order and each cell in the sort's order, so it is
// the same on every run.

@group(0) @binding(0) var<uniform> P: StepParams;
@group(0) @binding(1) var<storage, read_write> s: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read_write> cell_start: array<u32>;
@group(0) @binding(3) var<storage, read_write> boundary: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read_write> boundary_start: array<u32>;
@group(0) @binding(5) var<storage, read_write> fluid_count: array<u32>;
@group(0) @binding(6) var<storage, read_write> boundary_count: array<u32>;
@group(0) @binding(7) var<storage, read_write> fluid_offset: array<u32>;
@group(0) @binding(8) var<storage, read_write> boundary_offset: array<u32>;
@group(0) @binding(9) var<storage, read_write> fluid_list: array<u32>;
@group(0) @binding(10) var<storage, read_write> boundary_list: array<u32>;

// Counts (write = false) or writes (write = true) the neighbours of particle i.
fn visit(i: u32, write: bool) {
    let p = s[i].xyz;
    let h2 = P.h * P.h;
    let centre = cell_coords(p);
    let top = vec3<i32>(P.dims.xyz) - 1;
    let low = max(centre - 1, vec3<i32>(0));
    let high = min(centre + 1, top);
    var fluid = 0u;
    var walls = 0u;
    var fluid_at = 0u;
    var walls_at = 0u;
    if write {
        fluid_at = fluid_offset[i];
        walls_at = boundary_offset[i];
    }
    for (var z = low.z; z <= high.z; z++) {
        for (var y = low.y; y <= high.y; y++) {
            for (var cx = low.x; cx <= high.x; cx++) {
                let c = cell_index(vec3<i32>(cx, y, z));
                for (var j = cell_start[c]; j < cell_start[c + 1u]; j++) {
                    let d = p - s[j].xyz;
                    if j != i && dot(d, d) <= h2 {
                        if write {
                            fluid_list[fluid_at + fluid] = j;
                        }
                        fluid++;
                    }
                }
                for (var b = boundary_start[c]; b < boundary_start[c + 1u]; b++) {
                    let d = p - boundary[b].xyz;
                    if dot(d, d) <= h2 {
                        if write {
                            boundary_list[walls_at + walls] = b;
                        }
                        walls++;
                    }
                }
            }
        }
    }
    if !write {
        fluid_count[i] = fluid;
        boundary_count[i] = walls;
    }
}

@compute @workgroup_size(256)
fn count(@builtin(workgroup_id) wid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
         @builtin(local_invocation_index) lid: u32) {
    let i = item(wid, nwg, lid);
    if i < P.n {
        visit(i, false);
    }
}

@compute @workgroup_size(256)
fn fill(@builtin(workgroup_id) wid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
        @builtin(local_invocation_index) lid: u32) {
    let i = item(wid, nwg, lid);
    if i < P.n {
        visit(i, true);
    }
}
