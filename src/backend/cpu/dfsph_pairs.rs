//! The DFSPH step's pair geometry, recorded by the factor pass: for each fluid
//! particle, each neighbour j ≠ i in the walk's order with x_ij and
//! ∂W/∂r(r_ij) / r_ij. Positions do not move between the factor pass and the
//! drift, so every iteration of the divergence, density and velocity solves
//! reads the same pairs: recorded once, they save each iteration the cell
//! sweep, the square root and the kernel. The values are the ones the passes
//! computed themselves, in the same order, so the sums keep their bits (the
//! GPU twin recomputes them per iteration; nothing changes there).

use super::neighbors::{for_each_neighbor, CellTable, LIST_CHUNK};
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

/// Bytes a recorded pair takes: the pair and the velocity system's three
/// coefficients (dfsph_viscosity::Couplings), kept beside it.
pub const BYTES_PER_PAIR: usize = std::mem::size_of::<Pair>() + 12;

/// Steps a table that outgrew its bound is not recorded for before the next
/// try (as the neighbour list's).
const RETRY_STEPS: u32 = 100;

/// Most pairs a table holds: a quarter of the memory free when it is first
/// taken (the neighbour list may take half), or 2^24 pairs where that is
/// unknown. A step that records more keeps none: the passes sweep the cells
/// and evaluate the kernel themselves, with the same bits.
fn pair_bound() -> usize {
    match crate::host::available_memory() {
        Some(free) => (free / 4.0 / BYTES_PER_PAIR as f64) as usize,
        None => 1 << 24,
    }
}

/// The pairs of particles c·LIST_CHUNK .. (c+1)·LIST_CHUNK: those of the k-th
/// are pairs[offsets[k]..offsets[k + 1]] (none for a wall particle).
#[derive(Default)]
pub struct PairChunk {
    pub offsets: Vec<u32>,
    pub pairs: Vec<Pair>,
    /// Not recorded this step (`push` and `end` do nothing).
    off: bool,
}

impl PairChunk {
    #[inline(always)]
    pub fn push(&mut self, pair: Pair) {
        if !self.off {
            self.pairs.push(pair);
        }
    }
    /// Ends the current particle's pairs.
    #[inline(always)]
    pub fn end(&mut self) {
        if !self.off {
            self.offsets.push(self.pairs.len() as u32);
        }
    }
    pub fn of(&self, k: usize) -> &[Pair] {
        &self.pairs[self.offsets[k] as usize..self.offsets[k + 1] as usize]
    }
}

/// This step's pairs, valid for one cell table (`CellTable::generation`).
#[derive(Default)]
pub struct PairTable {
    generation: u64,
    chunks: Vec<PairChunk>,
    skip: u32,
    max_pairs: Option<usize>,
}

impl PairTable {
    /// A table that never holds more than `max_pairs` (tests: 0 forces the
    /// sweep-and-evaluate fallback).
    #[cfg(test)]
    pub fn with_bound(max_pairs: usize) -> Self {
        PairTable {
            max_pairs: Some(max_pairs),
            ..Default::default()
        }
    }

    /// `n` empty chunks for the factor pass to fill, reusing last step's
    /// buffers; chunks that record nothing while an oversized table waits.
    pub fn take_chunks(&mut self, n: usize) -> Vec<PairChunk> {
        let mut chunks = std::mem::take(&mut self.chunks);
        self.generation = 0;
        self.max_pairs.get_or_insert_with(pair_bound);
        let off = self.skip > 0;
        self.skip = self.skip.saturating_sub(1);
        chunks.resize_with(n, PairChunk::default);
        for c in &mut chunks {
            c.offsets.clear();
            c.offsets.push(0);
            c.pairs.clear();
            c.off = off;
        }
        chunks
    }

    /// Keeps the factor pass's chunks for `grid`, unless they were not
    /// recorded or hold more pairs than the bound.
    pub fn store(&mut self, grid: &CellTable, chunks: Vec<PairChunk>) {
        let max = *self.max_pairs.get_or_insert_with(pair_bound);
        self.store_within(grid, chunks, max);
    }

    fn store_within(&mut self, grid: &CellTable, chunks: Vec<PairChunk>, max_pairs: usize) {
        let recorded = !chunks.iter().any(|c| c.off);
        let pairs: usize = chunks.iter().map(|c| c.pairs.len()).sum();
        self.generation = 0;
        if recorded && pairs > max_pairs {
            // Over the bound: its memory is given back, not kept unread.
            self.skip = RETRY_STEPS;
            self.chunks = Vec::new();
            return;
        }
        if recorded {
            self.generation = grid.generation;
        }
        self.chunks = chunks;
    }

    /// The table's chunks when it holds this cell table's pairs.
    pub fn chunks(&self, grid: &CellTable) -> Option<&[PairChunk]> {
        (self.generation != 0 && self.generation == grid.generation).then_some(&self.chunks[..])
    }
}

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
    let pairs = match table.chunks(grid) {
        Some(chunks) => chunks[i / LIST_CHUNK].of(i % LIST_CHUNK),
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

#[cfg(test)]
mod tests {
    use super::*;

    fn recorded(n_pairs: usize) -> Vec<PairChunk> {
        let mut t = PairTable::default();
        let mut chunks = t.take_chunks(1);
        for _ in 0..n_pairs {
            chunks[0].push(Pair::default());
        }
        chunks[0].end();
        chunks
    }

    #[test]
    fn a_table_over_its_bound_is_dropped_and_waits_before_it_is_recorded_again() {
        let mut grid = CellTable::default();
        grid.generation = 7;
        let mut t = PairTable::default();
        t.store_within(&grid, recorded(3), 3);
        assert!(t.chunks(&grid).is_some());
        t.store_within(&grid, recorded(4), 3);
        assert!(t.chunks(&grid).is_none());
        assert!(t.chunks.is_empty(), "an oversized table's memory is kept");
        for _ in 0..RETRY_STEPS {
            let chunks = t.take_chunks(1);
            assert!(chunks[0].off);
            t.store_within(&grid, chunks, 3);
            assert!(t.chunks(&grid).is_none());
        }
        assert!(!t.take_chunks(1)[0].off);
    }

    #[test]
    fn a_table_of_another_cell_table_is_not_read() {
        let mut grid = CellTable::default();
        grid.generation = 7;
        let mut t = PairTable::default();
        t.store_within(&grid, recorded(2), 10);
        let mut other = CellTable::default();
        other.generation = 8;
        assert!(t.chunks(&other).is_none());
    }
}
