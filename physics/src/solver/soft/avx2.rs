//! The batches' lanes as one AVX2 register (`Lanes` for `F64x4Avx2`), for the functions
//! compiled with `#[target_feature(enable = "avx2")]` and nothing else: the compiler had
//! vectorised `F64x4`'s arrays there, but not their loads from four bodies, which it
//! split into scalar moves and spilled (a two-point batch's pass took ~720 instructions).
//!
//! Each operation is the one instruction whose result is the scalar code's to the bit:
//! `maxpd(a, b)` is `if a > b { a } else { b }`, `minpd(a, b)` is `if a < b { a } else
//! { b }`, comparisons are ordered (false on NaN) except `!=`, and there is no fused
//! multiply–add.
//!
//! Only a function compiled for AVX2 may use this type, and only once the processor is
//! known to have AVX2: its operations are `#[inline(always)]` wrappers of intrinsics that
//! become single instructions when inlined there.

use super::f64x4::{F64x4, LaneMask, Lanes};
use super::{BodyRow, SoftBody};
use std::arch::x86_64::*;
use std::ops::{Add, AddAssign, BitAnd, BitXor, Mul, Neg, Sub, SubAssign};

/// Four f64 lanes in a 256-bit register; the same size and alignment as `F64x4`.
#[derive(Debug, Clone, Copy)]
#[repr(transparent)]
pub(super) struct F64x4Avx2(__m256d);

/// A lane-wise condition: all ones or all zeros per lane.
#[derive(Debug, Clone, Copy)]
#[repr(transparent)]
pub(super) struct MaskAvx2(__m256d);

const _: () = {
    use std::mem::{align_of, size_of};
    assert!(size_of::<F64x4Avx2>() == size_of::<F64x4>());
    assert!(align_of::<F64x4Avx2>() == align_of::<F64x4>());
};

// SAFETY (every `unsafe` block below): the intrinsics need AVX2, which the functions this
// type is used in are compiled for and only called with (`ManifoldBatch::as_avx2`); the
// aligned loads and stores touch only the 32-byte rows `row` and `row_mut` name, which lie
// inside their bodies at 0 or 32 bytes from the start of a 32-byte-aligned `SoftBody`.

/// Row `k` of the four becomes lane `k` of each column (and back: it is its own inverse).
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

/// Where the 32-byte row `row` of the body `index` names starts (bounds-checked).
#[inline(always)]
fn row(bodies: &[SoftBody], index: u32, row: BodyRow) -> *const f64 {
    let body: *const SoftBody = &bodies[index as usize];
    body.cast::<f64>().wrapping_add(SoftBody::row_offset(row))
}

/// `row`, to write through: made from the mutable borrow, not a shared one.
#[inline(always)]
fn row_mut(bodies: &mut [SoftBody], index: u32, row: BodyRow) -> *mut f64 {
    let body: *mut SoftBody = &mut bodies[index as usize];
    body.cast::<f64>().wrapping_add(SoftBody::row_offset(row))
}

impl Lanes for F64x4Avx2 {
    type Mask = MaskAvx2;

    #[inline(always)]
    fn splat(x: f64) -> Self {
        Self(unsafe { _mm256_set1_pd(x) })
    }

    #[inline(always)]
    fn max(self, rhs: Self) -> Self {
        Self(unsafe { _mm256_max_pd(self.0, rhs.0) })
    }

    #[inline(always)]
    fn min(self, rhs: Self) -> Self {
        Self(unsafe { _mm256_min_pd(self.0, rhs.0) })
    }

    #[inline(always)]
    fn clamp(self, lo: Self, hi: Self) -> Self {
        hi.min(self).max_of(lo)
    }

    #[inline(always)]
    fn sqrt(self) -> Self {
        Self(unsafe { _mm256_sqrt_pd(self.0) })
    }

    #[inline(always)]
    fn gt(self, rhs: Self) -> MaskAvx2 {
        MaskAvx2(unsafe { _mm256_cmp_pd::<_CMP_GT_OQ>(self.0, rhs.0) })
    }

    #[inline(always)]
    fn ge(self, rhs: Self) -> MaskAvx2 {
        MaskAvx2(unsafe { _mm256_cmp_pd::<_CMP_GE_OQ>(self.0, rhs.0) })
    }

    #[inline(always)]
    fn lt(self, rhs: Self) -> MaskAvx2 {
        MaskAvx2(unsafe { _mm256_cmp_pd::<_CMP_LT_OQ>(self.0, rhs.0) })
    }

    #[inline(always)]
    fn eq(self, rhs: Self) -> MaskAvx2 {
        MaskAvx2(unsafe { _mm256_cmp_pd::<_CMP_EQ_OQ>(self.0, rhs.0) })
    }

    #[inline(always)]
    fn ne(self, rhs: Self) -> MaskAvx2 {
        MaskAvx2(unsafe { _mm256_cmp_pd::<_CMP_NEQ_UQ>(self.0, rhs.0) })
    }

    #[inline(always)]
    fn gather(bodies: &[SoftBody], index: &[u32; 4], which: BodyRow) -> [Self; 4] {
        // Written out: `array::map` was left out of line here.
        let load = |k: usize| unsafe { _mm256_load_pd(row(bodies, index[k], which)) };
        let [c0, c1, c2, c3] = transpose([load(0), load(1), load(2), load(3)]);
        [Self(c0), Self(c1), Self(c2), Self(c3)]
    }

    #[inline(always)]
    fn scatter_velocities(columns: [Self; 4], bodies: &mut [SoftBody], index: &[u32; 4]) {
        let [c0, c1, c2, c3] = columns;
        let rows = transpose([c0.0, c1.0, c2.0, c3.0]);
        for k in 0..4 {
            let at = row_mut(bodies, index[k], BodyRow::Velocity);
            unsafe { _mm256_store_pd(at, rows[k]) };
        }
    }
}

impl F64x4Avx2 {
    /// `if lo > self { lo } else { self }`, the lower bound of `clamp`.
    #[inline(always)]
    fn max_of(self, lo: Self) -> Self {
        Self(unsafe { _mm256_max_pd(lo.0, self.0) })
    }
}

impl LaneMask<F64x4Avx2> for MaskAvx2 {
    #[inline(always)]
    fn any(self) -> bool {
        unsafe { _mm256_movemask_pd(self.0) != 0 }
    }

    #[inline(always)]
    fn select(self, if_true: F64x4Avx2, if_false: F64x4Avx2) -> F64x4Avx2 {
        F64x4Avx2(unsafe { _mm256_blendv_pd(if_false.0, if_true.0, self.0) })
    }
}

impl BitAnd for MaskAvx2 {
    type Output = Self;
    #[inline(always)]
    fn bitand(self, rhs: Self) -> Self {
        Self(unsafe { _mm256_and_pd(self.0, rhs.0) })
    }
}

impl BitXor for MaskAvx2 {
    type Output = Self;
    #[inline(always)]
    fn bitxor(self, rhs: Self) -> Self {
        Self(unsafe { _mm256_xor_pd(self.0, rhs.0) })
    }
}

macro_rules! lane_op {
    ($trait:ident, $method:ident, $assign_trait:ident, $assign:ident, $intrinsic:ident) => {
        impl $trait for F64x4Avx2 {
            type Output = Self;
            #[inline(always)]
            fn $method(self, rhs: Self) -> Self {
                Self(unsafe { $intrinsic(self.0, rhs.0) })
            }
        }

        impl $assign_trait for F64x4Avx2 {
            #[inline(always)]
            fn $assign(&mut self, rhs: Self) {
                *self = Self(unsafe { $intrinsic(self.0, rhs.0) });
            }
        }
    };
}

lane_op!(Add, add, AddAssign, add_assign, _mm256_add_pd);
lane_op!(Sub, sub, SubAssign, sub_assign, _mm256_sub_pd);

impl Mul for F64x4Avx2 {
    type Output = Self;
    #[inline(always)]
    fn mul(self, rhs: Self) -> Self {
        Self(unsafe { _mm256_mul_pd(self.0, rhs.0) })
    }
}

impl Neg for F64x4Avx2 {
    type Output = Self;
    /// The sign bit flipped, as `-x` does.
    #[inline(always)]
    fn neg(self) -> Self {
        Self(unsafe { _mm256_xor_pd(self.0, _mm256_set1_pd(-0.0)) })
    }
}
