// uses: params bindings consts kernel grid phase
// writes: surface
// Interface normal and surface delta of the condensed material, R18 (3.25)-(3.27).
// Twin of src/backend/cpu/interface.rs (equations there). surface[i] = (n, delta),
// surface[n + i].x = Shepard sum Gamma_i.

fn condensed(ph: u32) -> bool {
    return P.phases[ph].kind != KIND_GAS;
}

// Twin of Params::gets_gas_interface.
fn gets_gas_interface(ph: u32) -> bool {
    let flows = P.flow.interface_viscosity > 0.0 || (P.sizes.flags & FLAG_SURFACE_TENSION) != 0u;
    return conducts(ph) || (flows && !is_wall(ph));
}

// Twin of Params::gets_free_surface_normal.
fn gets_free_surface_normal(ph: u32) -> bool {
    return conducts(ph) || ((P.sizes.flags & FLAG_SURFACE_TENSION) != 0u && !is_wall(ph));
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
    if (!gets_gas_interface(ph)) {
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
    if (!condensed(ph) || !gets_free_surface_normal(ph)) {
        surface[i] = vec4<f32>(0.0, 0.0, 0.0, 0.0);
        return;
    }
    let gamma_i = surface[n + i].x;
    let pi = pos[i];
    let ci = cell_coord(pi);
    let zr = z_range();
    var g = vec3<f32>(0.0, 0.0, 0.0);
    #for_each_neighbor(ci, zr, j) {
        let d = min_image(pi, pos[j]);
        let r2 = len2(d);
        if (r2 >= P.kernel.support2 || r2 <= 0.0 || !condensed(phase[j])) { continue; }
        let r = sqrt(r2);
        let f = volume(j) * (c_one() / gamma_i + c_one() / surface[n + j].x) * kernel_dw(r) / r;
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
