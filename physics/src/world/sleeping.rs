//! Sleeping: islands at rest long enough fall asleep, and wake when an awake body can
//! reach them or a motor on them switches on.

use super::World;
use crate::body::{Body, BodyHandle};
use crate::collide::{Aabb, BroadPhase};
use crate::math::Vec2;
use crate::solver::island::{UnionFind, merged_increasing};

/// Sleeping's and waking's buffers, reused from step to step.
#[derive(Debug, Clone, Default)]
pub(super) struct SleepScratch {
    /// The islands to wake.
    wake_labels: Vec<u32>,
    /// Waking's own broad phase, its bounding boxes and reaches by slot, the slots boxed
    /// and the pairs found.
    wake_broad_phase: BroadPhase,
    wake_boxes: Vec<Option<Aabb>>,
    wake_reach: Vec<f64>,
    wake_slots: Vec<u32>,
    wake_pairs: Vec<(u32, u32)>,
    /// The islands of the bodies still awake at the step's end, and whether each may
    /// sleep.
    island_union: UnionFind,
    island_ready: Vec<bool>,
}

/// Seconds an island must stay still before it sleeps.
const SLEEP_AFTER: f64 = 0.5;

impl World {
    /// Wakes `handle` and everything asleep in its island.
    pub fn wake_body(&mut self, handle: BodyHandle) {
        let Some(label) = self.sleep_labels.get(handle.index()).copied() else {
            return;
        };
        if self.body(handle).is_some_and(|b| b.asleep) {
            self.wake_island(label);
        }
    }

    fn wake_island(&mut self, label: u32) {
        for (body, &l) in self.bodies.iter_mut().zip(&self.sleep_labels) {
            if let Some(b) = body
                && b.asleep
                && l == label
            {
                b.wake();
            }
        }
        self.sets.mark_changed();
    }

    /// Wakes sleeping islands that an awake body can reach this step, and those with a
    /// motor switching on. Candidates come from the broad phase over the bodies' bounding
    /// circles (each awake one grown by its reach), so the cost follows the bodies near
    /// each other, not awake × asleep.
    pub(super) fn wake_where_needed(&mut self, dt: f64) {
        let margin = self.settings.contact_margin();
        let mut wake = std::mem::take(&mut self.scratch.sleeping.wake_labels);
        wake.clear();
        self.sets.refresh(&self.bodies);
        let (some_asleep, some_awake) = self.sets.some_asleep_and_awake();
        if some_asleep && some_awake {
            let reach = |b: &Body| {
                (b.velocity.norm()
                    + b.angular_velocity.abs() * b.bounding_radius()
                    + self.gravity.norm() * dt)
                    * dt
            };
            // Boxes for the bodies that can move, asleep or awake, by slot (the static
            // ones take no part).
            let s = &mut self.scratch.sleeping;
            let n = self.bodies.len();
            s.wake_boxes.resize(n, None);
            s.wake_reach.resize(n, 0.0);
            s.wake_slots.clear();
            let (awake, sleeping) = (self.sets.awake(), self.sets.sleeping());
            s.wake_slots.extend(merged_increasing(awake, sleeping));
            for &i in &s.wake_slots {
                let b = self.bodies[i as usize]
                    .as_ref()
                    .expect("a body that can move");
                let r = if b.asleep { 0.0 } else { reach(b) };
                let half = b.bounding_radius() + r + 0.5 * margin;
                s.wake_reach[i as usize] = r;
                s.wake_boxes[i as usize] = Some(Aabb {
                    min: b.position - Vec2::new(half, half),
                    max: b.position + Vec2::new(half, half),
                });
            }
            let bodies = &self.bodies;
            let asleep = |i: usize| bodies[i].as_ref().is_some_and(|b| b.asleep);
            let wanted = |i, j| asleep(i) != asleep(j);
            s.wake_broad_phase
                .pairs_among(&s.wake_boxes, &s.wake_slots, wanted, &mut s.wake_pairs);
            for &(i, j) in &s.wake_pairs {
                let (sleeper, awake) = if asleep(i as usize) { (i, j) } else { (j, i) };
                let (b, a) = (
                    bodies[sleeper as usize].as_ref().expect("boxed"),
                    bodies[awake as usize].as_ref().expect("boxed"),
                );
                let apart =
                    (b.position - a.position).norm() - b.bounding_radius() - a.bounding_radius();
                if apart <= margin + s.wake_reach[awake as usize] {
                    wake.push(self.sleep_labels[sleeper as usize]);
                }
            }
        }
        let step = self.step_count;
        for (h, m) in &self.body_motors {
            if m.is_on(step) && self.body(*h).is_some_and(|b| b.asleep) {
                wake.push(self.sleep_labels[h.index()]);
            }
        }
        for j in self.joints.iter().flatten() {
            if j.motor.is_some_and(|m| m.enabled) {
                for h in [Some(j.body_a), j.body_b].into_iter().flatten() {
                    if self.body(h).is_some_and(|b| b.asleep) {
                        wake.push(self.sleep_labels[h.index()]);
                    }
                }
            }
        }
        wake.sort_unstable();
        wake.dedup();
        for &label in &wake {
            self.wake_island(label);
        }
        self.scratch.sleeping.wake_labels = wake;
    }

    /// Times how long each awake body has been still, and puts to sleep the islands whose
    /// bodies have all been still long enough.
    pub(super) fn sleep_where_still(&mut self, dt: f64) {
        let tolerance = self.settings.sleep_speed();
        for &i in self.sets.awake() {
            let b = self.bodies[i as usize].as_mut().expect("an awake body");
            let speed = b.velocity.norm() + b.angular_velocity.abs() * b.bounding_radius();
            b.still_time = if speed < tolerance {
                b.still_time + dt
            } else {
                0.0
            };
        }
        let n = self.bodies.len();
        let moving = |bodies: &[Option<Body>], i: u32| {
            bodies[i as usize].as_ref().is_some_and(|b| !b.is_fixed())
        };
        let uf = &mut self.scratch.sleeping.island_union;
        uf.reset(n);
        for c in &self.contacts {
            if moving(&self.bodies, c.body_a.0) && moving(&self.bodies, c.body_b.0) {
                uf.union(c.body_a.0, c.body_b.0);
            }
        }
        for j in self.joints.iter().flatten() {
            if let Some(b) = j.body_b
                && moving(&self.bodies, j.body_a.0)
                && moving(&self.bodies, b.0)
            {
                uf.union(j.body_a.0, b.0);
            }
        }
        // An island may sleep when its stillest-to-be body has waited long enough and no
        // motor in it runs.
        let mut ready = std::mem::take(&mut self.scratch.sleeping.island_ready);
        ready.clear();
        ready.resize(n, true);
        for &i in self.sets.awake() {
            let b = self.bodies[i as usize].as_ref().expect("an awake body");
            if b.still_time < SLEEP_AFTER {
                ready[uf.find(i) as usize] = false;
            }
        }
        let step = self.step_count;
        for (h, m) in &self.body_motors {
            if m.is_on(step) {
                ready[uf.find(h.0) as usize] = false;
            }
        }
        for j in self.joints.iter().flatten() {
            if j.motor.is_some_and(|m| m.enabled) {
                ready[uf.find(j.body_a.0) as usize] = false;
                if let Some(b) = j.body_b {
                    ready[uf.find(b.0) as usize] = false;
                }
            }
        }
        self.sleep_labels.resize(n, u32::MAX);
        let mut some_fell_asleep = false;
        for &i in self.sets.awake() {
            let root = uf.find(i);
            if ready[root as usize] {
                let b = self.bodies[i as usize].as_mut().expect("an awake body");
                b.fall_asleep();
                self.sleep_labels[i as usize] = root;
                some_fell_asleep = true;
            }
        }
        if some_fell_asleep {
            self.sets.mark_changed();
        }
        self.scratch.sleeping.island_ready = ready;
    }
}
