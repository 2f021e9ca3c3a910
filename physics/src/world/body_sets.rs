//! The world's bodies sorted by what a step does with them: static bodies never move,
//! sleeping ones stay where they are until woken, and awake ones are the only ones a
//! step moves. The sets are slots into `World::bodies`, in ascending order, so that a
//! stage walking the awake set visits its bodies in the order a walk over every slot
//! would, and the numbers come out the same.
//!
//! A stage that keeps per-body results (outlines, bounds, reaches) refreshes the awake
//! ones every step and the rest only when the `epoch` it saw has passed: when a body was
//! added or removed, fell asleep or woke, or was handed out by `World::body_mut` while
//! static or asleep (and so may have been moved by hand).
//!
//! Under `auto` a step runs in two passes, each over its part of the awake set: the
//! other part is held, fixed for the pass (no velocity, no inverse mass) as a sleeping
//! body is, while the bodies themselves are left as they are. Every stage of a pass sees
//! the bodies through the sets (`moving`, `is_held`, `velocity_in_pass`).

use crate::body::Body;
use crate::math::{Vec2, cross_scalar};

#[derive(Debug, Clone, Default)]
pub(super) struct BodySets {
    statics: Vec<u32>,
    sleeping: Vec<u32>,
    awake: Vec<u32>,
    /// Counts the changes outside the awake set: a stage that made its results at another
    /// count makes them again for every body.
    epoch: u64,
    /// The lists are to be sorted again from the bodies before they are next read.
    stale: bool,
    /// In a pass of `auto`: per slot, whether the body is held (empty outside a pass).
    held: Vec<bool>,
    /// In a pass of `auto`: the awake bodies not held, increasing.
    pass_moving: Vec<u32>,
}

impl BodySets {
    /// A body outside the awake set may have changed, or a body changed sets.
    pub(super) fn mark_changed(&mut self) {
        self.epoch += 1;
        self.stale = true;
    }

    /// Sorts the bodies into the sets again if anything changed since the last time.
    pub(super) fn refresh(&mut self, bodies: &[Option<Body>]) {
        if !std::mem::take(&mut self.stale) {
            return;
        }
        debug_assert!(self.held.is_empty(), "the sets changed within a pass");
        self.statics.clear();
        self.sleeping.clear();
        self.awake.clear();
        for (i, body) in bodies.iter().enumerate() {
            let Some(body) = body else {
                continue;
            };
            let set = if body.is_static() {
                &mut self.statics
            } else if body.is_asleep() {
                &mut self.sleeping
            } else {
                &mut self.awake
            };
            set.push(i as u32);
        }
    }

    /// The bodies a step moves, those `auto` holds for one of its passes among them: the
    /// bodies whose kept results are made again for each pass. Current only after
    /// `refresh`.
    pub(super) fn awake(&self) -> &[u32] {
        debug_assert!(!self.stale, "read before refresh");
        &self.awake
    }

    /// The bodies this pass moves: the awake ones, less those held (current after
    /// `refresh`).
    pub(super) fn moving(&self) -> &[u32] {
        if !self.in_pass() {
            self.awake()
        } else {
            &self.pass_moving
        }
    }

    /// Starts a pass of `auto` that holds the awake bodies for which `held` is true: they
    /// are fixed to every stage of the pass until `end_pass`.
    pub(super) fn hold_for_pass(&mut self, slots: usize, held: impl Fn(u32) -> bool) {
        debug_assert!(!self.stale, "read before refresh");
        self.held.clear();
        self.held.resize(slots, false);
        self.pass_moving.clear();
        for &i in &self.awake {
            if held(i) {
                self.held[i as usize] = true;
            } else {
                self.pass_moving.push(i);
            }
        }
    }

    /// Ends `auto`'s pass: every awake body moves again.
    pub(super) fn end_pass(&mut self) {
        self.held.clear();
        self.pass_moving.clear();
    }

    /// Whether a pass of `auto` is under way (`hold_for_pass`).
    pub(super) fn in_pass(&self) -> bool {
        !self.held.is_empty()
    }

    /// Whether the body in `slot` is held still for this pass of `auto`.
    pub(super) fn is_held(&self, slot: u32) -> bool {
        self.held.get(slot as usize).is_some_and(|&held| held)
    }

    /// Whether this pass leaves the body in `slot` where it is: static, asleep or held.
    pub(super) fn fixed_in_pass(&self, slot: u32, body: &Body) -> bool {
        body.is_fixed() || self.is_held(slot)
    }

    /// The body's velocity and spin as this pass sees them: none for a body held still
    /// (it moves in its own pass; seen moving here, it would be moved twice).
    pub(super) fn velocity_in_pass(&self, slot: u32, body: &Body) -> (Vec2, f64) {
        if self.is_held(slot) {
            (Vec2::zeros(), 0.0)
        } else {
            (body.velocity, body.angular_velocity)
        }
    }

    /// The velocity of the body's material point at `point` as this pass sees it.
    pub(super) fn velocity_at_in_pass(&self, slot: u32, body: &Body, point: Vec2) -> Vec2 {
        let (velocity, spin) = self.velocity_in_pass(slot, body);
        velocity + cross_scalar(spin, point - body.position)
    }

    /// The static bodies (current after `refresh`).
    pub(super) fn statics(&self) -> &[u32] {
        debug_assert!(!self.stale, "read before refresh");
        &self.statics
    }

    /// The sleeping bodies (current after `refresh`).
    pub(super) fn sleeping(&self) -> &[u32] {
        debug_assert!(!self.stale, "read before refresh");
        &self.sleeping
    }

    /// The slots whose kept results are to be made again: every one of the `slots` if the
    /// sets changed since `made` or the kept results are not `whole` (one for every
    /// slot, made for the same inputs), else only the awake ones.
    pub(super) fn to_remake(&self, made: &mut EpochSeen, whole: bool, slots: usize) -> Slots<'_> {
        if made.sets_changed(self) || !whole {
            Slots::Every(0..slots as u32)
        } else {
            Slots::Awake(self.awake().iter())
        }
    }

    /// Whether some body is asleep, and whether some body is awake (current after
    /// `refresh`).
    pub(super) fn some_asleep_and_awake(&self) -> (bool, bool) {
        debug_assert!(!self.stale, "read before refresh");
        (!self.sleeping.is_empty(), !self.awake.is_empty())
    }
}

/// The slots whose kept results are made again (`BodySets::to_remake`): every one, or
/// the awake bodies'.
#[derive(Debug, Clone)]
pub(super) enum Slots<'a> {
    Every(std::ops::Range<u32>),
    Awake(std::slice::Iter<'a, u32>),
}

impl Slots<'_> {
    /// Every slot, not only the awake ones.
    pub(super) fn every(&self) -> bool {
        matches!(self, Slots::Every(_))
    }
}

impl Iterator for Slots<'_> {
    type Item = u32;
    fn next(&mut self) -> Option<u32> {
        match self {
            Slots::Every(range) => range.next(),
            Slots::Awake(slots) => slots.next().copied(),
        }
    }
}

/// The sets' epoch that a stage's kept per-body results were made at (none yet: made
/// at none).
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct EpochSeen(Option<u64>);

impl EpochSeen {
    /// Whether the sets changed since the last call (or since ever): then every body's
    /// result is to be made again, and not only the awake ones'.
    pub(super) fn sets_changed(&mut self, sets: &BodySets) -> bool {
        let now = Some(sets.epoch);
        std::mem::replace(&mut self.0, now) != now
    }

    /// The epoch last seen, if any.
    pub(super) fn epoch(&self) -> Option<u64> {
        self.0
    }
}
