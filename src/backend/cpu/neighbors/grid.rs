//! The cell grid: the cell table the sort builds, cell coordinates and keys,
//! the cells around a point in the walks' fixed order, and the minimum image
//! on periodic axes.

use crate::params::Params;
use std::sync::atomic::{AtomicU64, Ordering};

/// Source of `CellTable::generation`: unique across every table in the process, so
/// a thread's candidate cache can never mistake one backend's table for another's.
pub(super) static GENERATION: AtomicU64 = AtomicU64::new(1);

#[derive(Default)]
pub struct CellTable {
    pub start: Vec<u32>,
    pub end: Vec<u32>,
    /// The cell holds at least one fluid particle (the wall pass skips wall
    /// particles with no such cell around them).
    pub fluid: Vec<bool>,
    /// Changes whenever the table is rebuilt or the positions it indexes are
    /// replaced (`invalidate`); 0 = never built.
    pub generation: u64,
    /// The last sort's (cell, particle) keys and permutation, kept so that the
    /// next sort reuses their memory (fresh arrays are cleared page by page).
    pub(super) keys: Vec<(u32, u32)>,
    pub(super) perm: Vec<usize>,
}

impl CellTable {
    /// The positions changed without a rebuild (a state was loaded): cached
    /// candidates of the old positions must not be used.
    pub fn invalidate(&mut self) {
        self.generation = GENERATION.fetch_add(1, Ordering::Relaxed);
    }
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
pub(super) fn for_each_cell(pr: &Params, pi: &[f32; 4], mut f: impl FnMut(usize) -> bool) -> bool {
    let ci = cell_coord(pr, pi);
    let zr = if pr.sizes.dim == 3 { 1 } else { 0 };
    let flags = pr.sizes.flags;
    for dz in -zr..=zr {
        let Some(cz) = wrap(ci[2] + dz, pr.grid.cells[2], flags & 4 != 0) else {
            continue;
        };
        for dy in -1..=1 {
            let Some(cy) = wrap(ci[1] + dy, pr.grid.cells[1], flags & 2 != 0) else {
                continue;
            };
            for dx in -1..=1 {
                let Some(cx) = wrap(ci[0] + dx, pr.grid.cells[0], flags & 1 != 0) else {
                    continue;
                };
                if !f((cx + pr.grid.cells[0] * (cy + pr.grid.cells[1] * cz)) as usize) {
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
        c[a] = floor_to_i32(p[a] * pr.grid.cell_inv[a]).clamp(0, pr.grid.cells[a] as i32 - 1);
    }
    c
}

/// `x.floor() as i32` (saturating, 0 for a NaN) without `floorf`: without
/// SSE4.1 in the target, `floor` is a library call, and the cell coordinates of
/// every candidate gather and sort key took 4% of a step. Truncation, then one
/// less where it rounded up (a negative non-integer).
#[inline(always)]
pub(super) fn floor_to_i32(x: f32) -> i32 {
    let t = x as i32;
    t.saturating_sub((t as f32 > x) as i32)
}

#[inline(always)]
pub fn cell_index(pr: &Params, c: [i32; 3]) -> u32 {
    c[0] as u32 + pr.grid.cells[0] * (c[1] as u32 + pr.grid.cells[1] * c[2] as u32)
}

/// d = a − b with the minimum image on periodic axes.
#[inline(always)]
pub fn min_image(pr: &Params, a: [f32; 4], b: [f32; 4]) -> [f32; 3] {
    let mut d = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    for k in 0..3 {
        if pr.sizes.flags & (1 << k) != 0 {
            d[k] = wrap_axis(d[k], pr.grid.half_period[k], pr.grid.period[k]);
        }
    }
    d
}

/// One component of a difference brought into (−period/2, period/2]: the minimum
/// image on a periodic axis (a select, so a sweep of it vectorises).
#[inline(always)]
pub(super) fn wrap_axis(d: f32, half: f32, period: f32) -> f32 {
    if d > half {
        d - period
    } else if d < -half {
        d + period
    } else {
        d
    }
}

#[inline(always)]
pub(super) fn wrap(c: i32, n: u32, periodic: bool) -> Option<u32> {
    let n = n as i32;
    if c >= 0 && c < n {
        Some(c as u32)
    } else if periodic {
        Some(((c + n) % n) as u32)
    } else {
        None
    }
}

/// The cell a particle sorts into; n_cells, after every cell and in none, for
/// one that has left the domain: a fluid particle outside the keep
/// box, or a wall-kind particle stamped with the time it left (a member of a
/// rigid body that left, `bodies::place`; it may stand anywhere, its body's
/// centre is past the face). Other walls stay wherever they stand (those of a
/// closed side reach past the open face above it).
#[inline(always)]
pub(super) fn cell_key(pr: &Params, p: &[f32; 4], phase: u32) -> u32 {
    let gone = if pr.is_wall(phase) {
        p[3] > 0.0
    } else {
        pr.outside_keep_box(p)
    };
    if gone {
        pr.sizes.n_cells
    } else {
        cell_index(pr, cell_coord(pr, p))
    }
}
