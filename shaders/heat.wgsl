// uses: params bindings consts kernel grid phase math vapour
// writes: acc acc_b heat phase vel body
// Heat conduction in enthalpy form and temperature from enthalpy.
// Twin of src/backend/cpu/heat.rs (equations there): J22 (19)-(22), (25); F22 (41).

// Conductivity at liquid fraction fl, linear between the solid and liquid values.
fn conductivity(ph: u32, fl: f32) -> f32 {
    let ks = P.phases[ph].conductivity;
    return ks + fl * (P.phases[ph].liquid_conductivity - ks);
}

// Density for a particle's volume: summation density for fluids, rho0 for solids
// and walls.
fn heat_density(ph: u32, i: u32) -> f32 {
    if (is_wall(ph)) {
        return P.phases[ph].rho0;
    }
    return rho[i];
}

// Dirichlet wall particles: T = 2 T_wall - (Shepard mean of conducting neighbours),
// T_wall the particle's own fixed temperature (heat.x).
@compute @workgroup_size(64)
fn wall_temperature(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = thread_index(gid, nwg);
    if (i >= active_particles()) { return; }
    let ph = phase[i];
    if (conducts(ph) || (heat_flags(ph) & HEAT_DIRICHLET) == 0u) { return; }
    let pi = pos[i];
    let ci = cell_coord(pi);
    let zr = z_range();
    var sw = 0.0;
    var stw = 0.0;
    #for_each_neighbor(ci, zr, j) {
        let r2 = len2(min_image(pi, pos[j]));
        if (r2 < P.kernel.support2 && conducts(phase[j])) {
            let wk = kernel_w(sqrt(r2));
            sw = sw + wk;
            stw = stw + heat[j].y * wk;
        }
    }
    var hv = heat[i];
    let t_wall = hv.x;
    if (sw > 0.0) {
        hv.y = c_two() * t_wall - stw / sw;
    } else {
        hv.y = t_wall;
    }
    heat[i] = hv;
}

@compute @workgroup_size(64)
fn conduct(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = thread_index(gid, nwg);
    if (i >= active_particles()) { return; }
    let ph_i = phase[i];
    if (!conducts(ph_i)) { return; }
    let k_i = conductivity(ph_i, heat[i].z);
    let t_i = heat[i].y;
    let eta2 = P.kernel.eta2;
    let pi = pos[i];
    let ci = cell_coord(pi);
    let zr = z_range();
    var sum = 0.0;
    #for_each_neighbor(ci, zr, j) {
        let r2 = len2(min_image(pi, pos[j]));
        if (r2 >= P.kernel.support2 || r2 <= 0.0) { continue; }
        let ph_j = phase[j];
        var k_ij = 0.0;
        if (conducts(ph_j)) {
            let k_j = conductivity(ph_j, heat[j].z);
            // Ordered operands: both sides of a pair get the same bits.
            k_ij = c_four() * min(k_i, k_j) * max(k_i, k_j) / (k_i + k_j);
        } else if ((heat_flags(ph_j) & HEAT_DIRICHLET) != 0u) {
            k_ij = c_two() * k_i;
        } else {
            continue;
        }
        let r = sqrt(r2);
        let f = kernel_dw(r) * r / (r2 + eta2);
        let v_j = mass[j] / heat_density(ph_j, j);
        sum = sum + v_j * k_ij * (t_i - heat[j].y) * f;
    }
    // The laser pass left its source (W/kg) in heat.w.
    var source = 0.0;
    if (P.laser.model != 0u) {
        source = heat[i].w;
    }
    if ((P.sizes.flags & FLAG_VISCOUS_HEATING) != 0u) {
        source = source + acc[i].w;
    }
    var loss = 0.0;
    if ((P.sizes.flags & FLAG_INTERFACE) != 0u) {
        loss = surface_loss(ph_i, t_i, surface[i].w);
    }
    let rate = source - loss + sum / heat_density(ph_i, i);
    // Neighbours read only T (.y), so the enthalpy can be updated in place.
    var hv = heat[i];
    hv.x = hv.x + sim.dt * rate;
    hv.w = rate;
    heat[i] = hv;
}

// Evaporation F22 (18), (10) and radiation through the free surface, W/kg.
fn surface_loss(ph: u32, t: f32, delta: f32) -> f32 {
    var flux = 0.0;
    if (P.phases[ph].evap_pressure > 0.0) {
        let pv = vapour_pressure(ph, t);
        let mdot = P.phases[ph].recondensation * pv * sqrt(P.phases[ph].vapor_constant / t);
        flux = flux + mdot * (P.phases[ph].evap_latent_heat + P.phases[ph].liquid_heat_capacity * (t - P.phases[ph].evap_enthalpy_reference));
    }
    if (P.phases[ph].emissivity_sb > 0.0) {
        flux = flux + P.phases[ph].emissivity_sb * (t * t * t * t - P.surfaces.ambient_t4);
    }
    return flux * delta / P.phases[ph].rho0;
}

@compute @workgroup_size(64)
fn temperature(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = thread_index(gid, nwg);
    if (i >= active_particles()) { return; }
    let ph = phase[i];
    if (!conducts(ph)) { return; }
    var hv = heat[i];
    let h = hv.x;
    let c_s = P.phases[ph].heat_capacity;
    let band = P.phases[ph].band_enthalpy;
    let t_s = P.phases[ph].solidus;
    let t_l = P.phases[ph].liquidus;
    let flags = heat_flags(ph);
    // Stored enthalpy is relative to h(T_ref) (T_ref = solidus when melting).
    if ((flags & HEAT_MELTS) == 0u) {
        hv.y = P.phases[ph].reference_temperature + h / c_s;
        hv.z = select(0.0, 1.0, (flags & HEAT_LIQUID) != 0u);
    } else if (h <= 0.0) {
        hv.y = t_s + h / c_s;
        hv.z = 0.0;
    } else if (h >= band) {
        hv.y = t_l + (h - band) / P.phases[ph].liquid_heat_capacity;
        hv.z = 1.0;
    } else {
        let a = P.phases[ph].capacity_slope;
        let b = P.phases[ph].band_capacity;
        let x = c_two() * h / (b + sqrt(b * b + c_four() * a * h));
        hv.y = t_s + x;
        hv.z = x / (t_l - t_s);
    }
    heat[i] = hv;
    // Phase change at f_l = 1/2 (F22 §3.2, fixed substrate).
    let switch_to = (flags >> HEAT_SWITCH_SHIFT) & 15u;
    if (switch_to == 0u) { return; }
    let solid = P.phases[ph].kind == KIND_SOLID;
    if (solid && hv.z >= 0.5) {
        phase[i] = switch_to - 1u;
    } else if (!solid && hv.z < 0.5) {
        phase[i] = switch_to - 1u;
        vel[i] = vec4<f32>(0.0, 0.0, 0.0, 0.0);
        acc[i] = vec4<f32>(0.0, 0.0, 0.0, 0.0);
        acc_b[i] = vec4<f32>(0.0, 0.0, 0.0, 0.0);
        // Rigid bodies: body_bond bonds the bodies this particle touches.
        if ((P.sizes.flags & FLAG_BODIES) != 0u) {
            body[id[i]] = BODY_SOLIDIFIED;
        }
    }
}
