//! The step's contacts: the narrow phase over the candidate pairs (or a pair's last
//! manifold, reused), the speculative manifolds that cannot act dropped, and each
//! manifold's points made contacts.

use super::{Pipeline, World};
use crate::body::{Body, BodyHandle};
use crate::collide::{Manifold, collide_polygons_into};
use crate::math::Vec2;
use crate::solver::contact::{Contact, mixed_friction};
use crate::stage_clock::{self, Stage};

/// No more than the sum of their reaches, and nothing for bodies moving together.
fn relative_reach((shift_a, turn_a): (Vec2, f64), (shift_b, turn_b): (Vec2, f64)) -> f64 {
    (shift_a - shift_b).norm() + turn_a + turn_b
}

/// Whether two bodies may move relative to each other by more than `distance` in a step:
/// `relative_reach(a, b) > distance`, without its square root (it is asked of every
/// manifold).
fn relative_reach_exceeds(
    (shift_a, turn_a): (Vec2, f64),
    (shift_b, turn_b): (Vec2, f64),
    distance: f64,
) -> bool {
    let left = distance - turn_a - turn_b;
    left < 0.0 || (shift_a - shift_b).norm_squared() > left * left
}

impl World {
    /// Broad phase, then SAT on each candidate pair (thesis §3.1), or the pair's last
    /// manifold where it has barely moved (`collide::reuse`).
    ///
    /// Each body's bounds and contact margin grow by how far it can move this step, so a
    /// contact is found (as a speculative one) before the bodies meet, however fast; those
    /// that cannot act this step are then dropped (`drop_idle_manifolds`).
    pub(super) fn detect_contacts(&mut self, dt: f64, pipeline: Pipeline) {
        let started = stage_clock::mark();
        if !std::mem::take(&mut self.scratch.candidates_current) {
            self.find_candidate_pairs(dt);
        }
        self.profile.record(Stage::BroadPhase, started);
        let started = stage_clock::mark();
        let s = &mut self.scratch;
        let margin = self.settings.contact_margin();
        self.manifolds.clear();
        self.contacts.clear();
        let tie = self.settings.tie_tolerance();
        let reuse_tolerance = self.settings.manifold_reuse_tolerance();
        let cache = &mut self.manifold_caches[pipeline as usize];
        if self.settings.reuse_manifolds {
            cache.begin_step();
        } else {
            cache.clear();
        }
        for &(i, j) in &s.pairs {
            let (a, b) = (BodyHandle(i), BodyHandle(j));
            let (pose_a, pose_b) = (
                &self.bounds.poses[i as usize],
                &self.bounds.poses[j as usize],
            );
            let pair_margin =
                margin + self.bounds.reach[i as usize] + self.bounds.reach[j as usize];
            // A reused manifold is made in its place in the list (`reuse_into`).
            let limits = (pair_margin, reuse_tolerance);
            if self.settings.reuse_manifolds
                && cache.reuse_into((a, pose_a), (b, pose_b), limits, &mut self.manifolds)
            {
                continue;
            }
            self.bounds.polygons[i as usize].ensure_normals();
            self.bounds.polygons[j as usize].ensure_normals();
            let found = collide_polygons_into(
                (a, &self.bounds.polygons[i as usize]),
                (b, &self.bounds.polygons[j as usize]),
                (pair_margin, tie),
                &mut self.manifolds,
            );
            // A pair that may move past the reuse tolerance in this step will not be reused
            // at the next one: flying debris would fill the cache with manifolds that are
            // never read.
            let (motion_a, motion_b) = (
                self.bounds.motion[i as usize],
                self.bounds.motion[j as usize],
            );
            if found
                && self.settings.reuse_manifolds
                && !relative_reach_exceeds(motion_a, motion_b, reuse_tolerance)
                && let Some(m) = self.manifolds.last()
            {
                cache.store(m, (pose_a, pose_b), pair_margin);
            }
        }
        self.profile.record(Stage::NarrowPhase, started);
        let started = stage_clock::mark();
        self.drop_idle_manifolds(margin);
        for m in &self.manifolds {
            let body = |h: BodyHandle| self.bodies.get(h.index()).and_then(Option::as_ref);
            let (Some(a), Some(b)) = (body(m.body_a), body(m.body_b)) else {
                continue;
            };
            let friction = mixed_friction(
                a.friction.unwrap_or(self.friction),
                b.friction.unwrap_or(self.friction),
            );
            let start = &self.inputs.start_velocities;
            let sets = &self.sets;
            let approach = |h: BodyHandle, body: &Body, point: Vec2| {
                let (v, w) = start
                    .get(h.index())
                    .copied()
                    .unwrap_or_else(|| sets.velocity_in_pass(h.0, body));
                (v + crate::math::cross_scalar(w, point - body.position)).dot(&m.normal)
            };
            for p in m.points() {
                let approach_velocity =
                    approach(m.body_a, a, p.position) - approach(m.body_b, b, p.position);
                // Without velocities kept from the step's start (the soft step's forces
                // act inside its substeps), the approach is the velocity now.
                let normal_velocity = if start.is_empty() {
                    approach_velocity
                } else {
                    let velocity_a = sets.velocity_at_in_pass(m.body_a.0, a, p.position);
                    let velocity_b = sets.velocity_at_in_pass(m.body_b.0, b, p.position);
                    (velocity_a - velocity_b).dot(&m.normal)
                };
                self.contacts.push(Contact {
                    body_a: m.body_a,
                    body_b: m.body_b,
                    point: p.position,
                    normal: m.normal,
                    depth: p.depth,
                    id: p.id,
                    restitution: a.restitution.min(b.restitution),
                    friction,
                    approach_velocity,
                    normal_velocity,
                    normal_impulse: 0.0,
                    tangent_impulse: 0.0,
                });
            }
        }
        self.profile.record(Stage::Contacts, started);
    }

    /// Drops the speculative manifolds that cannot act this step: every point farther off
    /// than the two bodies can close on each other (`relative_reach`), allowing for how
    /// far a collision within the step may turn either one off its course.
    ///
    /// Each body's reach finds the manifolds whatever way a collision may send it; of
    /// those, debris flying off together keeps most that cannot act. The allowance is the
    /// guard for the turn: a body closing on others at speed v along their normals may
    /// change velocity by up to 2v (a bounce), and a pinned or motor-driven body by
    /// anything. Dropped on the relative reach alone, a body bounced off a wall into one
    /// it had no points with (docs/bench/profile.md, "Speculative manifolds that cannot
    /// act").
    fn drop_idle_manifolds(&mut self, margin: f64) {
        let s = &mut self.scratch;
        let motion = &self.bounds.motion;
        let gap_after = |m: &Manifold| {
            let (a, b) = (motion[m.body_a.index()], motion[m.body_b.index()]);
            -m.depth() - relative_reach(a, b)
        };
        // A manifold within the margin can close whatever the bodies do: a pile's, and
        // anything at rest, found without a square root.
        let within = |m: &Manifold| -m.depth() <= margin;
        if self.manifolds.iter().all(within) {
            return;
        }
        s.gaps.clear();
        s.gaps.extend(self.manifolds.iter().map(gap_after));
        // How far each body may be turned off its course this step.
        s.turn_off.clear();
        s.turn_off.resize(self.bodies.len(), 0.0);
        for &i in &self.jointed {
            s.turn_off[i as usize] = f64::INFINITY;
        }
        for (h, _) in &self.body_motors {
            s.turn_off[h.index()] = f64::INFINITY;
        }
        for (m, _) in self
            .manifolds
            .iter()
            .zip(&s.gaps)
            .filter(|(_, g)| **g <= margin)
        {
            let ((shift_a, turn_a), (shift_b, turn_b)) =
                (motion[m.body_a.index()], motion[m.body_b.index()]);
            let closing = (-(shift_a - shift_b).dot(&m.normal)).max(0.0) + turn_a + turn_b;
            s.turn_off[m.body_a.index()] += 2.0 * closing;
            s.turn_off[m.body_b.index()] += 2.0 * closing;
        }
        let mut k = 0;
        self.manifolds.retain(|m| {
            let allowance = s.turn_off[m.body_a.index()] + s.turn_off[m.body_b.index()];
            let keep = s.gaps[k] <= margin + allowance;
            k += 1;
            keep
        });
    }
}
