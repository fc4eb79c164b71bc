// uses: params consts kernel grid phase rigid math
// reads: pos vel mass phase id body bodies sim heat
// writes: rho press continuity density_gradient
// δ-SPH density (R18 §3.1.2, (3.14) with the diffusion (3.53) and its
// renormalisation f_l): the excess density's gradient (continuity_gradient),
// the continuity equation's rate and Shepard sum (continuity_rate), then
// rho += dt drho/dt and the EOS (continuity_update). Twin of src/backend/cpu/continuity.rs (equations
// and choices there).

// Particle i's reference density: its phase's density law at its temperature
// (the previous step's), else the phase's rho0.
fn particle_rho0(ph: u32, i: u32) -> f32 {
    if ((P.phases[ph].flags & PHASE_DENSITY_LAW) != 0u) {
        return reference_density(ph, heat[i][H_TEMPERATURE]);
    }
    return P.phases[ph].rho0;
}

// What the density diffusion subtracts from particle i's density (R18 (3.53):
// its reference density; nothing with density_diffusion = "raw").
fn diffusion_reference(ph: u32, i: u32) -> f32 {
    if ((P.sizes.flags & FLAG_RAW_DENSITY_DIFFUSION) != 0u) {
        return 0.0;
    }
    return particle_rho0(ph, i);
}

// Whether the diffusion acts between phases ph_i and ph_j: one phase (R18
// (3.53) here), or any two fluids with density_diffusion = "raw".
fn diffuses_with(ph_i: u32, ph_j: u32) -> bool {
    return ph_j == ph_i
        || ((P.sizes.flags & FLAG_RAW_DENSITY_DIFFUSION) != 0u && !is_wall(ph_j));
}

// The real velocity of a wall or body particle (not the wall pass's ghost).
fn solid_velocity(j: u32) -> vec3<f32> {
    if ((P.sizes.flags & FLAG_BODIES) != 0u) {
        let k = body[id[j]];
        if (k != NO_BODY) {
            return body_point_velocity(bodies[k], pos[j]);
        }
    }
    return P.phases[phase[j]].velocity.xyz;
}

// The renormalised gradient of the excess density over the particle's own
// phase (Antuono et al. 2010): <grad rho_bar>_i = M_i^-1 b_i with
// M_i = sum_j V_j (r_j - r_i) (x) grad_i W_ij (symmetric) and
// b_i = sum_j V_j (rho_bar_j - rho_bar_i) grad_i W_ij; 0 where M is near
// singular (|det| <= 1e-3: a particle with few neighbours of its phase).
@compute @workgroup_size(64)
fn continuity_gradient(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = thread_index(gid, nwg);
    if (i >= active_particles()) { return; }
    let ph_i = phase[i];
    if (is_wall(ph_i)) {
        density_gradient[i] = vec4<f32>(0.0, 0.0, 0.0, 0.0);
        return;
    }
    let excess_i = rho[i] - diffusion_reference(ph_i, i);
    let pi = pos[i];
    let ci = cell_coord(pi);
    let zr = z_range();
    var mxx = 0.0;
    var mxy = 0.0;
    var mxz = 0.0;
    var myy = 0.0;
    var myz = 0.0;
    var mzz = 0.0;
    var b = vec3<f32>(0.0);
    #for_each_neighbor(ci, zr, j) {
        let d = min_image(pi, pos[j]);
        let r2 = len2(d);
        if (r2 < P.kernel.support2 && r2 > 0.0 && diffuses_with(ph_i, phase[j])) {
            let r = sqrt(r2);
            let vf = mass[j] / rho[j] * (kernel_dw(r) / r);
            mxx = mxx - vf * d.x * d.x;
            mxy = mxy - vf * d.x * d.y;
            mxz = mxz - vf * d.x * d.z;
            myy = myy - vf * d.y * d.y;
            myz = myz - vf * d.y * d.z;
            mzz = mzz - vf * d.z * d.z;
            let db = (rho[j] - diffusion_reference(ph_i, j) - excess_i) * vf;
            b.x = b.x + db * d.x;
            b.y = b.y + db * d.y;
            b.z = b.z + db * d.z;
        }
    }
    let g = solve_symmetric(mxx, mxy, mxz, myy, myz, mzz, b);
    density_gradient[i] = vec4<f32>(g, 0.0);
}

@compute @workgroup_size(64)
fn continuity_rate(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = thread_index(gid, nwg);
    if (i >= active_particles()) { return; }
    let ph_i = phase[i];
    if (is_wall(ph_i)) {
        continuity[i] = vec2<f32>(0.0, c_one());
        return;
    }
    let rho_i = rho[i];
    let m_i = mass[i];
    let rho0_i = particle_rho0(ph_i, i);
    let c2_i = P.phases[ph_i].c2;
    let excess_i = rho_i - diffusion_reference(ph_i, i);
    let g_i = density_gradient[i];
    let v_i = vel[i];
    let pi = pos[i];
    let ci = cell_coord(pi);
    let zr = z_range();
    var div = 0.0;
    var diff = 0.0;
    var gamma = 0.0;
    #for_each_neighbor(ci, zr, j) {
        let d = min_image(pi, pos[j]);
        let r2 = len2(d);
        if (r2 < P.kernel.support2) {
            let r = sqrt(r2);
            let ph_j = phase[j];
            if (is_wall(ph_j)) {
                let rho_w = rho0_i + press[j] / c2_i;
                let vol_w = m_i / rho_w;
                gamma = gamma + vol_w * kernel_w(r);
                if (r2 > 0.0) {
                    let u = solid_velocity(j);
                    let ud = (v_i.x - u.x) * d.x + (v_i.y - u.y) * d.y + (v_i.z - u.z) * d.z;
                    div = div + vol_w * ud * (kernel_dw(r) / r);
                }
            } else {
                let rho_j = rho[j];
                let vol_j = mass[j] / rho_j;
                gamma = gamma + vol_j * kernel_w(r);
                if (r2 > 0.0) {
                    let v_j = vel[j];
                    let f = kernel_dw(r) / r;
                    let ud = (v_i.x - v_j.x) * d.x + (v_i.y - v_j.y) * d.y + (v_i.z - v_j.z) * d.z;
                    div = div + vol_j * ud * f;
                    if (diffuses_with(ph_i, ph_j)) {
                        let dr = rho_j - diffusion_reference(ph_i, j) - excess_i;
                        let gj = density_gradient[j];
                        let gd = (g_i.x + gj.x) * d.x + (g_i.y + gj.y) * d.y + (g_i.z + gj.z) * d.z;
                        diff = diff - vol_j * (dr + dr + gd) * f;
                    }
                }
            }
        }
    }
    let rate = rho_i * div + P.solve.delta_hc * diff;
    continuity[i] = vec2<f32>(rate, gamma);
}

@compute @workgroup_size(64)
fn continuity_update(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = thread_index(gid, nwg);
    if (i >= active_particles()) { return; }
    let ph = phase[i];
    if (is_wall(ph)) { return; }
    let r = rho[i] + sim.dt * continuity[i].x;
    rho[i] = r;
    press[i] = equation_of_state(ph, r, particle_rho0(ph, i));
}
