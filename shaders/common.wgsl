// Shared by every pass: the parameter block, all bindings, kernel functions and
// neighbour-cell helpers. Twin of src/params.rs, src/kernel.rs and
// src/backend/cpu/neighbors.rs. Bit-match rules (DESIGN.md): same operation order
// as the Rust twin, no fma, no built-in transcendentals, explicit x*x+y*y+z*z.

struct Params {
    counts: vec4<u32>,       // n, n_cells, dim, kernel
    grid: vec4<u32>,         // nx, ny, nz, flags
    cell_inv: vec4<f32>,
    period: vec4<f32>,
    half_period: vec4<f32>,
    kern: vec4<f32>,         // h, 1/h, sigma, support²
    gravity: vec4<f32>,      // g, background pressure
    dtp: vec4<f32>,          // h, c_max, viscous limit, fixed dt
    phase_a: array<vec4<f32>, 8>, // rho0, c², eta, kind
    phase_b: array<vec4<f32>, 8>, // wall velocity, slip
    phase_c: array<vec4<f32>, 8>, // heat: k, c_p, h_solidus, h_liquidus
    phase_d: array<vec4<f32>, 8>, // heat: T_solidus, T_liquidus, L, flags
    phase_e: array<vec4<f32>, 8>, // evaporation: C_p, C_T, 1/T_v, h_v
    phase_f: array<vec4<f32>, 8>, // T_h0, C_M, 0.82 c_s, emissivity * sigma_B
    phase_g: array<vec4<f32>, 8>, // mushy-zone sink C (1/s), unused
    heat: vec4<f32>,              // conduction dt limit, eta², heat scene (1/0), unused
    laser: vec4<f32>,             // absorptivity, beam radius, absorption coefficient, model
    iface: vec4<f32>,             // interface pass: 1/kappa, T_ambient^4, F22 gas mode (1/0), alpha_0^lg
    laser_grid: vec4<f32>,        // bin size, peak irradiance per watt, bin volume, column area
    laser_bins: vec4<u32>,        // bins per axis, path points + 256 * power steps
    laser_lo: vec4<f32>,          // bin grid lower corner (grid-relative)
    laser_path: array<vec4<f32>, 8>,  // time, lateral beam centre
    laser_power: array<vec4<f32>, 8>, // time, power from then on
    consts: array<vec4<f32>, 8>,  // arithmetic literals, see c_* below
    wall: vec4<f32>,              // wall pass: Shepard weight floor; moving wall phases (bit mask)
}

struct Sim {
    dt: f32,
    time: f32,
    step: u32,
    dt_limit: u32,
    umax2: f32,
    amax2: f32,
    pad0: u32,
    pad1: u32,
}

const FLAG_PRESSURE_FLOOR: u32 = 8u;
const FLAG_VISCOUS_HEATING: u32 = 16u;
const KIND_WALL: f32 = 2.0;
const KIND_SOLID: f32 = 3.0;
const HEAT_DIRICHLET: u32 = 1u;
const HEAT_MELTS: u32 = 2u;
const HEAT_LIQUID: u32 = 4u;
const WG: u32 = 64u;

@group(0) @binding(0) var<uniform> P: Params;
@group(0) @binding(1) var<storage, read_write> pos: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read_write> vel: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> acc: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read_write> acc_b: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read_write> rho: array<f32>;
@group(0) @binding(6) var<storage, read_write> press: array<f32>;
@group(0) @binding(7) var<storage, read_write> mass: array<f32>;
@group(0) @binding(8) var<storage, read_write> phase: array<u32>;
@group(0) @binding(9) var<storage, read_write> pid: array<u32>;
@group(0) @binding(10) var<storage, read_write> keys: array<vec2<u32>>;
@group(0) @binding(11) var<storage, read_write> cell_start: array<u32>;
@group(0) @binding(12) var<storage, read_write> cell_end: array<u32>;
@group(0) @binding(13) var<storage, read_write> s_pos: array<vec4<f32>>;
@group(0) @binding(14) var<storage, read_write> s_vel: array<vec4<f32>>;
@group(0) @binding(15) var<storage, read_write> s_acc: array<vec4<f32>>;
@group(0) @binding(16) var<storage, read_write> s_acc_b: array<vec4<f32>>;
@group(0) @binding(17) var<storage, read_write> s_mass: array<f32>;
@group(0) @binding(18) var<storage, read_write> s_phase: array<u32>;
@group(0) @binding(19) var<storage, read_write> s_pid: array<u32>;
@group(0) @binding(20) var<storage, read_write> sim: Sim;
@group(0) @binding(21) var<storage, read_write> partials: array<vec2<f32>>;
// Heat scenes: (h, T, f_l, dh/dt) and its reorder scratch; a 16-byte placeholder
// otherwise (no heat pass is dispatched).
@group(0) @binding(22) var<storage, read_write> heat: array<vec4<f32>>;
@group(0) @binding(23) var<storage, read_write> s_heat: array<vec4<f32>>;
// Laser scenes: per bin (sum of w V, absorbed power); a placeholder otherwise.
@group(0) @binding(24) var<storage, read_write> bins: array<vec2<f32>>;
// Interface scenes: (normal, delta) per particle, then the Shepard sums; a
// placeholder otherwise.
@group(0) @binding(25) var<storage, read_write> surface: array<vec4<f32>>;
// 1 where a cell holds a fluid particle (set in cell_bounds; the wall pass skips
// wall particles with no such cell around them). Order-free integer atomics.
@group(0) @binding(26) var<storage, read_write> cell_fluid: array<atomic<u32>>;

// Linear thread index for 1D work split over a 2D dispatch grid (65535-group limit).
fn thread_index(gid: vec3<u32>, nwg: vec3<u32>) -> u32 {
    return gid.x + gid.y * nwg.x * WG;
}

// Wall or solid: does not move, is a wall for the fluid passes.
fn is_wall(ph: u32) -> bool {
    return P.phase_a[ph].w >= KIND_WALL;
}

// A wall phase whose particles move with its velocity (phase_b.xyz).
fn wall_moves(ph: u32) -> bool {
    return ((u32(P.wall.y) >> ph) & 1u) != 0u;
}

// Carries an evolving temperature: liquid, gas or solid in a heat scene.
fn conducts(ph: u32) -> bool {
    return P.heat.z != 0.0 && P.phase_a[ph].w != KIND_WALL;
}

fn heat_flags(ph: u32) -> u32 {
    return u32(P.phase_d[ph].w);
}

// Arithmetic literals come from the uniform block, never from the source:
// lavapipe's compiler reassociates a literal times a product (6.0 * (a * a) differs
// from the Rust twin in 10% of inputs), while a runtime value is left alone.
// Comparisons and max/min with literals are exact and stay literal.
fn c_half() -> f32 { return P.consts[0].x; }
fn c_quarter() -> f32 { return P.consts[0].y; }
fn c_two() -> f32 { return P.consts[0].z; }
fn c_one() -> f32 { return P.consts[0].w; }
fn c_three() -> f32 { return P.consts[1].x; }
fn c_six() -> f32 { return P.consts[1].y; }
fn c_fifteen() -> f32 { return P.consts[1].z; }
fn c_five() -> f32 { return P.consts[1].w; }
fn c_thirty() -> f32 { return P.consts[2].x; }
fn c_seventy_five() -> f32 { return P.consts[2].y; }
fn c_one_and_half() -> f32 { return P.consts[2].z; }
fn c_three_quarters() -> f32 { return P.consts[2].w; }
fn c_nine_quarters() -> f32 { return P.consts[3].x; }
fn c_four() -> f32 { return P.consts[6].w; }
fn c_tenth() -> f32 { return P.consts[7].x; }

fn p4(t: f32) -> f32 { return t * t * t * t; }
fn p5(t: f32) -> f32 { return t * t * t * t * t; }

fn kernel_w(r: f32) -> f32 {
    let sigma = P.kern.z;
    let q = r * P.kern.y;
    switch P.counts.w {
        case 0u: {
            let t1 = max(c_one() - q, 0.0);
            let t2 = max(c_two() - q, 0.0);
            let t3 = max(c_three() - q, 0.0);
            return sigma * (p5(t3) - c_six() * p5(t2) + c_fifteen() * p5(t1));
        }
        case 1u: {
            let t = max(c_one() - c_half() * q, 0.0);
            return sigma * p4(t) * (c_two() * q + c_one());
        }
        default: {
            if (q < 1.0) {
                return sigma * (c_one() - c_one_and_half() * q * q + c_three_quarters() * q * q * q);
            } else if (q < 2.0) {
                let t = c_two() - q;
                return sigma * c_quarter() * t * t * t;
            }
            return 0.0;
        }
    }
}

// Negated literals are written as the exact negation of a product, so the operation
// order matches the Rust twin's `-5.0 * x`.
fn kernel_dw(r: f32) -> f32 {
    let sigma_h = P.kern.z * P.kern.y;
    let q = r * P.kern.y;
    switch P.counts.w {
        case 0u: {
            let t1 = max(c_one() - q, 0.0);
            let t2 = max(c_two() - q, 0.0);
            let t3 = max(c_three() - q, 0.0);
            return sigma_h * (-(c_five() * p4(t3)) + c_thirty() * p4(t2) - c_seventy_five() * p4(t1));
        }
        case 1u: {
            let t = max(c_one() - c_half() * q, 0.0);
            return sigma_h * (-(c_five() * q) * t * t * t);
        }
        default: {
            if (q < 1.0) {
                return sigma_h * (-(c_three() * q) + c_nine_quarters() * q * q);
            } else if (q < 2.0) {
                let t = c_two() - q;
                return sigma_h * (-(c_three_quarters() * t) * t);
            }
            return 0.0;
        }
    }
}

fn cell_coord(p: vec4<f32>) -> vec3<i32> {
    var c: vec3<i32>;
    for (var a = 0u; a < 3u; a++) {
        let f = floor(p[a] * P.cell_inv[a]);
        c[a] = clamp(i32(f), 0, i32(P.grid[a]) - 1);
    }
    return c;
}

fn cell_index(c: vec3<i32>) -> u32 {
    return u32(c.x) + P.grid.x * (u32(c.y) + P.grid.y * u32(c.z));
}

// Cell coordinate c on axis a, wrapped on periodic axes; -1 when outside the grid.
fn wrap_cell(c: i32, a: u32) -> i32 {
    let n = i32(P.grid[a]);
    if (c >= 0 && c < n) { return c; }
    if ((P.grid.w & (1u << a)) != 0u) { return (c + n) % n; }
    return -1;
}

// Index of neighbour cell ci + off (wrapped on periodic axes), -1 outside the grid.
fn neighbor_cell_index(ci: vec3<i32>, off: vec3<i32>) -> i32 {
    let cx = wrap_cell(ci.x + off.x, 0u);
    let cy = wrap_cell(ci.y + off.y, 1u);
    let cz = wrap_cell(ci.z + off.z, 2u);
    if (cx < 0 || cy < 0 || cz < 0) { return -1; }
    return cx + i32(P.grid.x) * (cy + i32(P.grid.y) * cz);
}

// Start and end of the sorted particles in neighbour cell ci + off (empty if outside).
fn neighbor_cell(ci: vec3<i32>, off: vec3<i32>) -> vec2<u32> {
    let c = neighbor_cell_index(ci, off);
    if (c < 0) { return vec2<u32>(0u, 0u); }
    return vec2<u32>(cell_start[u32(c)], cell_end[u32(c)]);
}

// The neighbour loops visit each (dy, dz) row of cells as segments of sorted
// particles. Without x-periodicity the row's cells ci.x-1..ci.x+1 (clipped to the
// grid) have consecutive indices, so their particles are one run of the sorted
// order: one segment, holding the same particles in the same order as the cell-by-
// cell walk of the CPU twin (so sums stay bit-identical), with one loop instead of
// three. A periodic x axis can wrap a cell out of the run: then one segment per cell.
fn row_segments() -> u32 {
    if ((P.grid.w & 1u) != 0u) { return 3u; }
    return 1u;
}

fn row_segment(ci: vec3<i32>, dy: i32, dz: i32, seg: u32) -> vec2<u32> {
    if ((P.grid.w & 1u) != 0u) {
        return neighbor_cell(ci, vec3<i32>(i32(seg) - 1, dy, dz));
    }
    let c = neighbor_cell_index(ci, vec3<i32>(0, dy, dz));
    if (c < 0) { return vec2<u32>(0u, 0u); }
    let first = u32(c) - select(0u, 1u, ci.x > 0);
    let last = u32(c) + select(0u, 1u, ci.x + 1 < i32(P.grid.x));
    // From the first non-empty cell's start to the last non-empty cell's end.
    var run = vec2<u32>(0u, 0u);
    var found = false;
    for (var k = first; k <= last; k++) {
        let s = cell_start[k];
        let e = cell_end[k];
        if (e > s) {
            if (!found) {
                run.x = s;
                found = true;
            }
            run.y = e;
        }
    }
    return run;
}

// d = r_i - r_j with the minimum image on periodic axes.
fn min_image(pi: vec4<f32>, pj: vec4<f32>) -> vec3<f32> {
    var d = vec3<f32>(pi.x - pj.x, pi.y - pj.y, pi.z - pj.z);
    for (var a = 0u; a < 3u; a++) {
        if ((P.grid.w & (1u << a)) != 0u) {
            if (d[a] > P.half_period[a]) {
                d[a] = d[a] - P.period[a];
            } else if (d[a] < -P.half_period[a]) {
                d[a] = d[a] + P.period[a];
            }
        }
    }
    return d;
}

fn len2(d: vec3<f32>) -> f32 {
    return d.x * d.x + d.y * d.y + d.z * d.z;
}

// Neighbour cells are visited dz, dy, dx from -1 to 1; in 2D only dz = 0.
fn z_range() -> i32 {
    return select(0, 1, P.counts.z == 3u);
}
