//! The neighbour walks: every pass's loop over the neighbours of a particle,
//! in the fixed order the WGSL loops use (cells by dz, dy, dx from −1 to 1,
//! particles in sorted order), over the cells or over the neighbour list the
//! density pass records; the candidates of a cell neighbourhood are copied
//! once per cell into a per-thread structure of arrays (`Candidates`) and
//! swept branch-free (the SIMD sweeps are in simd.rs).

use super::grid::{
    cell_coord, cell_index, for_each_cell, min_image, wrap_axis, CellTable, GENERATION,
};
use super::simd::WIDEST;
#[cfg(target_arch = "x86_64")]
use super::simd::{AVX2, AVX512};
use crate::backend::cpu::recorded::{Entry, RecordChunk, Recorded};
use crate::model::MAX_PHASES;
use crate::params::Params;
use std::cell::RefCell;
use std::sync::atomic::Ordering;

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

/// The neighbours of every fluid particle and every conducting solid, recorded
/// by the density (or continuity) pass in the walk's order, so that the
/// forces, interface and conduction passes of the same step read them instead
/// of sweeping the cells again. Valid for one cell table
/// (`CellTable::generation`).
pub type NeighborList = Recorded<u32>;

/// The neighbours of particles c·LIST_CHUNK .. (c+1)·LIST_CHUNK (none for a
/// wall particle).
pub type ListChunk = RecordChunk<u32>;

/// Particle i's recorded neighbours; None without a list for this cell table,
/// or for a particle the list holds none of (a wall: every fluid particle's
/// and conducting solid's entry holds at least itself).
pub(super) fn listed<'a>(list: &'a NeighborList, grid: &CellTable, i: usize) -> Option<&'a [u32]> {
    list.entries(grid, i).filter(|js| !js.is_empty())
}

/// `for_each_neighbor`, read from the step's neighbour list when it holds the
/// particle's neighbours for this cell table (a fluid particle's or a conducting
/// solid's): the same j in the same order, with d and
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

/// `f` gets the neighbours j of particle i, in `for_each_listed`'s order,
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
pub(super) struct Candidates {
    /// (CellTable::generation, cell, 0 or `Among::Phases`'s token) the copy
    /// belongs to.
    pub(super) key: (u64, usize, u64),
    pub(super) j: Vec<u32>,
    pub(super) x: Vec<f32>,
    pub(super) y: Vec<f32>,
    pub(super) z: Vec<f32>,
    pub(super) dx: Vec<f32>,
    pub(super) dy: Vec<f32>,
    pub(super) dz: Vec<f32>,
    pub(super) r2: Vec<f32>,
    /// Indices into the candidate arrays of those inside the support, in order,
    /// and their r².
    pub(super) hits: Vec<u32>,
    pub(super) hit_j: Vec<u32>,
    pub(super) hit_r2: Vec<f32>,
    pub(super) count: usize,
}

impl Candidates {
    pub(super) fn gather(
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
    pub(super) fn differences(&mut self, pr: &Params, pi: [f32; 4]) {
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
