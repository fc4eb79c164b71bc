//! Twin of shaders/neighbors.wgsl: cell keys, the (cell, index) sort, reordering of
//! every particle array by cell, the cell start/end table and the count of
//! particles that have left (sorted last, in no cell).
//! Keys are unique, so any correct sort gives the one order the GPU's bitonic sort gives.

use super::recorded::{Entry, RecordChunk, Recorded};
use crate::fields::{Held, FIELDS};
use crate::model::MAX_PHASES;
use crate::params::Params;
use crate::state::State;
use rayon::prelude::*;
use std::cell::RefCell;
use std::sync::atomic::{AtomicU64, Ordering};

/// Source of `CellTable::generation`: unique across every table in the process, so
/// a thread's candidate cache can never mistake one backend's table for another's.
static GENERATION: AtomicU64 = AtomicU64::new(1);

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
    keys: Vec<(u32, u32)>,
    perm: Vec<usize>,
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
fn for_each_cell(pr: &Params, pi: &[f32; 4], mut f: impl FnMut(usize) -> bool) -> bool {
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
fn floor_to_i32(x: f32) -> i32 {
    let t = x as i32;
    t.saturating_sub((t as f32 > x) as i32)
}

#[inline(always)]
pub fn cell_index(pr: &Params, c: [i32; 3]) -> u32 {
    c[0] as u32 + pr.grid.cells[0] * (c[1] as u32 + pr.grid.cells[1] * c[2] as u32)
}

/// Visit every neighbour j of particle i with r_ij² < support², in the fixed order
/// the WGSL loop uses: cells by dz, dy, dx from -1 to 1, particles in sorted order.
/// `f(j, d, r2)` gets d = r_i − r_j (minimum image on periodic axes).
///
/// Same pairs, same order and same arithmetic as `for_each_near(pos[i])`, but the
/// candidates of i's cell neighbourhood are gathered once per cell into a
/// per-thread structure-of-arrays copy, and the distance test runs over it as a
/// branch-free, vectorisable sweep. Particles are sorted by cell, so a thread's
/// consecutive particles share that copy; the walk per particle and the
/// mispredicted branch per candidate (about 15% of candidates are neighbours) were
/// most of the density pass.
#[inline(always)]
pub fn for_each_neighbor(
    pr: &Params,
    pos: &[[f32; 4]],
    grid: &CellTable,
    i: usize,
    f: impl FnMut(usize, [f32; 3], f32),
) {
    for_each_neighbor_among(pr, pos, grid, i, Among::All, f)
}

/// Which particles of a cell neighbourhood a sweep visits.
#[derive(Clone, Copy)]
pub enum Among<'a> {
    All,
    /// The particles whose phase p has bit p set in `mask`, as `phase` holds
    /// them during one pass. `token` is unique to that pass, so that a thread's
    /// cached copy of these candidates never outlives a phase change (melting)
    /// under the same cell table.
    Phases {
        phase: &'a [u32],
        mask: u32,
        token: u64,
    },
}

impl<'a> Among<'a> {
    /// The particles of the phases `keep` selects, for one pass.
    pub fn phases(phase: &'a [u32], keep: impl Fn(u32) -> bool) -> Self {
        let mask = (0..MAX_PHASES as u32)
            .filter(|&p| keep(p))
            .fold(0, |m, p| m | 1 << p);
        let token = GENERATION.fetch_add(1, Ordering::Relaxed);
        Among::Phases { phase, mask, token }
    }
}

/// `for_each_neighbor` over the particles `among` selects: the same of them,
/// in the same order, with the same d and r², as `for_each_neighbor` gives
/// them. The selection is made when a cell neighbourhood's candidates are
/// gathered, so the distance sweep of each particle runs over fewer of them
/// (for the wall pass, which wants fluid neighbours only, about half).
#[inline(always)]
pub fn for_each_neighbor_among(
    pr: &Params,
    pos: &[[f32; 4]],
    grid: &CellTable,
    i: usize,
    among: Among,
    mut f: impl FnMut(usize, [f32; 3], f32),
) {
    with_candidates(|near| {
        near.sweep(pr, pos, grid, pos[i], among);
        for k in 0..near.count {
            let c = near.hits[k] as usize;
            f(
                near.j[c] as usize,
                [near.dx[c], near.dy[c], near.dz[c]],
                near.r2[c],
            );
        }
    });
}

/// `f` gets the index j and r_ij² of every neighbour j of particle i
/// (r_ij² < support²), in `for_each_neighbor`'s order, as two slices.
#[inline(always)]
pub fn with_neighbors<R>(
    pr: &Params,
    pos: &[[f32; 4]],
    grid: &CellTable,
    i: usize,
    f: impl FnOnce(&[u32], &[f32]) -> R,
) -> R {
    with_candidates(|near| {
        #[cfg(target_arch = "x86_64")]
        if *AVX2 && pr.sizes.flags & 7 == 0 {
            near.gather(pr, pos, grid, &pos[i], Among::All);
            // SAFETY: the CPU has AVX-512F, or AVX2 (checked once at run time).
            let count = unsafe {
                if *AVX512 {
                    near.neighbours_avx512(pr, pos[i])
                } else {
                    near.neighbours_avx2(pr, pos[i])
                }
            };
            return f(&near.hit_j[..count], &near.hit_r2[..count]);
        }
        near.sweep(pr, pos, grid, pos[i], Among::All);
        let count = near.count;
        for k in 0..count {
            near.hit_j[k] = near.j[near.hits[k] as usize];
        }
        f(&near.hit_j[..count], &near.hit_r2[..count])
    })
}

/// Particles per chunk of the neighbour list (one parallel task each).
pub const LIST_CHUNK: usize = 1024;

/// A neighbour index: the list may take half the memory this machine has
/// free when it is first taken, before anything is recorded in it (4 bytes an
/// index), or 2^27 indices (512 MiB) where that is unknown (cpu/recorded.rs);
/// at 1e7 particles of dam_break_3d the list takes 2.6 GB and saves 27% of the
/// forces pass.
impl Entry for u32 {
    const MEMORY_SHARE: f64 = 0.5;
    const BYTES: usize = 4;
    const UNKNOWN_BOUND: usize = 1 << 27;
}

/// The neighbours of every fluid particle, recorded by the density pass in the
/// walk's order, so that the forces pass of the same step reads them instead of
/// sweeping the cells again. Valid for one cell table (`CellTable::generation`).
pub type NeighborList = Recorded<u32>;

/// The neighbours of particles c·LIST_CHUNK .. (c+1)·LIST_CHUNK (none for a
/// wall particle).
pub type ListChunk = RecordChunk<u32>;

/// Particle i's recorded neighbours; None without a list for this cell table,
/// or for a particle the list holds none of (a wall: every fluid particle's
/// entry holds at least itself).
fn listed<'a>(list: &'a NeighborList, grid: &CellTable, i: usize) -> Option<&'a [u32]> {
    list.entries(grid, i).filter(|js| !js.is_empty())
}

/// `for_each_neighbor`, read from the step's neighbour list when it holds the
/// particle's neighbours for this cell table (a fluid particle's): the same j in the same order, with d and
/// r² recomputed by `min_image` and the same sum, so the same bits. Without a list
/// the particle's neighbours are swept into a per-thread scratch list first, so
/// that `f` is called from one loop only: the compiler then inlines it and keeps
/// its sums in registers (forces pass on the peer scene: 16% faster).
#[inline(always)]
pub fn for_each_listed(
    pr: &Params,
    pos: &[[f32; 4]],
    grid: &CellTable,
    list: &NeighborList,
    i: usize,
    mut f: impl FnMut(usize, [f32; 3], f32),
) {
    with_listed(pr, pos, grid, list, i, |js| {
        let pi = pos[i];
        for &j in js {
            let j = j as usize;
            let d = min_image(pr, pi, pos[j]);
            let r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
            f(j, d, r2);
        }
    })
}

/// `f` gets the neighbours j of fluid particle i, in `for_each_listed`'s order,
/// as one slice: the step's list, or the cells swept into a per-thread scratch
/// list when the step has none.
#[inline(always)]
pub fn with_listed<R>(
    pr: &Params,
    pos: &[[f32; 4]],
    grid: &CellTable,
    list: &NeighborList,
    i: usize,
    f: impl FnOnce(&[u32]) -> R,
) -> R {
    if let Some(js) = listed(list, grid, i) {
        return f(js);
    }
    let mut js = SCRATCH.with(|s| s.take());
    with_neighbors(pr, pos, grid, i, |found, _| {
        js.clear();
        js.extend_from_slice(found);
    });
    let out = f(&js);
    SCRATCH.with(|s| s.replace(js));
    out
}

thread_local! {
    /// `for_each_listed`'s neighbours of one particle when the step has no list
    /// (taken while in use, so a nested call starts an empty one).
    static SCRATCH: RefCell<Vec<u32>> = const { RefCell::new(Vec::new()) };
}

thread_local! {
    static NEAR: RefCell<Candidates> = RefCell::new(Candidates::default());
}

/// Runs `f` on this thread's candidate cache, or on a fresh one when a caller up
/// the stack holds it (a neighbour callback that walks neighbours itself): the
/// same neighbours either way, the nested walk only slower.
#[inline(always)]
fn with_candidates<R>(f: impl FnOnce(&mut Candidates) -> R) -> R {
    NEAR.with(|near| match near.try_borrow_mut() {
        Ok(mut near) => f(&mut near),
        Err(_) => f(&mut Candidates::default()),
    })
}

/// The particles of one cell's neighbourhood in walk order (structure of arrays),
/// and the distances of the last swept point to them.
#[derive(Default)]
struct Candidates {
    /// (CellTable::generation, cell, 0 or `Among::Phases`'s token) the copy
    /// belongs to.
    key: (u64, usize, u64),
    j: Vec<u32>,
    x: Vec<f32>,
    y: Vec<f32>,
    z: Vec<f32>,
    dx: Vec<f32>,
    dy: Vec<f32>,
    dz: Vec<f32>,
    r2: Vec<f32>,
    /// Indices into the candidate arrays of those inside the support, in order,
    /// and their r².
    hits: Vec<u32>,
    hit_j: Vec<u32>,
    hit_r2: Vec<f32>,
    count: usize,
}

impl Candidates {
    fn gather(
        &mut self,
        pr: &Params,
        pos: &[[f32; 4]],
        grid: &CellTable,
        pi: &[f32; 4],
        among: Among,
    ) {
        let filter = match among {
            Among::All => 0,
            Among::Phases { token, .. } => token,
        };
        let cell = cell_index(pr, cell_coord(pr, pi)) as usize;
        let key = (grid.generation, cell, filter);
        if grid.generation != 0 && self.key == key {
            return;
        }
        self.key = key;
        self.j.clear();
        self.x.clear();
        self.y.clear();
        self.z.clear();
        for_each_cell(pr, pi, |c| {
            let (start, end) = (grid.start[c], grid.end[c]);
            match among {
                Among::All => {
                    let run = &pos[start as usize..end as usize];
                    self.j.extend(start..end);
                    self.x.extend(run.iter().map(|p| p[0]));
                    self.y.extend(run.iter().map(|p| p[1]));
                    self.z.extend(run.iter().map(|p| p[2]));
                }
                Among::Phases { phase, mask, .. } => {
                    for j in start..end {
                        if mask.checked_shr(phase[j as usize]).unwrap_or(0) & 1 != 0 {
                            let p = pos[j as usize];
                            self.j.push(j);
                            self.x.push(p[0]);
                            self.y.push(p[1]);
                            self.z.push(p[2]);
                        }
                    }
                }
            }
            true
        });
        let n = self.j.len();
        for v in [&mut self.dx, &mut self.dy, &mut self.dz, &mut self.r2] {
            v.resize(n, 0.0);
        }
        // Room past n for the whole-register stores of the compactions (a
        // register's lanes at a time, then the tail).
        self.hits.resize(n + WIDEST, 0);
        self.hit_j.resize(n + WIDEST, 0);
        self.hit_r2.resize(n + WIDEST, 0.0);
    }

    /// d = pi − r_j (minimum image) and r² for every candidate, then the in-order
    /// list of those with r² < support². The operations are `min_image`'s and
    /// `for_each_near`'s, so the bits are the same.
    #[inline(always)]
    fn sweep(
        &mut self,
        pr: &Params,
        pos: &[[f32; 4]],
        grid: &CellTable,
        pi: [f32; 4],
        among: Among,
    ) {
        self.gather(pr, pos, grid, &pi, among);
        #[cfg(target_arch = "x86_64")]
        if *AVX2 {
            // SAFETY: the CPU has AVX2 (checked once at run time).
            return unsafe { self.distances_avx2(pr, pi) };
        }
        self.distances(pr, pi);
    }

    /// `distances` compiled for AVX2: the same IEEE operations (Rust never fuses
    /// a multiply and an add), eight lanes at a time, and the compaction by
    /// left-packing (`compact_avx2`).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,popcnt")]
    unsafe fn distances_avx2(&mut self, pr: &Params, pi: [f32; 4]) {
        self.differences(pr, pi);
        let n = self.j.len();
        let (r2, support2) = (&self.r2[..n], pr.kernel.support2);
        // SAFETY: AVX2 is enabled here, AVX-512F where checked; hits and
        // hit_r2 hold n + WIDEST entries.
        self.count = unsafe {
            if *AVX512 {
                compact_avx512(r2, support2, &mut self.hits, &mut self.hit_r2)
            } else {
                compact_avx2(r2, support2, &mut self.hits, &mut self.hit_r2)
            }
        };
    }

    /// `with_neighbors` without periodic axes: j and r² of the candidates
    /// inside the support straight into hit_j and hit_r2, eight at a time, r²
    /// kept in registers (d is not stored: the callers want j and r² only).
    /// The same operations as `differences` (pi − x, then dx² + dy² + dz² in
    /// that order), so the same bits; returns the count.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,popcnt")]
    unsafe fn neighbours_avx2(&mut self, pr: &Params, pi: [f32; 4]) -> usize {
        use std::arch::x86_64::*;
        let n = self.j.len();
        let (x, y, z, j) = (&self.x[..n], &self.y[..n], &self.z[..n], &self.j[..n]);
        let (hit_j, hit_r2) = (&mut self.hit_j, &mut self.hit_r2);
        assert!(hit_j.len() >= n + 8 && hit_r2.len() >= n + 8);
        let support2 = pr.kernel.support2;
        let s2 = _mm256_set1_ps(support2);
        let (px, py, pz) = (
            _mm256_set1_ps(pi[0]),
            _mm256_set1_ps(pi[1]),
            _mm256_set1_ps(pi[2]),
        );
        let mut count = 0;
        let mut k = 0;
        while k + 8 <= n {
            // SAFETY: k + 8 <= n for the loads; count <= k, so the stores end
            // by n + 8.
            unsafe {
                let dx = _mm256_sub_ps(px, _mm256_loadu_ps(x.as_ptr().add(k)));
                let dy = _mm256_sub_ps(py, _mm256_loadu_ps(y.as_ptr().add(k)));
                let dz = _mm256_sub_ps(pz, _mm256_loadu_ps(z.as_ptr().add(k)));
                let r2 = _mm256_add_ps(
                    _mm256_add_ps(_mm256_mul_ps(dx, dx), _mm256_mul_ps(dy, dy)),
                    _mm256_mul_ps(dz, dz),
                );
                let mask = _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LT_OQ>(r2, s2)) as usize;
                let perm = _mm256_loadu_si256(LEFT_PACK[mask].as_ptr() as *const __m256i);
                let js = _mm256_loadu_si256(j.as_ptr().add(k) as *const __m256i);
                _mm256_storeu_si256(
                    hit_j.as_mut_ptr().add(count) as *mut __m256i,
                    _mm256_permutevar8x32_epi32(js, perm),
                );
                _mm256_storeu_ps(
                    hit_r2.as_mut_ptr().add(count),
                    _mm256_permutevar8x32_ps(r2, perm),
                );
                count += mask.count_ones() as usize;
            }
            k += 8;
        }
        while k < n {
            let d = [pi[0] - x[k], pi[1] - y[k], pi[2] - z[k]];
            let r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
            hit_j[count] = j[k];
            hit_r2[count] = r2;
            count += (r2 < support2) as usize;
            k += 1;
        }
        count
    }

    /// `neighbours_avx2` sixteen candidates at a time with AVX-512F: the
    /// same operations lane by lane, so the same r², and the hits packed in
    /// order by one compress each (j and r²); the tail is one masked block.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f,popcnt")]
    unsafe fn neighbours_avx512(&mut self, pr: &Params, pi: [f32; 4]) -> usize {
        use std::arch::x86_64::*;
        let n = self.j.len();
        let (x, y, z, j) = (&self.x[..n], &self.y[..n], &self.z[..n], &self.j[..n]);
        let (hit_j, hit_r2) = (&mut self.hit_j, &mut self.hit_r2);
        assert!(hit_j.len() >= n + 16 && hit_r2.len() >= n + 16);
        let s2 = _mm512_set1_ps(pr.kernel.support2);
        let p = pi.map(|c| _mm512_set1_ps(c));
        let mut count = 0;
        let mut k = 0;
        while k < n {
            // Lanes past n are not loaded (masked loads) and not selected.
            let lanes = lanes16(n - k);
            // SAFETY: the masked loads read lanes k..min(k + 16, n) only;
            // count <= k, so the stores at count end by n + 16.
            unsafe {
                let load = |v: &[f32]| _mm512_maskz_loadu_ps(lanes, v.as_ptr().add(k));
                let dx = _mm512_sub_ps(p[0], load(x));
                let dy = _mm512_sub_ps(p[1], load(y));
                let dz = _mm512_sub_ps(p[2], load(z));
                let r2 = _mm512_add_ps(
                    _mm512_add_ps(_mm512_mul_ps(dx, dx), _mm512_mul_ps(dy, dy)),
                    _mm512_mul_ps(dz, dz),
                );
                let hit = _mm512_mask_cmp_ps_mask::<_CMP_LT_OQ>(lanes, r2, s2);
                let js = _mm512_maskz_loadu_epi32(lanes, j.as_ptr().add(k) as *const i32);
                count += store_hits16(hit, js, r2, &mut hit_j[count..], &mut hit_r2[count..]);
            }
            k += 16;
        }
        count
    }

    fn distances(&mut self, pr: &Params, pi: [f32; 4]) {
        self.differences(pr, pi);
        let n = self.j.len();
        let support2 = pr.kernel.support2;
        // Branch-free compaction: every candidate is written at `count`, which
        // advances only past a neighbour (count <= k, so it stays in bounds).
        let (hits, hit_r2) = (&mut self.hits[..n], &mut self.hit_r2[..n]);
        let mut count = 0;
        for (k, &r2) in self.r2[..n].iter().enumerate() {
            hits[count] = k as u32;
            hit_r2[count] = r2;
            count += (r2 < support2) as usize;
        }
        self.count = count;
    }

    /// d and r² of every candidate (vectorised by the compiler).
    #[inline(always)]
    fn differences(&mut self, pr: &Params, pi: [f32; 4]) {
        let n = self.j.len();
        let axes = [
            (&self.x[..n], &mut self.dx[..n]),
            (&self.y[..n], &mut self.dy[..n]),
            (&self.z[..n], &mut self.dz[..n]),
        ];
        for (a, (src, d)) in axes.into_iter().enumerate() {
            for (d, &s) in d.iter_mut().zip(src) {
                *d = pi[a] - s;
            }
            if pr.sizes.flags & (1 << a) != 0 {
                let (half, period) = (pr.grid.half_period[a], pr.grid.period[a]);
                for d in d.iter_mut() {
                    *d = wrap_axis(*d, half, period);
                }
            }
        }
        let (dx, dy, dz) = (&self.dx[..n], &self.dy[..n], &self.dz[..n]);
        for (k, r2) in self.r2[..n].iter_mut().enumerate() {
            *r2 = dx[k] * dx[k] + dy[k] * dy[k] + dz[k] * dz[k];
        }
    }
}

#[cfg(target_arch = "x86_64")]
use crate::lanes::{AVX2, AVX512};

/// For each 8-bit mask, the lanes whose bit is set, in order, then the rest:
/// the permutation that packs a mask's lanes to the front.
#[cfg(target_arch = "x86_64")]
static LEFT_PACK: [[u32; 8]; 256] = {
    let mut table = [[0u32; 8]; 256];
    let mut m = 0;
    while m < 256 {
        let mut at = 0;
        let mut lane = 0;
        while lane < 8 {
            if m & (1 << lane) != 0 {
                table[m][at] = lane as u32;
                at += 1;
            }
            lane += 1;
        }
        // The unset lanes fill the rest (their values are overwritten later).
        let mut lane = 0;
        while lane < 8 {
            if m & (1 << lane) == 0 {
                table[m][at] = lane as u32;
                at += 1;
            }
            lane += 1;
        }
        m += 1;
    }
    table
};

/// Padding the compactions need past the candidates: one AVX-512 register.
const WIDEST: usize = 16;

/// The lanes of a sixteen-lane block that lie before the end, `left`
/// candidates away.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn lanes16(left: usize) -> u16 {
    if left >= 16 {
        0xffff
    } else {
        (1u16 << left) - 1
    }
}

/// The lanes of `js` and `r2` that `hit` selects, packed in order to the front
/// of `to_j` and `to_r2` (whole registers are stored: each holds at least
/// sixteen); returns their count.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,popcnt")]
#[inline]
fn store_hits16(
    hit: u16,
    js: std::arch::x86_64::__m512i,
    r2: std::arch::x86_64::__m512,
    to_j: &mut [u32],
    to_r2: &mut [f32],
) -> usize {
    use std::arch::x86_64::*;
    assert!(to_j.len() >= 16 && to_r2.len() >= 16);
    // SAFETY: both hold at least sixteen entries (checked above).
    unsafe {
        _mm512_storeu_si512(
            to_j.as_mut_ptr() as *mut _,
            _mm512_maskz_compress_epi32(hit, js),
        );
        _mm512_storeu_ps(to_r2.as_mut_ptr(), _mm512_maskz_compress_ps(hit, r2));
    }
    hit.count_ones() as usize
}

/// `compact_avx2` sixteen at a time with AVX-512F (one compress per array).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,popcnt")]
unsafe fn compact_avx512(r2: &[f32], support2: f32, hits: &mut [u32], hit_r2: &mut [f32]) -> usize {
    use std::arch::x86_64::*;
    let n = r2.len();
    assert!(hits.len() >= n + 16 && hit_r2.len() >= n + 16);
    let s2 = _mm512_set1_ps(support2);
    let mut base = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
    let sixteen = _mm512_set1_epi32(16);
    let mut count = 0;
    let mut k = 0;
    while k < n {
        let lanes = lanes16(n - k);
        // SAFETY: the masked load reads lanes k..min(k + 16, n) only; count
        // <= k, so the stores at count end by n + 16.
        unsafe {
            let v = _mm512_maskz_loadu_ps(lanes, r2.as_ptr().add(k));
            let hit = _mm512_mask_cmp_ps_mask::<_CMP_LT_OQ>(lanes, v, s2);
            count += store_hits16(hit, base, v, &mut hits[count..], &mut hit_r2[count..]);
        }
        base = _mm512_add_epi32(base, sixteen);
        k += 16;
    }
    count
}

/// The indices k and r²[k] of every r²[k] < support², in order, into `hits` and
/// `hit_r2` (each at least r2.len() + 8 long); returns their count. Eight
/// candidates at a time: one compare, a mask, and a permutation that packs the
/// neighbours to the front, stored whole at `count` (the lanes past the
/// neighbours are overwritten by the next store). Same selection as the scalar
/// `r2 < support2` (false for NaN, as _CMP_LT_OQ).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,popcnt")]
unsafe fn compact_avx2(r2: &[f32], support2: f32, hits: &mut [u32], hit_r2: &mut [f32]) -> usize {
    use std::arch::x86_64::*;
    let n = r2.len();
    assert!(hits.len() >= n + 8 && hit_r2.len() >= n + 8);
    let s2 = _mm256_set1_ps(support2);
    let mut base = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    let eight = _mm256_set1_epi32(8);
    let mut count = 0;
    let mut k = 0;
    while k + 8 <= n {
        // SAFETY: k + 8 <= n; count <= k, so count + 8 <= n + 8.
        unsafe {
            let v = _mm256_loadu_ps(r2.as_ptr().add(k));
            let mask = _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LT_OQ>(v, s2)) as usize;
            let perm = _mm256_loadu_si256(LEFT_PACK[mask].as_ptr() as *const __m256i);
            let idx = _mm256_permutevar8x32_epi32(base, perm);
            _mm256_storeu_si256(hits.as_mut_ptr().add(count) as *mut __m256i, idx);
            _mm256_storeu_ps(
                hit_r2.as_mut_ptr().add(count),
                _mm256_permutevar8x32_ps(v, perm),
            );
            count += mask.count_ones() as usize;
        }
        base = _mm256_add_epi32(base, eight);
        k += 8;
    }
    while k < n {
        hits[count] = k as u32;
        hit_r2[count] = r2[k];
        count += (r2[k] < support2) as usize;
        k += 1;
    }
    count
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
            if r2 < pr.kernel.support2 {
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
        if pr.sizes.flags & (1 << k) != 0 {
            d[k] = wrap_axis(d[k], pr.grid.half_period[k], pr.grid.period[k]);
        }
    }
    d
}

/// One component of a difference brought into (−period/2, period/2]: the minimum
/// image on a periodic axis (a select, so a sweep of it vectorises).
#[inline(always)]
fn wrap_axis(d: f32, half: f32, period: f32) -> f32 {
    if d > half {
        d - period
    } else if d < -half {
        d + period
    } else {
        d
    }
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

/// The cell a particle sorts into; n_cells, after every cell and in none, for
/// one that has left the domain: a fluid particle outside the keep
/// box, or a wall-kind particle stamped with the time it left (a member of a
/// rigid body that left, `bodies::place`; it may stand anywhere, its body's
/// centre is past the face). Other walls stay wherever they stand (those of a
/// closed side reach past the open face above it).
#[inline(always)]
fn cell_key(pr: &Params, p: &[f32; 4], phase: u32) -> u32 {
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

pub fn run(pr: &Params, st: &mut State, grid: &mut CellTable) {
    let n = st.len();
    let (mut keys, mut perm) = (
        std::mem::take(&mut grid.keys),
        std::mem::take(&mut grid.perm),
    );
    st.pos
        .par_iter()
        .enumerate()
        .map(|(i, p)| (cell_key(pr, p, st.phase[i]), i as u32))
        .collect_into_vec(&mut keys);
    keys.par_sort_unstable();
    keys.par_iter()
        .map(|k| k.1 as usize)
        .collect_into_vec(&mut perm);
    // Every sorted field the scene holds (crate::fields); the others are
    // recomputed after the sort.
    let held = Held::of_state(st);
    for f in FIELDS.iter().filter(|f| f.sorted_in(held)) {
        (f.permute)(st, &perm);
    }
    let n_cells = pr.sizes.n_cells as usize;
    grid.invalidate();
    grid.start.clear();
    grid.start.resize(n_cells, 0);
    grid.end.clear();
    grid.end.resize(n_cells, 0);
    grid.fluid.clear();
    grid.fluid.resize(n_cells, false);
    let gone = pr.sizes.n_cells;
    st.sim.removed = keys.iter().rev().take_while(|k| k.0 == gone).count() as u32;
    for k in 0..n - st.sim.removed as usize {
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
    (grid.keys, grid.perm) = (keys, perm);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::backend::cpu::recorded::RETRY_STEPS;

    type Visit = (usize, [u32; 3], u32);

    fn bits(j: usize, d: [f32; 3], r2: f32) -> Visit {
        (j, d.map(f32::to_bits), r2.to_bits())
    }

    /// The pairs a walk reports, in its order, as bits.
    fn visits(walk: impl FnOnce(&mut dyn FnMut(usize, [f32; 3], f32))) -> Vec<Visit> {
        let mut seen = Vec::new();
        walk(&mut |j, d, r2| seen.push(bits(j, d, r2)));
        seen
    }

    /// `floor_to_i32` is `floor` then the saturating `as i32`, at the integers,
    /// between them, at the ends of the i32 range and past them, and for a NaN.
    #[test]
    fn floor_to_i32_is_floor() {
        let mut xs = vec![
            0.0,
            -0.0,
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::MAX,
            f32::MIN,
            f32::MIN_POSITIVE,
            -f32::MIN_POSITIVE,
            2147483648.0,
            -2147483648.0,
            -2147483904.0,
            16777217.0,
            -8388607.5,
        ];
        for k in -2000..2000 {
            let x = k as f32 * 0.37;
            xs.extend([x, x.next_up(), x.next_down(), k as f32]);
        }
        for x in xs {
            assert_eq!(floor_to_i32(x), x.floor() as i32, "x = {x:e}");
        }
    }

    /// The sixteen-lane sweeps (AVX-512F) find the neighbours and r² the
    /// eight-lane ones (AVX2) find, in the same order, with the same bits:
    /// on every particle's gathered candidates of a jittered 3D scene, less
    /// the last i mod 16 of them for particle i, so that every tail length
    /// occurs. Where the CPU lacks AVX-512F there is nothing to compare (the
    /// eight-lane sweep is the one that runs).
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn sixteen_lane_sweeps_match_the_eight_lane_ones() {
        if !*AVX512 {
            eprintln!("no AVX-512F here: only the eight-lane sweeps run");
            return;
        }
        let (pr, st, grid) = jittered("dam_break_3d");
        let mut near = Candidates::default();
        let mut tails = [false; 16];
        for i in 0..st.len() {
            near.gather(&pr, &st.pos, &grid, &st.pos[i], Among::All);
            let keep = near.j.len().saturating_sub(i % 16);
            near.j.truncate(keep);
            near.x.truncate(keep);
            near.y.truncate(keep);
            near.z.truncate(keep);
            near.key = Default::default(); // gather afresh for the next one
            tails[keep % 16] = true;
            // SAFETY: AVX-512F (checked above) implies the AVX2 of `AVX512`.
            let narrow = unsafe { near.neighbours_avx2(&pr, st.pos[i]) };
            let eight = (
                near.hit_j[..narrow].to_vec(),
                bits_of(&near.hit_r2[..narrow]),
            );
            let wide = unsafe { near.neighbours_avx512(&pr, st.pos[i]) };
            let sixteen = (near.hit_j[..wide].to_vec(), bits_of(&near.hit_r2[..wide]));
            assert_eq!(eight, sixteen, "neighbours of particle {i}");
            near.differences(&pr, st.pos[i]);
            let n = near.j.len();
            let (hits, hit_r2) = (&mut near.hits, &mut near.hit_r2);
            let support2 = pr.kernel.support2;
            let narrow = unsafe { compact_avx2(&near.r2[..n], support2, hits, hit_r2) };
            let eight = (hits[..narrow].to_vec(), bits_of(&hit_r2[..narrow]));
            let wide = unsafe { compact_avx512(&near.r2[..n], support2, hits, hit_r2) };
            let sixteen = (hits[..wide].to_vec(), bits_of(&hit_r2[..wide]));
            assert_eq!(eight, sixteen, "compaction of particle {i}");
        }
        assert!(tails.iter().all(|&t| t), "tail lengths seen: {tails:?}");
    }

    fn bits_of(v: &[f32]) -> Vec<u32> {
        v.iter().map(|x| x.to_bits()).collect()
    }

    /// A scene with jittered particles (irregular distances), sorted into cells.
    fn jittered(scene: &str) -> (Params, State, CellTable) {
        let path = format!(
            "{}/scenarios/validation/{scene}.toml",
            env!("CARGO_MANIFEST_DIR")
        );
        let l = crate::load::load(&path, &["jitter=0.3".into()]).unwrap();
        let pr = Params::new(&l.model, 2);
        let mut st = l.state.clone();
        let mut grid = CellTable::default();
        run(&pr, &mut st, &mut grid);
        (pr, st, grid)
    }

    /// The cached sweep (`for_each_neighbor`), the recorded list
    /// (`for_each_listed`) and the list's fallback after `invalidate` visit exactly
    /// the pairs of the plain cell walk (`for_each_near`), in its order, with the
    /// same bits of d and r²: periodic 2D and walled 3D.
    #[test]
    fn sweep_and_list_match_the_plain_walk() {
        for scene in ["poiseuille_2d", "dam_break_3d"] {
            let (pr, mut st, mut grid) = jittered(scene);
            let mut list = NeighborList::default();
            super::super::density::run(&pr, &mut st, &grid, &mut list);
            let pos = &st.pos;
            let mut pairs = 0;
            for i in 0..pos.len() {
                let walk = visits(|f| for_each_near(&pr, pos, &grid, pos[i], f));
                let swept = visits(|f| for_each_neighbor(&pr, pos, &grid, i, f));
                assert_eq!(walk, swept, "{scene}: sweep of particle {i}");
                if !pr.is_wall(st.phase[i]) {
                    let listed = visits(|f| for_each_listed(&pr, pos, &grid, &list, i, f));
                    assert_eq!(walk, listed, "{scene}: list of particle {i}");
                    assert!(super::listed(&list, &grid, i).is_some());
                }
                pairs += walk.len();
            }
            assert!(pairs > 10 * pos.len(), "{scene}: {pairs} pairs");
            grid.invalidate();
            let i = (0..pos.len()).find(|&i| !pr.is_wall(st.phase[i])).unwrap();
            assert!(listed(&list, &grid, i).is_none(), "stale list used");
            let walk = visits(|f| for_each_near(&pr, pos, &grid, pos[i], f));
            let listed = visits(|f| for_each_listed(&pr, pos, &grid, &list, i, f));
            assert_eq!(walk, listed, "{scene}: fallback sweep");
        }
    }

    /// A list over its bound is dropped and not recorded again for
    /// RETRY_STEPS steps (the passes sweep the cells meanwhile, with the same
    /// neighbours), then recorded again.
    #[test]
    fn a_list_over_its_bound_waits_before_it_is_recorded_again() {
        let (pr, mut st, grid) = jittered("dam_break_3d");
        let fluid = (0..st.len()).find(|&i| !pr.is_wall(st.phase[i])).unwrap();
        let mut list = NeighborList::default();
        let chunks = list.take_chunks(st.active().div_ceil(LIST_CHUNK));
        let mut filled = chunks;
        for (c, chunk) in filled.iter_mut().enumerate() {
            for i in c * LIST_CHUNK..((c + 1) * LIST_CHUNK).min(st.active()) {
                with_neighbors(&pr, &st.pos, &grid, i, |js, _| chunk.push(js));
            }
        }
        list.store_within(&grid, filled, 10);
        assert!(
            listed(&list, &grid, fluid).is_none(),
            "a list over its bound was kept"
        );
        for step in 0..RETRY_STEPS {
            super::super::density::run(&pr, &mut st, &grid, &mut list);
            assert!(
                listed(&list, &grid, fluid).is_none(),
                "recorded again at step {step}"
            );
        }
        super::super::density::run(&pr, &mut st, &grid, &mut list);
        assert!(
            listed(&list, &grid, fluid).is_some(),
            "never recorded again"
        );
    }

    /// A walk from inside a neighbour callback (the thread's candidate cache is
    /// held) sees the same neighbours as a plain walk, and leaves the outer walk's
    /// cache intact.
    #[test]
    fn nested_walks_match_the_plain_walk() {
        let (pr, st, grid) = jittered("dam_break_3d");
        let pos = &st.pos;
        let i = pos.len() / 2;
        let mut outer: Vec<Visit> = Vec::new();
        let mut nested = 0;
        for_each_neighbor(&pr, pos, &grid, i, |j, d, r2| {
            outer.push(bits(j, d, r2));
            let walk = visits(|f| for_each_near(&pr, pos, &grid, pos[j], f));
            let inner = visits(|f| for_each_neighbor(&pr, pos, &grid, j, f));
            assert_eq!(walk, inner, "nested walk from particle {j}");
            nested += 1;
        });
        let walk = visits(|f| for_each_near(&pr, pos, &grid, pos[i], f));
        assert_eq!(walk, outer, "outer walk of particle {i}");
        assert!(nested > 10, "{nested} neighbours");
    }
}
