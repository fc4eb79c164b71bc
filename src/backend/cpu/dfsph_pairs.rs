//! The DFSPH step's pair geometry, recorded by the factor pass: for each fluid
//! particle, each neighbour j ≠ i in the walk's order with x_ij and
//! ∂W/∂r(r_ij) / r_ij. Positions do not move between the factor pass and the
//! drift, so every iteration of the divergence, density and velocity solves
//! reads the same pairs: recorded once, they save each iteration the cell
//! sweep, the square root and the kernel. The values are the ones the passes
//! computed themselves, in the same order, so the sums keep their bits (the
//! GPU twin recomputes them per iteration; nothing changes there).

use super::neighbors::{for_each_neighbor, CellTable};
use super::recorded::{Entry, RecordChunk, Recorded};
use crate::kernel;
use crate::params::Params;
use std::cell::RefCell;

/// Neighbour j of a fluid particle: x_ij and g = ∂W/∂r / r at r_ij > 0.
#[derive(Clone, Copy, Default)]
pub struct Pair {
    pub j: u32,
    pub d: [f32; 3],
    pub g: f32,
}

/// A pair and the velocity system's three coefficients kept beside it
/// (dfsph_viscosity::Couplings): the table may take a quarter of the memory
/// free when it is first taken (the neighbour list may take half), or 2^24
/// pairs where that is unknown (cpu/recorded.rs). Over it, the solves sweep
/// and evaluate the kernel themselves, with the same bits.
impl Entry for Pair {
    const MEMORY_SHARE: f64 = 0.25;
    const BYTES: usize = std::mem::size_of::<Pair>() + 12;
    const UNKNOWN_BOUND: usize = 1 << 24;
}

/// This step's pairs, valid for one cell table (`CellTable::generation`).
pub type PairTable = Recorded<Pair>;

/// The pairs of particles c·LIST_CHUNK .. (c+1)·LIST_CHUNK (none for a wall
/// particle).
pub type PairChunk = RecordChunk<Pair>;

/// `f(j, x_ij, g)` for every neighbour j ≠ i of fluid particle i in the
/// walk's order: from the table when it holds this cell table's pairs, else
/// swept and evaluated here with the same operations into a per-thread
/// scratch list first, so that `f` is called from one loop only (the
/// compiler then inlines it and keeps its sums in registers: called from two
/// loops, the divergence and density solves' sum went through memory and
/// took three times as long a pair).
#[inline(always)]
pub fn for_each_pair(
    pr: &Params,
    pos: &[[f32; 4]],
    grid: &CellTable,
    table: &PairTable,
    i: usize,
    mut f: impl FnMut(usize, [f32; 3], f32),
) {
    let mut scratch = None;
    let pairs = match table.entries(grid, i) {
        Some(pairs) => pairs,
        None => {
            let mut pairs = SCRATCH.with(|s| s.take());
            pairs.clear();
            for_each_neighbor(pr, pos, grid, i, |j, d, r2| {
                if r2 > 0.0 {
                    let r = r2.sqrt();
                    let g = kernel::dw(pr, r) / r;
                    pairs.push(Pair { j: j as u32, d, g });
                }
            });
            &scratch.insert(pairs)[..]
        }
    };
    for p in pairs {
        f(p.j as usize, p.d, p.g);
    }
    if let Some(pairs) = scratch {
        SCRATCH.with(|s| s.replace(pairs));
    }
}

thread_local! {
    /// `for_each_pair`'s pairs of one particle when the step has no table
    /// (taken while in use, so a nested call starts an empty one).
    static SCRATCH: RefCell<Vec<Pair>> = const { RefCell::new(Vec::new()) };
}
