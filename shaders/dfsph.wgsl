// uses: params consts kernel grid phase reduce
// reads: mass phase acc heat
// writes: pos vel rho press dfsph dfsph_warm solvers partials
// Divergence-free SPH (Bender & Koschier 2015, 2017; J22 §3.1): the per-particle
// factor, the divergence-free and constant-density solves (bounded repeats
// whose residual sets the solver's converged flag), the full-step prediction
// and drift, with Akinci et al. (2012) boundary volumes on the wall particles.
// Twin of src/backend/cpu/dfsph.rs (equations and choices there).

// The wall's velocity (its phase's; walls do not move under DFSPH).
fn boundary_velocity(j: u32) -> vec3<f32> {
    return P.phases[phase[j]].velocity.xyz;
}

// dfsph_boundary_volume: a wall particle's volume V_b = m_b / rho0_b (the
// lattice's volume per particle) in dfsph.x; its pressure 0 (the forces pass
// then reads the wall as fluid at rho0).
@compute @workgroup_size(64)
fn dfsph_boundary_volume(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = thread_index(gid, nwg);
    if (i >= active_particles()) { return; }
    let ph = phase[i];
    if (!is_wall(ph)) { return; }
    dfsph[i] = vec4<f32>(mass[i] / P.phases[ph].rho0, 0.0, 0.0, 0.0);
    press[i] = 0.0;
}

// dfsph_factor: rho_i = m_i sum_f W_if + rho0_i sum_b V_b W_ib and the factor
// alpha_i = rho_i / (|sum_j g_j|^2 + sum_f |g_f|^2), g_f = m_f grad W_if,
// g_b = rho0_i V_b grad W_ib; 0 without neighbours. Pressure 0 for the forces
// pass (the non-pressure forces).
@compute @workgroup_size(64)
fn dfsph_factor(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = thread_index(gid, nwg);
    if (i >= active_particles()) { return; }
    let ph_i = phase[i];
    if (is_wall(ph_i)) { return; }
    let rho0_i = P.phases[ph_i].rho0;
    let pi = pos[i];
    let ci = cell_coord(pi);
    let zr = z_range();
    var sum_f = 0.0;
    var sum_b = 0.0;
    var g = vec3<f32>(0.0);
    var gb = vec3<f32>(0.0);
    var sq = 0.0;
    #for_each_neighbor(ci, zr, j) {
        let d = min_image(pi, pos[j]);
        let r2 = len2(d);
        if (r2 < P.kernel.support2) {
            let r = sqrt(r2);
            if (is_wall(phase[j])) {
                let psi = rho0_i * dfsph[j].x;
                sum_b = sum_b + dfsph[j].x * kernel_w(r);
                if (r2 > 0.0) {
                    let f = psi * (kernel_dw(r) / r);
                    g.x = g.x + f * d.x;
                    g.y = g.y + f * d.y;
                    g.z = g.z + f * d.z;
                    gb.x = gb.x + f * d.x;
                    gb.y = gb.y + f * d.y;
                    gb.z = gb.z + f * d.z;
                }
            } else {
                sum_f = sum_f + kernel_w(r);
                if (r2 > 0.0) {
                    let f = mass[j] * (kernel_dw(r) / r);
                    g.x = g.x + f * d.x;
                    g.y = g.y + f * d.y;
                    g.z = g.z + f * d.z;
                    sq = sq + f * f * r2;
                }
            }
        }
    }
    let rho_i = mass[i] * sum_f + rho0_i * sum_b;
    let denom = g.x * (g.x + gb.x) + g.y * (g.y + gb.y) + g.z * (g.z + gb.z) + sq;
    var alpha = 0.0;
    if (denom > 0.0) {
        alpha = rho_i / denom;
    }
    rho[i] = rho_i;
    press[i] = 0.0;
    dfsph[i] = vec4<f32>(alpha, 0.0, 0.0, 0.0);
}

// D rho_i / Dt = sum_f m_f (v_i - v_f).grad W_if + sum_b rho0_i V_b (v_i - v_b).grad W_ib,
// and the number of neighbours it summed.
struct Rate {
    rate: f32,
    neighbours: u32,
}

fn density_rate(i: u32) -> Rate {
    let rho0_i = P.phases[phase[i]].rho0;
    let v_i = vel[i];
    let pi = pos[i];
    let ci = cell_coord(pi);
    let zr = z_range();
    var rate = 0.0;
    var neighbours = 0u;
    #for_each_neighbor(ci, zr, j) {
        let d = min_image(pi, pos[j]);
        let r2 = len2(d);
        if (r2 < P.kernel.support2 && r2 > 0.0) {
            let r = sqrt(r2);
            var u = vec3<f32>(0.0);
            var w = 0.0;
            if (is_wall(phase[j])) {
                u = boundary_velocity(j);
                w = rho0_i * dfsph[j].x;
            } else {
                u = vel[j].xyz;
                w = mass[j];
            }
            let ud = (v_i.x - u.x) * d.x + (v_i.y - u.y) * d.y + (v_i.z - u.z) * d.z;
            rate = rate + w * ud * (kernel_dw(r) / r);
            neighbours = neighbours + 1u;
        }
    }
    return Rate(rate, neighbours);
}

// v_i -= dt (sum_f m_f (k_i / rho_i + k_f / rho_f) grad W_if
//            + sum_b rho0_i V_b (k_i / rho_i) grad W_ib), k = dfsph.z.
fn apply_kappa(i: u32) {
    let rho0_i = P.phases[phase[i]].rho0;
    let k_i = dfsph[i].z / rho[i];
    let pi = pos[i];
    let ci = cell_coord(pi);
    let zr = z_range();
    var dv = vec3<f32>(0.0);
    #for_each_neighbor(ci, zr, j) {
        let d = min_image(pi, pos[j]);
        let r2 = len2(d);
        if (r2 < P.kernel.support2 && r2 > 0.0) {
            let r = sqrt(r2);
            var s = 0.0;
            if (is_wall(phase[j])) {
                let s_b = rho0_i * dfsph[j].x * k_i;
                s = s_b + s_b;
            } else {
                s = mass[j] * (k_i + dfsph[j].z / rho[j]);
            }
            let f = s * (kernel_dw(r) / r);
            dv.x = dv.x + f * d.x;
            dv.y = dv.y + f * d.y;
            dv.z = dv.z + f * d.z;
        }
    }
    let dt = sim.dt;
    var v = vel[i];
    v.x = v.x - dt * dv.x;
    v.y = v.y - dt * dv.y;
    v.z = v.z - dt * dv.z;
    vel[i] = v;
}

// The solvers' residual: the mean of max(error_i, 0) / rho0_i over fluid
// particles by the fixed two-level tree (lib/reduce.wgsl).
fn residual_level_one(t: u32, g: u32) {
    let i = g * DWG + t;
    var e = vec2<f32>(0.0, 0.0);
    if (i < active_particles() && !is_wall(phase[i])) {
        e = vec2<f32>(max(dfsph[i].y, 0.0) / P.phases[phase[i]].rho0, c_one());
    }
    tree_level_one(t, g, e);
}

// The mean error over fluid particles (thread 0 holds it after the call).
fn residual_level_two(t: u32) -> f32 {
    let total = tree_level_two(t);
    if (total.y > 0.0) {
        return total.x / total.y;
    }
    return 0.0;
}

fn finish_iteration(slot: u32, mean_error: f32, tolerance: f32, min_iterations: u32) {
    let s = solvers[slot];
    let converged = mean_error <= tolerance && s.iterations + 1u >= min_iterations;
    solvers[slot] = solver_finish(s, mean_error, converged, P.solve.dfsph_max_iterations);
}

fn divergence_converged() -> bool {
    return solvers[SOLVER_DIVERGENCE].converged != 0u;
}

fn density_converged() -> bool {
    return solvers[SOLVER_DENSITY].converged != 0u;
}

// Divergence error of fluid particle i: D rho / Dt (the sum of k is kept
// non-negative, so only compression is corrected: a free surface's particles
// may separate); 0 for a particle with fewer than a quarter of the lattice's
// neighbours (spray). There alpha = rho / (a sum of a few |m grad W|^2) grows
// without bound as its neighbours near the support's edge: a lone droplet
// particle (3D spread at D0/dx = 25) met one at 2.985 dx, took k_i = 6e15
// and, warm-started next step with the pair closer, left at 1e4 m/s.
// SPlisHSPlasH skips the divergence solve below 20 neighbours (3D) for the
// same reason; its density solve corrects compression only, which a sparse
// particle never has.
fn divergence_error(i: u32) {
    var e = dfsph[i];
    let rate = density_rate(i);
    e.y = rate.rate;
    if (rate.neighbours < P.solve.dfsph_min_neighbours) {
        e.y = 0.0;
    }
    dfsph[i] = e;
}

// Density error: rho_i + dt D rho / Dt - rho0, the predicted excess.
fn density_error(i: u32) {
    var e = dfsph[i];
    let rho0_i = P.phases[phase[i]].rho0;
    e.y = rho[i] + sim.dt * density_rate(i).rate - rho0_i;
    dfsph[i] = e;
}

// One projected, relaxed Jacobi update of the summed k: sum <- max(sum +
// omega alpha error / scale, 0) with omega = 1/2; dfsph.z holds the change,
// which the velocity dispatch applies.
fn relax(i: u32, scale: f32) {
    var e = dfsph[i];
    let next = max(e.w + c_half() * e.x * e.y / scale, 0.0);
    e.z = next - e.w;
    e.w = next;
    dfsph[i] = e;
}

// The warm start (Bender & Koschier 2017 §4.4): half the previous step's
// summed k, rescaled to this dt, for every fluid particle (SPlisHSPlasH 2.11
// applies it only where the particle is compressed now; the relaxation's
// projection takes back what is not needed). In dfsph.z (applied by the
// velocity dispatch that follows) and dfsph.w (the sum).
fn warm_start(i: u32, stored: f32, scale: f32) {
    var e = dfsph[i];
    let k = c_half() * stored / scale;
    e.z = k;
    e.w = k;
    dfsph[i] = e;
}

// Begin: the solver reset, the errors and the warm start's k (the stage's
// velocity and error dispatches then apply it).
@compute @workgroup_size(64)
fn dfsph_divergence_begin(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = thread_index(gid, nwg);
    if (i == 0u) {
        solvers[SOLVER_DIVERGENCE] = solver_reset(solvers[SOLVER_DIVERGENCE]);
    }
    if (i >= active_particles() || is_wall(phase[i])) { return; }
    divergence_error(i);
    warm_start(i, dfsph_warm[i].y, sim.dt);
}

// k_i = alpha_i max(D rho / Dt, 0) / dt.
@compute @workgroup_size(64)
fn dfsph_divergence_kappa(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    if (divergence_converged()) { return; }
    let i = thread_index(gid, nwg);
    if (i >= active_particles() || is_wall(phase[i])) { return; }
    relax(i, sim.dt);
}

// The begin stage's application of the warm start and its new errors (the
// solver was just reset: no converged test).
@compute @workgroup_size(64)
fn dfsph_divergence_warm_velocity(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = thread_index(gid, nwg);
    if (i >= active_particles() || is_wall(phase[i])) { return; }
    apply_kappa(i);
}

@compute @workgroup_size(64)
fn dfsph_divergence_warm_error(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = thread_index(gid, nwg);
    if (i >= active_particles() || is_wall(phase[i])) { return; }
    divergence_error(i);
}

@compute @workgroup_size(64)
fn dfsph_divergence_velocity(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    if (divergence_converged()) { return; }
    let i = thread_index(gid, nwg);
    if (i >= active_particles() || is_wall(phase[i])) { return; }
    apply_kappa(i);
}

@compute @workgroup_size(64)
fn dfsph_divergence_error(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    if (divergence_converged()) { return; }
    let i = thread_index(gid, nwg);
    if (i >= active_particles() || is_wall(phase[i])) { return; }
    divergence_error(i);
}

@compute @workgroup_size(256)
fn dfsph_divergence_residual(@builtin(local_invocation_index) t: u32, @builtin(workgroup_id) wid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    if (divergence_converged()) { return; }
    residual_level_one(t, wid.x + wid.y * nwg.x);
}

// Converged when the mean divergence error times dt (a density error per
// step) is at the tolerance, after at least one iteration.
@compute @workgroup_size(256)
fn dfsph_divergence_residual_final(@builtin(local_invocation_index) t: u32) {
    if (divergence_converged()) { return; }
    let mean = residual_level_two(t);
    if (t != 0u) { return; }
    finish_iteration(SOLVER_DIVERGENCE, mean * sim.dt, P.solve.dfsph_divergence_tolerance, 1u);
}

// v* = v + dt a (the non-pressure forces), then the mushy-zone sink; the divergence solve's warm
// store dt sum(k).
@compute @workgroup_size(64)
fn dfsph_predict(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = thread_index(gid, nwg);
    if (i >= active_particles() || is_wall(phase[i])) { return; }
    let dt = sim.dt;
    var warm = dfsph_warm[i];
    warm.y = dt * dfsph[i].w;
    dfsph_warm[i] = warm;
    let a = acc[i];
    let b = wall_head(i);
    var v = vel[i];
    v.x = v.x + dt * a.x - dt * b.x;
    v.y = v.y + dt * a.y - dt * b.y;
    v.z = v.z + dt * a.z - dt * b.z;
    // The mushy-zone sink J22 (11)-(13), as the WCSPH kick has it.
    let sink = P.phases[phase[i]].mushy_damping;
    if (sink > 0.0) {
        let damp = c_one() + dt * sink * (c_one() - heat[i][H_LIQUID]);
        v.x = v.x / damp;
        v.y = v.y / damp;
        v.z = v.z / damp;
    }
    vel[i] = v;
}

// The walls' hydrostatic head (Adami et al. 2012's extrapolation, the part
// that does not depend on k): a wall particle b holds k_b / rho_b = k_i /
// rho_i + g.(x_b - x_i) / rho_i; the k_i part is in apply_kappa, this is
// sum_b psi_b (g.(x_b - x_i) / rho_i) grad W_ib, applied once per step.
fn wall_head(i: u32) -> vec3<f32> {
    let rho0_i = P.phases[phase[i]].rho0;
    let g = P.flow.gravity;
    let rho_i = rho[i];
    let pi = pos[i];
    let ci = cell_coord(pi);
    let zr = z_range();
    var h = vec3<f32>(0.0);
    #for_each_neighbor(ci, zr, j) {
        let d = min_image(pi, pos[j]);
        let r2 = len2(d);
        if (r2 < P.kernel.support2 && r2 > 0.0 && is_wall(phase[j])) {
            let r = sqrt(r2);
            let gd = 0.0 - g.x * d.x - g.y * d.y - g.z * d.z;
            let f = rho0_i * dfsph[j].x * (gd / rho_i) * (kernel_dw(r) / r);
            h.x = h.x + f * d.x;
            h.y = h.y + f * d.y;
            h.z = h.z + f * d.z;
        }
    }
    return h;
}

@compute @workgroup_size(64)
fn dfsph_density_begin(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = thread_index(gid, nwg);
    if (i == 0u) {
        solvers[SOLVER_DENSITY] = solver_reset(solvers[SOLVER_DENSITY]);
    }
    if (i >= active_particles() || is_wall(phase[i])) { return; }
    density_error(i);
    let dt = sim.dt;
    warm_start(i, dfsph_warm[i].x, dt * dt);
}

// k_i = alpha_i max(rho*_i - rho0, 0) / dt^2, summed in dfsph.w (the step's
// pressure is k rho).
@compute @workgroup_size(64)
fn dfsph_density_kappa(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    if (density_converged()) { return; }
    let i = thread_index(gid, nwg);
    if (i >= active_particles() || is_wall(phase[i])) { return; }
    let dt = sim.dt;
    relax(i, dt * dt);
}

// The begin stage's application of the warm start and its new errors.
@compute @workgroup_size(64)
fn dfsph_density_warm_velocity(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = thread_index(gid, nwg);
    if (i >= active_particles() || is_wall(phase[i])) { return; }
    apply_kappa(i);
}

@compute @workgroup_size(64)
fn dfsph_density_warm_error(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = thread_index(gid, nwg);
    if (i >= active_particles() || is_wall(phase[i])) { return; }
    density_error(i);
}

@compute @workgroup_size(64)
fn dfsph_density_velocity(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    if (density_converged()) { return; }
    let i = thread_index(gid, nwg);
    if (i >= active_particles() || is_wall(phase[i])) { return; }
    apply_kappa(i);
}

@compute @workgroup_size(64)
fn dfsph_density_error(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    if (density_converged()) { return; }
    let i = thread_index(gid, nwg);
    if (i >= active_particles() || is_wall(phase[i])) { return; }
    density_error(i);
}

@compute @workgroup_size(256)
fn dfsph_density_residual(@builtin(local_invocation_index) t: u32, @builtin(workgroup_id) wid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    if (density_converged()) { return; }
    residual_level_one(t, wid.x + wid.y * nwg.x);
}

// Converged when the mean density error is at the tolerance, after at least
// two iterations (Bender & Koschier 2017).
@compute @workgroup_size(256)
fn dfsph_density_residual_final(@builtin(local_invocation_index) t: u32) {
    if (density_converged()) { return; }
    let mean = residual_level_two(t);
    if (t != 0u) { return; }
    finish_iteration(SOLVER_DENSITY, mean, P.solve.dfsph_density_tolerance, 2u);
}

// x += dt v*, wrapped and stamped if it left; the step's pressure p = k rho
// (k summed over the density solve's iterations).
@compute @workgroup_size(64)
fn dfsph_drift(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = thread_index(gid, nwg);
    if (i >= active_particles() || is_wall(phase[i])) { return; }
    let dt = sim.dt;
    let v = vel[i];
    var x = pos[i];
    for (var c = 0u; c < 3u; c++) {
        x[c] = wrap_periodic(x[c] + dt * v[c], c);
    }
    pos[i] = stamp_if_left(x);
    let k = dfsph[i].w;
    var warm = dfsph_warm[i];
    press[i] = (k + warm.y / dt) * rho[i];
    warm.x = dt * dt * k;
    dfsph_warm[i] = warm;
}
