//! Deterministic random numbers for scene building: the jitter of the lattice
//! (setup.rs), the powder pour (powder.rs) and the benchmarks' random scenes. One
//! generator, so a seed means the same numbers everywhere it is used.

/// A small deterministic generator (SplitMix64); its output is fixed by the seed
/// on every platform.
pub(crate) struct SplitMix(pub(crate) u64);

impl SplitMix {
    pub(crate) fn next_f64(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 53) as f64
    }
}
