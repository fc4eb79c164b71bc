// uses: params consts grid phase
// reads: acc acc_b phase heat sim
// writes: pos vel
// Velocity Verlet with transport velocity. Twin of src/backend/cpu/integrate.rs.

@compute @workgroup_size(64)
fn kick_drift(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = thread_index(gid, nwg);
    if (i >= active_particles()) { return; }
    let ph = phase[i];
    let dt = sim.dt;
    if (is_wall(ph)) {
        // A moving wall drifts with its prescribed velocity; others stay.
        if (wall_moves(ph)) {
            let w = P.phases[ph].velocity;
            var xw = pos[i];
            for (var c = 0u; c < 3u; c++) {
                xw[c] = wrap_periodic(xw[c] + dt * w[c], c);
            }
            pos[i] = xw;
        }
        return;
    }
    let hdt = c_half() * dt;
    let a = acc[i];
    let ab = acc_b[i];
    var v = vel[i];
    var x = pos[i];
    for (var c = 0u; c < 3u; c++) {
        v[c] = v[c] + hdt * a[c];
        x[c] = wrap_periodic(x[c] + dt * (v[c] + hdt * ab[c]), c);
    }
    vel[i] = v;
    pos[i] = stamp_if_left(x);
}

@compute @workgroup_size(64)
fn kick(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = thread_index(gid, nwg);
    if (i >= active_particles()) { return; }
    if (is_wall(phase[i])) { return; }
    let hdt = c_half() * sim.dt;
    let a = acc[i];
    var v = vel[i];
    for (var c = 0u; c < 3u; c++) {
        v[c] = v[c] + hdt * a[c];
    }
    // Mushy-zone sink J22 (12): v / (1 + dt C (1 - f_l)), semi-implicit.
    let sink = P.phases[phase[i]].mushy_damping;
    if (sink > 0.0) {
        let damp = c_one() + sim.dt * sink * (c_one() - heat[i][H_LIQUID]);
        for (var c = 0u; c < 3u; c++) {
            v[c] = v[c] / damp;
        }
    }
    vel[i] = v;
}
