// Velocity Verlet with transport velocity. Twin of src/backend/cpu/integrate.rs.

@compute @workgroup_size(64)
fn kick_drift(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = thread_index(gid, nwg);
    if (i >= P.counts.x) { return; }
    if (is_wall(phase[i])) { return; }
    let dt = sim.dt;
    let hdt = c_half() * dt;
    let a = acc[i];
    let ab = acc_b[i];
    var v = vel[i];
    var x = pos[i];
    for (var c = 0u; c < 3u; c++) {
        v[c] = v[c] + hdt * a[c];
        x[c] = x[c] + dt * (v[c] + hdt * ab[c]);
        if ((P.grid.w & (1u << c)) != 0u) {
            if (x[c] >= P.period[c]) {
                x[c] = x[c] - P.period[c];
            } else if (x[c] < 0.0) {
                x[c] = x[c] + P.period[c];
            }
        }
    }
    vel[i] = v;
    pos[i] = x;
}

@compute @workgroup_size(64)
fn kick(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = thread_index(gid, nwg);
    if (i >= P.counts.x) { return; }
    if (is_wall(phase[i])) { return; }
    let hdt = c_half() * sim.dt;
    let a = acc[i];
    var v = vel[i];
    for (var c = 0u; c < 3u; c++) {
        v[c] = v[c] + hdt * a[c];
    }
    // Mushy-zone sink J22 (12): v / (1 + dt C (1 - f_l)), semi-implicit.
    let sink = P.phase_g[phase[i]].x;
    if (sink > 0.0) {
        let damp = c_one() + sim.dt * sink * (c_one() - heat[i].z);
        for (var c = 0u; c < 3u; c++) {
            v[c] = v[c] / damp;
        }
    }
    vel[i] = v;
}
