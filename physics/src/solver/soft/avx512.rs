//! The batches' eight lanes as one AVX-512 register (`Lanes` for `F64x8Avx512`), for the
//! functions compiled with `#[target_feature(enable = "avx512f")]` and nothing else. Each
//! operation is the one instruction whose result is the scalar code's to the bit, as in
//! `avx2` (`maxpd`, `minpd`, ordered comparisons except `!=`, `vfmadd` as `f64::mul_add`);
//! the comparisons leave a mask register, one bit a lane.
//!
//! Only a function compiled for AVX-512 may use this type, and only once the processor
//! is known to have it: its operations are `#[inline(always)]` wrappers of intrinsics.

use super::bodies::{BodyRow, SoftBody};
use super::lanes::{F64x8, LANES, LaneMask, Lanes};
use std::arch::x86_64::*;
use std::ops::{Add, AddAssign, BitAnd, BitXor, Div, Mul, Neg, Sub, SubAssign};

/// Eight f64 lanes in a 512-bit register; the same size and alignment as `F64x8`.
#[derive(Debug, Clone, Copy)]
#[repr(transparent)]
pub(super) struct F64x8Avx512(__m512d);

/// A lane-wise condition, one bit a lane.
#[derive(Debug, Clone, Copy)]
pub(super) struct MaskAvx512(__mmask8);

const _: () = {
    use std::mem::{align_of, size_of};
    assert!(size_of::<F64x8Avx512>() == size_of::<F64x8>());
    assert!(align_of::<F64x8Avx512>() == align_of::<F64x8>());
};

// SAFETY (every `unsafe` block below): the intrinsics need AVX-512F, which the functions
// this type is used in are compiled for and only called with (`batch::LaneBatch`);
// the aligned loads and stores touch only the 32-byte rows `row` and `row_mut` name,
// which lie inside their bodies at 0 or 32 bytes from the start of a 32-byte-aligned
// `SoftBody`, and the bodies lie inside the slice (`Lanes::gather`'s precondition).

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

/// Picks, by `vpermt2pd`, eight of the sixteen numbers of `a` (0–7) and `b` (8–15).
#[inline(always)]
fn pick(a: __m512d, [i0, i1, i2, i3, i4, i5, i6, i7]: [i64; 8], b: __m512d) -> __m512d {
    unsafe { _mm512_permutex2var_pd(a, _mm512_setr_epi64(i0, i1, i2, i3, i4, i5, i6, i7), b) }
}

/// Of each 128-bit quarter of the two: the first numbers interleaved (`unpcklpd`), and
/// the second ones (`unpckhpd`).
#[inline(always)]
fn interleave(a: __m512d, b: __m512d) -> (__m512d, __m512d) {
    unsafe { (_mm512_unpacklo_pd(a, b), _mm512_unpackhi_pd(a, b)) }
}

impl Lanes for F64x8Avx512 {
    type Mask = MaskAvx512;

    #[inline(always)]
    fn splat(x: f64) -> Self {
        Self(unsafe { _mm512_set1_pd(x) })
    }

    #[inline(always)]
    fn max(self, rhs: Self) -> Self {
        Self(unsafe { _mm512_max_pd(self.0, rhs.0) })
    }

    #[inline(always)]
    fn min(self, rhs: Self) -> Self {
        Self(unsafe { _mm512_min_pd(self.0, rhs.0) })
    }

    #[inline(always)]
    fn clamp(self, lo: Self, hi: Self) -> Self {
        let below_hi = hi.min(self);
        Self(unsafe { _mm512_max_pd(lo.0, below_hi.0) })
    }

    #[inline(always)]
    fn sqrt(self) -> Self {
        Self(unsafe { _mm512_sqrt_pd(self.0) })
    }

    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        Self(unsafe { _mm512_fmadd_pd(self.0, a.0, b.0) })
    }

    #[inline(always)]
    fn neg_mul_add(self, a: Self, b: Self) -> Self {
        Self(unsafe { _mm512_fnmadd_pd(self.0, a.0, b.0) })
    }

    #[inline(always)]
    fn gt(self, rhs: Self) -> MaskAvx512 {
        MaskAvx512(unsafe { _mm512_cmp_pd_mask::<_CMP_GT_OQ>(self.0, rhs.0) })
    }

    #[inline(always)]
    fn ge(self, rhs: Self) -> MaskAvx512 {
        MaskAvx512(unsafe { _mm512_cmp_pd_mask::<_CMP_GE_OQ>(self.0, rhs.0) })
    }

    #[inline(always)]
    fn lt(self, rhs: Self) -> MaskAvx512 {
        MaskAvx512(unsafe { _mm512_cmp_pd_mask::<_CMP_LT_OQ>(self.0, rhs.0) })
    }

    #[inline(always)]
    fn eq(self, rhs: Self) -> MaskAvx512 {
        MaskAvx512(unsafe { _mm512_cmp_pd_mask::<_CMP_EQ_OQ>(self.0, rhs.0) })
    }

    #[inline(always)]
    fn ne(self, rhs: Self) -> MaskAvx512 {
        MaskAvx512(unsafe { _mm512_cmp_pd_mask::<_CMP_NEQ_UQ>(self.0, rhs.0) })
    }

    /// Eight 4-number rows into four 8-lane columns: rows k and k + 4 share a register
    /// (one half each), `unpck` pairs rows within each 128-bit quarter, and `vpermt2pd`
    /// puts the pairs in lane order.
    #[inline(always)]
    unsafe fn gather(bodies: &[SoftBody], index: &[u32; LANES], which: BodyRow) -> [Self; 4] {
        let load = |k: usize| unsafe { _mm256_load_pd(row(bodies, index[k], which)) };
        let joined = |k: usize| unsafe {
            _mm512_insertf64x4::<1>(_mm512_castpd256_pd512(load(k)), load(k + 4))
        };
        // z_k = [row k | row k + 4].
        let (z0, z1, z2, z3) = (joined(0), joined(1), joined(2), joined(3));
        // t0 = [r0c0 r1c0 r0c2 r1c2 | r4c0 r5c0 r4c2 r5c2], t1 the same of columns 1, 3.
        let (t0, t1) = interleave(z0, z1);
        let (t2, t3) = interleave(z2, z3);
        const EVEN: [i64; 8] = [0, 1, 8, 9, 4, 5, 12, 13];
        const ODD: [i64; 8] = [2, 3, 10, 11, 6, 7, 14, 15];
        [
            Self(pick(t0, EVEN, t2)),
            Self(pick(t1, EVEN, t3)),
            Self(pick(t0, ODD, t2)),
            Self(pick(t1, ODD, t3)),
        ]
    }

    /// `gather`'s inverse, the rows stored lane 0 first.
    #[inline(always)]
    unsafe fn scatter_velocities(
        columns: [Self; 4],
        bodies: &mut [SoftBody],
        index: &[u32; LANES],
    ) {
        let [c0, c1, c2, c3] = columns.map(|c| c.0);
        // u0's quarters are the first halves of rows 0, 2, 4, 6; u1's of rows 1, 3, 5, 7;
        // u2 and u3 hold the second halves.
        let (u0, u1) = interleave(c0, c1);
        let (u2, u3) = interleave(c2, c3);
        const FIRST: [i64; 8] = [0, 1, 8, 9, 2, 3, 10, 11];
        const SECOND: [i64; 8] = [4, 5, 12, 13, 6, 7, 14, 15];
        // [row 0 | row 2], [row 4 | row 6], [row 1 | row 3], [row 5 | row 7].
        let pairs = [
            pick(u0, FIRST, u2),
            pick(u0, SECOND, u2),
            pick(u1, FIRST, u3),
            pick(u1, SECOND, u3),
        ];
        let rows: [__m256d; 8] = std::array::from_fn(|k| {
            let pair = pairs[(k % 2) * 2 + k / 4];
            if (k / 2) % 2 == 0 {
                unsafe { _mm512_castpd512_pd256(pair) }
            } else {
                unsafe { _mm512_extractf64x4_pd::<1>(pair) }
            }
        });
        for (k, row) in rows.into_iter().enumerate() {
            let at = row_mut(bodies, index[k], BodyRow::Velocity);
            unsafe { _mm256_store_pd(at, row) };
        }
    }
}

impl LaneMask<F64x8Avx512> for MaskAvx512 {
    #[inline(always)]
    fn any(self) -> bool {
        self.0 != 0
    }

    #[inline(always)]
    fn select(self, if_true: F64x8Avx512, if_false: F64x8Avx512) -> F64x8Avx512 {
        F64x8Avx512(unsafe { _mm512_mask_blend_pd(self.0, if_false.0, if_true.0) })
    }
}

impl BitAnd for MaskAvx512 {
    type Output = Self;
    #[inline(always)]
    fn bitand(self, rhs: Self) -> Self {
        Self(self.0 & rhs.0)
    }
}

impl BitXor for MaskAvx512 {
    type Output = Self;
    #[inline(always)]
    fn bitxor(self, rhs: Self) -> Self {
        Self(self.0 ^ rhs.0)
    }
}

macro_rules! lane_op {
    ($trait:ident, $method:ident, $assign_trait:ident, $assign:ident, $intrinsic:ident) => {
        impl $trait for F64x8Avx512 {
            type Output = Self;
            #[inline(always)]
            fn $method(self, rhs: Self) -> Self {
                Self(unsafe { $intrinsic(self.0, rhs.0) })
            }
        }

        impl $assign_trait for F64x8Avx512 {
            #[inline(always)]
            fn $assign(&mut self, rhs: Self) {
                *self = Self(unsafe { $intrinsic(self.0, rhs.0) });
            }
        }
    };
}

lane_op!(Add, add, AddAssign, add_assign, _mm512_add_pd);
lane_op!(Sub, sub, SubAssign, sub_assign, _mm512_sub_pd);

impl Mul for F64x8Avx512 {
    type Output = Self;
    #[inline(always)]
    fn mul(self, rhs: Self) -> Self {
        Self(unsafe { _mm512_mul_pd(self.0, rhs.0) })
    }
}

impl Div for F64x8Avx512 {
    type Output = Self;
    #[inline(always)]
    fn div(self, rhs: Self) -> Self {
        Self(unsafe { _mm512_div_pd(self.0, rhs.0) })
    }
}

impl Neg for F64x8Avx512 {
    type Output = Self;
    /// The sign bit flipped, as `-x` does.
    #[inline(always)]
    fn neg(self) -> Self {
        let sign = unsafe { _mm512_set1_epi64(i64::MIN) };
        Self(unsafe { _mm512_castsi512_pd(_mm512_xor_si512(_mm512_castpd_si512(self.0), sign)) })
    }
}
