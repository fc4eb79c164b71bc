//! Per-particle records one pass of a step makes for later passes of the same
//! step to read (the neighbour list, DFSPH's pair table): entries in chunks of
//! LIST_CHUNK particles, valid for one cell table (`CellTable::generation`),
//! bounded by a share of the memory free when first taken. A step that
//! records more keeps none and gives the memory back; the next RETRY_STEPS
//! steps record nothing, and the readers sweep the cells themselves meanwhile
//! (with the same bits), since recording only to drop it costs the recording
//! pass twice.

use super::neighbors::{CellTable, LIST_CHUNK};

/// Steps a record that outgrew its bound is not made for before the next try.
pub const RETRY_STEPS: u32 = 100;

/// What one entry of a record costs and how much memory its record may take.
pub trait Entry: Copy {
    /// Share of the free memory the record may take.
    const MEMORY_SHARE: f64;
    /// Bytes an entry takes, with what is kept beside it.
    const BYTES: usize;
    /// Most entries where the free memory is unknown.
    const UNKNOWN_BOUND: usize;
}

fn bound<T: Entry>() -> usize {
    match crate::host::available_memory() {
        Some(free) => (free * T::MEMORY_SHARE / T::BYTES as f64) as usize,
        None => T::UNKNOWN_BOUND,
    }
}

/// The entries of particles c·LIST_CHUNK .. (c+1)·LIST_CHUNK: those of the
/// k-th are items[offsets[k]..offsets[k + 1]] (none for a particle not recorded).
pub struct RecordChunk<T> {
    pub offsets: Vec<u32>,
    pub items: Vec<T>,
    /// Not recorded this step (`push`, `extend` and `end` do nothing).
    off: bool,
}

impl<T> Default for RecordChunk<T> {
    fn default() -> Self {
        RecordChunk {
            offsets: Vec::new(),
            items: Vec::new(),
            off: false,
        }
    }
}

impl<T: Copy> RecordChunk<T> {
    /// Adds one entry to the current particle.
    #[inline(always)]
    pub fn push_one(&mut self, item: T) {
        if !self.off {
            self.items.push(item);
        }
    }
    /// Ends the current particle's entries.
    #[inline(always)]
    pub fn end(&mut self) {
        if !self.off {
            self.offsets.push(self.items.len() as u32);
        }
    }
    /// Ends the current particle with entries `items` (empty for one not gathered).
    #[inline(always)]
    pub fn push(&mut self, items: &[T]) {
        if !self.off {
            self.items.extend_from_slice(items);
            self.offsets.push(self.items.len() as u32);
        }
    }
    /// The k-th particle's entries.
    pub fn of(&self, k: usize) -> &[T] {
        &self.items[self.offsets[k] as usize..self.offsets[k + 1] as usize]
    }
}

/// One step's record, valid for one cell table.
pub struct Recorded<T> {
    generation: u64,
    chunks: Vec<RecordChunk<T>>,
    /// Steps left before a record that outgrew its bound is made again.
    skip: u32,
    /// The bound, read when the record is first taken.
    max_entries: Option<usize>,
}

impl<T> Default for Recorded<T> {
    fn default() -> Self {
        Recorded {
            generation: 0,
            chunks: Vec::new(),
            skip: 0,
            max_entries: None,
        }
    }
}

impl<T: Entry> Recorded<T> {
    /// A record that never holds more than `max_entries` (tests: 0 forces
    /// the readers' fallback).
    #[cfg(test)]
    pub fn with_bound(max_entries: usize) -> Self {
        Recorded {
            max_entries: Some(max_entries),
            ..Default::default()
        }
    }

    /// `n` empty chunks for the recording pass to fill, reusing the buffers of
    /// the last step's record (no allocation once the sizes have settled);
    /// chunks that record nothing while an oversized record waits.
    pub fn take_chunks(&mut self, n: usize) -> Vec<RecordChunk<T>> {
        let mut chunks = std::mem::take(&mut self.chunks);
        self.generation = 0;
        self.max_entries.get_or_insert_with(bound::<T>);
        let off = self.skip > 0;
        self.skip = self.skip.saturating_sub(1);
        chunks.resize_with(n, RecordChunk::default);
        for c in &mut chunks {
            c.offsets.clear();
            c.offsets.push(0);
            c.items.clear();
            c.off = off;
        }
        chunks
    }

    /// Keeps the recording pass's chunks for `grid`, unless they were not
    /// recorded or hold more entries than the bound (then the memory is given
    /// back and the next RETRY_STEPS steps record none).
    pub fn store(&mut self, grid: &CellTable, chunks: Vec<RecordChunk<T>>) {
        let max = *self.max_entries.get_or_insert_with(bound::<T>);
        self.store_within(grid, chunks, max);
    }

    pub(super) fn store_within(
        &mut self,
        grid: &CellTable,
        chunks: Vec<RecordChunk<T>>,
        max_entries: usize,
    ) {
        self.generation = 0;
        let recorded = !chunks.iter().any(|c| c.off);
        let entries: usize = chunks.iter().map(|c| c.items.len()).sum();
        if recorded && entries > max_entries {
            self.skip = RETRY_STEPS;
            self.chunks = Vec::new();
            return;
        }
        if recorded {
            self.generation = grid.generation;
        }
        self.chunks = chunks;
    }

    /// The record's chunks when it holds this cell table's entries.
    pub fn chunks(&self, grid: &CellTable) -> Option<&[RecordChunk<T>]> {
        (self.generation != 0 && self.generation == grid.generation).then_some(&self.chunks[..])
    }

    /// Particle i's entries when the record holds this cell table's.
    pub fn entries(&self, grid: &CellTable, i: usize) -> Option<&[T]> {
        self.chunks(grid)
            .map(|c| c[i / LIST_CHUNK].of(i % LIST_CHUNK))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn recorded(n: usize) -> Vec<RecordChunk<u32>> {
        let mut chunks = Recorded::<u32>::default().take_chunks(1);
        for k in 0..n as u32 {
            chunks[0].push_one(k);
        }
        chunks[0].end();
        chunks
    }

    /// A record over its bound is dropped with its memory and not made again
    /// for RETRY_STEPS steps, then made again.
    #[test]
    fn a_record_over_its_bound_gives_its_memory_back_and_waits() {
        let mut grid = CellTable::default();
        grid.generation = 7;
        let mut t = Recorded::<u32>::default();
        t.store_within(&grid, recorded(3), 3);
        assert_eq!(t.entries(&grid, 0), Some(&[0, 1, 2][..]));
        t.store_within(&grid, recorded(4), 3);
        assert!(t.chunks(&grid).is_none());
        assert!(t.chunks.is_empty(), "an oversized record's memory is kept");
        for _ in 0..RETRY_STEPS {
            let chunks = t.take_chunks(1);
            assert!(chunks[0].off);
            t.store_within(&grid, chunks, 3);
            assert!(t.chunks(&grid).is_none());
        }
        assert!(!t.take_chunks(1)[0].off);
    }

    #[test]
    fn a_record_of_another_cell_table_is_not_read() {
        let mut grid = CellTable::default();
        grid.generation = 7;
        let mut t = Recorded::<u32>::default();
        t.store_within(&grid, recorded(2), 10);
        let mut other = CellTable::default();
        other.generation = 8;
        assert!(t.chunks(&other).is_none());
        assert!(t.entries(&other, 0).is_none());
    }
}
