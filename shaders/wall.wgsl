// uses: params consts kernel grid phase rigid
// reads: pos phase id body bodies cell_fluid
// writes: rho press vel
// Generalized wall boundary (Adami, Hu & Adams 2012): each wall particle gathers
// pressure and velocity from its fluid neighbours. Twin of src/backend/cpu/wall.rs.

@compute @workgroup_size(64)
fn wall(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = thread_index(gid, nwg);
    if (i >= active_particles()) { return; }
    let ph = phase[i];
    if (!is_wall(ph)) { return; }
    let pi = pos[i];
    let ci = cell_coord(pi);
    let zr = z_range();
    var sw = 0.0;
    var sp = 0.0;
    var sr = vec3<f32>(0.0);
    var sv = vec3<f32>(0.0);
    // Without fluid in the cells around, the sums stay zero: skip the loop.
    var gather = false;
    for (var dz = -zr; dz <= zr; dz++) {
        for (var dy = -1; dy <= 1; dy++) {
            for (var dx = -1; dx <= 1; dx++) {
                let c = neighbor_cell_index(ci, vec3<i32>(dx, dy, dz));
                if (c >= 0 && atomicLoad(&cell_fluid[u32(c)]) != 0u) {
                    gather = true;
                }
            }
        }
    }
    if (gather) {
        #for_each_neighbor(ci, zr, j) {
            let d = min_image(pi, pos[j]);
            let r2 = len2(d);
            if (r2 < P.kernel.support2 && !is_wall(phase[j])) {
                let wk = kernel_w(sqrt(r2));
                sw = sw + wk;
                sp = sp + press[j] * wk;
                let rw = rho[j] * wk;
                let v = vel[j];
                for (var a = 0u; a < 3u; a++) {
                    sr[a] = sr[a] + rw * d[a];
                    sv[a] = sv[a] + v[a] * wk;
                }
            }
        }
    }
    // The wall's own velocity: its phase's, or a body particle's rigid motion.
    var b = P.phases[ph].velocity;
    if ((P.sizes.flags & FLAG_BODIES) != 0u) {
        let k = body[id[i]];
        if (k != NO_BODY) {
            b = vec4<f32>(body_point_velocity(bodies[k], pi), 0.0);
        }
    }
    // Regularised Shepard division (the CPU twin explains why): as Σ W -> 0 the
    // pressure goes to 0 and the velocity to the wall's own, continuously.
    let g = P.flow.gravity;
    let den = sw + P.flow.wall_weight_floor;
    var p = (sp + (g.x * sr.x + g.y * sr.y + g.z * sr.z)) / den;
    let v = vec4<f32>(b.x + (b.x * sw - sv.x) / den, b.y + (b.y * sw - sv.y) / den, b.z + (b.z * sw - sv.z) / den, 0.0);
    if ((P.sizes.flags & FLAG_PRESSURE_FLOOR) != 0u) {
        p = max(p, 0.0);
    }
    rho[i] = P.phases[ph].rho0 + p / P.phases[ph].c2;
    press[i] = p;
    vel[i] = v;
}
