// uses: params grid phase
// reads: pos phase
// writes: keys cell_start cell_end cell_fluid sim
// Neighbour search. Twin of src/backend/cpu/neighbors/mod.rs.
// 1. cell_keys: key (cell, index) per particle; a particle that has left the
//    domain gets cell n_cells (after every cell), padding keys sort last.
// 2. bitonic sort over the padded keys. Keys are unique, so the result is the single
//    sorted order (stable by index). Stages whose pairs lie inside one block of
//    SORT_BLOCK keys run in workgroup memory (bitonic_local, many stages per
//    dispatch); only stages with j >= SORT_BLOCK go through global memory
//    (bitonic_global, one stage per dispatch). At 2^24 keys that is 91 global
//    passes and 14 local ones instead of 300 global ones.
// 3. reorder: gather every particle array into scratch in sorted order
//    (the host copies scratch back).
// 4. cell_bounds: start/end of each cell's run of sorted particles, and the
//    number of removed particles (sim.removed).

// One sort dispatch: bitonic_global runs stage (j, k); bitonic_local runs, for every
// k from k to k_last (doubling), the stages j = min(k/2, SORT_BLOCK/2) down to 1.
struct SortStage {
    j: u32,
    k: u32,
    k_last: u32,
    pad0: u32,
}

@group(1) @binding(0) var<uniform> stage: SortStage;

// Twin of SORT_BLOCK in src/backend/gpu/mod.rs. 2048 keys of 8 bytes fill the 16 KiB
// of workgroup memory every WebGPU adapter offers.
const SORT_BLOCK: u32 = 2048u;
const SORT_THREADS: u32 = 256u;
var<workgroup> sort_tile: array<vec2<u32>, 2048>;

fn key_greater(a: vec2<u32>, b: vec2<u32>) -> bool {
    return a.x > b.x || (a.x == b.x && a.y > b.y);
}

// Lower index of the p-th compare-exchange pair of a stage with distance j (a power
// of two): p's bits below j stay, the bits above move up one to skip the partners.
fn pair_low(p: u32, j: u32) -> u32 {
    return ((p & ~(j - 1u)) << 1u) | (p & (j - 1u));
}

@compute @workgroup_size(64)
fn cell_keys(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = thread_index(gid, nwg);
    if (i >= arrayLength(&keys)) { return; }
    if (i < P.sizes.n_particles) {
        // A fluid particle outside the keep box has left: its key, n_cells, sorts
        // it after every cell and keeps it out of the cell table. Walls
        // stay, wherever they stand (those of a closed side reach past the open
        // face above it), except the members of a rigid body that left, which
        // body_place stamped with the time it left (w > 0).
        var gone = outside_keep_box(pos[i]);
        if (is_wall(phase[i])) {
            gone = pos[i].w > 0.0;
        }
        var c = P.sizes.n_cells;
        if (!gone) {
            c = cell_index(cell_coord(pos[i]));
        }
        keys[i] = vec2<u32>(c, i);
    } else {
        keys[i] = vec2<u32>(0xffffffffu, 0xffffffffu);
    }
}

@compute @workgroup_size(64)
fn bitonic_global(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let p = thread_index(gid, nwg);
    if (p >= arrayLength(&keys) / 2u) { return; }
    let i = pair_low(p, stage.j);
    let l = i + stage.j;
    let a = keys[i];
    let b = keys[l];
    let ascending = (i & stage.k) == 0u;
    if (key_greater(a, b) == ascending) {
        keys[i] = b;
        keys[l] = a;
    }
}

@compute @workgroup_size(256)
fn bitonic_local(@builtin(local_invocation_index) t: u32, @builtin(workgroup_id) wid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let block = min(SORT_BLOCK, arrayLength(&keys));
    let base = (wid.x + wid.y * nwg.x) * block;
    for (var e = t; e < block; e += SORT_THREADS) {
        sort_tile[e] = keys[base + e];
    }
    workgroupBarrier();
    for (var k = stage.k; k <= stage.k_last; k = k * 2u) {
        for (var j = min(k / 2u, SORT_BLOCK / 2u); j > 0u; j = j / 2u) {
            for (var p = t; p < block / 2u; p += SORT_THREADS) {
                let i = pair_low(p, j);
                let l = i + j;
                let a = sort_tile[i];
                let b = sort_tile[l];
                let ascending = ((base + i) & k) == 0u;
                if (key_greater(a, b) == ascending) {
                    sort_tile[i] = b;
                    sort_tile[l] = a;
                }
            }
            workgroupBarrier();
        }
    }
    for (var e = t; e < block; e += SORT_THREADS) {
        keys[base + e] = sort_tile[e];
    }
}

@compute @workgroup_size(64)
fn reorder(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let k = thread_index(gid, nwg);
    if (k >= P.sizes.n_particles) { return; }
    let s = keys[k].y;
    // Every sorted field of crate::fields::FIELDS: s_<field>[k] = <field>[s].
    #reorder_sorted_fields(k, s)
}

@compute @workgroup_size(64)
fn cell_bounds(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let k = thread_index(gid, nwg);
    let n = P.sizes.n_particles;
    if (k >= n) { return; }
    let c = keys[k].x;
    let gone = P.sizes.n_cells;
    // The removed particles are the last run of keys: its first one counts them.
    if (c == gone) {
        if (k == 0u || keys[k - 1u].x != gone) {
            sim.removed = n - k;
        }
        return;
    }
    if (k == n - 1u) {
        sim.removed = 0u;
    }
    if (k == 0u || keys[k - 1u].x != c) {
        cell_start[c] = k;
    }
    if (k == n - 1u || keys[k + 1u].x != c) {
        cell_end[c] = k + 1u;
    }
    if (!is_wall(phase[k])) {
        atomicOr(&cell_fluid[c], 1u);
    }
}
