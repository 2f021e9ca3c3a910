//! Four f64 lanes, written as plain arrays so that the compiler vectorises them: with
//! AVX2 (chosen at run time, see `ManifoldBatch::solve`) each operation is one 256-bit
//! instruction; without, two SSE2 ones. Every lane rounds as the scalar code does, so
//! both paths give the same bits.

use std::ops::{Add, AddAssign, BitAnd, BitXor, Mul, Neg, Sub, SubAssign};

#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[repr(C, align(32))]
pub(super) struct F64x4(pub [f64; 4]);

/// A lane-wise condition, each lane all ones or all zeros as a vector comparison leaves
/// it, so that choosing by it is one blend (a `bool` per lane cost conversions both ways).
#[derive(Debug, Clone, Copy, PartialEq)]
#[repr(C, align(32))]
pub(super) struct Mask4([u64; 4]);

impl F64x4 {
    #[inline(always)]
    pub fn splat(x: f64) -> Self {
        Self([x; 4])
    }

    #[inline(always)]
    pub fn from_fn(f: impl FnMut(usize) -> f64) -> Self {
        Self(std::array::from_fn(f))
    }

    #[inline(always)]
    fn zip(self, rhs: Self, f: impl Fn(f64, f64) -> f64) -> Self {
        Self::from_fn(|k| f(self.0[k], rhs.0[k]))
    }

    #[inline(always)]
    fn compare(self, rhs: Self, f: impl Fn(f64, f64) -> bool) -> Mask4 {
        Mask4(std::array::from_fn(|k| {
            if f(self.0[k], rhs.0[k]) { u64::MAX } else { 0 }
        }))
    }

    /// The larger of each pair (for numbers; no NaN reaches the solver).
    #[inline(always)]
    pub fn max(self, rhs: Self) -> Self {
        self.zip(rhs, |a, b| if a > b { a } else { b })
    }

    #[inline(always)]
    pub fn min(self, rhs: Self) -> Self {
        self.zip(rhs, |a, b| if a < b { a } else { b })
    }

    /// `f64::clamp` lane by lane, to the bit (a zero keeps its sign as there), for
    /// `lo <= hi`: the upper bound where `hi < x`, then the lower where `lo > ` that, which
    /// are one `minpd` and one `maxpd`.
    #[inline(always)]
    pub fn clamp(self, lo: Self, hi: Self) -> Self {
        let below_hi = hi.zip(self, |hi, x| if hi < x { hi } else { x });
        lo.zip(below_hi, |lo, t| if lo > t { lo } else { t })
    }

    #[inline(always)]
    pub fn sqrt(self) -> Self {
        Self::from_fn(|k| self.0[k].sqrt())
    }

    #[inline(always)]
    pub fn gt(self, rhs: Self) -> Mask4 {
        self.compare(rhs, |a, b| a > b)
    }

    #[inline(always)]
    pub fn ge(self, rhs: Self) -> Mask4 {
        self.compare(rhs, |a, b| a >= b)
    }

    #[inline(always)]
    pub fn lt(self, rhs: Self) -> Mask4 {
        self.compare(rhs, |a, b| a < b)
    }

    #[inline(always)]
    pub fn eq(self, rhs: Self) -> Mask4 {
        self.compare(rhs, |a, b| a == b)
    }

    #[inline(always)]
    pub fn ne(self, rhs: Self) -> Mask4 {
        self.compare(rhs, |a, b| a != b)
    }
}

impl Mask4 {
    #[inline(always)]
    pub fn any(self) -> bool {
        self.0.iter().fold(0, |any, &m| any | m) != 0
    }

    /// `if_true` where the condition holds, `if_false` elsewhere (bit for bit).
    #[inline(always)]
    pub fn select(self, if_true: F64x4, if_false: F64x4) -> F64x4 {
        F64x4::from_fn(|k| {
            let m = self.0[k];
            f64::from_bits((if_true.0[k].to_bits() & m) | (if_false.0[k].to_bits() & !m))
        })
    }
}

impl BitAnd for Mask4 {
    type Output = Self;
    #[inline(always)]
    fn bitand(self, rhs: Self) -> Self {
        Self(std::array::from_fn(|k| self.0[k] & rhs.0[k]))
    }
}

impl BitXor for Mask4 {
    type Output = Self;
    #[inline(always)]
    fn bitxor(self, rhs: Self) -> Self {
        Self(std::array::from_fn(|k| self.0[k] ^ rhs.0[k]))
    }
}

macro_rules! lane_op {
    ($trait:ident, $method:ident, $assign_trait:ident, $assign:ident, $op:tt) => {
        impl $trait for F64x4 {
            type Output = Self;
            #[inline(always)]
            fn $method(self, rhs: Self) -> Self {
                self.zip(rhs, |a, b| a $op b)
            }
        }

        impl $assign_trait for F64x4 {
            #[inline(always)]
            fn $assign(&mut self, rhs: Self) {
                *self = *self $op rhs;
            }
        }
    };
}

lane_op!(Add, add, AddAssign, add_assign, +);
lane_op!(Sub, sub, SubAssign, sub_assign, -);

impl Mul for F64x4 {
    type Output = Self;
    #[inline(always)]
    fn mul(self, rhs: Self) -> Self {
        self.zip(rhs, |a, b| a * b)
    }
}

impl Neg for F64x4 {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        Self::from_fn(|k| -self.0[k])
    }
}
