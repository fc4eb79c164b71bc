// uses: params consts grid phase math
// reads: pos mass phase surface sim
// writes: bins heat
// Beer-Lambert laser absorption with column binning (R18 §3.2.2), beam down the
// last axis. Twin of src/backend/cpu/laser.rs (equations there).

fn absorbs(ph: u32) -> bool {
    return conducts(ph) && P.phases[ph].kind != KIND_GAS;
}

fn bin_centre(k: vec3<u32>) -> vec4<f32> {
    let dx = P.laser.bin_size;
    return vec4<f32>(
        P.laser.lo.x + (f32(k.x) + c_half()) * dx,
        P.laser.lo.y + (f32(k.y) + c_half()) * dx,
        P.laser.lo.z + (f32(k.z) + c_half()) * dx,
        0.0);
}

// Cloud-in-cell weight of a particle offset d from a bin centre.
fn cic(d: vec3<f32>) -> f32 {
    let dx = P.laser.bin_size;
    var w = 1.0;
    for (var a = 0u; a < P.sizes.dim; a++) {
        w = w * max(c_one() - abs(d[a]) / dx, 0.0);
    }
    return w;
}

fn n_bins() -> u32 {
    return P.laser.bins.x * P.laser.bins.y * P.laser.bins.z;
}

@compute @workgroup_size(64)
fn laser_bins(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let b = thread_index(gid, nwg);
    if (b >= n_bins()) { return; }
    let nb = P.laser.bins;
    let c = bin_centre(vec3<u32>(b % nb.x, (b / nb.x) % nb.y, b / (nb.x * nb.y)));
    let ci = cell_coord(c);
    let zr = z_range();
    var sum = 0.0;
    #for_each_neighbor(ci, zr, j) {
        let d = min_image(c, pos[j]);
        if (len2(d) < P.kernel.support2 && absorbs(phase[j])) {
            let v = mass[j] / P.phases[phase[j]].rho0;
            sum = sum + cic(d) * v;
        }
    }
    bins[b] = vec2<f32>(sum, 0.0);
}

// zeta s_l at point p: zeta P s0 exp(-2 d^2/r_w^2), d the lateral distance from the
// beam centre; both laser models share it.
fn irradiance(p: vec4<f32>, centre: vec2<f32>, power: f32) -> f32 {
    let d0 = p.x - centre.x;
    var d1 = 0.0;
    if (P.sizes.dim == 3u) {
        d1 = p.y - centre.y;
    }
    let r2 = d0 * d0 + d1 * d1;
    let rw = P.laser.radius;
    return P.laser.absorptivity * power * P.laser.peak_per_watt * pm_exp(-(c_two() * r2 / (rw * rw)));
}

fn beam_centre(t: f32) -> vec2<f32> {
    let n = P.laser.path_points;
    if (t <= P.laser.path[0].time) {
        return vec2<f32>(P.laser.path[0].x, P.laser.path[0].y);
    }
    for (var k = 1u; k < n; k++) {
        if (t < P.laser.path[k].time) {
            let p0 = P.laser.path[k - 1u];
            let p1 = P.laser.path[k];
            let f = (t - p0.time) / (p1.time - p0.time);
            return vec2<f32>(p0.x + f * (p1.x - p0.x), p0.y + f * (p1.y - p0.y));
        }
    }
    return vec2<f32>(P.laser.path[n - 1u].x, P.laser.path[n - 1u].y);
}

fn beam_power(t: f32) -> f32 {
    let n = P.laser.power_steps;
    var p = 0.0;
    for (var k = 0u; k < n; k++) {
        if (P.laser.power[k].time <= t) {
            p = P.laser.power[k].power;
        }
    }
    return p;
}

@compute @workgroup_size(64)
fn laser_columns(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let c = thread_index(gid, nwg);
    let nb = P.laser.bins;
    let three = P.sizes.dim == 3u;
    let n_cols = select(nb.x, nb.x * nb.y, three);
    if (c >= n_cols) { return; }
    let depth = select(nb.y, nb.z, three);
    let stride = select(nb.x, nb.x * nb.y, three);
    let t = sim.time;
    let centre = beam_centre(t);
    let power = beam_power(t);
    let a = P.laser.absorption;
    let dx = P.laser.bin_size;
    let top = bin_centre(vec3<u32>(c % nb.x, select(0u, c / nb.x, three), 0u));
    var i = irradiance(top, centre, power) * P.laser.column_area;
    for (var k = i32(depth) - 1; k >= 0; k--) {
        let b = c + u32(k) * stride;
        let vf = bins[b].x / P.laser.bin_volume;
        let trans = pm_exp(-(a * dx * vf));
        bins[b].y = i * (c_one() - trans);
        i = i * trans;
    }
}

// Bin coordinate on axis a, wrapped on periodic axes; -1 outside the grid.
fn bin_axis(k: i32, a: u32) -> i32 {
    let n = i32(P.laser.bins[a]);
    if (k >= 0 && k < n) { return k; }
    if ((P.sizes.flags & (1u << a)) != 0u) { return (k + n) % n; }
    return -1;
}

@compute @workgroup_size(64)
fn laser_deposit(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = thread_index(gid, nwg);
    if (i >= active_particles()) { return; }
    let ph = phase[i];
    if (!conducts(ph)) { return; }
    if (absorbs(ph)) {
        heat[i][H_RATE] = binned_source(i, ph);
    } else {
        heat[i][H_RATE] = 0.0;
    }
}

// Share of the neighbouring bins' power particle i takes, per unit mass.
fn binned_source(i: u32, ph: u32) -> f32 {
    let p = pos[i];
    let v = mass[i] / P.phases[ph].rho0;
    let dx = P.laser.bin_size;
    let nb = P.laser.bins;
    var k: vec3<i32>;
    for (var a = 0u; a < 3u; a++) {
        let f = floor((p[a] - P.laser.lo[a]) / dx);
        k[a] = clamp(i32(f), 0, i32(nb[a]) - 1);
    }
    let zr = z_range();
    var sum = 0.0;
    for (var oz = -zr; oz <= zr; oz++) {
        for (var oy = -1; oy <= 1; oy++) {
            for (var ox = -1; ox <= 1; ox++) {
                let bx = bin_axis(k.x + ox, 0u);
                let by = bin_axis(k.y + oy, 1u);
                let bz = bin_axis(k.z + oz, 2u);
                if (bx < 0 || by < 0 || bz < 0) { continue; }
                let idx = vec3<u32>(u32(bx), u32(by), u32(bz));
                let b = idx.x + nb.x * (idx.y + nb.y * idx.z);
                let w = cic(min_image(p, bin_centre(idx)));
                let bv = bins[b];
                if (w > 0.0 && bv.x > 0.0) {
                    sum = sum + bv.y * (w * v) / bv.x;
                }
            }
        }
    }
    return sum / mass[i];
}

// Gaussian surface flux F22 (17): q = zeta <-n.e_l> s_l(x) delta / rho0, e_l = -e_up.
@compute @workgroup_size(64)
fn laser_surface(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = thread_index(gid, nwg);
    if (i >= active_particles()) { return; }
    let ph = phase[i];
    if (!conducts(ph)) { return; }
    if (!absorbs(ph)) {
        heat[i][H_RATE] = 0.0;
        return;
    }
    let up = P.sizes.dim - 1u;
    let s = surface[i];
    let cosine = max(s[up], 0.0);
    let q = irradiance(pos[i], beam_centre(sim.time), beam_power(sim.time));
    heat[i][H_RATE] = q * cosine * s[S_DELTA] / P.phases[ph].rho0;
}
