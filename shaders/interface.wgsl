// uses: params consts kernel grid phase
// reads: pos rho mass phase heat
// writes: surface
// Interface normal and surface delta of the condensed material, R18 (3.25)-(3.27).
// Twin of src/backend/cpu/interface.rs (equations there). surface[i] = (n, delta),
// surface[n + i][S_SHEPARD] = Shepard sum Gamma_i.

fn condensed(ph: u32) -> bool {
    return P.phases[ph].kind != KIND_GAS;
}

// Twin of Params::gets_interface (both forms).
fn gets_interface(ph: u32) -> bool {
    let flows = P.flow.interface_viscosity > 0.0 || (P.sizes.flags & FLAG_SURFACE_TENSION) != 0u;
    return conducts(ph) || (flows && !is_wall(ph));
}

fn volume(j: u32) -> f32 {
    return mass[j] / P.phases[phase[j]].rho0;
}

@compute @workgroup_size(64)
fn shepard(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = thread_index(gid, nwg);
    let n = P.sizes.n_particles;
    if (i >= active_particles()) { return; }
    var g = 0.0;
    if (condensed(phase[i])) {
        let pi = pos[i];
        let ci = cell_coord(pi);
        let zr = z_range();
        #for_each_neighbor(ci, zr, j) {
            let r2 = len2(min_image(pi, pos[j]));
            if (r2 < P.kernel.support2 && condensed(phase[j])) {
                g = g + volume(j) * kernel_w(sqrt(r2));
            }
        }
    }
    surface[n + i] = vec4<f32>(g, 0.0, 0.0, 0.0);
}

fn vol_density(j: u32) -> f32 {
    let ph = phase[j];
    if (is_wall(ph)) {
        return P.phases[ph].rho0;
    }
    return rho[j];
}

// F22 (19)-(20): condensed-gas interface, for scenes with gas particles.
fn gas_interface(i: u32) {
    let ph = phase[i];
    if (!gets_interface(ph)) {
        surface[i] = vec4<f32>(0.0, 0.0, 0.0, 0.0);
        return;
    }
    let side = condensed(ph);
    let rho_i = vol_density(i);
    let v_i = mass[i] / rho_i;
    let pi = pos[i];
    let ci = cell_coord(pi);
    let zr = z_range();
    var g = vec3<f32>(0.0, 0.0, 0.0);
    #for_each_neighbor(ci, zr, j) {
        let d = min_image(pi, pos[j]);
        let r2 = len2(d);
        if (r2 >= P.kernel.support2 || r2 <= 0.0 || condensed(phase[j]) == side) { continue; }
        let rho_j = vol_density(j);
        let v_j = mass[j] / rho_j;
        let r = sqrt(r2);
        let f = (v_i * v_i + v_j * v_j) * (rho_i / (rho_i + rho_j)) * kernel_dw(r) / r;
        g.x = g.x + f * d.x;
        g.y = g.y + f * d.y;
        g.z = g.z + f * d.z;
    }
    g = vec3<f32>(g.x / v_i, g.y / v_i, g.z / v_i);
    let delta = sqrt(g.x * g.x + g.y * g.y + g.z * g.z);
    if (delta > c_tenth() * P.kernel.inv_h) {
        surface[i] = vec4<f32>(g.x / delta, g.y / delta, g.z / delta, delta * P.surfaces.inv_kappa);
    } else {
        surface[i] = vec4<f32>(0.0, 0.0, 0.0, 0.0);
    }
}

// F22's chi_j of a wall or solid neighbour: 1 - clamp((T_j - T_m) / dT_s + 1, 0, 1)
// for a conducting (solid) particle with the tension ramp, 1 otherwise.
fn solid_weight(j: u32) -> f32 {
    if (P.tension.inv_ramp_width == 0.0 || !conducts(phase[j])) {
        return c_one();
    }
    return c_one() - min(max((heat[j][H_TEMPERATURE] - P.tension.t_melt) * P.tension.inv_ramp_width + c_one(), 0.0), c_one());
}

// Wetting by a prescribed normal, F22 (27)-(29) (the CPU twin explains it). It
// reads only its own normal (and the neighbours' positions), so the `wetting`
// dispatch rewrites surface[i] in place.
fn wet(i: u32, n: vec4<f32>) -> vec4<f32> {
    var c = 0.0;
    var cw = 0.0;
    var sw = 0.0;
    var g = vec3<f32>(0.0, 0.0, 0.0);
    let pi = pos[i];
    let ci = cell_coord(pi);
    let zr = z_range();
    #for_each_neighbor(ci, zr, j) {
        let d = min_image(pi, pos[j]);
        let r2 = len2(d);
        let ph = phase[j];
        if (r2 >= P.kernel.support2 || r2 <= 0.0 || !is_wall(ph)) { continue; }
        let r = sqrt(r2);
        let v = mass[j] / P.phases[ph].rho0 * solid_weight(j);
        let wv = v * kernel_w(r);
        c = c + wv;
        cw = cw + wv * P.phases[ph].contact_cos;
        sw = sw + wv * P.phases[ph].contact_sin;
        let f = v * kernel_dw(r) / r;
        g.x = g.x + f * d.x;
        g.y = g.y + f * d.y;
        g.z = g.z + f * d.z;
    }
    let gl = sqrt(g.x * g.x + g.y * g.y + g.z * g.z);
    if (gl <= c_tenth() * P.kernel.inv_h) {
        return n;
    }
    let ns = vec3<f32>(g.x / gl, g.y / gl, g.z / gl);
    let nn = n.x * ns.x + n.y * ns.y + n.z * ns.z;
    var t = vec3<f32>(n.x - nn * ns.x, n.y - nn * ns.y, n.z - nn * ns.z);
    let tl = sqrt(t.x * t.x + t.y * t.y + t.z * t.z);
    if (tl > 1e-6) {
        t = vec3<f32>(t.x / tl, t.y / tl, t.z / tl);
    } else {
        t = vec3<f32>(0.0, 0.0, 0.0);
    }
    let al = sqrt(cw * cw + sw * sw);
    if (al <= 0.0) {
        return n;
    }
    var cs = cw / al;
    let sn = sw / al;
    if (phase[i] != P.tension.liquid) {
        cs = -cs;
    }
    let f = min(max(c * c_five(), 0.0), c_one());
    var m = vec3<f32>(0.0, 0.0, 0.0);
    for (var a = 0u; a < 3u; a++) {
        let prescribed = t[a] * sn - ns[a] * cs;
        m[a] = f * prescribed + (c_one() - f) * n[a];
    }
    let ml = sqrt(m.x * m.x + m.y * m.y + m.z * m.z);
    if (ml > 1e-6) {
        return vec4<f32>(m.x / ml, m.y / ml, m.z / ml, n.w);
    }
    return vec4<f32>(0.0, 0.0, 0.0, n.w);
}

@compute @workgroup_size(64)
fn wetting(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = thread_index(gid, nwg);
    if (i >= active_particles()) { return; }
    let ph = phase[i];
    let n_i = surface[i];
    if (n_i[S_DELTA] == 0.0 || (ph != P.tension.liquid && ph != P.tension.gas)) { return; }
    surface[i] = wet(i, n_i);
}

@compute @workgroup_size(64)
fn normals(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = thread_index(gid, nwg);
    let n = P.sizes.n_particles;
    if (i >= active_particles()) { return; }
    if ((P.sizes.flags & FLAG_GAS_INTERFACE) != 0u) {
        gas_interface(i);
        return;
    }
    let ph = phase[i];
    if (!condensed(ph) || !gets_interface(ph)) {
        surface[i] = vec4<f32>(0.0, 0.0, 0.0, 0.0);
        return;
    }
    let gamma_i = surface[n + i][S_SHEPARD];
    let pi = pos[i];
    let ci = cell_coord(pi);
    let zr = z_range();
    var g = vec3<f32>(0.0, 0.0, 0.0);
    #for_each_neighbor(ci, zr, j) {
        let d = min_image(pi, pos[j]);
        let r2 = len2(d);
        if (r2 >= P.kernel.support2 || r2 <= 0.0 || !condensed(phase[j])) { continue; }
        let r = sqrt(r2);
        let f = volume(j) * (c_one() / gamma_i + c_one() / surface[n + j][S_SHEPARD]) * kernel_dw(r) / r;
        g.x = g.x + f * d.x;
        g.y = g.y + f * d.y;
        g.z = g.z + f * d.z;
    }
    let delta = sqrt(g.x * g.x + g.y * g.y + g.z * g.z);
    if (delta > c_tenth() * P.kernel.inv_h) {
        let scaled = delta * P.surfaces.inv_kappa;
        surface[i] = vec4<f32>(-g.x / delta, -g.y / delta, -g.z / delta, scaled);
    } else {
        surface[i] = vec4<f32>(0.0, 0.0, 0.0, 0.0);
    }
}
