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

use crate::body::Body;

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

    /// The bodies a step moves (bodies `auto` holds for one of its passes among them).
    /// Current only after `refresh`.
    pub(super) fn awake(&self) -> &[u32] {
        debug_assert!(!self.stale, "read before refresh");
        &self.awake
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
