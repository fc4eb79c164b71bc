// uses: params consts kernel grid phase rigid
// reads: rho press mass phase id heat sim continuity
// writes: pos vel acc acc_b body body_offset bodies members slots
// Rigid bodies (F22 2.2, 3.4) in the kick-drift-kick step: half kicks of V and
// the world angular momentum L, drift, free rotation split into exact turns
// about the principal axes, members placed at X + R r0; F22 (39)-(40) contact
// on members (and F22 (38): the reaction to the forces pass's pressure, viscous
// and solid-fluid viscous force on each fluid neighbour); per-body sums over the
// members in ascending id, one thread per body. Twin of src/backend/cpu/bodies.rs (the derivation is there).

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
    if (k >= P.bodies.n_bodies || !body_moves(bodies[k])) { return; }
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
    // Its centre left the domain through an open side: it moves no more, and
    // body_place marks its members as leaving.
    if (outside_keep_box(b.x)) {
        // It stops where it left (as its removed members do); /bodies then
        // reads it at rest there.
        b.bonded = BODY_LEFT;
        b.v = vec4<f32>(0.0);
        b.l = vec4<f32>(0.0);
        b.force = vec4<f32>(0.0);
        b.torque = vec4<f32>(0.0);
    }
    bodies[k] = b;
}

@compute @workgroup_size(64)
fn body_place(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = thread_index(gid, nwg);
    if (i >= active_particles()) { return; }
    let k = body[id[i]];
    if (k == NO_BODY) { return; }
    let b = bodies[k];
    var x = pos[i];
    if (b.bonded == BODY_LEFT) {
        // The time it left in w: the next sort removes it (neighbors.wgsl).
        x.w = sim.time + sim.dt;
        pos[i] = x;
        return;
    }
    let r = quat_rotate(b.q, body_offset[id[i]].xyz);
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
            var fp = 0.0;
            if (!TERM_SHEPARD_PRESSURE) {
                fp = pressure(press[j], p_r, rho_j, rho_w, dwdr, r);
            }
            let eta_jw = pair_viscosity(eta_j, eta_j, slip);
            var fv = 0.0;
            if (!TERM_MARRONE_VISCOSITY) {
                fv = viscosity(eta_jw, dwdr, r);
            }
            let v_j = vel[j];
            let dj = -d;
            for (var a = 0u; a < 3u; a++) {
                let u = v_j[a] - v_r[a];
                f[a] = f[a] - vv * (fp * dj[a] + fv * u);
            }
            if (TERM_SHEPARD_PRESSURE) {
                let s = shepard_pressure(m_j, m_j, rho_j, rho_w, press[j], p_r, continuity[j].y, c_one(), dwdr, r);
                for (var a = 0u; a < 3u; a++) {
                    f[a] = f[a] - s * dj[a];
                }
            }
            if (TERM_MARRONE_VISCOSITY) {
                let s = marrone_viscosity(m_j, m_j, rho_j, rho_w, eta_jw, v_j.xyz - v_r.xyz, dj, r2, dwdr, r);
                for (var a = 0u; a < 3u; a++) {
                    f[a] = f[a] - s * dj[a];
                }
            }
            if (TERM_SOLID_FLUID_VISCOSITY) {
                // F22 (33) as the forces pass applies it between the melt and a
                // wall: the fluid's own alpha^sf, mass and sound speed.
                let alpha_j = solid_fluid_viscosity_alpha(ph_j, heat[j][H_TEMPERATURE]);
                let alpha = (alpha_j + alpha_j) * c_half();
                let c2_j = P.phases[ph_j].c2;
                let s = solid_fluid_viscosity(m_j, m_j, rho_j, rho_w, c2_j, c2_j, v_j.xyz - v_r.xyz, dj, r2, dwdr, alpha);
                for (var a = 0u; a < 3u; a++) {
                    f[a] = f[a] - s * dj[a];
                }
            }
            if (TERM_BARRIER && r < P.flow.barrier_radius) {
                // F22 (34) as the forces pass applies it to the fluid from a
                // wall particle: the wall phase's velocity, not the body's.
                let s = barrier(v_j, P.phases[ph_r].velocity, dj, r);
                for (var a = 0u; a < 3u; a++) {
                    f[a] = f[a] - s * dj[a];
                }
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
    if (k >= P.bodies.n_bodies || !body_moves(bodies[k])) { return; }
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
    if (k >= P.bodies.n_bodies || !body_moves(bodies[k])) { return; }
    bodies[k] = kick_body(bodies[k], c_half() * sim.dt);
}

// A particle that solidified in this step (BODY_SOLIDIFIED, from the temperature
// pass) flags every body particle within 1.5 dx (body_offset.w = 1; threads that
// flag the same particle write the same value) and is NO_BODY again.
@compute @workgroup_size(64)
fn body_bond(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = thread_index(gid, nwg);
    if (i >= active_particles()) { return; }
    if (body[id[i]] != BODY_SOLIDIFIED) { return; }
    body[id[i]] = NO_BODY;
    let pi = pos[i];
    let reach = c_one_and_half() * P.bodies.contact_distance;
    let reach2 = reach * reach;
    let ci = cell_coord(pi);
    let zr = z_range();
    #for_each_neighbor(ci, zr, j) {
        let d = min_image(pi, pos[j]);
        if (len2(d) < reach2 && body[id[j]] < P.bodies.n_bodies) {
            body_offset[id[j]].w = c_one();
        }
    }
}

// A melted member leaves body b: a fluid particle with b's material velocity,
// taking its own force f (in acc) with it as the acceleration f/m; returns f.
fn release(b: Body, m_id: u32, i: u32) -> vec3<f32> {
    let u = body_point_velocity(b, pos[i]);
    let f = acc[i].xyz;
    let m = mass[i];
    vel[i] = vec4<f32>(u, vel[i].w);
    acc[i] = vec4<f32>(f.x / m, f.y / m, f.z / m, 0.0);
    acc_b[i] = vec4<f32>(0.0);
    body[m_id] = NO_BODY;
    return f;
}

// Body k bonds into the substrate: melted members leave, the rest stay put as
// fixed solid particles and stay listed (count, their mass); bonded stops every
// body pass.
fn bond_body(k: u32) {
    var b = bodies[k];
    var kept = 0u;
    var m_new = 0.0;
    for (var m = b.first; m < b.first + b.count; m++) {
        let m_id = members[m];
        let i = slots[m_id];
        body[m_id] = NO_BODY;
        if (!is_wall(phase[i])) {
            // Its force leaves with it; the rest goes into the substrate.
            _ = release(b, m_id, i);
            continue;
        }
        members[b.first + kept] = m_id;
        kept++;
        m_new = m_new + mass[i];
        vel[i] = vec4<f32>(0.0, 0.0, 0.0, vel[i].w);
        acc[i] = vec4<f32>(0.0);
        acc_b[i] = vec4<f32>(0.0);
    }
    b.count = kept;
    b.x.w = m_new;
    b.bonded = BODY_BONDED;
    b.v = vec4<f32>(0.0);
    b.l = vec4<f32>(0.0);
    b.force = vec4<f32>(0.0);
    b.torque = vec4<f32>(0.0);
    bodies[k] = b;
}

fn mat_mul(a: array<vec3<f32>, 3>, b: array<vec3<f32>, 3>) -> array<vec3<f32>, 3> {
    var c: array<vec3<f32>, 3>;
    for (var i = 0u; i < 3u; i++) {
        for (var j = 0u; j < 3u; j++) {
            c[i][j] = a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j];
        }
    }
    return c;
}

fn transpose3(a: array<vec3<f32>, 3>) -> array<vec3<f32>, 3> {
    var t: array<vec3<f32>, 3>;
    for (var i = 0u; i < 3u; i++) {
        for (var j = 0u; j < 3u; j++) {
            t[i][j] = a[j][i];
        }
    }
    return t;
}

fn identity3() -> array<vec3<f32>, 3> {
    return array<vec3<f32>, 3>(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0), vec3<f32>(0.0, 0.0, 1.0));
}

struct Eigen {
    moments: vec3<f32>,
    axes: array<vec3<f32>, 3>,   // rows; the axes are the columns
}

// Cyclic Jacobi rotations with the algebraic angle (square roots only), 6 sweeps;
// twin of backend::cpu::bodies::jacobi (the reasoning is there).
fn jacobi(a0: array<vec3<f32>, 3>) -> Eigen {
    var a = a0;
    var q = identity3();
    for (var sweep = 0u; sweep < 6u; sweep++) {
        for (var pair = 0u; pair < 3u; pair++) {
            let p = select(0u, 1u, pair == 2u);
            let r = select(1u, 2u, pair != 0u);
            let apr = a[p][r];
            if (abs(apr) <= c_jacobi_floor() * (abs(a[p][p]) + abs(a[r][r]))) { continue; }
            let theta = (a[r][r] - a[p][p]) / (apr + apr);
            let t_abs = c_one() / (abs(theta) + sqrt(theta * theta + c_one()));
            let t = select(t_abs, -t_abs, theta < 0.0);
            let c = c_one() / sqrt(t * t + c_one());
            let s = t * c;
            var g = identity3();
            g[p][p] = c;
            g[r][r] = c;
            g[p][r] = s;
            g[r][p] = -s;
            a = mat_mul(transpose3(g), mat_mul(a, g));
            a[p][r] = 0.0;
            a[r][p] = 0.0;
            q = mat_mul(q, g);
        }
    }
    return Eigen(vec3<f32>(a[0][0], a[1][1], a[2][2]), q);
}

fn normalized4(q: vec4<f32>) -> vec4<f32> {
    let n = sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
    return vec4<f32>(q.x / n, q.y / n, q.z / n, q.w / n);
}

// The unit quaternion of a rotation matrix (Shepperd), twin of
// backend::cpu::bodies::quaternion_of.
fn quaternion_of(r: array<vec3<f32>, 3>) -> vec4<f32> {
    let t = r[0][0] + r[1][1] + r[2][2];
    var q: vec4<f32>;
    if (t > max(max(r[0][0], r[1][1]), r[2][2])) {
        let w = c_half() * sqrt(c_one() + t);
        let f = c_quarter() / w;
        q = vec4<f32>((r[2][1] - r[1][2]) * f, (r[0][2] - r[2][0]) * f, (r[1][0] - r[0][1]) * f, w);
    } else if (r[0][0] >= r[1][1] && r[0][0] >= r[2][2]) {
        let x = c_half() * sqrt(c_one() + r[0][0] - r[1][1] - r[2][2]);
        let f = c_quarter() / x;
        q = vec4<f32>(x, (r[0][1] + r[1][0]) * f, (r[0][2] + r[2][0]) * f, (r[2][1] - r[1][2]) * f);
    } else if (r[1][1] >= r[2][2]) {
        let y = c_half() * sqrt(c_one() - r[0][0] + r[1][1] - r[2][2]);
        let f = c_quarter() / y;
        q = vec4<f32>((r[0][1] + r[1][0]) * f, y, (r[1][2] + r[2][1]) * f, (r[0][2] - r[2][0]) * f);
    } else {
        let z = c_half() * sqrt(c_one() - r[0][0] - r[1][1] + r[2][2]);
        let f = c_quarter() / z;
        q = vec4<f32>((r[0][2] + r[2][0]) * f, (r[1][2] + r[2][1]) * f, z, (r[1][0] - r[0][1]) * f);
    }
    return normalized4(q);
}

// Body k sheds its melted members (F22 (37)); twin of backend::cpu::bodies::shed.
fn shed(k: u32) {
    let b = bodies[k];
    var kept = 0u;
    var m_new = 0.0;
    var s = vec3<f32>(0.0);
    // The force and torque (about the old centre) of the members that stay.
    var f = b.force.xyz;
    var tq = b.torque.xyz;
    for (var m = b.first; m < b.first + b.count; m++) {
        let m_id = members[m];
        let i = slots[m_id];
        if (!is_wall(phase[i])) {
            let x = pos[i];
            let fk = release(b, m_id, i);
            let r = vec3<f32>(x.x - b.x.x, x.y - b.x.y, x.z - b.x.z);
            f = vec3<f32>(f.x - fk.x, f.y - fk.y, f.z - fk.z);
            tq = vec3<f32>(
                tq.x - r.y * fk.z + r.z * fk.y,
                tq.y - r.z * fk.x + r.x * fk.z,
                tq.z - r.x * fk.y + r.y * fk.x);
            continue;
        }
        members[b.first + kept] = m_id;
        kept++;
        let mi = mass[i];
        let r0 = body_offset[m_id];
        m_new = m_new + mi;
        for (var c = 0u; c < 3u; c++) {
            s[c] = s[c] + mi * r0[c];
        }
    }
    var nb = b;
    nb.count = kept;
    if (kept == 0u) {
        nb.x.w = 0.0;
        nb.v = vec4<f32>(0.0);
        nb.l = vec4<f32>(0.0);
        nb.force = vec4<f32>(0.0);
        nb.torque = vec4<f32>(0.0);
        bodies[k] = nb;
        return;
    }
    let c0 = vec3<f32>(s.x / m_new, s.y / m_new, s.z / m_new);
    let ip = b.inertia.w;
    var a: array<vec3<f32>, 3>;
    for (var m = b.first; m < b.first + kept; m++) {
        let m_id = members[m];
        let mi = mass[slots[m_id]];
        let o = body_offset[m_id];
        let r = vec3<f32>(o.x - c0.x, o.y - c0.y, o.z - c0.z);
        let r2 = r.x * r.x + r.y * r.y + r.z * r.z;
        for (var p = 0u; p < 3u; p++) {
            a[p][p] = a[p][p] + mi * (ip + r2 - r[p] * r[p]);
        }
        a[0][1] = a[0][1] - mi * (r.x * r.y);
        a[0][2] = a[0][2] - mi * (r.x * r.z);
        a[1][2] = a[1][2] - mi * (r.y * r.z);
    }
    a[1][0] = a[0][1];
    a[2][0] = a[0][2];
    a[2][1] = a[1][2];
    let e = jacobi(a);
    let axes = e.axes;
    for (var m = b.first; m < b.first + kept; m++) {
        let m_id = members[m];
        let o = body_offset[m_id];
        let r = vec3<f32>(o.x - c0.x, o.y - c0.y, o.z - c0.z);
        var t: vec3<f32>;
        for (var j = 0u; j < 3u; j++) {
            t[j] = axes[0][j] * r.x + axes[1][j] * r.y + axes[2][j] * r.z;
        }
        body_offset[m_id] = vec4<f32>(t, 0.0);
    }
    let w = body_angular_velocity(b);
    let cw = quat_rotate(b.q, c0);
    let q = normalized4(quat_mul(b.q, quaternion_of(axes)));
    let lb = quat_rotate(quat_conj(q), w);
    let l = quat_rotate(q, vec3<f32>(lb.x * e.moments.x, lb.y * e.moments.y, lb.z * e.moments.z));
    nb.x = vec4<f32>(b.x.x + cw.x, b.x.y + cw.y, b.x.z + cw.z, m_new);
    nb.q = q;
    nb.v = vec4<f32>(
        b.v.x + w.y * cw.z - w.z * cw.y,
        b.v.y + w.z * cw.x - w.x * cw.z,
        b.v.z + w.x * cw.y - w.y * cw.x,
        0.0);
    nb.l = vec4<f32>(l, 0.0);
    nb.inertia = vec4<f32>(e.moments, ip);
    nb.force = vec4<f32>(f, 0.0);
    nb.torque = vec4<f32>(
        tq.x - cw.y * f.z + cw.z * f.y,
        tq.y - cw.z * f.x + cw.x * f.z,
        tq.z - cw.x * f.y + cw.y * f.x,
        0.0);
    bodies[k] = nb;
}

// F22 (37) and the bonding rule per body (backend::cpu::bodies::melt says how):
// a body touched by solidifying melt bonds into the substrate, otherwise its
// melted members leave.
@compute @workgroup_size(64)
fn body_melt(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let k = thread_index(gid, nwg);
    if (k >= P.bodies.n_bodies) { return; }
    let b = bodies[k];
    if (!body_moves(b)) { return; }
    var melted = false;
    var touched = false;
    for (var m = b.first; m < b.first + b.count; m++) {
        let m_id = members[m];
        melted = melted || !is_wall(phase[slots[m_id]]);
        touched = touched || body_offset[m_id].w > 0.0;
    }
    if (touched) {
        bond_body(k);
    } else if (melted) {
        shed(k);
    }
}
