// Neighbour search. Twin of src/backend/cpu/neighbors.rs.
// 1. cell_keys: key (cell, index) per particle; padding keys sort last.
// 2. bitonic: one compare-exchange stage (j, k) of a bitonic sort over the padded keys.
//    Keys are unique, so the result is the single sorted order (stable by index).
// 3. reorder: gather every particle array into scratch in sorted order
//    (the host copies scratch back).
// 4. cell_bounds: start/end of each cell's run of sorted particles.

struct SortStage {
    j: u32,
    k: u32,
    pad0: u32,
    pad1: u32,
}

@group(1) @binding(0) var<uniform> stage: SortStage;

@compute @workgroup_size(64)
fn cell_keys(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = thread_index(gid, nwg);
    if (i >= arrayLength(&keys)) { return; }
    if (i < P.counts.x) {
        keys[i] = vec2<u32>(cell_index(cell_coord(pos[i])), i);
    } else {
        keys[i] = vec2<u32>(0xffffffffu, 0xffffffffu);
    }
}

@compute @workgroup_size(64)
fn bitonic(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = thread_index(gid, nwg);
    let l = i ^ stage.j;
    if (i >= arrayLength(&keys) || l <= i) { return; }
    let a = keys[i];
    let b = keys[l];
    let a_greater = a.x > b.x || (a.x == b.x && a.y > b.y);
    let ascending = (i & stage.k) == 0u;
    if (a_greater == ascending) {
        keys[i] = b;
        keys[l] = a;
    }
}

@compute @workgroup_size(64)
fn reorder(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let k = thread_index(gid, nwg);
    if (k >= P.counts.x) { return; }
    let s = keys[k].y;
    s_pos[k] = pos[s];
    s_vel[k] = vel[s];
    s_acc[k] = acc[s];
    s_acc_b[k] = acc_b[s];
    s_mass[k] = mass[s];
    s_phase[k] = phase[s];
    s_pid[k] = pid[s];
    if (P.heat.z != 0.0) {
        s_heat[k] = heat[s];
    }
}

@compute @workgroup_size(64)
fn cell_bounds(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let k = thread_index(gid, nwg);
    let n = P.counts.x;
    if (k >= n) { return; }
    let c = keys[k].x;
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
