//! Half of a batch's eight lanes in one AVX2 register (`Lanes` for `HalfAvx2<H>`: lanes
//! 0–3 for `H = 0`, 4–7 for `H = 1`), for the functions compiled with
//! `#[target_feature(enable = "avx2")]` and nothing else. Those functions solve a batch
//! half by half: its manifolds share no moving body, so each half is solved as if alone,
//! and a half whose lanes are all unused is skipped. All eight lanes at once, in two
//! registers a row, spilled: the pair's velocities alone are sixteen registers, all that
//! AVX2 has (the batches' passes took 666K instructions a step on the 20-row pyramid
//! against 564K with four lanes; docs/bench/profile.md, "A machine without AVX-512").
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

/// Lanes `4H..4H + 4` of a batch's eight, read from and written to their half of an
/// `F64x8` (the same size, layout and alignment). A value computed here carries its lanes
/// in both halves; only `set` writes into a batch, and only this half, so that solving
/// one half leaves the other's numbers as they were.
#[derive(Debug, Clone, Copy)]
#[repr(C, align(64))]
pub(super) struct HalfAvx2<const H: usize>([__m256d; 2]);

/// A lane-wise condition of a half: all ones or all zeros per lane.
#[derive(Debug, Clone, Copy)]
pub(super) struct HalfMaskAvx2(__m256d);

const _: () = {
    use std::mem::{align_of, size_of};
    assert!(size_of::<HalfAvx2<0>>() == size_of::<F64x8>());
    assert!(align_of::<HalfAvx2<0>>() == align_of::<F64x8>());
    assert!(size_of::<HalfAvx2<1>>() == size_of::<F64x8>());
    assert!(align_of::<HalfAvx2<1>>() == align_of::<F64x8>());
};

/// Lanes a half holds.
const HALF: usize = LANES / 2;

// SAFETY (every `unsafe` block below): the intrinsics need AVX2, which the functions this
// type is used in are compiled for and only called with (`ManifoldBatch::as_lanes`); the
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

impl<const H: usize> HalfAvx2<H> {
    /// This half's lanes.
    #[inline(always)]
    fn lanes(self) -> __m256d {
        self.0[H]
    }

    /// A value with `lanes` as this half's (in both halves: see the type).
    #[inline(always)]
    fn of(lanes: __m256d) -> Self {
        Self([lanes; 2])
    }

    /// `f` on this half's lanes of `a` and `b`.
    #[inline(always)]
    fn zip(a: Self, b: Self, f: impl Fn(__m256d, __m256d) -> __m256d) -> Self {
        Self::of(f(a.lanes(), b.lanes()))
    }

    /// The comparison `f` on this half's lanes, as a mask.
    #[inline(always)]
    fn compare(a: Self, b: Self, f: impl Fn(__m256d, __m256d) -> __m256d) -> HalfMaskAvx2 {
        HalfMaskAvx2(f(a.lanes(), b.lanes()))
    }

    /// `if lo > self { lo } else { self }`, the lower bound of `clamp`.
    #[inline(always)]
    fn max_of(self, lo: Self) -> Self {
        Self::zip(lo, self, |a, b| unsafe { _mm256_max_pd(a, b) })
    }
}

impl<const H: usize> Lanes for HalfAvx2<H> {
    type Mask = HalfMaskAvx2;

    #[inline(always)]
    fn splat(x: f64) -> Self {
        Self::of(unsafe { _mm256_set1_pd(x) })
    }

    #[inline(always)]
    fn max(self, rhs: Self) -> Self {
        Self::zip(self, rhs, |a, b| unsafe { _mm256_max_pd(a, b) })
    }

    #[inline(always)]
    fn min(self, rhs: Self) -> Self {
        Self::zip(self, rhs, |a, b| unsafe { _mm256_min_pd(a, b) })
    }

    #[inline(always)]
    fn clamp(self, lo: Self, hi: Self) -> Self {
        hi.min(self).max_of(lo)
    }

    #[inline(always)]
    fn sqrt(self) -> Self {
        Self::of(unsafe { _mm256_sqrt_pd(self.lanes()) })
    }

    #[inline(always)]
    fn gt(self, rhs: Self) -> HalfMaskAvx2 {
        Self::compare(self, rhs, |a, b| unsafe {
            _mm256_cmp_pd::<_CMP_GT_OQ>(a, b)
        })
    }

    #[inline(always)]
    fn ge(self, rhs: Self) -> HalfMaskAvx2 {
        Self::compare(self, rhs, |a, b| unsafe {
            _mm256_cmp_pd::<_CMP_GE_OQ>(a, b)
        })
    }

    #[inline(always)]
    fn lt(self, rhs: Self) -> HalfMaskAvx2 {
        Self::compare(self, rhs, |a, b| unsafe {
            _mm256_cmp_pd::<_CMP_LT_OQ>(a, b)
        })
    }

    #[inline(always)]
    fn eq(self, rhs: Self) -> HalfMaskAvx2 {
        Self::compare(self, rhs, |a, b| unsafe {
            _mm256_cmp_pd::<_CMP_EQ_OQ>(a, b)
        })
    }

    #[inline(always)]
    fn ne(self, rhs: Self) -> HalfMaskAvx2 {
        Self::compare(self, rhs, |a, b| unsafe {
            _mm256_cmp_pd::<_CMP_NEQ_UQ>(a, b)
        })
    }

    /// This half's lanes only: the other half of `self` keeps its numbers.
    #[inline(always)]
    fn set(&mut self, value: Self) {
        self.0[H] = value.lanes();
    }

    #[inline(always)]
    unsafe fn gather(bodies: &[SoftBody], index: &[u32; LANES], which: BodyRow) -> [Self; 4] {
        // Written out: `array::map` was left out of line here.
        let load = |k: usize| unsafe { _mm256_load_pd(row(bodies, index[H * HALF + k], which)) };
        let [c0, c1, c2, c3] = transpose([load(0), load(1), load(2), load(3)]);
        [Self::of(c0), Self::of(c1), Self::of(c2), Self::of(c3)]
    }

    #[inline(always)]
    unsafe fn scatter_velocities(
        columns: [Self; 4],
        bodies: &mut [SoftBody],
        index: &[u32; LANES],
    ) {
        let [c0, c1, c2, c3] = columns.map(Self::lanes);
        for (k, row) in transpose([c0, c1, c2, c3]).into_iter().enumerate() {
            let at = row_mut(bodies, index[H * HALF + k], BodyRow::Velocity);
            unsafe { _mm256_store_pd(at, row) };
        }
    }
}

impl<const H: usize> LaneMask<HalfAvx2<H>> for HalfMaskAvx2 {
    #[inline(always)]
    fn any(self) -> bool {
        unsafe { _mm256_movemask_pd(self.0) != 0 }
    }

    #[inline(always)]
    fn select(self, if_true: HalfAvx2<H>, if_false: HalfAvx2<H>) -> HalfAvx2<H> {
        HalfAvx2::of(unsafe { _mm256_blendv_pd(if_false.lanes(), if_true.lanes(), self.0) })
    }
}

impl BitAnd for HalfMaskAvx2 {
    type Output = Self;
    #[inline(always)]
    fn bitand(self, rhs: Self) -> Self {
        Self(unsafe { _mm256_and_pd(self.0, rhs.0) })
    }
}

impl BitXor for HalfMaskAvx2 {
    type Output = Self;
    #[inline(always)]
    fn bitxor(self, rhs: Self) -> Self {
        Self(unsafe { _mm256_xor_pd(self.0, rhs.0) })
    }
}

macro_rules! lane_op {
    ($trait:ident, $method:ident, $assign_trait:ident, $assign:ident, $intrinsic:ident) => {
        impl<const H: usize> $trait for HalfAvx2<H> {
            type Output = Self;
            #[inline(always)]
            fn $method(self, rhs: Self) -> Self {
                Self::zip(self, rhs, |a, b| unsafe { $intrinsic(a, b) })
            }
        }

        impl<const H: usize> $assign_trait for HalfAvx2<H> {
            #[inline(always)]
            fn $assign(&mut self, rhs: Self) {
                *self = Self::zip(*self, rhs, |a, b| unsafe { $intrinsic(a, b) });
            }
        }
    };
}

lane_op!(Add, add, AddAssign, add_assign, _mm256_add_pd);
lane_op!(Sub, sub, SubAssign, sub_assign, _mm256_sub_pd);

impl<const H: usize> Mul for HalfAvx2<H> {
    type Output = Self;
    #[inline(always)]
    fn mul(self, rhs: Self) -> Self {
        Self::zip(self, rhs, |a, b| unsafe { _mm256_mul_pd(a, b) })
    }
}

impl<const H: usize> Neg for HalfAvx2<H> {
    type Output = Self;
    /// The sign bit flipped, as `-x` does.
    #[inline(always)]
    fn neg(self) -> Self {
        let sign = unsafe { _mm256_set1_pd(-0.0) };
        Self::of(unsafe { _mm256_xor_pd(self.lanes(), sign) })
    }
}
