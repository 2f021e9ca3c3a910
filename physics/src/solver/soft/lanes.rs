//! Eight f64 lanes, as the batches compute with them (`Lanes`): `F64x8`, plain arrays that
//! the compiler vectorises, on any processor; `avx2::Avx2Lanes`, four of them to a 256-bit
//! register, both halves of a row or one, inside the functions compiled for AVX2; and
//! `avx512::F64x8Avx512`, all of them in one 512-bit register, inside those compiled for
//! AVX-512 (chosen at run time, see `batch::LanePath::best`). Every lane rounds as the
//! scalar code does, so all three give the same bits: where the scalar code fuses a
//! multiply and an add (`f64::mul_add`, one rounding), the lanes do too (`Lanes::mul_add`).

use super::bodies::{BodyRow, SoftBody};
use std::ops::{Add, AddAssign, BitAnd, BitXor, Div, Mul, Neg, Sub, SubAssign};

/// How many manifolds a batch holds, one a lane.
pub(super) const LANES: usize = 8;

/// Eight lanes of f64 and what the batches do with them. A batch is stored with
/// `F64x8`s and read as any implementation (they share its layout).
pub(super) trait Lanes:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + AddAssign
    + SubAssign
{
    type Mask: LaneMask<Self>;
    fn splat(x: f64) -> Self;
    /// The larger of each pair, `if a > b { a } else { b }` (no NaN reaches the solver).
    fn max(self, rhs: Self) -> Self;
    /// `if a < b { a } else { b }`.
    fn min(self, rhs: Self) -> Self;
    /// `f64::clamp` lane by lane, to the bit (a zero keeps its sign as there), for
    /// `lo <= hi`: the upper bound where `hi < x`, then the lower where `lo >` that.
    fn clamp(self, lo: Self, hi: Self) -> Self;
    fn sqrt(self) -> Self;
    /// `self · a + b` rounded once: `f64::mul_add` lane by lane.
    fn mul_add(self, a: Self, b: Self) -> Self;
    /// `b − self · a` rounded once: `(−self).mul_add(a, b)` lane by lane (negating is
    /// exact).
    fn neg_mul_add(self, a: Self, b: Self) -> Self;
    fn gt(self, rhs: Self) -> Self::Mask;
    fn ge(self, rhs: Self) -> Self::Mask;
    fn lt(self, rhs: Self) -> Self::Mask;
    fn eq(self, rhs: Self) -> Self::Mask;
    fn ne(self, rhs: Self) -> Self::Mask;
    /// Writes `value` into a batch's field: every lane this type computes, and no other
    /// (`avx2::LowerHalf` computes half of them, and the other half must keep its numbers).
    #[inline(always)]
    fn set(&mut self, value: Self) {
        *self = value;
    }
    /// The row `row` of the bodies `index` names, one body a lane: its four numbers as
    /// four columns (`SoftBody::row`).
    ///
    /// # Safety
    /// Every index must be below `bodies.len()` (the SIMD paths do not check them: the
    /// batch checks all its indices once per pass, `ManifoldBatch::indices_fit`).
    unsafe fn gather(bodies: &[SoftBody], index: &[u32; LANES], row: BodyRow) -> [Self; 4];
    /// Writes the velocity row's first three columns back, lane 0 first, so that a fixed
    /// body in several lanes of one side keeps the last lane's, as the scalar lane-by-lane
    /// stores left it (it can differ only in the sign of a zero); the fourth column must
    /// be the inverse masses `gather` read.
    ///
    /// # Safety
    /// As `gather`.
    unsafe fn scatter_velocities(columns: [Self; 4], bodies: &mut [SoftBody], index: &[u32; LANES]);
}

/// A lane-wise condition of `L`'s lanes.
pub(super) trait LaneMask<L>: Copy + BitAnd<Output = Self> + BitXor<Output = Self> {
    fn any(self) -> bool;
    /// `if_true` where the condition holds, `if_false` elsewhere (bit for bit).
    fn select(self, if_true: L, if_false: L) -> L;
}

#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[repr(C, align(64))]
pub(super) struct F64x8(pub [f64; LANES]);

/// A lane-wise condition, each lane all ones or all zeros as a vector comparison leaves
/// it, so that choosing by it is one blend (a `bool` per lane cost conversions both ways).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Mask8([u64; LANES]);

impl F64x8 {
    #[inline(always)]
    pub(crate) fn from_fn(f: impl FnMut(usize) -> f64) -> Self {
        Self(std::array::from_fn(f))
    }

    #[inline(always)]
    fn zip(self, rhs: Self, f: impl Fn(f64, f64) -> f64) -> Self {
        Self::from_fn(|k| f(self.0[k], rhs.0[k]))
    }

    #[inline(always)]
    fn compare(self, rhs: Self, f: impl Fn(f64, f64) -> bool) -> Mask8 {
        Mask8(std::array::from_fn(|k| {
            if f(self.0[k], rhs.0[k]) { u64::MAX } else { 0 }
        }))
    }
}

impl Lanes for F64x8 {
    type Mask = Mask8;

    #[inline(always)]
    fn splat(x: f64) -> Self {
        Self([x; LANES])
    }

    #[inline(always)]
    fn max(self, rhs: Self) -> Self {
        self.zip(rhs, |a, b| if a > b { a } else { b })
    }

    #[inline(always)]
    fn min(self, rhs: Self) -> Self {
        self.zip(rhs, |a, b| if a < b { a } else { b })
    }

    #[inline(always)]
    fn clamp(self, lo: Self, hi: Self) -> Self {
        let below_hi = hi.zip(self, |hi, x| if hi < x { hi } else { x });
        lo.zip(below_hi, |lo, t| if lo > t { lo } else { t })
    }

    #[inline(always)]
    fn sqrt(self) -> Self {
        Self::from_fn(|k| self.0[k].sqrt())
    }

    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        Self::from_fn(|k| self.0[k].mul_add(a.0[k], b.0[k]))
    }

    #[inline(always)]
    fn neg_mul_add(self, a: Self, b: Self) -> Self {
        Self::from_fn(|k| (-self.0[k]).mul_add(a.0[k], b.0[k]))
    }

    #[inline(always)]
    fn gt(self, rhs: Self) -> Mask8 {
        self.compare(rhs, |a, b| a > b)
    }

    #[inline(always)]
    fn ge(self, rhs: Self) -> Mask8 {
        self.compare(rhs, |a, b| a >= b)
    }

    #[inline(always)]
    fn lt(self, rhs: Self) -> Mask8 {
        self.compare(rhs, |a, b| a < b)
    }

    #[inline(always)]
    fn eq(self, rhs: Self) -> Mask8 {
        self.compare(rhs, |a, b| a == b)
    }

    #[inline(always)]
    fn ne(self, rhs: Self) -> Mask8 {
        self.compare(rhs, |a, b| a != b)
    }

    #[inline(always)]
    unsafe fn gather(bodies: &[SoftBody], index: &[u32; LANES], row: BodyRow) -> [Self; 4] {
        let rows = index.map(|i| bodies[i as usize].row(row));
        std::array::from_fn(|c| Self::from_fn(|k| rows[k][c]))
    }

    #[inline(always)]
    unsafe fn scatter_velocities(
        [x, y, w, _]: [Self; 4],
        bodies: &mut [SoftBody],
        index: &[u32; LANES],
    ) {
        for k in 0..LANES {
            let body = &mut bodies[index[k] as usize];
            body.v.x = x.0[k];
            body.v.y = y.0[k];
            body.w = w.0[k];
        }
    }
}

impl LaneMask<F64x8> for Mask8 {
    #[inline(always)]
    fn any(self) -> bool {
        self.0.iter().fold(0, |any, &m| any | m) != 0
    }

    #[inline(always)]
    fn select(self, if_true: F64x8, if_false: F64x8) -> F64x8 {
        F64x8::from_fn(|k| {
            let m = self.0[k];
            f64::from_bits((if_true.0[k].to_bits() & m) | (if_false.0[k].to_bits() & !m))
        })
    }
}

impl BitAnd for Mask8 {
    type Output = Self;
    #[inline(always)]
    fn bitand(self, rhs: Self) -> Self {
        Self(std::array::from_fn(|k| self.0[k] & rhs.0[k]))
    }
}

impl BitXor for Mask8 {
    type Output = Self;
    #[inline(always)]
    fn bitxor(self, rhs: Self) -> Self {
        Self(std::array::from_fn(|k| self.0[k] ^ rhs.0[k]))
    }
}

macro_rules! lane_op {
    ($trait:ident, $method:ident, $assign_trait:ident, $assign:ident, $op:tt) => {
        impl $trait for F64x8 {
            type Output = Self;
            #[inline(always)]
            fn $method(self, rhs: Self) -> Self {
                self.zip(rhs, |a, b| a $op b)
            }
        }

        impl $assign_trait for F64x8 {
            #[inline(always)]
            fn $assign(&mut self, rhs: Self) {
                *self = *self $op rhs;
            }
        }
    };
}

lane_op!(Add, add, AddAssign, add_assign, +);
lane_op!(Sub, sub, SubAssign, sub_assign, -);

impl Mul for F64x8 {
    type Output = Self;
    #[inline(always)]
    fn mul(self, rhs: Self) -> Self {
        self.zip(rhs, |a, b| a * b)
    }
}

impl Div for F64x8 {
    type Output = Self;
    #[inline(always)]
    fn div(self, rhs: Self) -> Self {
        self.zip(rhs, |a, b| a / b)
    }
}

impl Neg for F64x8 {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        Self::from_fn(|k| -self.0[k])
    }
}
