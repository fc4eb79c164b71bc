// uses: params consts grid phase math
// reads: pos mass phase surface sim
// writes: bins ray_counts ray_split heat
// Beer-Lambert laser absorption with column binning (R18 §3.2.2), the ray-traced
// Fresnel absorption on the same bins, and the Gaussian surface flux; beam down
// the last axis. Twin of src/backend/cpu/laser.rs (equations there).

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
    let traced = P.laser.model == LASER_RAY_TRACED;
    var sum = 0.0;
    var sn = 0.0;
    var sk = 0.0;
    #for_each_neighbor(ci, zr, j) {
        let d = min_image(c, pos[j]);
        if (len2(d) < P.kernel.support2 && absorbs(phase[j])) {
            let v = mass[j] / P.phases[phase[j]].rho0;
            let wv = cic(d) * v;
            sum = sum + wv;
            if (traced) {
                sn = sn + wv * P.phases[phase[j]].optical_n;
                sk = sk + wv * P.phases[phase[j]].optical_k;
            }
        }
    }
    bins[b] = vec4<f32>(sum, 0.0, sn, sk);
    if (traced) {
        atomicStore(&ray_counts[b], 0u);
        if (b == 0u) {
            for (var k = 0u; k < 4u; k++) {
                atomicStore(&ray_split[k], 0u);
            }
        }
    }
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

// ---- Ray-traced absorption (twin: cpu/laser.rs trace, rays, ray_bins) ----

const RAYS_INCIDENT: u32 = 0u;
const RAYS_ABSORBED: u32 = 1u;
const RAYS_LEAVING: u32 = 2u;
const RAYS_AT_LIMIT: u32 = 3u;
const NO_BIN: u32 = 0xffffffffu;

struct RayFill {
    v: f32,
    bin: u32,
}

// Filled fraction of bin k (wrapped on periodic axes; 0 outside) and its index.
fn ray_fill(k: vec3<i32>) -> RayFill {
    let bx = bin_axis(k.x, 0u);
    let by = bin_axis(k.y, 1u);
    let bz = bin_axis(k.z, 2u);
    if (bx < 0 || by < 0 || bz < 0) { return RayFill(0.0, NO_BIN); }
    let nb = P.laser.bins;
    let b = u32(bx) + nb.x * (u32(by) + nb.y * u32(bz));
    return RayFill(bins[b].x / P.laser.bin_volume, b);
}

struct RayCell {
    k: vec3<i32>,
    f: vec3<f32>,
}

// The interpolation cell of x: its lower corner's bin coordinates and the
// fractions along each axis (axes past the dimension: 0 and 0).
fn ray_cell(x: vec3<f32>) -> RayCell {
    let dx = P.laser.bin_size;
    var k = vec3<i32>(0, 0, 0);
    var f = vec3<f32>(0.0, 0.0, 0.0);
    for (var a = 0u; a < P.sizes.dim; a++) {
        let u = (x[a] - P.laser.lo[a]) / dx - c_half();
        let fl = floor(u);
        k[a] = i32(fl);
        f[a] = u - fl;
    }
    return RayCell(k, f);
}

fn corner_weight(f: vec3<f32>, c: u32) -> f32 {
    let wx = select(c_one() - f.x, f.x, (c & 1u) == 1u);
    let wy = select(c_one() - f.y, f.y, ((c >> 1u) & 1u) == 1u);
    var wz = 1.0;
    if (P.sizes.dim == 3u) {
        wz = select(c_one() - f.z, f.z, ((c >> 2u) & 1u) == 1u);
    }
    return wx * wy * wz;
}

fn n_corners() -> u32 {
    return select(4u, 8u, P.sizes.dim == 3u);
}

fn corner(k: vec3<i32>, c: u32) -> vec3<i32> {
    return vec3<i32>(k.x + i32(c & 1u), k.y + i32((c >> 1u) & 1u), k.z + i32((c >> 2u) & 1u));
}

// V_f at x, interpolated between bin centres.
fn ray_value(x: vec3<f32>) -> f32 {
    let cell = ray_cell(x);
    var v = 0.0;
    for (var c = 0u; c < n_corners(); c++) {
        v = v + corner_weight(cell.f, c) * ray_fill(corner(cell.k, c)).v;
    }
    return v;
}

struct RaySurface {
    grad: vec3<f32>,
    best: u32,
}

// At a hit: grad V_f up to a positive factor (central differences at the
// corners, interpolated) and the bin of the largest corner value.
fn ray_surface(x: vec3<f32>) -> RaySurface {
    let cell = ray_cell(x);
    var g = vec3<f32>(0.0, 0.0, 0.0);
    var best_v = 0.0;
    var best = NO_BIN;
    for (var c = 0u; c < n_corners(); c++) {
        let kc = corner(cell.k, c);
        let fc = ray_fill(kc);
        if (fc.v > best_v) {
            best_v = fc.v;
            best = fc.bin;
        }
        let w = corner_weight(cell.f, c);
        for (var a = 0u; a < P.sizes.dim; a++) {
            var hi = kc;
            var lo = kc;
            hi[a] = hi[a] + 1;
            lo[a] = lo[a] - 1;
            let d = ray_fill(hi).v - ray_fill(lo).v;
            g[a] = g[a] + w * d;
        }
    }
    return RaySurface(g, best);
}

// x on the bin box, wrapped on periodic axes (w = 1), or w = 0 once it has left.
fn ray_in_box(x_in: vec3<f32>) -> vec4<f32> {
    var x = x_in;
    for (var a = 0u; a < P.sizes.dim; a++) {
        let lo = P.laser.lo[a];
        let len = f32(P.laser.bins[a]) * P.laser.bin_size;
        if (x[a] < lo || x[a] > lo + len) {
            if ((P.sizes.flags & (1u << a)) == 0u) {
                return vec4<f32>(x, 0.0);
            }
            x[a] = select(x[a] - len, x[a] + len, x[a] < lo);
        }
    }
    return vec4<f32>(x, 1.0);
}

fn along(x: vec3<f32>, d: vec3<f32>, s: f32) -> vec3<f32> {
    return vec3<f32>(x.x + d.x * s, x.y + d.y * s, x.z + d.z * s);
}

fn back(x: vec3<f32>, d: vec3<f32>, s: f32) -> vec3<f32> {
    return vec3<f32>(x.x - d.x * s, x.y - d.y * s, x.z - d.z * s);
}

fn n_rays() -> u32 {
    let n = P.laser.rays_per_side;
    return select(n, n * n, P.sizes.dim == 3u);
}

@compute @workgroup_size(64)
fn laser_rays(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let r = thread_index(gid, nwg);
    if (r >= n_rays()) { return; }
    let dim = P.sizes.dim;
    let up = dim - 1u;
    let n = P.laser.rays_per_side;
    let half = i32(n / 2u);
    let ox = f32(i32(r % n) - half) * P.laser.ray_spacing;
    var oy = 0.0;
    if (dim == 3u) {
        oy = f32(i32(r / n) - half) * P.laser.ray_spacing;
    }
    let r2 = ox * ox + oy * oy;
    let rw = P.laser.radius;
    var g = 0.0;
    if (P.laser.profile == PROFILE_GAUSSIAN) {
        g = pm_exp(-(c_two() * r2 / (rw * rw)));
    } else if (r2 <= rw * rw) {
        g = 1.0;
    }
    let t = sim.time;
    let centre = beam_centre(t);
    let power = beam_power(t);
    let q0 = u32(floor(power * g * P.laser.ray_norm / P.laser.power_unit + c_half()));
    atomicAdd(&ray_split[RAYS_INCIDENT], q0);
    var q = q0;
    if (q == 0u) { return; }
    var x = vec3<f32>(0.0, 0.0, 0.0);
    var d = vec3<f32>(0.0, 0.0, 0.0);
    x.x = centre.x + ox;
    if (dim == 3u) {
        x.y = centre.y + oy;
    }
    x[up] = P.laser.lo[up] + f32(P.laser.bins[up]) * P.laser.bin_size;
    d[up] = -1.0;
    let h = P.laser.march_step;
    for (var bounce = 0u; bounce < P.laser.max_bounces; bounce++) {
        var a = x;
        var hit = false;
        for (var s = 0u; s < P.laser.march_steps; s++) {
            let b = ray_in_box(along(a, d, h));
            if (b.w == 0.0) { break; }
            if (ray_value(b.xyz) >= 0.5) {
                hit = true;
                break;
            }
            a = b.xyz;
        }
        if (!hit) {
            atomicAdd(&ray_split[RAYS_LEAVING], q);
            return;
        }
        var t0 = 0.0;
        var t1 = h;
        for (var it = 0; it < 4; it++) {
            let tm = c_half() * (t0 + t1);
            let m = ray_in_box(along(a, d, tm));
            if (m.w != 0.0 && ray_value(m.xyz) >= 0.5) {
                t1 = tm;
            } else {
                t0 = tm;
            }
        }
        var bp = ray_in_box(along(a, d, t1));
        if (bp.w == 0.0) { bp = vec4<f32>(a, 1.0); }
        let s = ray_surface(bp.xyz);
        let g = s.grad;
        // without a negated sum (lavapipe reassociates -(x + y + z)), and over
        // gg itself (it turns sqrt(x) * sqrt(x) into x)
        let gg = g.x * g.x + g.y * g.y + g.z * g.z;
        let len = sqrt(gg);
        let dg = d.x * g.x + d.y * g.y + d.z * g.z;
        var cosine = 1.0;
        if (len > 0.0) {
            cosine = abs(dg) / len;
        }
        let bin = bins[s.best];
        let absorbed = fresnel(bin.z / bin.x, bin.w / bin.x, cosine);
        var dq = min(u32(floor(f32(q) * absorbed + c_half())), q);
        if (bounce + 1u == P.laser.max_bounces) {
            atomicAdd(&ray_split[RAYS_AT_LIMIT], q - dq);
            dq = q;
        }
        if (dq > 0u) {
            atomicAdd(&ray_counts[s.best], dq);
            atomicAdd(&ray_split[RAYS_ABSORBED], dq);
        }
        q = q - dq;
        if (q == 0u) { return; }
        // from half a bin off the surface on the ray's side (cpu/laser.rs
        // says why), or the last point found outside
        let xo = ray_in_box(along(a, d, t0));
        x = select(a, xo.xyz, xo.w != 0.0);
        var off = back(bp.xyz, d, c_half() * P.laser.bin_size);
        var rf = vec3<f32>(-d.x, -d.y, -d.z);
        if (len > 0.0) {
            let k = c_half() * P.laser.bin_size / len;
            if (dg > 0.0) {
                off = back(bp.xyz, g, k);
            } else {
                off = along(bp.xyz, g, k);
            }
            rf = back(d, g, c_two() * dg / gg);
        }
        let ob = ray_in_box(off);
        if (ob.w != 0.0 && ray_value(ob.xyz) < 0.5) {
            x = ob.xyz;
        }
        let rl = sqrt(rf.x * rf.x + rf.y * rf.y + rf.z * rf.z);
        d = vec3<f32>(rf.x / rl, rf.y / rl, rf.z / rl);
    }
}

// Each bin's absorbed power from its count.
@compute @workgroup_size(64)
fn laser_ray_bins(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let b = thread_index(gid, nwg);
    if (b >= n_bins()) { return; }
    bins[b].y = f32(atomicLoad(&ray_counts[b])) * P.laser.power_unit;
}
