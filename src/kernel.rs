//! Smoothing kernels, CPU side. Twin of shaders/lib/kernel.wgsl: same formulas in the
//! same operation order (no mul_add), so both give the same bits (DESIGN rule 1).

use crate::lanes::Lane;
use crate::params::Params;

#[inline(always)]
fn p4<R: Lane>(t: R) -> R {
    t * t * t * t
}

#[inline(always)]
fn p5<R: Lane>(t: R) -> R {
    t * t * t * t * t
}

/// W(r) for the kernel chosen in `params.kernel.kind`, on one distance or on
/// eight (`Lane`).
#[inline(always)]
pub fn w<R: Lane>(pr: &Params, r: R) -> R {
    let (sigma, h_inv) = (pr.kernel.sigma, pr.kernel.inv_h);
    match pr.kernel.kind {
        0 => w_quintic(sigma, h_inv, r),
        1 => w_wendland_c2(sigma, h_inv, r),
        _ => w_cubic(sigma, h_inv, r),
    }
}

// The kernels on one distance or on eight (`Lane`), with the same operations.

#[inline(always)]
fn w_quintic<R: Lane>(sigma: f32, h_inv: f32, r: R) -> R {
    let c = R::splat;
    let q = r * c(h_inv);
    let t1 = (c(1.0) - q).max0();
    let t2 = (c(2.0) - q).max0();
    let t3 = (c(3.0) - q).max0();
    c(sigma) * (p5(t3) - c(6.0) * p5(t2) + c(15.0) * p5(t1))
}

#[inline(always)]
fn w_wendland_c2<R: Lane>(sigma: f32, h_inv: f32, r: R) -> R {
    let c = R::splat;
    let q = r * c(h_inv);
    let t = (c(1.0) - c(0.5) * q).max0();
    c(sigma) * p4(t) * (c(2.0) * q + c(1.0))
}

/// Both pieces are evaluated and one is selected, so that a batch of these
/// vectorises; each piece has the same operations as a branch would.
#[inline(always)]
fn w_cubic<R: Lane>(sigma: f32, h_inv: f32, r: R) -> R {
    let c = R::splat;
    let q = r * c(h_inv);
    let inner = c(sigma) * (c(1.0) - c(1.5) * q * q + c(0.75) * q * q * q);
    let t = c(2.0) - q;
    let outer = c(sigma) * c(0.25) * t * t * t;
    q.where_lt(1.0, inner, q.where_lt(2.0, outer, c(0.0)))
}

/// Σ_k W(√r2_k) summed in the order given: the same bits as adding `w` one
/// neighbour at a time. The kernel values of a block are computed first, in a
/// loop without branches (eight lanes with AVX2; otherwise the compiler
/// vectorises it, 4 lanes with SSE2), and then added in order.
pub fn sum_w(pr: &Params, r2: &[f32]) -> f32 {
    #[cfg(target_arch = "x86_64")]
    if *crate::lanes::AVX2 {
        // SAFETY: the CPU has AVX2 (checked once at run time).
        return unsafe { sum_w_avx2(pr, r2) };
    }
    let (sigma, h_inv) = (pr.kernel.sigma, pr.kernel.inv_h);
    match pr.kernel.kind {
        0 => sum_in_order(r2, |r| w_quintic(sigma, h_inv, r)),
        1 => sum_in_order(r2, |r| w_wendland_c2(sigma, h_inv, r)),
        _ => sum_in_order(r2, |r| w_cubic(sigma, h_inv, r)),
    }
}

#[inline(always)]
fn sum_in_order(r2: &[f32], w: impl Fn(f32) -> f32) -> f32 {
    const BLOCK: usize = 64;
    let mut values = [0.0f32; BLOCK];
    let mut sum = 0.0f32;
    for chunk in r2.chunks(BLOCK) {
        for (v, &x) in values.iter_mut().zip(chunk) {
            *v = w(x.sqrt());
        }
        for &v in &values[..chunk.len()] {
            sum += v;
        }
    }
    sum
}

/// `sum_w` eight distances at a time (the tail one at a time), the kernel in
/// eight lanes with the scalar kernel's operations, then added in order.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn sum_w_avx2(pr: &Params, r2: &[f32]) -> f32 {
    use crate::lanes::F8;
    use std::arch::x86_64::{_mm256_loadu_ps, _mm256_sqrt_ps};
    let mut sum = 0.0f32;
    let blocks = r2.chunks_exact(8);
    let tail = blocks.remainder();
    for block in blocks {
        // SAFETY: the block holds eight f32; AVX is enabled here.
        let x = unsafe { _mm256_loadu_ps(block.as_ptr()) };
        let values = w(pr, F8(_mm256_sqrt_ps(x))).to_array();
        for v in values {
            sum += v;
        }
    }
    for &x in tail {
        sum += w(pr, x.sqrt());
    }
    sum
}

/// wt_k W(√r2_k) for the first `len` (≤ 8) entries: eight lanes with AVX2
/// when the block is full, one at a time otherwise, the same operations either
/// way. A Shepard sum Σ V_j W_ij adds them in order (wt = 0 for a neighbour it
/// leaves out: +0, which leaves a sum of non-negative terms as it is).
#[inline(always)]
pub fn weighted_w8(pr: &Params, r2: &[f32; 8], wt: &[f32; 8], len: usize) -> [f32; 8] {
    #[cfg(target_arch = "x86_64")]
    if len == 8 && *crate::lanes::AVX2 {
        // SAFETY: the CPU has AVX2 (checked once at run time).
        return unsafe { weighted_w8_avx2(pr, r2, wt) };
    }
    let mut out = [0.0f32; 8];
    for k in 0..len.min(8) {
        out[k] = wt[k] * w(pr, r2[k].sqrt());
    }
    out
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn weighted_w8_avx2(pr: &Params, r2: &[f32; 8], wt: &[f32; 8]) -> [f32; 8] {
    use crate::lanes::F8;
    (F8::from_array(*wt) * w(pr, F8::from_array(*r2).sqrt())).to_array()
}

/// dW/dr for the kernel chosen in `params.kernel.kind`, on one distance or on
/// eight (`Lane`): the same operations either way. The cubic's two pieces are
/// both evaluated and one is selected, each with the operations a branch has.
#[inline(always)]
pub fn dw<R: Lane>(pr: &Params, r: R) -> R {
    let c = R::splat;
    let sigma_h = c(pr.kernel.sigma * pr.kernel.inv_h);
    let q = r * c(pr.kernel.inv_h);
    match pr.kernel.kind {
        0 => {
            let t1 = (c(1.0) - q).max0();
            let t2 = (c(2.0) - q).max0();
            let t3 = (c(3.0) - q).max0();
            sigma_h * (c(-5.0) * p4(t3) + c(30.0) * p4(t2) - c(75.0) * p4(t1))
        }
        1 => {
            let t = (c(1.0) - c(0.5) * q).max0();
            sigma_h * (c(-5.0) * q * t * t * t)
        }
        _ => {
            let inner = sigma_h * (c(-3.0) * q + c(2.25) * q * q);
            let t = c(2.0) - q;
            let outer = sigma_h * (c(-0.75) * t * t);
            q.where_lt(1.0, inner, q.where_lt(2.0, outer, c(0.0)))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::kernel_sigma;
    use crate::scene::KernelKind;
    use bytemuck::Zeroable;

    fn params(kind: KernelKind, dim: u32, h: f64) -> Params {
        let mut p = Params::zeroed();
        p.sizes.dim = dim;
        p.kernel.kind = kind.code();
        p.kernel.h = h as f32;
        p.kernel.inv_h = (1.0 / h) as f32;
        p.kernel.sigma = kernel_sigma(kind, dim, h) as f32;
        p
    }

    /// ∫W dV = 1 in 2D and 3D for every kernel. Midpoint rule on a fine radial grid:
    /// error O(dr²) ≈ 1e-7 here, far below the 1e-4 tolerance; f32 kernel values add
    /// ~1e-7 relative each.
    #[test]
    fn kernels_are_normalised() {
        for kind in [
            KernelKind::Quintic,
            KernelKind::WendlandC2,
            KernelKind::Cubic,
        ] {
            for dim in [2u32, 3] {
                let h = 0.7;
                let p = params(kind, dim, h);
                let rc = kind.support_factor() * h;
                let n = 20000;
                let dr = rc / n as f64;
                let mut integral = 0.0;
                for k in 0..n {
                    let r = (k as f64 + 0.5) * dr;
                    let shell = if dim == 2 {
                        2.0 * std::f64::consts::PI * r
                    } else {
                        4.0 * std::f64::consts::PI * r * r
                    };
                    integral += w(&p, r as f32) as f64 * shell * dr;
                }
                assert!(
                    (integral - 1.0).abs() < 1e-4,
                    "{kind:?} {dim}D integrates to {integral}"
                );
            }
        }
    }

    /// dW/dr agrees with a central difference of W to 1e-3 relative (step 1e-3 h in
    /// f64 of f32 values: truncation ~1e-6, rounding ~1e-4 relative at worst).
    #[test]
    fn derivative_matches_finite_difference() {
        for kind in [
            KernelKind::Quintic,
            KernelKind::WendlandC2,
            KernelKind::Cubic,
        ] {
            let p = params(kind, 3, 1.0);
            for k in 1..50 {
                let r = k as f32 * 0.05 * kind.support_factor() as f32 / 2.5;
                if r >= kind.support_factor() as f32 {
                    continue;
                }
                let e = 1e-3f32;
                let fd = (w(&p, r + e) as f64 - w(&p, r - e) as f64) / (2.0 * e as f64);
                let an = dw(&p, r) as f64;
                let scale = dw(&p, 0.5 * kind.support_factor() as f32).abs() as f64;
                assert!(
                    (fd - an).abs() < 1e-3 * scale + 1e-3 * an.abs(),
                    "{kind:?} r={r}: fd {fd} vs {an}"
                );
            }
        }
    }

    /// `sum_w` (eight lanes with AVX2) and `dw` on eight lanes give the bits of
    /// the scalar kernels added one neighbour at a time, for every kernel, on
    /// lists of 0 to 40 distances that cross every piece of each kernel and its
    /// support (and r = 0).
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn eight_lanes_give_the_scalar_kernel_bits() {
        use crate::lanes::{AVX2, F8};
        use std::arch::x86_64::_mm256_loadu_ps;
        if !*AVX2 {
            return;
        }
        #[target_feature(enable = "avx2")]
        fn dw8(pr: &Params, r: &[f32; 8]) -> [f32; 8] {
            // SAFETY: AVX2 is enabled in this function; r holds eight f32.
            dw(pr, F8(unsafe { _mm256_loadu_ps(r.as_ptr()) })).to_array()
        }
        for kind in [
            KernelKind::Quintic,
            KernelKind::WendlandC2,
            KernelKind::Cubic,
        ] {
            let h = 0.7;
            let p = params(kind, 3, h);
            let reach = (kind.support_factor() * h * 1.1) as f32;
            let r: Vec<f32> = (0..40)
                .map(|k| ((k * 37 % 41) as f32 / 40.0) * reach)
                .collect();
            for n in 0..=r.len() {
                let r2: Vec<f32> = r[..n].iter().map(|r| r * r).collect();
                let one_by_one = r2.iter().fold(0.0f32, |s, &x| s + w(&p, x.sqrt()));
                assert_eq!(
                    sum_w(&p, &r2).to_bits(),
                    one_by_one.to_bits(),
                    "{kind:?}, {n}"
                );
                // Weights with zeros among them (the neighbours a Shepard sum
                // leaves out): the bits of adding v W one at a time, skipping those.
                let wt: Vec<f32> = (0..n)
                    .map(|k| {
                        if k % 5 == 3 {
                            0.0
                        } else {
                            1.0e-3 * (1 + k % 7) as f32 / 3.0
                        }
                    })
                    .collect();
                let skipping = r2.iter().zip(&wt).fold(0.0f32, |s, (&x, &v)| {
                    if v == 0.0 {
                        s
                    } else {
                        s + v * w(&p, x.sqrt())
                    }
                });
                let mut blocks = 0.0f32;
                for (x, v) in r2.chunks(8).zip(wt.chunks(8)) {
                    let (mut xb, mut vb) = ([0.0f32; 8], [0.0f32; 8]);
                    xb[..x.len()].copy_from_slice(x);
                    vb[..v.len()].copy_from_slice(v);
                    for t in &weighted_w8(&p, &xb, &vb, x.len())[..x.len()] {
                        blocks += t;
                    }
                }
                assert_eq!(blocks.to_bits(), skipping.to_bits(), "{kind:?}, {n}");
            }
            for block in r.chunks_exact(8) {
                let block: [f32; 8] = block.try_into().unwrap();
                // SAFETY: the CPU has AVX2 (checked above).
                let lanes = unsafe { dw8(&p, &block) };
                for (k, &x) in block.iter().enumerate() {
                    assert_eq!(lanes[k].to_bits(), dw(&p, x).to_bits(), "{kind:?}, r = {x}");
                }
            }
        }
    }
}
