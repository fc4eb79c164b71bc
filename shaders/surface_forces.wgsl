// uses: params consts kernel grid phase math vapour
// reads: pos rho mass phase heat
// writes: acc surface
// Forces at the interface, added to the acceleration the forces pass wrote:
// surface_tension, CSF with Marangoni stress F22 (24)-(26), (8), (21) between the
// liquid and the gas of P.tension (curvature kappa_i, Morris 2000 / F22 (25), to
// surface[n + i][S_CURVATURE]), or in the free-surface form (R18 3.1.1-3.1.2) its raw
// curvature (tension_curvature) then the smoothed curvature and force
// (tension_smooth), or J22 (5)-(8)'s colour Laplacian in its place
// (tension_colour, tension_laplacian); recoil, F22 (30). Twin of src/backend/cpu/surface_forces.rs
// (equations and choices there).

// F22 (21) f[T, T_m, T_m + dT_s]; 1 without a ramp.
fn tension_ramp(t: f32) -> f32 {
    if (P.tension.inv_ramp_width == 0.0) {
        return c_one();
    }
    return min(max((t - P.tension.t_melt) * P.tension.inv_ramp_width, 0.0), c_one());
}

fn in_tension_pair(ph: u32) -> bool {
    return ph == P.tension.liquid || ph == P.tension.gas;
}

// Temperature of a particle (0 in scenes without heat).
fn tension_temperature(j: u32) -> f32 {
    if ((P.sizes.flags & FLAG_HEAT) == 0u) {
        return 0.0;
    }
    return heat[j][H_TEMPERATURE];
}

// Carries a temperature for the gradient F22 (26): conducting, or a Dirichlet wall.
fn has_temperature(ph: u32) -> bool {
    return conducts(ph) || ((P.sizes.flags & FLAG_HEAT) != 0u && (heat_flags(ph) & HEAT_DIRICHLET) != 0u);
}

// Volume for the temperature gradient: m/rho for fluids, m/rho0 for solids and walls.
fn tension_volume(j: u32) -> f32 {
    let ph = phase[j];
    if (is_wall(ph)) {
        return mass[j] / P.phases[ph].rho0;
    }
    return mass[j] / rho[j];
}

@compute @workgroup_size(64)
fn surface_tension(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = thread_index(gid, nwg);
    if (i >= active_particles()) { return; }
    let n = P.sizes.n_particles;
    let ph_i = phase[i];
    if (!in_tension_pair(ph_i)) { return; }
    let liquid_i = ph_i == P.tension.liquid;
    let s_i = surface[i];
    if (s_i[S_DELTA] == 0.0) {
        surface[n + i][S_CURVATURE] = 0.0;
        return;
    }
    let heated = (P.sizes.flags & FLAG_HEAT) != 0u;
    let t_i = tension_temperature(i);
    let pi = pos[i];
    let ci = cell_coord(pi);
    let zr = z_range();
    var num = 0.0;
    var den = 0.0;
    var gt = vec3<f32>(0.0);
    #for_each_neighbor(ci, zr, j) {
        let d = min_image(pi, pos[j]);
        let r2 = len2(d);
        if (r2 < P.kernel.support2) {
            let ph_j = phase[j];
            let r = sqrt(r2);
            let s_j = surface[j];
            if (in_tension_pair(ph_j) && s_j[S_DELTA] != 0.0) {
                let v_j = mass[j] / rho[j];
                let fv = tension_ramp(tension_temperature(j)) * v_j;
                den = den + fv * kernel_w(r);
                if (r2 > 0.0) {
                    var nj = s_j.xyz;
                    if ((ph_j == P.tension.liquid) != liquid_i) {
                        nj = -nj;
                    }
                    let dn = (s_i.x - nj.x) * d.x + (s_i.y - nj.y) * d.y + (s_i.z - nj.z) * d.z;
                    num = num + fv * (dn / r) * kernel_dw(r);
                }
            }
            if (heated && r2 > 0.0 && has_temperature(ph_j)) {
                let g = tension_volume(j) * (heat[j][H_TEMPERATURE] - t_i) * kernel_dw(r) / r;
                gt.x = gt.x + g * d.x;
                gt.y = gt.y + g * d.y;
                gt.z = gt.z + g * d.z;
            }
        }
    }
    var kappa = 0.0;
    if (den > 0.0) {
        kappa = -(num / den);
    }
    surface[n + i][S_CURVATURE] = kappa;
    if (!liquid_i) { return; }
    var a = acc[i];
    a = vec4<f32>(a.xyz + tension_force(s_i, t_i, kappa, gt, rho[i]), a.w);
    acc[i] = a;
}

// (alpha, d alpha / dT) at t_i: F22 (8) plus R18 (4.2)'s solute term (Sahoo)
// when sahoo_r_gamma > 0, clipped at alpha_min. Twin of Params::tension_law.
fn tension_law(t_i: f32) -> vec2<f32> {
    var alpha = P.tension.alpha0 + P.tension.alpha_slope * (t_i - P.tension.t_ref);
    var slope = P.tension.alpha_slope;
    if (P.tension.sahoo_r_gamma > 0.0) {
        let ka = P.tension.sahoo_k_a * pm_exp(P.tension.sahoo_q / t_i);
        let l = pm_ln(c_one() + ka);
        alpha = alpha - P.tension.sahoo_r_gamma * t_i * l;
        slope = slope - P.tension.sahoo_r_gamma * l - P.tension.sahoo_gamma_h * ka / (t_i * (c_one() + ka));
    }
    if (alpha <= P.tension.alpha_min) {
        return vec2<f32>(P.tension.alpha_min, 0.0);
    }
    return vec2<f32>(alpha, slope);
}

// F22 (24) per unit mass on a liquid particle with normal and delta s_i,
// temperature t_i, curvature kappa and temperature gradient gt:
// f[T_i] delta (alpha' grad_t T - alpha kappa n) / rho, F22 (8) (alpha' = 0 where clipped).
fn tension_force(s_i: vec4<f32>, t_i: f32, kappa: f32, gt: vec3<f32>, rho_i: f32) -> vec3<f32> {
    let law = tension_law(t_i);
    let alpha = law.x;
    let slope = law.y;
    let delta = s_i[S_DELTA];
    let nt = s_i.x * gt.x + s_i.y * gt.y + s_i.z * gt.z;
    let tx = gt.x - nt * s_i.x;
    let ty = gt.y - nt * s_i.y;
    let tz = gt.z - nt * s_i.z;
    let scale = tension_ramp(t_i) * delta / rho_i;
    let normal = alpha * kappa;
    return vec3<f32>(
        scale * (slope * tx - normal * s_i.x),
        scale * (slope * ty - normal * s_i.y),
        scale * (slope * tz - normal * s_i.z),
    );
}

// The free-surface form's tension acts on particles with a normal, but not on
// those with a full support and a weak colour gradient (twin of bears_tension
// in src/backend/cpu/surface_forces.rs, which says why).
fn bears_tension(j: u32, n: u32) -> bool {
    let delta = surface[j][S_DELTA];
    return delta != 0.0
        && (surface[n + j][S_SHEPARD] < INTERIOR_SHEPARD || delta >= P.surfaces.interior_delta);
}

// Free-surface form, first dispatch, R18 (3.28)-(3.29): raw Morris curvature
// over the liquid's particles with a normal, weights V delta (V = m / rho0),
// capped at |kappa| <= 1/support; to surface[n + i][S_RAW_CURVATURE] (the Shepard pass zeroed
// it for everyone else). With thin_layer_rows (R18 4.4), S_THIN = 1 where no
// liquid particle lies thin_layer_depth or deeper along -n.
@compute @workgroup_size(64)
fn tension_curvature(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = thread_index(gid, nwg);
    if (i >= active_particles()) { return; }
    let n = P.sizes.n_particles;
    let liquid = P.tension.liquid;
    let s_i = surface[i];
    if (phase[i] != liquid || !bears_tension(i, n)) { return; }
    let pi = pos[i];
    let ci = cell_coord(pi);
    let zr = z_range();
    var num = 0.0;
    var den = 0.0;
    var deep = false;
    #for_each_neighbor(ci, zr, j) {
        let d = min_image(pi, pos[j]);
        let r2 = len2(d);
        if (r2 < P.kernel.support2) {
            let s_j = surface[j];
            if (phase[j] == liquid && d.x * s_i.x + d.y * s_i.y + d.z * s_i.z >= P.tension.thin_layer_depth) {
                deep = true;
            }
            if (phase[j] == liquid && bears_tension(j, n)) {
                let r = sqrt(r2);
                let fv = tension_ramp(tension_temperature(j)) * (mass[j] / P.phases[liquid].rho0) * s_j[S_DELTA];
                den = den + fv * kernel_w(r);
                if (r2 > 0.0) {
                    let dn = (s_i.x - s_j.x) * d.x + (s_i.y - s_j.y) * d.y + (s_i.z - s_j.z) * d.z;
                    num = num + fv * (dn / r) * kernel_dw(r);
                }
            }
        }
    }
    var kappa = 0.0;
    if (den > 0.0) {
        kappa = -(num / den);
    }
    surface[n + i][S_RAW_CURVATURE] = min(max(kappa, -P.tension.kappa_max), P.tension.kappa_max);
    if (P.tension.thin_layer_depth > 0.0 && !deep) {
        surface[n + i][S_THIN] = c_one();
    }
}

// Free-surface form, second dispatch: the curvature smoothed, R18 (3.30), the
// Shepard-corrected temperature gradient, R18 (3.34), and the force with rho0.
@compute @workgroup_size(64)
fn tension_smooth(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = thread_index(gid, nwg);
    if (i >= active_particles()) { return; }
    let n = P.sizes.n_particles;
    let liquid = P.tension.liquid;
    let s_i = surface[i];
    if (phase[i] != liquid || !bears_tension(i, n)) { return; }
    let heated = (P.sizes.flags & FLAG_HEAT) != 0u;
    let t_i = tension_temperature(i);
    let pi = pos[i];
    let ci = cell_coord(pi);
    let zr = z_range();
    var num = 0.0;
    var den = 0.0;
    var shepard = 0.0;
    var gt = vec3<f32>(0.0);
    #for_each_neighbor(ci, zr, j) {
        let d = min_image(pi, pos[j]);
        let r2 = len2(d);
        if (r2 < P.kernel.support2) {
            let ph_j = phase[j];
            let r = sqrt(r2);
            let w = kernel_w(r);
            let v_j = mass[j] / P.phases[ph_j].rho0;
            if (ph_j == liquid && bears_tension(j, n)) {
                let fv = tension_ramp(tension_temperature(j)) * v_j * surface[j][S_DELTA];
                den = den + fv * w;
                num = num + fv * surface[n + j][S_RAW_CURVATURE] * w;
            }
            if (heated && has_temperature(ph_j)) {
                shepard = shepard + v_j * w;
                if (r2 > 0.0) {
                    let g = v_j * (heat[j][H_TEMPERATURE] - t_i) * kernel_dw(r) / r;
                    gt.x = gt.x + g * d.x;
                    gt.y = gt.y + g * d.y;
                    gt.z = gt.z + g * d.z;
                }
            }
        }
    }
    var kappa = 0.0;
    if (den > 0.0) {
        kappa = num / den;
    }
    if (shepard > 0.0) {
        gt = vec3<f32>(gt.x / shepard, gt.y / shepard, gt.z / shepard);
    }
    surface[n + i][S_CURVATURE] = kappa;
    // R18 4.4: none on a layer of thin_layer_rows particles or fewer.
    if (surface[n + i][S_THIN] != 0.0) { return; }
    var a = acc[i];
    a = vec4<f32>(a.xyz + tension_force(s_i, t_i, kappa, gt, P.phases[liquid].rho0), a.w);
    acc[i] = a;
}

// F22 (30) recoil: the vapour's pressure p_v(T) (F22 (10), the law of the
// evaporation loss) pushes a liquid particle at the surface inward:
// a -= p_v delta n / rho0 (V = m / rho0, the volume delta is normalised with).
@compute @workgroup_size(64)
fn recoil(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = thread_index(gid, nwg);
    if (i >= active_particles()) { return; }
    let ph = phase[i];
    if ((P.phases[ph].flags & PHASE_RECOIL) == 0u) { return; }
    let s = surface[i];
    if (s[S_DELTA] == 0.0) { return; }
    let f = vapour_pressure(ph, heat[i][H_TEMPERATURE]) * s[S_DELTA] / P.phases[ph].rho0;
    var a = acc[i];
    a.x = a.x - f * s.x;
    a.y = a.y - f * s.y;
    a.z = a.z - f * s.z;
    acc[i] = a;
}

// J22 (5), first dispatch of model = "muller": the colour c_i = sum_j (m_j / rho_j)
// W_ij over the liquid's particles (j = i included), to surface[n + i][S_COLOUR].
// Twin of tension_colour in src/backend/cpu/surface_forces.rs.
@compute @workgroup_size(64)
fn tension_colour(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = thread_index(gid, nwg);
    if (i >= active_particles()) { return; }
    let n = P.sizes.n_particles;
    let liquid = P.tension.liquid;
    if (phase[i] != liquid) { return; }
    let pi = pos[i];
    let ci = cell_coord(pi);
    let zr = z_range();
    var c = 0.0;
    #for_each_neighbor(ci, zr, j) {
        let r2 = len2(min_image(pi, pos[j]));
        if (r2 < P.kernel.support2 && phase[j] == liquid) {
            c = c + mass[j] / rho[j] * kernel_w(sqrt(r2));
        }
    }
    surface[n + i][S_COLOUR] = c;
}

// J22 (6)-(8), second dispatch: the colour's gradient n_i and Laplacian, and the
// force -sigma lap n / |n| per unit volume, divided by rho_i, where |n| passes
// the interface's threshold 0.1 / h. Twin of tension_laplacian (equations there).
@compute @workgroup_size(64)
fn tension_laplacian(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = thread_index(gid, nwg);
    if (i >= active_particles()) { return; }
    let n = P.sizes.n_particles;
    let liquid = P.tension.liquid;
    if (phase[i] != liquid) { return; }
    let c_i = surface[n + i][S_COLOUR];
    let eps = P.kernel.h * c_tenth() * c_tenth();
    let pi = pos[i];
    let ci = cell_coord(pi);
    let zr = z_range();
    var g = vec3<f32>(0.0);
    var lap = 0.0;
    #for_each_neighbor(ci, zr, j) {
        let d = min_image(pi, pos[j]);
        let r2 = len2(d);
        if (r2 >= P.kernel.support2 || r2 <= 0.0 || phase[j] != liquid) { continue; }
        let r = sqrt(r2);
        let v_j = mass[j] / rho[j];
        let dc = surface[n + j][S_COLOUR] - c_i;
        let dw = kernel_dw(r);
        let f = v_j * dc * dw / r;
        g.x = g.x + f * d.x;
        g.y = g.y + f * d.y;
        g.z = g.z + f * d.z;
        lap = lap + v_j * dc * c_two() * abs(dw) / (r + eps);
    }
    let gl = sqrt(g.x * g.x + g.y * g.y + g.z * g.z);
    var kappa = 0.0;
    if (gl > c_tenth() * P.kernel.inv_h) {
        kappa = -(lap / gl);
        let scale = P.tension.alpha0 * tension_ramp(tension_temperature(i)) * kappa / rho[i];
        var a = acc[i];
        a.x = a.x + scale * g.x;
        a.y = a.y + scale * g.y;
        a.z = a.z + scale * g.z;
        acc[i] = a;
    }
    surface[n + i][S_CURVATURE] = kappa;
}
