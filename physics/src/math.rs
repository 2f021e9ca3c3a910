//! 2D vector helpers in the notation of thesis §0.

/// A 2D vector (f64).
pub type Vec2 = nalgebra::Vector2<f64>;

/// Perp-dot product `a ⊗ b = a_x b_y − a_y b_x`, the 2D stand-in for the cross product.
#[inline]
pub(crate) fn cross(a: Vec2, b: Vec2) -> f64 {
    a.x * b.y - a.y * b.x
}

/// `a⊥ = (−a_y, a_x)`: `a` turned by +90°.
#[inline]
pub(crate) fn perp(a: Vec2) -> Vec2 {
    Vec2::new(-a.y, a.x)
}

/// `ω × r` for a scalar angular velocity: the velocity of a point at lever arm `r`.
#[inline]
pub(crate) fn cross_scalar(omega: f64, r: Vec2) -> Vec2 {
    Vec2::new(-omega * r.y, omega * r.x)
}

/// A rotation by an angle, stored as its cosine and sine (in that order: the soft step
/// reads them as a pair).
#[derive(Debug, Clone, Copy, PartialEq)]
#[repr(C)]
pub(crate) struct Rot {
    pub cos: f64,
    pub sin: f64,
}

impl Default for Rot {
    /// No rotation.
    fn default() -> Self {
        Self { cos: 1.0, sin: 0.0 }
    }
}

impl Rot {
    #[inline]
    pub(crate) fn new(angle: f64) -> Self {
        let (sin, cos) = angle.sin_cos();
        Self { cos, sin }
    }

    /// `R(θ)·v`.
    #[inline]
    pub(crate) fn apply(self, v: Vec2) -> Vec2 {
        Vec2::new(
            self.cos * v.x - self.sin * v.y,
            self.sin * v.x + self.cos * v.y,
        )
    }

    /// `R(θ)ᵀ·v`.
    #[inline]
    pub(crate) fn apply_inverse(self, v: Vec2) -> Vec2 {
        Vec2::new(
            self.cos * v.x + self.sin * v.y,
            -self.sin * v.x + self.cos * v.y,
        )
    }
}

/// `x` held within `[lo, hi]`: the upper bound where `hi < x`, then the lower where
/// `lo >` that. Bit for bit `f64::clamp` (a zero keeps its sign) for `lo <= hi`, and
/// as the soft step's lanes clamp; unlike `f64::clamp` it never panics: a NaN bound (a
/// state gone non-finite, which the step reports) is passed over.
#[inline(always)]
pub(crate) fn clamp(x: f64, lo: f64, hi: f64) -> f64 {
    let below_hi = if hi < x { hi } else { x };
    if lo > below_hi { lo } else { below_hi }
}

/// `a` where `a > b`, else `b`: the soft step's lanes' `max`, to the bit.
#[inline(always)]
pub(crate) fn greater(a: f64, b: f64) -> f64 {
    if a > b { a } else { b }
}

/// `a` where `a < b`, else `b`: the soft step's lanes' `min`, to the bit.
#[inline(always)]
pub(crate) fn lesser(a: f64, b: f64) -> f64 {
    if a < b { a } else { b }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn perp_dot_matches_perp_then_dot() {
        let (a, b) = (Vec2::new(1.5, -2.0), Vec2::new(0.25, 3.0));
        assert_eq!(cross(a, b), perp(a).dot(&b));
        assert_eq!(cross_scalar(2.0, a), perp(a) * 2.0);
    }

    /// The soft step uses a contact's reach r · n as its tangent lever r × perp(n): the
    /// same products, one negated twice, so the same number (a zero's sign aside).
    #[test]
    fn the_tangent_lever_is_the_reach() {
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 4.0 - 2.0
        };
        for _ in 0..10_000 {
            let r = Vec2::new(next(), next());
            let n = Rot::new(3.2 * next()).apply(Vec2::new(1.0, 0.0));
            assert_eq!(cross(r, perp(n)), r.dot(&n), "r {r:?}, n {n:?}");
        }
    }

    #[test]
    fn rotation_round_trips() {
        let r = Rot::new(0.7);
        let v = Vec2::new(3.0, -1.0);
        assert!((r.apply_inverse(r.apply(v)) - v).norm() < 1e-15);
        assert!((Rot::new(std::f64::consts::FRAC_PI_2).apply(v) - perp(v)).norm() < 1e-15);
    }
}
