// uses: params bindings consts kernel grid phase rigid
// writes: pos acc bodies slots
// Rigid bodies (F22 2.2, 3.4) in the kick-drift-kick step: half kicks of V and
// the world angular momentum L, drift, free rotation split into exact turns
// about the principal axes, members placed at X + R r0; F22 (39)-(40) contact
// on members; per-body sums over the members in ascending id, one thread per
// body. Twin of src/backend/cpu/bodies.rs (the derivation is there).

fn quat_mul(a: vec4<f32>, b: vec4<f32>) -> vec4<f32> {
    return vec4<f32>(
        a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
        a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x,
        a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w,
        a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z);
}

// Half kick: V += h (F/M + g), L += h tau (world frame).
fn kick_body(b0: Body, h: f32) -> Body {
    var b = b0;
    let g = P.flow.gravity;
    for (var c = 0u; c < 3u; c++) {
        b.v[c] = b.v[c] + h * (b.force[c] / b.x.w + g[c]);
        b.l[c] = b.l[c] + h * b.torque[c];
    }
    return b;
}

// The exact free rotation about body axis k for time tau (Cayley turn), the spin
// from the body-frame momentum R^T L of the current orientation.
fn turn(b0: Body, k: u32, tau: f32) -> Body {
    var b = b0;
    let lb = quat_rotate(quat_conj(b.q), b.l.xyz);
    let half = c_half() * (tau * (lb[k] / b.inertia[k]));
    let s = c_one() / sqrt(c_one() + half * half);
    var qr = vec4<f32>(0.0, 0.0, 0.0, s);
    qr[k] = half * s;
    b.q = quat_mul(b.q, qr);
    return b;
}

@compute @workgroup_size(64)
fn body_drift(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let k = thread_index(gid, nwg);
    if (k >= P.bodies.n_bodies) { return; }
    let dt = sim.dt;
    let h = c_half() * dt;
    var b = kick_body(bodies[k], h);
    for (var c = 0u; c < 3u; c++) {
        b.x[c] = b.x[c] + dt * b.v[c];
    }
    // Free rotation x(1/2) y(1/2) z(1) y(1/2) x(1/2), then q renormalised.
    b = turn(b, 0u, h);
    b = turn(b, 1u, h);
    b = turn(b, 2u, dt);
    b = turn(b, 1u, h);
    b = turn(b, 0u, h);
    let q = b.q;
    let n = sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
    b.q = vec4<f32>(q.x / n, q.y / n, q.z / n, q.w / n);
    bodies[k] = b;
}

@compute @workgroup_size(64)
fn body_place(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = thread_index(gid, nwg);
    if (i >= active_particles()) { return; }
    let k = body[id[i]];
    if (k == NO_BODY) { return; }
    let b = bodies[k];
    let r = quat_rotate(b.q, body_offset[id[i]].xyz);
    var x = pos[i];
    for (var c = 0u; c < 3u; c++) {
        x[c] = b.x[c] + r[c];
    }
    pos[i] = x;
}

// F22 (39)-(40): repulsive spring-dashpot with other bodies' particles and with
// wall and solid particles closer than dx, plus F22 (38): minus the pressure and
// viscous force the forces pass puts on each fluid neighbour from this particle
// (the same pair term, evaluated from this side); the force (N) into acc.
@compute @workgroup_size(64)
fn body_forces(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = thread_index(gid, nwg);
    if (i >= active_particles()) { return; }
    let k = body[id[i]];
    if (k == NO_BODY) { return; }
    let pi = pos[i];
    let ui = body_point_velocity(bodies[k], pi);
    let dist = P.bodies.contact_distance;
    let reach2 = dist * dist;
    let ci = cell_coord(pi);
    let zr = z_range();
    let ph_r = phase[i];
    let slip = (P.phases[ph_r].flags & PHASE_FREE_SLIP) != 0u;
    let p_r = press[i];
    let v_r = vel[i];
    var f = vec3<f32>(0.0);
    #for_each_neighbor(ci, zr, j) {
        let d = min_image(pi, pos[j]);
        let r2 = len2(d);
        let kj = body[id[j]];
        let ph_j = phase[j];
        if (r2 < P.kernel.support2 && r2 > 0.0 && kj == NO_BODY && !is_wall(ph_j)) {
            // The fluid particle j's view of this pair, as the forces pass has it.
            let r = sqrt(r2);
            let dwdr = kernel_dw(r);
            let rho_j = rho[j];
            let m_j = mass[j];
            let vol_j = m_j / rho_j;
            let rho_w = P.phases[ph_j].rho0 + p_r / P.phases[ph_j].c2;
            let vol_w = m_j / rho_w;
            let vv = vol_j * vol_j + vol_w * vol_w;
            let eta_j = P.phases[ph_j].eta;
            let fp = pressure(press[j], p_r, rho_j, rho_w, dwdr, r);
            let fv = viscosity(pair_viscosity(eta_j, eta_j, slip), dwdr, r);
            let v_j = vel[j];
            let dj = -d;
            for (var a = 0u; a < 3u; a++) {
                let u = v_j[a] - v_r[a];
                f[a] = f[a] - vv * (fp * dj[a] + fv * u);
            }
        }
        let solid_j = kj != NO_BODY || is_wall(phase[j]);
        if (r2 < P.kernel.support2 && kj != k && r2 < reach2 && r2 > 0.0 && solid_j) {
            var uj = vec3<f32>(0.0);
            if (kj != NO_BODY) {
                uj = body_point_velocity(bodies[kj], pos[j]);
            } else if (wall_moves(phase[j])) {
                uj = P.phases[phase[j]].velocity.xyz;
            }
            let r = sqrt(r2);
            let e = vec3<f32>(d.x / r, d.y / r, d.z / r);
            let gdot = -(e.x * (ui.x - uj.x) + e.y * (ui.y - uj.y) + e.z * (ui.z - uj.z));
            let fn_ = P.bodies.contact_stiffness * (dist - r) + P.bodies.contact_damping * gdot;
            if (fn_ > 0.0) {
                for (var c = 0u; c < 3u; c++) {
                    f[c] = f[c] + fn_ * e[c];
                }
            }
        }
    }
    acc[i] = vec4<f32>(f, 0.0);
}

// Each particle's current index by its id, for the per-body sums.
@compute @workgroup_size(64)
fn body_slots(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = thread_index(gid, nwg);
    if (i >= active_particles()) { return; }
    slots[id[i]] = i;
}

// Force and torque of one body: its members in ascending id, one after another.
@compute @workgroup_size(64)
fn body_sum(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let k = thread_index(gid, nwg);
    if (k >= P.bodies.n_bodies) { return; }
    var b = bodies[k];
    var f = vec3<f32>(0.0);
    var t = vec3<f32>(0.0);
    for (var m = b.first; m < b.first + b.count; m++) {
        let i = slots[members[m]];
        let fi = acc[i].xyz;
        let x = pos[i];
        let r = vec3<f32>(x.x - b.x.x, x.y - b.x.y, x.z - b.x.z);
        f = vec3<f32>(f.x + fi.x, f.y + fi.y, f.z + fi.z);
        t = vec3<f32>(
            t.x + r.y * fi.z - r.z * fi.y,
            t.y + r.z * fi.x - r.x * fi.z,
            t.z + r.x * fi.y - r.y * fi.x);
    }
    b.force = vec4<f32>(f, 0.0);
    b.torque = vec4<f32>(t, 0.0);
    bodies[k] = b;
}

@compute @workgroup_size(64)
fn body_kick(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let k = thread_index(gid, nwg);
    if (k >= P.bodies.n_bodies) { return; }
    bodies[k] = kick_body(bodies[k], c_half() * sim.dt);
}
