//! The bitonic sort of (cell, index) keys: which dispatches it takes and the
//! per-dispatch uniforms (neighbors.wgsl `bitonic_local` / `bitonic_global`).

/// Stride between sort-stage uniforms (the usual min_uniform_buffer_offset_alignment).
pub const STAGE_STRIDE: u64 = 256;

/// Keys per workgroup-memory block of the bitonic sort (twin of neighbors.wgsl).
pub const SORT_BLOCK: u32 = 2048;

/// One dispatch of the bitonic sort (neighbors.wgsl).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SortStep {
    /// Compare-exchange stage (j, k) with j >= SORT_BLOCK, through global memory.
    Global { j: u32, k: u32 },
    /// Every stage with j < SORT_BLOCK of k = k_first..=k_last, in workgroup memory.
    Local { k_first: u32, k_last: u32 },
}

impl SortStep {
    /// The SortStage uniform: (j, k, k_last, 0).
    pub fn uniform(&self) -> [u32; 4] {
        match *self {
            SortStep::Global { j, k } => [j, k, 0, 0],
            SortStep::Local { k_first, k_last } => [0, k_first, k_last, 0],
        }
    }
}

/// The dispatches of a bitonic sort over n_pad keys (a power of two): all of
/// k <= SORT_BLOCK at once in workgroup memory, then per larger k its global stages
/// down to j = SORT_BLOCK and one local dispatch for the rest.
pub fn sort_stages(n_pad: u32) -> Vec<SortStep> {
    let block = SORT_BLOCK.min(n_pad);
    let mut out = vec![SortStep::Local {
        k_first: 2,
        k_last: block,
    }];
    let mut k = 2 * block;
    while k <= n_pad {
        let mut j = k / 2;
        while j >= block {
            out.push(SortStep::Global { j, k });
            j /= 2;
        }
        out.push(SortStep::Local {
            k_first: k,
            k_last: k,
        });
        k *= 2;
    }
    out
}

/// The uniforms of all dispatches, `STAGE_STRIDE` apart (bound with a dynamic offset).
pub fn stage_uniforms(stages: &[SortStep]) -> Vec<u8> {
    let mut bytes = vec![0u8; stages.len().max(1) * STAGE_STRIDE as usize];
    for (s, step) in stages.iter().enumerate() {
        let o = s * STAGE_STRIDE as usize;
        for (w, word) in step.uniform().iter().enumerate() {
            bytes[o + 4 * w..o + 4 * w + 4].copy_from_slice(&word.to_le_bytes());
        }
    }
    bytes
}
