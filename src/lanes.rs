//! Arithmetic on one f32 or on eight at once (AVX2), so that a kernel or a pair
//! term is written once and serves both the scalar CPU sweeps and the 8-wide
//! ones. Each operation is the same IEEE operation lane by lane (an f32 add is
//! `addss` or one lane of `vaddps`; nothing is fused), so a term evaluated on
//! eight neighbours gives, lane by lane, the bits it gives on one.

use std::ops::{Add, Div, Mul, Neg, Sub};

/// A number the kernels and pair terms compute with: `f32`, or `F8` (eight f32).
pub trait Lane:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// The value x in every lane.
    fn splat(x: f32) -> Self;
    /// max(x, 0) per lane, and 0 for a NaN (as `f32::max(x, 0.0)`).
    fn max0(self) -> Self;
    /// Per lane: `then` where self < bound, else `other` (`other` for a NaN).
    fn where_lt(self, bound: f32, then: Self, other: Self) -> Self;
    /// The correctly rounded square root (`sqrtss`, or one lane of `vsqrtps`).
    fn sqrt(self) -> Self;
}

impl Lane for f32 {
    #[inline(always)]
    fn splat(x: f32) -> Self {
        x
    }
    #[inline(always)]
    fn max0(self) -> Self {
        self.max(0.0)
    }
    #[inline(always)]
    fn where_lt(self, bound: f32, then: Self, other: Self) -> Self {
        if self < bound {
            then
        } else {
            other
        }
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f32::sqrt(self)
    }
}

#[cfg(target_arch = "x86_64")]
pub(crate) use avx::F8;
#[cfg(target_arch = "x86_64")]
pub use avx::{AVX2, AVX512};

#[cfg(target_arch = "x86_64")]
mod avx {
    use super::Lane;
    use std::arch::x86_64::*;
    use std::ops::{Add, Div, Mul, Neg, Sub};

    /// Whether this CPU has AVX2 and POPCNT (checked once, at first use; every
    /// AVX2 CPU has POPCNT, which the neighbour compaction counts lanes with).
    pub static AVX2: std::sync::LazyLock<bool> = std::sync::LazyLock::new(|| {
        std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("popcnt")
    });

    /// Whether this CPU has AVX-512F as well (checked once): the neighbour
    /// sweeps then compare sixteen candidates at a time and pack the hits with
    /// one compress instruction each.
    pub static AVX512: std::sync::LazyLock<bool> =
        std::sync::LazyLock::new(|| *AVX2 && std::arch::is_x86_feature_detected!("avx512f"));

    /// Eight f32 in one AVX register. Private to the crate, whose code makes
    /// one only inside `#[target_feature(enable = "avx2")]` functions reached
    /// after the `AVX2` check (`F8::splat` and the operators are safe to call
    /// but execute AVX instructions); each operation is `#[inline(always)]` so
    /// that it is compiled into that caller with its features.
    #[derive(Clone, Copy)]
    pub(crate) struct F8(pub(crate) __m256);

    impl F8 {
        /// Eight lanes into a register (gathered scalars).
        #[inline(always)]
        pub(crate) fn from_array(x: [f32; 8]) -> F8 {
            // SAFETY: as the operators below: an F8 is made only where AVX is
            // enabled; the load reads the eight f32 of `x`.
            F8(unsafe { _mm256_loadu_ps(x.as_ptr()) })
        }
        /// The register as eight lanes (for tests and scalar tails).
        #[inline(always)]
        pub(crate) fn to_array(self) -> [f32; 8] {
            // SAFETY: __m256 and [f32; 8] have the same size, any bits are valid.
            unsafe { std::mem::transmute::<__m256, [f32; 8]>(self.0) }
        }
    }

    macro_rules! binary {
        ($trait:ident, $method:ident, $intrinsic:ident) => {
            impl $trait for F8 {
                type Output = F8;
                #[inline(always)]
                fn $method(self, rhs: F8) -> F8 {
                    // SAFETY: an F8 exists only where AVX is enabled (above).
                    F8(unsafe { $intrinsic(self.0, rhs.0) })
                }
            }
        };
    }
    binary!(Add, add, _mm256_add_ps);
    binary!(Sub, sub, _mm256_sub_ps);
    binary!(Mul, mul, _mm256_mul_ps);
    binary!(Div, div, _mm256_div_ps);

    impl Neg for F8 {
        type Output = F8;
        /// The sign bit flipped, as the scalar negation (exact).
        #[inline(always)]
        fn neg(self) -> F8 {
            // SAFETY: as above.
            F8(unsafe { _mm256_xor_ps(self.0, _mm256_set1_ps(-0.0)) })
        }
    }

    impl Lane for F8 {
        #[inline(always)]
        fn splat(x: f32) -> Self {
            // SAFETY: as above.
            F8(unsafe { _mm256_set1_ps(x) })
        }
        /// `vmaxps(x, 0)` returns its second operand, 0, when x is a NaN.
        #[inline(always)]
        fn max0(self) -> Self {
            // SAFETY: as above.
            F8(unsafe { _mm256_max_ps(self.0, _mm256_setzero_ps()) })
        }
        #[inline(always)]
        fn where_lt(self, bound: f32, then: Self, other: Self) -> Self {
            // SAFETY: as above.
            F8(unsafe {
                let lt = _mm256_cmp_ps::<_CMP_LT_OQ>(self.0, _mm256_set1_ps(bound));
                _mm256_blendv_ps(other.0, then.0, lt)
            })
        }
        #[inline(always)]
        fn sqrt(self) -> Self {
            // SAFETY: as above.
            F8(unsafe { _mm256_sqrt_ps(self.0) })
        }
    }
}

#[cfg(all(test, target_arch = "x86_64"))]
mod tests {
    use super::*;
    use std::arch::x86_64::*;

    /// Each operation gives, lane by lane, the scalar operation's bits, on
    /// values that exercise rounding, NaN, ±0 and the select's edges.
    #[test]
    fn eight_lanes_give_the_scalar_bits() {
        if !*AVX2 {
            return;
        }
        let a = [
            1.0f32 / 3.0,
            -2.5,
            0.0,
            -0.0,
            f32::NAN,
            7.0e-39,
            3.0e38,
            1.0,
        ];
        let b = [7.0f32, 1.0e-3, -0.0, 2.0, 1.0, 3.0, 0.1, 1.0];
        // a also holds a negative (sqrt: NaN), ±0 and a subnormal.
        #[target_feature(enable = "avx2")]
        fn lanes(a: [f32; 8], b: [f32; 8]) -> [[f32; 8]; 10] {
            // SAFETY: AVX2 is enabled in this function.
            let (x, y) = unsafe {
                (
                    F8(_mm256_loadu_ps(a.as_ptr())),
                    F8(_mm256_loadu_ps(b.as_ptr())),
                )
            };
            [
                (x + y).to_array(),
                (x - y).to_array(),
                (x * y).to_array(),
                (x / y).to_array(),
                (-x).to_array(),
                x.max0().to_array(),
                x.where_lt(1.0, x, y).to_array(),
                (F8::splat(2.0) * x).to_array(),
                x.sqrt().to_array(),
                F8::from_array(b).to_array(),
            ]
        }
        // SAFETY: the CPU has AVX2 (checked above).
        let got = unsafe { lanes(a, b) };
        for k in 0..8 {
            let (x, y) = (a[k], b[k]);
            let want = [
                x + y,
                x - y,
                x * y,
                x / y,
                -x,
                x.max0(),
                x.where_lt(1.0, x, y),
                2.0 * x,
                x.sqrt(),
                y,
            ];
            for (op, w) in want.iter().enumerate() {
                assert_eq!(got[op][k].to_bits(), w.to_bits(), "op {op}, lane {k}");
            }
        }
    }
}
