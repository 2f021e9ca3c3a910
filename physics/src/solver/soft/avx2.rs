//! The batches' eight lanes as two AVX2 registers (`Lanes` for `F64x8Avx2`), lanes 0–3
//! and 4–7, for the functions compiled with `#[target_feature(enable = "avx2")]` and
//! nothing else: the compiler had vectorised plain arrays there, but not their loads
//! from the bodies, which it split into scalar moves and spilled (a two-point batch of
//! four lanes took ~720 instructions a pass).
//!
//! Each operation is the one instruction whose result is the scalar code's to the bit:
//! `maxpd(a, b)` is `if a > b { a } else { b }`, `minpd(a, b)` is `if a < b { a } else
//! { b }`, comparisons are ordered (false on NaN) except `!=`, and there is no fused
//! multiply–add.
//!
//! Only a function compiled for AVX2 may use this type, and only once the processor is
//! known to have AVX2: its operations are `#[inline(always)]` wrappers of intrinsics that
//! become single instructions when inlined there.

use super::lanes::{F64x8, LANES, LaneMask, Lanes};
use super::{BodyRow, SoftBody};
use std::arch::x86_64::*;
use std::ops::{Add, AddAssign, BitAnd, BitXor, Mul, Neg, Sub, SubAssign};

/// Eight f64 lanes in two 256-bit registers, lanes 0–3 then 4–7; the same size, layout
/// and alignment as `F64x8`.
#[derive(Debug, Clone, Copy)]
#[repr(C, align(64))]
pub(super) struct F64x8Avx2(__m256d, __m256d);

/// A lane-wise condition: all ones or all zeros per lane, in the lanes' two halves.
#[derive(Debug, Clone, Copy)]
pub(super) struct MaskAvx2(__m256d, __m256d);

const _: () = {
    use std::mem::{align_of, size_of};
    assert!(size_of::<F64x8Avx2>() == size_of::<F64x8>());
    assert!(align_of::<F64x8Avx2>() == align_of::<F64x8>());
};

// SAFETY (every `unsafe` block below): the intrinsics need AVX2, which the functions this
// type is used in are compiled for and only called with (`ManifoldBatch::as_avx2`); the
// aligned loads and stores touch only the 32-byte rows `row` and `row_mut` name, which lie
// inside their bodies at 0 or 32 bytes from the start of a 32-byte-aligned `SoftBody`, and
// the bodies lie inside the slice (`Lanes::gather`'s precondition).

/// Row `k` of four becomes lane `k` of each column (and back: it is its own inverse).
#[inline(always)]
fn transpose([r0, r1, r2, r3]: [__m256d; 4]) -> [__m256d; 4] {
    unsafe {
        let t0 = _mm256_unpacklo_pd(r0, r1);
        let t1 = _mm256_unpackhi_pd(r0, r1);
        let t2 = _mm256_unpacklo_pd(r2, r3);
        let t3 = _mm256_unpackhi_pd(r2, r3);
        [
            _mm256_permute2f128_pd::<0x20>(t0, t2),
            _mm256_permute2f128_pd::<0x20>(t1, t3),
            _mm256_permute2f128_pd::<0x31>(t0, t2),
            _mm256_permute2f128_pd::<0x31>(t1, t3),
        ]
    }
}

/// Where the 32-byte row `row` of the body `index` names starts. Not bounds-checked:
/// `gather`'s caller guarantees `index < bodies.len()` (`Lanes::gather`).
#[inline(always)]
fn row(bodies: &[SoftBody], index: u32, row: BodyRow) -> *const f64 {
    let body: *const SoftBody = bodies.as_ptr().wrapping_add(index as usize);
    body.cast::<f64>().wrapping_add(SoftBody::row_offset(row))
}

/// `row`, to write through: made from the mutable borrow, not a shared one.
#[inline(always)]
fn row_mut(bodies: &mut [SoftBody], index: u32, row: BodyRow) -> *mut f64 {
    let body: *mut SoftBody = bodies.as_mut_ptr().wrapping_add(index as usize);
    body.cast::<f64>().wrapping_add(SoftBody::row_offset(row))
}

/// `f` on each half of `a` and `b`'s lanes.
#[inline(always)]
fn halves(a: F64x8Avx2, b: F64x8Avx2, f: impl Fn(__m256d, __m256d) -> __m256d) -> F64x8Avx2 {
    F64x8Avx2(f(a.0, b.0), f(a.1, b.1))
}

/// The comparison `f` on each half, as a mask.
#[inline(always)]
fn compare(a: F64x8Avx2, b: F64x8Avx2, f: impl Fn(__m256d, __m256d) -> __m256d) -> MaskAvx2 {
    MaskAvx2(f(a.0, b.0), f(a.1, b.1))
}

impl Lanes for F64x8Avx2 {
    type Mask = MaskAvx2;

    #[inline(always)]
    fn splat(x: f64) -> Self {
        let x = unsafe { _mm256_set1_pd(x) };
        Self(x, x)
    }

    #[inline(always)]
    fn max(self, rhs: Self) -> Self {
        halves(self, rhs, |a, b| unsafe { _mm256_max_pd(a, b) })
    }

    #[inline(always)]
    fn min(self, rhs: Self) -> Self {
        halves(self, rhs, |a, b| unsafe { _mm256_min_pd(a, b) })
    }

    #[inline(always)]
    fn clamp(self, lo: Self, hi: Self) -> Self {
        hi.min(self).max_of(lo)
    }

    #[inline(always)]
    fn sqrt(self) -> Self {
        Self(unsafe { _mm256_sqrt_pd(self.0) }, unsafe {
            _mm256_sqrt_pd(self.1)
        })
    }

    #[inline(always)]
    fn gt(self, rhs: Self) -> MaskAvx2 {
        compare(self, rhs, |a, b| unsafe {
            _mm256_cmp_pd::<_CMP_GT_OQ>(a, b)
        })
    }

    #[inline(always)]
    fn ge(self, rhs: Self) -> MaskAvx2 {
        compare(self, rhs, |a, b| unsafe {
            _mm256_cmp_pd::<_CMP_GE_OQ>(a, b)
        })
    }

    #[inline(always)]
    fn lt(self, rhs: Self) -> MaskAvx2 {
        compare(self, rhs, |a, b| unsafe {
            _mm256_cmp_pd::<_CMP_LT_OQ>(a, b)
        })
    }

    #[inline(always)]
    fn eq(self, rhs: Self) -> MaskAvx2 {
        compare(self, rhs, |a, b| unsafe {
            _mm256_cmp_pd::<_CMP_EQ_OQ>(a, b)
        })
    }

    #[inline(always)]
    fn ne(self, rhs: Self) -> MaskAvx2 {
        compare(self, rhs, |a, b| unsafe {
            _mm256_cmp_pd::<_CMP_NEQ_UQ>(a, b)
        })
    }

    #[inline(always)]
    unsafe fn gather(bodies: &[SoftBody], index: &[u32; LANES], which: BodyRow) -> [Self; 4] {
        // Written out: `array::map` was left out of line here.
        let load = |k: usize| unsafe { _mm256_load_pd(row(bodies, index[k], which)) };
        let [a0, a1, a2, a3] = transpose([load(0), load(1), load(2), load(3)]);
        let [b0, b1, b2, b3] = transpose([load(4), load(5), load(6), load(7)]);
        [Self(a0, b0), Self(a1, b1), Self(a2, b2), Self(a3, b3)]
    }

    #[inline(always)]
    unsafe fn scatter_velocities(
        columns: [Self; 4],
        bodies: &mut [SoftBody],
        index: &[u32; LANES],
    ) {
        let [c0, c1, c2, c3] = columns;
        let low = transpose([c0.0, c1.0, c2.0, c3.0]);
        let high = transpose([c0.1, c1.1, c2.1, c3.1]);
        for (k, row) in low.into_iter().chain(high).enumerate() {
            let at = row_mut(bodies, index[k], BodyRow::Velocity);
            unsafe { _mm256_store_pd(at, row) };
        }
    }
}

impl F64x8Avx2 {
    /// `if lo > self { lo } else { self }`, the lower bound of `clamp`.
    #[inline(always)]
    fn max_of(self, lo: Self) -> Self {
        halves(lo, self, |a, b| unsafe { _mm256_max_pd(a, b) })
    }
}

impl LaneMask<F64x8Avx2> for MaskAvx2 {
    #[inline(always)]
    fn any(self) -> bool {
        unsafe { _mm256_movemask_pd(_mm256_or_pd(self.0, self.1)) != 0 }
    }

    #[inline(always)]
    fn select(self, if_true: F64x8Avx2, if_false: F64x8Avx2) -> F64x8Avx2 {
        F64x8Avx2(
            unsafe { _mm256_blendv_pd(if_false.0, if_true.0, self.0) },
            unsafe { _mm256_blendv_pd(if_false.1, if_true.1, self.1) },
        )
    }
}

impl BitAnd for MaskAvx2 {
    type Output = Self;
    #[inline(always)]
    fn bitand(self, rhs: Self) -> Self {
        Self(unsafe { _mm256_and_pd(self.0, rhs.0) }, unsafe {
            _mm256_and_pd(self.1, rhs.1)
        })
    }
}

impl BitXor for MaskAvx2 {
    type Output = Self;
    #[inline(always)]
    fn bitxor(self, rhs: Self) -> Self {
        Self(unsafe { _mm256_xor_pd(self.0, rhs.0) }, unsafe {
            _mm256_xor_pd(self.1, rhs.1)
        })
    }
}

macro_rules! lane_op {
    ($trait:ident, $method:ident, $assign_trait:ident, $assign:ident, $intrinsic:ident) => {
        impl $trait for F64x8Avx2 {
            type Output = Self;
            #[inline(always)]
            fn $method(self, rhs: Self) -> Self {
                halves(self, rhs, |a, b| unsafe { $intrinsic(a, b) })
            }
        }

        impl $assign_trait for F64x8Avx2 {
            #[inline(always)]
            fn $assign(&mut self, rhs: Self) {
                *self = halves(*self, rhs, |a, b| unsafe { $intrinsic(a, b) });
            }
        }
    };
}

lane_op!(Add, add, AddAssign, add_assign, _mm256_add_pd);
lane_op!(Sub, sub, SubAssign, sub_assign, _mm256_sub_pd);

impl Mul for F64x8Avx2 {
    type Output = Self;
    #[inline(always)]
    fn mul(self, rhs: Self) -> Self {
        halves(self, rhs, |a, b| unsafe { _mm256_mul_pd(a, b) })
    }
}

impl Neg for F64x8Avx2 {
    type Output = Self;
    /// The sign bit flipped, as `-x` does.
    #[inline(always)]
    fn neg(self) -> Self {
        let sign = unsafe { _mm256_set1_pd(-0.0) };
        Self(unsafe { _mm256_xor_pd(self.0, sign) }, unsafe {
            _mm256_xor_pd(self.1, sign)
        })
    }
}
