// uses: params consts kernel grid phase
// reads: pos vel rho press mass phase heat surface continuity
// writes: acc acc_b
// Pressure + viscous forces F22 (23) (or R18 (3.17), (3.18) under delta_wcsph),
// transport-velocity background pressure
// (Adami 2013), interface viscosity F22 (31), solid-fluid viscosity F22 (33),
// viscous heating, the wall barrier
// F22 (34) and gravity: one
// sweep over the neighbours, each pair term a function in shaders/terms/ (the
// host appends the pass's terms; a switchable term is removed at pipeline
// creation by its override constant). Twin of src/backend/cpu/forces.rs, which
// explains the wall treatment.

@compute @workgroup_size(64)
fn forces(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = thread_index(gid, nwg);
    if (i >= active_particles()) { return; }
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
    var alpha_i = 0.0;
    // The runtime test is not needed for the result, but without it lavapipe's
    // two_layer_ratio1000_2d differed from the CPU twin by 2 ULP at step 48, as if
    // α_0 had been factored out of α_i + α_j (the CPU multiplies each).
    if (TERM_INTERFACE_VISCOSITY && P.flow.interface_viscosity > 0.0) {
        alpha_i = interface_viscosity_alpha(surface[i][S_DELTA]);
    }
    var gamma_i = c_one();
    if (TERM_SHEPARD_PRESSURE) {
        gamma_i = continuity[i].y;
    }
    var alpha_sf_i = 0.0;
    if (TERM_SOLID_FLUID_VISCOSITY) {
        alpha_sf_i = solid_fluid_viscosity_alpha(phase[i], heat[i][H_TEMPERATURE]);
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
            // The pair terms, in the order of backend::terms::PAIR_TERMS.
            // F22 (23)'s pressure and viscosity, or (delta_wcsph) R18's.
            var fp = 0.0;
            if (!TERM_SHEPARD_PRESSURE) {
                fp = pressure(p_i, p_j, rho_i, rho_j, dwdr, r);
            }
            let eta_ij = pair_viscosity(eta_i, eta_j, slip);
            var fv = 0.0;
            if (!TERM_MARRONE_VISCOSITY) {
                fv = viscosity(eta_ij, dwdr, r);
            }
            let v_j = vel[j];
            for (var a = 0u; a < 3u; a++) {
                let u = v_i[a] - v_j[a];
                f[a] = f[a] + vv * (fp * d[a] + fv * u);
            }
            if (TERM_SHEPARD_PRESSURE) {
                var gamma_j = c_one();
                if (!wall) {
                    gamma_j = continuity[j].y;
                }
                let s = shepard_pressure(m_i, m_j, rho_i, rho_j, p_i, p_j, gamma_i, gamma_j, dwdr, r);
                for (var a = 0u; a < 3u; a++) {
                    f[a] = f[a] + s * d[a];
                }
            }
            if (TERM_MARRONE_VISCOSITY) {
                let s = marrone_viscosity(m_i, m_j, rho_i, rho_j, eta_ij, v_i.xyz - v_j.xyz, d, r2, dwdr, r);
                for (var a = 0u; a < 3u; a++) {
                    f[a] = f[a] + s * d[a];
                }
            }
            if (TERM_BACKGROUND_PRESSURE) {
                let fbg = background_pressure(pb, dwdr, r);
                for (var a = 0u; a < 3u; a++) {
                    fb[a] = fb[a] + vv * (fbg * d[a]);
                }
            }
            if (TERM_INTERFACE_VISCOSITY && !wall) {
                let alpha = (alpha_i + interface_viscosity_alpha(surface[j][S_DELTA])) * c_half();
                let s = interface_viscosity(m_i, m_j, rho_i, rho_j, c2_i, P.phases[ph_j].c2, v_i.xyz - v_j.xyz, d, r2, dwdr, alpha);
                for (var a = 0u; a < 3u; a++) {
                    f[a] = f[a] + s * d[a];
                }
            }
            if (TERM_SOLID_FLUID_VISCOSITY) {
                var alpha_j = alpha_sf_i;
                var c2_j = c2_i;
                if (!wall) {
                    alpha_j = solid_fluid_viscosity_alpha(ph_j, heat[j][H_TEMPERATURE]);
                    c2_j = P.phases[ph_j].c2;
                }
                let alpha = (alpha_sf_i + alpha_j) * c_half();
                let s = solid_fluid_viscosity(m_i, m_j, rho_i, rho_j, c2_i, c2_j, v_i.xyz - v_j.xyz, d, r2, dwdr, alpha);
                for (var a = 0u; a < 3u; a++) {
                    f[a] = f[a] + s * d[a];
                }
            }
            if (TERM_VISCOUS_HEATING) {
                var w = v_j.xyz;
                var share = c_half();
                if (wall) {
                    w = P.phases[ph_j].velocity.xyz;
                    share = c_one();
                }
                heating = heating - viscous_heating(v_i, v_j, w, share, vv, fv);
            }
            if (TERM_BARRIER && wall && r < P.flow.barrier_radius) {
                let s = barrier(v_i, P.phases[ph_j].velocity, d, r);
                for (var a = 0u; a < 3u; a++) {
                    f[a] = f[a] + s * d[a];
                }
            }
        }
    }
    let g = P.flow.gravity;
    acc[i] = vec4<f32>(f.x / m_i + g.x, f.y / m_i + g.y, f.z / m_i + g.z, heating / m_i);
    acc_b[i] = vec4<f32>(fb.x / m_i, fb.y / m_i, fb.z / m_i, 0.0);
}
