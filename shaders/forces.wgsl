// uses: params bindings consts kernel grid phase
// Pressure + viscous forces F22 (23), transport-velocity background pressure
// (Adami 2013) and gravity. Twin of src/backend/cpu/forces.rs, which explains the
// wall treatment.

// F22 (31) for one fluid pair: the factor of r_ij in the force on i (the CPU twin
// explains the form).
fn interface_viscosity(m_i: f32, m_j: f32, rho_i: f32, rho_j: f32, c2_i: f32, c2_j: f32,
                       u: vec3<f32>, d: vec3<f32>, r2: f32, dwdr: f32, alpha: f32) -> f32 {
    let c = (sqrt(c2_i) + sqrt(c2_j)) * c_half();
    let rho_m = (rho_i + rho_j) * c_half();
    let ur = u.x * d.x + u.y * d.y + u.z * d.z;
    let r = sqrt(r2);
    return m_i * m_j * alpha * P.kernel.h * c / rho_m * ur / (r2 + P.kernel.eta2) * dwdr / r;
}

@compute @workgroup_size(64)
fn forces(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = thread_index(gid, nwg);
    if (i >= P.sizes.n_particles) { return; }
    let ph_i = phase[i];
    if (is_wall(ph_i)) { return; }
    let rho0_i = P.phases[ph_i].rho0;
    let c2_i = P.phases[ph_i].c2;
    let rho_i = rho[i];
    let p_i = press[i];
    let m_i = mass[i];
    let eta_i = P.phases[ph_i].eta;
    let v_i = vel[i];
    let vol_i = m_i / rho_i;
    let pb = P.flow.background_pressure;
    let pi = pos[i];
    let ci = cell_coord(pi);
    let zr = z_range();
    var f = vec3<f32>(0.0);
    var fb = vec3<f32>(0.0);
    var heating = 0.0;
    let viscous_heating = (P.sizes.flags & FLAG_VISCOUS_HEATING) != 0u;
    let h = P.kernel.h;
    let alpha0 = P.flow.interface_viscosity;
    var alpha_i = 0.0;
    if (alpha0 > 0.0) {
        alpha_i = alpha0 * min(h * surface[i].w, c_one());
    }
    #for_each_neighbor(ci, zr, j) {
        let d = min_image(pi, pos[j]);
        let r2 = len2(d);
        if (r2 < P.kernel.support2 && r2 > 0.0) {
            let r = sqrt(r2);
            let dwdr = kernel_dw(r);
            let ph_j = phase[j];
            let wall = P.phases[ph_j].kind >= KIND_WALL;
            let p_j = press[j];
            var rho_j = rho[j];
            var m_j = mass[j];
            var eta_j = P.phases[ph_j].eta;
            if (wall) {
                rho_j = rho0_i + p_j / c2_i;
                m_j = m_i;
                eta_j = eta_i;
            }
            let slip = wall && (P.phases[ph_j].flags & PHASE_FREE_SLIP) != 0u;
            let vol_j = m_j / rho_j;
            let vv = vol_i * vol_i + vol_j * vol_j;
            let p_avg = (rho_j * p_i + rho_i * p_j) / (rho_i + rho_j);
            let eta_sum = eta_i + eta_j;
            var eta_avg = 0.0;
            if (eta_sum > 0.0 && !slip) {
                eta_avg = c_two() * eta_i * eta_j / eta_sum;
            }
            let fp = -p_avg * dwdr / r;
            let fv = eta_avg * dwdr / r;
            let fbg = -pb * dwdr / r;
            let v_j = vel[j];
            for (var a = 0u; a < 3u; a++) {
                let u = v_i[a] - v_j[a];
                f[a] = f[a] + vv * (fp * d[a] + fv * u);
                fb[a] = fb[a] + vv * (fbg * d[a]);
            }
            if (alpha0 > 0.0 && !wall) {
                let alpha = (alpha_i + alpha0 * min(h * surface[j].w, c_one())) * c_half();
                let s = interface_viscosity(m_i, m_j, rho_i, rho_j, c2_i, P.phases[ph_j].c2, v_i.xyz - v_j.xyz, d, r2, dwdr, alpha);
                for (var a = 0u; a < 3u; a++) {
                    f[a] = f[a] + s * d[a];
                }
            }
            if (viscous_heating) {
                // Power the pair's viscous force dissipates: fluid pairs
                // share F.(u_i - u_j); against a wall it is F.(u_i - U_wall)
                // with the wall's real velocity (the mirrored one is a ghost).
                var w = v_j.xyz;
                var share = c_half();
                if (wall) {
                    w = P.phases[ph_j].velocity.xyz;
                    share = c_one();
                }
                let ux = v_i.x - v_j.x;
                let uy = v_i.y - v_j.y;
                let uz = v_i.z - v_j.z;
                let wx = v_i.x - w.x;
                let wy = v_i.y - w.y;
                let wz = v_i.z - w.z;
                let uw = ux * wx + uy * wy + uz * wz;
                heating = heating - share * vv * fv * uw;
            }
        }
    }
    let g = P.flow.gravity;
    acc[i] = vec4<f32>(f.x / m_i + g.x, f.y / m_i + g.y, f.z / m_i + g.z, heating / m_i);
    acc_b[i] = vec4<f32>(fb.x / m_i, fb.y / m_i, fb.z / m_i, 0.0);
}
