// uses: params consts kernel grid phase math vapour
// reads: pos rho mass id surface sim
// writes: acc acc_b heat phase vel body heat_start solvers partials solidification
// Heat conduction in enthalpy form and temperature from enthalpy.
// Twin of src/backend/cpu/heat.rs (equations there): J22 (19)-(22), (25); F22 (41).

// Conductivity at temperature t and liquid fraction fl: the phase's
// conductivity_table lambda(T) (held at its ends), else linear in fl between the
// solid and liquid values. Twin of conductivity in src/backend/cpu/heat.rs.
fn conductivity(ph: u32, t: f32, fl: f32) -> f32 {
    if ((P.sizes.flags & FLAG_CONDUCTIVITY_TABLE) != 0u && P.phases[ph].conductivity_points > 0u) {
        let tt = max(t, P.phases[ph].conductivity_law[0].temperature[0]);
        var k = 0u;
        for (var i = 1u; i < P.phases[ph].conductivity_points; i = i + 1u) {
            if (tt >= P.phases[ph].conductivity_law[i / 4u].temperature[i % 4u]) {
                k = i;
            }
        }
        let row = k / 4u;
        let c = k % 4u;
        return P.phases[ph].conductivity_law[row].value[c] + P.phases[ph].conductivity_law[row].slope[c] * (tt - P.phases[ph].conductivity_law[row].temperature[c]);
    }
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
    mirror_temperature(i);
}

fn mirror_temperature(i: u32) {
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
            stw = stw + heat[j][H_TEMPERATURE] * wk;
        }
    }
    var hv = heat[i];
    let t_wall = hv[H_ENTHALPY];
    if (sw > 0.0) {
        hv[H_TEMPERATURE] = c_two() * t_wall - stw / sw;
    } else {
        hv[H_TEMPERATURE] = t_wall;
    }
    heat[i] = hv;
}

// dh_i/dt of conducting particle i at the temperatures in heat.y (and liquid
// fractions in heat.z): conduction, the laser's source (W/kg), viscous heating,
// minus the surface losses.
fn conduction_rate(i: u32, laser_source: f32) -> f32 {
    let ph_i = phase[i];
    let k_i = conductivity(ph_i, heat[i][H_TEMPERATURE], heat[i][H_LIQUID]);
    let t_i = heat[i][H_TEMPERATURE];
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
            let k_j = conductivity(ph_j, heat[j][H_TEMPERATURE], heat[j][H_LIQUID]);
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
        sum = sum + v_j * k_ij * (t_i - heat[j][H_TEMPERATURE]) * f;
    }
    var source = laser_source;
    if ((P.sizes.flags & FLAG_VISCOUS_HEATING) != 0u) {
        source = source + acc[i].w;
    }
    var loss = 0.0;
    if ((P.sizes.flags & FLAG_INTERFACE) != 0u) {
        loss = surface_loss(ph_i, t_i, surface[i][S_DELTA]);
    }
    return source - loss + sum / heat_density(ph_i, i);
}

// The laser pass left its source (W/kg) in heat.w.
fn laser_source(i: u32) -> f32 {
    if (P.laser.model != 0u) {
        return heat[i][H_RATE];
    }
    return 0.0;
}

@compute @workgroup_size(64)
fn conduct(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = thread_index(gid, nwg);
    if (i >= active_particles()) { return; }
    if (!conducts(phase[i]) || programmed(phase[i])) { return; }
    let rate = conduction_rate(i, laser_source(i));
    // Neighbours read only T (.y), so the enthalpy can be updated in place.
    var hv = heat[i];
    hv[H_ENTHALPY] = hv[H_ENTHALPY] + sim.dt * rate;
    hv[H_RATE] = rate;
    heat[i] = hv;
}

// Trapezoidal rule (R18 Algorithm 3.1), fixed-point iteration; twin of the
// functions after `conduct` in src/backend/cpu/heat.rs (equations there).
// heat_begin: heat_start = (h^n, laser source, 0, 0), heat.w (the rate) 0; the
// solver reset.
@compute @workgroup_size(64)
fn heat_begin(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = thread_index(gid, nwg);
    if (i == 0u) {
        solvers[SOLVER_HEAT] = solver_reset(solvers[SOLVER_HEAT]);
    }
    if (i >= active_particles()) { return; }
    if (conducts(phase[i])) {
        var hv = heat[i];
        heat_start[i] = vec4<f32>(hv[H_ENTHALPY], laser_source(i), 0.0, 0.0);
        hv[H_RATE] = 0.0;
        heat[i] = hv;
    } else {
        heat_start[i] = vec4<f32>(0.0, 0.0, 0.0, 0.0);
    }
}

fn heat_converged() -> bool {
    return solvers[SOLVER_HEAT].converged != 0u;
}

// T and f_l of the iterate h^k.
@compute @workgroup_size(64)
fn iterate_temperature(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    if (heat_converged()) { return; }
    let i = thread_index(gid, nwg);
    if (i >= active_particles()) { return; }
    let ph = phase[i];
    if (!conducts(ph)) { return; }
    var hv = heat[i];
    let tf = temperature_of(ph, hv[H_ENTHALPY]);
    hv[H_TEMPERATURE] = tf.x;
    hv[H_LIQUID] = tf.y;
    heat[i] = hv;
}

@compute @workgroup_size(64)
fn iterate_wall_temperature(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    if (heat_converged()) { return; }
    let i = thread_index(gid, nwg);
    if (i >= active_particles()) { return; }
    mirror_temperature(i);
}

// rate_k (kept as rate_0 in heat_start.z on the first iteration),
// h^{k+1} = h^n + dt ((rate_0 + rate_k) / 2), |rate_k - rate_{k-1}| to
// heat_start.w (rates, not enthalpies: (a + b) - a is what lavapipe would fold
// to b). Neighbours read only T and f_l (.y, .z): in place.
@compute @workgroup_size(64)
fn iterate_conduct(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    if (heat_converged()) { return; }
    let i = thread_index(gid, nwg);
    if (i >= active_particles()) { return; }
    if (!conducts(phase[i])) { return; }
    var hs = heat_start[i];
    let rate = conduction_rate(i, hs.y);
    var hv = heat[i];
    if (solvers[SOLVER_HEAT].iterations == 0u) {
        hs.z = rate;
    }
    hs.w = abs(rate - hv[H_RATE]);
    hv[H_ENTHALPY] = hs.x + sim.dt * ((hs.z + rate) * c_half());
    hv[H_RATE] = rate;
    heat_start[i] = hs;
    heat[i] = hv;
}

// Max over conducting particles of |rate_k - rate_{k-1}| (heat_start.w) and
// |rate_0 + rate_k| by the two-level tree of the
// time step (timestep.wgsl): per workgroup into partials, then one workgroup.
const HWG: u32 = 256u;
var<workgroup> hred: array<vec2<f32>, 256>;

fn heat_tree_max(t: u32) {
    for (var s = HWG / 2u; s > 0u; s = s / 2u) {
        workgroupBarrier();
        if (t < s) {
            hred[t] = max(hred[t], hred[t + s]);
        }
    }
    workgroupBarrier();
}

@compute @workgroup_size(256)
fn heat_residual(@builtin(local_invocation_index) t: u32, @builtin(workgroup_id) wid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    if (heat_converged()) { return; }
    let g = wid.x + wid.y * nwg.x;
    let i = g * HWG + t;
    var m = vec2<f32>(0.0, 0.0);
    if (i < active_particles() && conducts(phase[i])) {
        let hs = heat_start[i];
        m = vec2<f32>(hs.w, abs(hs.z + heat[i][H_RATE]));
    }
    hred[t] = m;
    heat_tree_max(t);
    if (t == 0u) {
        partials[g] = hred[0];
    }
}

@compute @workgroup_size(256)
fn heat_residual_final(@builtin(local_invocation_index) t: u32) {
    if (heat_converged()) { return; }
    let groups = (P.sizes.n_particles + HWG - 1u) / HWG;
    var m = vec2<f32>(0.0, 0.0);
    for (var g = t; g < groups; g += HWG) {
        m = max(m, partials[g]);
    }
    hred[t] = m;
    heat_tree_max(t);
    if (t != 0u) { return; }
    let s = solvers[SOLVER_HEAT];
    var residual = 0.0;
    if (hred[0].y == 0.0) {
        residual = 0.0;
    } else if (s.iterations == 0u) {
        residual = c_one();
    } else {
        residual = hred[0].x / hred[0].y;
    }
    solvers[SOLVER_HEAT] = solver_finish(s, residual, residual <= P.solve.heat_tolerance,
        P.solve.heat_max_iterations);
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

// (T, f_l) of the stored enthalpy h (relative to h(T_ref); T_ref = solidus when
// the phase melts). Twin of temperature_of in src/backend/cpu/heat.rs.
fn temperature_of(ph: u32, h: f32) -> vec2<f32> {
    if (P.phases[ph].enthalpy_points > 0u) {
        return table_temperature_of(ph, h);
    }
    let c_s = P.phases[ph].heat_capacity;
    let band = P.phases[ph].band_enthalpy;
    let t_s = P.phases[ph].solidus;
    let t_l = P.phases[ph].liquidus;
    let flags = heat_flags(ph);
    if ((flags & HEAT_MELTS) == 0u) {
        return vec2<f32>(P.phases[ph].reference_temperature + h / c_s, select(0.0, 1.0, (flags & HEAT_LIQUID) != 0u));
    } else if (h <= 0.0) {
        return vec2<f32>(t_s + h / c_s, 0.0);
    } else if (h >= band) {
        return vec2<f32>(t_l + (h - band) / P.phases[ph].liquid_heat_capacity, 1.0);
    }
    let a = P.phases[ph].capacity_slope;
    let b = P.phases[ph].band_capacity;
    let x = c_two() * h / (b + sqrt(b * b + c_four() * a * h));
    return vec2<f32>(t_s + x, x / (t_l - t_s));
}

// (T, f_l) of h on an enthalpy_table: the segment whose point value h reaches,
// continued past the ends; f_l linear in T over the melting band. Twin of
// table_temperature_of in src/backend/cpu/heat.rs.
fn table_temperature_of(ph: u32, h: f32) -> vec2<f32> {
    var k = 0u;
    for (var i = 1u; i < P.phases[ph].enthalpy_points; i = i + 1u) {
        if (h >= P.phases[ph].enthalpy[i / 4u].value[i % 4u]) {
            k = i;
        }
    }
    let row = k / 4u;
    let c = k % 4u;
    let t = P.phases[ph].enthalpy[row].temperature[c] + (h - P.phases[ph].enthalpy[row].value[c]) / P.phases[ph].enthalpy[row].slope[c];
    let flags = heat_flags(ph);
    if ((flags & HEAT_MELTS) != 0u) {
        let fl = (t - P.phases[ph].solidus) / (P.phases[ph].liquidus - P.phases[ph].solidus);
        return vec2<f32>(t, min(max(fl, 0.0), c_one()));
    }
    return vec2<f32>(t, select(0.0, 1.0, (flags & HEAT_LIQUID) != 0u));
}

// A PHASE_PROGRAM phase's temperature at time t. Twin of
// Params::programmed_temperature.
fn programmed_temperature(ph: u32, time: f32) -> f32 {
    let cycle = pm_sin_cycles(P.phases[ph].program_frequency * time);
    let amplitude = P.phases[ph].program_amplitude + P.phases[ph].program_amplitude_rate * time;
    return P.phases[ph].program_temperature + amplitude * cycle + P.phases[ph].program_rate * min(time, P.phases[ph].program_until);
}

fn programmed(ph: u32) -> bool {
    return (heat_flags(ph) & PHASE_PROGRAM) != 0u;
}

@compute @workgroup_size(64)
fn temperature(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = thread_index(gid, nwg);
    if (i >= active_particles()) { return; }
    let ph = phase[i];
    if (!conducts(ph)) { return; }
    let flags = heat_flags(ph);
    var hv = heat[i];
    // A programmed particle: the enthalpy of its temperature at the step's
    // end (twin of impose_program in src/backend/cpu/heat.rs).
    if (programmed(ph)) {
        let t = programmed_temperature(ph, sim.time + sim.dt);
        hv[H_ENTHALPY] = P.phases[ph].heat_capacity * (t - P.phases[ph].reference_temperature);
    }
    let t_prev = hv[H_TEMPERATURE];
    let tf = temperature_of(ph, hv[H_ENTHALPY]);
    hv[H_TEMPERATURE] = tf.x;
    hv[H_LIQUID] = tf.y;
    heat[i] = hv;
    if ((P.sizes.flags & FLAG_SOLIDIFICATION) != 0u && (flags & HEAT_MELTS) != 0u) {
        var t_start = t_prev;
        if (P.solve.heat_integrator == HEAT_TRAPEZOIDAL) {
            t_start = temperature_of(ph, heat_start[i].x).x;
        }
        record_liquidus_crossing(i, ph, t_start, tf.x, hv[H_RATE]);
    }
    // Phase change at f_l = 1/2 (F22 §3.2, fixed substrate).
    let switch_to = (flags >> HEAT_SWITCH_SHIFT) & 15u;
    if (switch_to == 0u) { return; }
    let solid = P.phases[ph].kind == KIND_SOLID;
    if (solid && hv[H_LIQUID] >= 0.5) {
        phase[i] = switch_to - 1u;
    } else if (!solid && hv[H_LIQUID] < 0.5) {
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

// The solidification record (twin of record_crossing in
// src/backend/cpu/heat.rs): a melting particle whose temperature falls through
// the liquidus in this step (t_start >= T_l > t_new) records the crossing's
// time (linear in T within the step), its position and the cooling rate
// -dh/dt / c_l (the liquid side's, at the step's rate), and leaves its |grad T|
// pending for solidification_gradient. t_start is the step's first
// temperature (the trapezoidal iterates overwrote heat.y: T(h^n) then).
fn record_liquidus_crossing(i: u32, ph: u32, t_start: f32, t_new: f32, rate: f32) {
    let t_l = P.phases[ph].liquidus;
    if (t_start < t_l || t_new >= t_l) { return; }
    let k = id[i];
    var a = solidification[k];
    a[SOL_TIME] = sim.time + sim.dt * ((t_start - t_l) / (t_start - t_new));
    a[SOL_GRADIENT] = -c_one();
    a[SOL_COOLING] = -rate / P.phases[ph].liquid_heat_capacity;
    a[SOL_COUNT] = a[SOL_COUNT] + c_one();
    solidification[k] = a;
    let p = pos[i];
    solidification[P.sizes.n_particles + k] = vec4<f32>(p.x, p.y, p.z, c_one());
}

// |grad T| of each particle whose liquidus crossing in this step left it
// pending, once every temperature of the step is final. Twin of
// solidification_gradient in src/backend/cpu/heat.rs (equations there).
@compute @workgroup_size(64)
fn solidification_gradient(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = thread_index(gid, nwg);
    if (i >= active_particles()) { return; }
    let at = P.sizes.n_particles + id[i];
    var b = solidification[at];
    if (b[SOL_PENDING] == 0.0) { return; }
    let g = temperature_gradient(i);
    var a = solidification[id[i]];
    a[SOL_GRADIENT] = sqrt(len2(g));
    solidification[id[i]] = a;
    b[SOL_PENDING] = 0.0;
    solidification[at] = b;
}

// The renormalised temperature gradient M^-1 sum_j V_j (T_j - T_i) grad_i W_ij
// over conducting neighbours and Dirichlet walls (at their mirror temperatures).
fn temperature_gradient(i: u32) -> vec3<f32> {
    let pi = pos[i];
    let ci = cell_coord(pi);
    let zr = z_range();
    let t_i = heat[i][H_TEMPERATURE];
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
        let ph_j = phase[j];
        if (r2 < P.kernel.support2 && r2 > 0.0 && (conducts(ph_j) || (heat_flags(ph_j) & HEAT_DIRICHLET) != 0u)) {
            let r = sqrt(r2);
            let vf = mass[j] / heat_density(ph_j, j) * (kernel_dw(r) / r);
            mxx = mxx - vf * d.x * d.x;
            mxy = mxy - vf * d.x * d.y;
            mxz = mxz - vf * d.x * d.z;
            myy = myy - vf * d.y * d.y;
            myz = myz - vf * d.y * d.z;
            mzz = mzz - vf * d.z * d.z;
            let db = (heat[j][H_TEMPERATURE] - t_i) * vf;
            b.x = b.x + db * d.x;
            b.y = b.y + db * d.y;
            b.z = b.z + db * d.z;
        }
    }
    return solve_symmetric(mxx, mxy, mxz, myy, myz, mzz, b);
}
