//! Twin of shaders/neighbors.wgsl: cell keys, the (cell, index) sort, reordering of
//! every particle array by cell, and the cell start/end table.
//! Keys are unique, so any correct sort gives the one order the GPU's bitonic sort gives.

use crate::params::Params;
use crate::state::State;
use rayon::prelude::*;

#[derive(Default)]
pub struct CellTable {
    pub start: Vec<u32>,
    pub end: Vec<u32>,
    /// The cell holds at least one fluid particle (the wall pass skips wall
    /// particles with no such cell around them).
    pub fluid: Vec<bool>,
}

/// True if any cell the neighbour loop of point `pi` visits holds fluid.
#[inline(always)]
pub fn fluid_nearby(pr: &Params, grid: &CellTable, pi: &[f32; 4]) -> bool {
    !for_each_cell(pr, pi, |c| !grid.fluid[c])
}

/// Visit the cells the neighbour loop of point `pi` covers, in its fixed order
/// (dz, dy, dx from −1 to 1; wrapped on periodic axes, skipped outside the grid),
/// until `f` returns false. Returns false if it stopped early.
#[inline(always)]
fn for_each_cell(pr: &Params, pi: &[f32; 4], mut f: impl FnMut(usize) -> bool) -> bool {
    let ci = cell_coord(pr, pi);
    let zr = if pr.counts[2] == 3 { 1 } else { 0 };
    let flags = pr.grid[3];
    for dz in -zr..=zr {
        let Some(cz) = wrap(ci[2] + dz, pr.grid[2], flags & 4 != 0) else {
            continue;
        };
        for dy in -1..=1 {
            let Some(cy) = wrap(ci[1] + dy, pr.grid[1], flags & 2 != 0) else {
                continue;
            };
            for dx in -1..=1 {
                let Some(cx) = wrap(ci[0] + dx, pr.grid[0], flags & 1 != 0) else {
                    continue;
                };
                if !f((cx + pr.grid[0] * (cy + pr.grid[1] * cz)) as usize) {
                    return false;
                }
            }
        }
    }
    true
}

/// Integer cell coordinates of a position, clamped into the grid.
#[inline(always)]
pub fn cell_coord(pr: &Params, p: &[f32; 4]) -> [i32; 3] {
    let mut c = [0i32; 3];
    for a in 0..3 {
        let f = (p[a] * pr.cell_inv[a]).floor();
        c[a] = (f as i32).clamp(0, pr.grid[a] as i32 - 1);
    }
    c
}

#[inline(always)]
pub fn cell_index(pr: &Params, c: [i32; 3]) -> u32 {
    c[0] as u32 + pr.grid[0] * (c[1] as u32 + pr.grid[1] * c[2] as u32)
}

/// Visit every neighbour j of particle i with r_ij² < support², in the fixed order
/// the WGSL loop uses: cells by dz, dy, dx from -1 to 1, particles in sorted order.
/// `f(j, d, r2)` gets d = r_i − r_j (minimum image on periodic axes).
#[inline(always)]
pub fn for_each_neighbor(
    pr: &Params,
    pos: &[[f32; 4]],
    grid: &CellTable,
    i: usize,
    f: impl FnMut(usize, [f32; 3], f32),
) {
    for_each_near(pr, pos, grid, pos[i], f);
}

/// Visit every particle j within the support of point `pi`, in the same order as
/// `for_each_neighbor`; `f(j, d, r2)` gets d = pi − r_j (minimum image).
#[inline(always)]
pub fn for_each_near(
    pr: &Params,
    pos: &[[f32; 4]],
    grid: &CellTable,
    pi: [f32; 4],
    mut f: impl FnMut(usize, [f32; 3], f32),
) {
    for_each_cell(pr, &pi, |c| {
        for j in grid.start[c] as usize..grid.end[c] as usize {
            let d = min_image(pr, pi, pos[j]);
            let r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
            if r2 < pr.kernel[3] {
                f(j, d, r2);
            }
        }
        true
    });
}

/// d = a − b with the minimum image on periodic axes.
#[inline(always)]
pub fn min_image(pr: &Params, a: [f32; 4], b: [f32; 4]) -> [f32; 3] {
    let mut d = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    for k in 0..3 {
        if pr.grid[3] & (1 << k) != 0 {
            if d[k] > pr.half_period[k] {
                d[k] -= pr.period[k];
            } else if d[k] < -pr.half_period[k] {
                d[k] += pr.period[k];
            }
        }
    }
    d
}

#[inline(always)]
fn wrap(c: i32, n: u32, periodic: bool) -> Option<u32> {
    let n = n as i32;
    if c >= 0 && c < n {
        Some(c as u32)
    } else if periodic {
        Some(((c + n) % n) as u32)
    } else {
        None
    }
}

pub fn run(pr: &Params, st: &mut State, grid: &mut CellTable) {
    let n = st.len();
    let mut keys: Vec<(u32, u32)> = st
        .pos
        .par_iter()
        .enumerate()
        .map(|(i, p)| (cell_index(pr, cell_coord(pr, p)), i as u32))
        .collect();
    keys.par_sort_unstable();
    let perm: Vec<usize> = keys.iter().map(|k| k.1 as usize).collect();
    permute(&mut st.pos, &perm);
    permute(&mut st.vel, &perm);
    permute(&mut st.acc, &perm);
    permute(&mut st.acc_b, &perm);
    permute(&mut st.mass, &perm);
    permute(&mut st.phase, &perm);
    permute(&mut st.id, &perm);
    if !st.heat.is_empty() {
        permute(&mut st.heat, &perm);
    }
    let n_cells = pr.counts[1] as usize;
    grid.start.clear();
    grid.start.resize(n_cells, 0);
    grid.end.clear();
    grid.end.resize(n_cells, 0);
    grid.fluid.clear();
    grid.fluid.resize(n_cells, false);
    for k in 0..n {
        let c = keys[k].0;
        if k == 0 || keys[k - 1].0 != c {
            grid.start[c as usize] = k as u32;
        }
        if k == n - 1 || keys[k + 1].0 != c {
            grid.end[c as usize] = k as u32 + 1;
        }
        if !pr.is_wall(st.phase[k]) {
            grid.fluid[c as usize] = true;
        }
    }
}

fn permute<T: Copy + Send + Sync>(v: &mut Vec<T>, perm: &[usize]) {
    let src = &*v;
    let out: Vec<T> = perm.par_iter().map(|&s| src[s]).collect();
    *v = out;
}
