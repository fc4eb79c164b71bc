// uses: params
// reads: cell_start cell_end sim
// Thread indexing, the cell grid and the neighbour walk's helpers. Twin of
// src/backend/cpu/neighbors/grid.rs and walks.rs. The walk itself is written once, as the
// #for_each_neighbor template (src/backend/gpu/shaders.rs expands it).

// Linear thread index for 1D work split over a 2D dispatch grid (65535-group limit).
fn thread_index(gid: vec3<u32>, nwg: vec3<u32>) -> u32 {
    return gid.x + gid.y * nwg.x * WG;
}

// Particles still in the simulation: the removed ones sit after them, sorted
// last by the neighbour pass; every other pass stops here.
fn active_particles() -> u32 {
    return P.sizes.n_particles - sim.removed;
}

// Outside the box a particle must stay in: it has left.
fn outside_keep_box(p: vec4<f32>) -> bool {
    let lo = P.grid.keep_lo;
    let hi = P.grid.keep_hi;
    return p.x < lo.x || p.x > hi.x || p.y < lo.y || p.y > hi.y || p.z < lo.z || p.z > hi.z;
}

// A fluid particle that has just left the keep box carries the time it left in
// w; the neighbour pass then sorts it last and the passes stop before it (issue
// 18). Walls are never removed.
fn stamp_if_left(x: vec4<f32>) -> vec4<f32> {
    var y = x;
    if (outside_keep_box(x)) {
        y.w = sim.time + sim.dt;
    }
    return y;
}

// Brings coordinate x of axis c back into [0, period) on a periodic axis.
fn wrap_periodic(x: f32, c: u32) -> f32 {
    if ((P.sizes.flags & (1u << c)) != 0u) {
        if (x >= P.grid.period[c]) {
            return x - P.grid.period[c];
        } else if (x < 0.0) {
            return x + P.grid.period[c];
        }
    }
    return x;
}

fn cell_coord(p: vec4<f32>) -> vec3<i32> {
    var c: vec3<i32>;
    for (var a = 0u; a < 3u; a++) {
        let f = floor(p[a] * P.grid.cell_inv[a]);
        c[a] = clamp(i32(f), 0, i32(P.grid.cells[a]) - 1);
    }
    return c;
}

fn cell_index(c: vec3<i32>) -> u32 {
    return u32(c.x) + P.grid.cells.x * (u32(c.y) + P.grid.cells.y * u32(c.z));
}

// Cell coordinate c on axis a, wrapped on periodic axes; -1 when outside the grid.
fn wrap_cell(c: i32, a: u32) -> i32 {
    let n = i32(P.grid.cells[a]);
    if (c >= 0 && c < n) { return c; }
    if ((P.sizes.flags & (1u << a)) != 0u) { return (c + n) % n; }
    return -1;
}

// Index of neighbour cell ci + off (wrapped on periodic axes), -1 outside the grid.
fn neighbor_cell_index(ci: vec3<i32>, off: vec3<i32>) -> i32 {
    let cx = wrap_cell(ci.x + off.x, 0u);
    let cy = wrap_cell(ci.y + off.y, 1u);
    let cz = wrap_cell(ci.z + off.z, 2u);
    if (cx < 0 || cy < 0 || cz < 0) { return -1; }
    return cx + i32(P.grid.cells.x) * (cy + i32(P.grid.cells.y) * cz);
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
    if ((P.sizes.flags & 1u) != 0u) { return 3u; }
    return 1u;
}

fn row_segment(ci: vec3<i32>, dy: i32, dz: i32, seg: u32) -> vec2<u32> {
    if ((P.sizes.flags & 1u) != 0u) {
        return neighbor_cell(ci, vec3<i32>(i32(seg) - 1, dy, dz));
    }
    let c = neighbor_cell_index(ci, vec3<i32>(0, dy, dz));
    if (c < 0) { return vec2<u32>(0u, 0u); }
    let first = u32(c) - select(0u, 1u, ci.x > 0);
    let last = u32(c) + select(0u, 1u, ci.x + 1 < i32(P.grid.cells.x));
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
        if ((P.sizes.flags & (1u << a)) != 0u) {
            if (d[a] > P.grid.half_period[a]) {
                d[a] = d[a] - P.grid.period[a];
            } else if (d[a] < -P.grid.half_period[a]) {
                d[a] = d[a] + P.grid.period[a];
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
    return select(0, 1, P.sizes.dim == 3u);
}
