//! Restitution, once after the substeps: the points that approached faster than the
//! threshold and pushed bounce, a manifold's two points together.

use super::SoftStepSolver;
use super::constraints::PointConstraint;
use super::contacts::{BodyPair, apply_normal, solve_normal_pair};

impl SoftStepSolver {
    /// Restitution once, after the substeps, for contacts that were approaching faster
    /// than the threshold and did push.
    ///
    /// A flat face landing bounces on both corners at once: solved one corner at a time,
    /// the first would tip the body and the second bounce less.
    pub(super) fn restitution(&mut self, bounce_below: f64) {
        let bounces = |p: &PointConstraint| {
            p.restitution != 0.0
                && p.relative_velocity <= -bounce_below
                && p.max_normal_impulse != 0.0
        };
        let mut i = 0;
        while i < self.points.len() {
            let paired = self.points[i].pair_coupling.is_some();
            if paired && bounces(&self.points[i]) && bounces(&self.points[i + 1]) {
                let (first, second) = self.points.split_at_mut(i + 1);
                let (p, q) = (&mut first[i], &mut second[0]);
                let target = |p: &PointConstraint| -p.restitution * p.relative_velocity;
                let targets = (target(p), target(q));
                let mut pair = BodyPair::load(&self.loaded.bodies, p.a, p.b);
                let velocities = (pair.normal_velocity(p), pair.normal_velocity(q));
                solve_normal_pair(&mut pair, (p, q), velocities, targets);
                pair.store(&mut self.loaded.bodies);
                i += 2;
                continue;
            }
            let stride = if paired { 2 } else { 1 };
            for p in &mut self.points[i..i + stride] {
                if bounces(p) {
                    let mut pair = BodyPair::load(&self.loaded.bodies, p.a, p.b);
                    let vn = pair.normal_velocity(p);
                    let impulse = -p.normal_mass * (vn + p.restitution * p.relative_velocity);
                    apply_normal(&mut pair, p, p.normal_impulse + impulse);
                    pair.store(&mut self.loaded.bodies);
                }
            }
            i += stride;
        }
    }
}
