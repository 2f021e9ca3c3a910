//! A bounce adds no kinetic energy. Newton's law of restitution (thesis eq. 19) asks each
//! point to leave at e times its approach; solved for several points at once (a face's
//! two corners, a rack of balls struck together, an approach read before another impact
//! changed it) its answer can leave the bodies faster than they came (docs/physics.md,
//! "What the solvers guarantee"). Poisson's reading of a collision, the restitution
//! impulse at most the compression's, adds none. Every solve that bounces is held to that: if its
//! answer has more kinetic energy than the bodies brought (or than the same solve without
//! a bounce leaves, where motors work), the answer becomes the inelastic one plus the
//! largest share of the bounce that keeps the energy within it. Both answers satisfy the
//! pins, the contacts and the friction bounds, and so does every mix of the two.

use super::SolverBody;
use crate::math::Vec2;

/// The velocities of a solve's bodies, by slot, kept to compare and mix answers.
#[derive(Debug, Clone, Default)]
pub(crate) struct KeptVelocities {
    slots: Vec<u32>,
    velocities: Vec<(Vec2, f64)>,
}

impl KeptVelocities {
    /// Keeps the velocities of `slots` (sorted and deduplicated here).
    pub(crate) fn keep(&mut self, bodies: &[SolverBody], slots: impl Iterator<Item = u32>) {
        self.slots.clear();
        self.slots.extend(slots);
        self.slots.sort_unstable();
        self.slots.dedup();
        self.velocities.clear();
        self.velocities.extend(self.slots.iter().map(|&i| {
            let b = &bodies[i as usize];
            (b.velocity, b.angular_velocity)
        }));
    }

    /// Keeps the same slots' velocities as `other` did, as they are now.
    pub(crate) fn keep_like(&mut self, other: &KeptVelocities, bodies: &[SolverBody]) {
        self.keep(bodies, other.slots.iter().copied());
    }

    /// Puts the kept velocities back.
    pub(crate) fn restore(&self, bodies: &mut [SolverBody]) {
        for (&i, &(v, w)) in self.slots.iter().zip(&self.velocities) {
            bodies[i as usize].velocity = v;
            bodies[i as usize].angular_velocity = w;
        }
    }

    /// The kinetic energy of the kept velocities, with the bodies' masses.
    pub(crate) fn kinetic_energy(&self, bodies: &[SolverBody]) -> f64 {
        self.slots
            .iter()
            .zip(&self.velocities)
            .map(|(&i, &(v, w))| {
                SolverBody {
                    velocity: v,
                    angular_velocity: w,
                    ..bodies[i as usize]
                }
                .kinetic_energy()
            })
            .sum()
    }
}

/// What holding a bounce to the energy brought needs: the velocities of the solve's
/// bodies before it, after it and after the same solve without a bounce, and the
/// bouncing solve's impulses. The exact solver's islands and the impact pass's pairs go
/// through it alike: `before`, the bouncing solve, `bounced`; if that gained energy,
/// `undo_bounce`, the solve without a bounce, `hold`.
#[derive(Debug, Clone, Default)]
pub(crate) struct BounceGuard {
    before: KeptVelocities,
    full: KeptVelocities,
    inelastic: KeptVelocities,
    x_full: Vec<f64>,
}

impl BounceGuard {
    /// Keeps the velocities of the bodies at `slots` before the bouncing solve; their
    /// kinetic energy, what the bodies brought.
    pub(crate) fn before(
        &mut self,
        bodies: &[SolverBody],
        slots: impl Iterator<Item = u32>,
    ) -> f64 {
        self.before.keep(bodies, slots);
        self.before.kinetic_energy(bodies)
    }

    /// After the bouncing solve: keeps its velocities; their kinetic energy.
    pub(crate) fn bounced(&mut self, bodies: &[SolverBody]) -> f64 {
        self.full.keep_like(&self.before, bodies);
        self.full.kinetic_energy(bodies)
    }

    /// The bodies as they were before the bouncing solve.
    pub(crate) fn restore_before(&self, bodies: &mut [SolverBody]) {
        self.before.restore(bodies);
    }

    /// Keeps the bouncing solve's impulses `x` and puts the bodies back as they were
    /// before it, for the same solve without a bounce.
    pub(crate) fn undo_bounce(&mut self, bodies: &mut [SolverBody], x: &[f64]) {
        self.x_full.clear();
        self.x_full.extend_from_slice(x);
        self.before.restore(bodies);
    }

    /// After the solve without a bounce, whose impulses are `x`: the bodies and `x`
    /// become that answer plus the largest share of the bounce that keeps the energy
    /// within what was `brought` (or what the answer without a bounce leaves, where
    /// motors work), or the whole bounce where that is within it.
    pub(crate) fn hold(
        &mut self,
        bodies: &mut [SolverBody],
        brought: f64,
        bounced: f64,
        x: &mut [f64],
    ) {
        self.inelastic.keep_like(&self.before, bodies);
        let allowed = brought.max(self.inelastic.kinetic_energy(bodies));
        if !gains_energy(allowed, bounced) {
            self.full.restore(bodies);
            x.copy_from_slice(&self.x_full);
            return;
        }
        let s = bounce_share(&self.inelastic, &self.full, bodies, allowed);
        mix_velocities(&self.inelastic, &self.full, s, bodies);
        for (x, &full) in x.iter_mut().zip(&self.x_full) {
            *x += (full - *x) * s;
        }
    }
}

/// The largest share s in [0, 1] of the way from `inelastic` to `full` (the same slots)
/// at which the bodies have at most `allowed` kinetic energy, given that `inelastic` has
/// no more than that. The energy along the way is a convex quadratic in s.
pub(crate) fn bounce_share(
    inelastic: &KeptVelocities,
    full: &KeptVelocities,
    bodies: &[SolverBody],
    allowed: f64,
) -> f64 {
    let (mut c0, mut c1, mut c2) = (0.0, 0.0, 0.0);
    for ((&i, &(v, w)), &(v_full, w_full)) in inelastic
        .slots
        .iter()
        .zip(&inelastic.velocities)
        .zip(&full.velocities)
    {
        let b = &bodies[i as usize];
        let mass = if b.inv_mass > 0.0 {
            1.0 / b.inv_mass
        } else {
            0.0
        };
        let inertia = if b.inv_inertia > 0.0 {
            1.0 / b.inv_inertia
        } else {
            0.0
        };
        let (dv, dw) = (v_full - v, w_full - w);
        c0 += 0.5 * (mass * v.norm_squared() + inertia * w * w);
        c1 += mass * v.dot(&dv) + inertia * w * dw;
        c2 += 0.5 * (mass * dv.norm_squared() + inertia * dw * dw);
    }
    if c2 <= 0.0 || !(c0 + c1 + c2).is_finite() {
        return 0.0;
    }
    let room = (allowed - c0).max(0.0);
    let s = (-c1 + (c1 * c1 + 4.0 * c2 * room).sqrt()) / (2.0 * c2);
    // A hair short of the root, so that rounding cannot put the mix above `allowed`.
    (s * (1.0 - 1e-12)).clamp(0.0, 1.0)
}

/// Sets the kept slots' velocities to `inelastic` + s·(`full` − `inelastic`).
pub(crate) fn mix_velocities(
    inelastic: &KeptVelocities,
    full: &KeptVelocities,
    s: f64,
    bodies: &mut [SolverBody],
) {
    for ((&i, &(v, w)), &(v_full, w_full)) in inelastic
        .slots
        .iter()
        .zip(&inelastic.velocities)
        .zip(&full.velocities)
    {
        bodies[i as usize].velocity = v + (v_full - v) * s;
        bodies[i as usize].angular_velocity = w + (w_full - w) * s;
    }
}

/// Whether `after` has more kinetic energy than `before` allows (a relative 1e-12 for
/// rounding), or is not a number.
pub(crate) fn gains_energy(before: f64, after: f64) -> bool {
    let allowed = before * (1.0 + 1e-12) + f64::MIN_POSITIVE;
    after.is_nan() || after > allowed
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two unit masses, one at rest: the share that brings the pair's energy to exactly
    /// what is allowed, found from the quadratic.
    #[test]
    fn the_share_meets_the_allowed_energy() {
        let bodies = vec![
            SolverBody {
                inv_mass: 1.0,
                inv_inertia: 1.0,
                ..Default::default()
            };
            2
        ];
        let mut moving = bodies.clone();
        let mut inelastic = KeptVelocities::default();
        moving[0].velocity = Vec2::new(1.0, 0.0);
        moving[1].velocity = Vec2::new(1.0, 0.0);
        inelastic.keep(&moving, 0..2);
        let mut full = KeptVelocities::default();
        moving[0].velocity = Vec2::new(-1.0, 0.0);
        moving[1].velocity = Vec2::new(4.0, 0.0);
        full.keep(&moving, 0..2);
        // Energy along the way: ½((1 − 2s)² + (1 + 3s)²) = 1 + s + 6.5s²; allowed 2 (the
        // pair brought one unit mass at 2): s = (√27 − 1)/13.
        let s = bounce_share(&inelastic, &full, &bodies, 2.0);
        assert!((s - (27f64.sqrt() - 1.0) / 13.0).abs() < 1e-12, "{s}");
        mix_velocities(&inelastic, &full, s, &mut moving);
        let energy: f64 = moving.iter().map(SolverBody::kinetic_energy).sum();
        assert!(energy <= 2.0 && energy > 2.0 - 1e-9, "{energy}");
    }
}
