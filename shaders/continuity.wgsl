// uses: params consts kernel grid phase rigid
// reads: pos vel mass phase id body bodies sim
// writes: rho press continuity
// δ-SPH density (R18 §3.1.2, (3.14) with the diffusion (3.53)): the continuity
// equation's rate and Shepard sum (continuity_rate), then rho += dt drho/dt and
// the EOS (continuity_update). Twin of src/backend/cpu/continuity.rs (equations
// and choices there).

// The EOS p = c²(rho - rho0), clamped at 0 with the pressure floor: the density
// pass's, twin of backend::cpu::density::equation_of_state.
fn continuity_eos(ph: u32, r: f32) -> f32 {
    let p = P.phases[ph].c2 * (r - P.phases[ph].rho0);
    if ((P.sizes.flags & FLAG_PRESSURE_FLOOR) != 0u) {
        return max(p, 0.0);
    }
    return p;
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
    let rho0_i = P.phases[ph_i].rho0;
    let c2_i = P.phases[ph_i].c2;
    let excess_i = rho_i - rho0_i;
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
                    if (ph_j == ph_i) {
                        let excess_j = rho_j - rho0_i;
                        diff = diff - vol_j * (excess_j - excess_i) * f;
                    }
                }
            }
        }
    }
    let rate = rho_i * div + P.solve.delta_hc * (diff + diff);
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
    press[i] = continuity_eos(ph, r);
}
