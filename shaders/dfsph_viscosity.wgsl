// uses: params consts kernel grid phase reduce
// reads: pos mass phase rho dfsph
// writes: vel dfsph_cg solvers partials
// DFSPH's implicit velocity system, J22 (17): the viscosity (F22 (23)'s form,
// or Weiler et al. (2018)'s with viscosity_form = "marrone"), XSPH and the
// cohesion and adhesion terms solved for v^{t+1} by matrix-free
// Jacobi-preconditioned conjugate gradients, the system multiplied by m_i so
// that it is symmetric. Twin of src/backend/cpu/dfsph_viscosity.rs (equations
// and choices there). dfsph_cg[4 i + k]: k = 0 residual r, 1 direction p,
// 2 A p, 3 diag(A). pair_viscosity comes from shaders/terms/viscosity.wgsl
// (backend::terms::BORROWED).

const CG_R: u32 = 0u;
const CG_P: u32 = 1u;
const CG_Q: u32 = 2u;
const CG_DIAG: u32 = 3u;

fn viscosity_converged() -> bool {
    return solvers[SOLVER_VISCOSITY].converged != 0u;
}

// The pair's coefficients (k_p, k_i, s) for fluid particle i and neighbour j
// at r^2 = r2: the projected viscosity's (Weiler 2018, form 1) or the
// isotropic one's (F22 (23), form 0), both <= 0, and XSPH's.
fn cg_pair(i: u32, j: u32, vol_i: f32, r2: f32) -> vec3<f32> {
    let r = sqrt(r2);
    let g = kernel_dw(r) / r;
    let mu_i = P.phases[phase[i]].implicit_eta;
    let ph_j = phase[j];
    let wall = is_wall(ph_j);
    var mu = 0.0;
    var vol_j = 0.0;
    if (wall) {
        let slip = (P.phases[ph_j].flags & PHASE_FREE_SLIP) != 0u;
        mu = pair_viscosity(mu_i, mu_i, slip);
        vol_j = dfsph[j].x;
    } else {
        mu = pair_viscosity(mu_i, P.phases[ph_j].implicit_eta, false);
        vol_j = mass[j] / rho[j];
    }
    let dt = sim.dt;
    var kp = 0.0;
    var ki = 0.0;
    if (P.solve.dfsph_viscosity_form == 1u) {
        let f = dt * P.solve.viscosity_factor;
        kp = f * mu * vol_i * vol_j * g / (r2 + P.solve.dfsph_viscosity_eps);
    } else {
        ki = dt * mu * (vol_i * vol_i + vol_j * vol_j) * g;
    }
    var s = 0.0;
    if (!wall) {
        let rho_i = rho[i];
        let rho_j = rho[j];
        s = P.solve.dfsph_xsph * mass[i] * mass[j] * kernel_w(r) / ((rho_i + rho_j) * c_half());
    }
    return vec3<f32>(kp, ki, s);
}

var<private> cg_diag: vec3<f32>;

// sum_j [-k_p x (x.u) - k_i u + s u] over i's neighbours with u the difference of the
// velocity (which = 0; a wall's: its no-slip velocity) or of the direction p
// (which = 1; a wall's: 0); the diagonal m_i + sum_j (-k_p x_a^2 - k_i + s)
// in cg_diag.
fn cg_sweep(i: u32, which: u32) -> vec3<f32> {
    let m_i = mass[i];
    let vol_i = m_i / rho[i];
    var f_i = vel[i].xyz;
    if (which == 1u) {
        f_i = dfsph_cg[4u * i + CG_P].xyz;
    }
    let pi = pos[i];
    let ci = cell_coord(pi);
    let zr = z_range();
    var acc = vec3<f32>(0.0);
    var dg = vec3<f32>(m_i, m_i, m_i);
    #for_each_neighbor(ci, zr, j) {
        let d = min_image(pi, pos[j]);
        let r2 = len2(d);
        if (r2 < P.kernel.support2 && r2 > 0.0) {
            let ks = cg_pair(i, j, vol_i, r2);
            var f_j = vec3<f32>(0.0);
            if (is_wall(phase[j])) {
                if (which == 0u) {
                    f_j = dfsph_cg[4u * j + CG_R].xyz;
                }
            } else if (which == 0u) {
                f_j = vel[j].xyz;
            } else {
                f_j = dfsph_cg[4u * j + CG_P].xyz;
            }
            let u = vec3<f32>(f_i.x - f_j.x, f_i.y - f_j.y, f_i.z - f_j.z);
            let c = ks.x * (d.x * u.x + d.y * u.y + d.z * u.z);
            acc.x = acc.x - c * d.x - ks.y * u.x + ks.z * u.x;
            acc.y = acc.y - c * d.y - ks.y * u.y + ks.z * u.y;
            acc.z = acc.z - c * d.z - ks.y * u.z + ks.z * u.z;
            dg.x = dg.x - ks.x * d.x * d.x - ks.y + ks.z;
            dg.y = dg.y - ks.x * d.y * d.y - ks.y + ks.z;
            dg.z = dg.z - ks.x * d.z * d.z - ks.y + ks.z;
        }
    }
    cg_diag = dg;
    return acc;
}

fn dot3(a: vec4<f32>, b: vec4<f32>) -> f32 {
    return a.x * b.x + a.y * b.y + a.z * b.z;
}

// z = r / diag(A).
fn precondition(i: u32) -> vec4<f32> {
    let r = dfsph_cg[4u * i + CG_R];
    let dg = dfsph_cg[4u * i + CG_DIAG];
    return vec4<f32>(r.x / dg.x, r.y / dg.y, r.z / dg.z, 0.0);
}

fn is_fluid_slot(i: u32) -> bool {
    return i < active_particles() && !is_wall(phase[i]);
}

// Before v* = v + dt a: each wall particle's no-slip velocity in its
// dfsph_cg[4 b] (Adami et al. 2012, as the wall pass: u_b = 2 u_w - the
// Shepard mean of the fluid's v over its neighbours, the divisor sum W + eps).
@compute @workgroup_size(64)
fn dfsph_viscosity_wall(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let b = thread_index(gid, nwg);
    if (b >= active_particles() || !is_wall(phase[b])) { return; }
    let pb = pos[b];
    let ci = cell_coord(pb);
    let zr = z_range();
    var sw = 0.0;
    var sv = vec3<f32>(0.0);
    #for_each_neighbor(ci, zr, j) {
        let d = min_image(pb, pos[j]);
        let r2 = len2(d);
        if (r2 < P.kernel.support2 && !is_wall(phase[j])) {
            let wk = kernel_w(sqrt(r2));
            sw = sw + wk;
            let v = vel[j];
            sv.x = sv.x + v.x * wk;
            sv.y = sv.y + v.y * wk;
            sv.z = sv.z + v.z * wk;
        }
    }
    let u = P.phases[phase[b]].velocity;
    let den = sw + P.flow.wall_weight_floor;
    dfsph_cg[4u * b + CG_R] = vec4<f32>(u.x + (u.x * sw - sv.x) / den, u.y + (u.y * sw - sv.y) / den,
        u.z + (u.z * sw - sv.z) / den, 0.0);
}

// J22 (15)-(16) as printed, on the right side: m_i dt a_i with a_i =
// -gamma_f sum_{same phase} (m_bar / rho_bar) x_ij W_ij - gamma_b sum_b
// (m_bar / rho_bar) x_ib W_ib, a wall's mass rho0_i V_b and density rho0_i.
fn cohesion_impulse(i: u32) -> vec3<f32> {
    let m_i = mass[i];
    let rho_i = rho[i];
    let ph_i = phase[i];
    let rho0_i = P.phases[ph_i].rho0;
    let pi = pos[i];
    let ci = cell_coord(pi);
    let zr = z_range();
    var sf = vec3<f32>(0.0);
    var sb = vec3<f32>(0.0);
    #for_each_neighbor(ci, zr, j) {
        let d = min_image(pi, pos[j]);
        let r2 = len2(d);
        if (r2 < P.kernel.support2 && r2 > 0.0) {
            let w = kernel_w(sqrt(r2));
            if (is_wall(phase[j])) {
                let m_b = rho0_i * dfsph[j].x;
                let f = (m_i + m_b) / (rho_i + rho0_i) * w;
                sb.x = sb.x + f * d.x;
                sb.y = sb.y + f * d.y;
                sb.z = sb.z + f * d.z;
            } else if (phase[j] == ph_i) {
                let f = (m_i + mass[j]) / (rho_i + rho[j]) * w;
                sf.x = sf.x + f * d.x;
                sf.y = sf.y + f * d.y;
                sf.z = sf.z + f * d.z;
            }
        }
    }
    let gf = P.solve.dfsph_cohesion;
    let gb = P.solve.dfsph_adhesion;
    let mdt = m_i * sim.dt;
    return vec3<f32>(-(gf * sf.x + gb * sb.x) * mdt, -(gf * sf.y + gb * sb.y) * mdt,
        -(gf * sf.z + gb * sb.z) * mdt);
}

// Begin at x0 = v*: r = -sum (pair terms at v*), diag(A), p = z.
@compute @workgroup_size(64)
fn dfsph_viscosity_begin(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = thread_index(gid, nwg);
    if (!is_fluid_slot(i)) { return; }
    let acc = cg_sweep(i, 0u);
    let diag = cg_diag;
    if (P.solve.dfsph_cohesion > 0.0 || P.solve.dfsph_adhesion > 0.0) {
        let c = cohesion_impulse(i);
        dfsph_cg[4u * i + CG_R] = vec4<f32>(c.x - acc.x, c.y - acc.y, c.z - acc.z, 0.0);
    } else {
        dfsph_cg[4u * i + CG_R] = vec4<f32>(-acc.x, -acc.y, -acc.z, 0.0);
    }
    cg_diag = diag;
    dfsph_cg[4u * i + CG_DIAG] = vec4<f32>(diag, 0.0);
    dfsph_cg[4u * i + CG_P] = precondition(i);
}

// (r.z, r.r) at x0.
@compute @workgroup_size(256)
fn dfsph_viscosity_begin_sum(@builtin(local_invocation_index) t: u32, @builtin(workgroup_id) wid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let g = wid.x + wid.y * nwg.x;
    let i = g * DWG + t;
    var e = vec2<f32>(0.0, 0.0);
    if (is_fluid_slot(i)) {
        let r = dfsph_cg[4u * i + CG_R];
        e = vec2<f32>(dot3(r, dfsph_cg[4u * i + CG_P]), dot3(r, r));
    }
    tree_level_one(t, g, e);
}

// The solver reset with r.z and r0.r0; converged at once when r.z = 0.
@compute @workgroup_size(256)
fn dfsph_viscosity_begin_final(@builtin(local_invocation_index) t: u32) {
    let total = tree_level_two(t);
    if (t != 0u) { return; }
    var s = solver_reset(solvers[SOLVER_VISCOSITY]);
    s.converged = select(0u, 1u, total.x <= 0.0);
    s.scalars = vec4<f32>(total.x, total.y, 0.0, 0.0);
    solvers[SOLVER_VISCOSITY] = s;
}

// q = A p.
@compute @workgroup_size(64)
fn dfsph_viscosity_apply(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    if (viscosity_converged()) { return; }
    let i = thread_index(gid, nwg);
    if (!is_fluid_slot(i)) { return; }
    let acc = cg_sweep(i, 1u);
    let m = mass[i];
    let p = dfsph_cg[4u * i + CG_P];
    dfsph_cg[4u * i + CG_Q] = vec4<f32>(m * p.x + acc.x, m * p.y + acc.y, m * p.z + acc.z, 0.0);
}

// (p.q, 0).
@compute @workgroup_size(256)
fn dfsph_viscosity_apply_sum(@builtin(local_invocation_index) t: u32, @builtin(workgroup_id) wid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    if (viscosity_converged()) { return; }
    let g = wid.x + wid.y * nwg.x;
    let i = g * DWG + t;
    var e = vec2<f32>(0.0, 0.0);
    if (is_fluid_slot(i)) {
        e = vec2<f32>(dot3(dfsph_cg[4u * i + CG_P], dfsph_cg[4u * i + CG_Q]), 0.0);
    }
    tree_level_one(t, g, e);
}

// alpha = r.z / p.q.
@compute @workgroup_size(256)
fn dfsph_viscosity_apply_final(@builtin(local_invocation_index) t: u32) {
    if (viscosity_converged()) { return; }
    let total = tree_level_two(t);
    if (t != 0u) { return; }
    var s = solvers[SOLVER_VISCOSITY];
    var alpha = 0.0;
    if (total.x > 0.0) {
        alpha = s.scalars.x / total.x;
    }
    s.scalars.z = alpha;
    solvers[SOLVER_VISCOSITY] = s;
}

// v += alpha p, r -= alpha q.
@compute @workgroup_size(64)
fn dfsph_viscosity_update(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    if (viscosity_converged()) { return; }
    let i = thread_index(gid, nwg);
    if (!is_fluid_slot(i)) { return; }
    let alpha = solvers[SOLVER_VISCOSITY].scalars.z;
    let p = dfsph_cg[4u * i + CG_P];
    let q = dfsph_cg[4u * i + CG_Q];
    var v = vel[i];
    v.x = v.x + alpha * p.x;
    v.y = v.y + alpha * p.y;
    v.z = v.z + alpha * p.z;
    vel[i] = v;
    var r = dfsph_cg[4u * i + CG_R];
    r.x = r.x - alpha * q.x;
    r.y = r.y - alpha * q.y;
    r.z = r.z - alpha * q.z;
    dfsph_cg[4u * i + CG_R] = r;
}

// (r.z, r.r).
@compute @workgroup_size(256)
fn dfsph_viscosity_update_sum(@builtin(local_invocation_index) t: u32, @builtin(workgroup_id) wid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    if (viscosity_converged()) { return; }
    let g = wid.x + wid.y * nwg.x;
    let i = g * DWG + t;
    var e = vec2<f32>(0.0, 0.0);
    if (is_fluid_slot(i)) {
        let r = dfsph_cg[4u * i + CG_R];
        e = vec2<f32>(dot3(r, precondition(i)), dot3(r, r));
    }
    tree_level_one(t, g, e);
}

// beta = r.z_new / r.z, the relative residual |r| / |r0| and the converged flag.
@compute @workgroup_size(256)
fn dfsph_viscosity_update_final(@builtin(local_invocation_index) t: u32) {
    if (viscosity_converged()) { return; }
    let total = tree_level_two(t);
    if (t != 0u) { return; }
    var s = solvers[SOLVER_VISCOSITY];
    var beta = 0.0;
    if (s.scalars.x > 0.0) {
        beta = total.x / s.scalars.x;
    }
    s.scalars.x = total.x;
    s.scalars.w = beta;
    var residual = 0.0;
    if (s.scalars.y > 0.0) {
        residual = sqrt(total.y / s.scalars.y);
    }
    solvers[SOLVER_VISCOSITY] = solver_finish(s, residual,
        residual <= P.solve.dfsph_viscosity_tolerance, P.solve.dfsph_viscosity_max_iterations);
}

// p = z + beta p.
@compute @workgroup_size(64)
fn dfsph_viscosity_direction(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    if (viscosity_converged()) { return; }
    let i = thread_index(gid, nwg);
    if (!is_fluid_slot(i)) { return; }
    let beta = solvers[SOLVER_VISCOSITY].scalars.w;
    let z = precondition(i);
    var p = dfsph_cg[4u * i + CG_P];
    p.x = z.x + beta * p.x;
    p.y = z.y + beta * p.y;
    p.z = z.z + beta * p.z;
    dfsph_cg[4u * i + CG_P] = p;
}
