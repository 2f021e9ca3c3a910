//! A batch's eight lanes in AVX2 registers, four to a register (`Avx2Lanes`), for the
//! functions compiled with `#[target_feature(enable = "avx2,fma")]` and nothing else. A row
//! of eight lanes is two registers, its halves (lanes 0–3 and 4–7); a type computes the
//! halves `FIRST..END` of them and leaves the others alone:
//!
//! - `BothHalves` warm-starts and solves a full batch: the two halves' manifolds share no
//!   moving body, so their chains of dependent updates are independent, and interleaved
//!   they keep the processor busy where one half alone waits on each result (docs/bench/
//!   profile.md, "Both halves at once"; the warm start too since its multiply–adds are
//!   fused, "Fused multiply–adds in the contact rows").
//! - `LowerHalf` computes lanes 0–3 of a batch whose upper half is unused, which is then
//!   skipped.
//!
//! Each operation is the one instruction whose result is the scalar code's to the bit:
//! `maxpd(a, b)` is `if a > b { a } else { b }`, `minpd(a, b)` is `if a < b { a } else
//! { b }`, comparisons are ordered (false on NaN) except `!=`, and a fused multiply–add
//! (`vfmadd`, `vfnmadd`) is `f64::mul_add`, rounded once.
//!
//! Only a function compiled for AVX2 and FMA may use these types, and only once the
//! processor is known to have both: their operations are `#[inline(always)]` wrappers of
//! intrinsics that become single instructions when inlined there.

use super::bodies::{BodyRow, SoftBody};
use super::lanes::{F64x8, LANES, LaneMask, Lanes};
use std::arch::x86_64::*;
use std::ops::{Add, AddAssign, BitAnd, BitXor, Div, Mul, Neg, Sub, SubAssign};

/// Lanes `4 FIRST..4 END` of a batch's eight, read from and written to their halves of an
/// `F64x8` (the same size, layout and alignment). The halves outside `FIRST..END` of a
/// computed value hold nothing meaningful; only `set` writes into a batch, and only the
/// computed halves, so that solving one half leaves the other's numbers as they were.
#[derive(Debug, Clone, Copy)]
#[repr(C, align(64))]
pub(super) struct Avx2Lanes<const FIRST: usize, const END: usize>([__m256d; 2]);

/// All eight lanes, both halves interleaved.
pub(super) type BothHalves = Avx2Lanes<0, 2>;
/// Lanes 0–3.
pub(super) type LowerHalf = Avx2Lanes<0, 1>;

/// A lane-wise condition of the same halves: all ones or all zeros per lane.
#[derive(Debug, Clone, Copy)]
pub(super) struct Avx2Mask<const FIRST: usize, const END: usize>([__m256d; 2]);

const _: () = {
    use std::mem::{align_of, size_of};
    assert!(size_of::<BothHalves>() == size_of::<F64x8>());
    assert!(align_of::<BothHalves>() == align_of::<F64x8>());
};

/// Lanes a half holds.
const HALF: usize = LANES / 2;

// SAFETY (every `unsafe` block below): the intrinsics need AVX2 and FMA, which the functions
// these types are used in are compiled for and only called with (`batch::LaneBatch`); the
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

/// `computed(h)` for the halves `FIRST..END`, `rest`'s own elsewhere (unread): the one
/// place that decides which halves an operation computes.
#[inline(always)]
fn on_halves<const FIRST: usize, const END: usize>(
    rest: [__m256d; 2],
    computed: impl Fn(usize) -> __m256d,
) -> [__m256d; 2] {
    std::array::from_fn(|h| {
        if (FIRST..END).contains(&h) {
            computed(h)
        } else {
            rest[h]
        }
    })
}

impl<const FIRST: usize, const END: usize> Avx2Lanes<FIRST, END> {
    /// `f` on the computed halves of `a` and `b` (the others are `a`'s, unread).
    #[inline(always)]
    fn zip(a: Self, b: Self, f: impl Fn(__m256d, __m256d) -> __m256d) -> Self {
        Self(on_halves::<FIRST, END>(a.0, |h| f(a.0[h], b.0[h])))
    }

    /// `f` on each computed half.
    #[inline(always)]
    fn map(self, f: impl Fn(__m256d) -> __m256d) -> Self {
        Self::zip(self, self, |a, _| f(a))
    }

    /// The comparison `f` on the computed halves, as a mask.
    #[inline(always)]
    fn compare(a: Self, b: Self, f: impl Fn(__m256d, __m256d) -> __m256d) -> Avx2Mask<FIRST, END> {
        Avx2Mask(Self::zip(a, b, f).0)
    }

    /// `if lo > self { lo } else { self }`, the lower bound of `clamp`.
    #[inline(always)]
    fn max_of(self, lo: Self) -> Self {
        Self::zip(lo, self, |a, b| unsafe { _mm256_max_pd(a, b) })
    }
}

impl<const FIRST: usize, const END: usize> Lanes for Avx2Lanes<FIRST, END> {
    type Mask = Avx2Mask<FIRST, END>;

    #[inline(always)]
    fn splat(x: f64) -> Self {
        let lanes = unsafe { _mm256_set1_pd(x) };
        Self([lanes; 2])
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
        self.map(|a| unsafe { _mm256_sqrt_pd(a) })
    }

    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        Self(on_halves::<FIRST, END>(self.0, |h| unsafe {
            _mm256_fmadd_pd(self.0[h], a.0[h], b.0[h])
        }))
    }

    #[inline(always)]
    fn neg_mul_add(self, a: Self, b: Self) -> Self {
        Self(on_halves::<FIRST, END>(self.0, |h| unsafe {
            _mm256_fnmadd_pd(self.0[h], a.0[h], b.0[h])
        }))
    }

    #[inline(always)]
    fn gt(self, rhs: Self) -> Self::Mask {
        Self::compare(self, rhs, |a, b| unsafe {
            _mm256_cmp_pd::<_CMP_GT_OQ>(a, b)
        })
    }

    #[inline(always)]
    fn ge(self, rhs: Self) -> Self::Mask {
        Self::compare(self, rhs, |a, b| unsafe {
            _mm256_cmp_pd::<_CMP_GE_OQ>(a, b)
        })
    }

    #[inline(always)]
    fn lt(self, rhs: Self) -> Self::Mask {
        Self::compare(self, rhs, |a, b| unsafe {
            _mm256_cmp_pd::<_CMP_LT_OQ>(a, b)
        })
    }

    #[inline(always)]
    fn eq(self, rhs: Self) -> Self::Mask {
        Self::compare(self, rhs, |a, b| unsafe {
            _mm256_cmp_pd::<_CMP_EQ_OQ>(a, b)
        })
    }

    #[inline(always)]
    fn ne(self, rhs: Self) -> Self::Mask {
        Self::compare(self, rhs, |a, b| unsafe {
            _mm256_cmp_pd::<_CMP_NEQ_UQ>(a, b)
        })
    }

    /// The computed halves only: the others keep their numbers.
    #[inline(always)]
    fn set(&mut self, value: Self) {
        for h in FIRST..END {
            self.0[h] = value.0[h];
        }
    }

    #[inline(always)]
    unsafe fn gather(bodies: &[SoftBody], index: &[u32; LANES], which: BodyRow) -> [Self; 4] {
        let mut columns = [Self::splat(0.0); 4];
        for h in FIRST..END {
            // Written out: `array::map` was left out of line here.
            let load =
                |k: usize| unsafe { _mm256_load_pd(row(bodies, index[h * HALF + k], which)) };
            let half = transpose([load(0), load(1), load(2), load(3)]);
            for (column, lanes) in columns.iter_mut().zip(half) {
                column.0[h] = lanes;
            }
        }
        columns
    }

    #[inline(always)]
    unsafe fn scatter_velocities(
        columns: [Self; 4],
        bodies: &mut [SoftBody],
        index: &[u32; LANES],
    ) {
        for h in FIRST..END {
            let [c0, c1, c2, c3] = columns.map(|c| c.0[h]);
            for (k, row) in transpose([c0, c1, c2, c3]).into_iter().enumerate() {
                let at = row_mut(bodies, index[h * HALF + k], BodyRow::Velocity);
                unsafe { _mm256_store_pd(at, row) };
            }
        }
    }
}

impl<const FIRST: usize, const END: usize> LaneMask<Avx2Lanes<FIRST, END>>
    for Avx2Mask<FIRST, END>
{
    #[inline(always)]
    fn any(self) -> bool {
        (FIRST..END).any(|h| unsafe { _mm256_movemask_pd(self.0[h]) != 0 })
    }

    #[inline(always)]
    fn select(
        self,
        if_true: Avx2Lanes<FIRST, END>,
        if_false: Avx2Lanes<FIRST, END>,
    ) -> Avx2Lanes<FIRST, END> {
        Avx2Lanes(on_halves::<FIRST, END>(if_false.0, |h| unsafe {
            _mm256_blendv_pd(if_false.0[h], if_true.0[h], self.0[h])
        }))
    }
}

impl<const FIRST: usize, const END: usize> BitAnd for Avx2Mask<FIRST, END> {
    type Output = Self;
    #[inline(always)]
    fn bitand(self, rhs: Self) -> Self {
        Self(on_halves::<FIRST, END>(self.0, |h| unsafe {
            _mm256_and_pd(self.0[h], rhs.0[h])
        }))
    }
}

impl<const FIRST: usize, const END: usize> BitXor for Avx2Mask<FIRST, END> {
    type Output = Self;
    #[inline(always)]
    fn bitxor(self, rhs: Self) -> Self {
        Self(on_halves::<FIRST, END>(self.0, |h| unsafe {
            _mm256_xor_pd(self.0[h], rhs.0[h])
        }))
    }
}

macro_rules! lane_op {
    ($trait:ident, $method:ident, $assign_trait:ident, $assign:ident, $intrinsic:ident) => {
        impl<const FIRST: usize, const END: usize> $trait for Avx2Lanes<FIRST, END> {
            type Output = Self;
            #[inline(always)]
            fn $method(self, rhs: Self) -> Self {
                Self::zip(self, rhs, |a, b| unsafe { $intrinsic(a, b) })
            }
        }

        impl<const FIRST: usize, const END: usize> $assign_trait for Avx2Lanes<FIRST, END> {
            #[inline(always)]
            fn $assign(&mut self, rhs: Self) {
                *self = Self::zip(*self, rhs, |a, b| unsafe { $intrinsic(a, b) });
            }
        }
    };
}

lane_op!(Add, add, AddAssign, add_assign, _mm256_add_pd);
lane_op!(Sub, sub, SubAssign, sub_assign, _mm256_sub_pd);

impl<const FIRST: usize, const END: usize> Mul for Avx2Lanes<FIRST, END> {
    type Output = Self;
    #[inline(always)]
    fn mul(self, rhs: Self) -> Self {
        Self::zip(self, rhs, |a, b| unsafe { _mm256_mul_pd(a, b) })
    }
}

impl<const FIRST: usize, const END: usize> Div for Avx2Lanes<FIRST, END> {
    type Output = Self;
    #[inline(always)]
    fn div(self, rhs: Self) -> Self {
        Self::zip(self, rhs, |a, b| unsafe { _mm256_div_pd(a, b) })
    }
}

impl<const FIRST: usize, const END: usize> Neg for Avx2Lanes<FIRST, END> {
    type Output = Self;
    /// The sign bit flipped, as `-x` does.
    #[inline(always)]
    fn neg(self) -> Self {
        let sign = unsafe { _mm256_set1_pd(-0.0) };
        self.map(|a| unsafe { _mm256_xor_pd(a, sign) })
    }
}
