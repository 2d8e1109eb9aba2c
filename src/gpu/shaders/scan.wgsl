// Exclusive prefix sums of u32 counts (the cells' and the neighbour lists' offsets,
// docs/method.md §6), in three passes over blocks of 1024: each block's sum, the scan of
// the block sums by one workgroup, then each block's own scan. Integer sums: the result
// does not depend on the order of the additions.

struct ScanParams {
    // Entries to scan; output receives len + 1 (the total last).
    len: u32,
    blocks: u32,
    pad0: u32,
    pad1: u32,
}

@group(0) @binding(0) var<uniform> S: ScanParams;
@group(0) @binding(1) var<storage, read_write> input: array<u32>;
@group(0) @binding(2) var<storage, read_write> output: array<u32>;
@group(0) @binding(3) var<storage, read_write> sums: array<u32>;

const THREADS: u32 = 256u;
const PER_THREAD: u32 = 4u;
const BLOCK: u32 = 1024u;

var<workgroup> shared_sums: array<u32, 256>;

fn block_of(wid: vec3<u32>, nwg: vec3<u32>) -> u32 {
    return wid.y * nwg.x + wid.x;
}

// Inclusive scan of shared_sums (Hillis–Steele); every thread must call it.
fn scan_shared(lid: u32) {
    for (var offset = 1u; offset < THREADS; offset *= 2u) {
        workgroupBarrier();
        var add = 0u;
        if lid >= offset {
            add = shared_sums[lid - offset];
        }
        workgroupBarrier();
        shared_sums[lid] += add;
    }
    workgroupBarrier();
}

fn thread_total(first: u32) -> u32 {
    var total = 0u;
    for (var k = 0u; k < PER_THREAD; k++) {
        let e = first + k;
        if e < S.len {
            total += input[e];
        }
    }
    return total;
}

@compute @workgroup_size(256)
fn block_sums(@builtin(workgroup_id) wid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
              @builtin(local_invocation_index) lid: u32) {
    let b = block_of(wid, nwg);
    shared_sums[lid] = thread_total(b * BLOCK + lid * PER_THREAD);
    scan_shared(lid);
    if lid == THREADS - 1u && b < S.blocks {
        sums[b] = shared_sums[lid];
    }
}

// One workgroup: the block sums turned into the blocks' starting offsets, the total into
// output[len].
@compute @workgroup_size(256)
fn scan_sums(@builtin(local_invocation_index) lid: u32) {
    var carry = 0u;
    for (var first = 0u; first < S.blocks; first += THREADS) {
        let b = first + lid;
        var value = 0u;
        if b < S.blocks {
            value = sums[b];
        }
        shared_sums[lid] = value;
        scan_shared(lid);
        if b < S.blocks {
            sums[b] = carry + shared_sums[lid] - value;
        }
        carry += shared_sums[THREADS - 1u];
        workgroupBarrier();
    }
    if lid == 0u {
        output[S.len] = carry;
    }
}

@compute @workgroup_size(256)
fn scan_blocks(@builtin(workgroup_id) wid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
               @builtin(local_invocation_index) lid: u32) {
    let b = block_of(wid, nwg);
    let first = b * BLOCK + lid * PER_THREAD;
    let own = thread_total(first);
    shared_sums[lid] = own;
    scan_shared(lid);
    if b >= S.blocks {
        return;
    }
    var running = sums[b] + shared_sums[lid] - own;
    for (var k = 0u; k < PER_THREAD; k++) {
        let e = first + k;
        if e < S.len {
            output[e] = running;
            running += input[e];
        }
    }
}
