//! Portable exp, ln and pow: built from + − × ÷, floor and bit manipulation only,
//! written once here and once in shaders/lib/math.wgsl with the same operations
//! in the same order, so both backends give the same bits (DESIGN rule 2; built-in
//! WGSL exp/pow differ from Rust by a few ULP). The shader reads every coefficient
//! from the parameter block (see params::SHADER_CONSTS); these are the same f32s.
//!
//! Domain: exp for any x (saturating to 0 below −87.3 and to +inf above 88);
//! ln for positive normal x (0 → −inf, negative or NaN → NaN, subnormals unsupported);
//! pow(x, y) = exp(y ln x) for x > 0.

pub const LOG2E: f32 = std::f32::consts::LOG2_E;
/// ln 2 split so n·LN2_HI is exact for |n| < 2^11 (Cody–Waite reduction).
pub const LN2_HI: f32 = 0.693_359_4;
pub const LN2_LO: f32 = -2.121_944_4e-4;
/// Taylor coefficients 1/k! for k = 2..7 of e^r on |r| ≤ ln2/2 (truncation < 2e-9).
pub const EXP_C: [f32; 6] = [
    0.5,
    1.0 / 6.0,
    1.0 / 24.0,
    1.0 / 120.0,
    1.0 / 720.0,
    1.0 / 5040.0,
];
/// 1/(2k+1) for k = 1..5: ln(1+f) = 2s(1 + s²/3 + s⁴/5 + …), s = f/(2+f), |s| ≤ 0.172.
pub const LN_C: [f32; 5] = [1.0 / 3.0, 1.0 / 5.0, 1.0 / 7.0, 1.0 / 9.0, 1.0 / 11.0];

/// Odd Taylor coefficients of sin θ, −1/3!, 1/5!, …, −1/11!, on |θ| ≤ π/2
/// (truncation θ¹³/13! < 6e-8).
pub const SIN_C: [f32; 5] = [
    -1.0 / 6.0,
    1.0 / 120.0,
    -1.0 / 5040.0,
    1.0 / 362_880.0,
    -1.0 / 39_916_800.0,
];

const EXP_MAX: f32 = 88.0;
const EXP_MIN: f32 = -87.3;

pub fn exp(x: f32) -> f32 {
    if x.is_nan() {
        return x;
    }
    if x > EXP_MAX {
        return f32::INFINITY;
    }
    if x < EXP_MIN {
        return 0.0;
    }
    let n = (x * LOG2E + EXP_C[0]).floor();
    let r = (x - n * LN2_HI) - n * LN2_LO;
    let c = &EXP_C;
    let p =
        1.0 + r * (1.0 + r * (c[0] + r * (c[1] + r * (c[2] + r * (c[3] + r * (c[4] + r * c[5]))))));
    let scale = f32::from_bits(((n as i32 + 127) as u32) << 23);
    p * scale
}

pub fn ln(x: f32) -> f32 {
    if !(x > 0.0) {
        return if x == 0.0 {
            f32::NEG_INFINITY
        } else {
            f32::NAN
        };
    }
    if x == f32::INFINITY {
        return x;
    }
    let bits = x.to_bits();
    let mut e = ((bits >> 23) & 0xff) as i32 - 127;
    let mut m = f32::from_bits((bits & 0x007f_ffff) | 0x3f80_0000);
    if m > std::f32::consts::SQRT_2 {
        m *= 0.5;
        e += 1;
    }
    let f = m - 1.0;
    let s = f / (2.0 + f);
    let z = s * s;
    let c = &LN_C;
    let poly = 1.0 + z * (c[0] + z * (c[1] + z * (c[2] + z * (c[3] + z * c[4]))));
    let lnm = (s + s) * poly;
    let ef = e as f32;
    ef * LN2_HI + (ef * LN2_LO + lnm)
}

pub fn pow(x: f32, y: f32) -> f32 {
    exp(y * ln(x))
}

/// M g = b for the symmetric M = (xx, xy, xz, yy, yz, zz), by cofactors (the
/// 2×2 block in 2D); 0 where |det M| ≤ 1e-3. The renormalised gradients
/// (continuity's density, the solidification record's temperature). Twin of
/// `solve_symmetric` in shaders/lib/math.wgsl.
pub fn solve_symmetric(dim: u32, m: [f32; 6], b: [f32; 3]) -> [f32; 3] {
    let [xx, xy, xz, yy, yz, zz] = m;
    let mut g = [0.0f32; 3];
    if dim == 2 {
        let det = xx * yy - xy * xy;
        if det.abs() > 1.0e-3 {
            g[0] = (yy * b[0] - xy * b[1]) / det;
            g[1] = (xx * b[1] - xy * b[0]) / det;
        }
        return g;
    }
    let c00 = yy * zz - yz * yz;
    let c01 = xz * yz - xy * zz;
    let c02 = xy * yz - xz * yy;
    let c11 = xx * zz - xz * xz;
    let c12 = xy * xz - xx * yz;
    let c22 = xx * yy - xy * xy;
    let det = xx * c00 + xy * c01 + xz * c02;
    if det.abs() > 1.0e-3 {
        g[0] = (c00 * b[0] + c01 * b[1] + c02 * b[2]) / det;
        g[1] = (c01 * b[0] + c11 * b[1] + c12 * b[2]) / det;
        g[2] = (c02 * b[0] + c12 * b[1] + c22 * b[2]) / det;
    }
    g
}

/// sin(2π x) for x in cycles (a temperature program's phase t/P): x reduced to
/// f ∈ [−¼, ¼] by sin's period and its symmetry about ¼ cycle, then the
/// Taylor polynomial of θ = 2π f. Finite x only; |x| up to 2^22 keeps f to
/// 2^-2 cycles' ULP (a program runs a few hundred cycles).
pub fn sin_cycles(x: f32) -> f32 {
    let mut f = x - (x + 0.5).floor();
    if f > 0.25 {
        f = 0.5 - f;
    } else if f < -0.25 {
        f = -0.5 - f;
    }
    let th = f * std::f32::consts::TAU;
    let z = th * th;
    let c = &SIN_C;
    let p = c[0] + z * (c[1] + z * (c[2] + z * (c[3] + z * c[4])));
    th + th * (z * p)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ulps(a: f32, b: f64) -> f64 {
        let ulp = (b.abs() as f32).max(f32::MIN_POSITIVE);
        let ulp = f32::from_bits(ulp.to_bits() + 1) - ulp;
        (a as f64 - b).abs() / ulp as f64
    }

    /// exp within 3 ULP of the f64 result over its whole range: reduction error
    /// ~1 ULP, Taylor truncation < 2e-9, Horner rounding ~1 ULP.
    #[test]
    fn exp_within_3_ulp() {
        let mut worst: f64 = 0.0;
        for k in 0..200_000 {
            let x = -87.0 + 175.0 * k as f32 / 200_000.0;
            worst = worst.max(ulps(exp(x), (x as f64).exp()));
        }
        assert!(worst <= 3.0, "exp worst {worst} ULP");
        assert_eq!(exp(0.0), 1.0);
        assert_eq!(exp(100.0), f32::INFINITY);
        assert_eq!(exp(-100.0), 0.0);
    }

    /// sin(2π x) within 3e-7 absolute over −3..100 cycles, against the f64 sine
    /// of the same f32 x: the reduction f = x − ⌊x + ½⌋ is exact (Sterbenz), then
    /// θ = 2π f (½ ULP of 1.6), the truncation (< 6e-8) and Horner (~2 ULP of 1).
    #[test]
    fn sin_cycles_accurate() {
        let mut worst: f64 = 0.0;
        for k in 0..400_000 {
            let x = -3.0 + 103.0 * k as f32 / 400_000.0;
            let exact = (std::f64::consts::TAU * x as f64).sin();
            worst = worst.max((sin_cycles(x) as f64 - exact).abs());
        }
        assert!(worst <= 3e-7, "sin worst {worst}");
        assert_eq!(sin_cycles(0.0), 0.0);
        assert!((sin_cycles(0.25) - 1.0).abs() <= 1.2e-7);
        assert!((sin_cycles(-0.25) + 1.0).abs() <= 1.2e-7);
    }

    /// ln within 2e-7 absolute near 1 and 3 ULP elsewhere, over 1e-37 .. 1e38.
    #[test]
    fn ln_accurate() {
        let mut worst: f64 = 0.0;
        for k in 0..200_000 {
            let x = (10f64.powf(-37.0 + 75.0 * k as f64 / 200_000.0)) as f32;
            let r = (x as f64).ln();
            let err = if r.abs() < 0.5 {
                (ln(x) as f64 - r).abs() / 2e-7 * 3.0
            } else {
                ulps(ln(x), r)
            };
            worst = worst.max(err);
        }
        assert!(worst <= 3.0, "ln worst {worst} (ULP or scaled absolute)");
        assert_eq!(ln(1.0), 0.0);
        assert!(ln(-1.0).is_nan());
        assert_eq!(ln(0.0), f32::NEG_INFINITY);
    }

    /// pow = exp(y ln x) in f32: an error of k ULP in the f32 product y·ln x becomes
    /// a relative error k·|y ln x|·2⁻²⁴ of the result. With ln within 3 ULP and the
    /// product's rounding (½ ULP), k ≤ 4; exp adds its own 3 ULP. Each sample must be
    /// within (4|y ln x| + 4)·2⁻²⁴; the test reports the worst ratio to that bound.
    #[test]
    fn pow_relative_error_within_propagation_bound() {
        let eps = 2f64.powi(-24);
        let mut worst: f64 = 0.0;
        for i in 1..300 {
            for j in -40..=40 {
                let (x, y) = (i as f32 * 0.37, j as f32 * 0.173);
                let arg = y as f64 * (x as f64).ln();
                if arg.abs() > 80.0 {
                    continue;
                }
                let r = (x as f64).powf(y as f64);
                let bound = (4.0 * arg.abs() + 4.0) * eps;
                worst = worst.max((pow(x, y) as f64 - r).abs() / r / bound);
            }
        }
        assert!(
            worst <= 1.0,
            "pow exceeds the error-propagation bound by {worst}x"
        );
    }
}
