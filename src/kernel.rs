//! Smoothing kernels, CPU side. Twin of shaders/lib/kernel.wgsl: same formulas in the
//! same operation order (no mul_add), so both give the same bits (DESIGN rule 1).

use crate::params::Params;

#[inline(always)]
fn p4(t: f32) -> f32 {
    t * t * t * t
}

#[inline(always)]
fn p5(t: f32) -> f32 {
    t * t * t * t * t
}

/// W(r) for the kernel chosen in `params.kernel.kind`.
#[inline(always)]
pub fn w(pr: &Params, r: f32) -> f32 {
    let (sigma, h_inv) = (pr.kernel.sigma, pr.kernel.inv_h);
    match pr.kernel.kind {
        0 => w_quintic(sigma, h_inv, r),
        1 => w_wendland_c2(sigma, h_inv, r),
        _ => w_cubic(sigma, h_inv, r),
    }
}

#[inline(always)]
fn w_quintic(sigma: f32, h_inv: f32, r: f32) -> f32 {
    let q = r * h_inv;
    let t1 = (1.0 - q).max(0.0);
    let t2 = (2.0 - q).max(0.0);
    let t3 = (3.0 - q).max(0.0);
    sigma * (p5(t3) - 6.0 * p5(t2) + 15.0 * p5(t1))
}

#[inline(always)]
fn w_wendland_c2(sigma: f32, h_inv: f32, r: f32) -> f32 {
    let q = r * h_inv;
    let t = (1.0 - 0.5 * q).max(0.0);
    sigma * p4(t) * (2.0 * q + 1.0)
}

/// Both pieces are evaluated and one is selected, so that a batch of these
/// vectorises; each piece has the same operations as a branch would.
#[inline(always)]
fn w_cubic(sigma: f32, h_inv: f32, r: f32) -> f32 {
    let q = r * h_inv;
    let inner = sigma * (1.0 - 1.5 * q * q + 0.75 * q * q * q);
    let t = 2.0 - q;
    let outer = sigma * 0.25 * t * t * t;
    if q < 1.0 {
        inner
    } else if q < 2.0 {
        outer
    } else {
        0.0
    }
}

/// Σ_k W(√r2_k) summed in the order given: the same bits as adding `w` one
/// neighbour at a time. The kernel values of a block are computed first, in a
/// loop without branches that the compiler vectorises (4 lanes with SSE2), and
/// then added in order.
pub fn sum_w(pr: &Params, r2: &[f32]) -> f32 {
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

/// dW/dr for the kernel chosen in `params.kernel.kind`.
#[inline(always)]
pub fn dw(pr: &Params, r: f32) -> f32 {
    let sigma_h = pr.kernel.sigma * pr.kernel.inv_h;
    let q = r * pr.kernel.inv_h;
    match pr.kernel.kind {
        0 => {
            let t1 = (1.0 - q).max(0.0);
            let t2 = (2.0 - q).max(0.0);
            let t3 = (3.0 - q).max(0.0);
            sigma_h * (-5.0 * p4(t3) + 30.0 * p4(t2) - 75.0 * p4(t1))
        }
        1 => {
            let t = (1.0 - 0.5 * q).max(0.0);
            sigma_h * (-5.0 * q * t * t * t)
        }
        _ => {
            if q < 1.0 {
                sigma_h * (-3.0 * q + 2.25 * q * q)
            } else if q < 2.0 {
                let t = 2.0 - q;
                sigma_h * (-0.75 * t * t)
            } else {
                0.0
            }
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
}
