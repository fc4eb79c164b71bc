//! The SIMD sweeps of the neighbour walks (AVX2 and AVX-512F, chosen once at
//! run time): the same IEEE operations as the scalar sweep in walks.rs, lane
//! by lane, and the hits packed in order, so the same neighbours with the
//! same bits.

#[cfg(target_arch = "x86_64")]
use super::walks::Candidates;
#[cfg(target_arch = "x86_64")]
pub(super) use crate::lanes::{AVX2, AVX512};
#[cfg(target_arch = "x86_64")]
use crate::params::Params;

#[cfg(target_arch = "x86_64")]
impl Candidates {
    /// `distances` compiled for AVX2: the same IEEE operations (Rust never fuses
    /// a multiply and an add), eight lanes at a time, and the compaction by
    /// left-packing (`compact_avx2`).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,popcnt")]
    pub(super) unsafe fn distances_avx2(&mut self, pr: &Params, pi: [f32; 4]) {
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
    pub(super) unsafe fn neighbours_avx2(&mut self, pr: &Params, pi: [f32; 4]) -> usize {
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
    pub(super) unsafe fn neighbours_avx512(&mut self, pr: &Params, pi: [f32; 4]) -> usize {
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
}

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
pub(super) const WIDEST: usize = 16;

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
pub(super) unsafe fn compact_avx512(
    r2: &[f32],
    support2: f32,
    hits: &mut [u32],
    hit_r2: &mut [f32],
) -> usize {
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
pub(super) unsafe fn compact_avx2(
    r2: &[f32],
    support2: f32,
    hits: &mut [u32],
    hit_r2: &mut [f32],
) -> usize {
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
