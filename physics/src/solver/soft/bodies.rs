//! The bodies as the soft step reads them (`SoftBody`, the null body last), loaded at the
//! step's start, and which of them move, are in motion or are pinned.

use super::SoftBody;
use crate::math::Vec2;
use crate::solver::SolverBody;
use crate::solver::island::merged_increasing;
use crate::solver::joint::JointConstraint;

/// The soft step's bodies, by slot, and the lists of which move: loaded whole, or only
/// those the world says changed and the fixed ones with a velocity.
#[derive(Debug, Clone, Default)]
pub(super) struct LoadedBodies {
    pub(super) bodies: Vec<SoftBody>,
    /// By body, whether a pin joins it (empty if there are no pins): such a body's
    /// island is solved with the rest, not in a chunk (`PassPlan::assign_chunks`).
    pub(super) pinned: Vec<bool>,
    /// Whether a fixed body has a velocity this step (a static body the caller set moving):
    /// its motion counts in every substep of the islands it touches, which a chunk solved
    /// apart would not see, so the chunks are then solved with the rest.
    pub(super) a_fixed_body_moves: bool,
    /// The bodies that move or have a velocity, increasing: the only ones the substeps
    /// integrate (a terrain of 2,000 static tiles is not walked four times a step).
    pub(super) in_motion: Vec<u32>,
    /// The bodies that move, increasing: the ones `store` writes back.
    pub(super) moving: Vec<u32>,
    /// The fixed bodies with a velocity (a conveyor), increasing: loaded again every
    /// step, as their motion within a step is the solver's own.
    fixed_in_motion: Vec<u32>,
    /// The slots, increasing, whose bodies alone may differ from those the last step was
    /// handed (`bodies_changed_only`), for the next step; unless set, every body.
    changed_only: Vec<u32>,
    only_those_changed: bool,
    /// Scratch for `load`: last step's fixed bodies in motion.
    spare_slots: Vec<u32>,
}

impl LoadedBodies {
    /// Only the bodies in `slots` (increasing) may differ from those the last step was
    /// handed: the next step loads those, and the fixed bodies with a velocity.
    pub(super) fn changed_only(&mut self, slots: &[u32]) {
        self.changed_only.clear();
        self.changed_only.extend_from_slice(slots);
        self.only_those_changed = true;
    }

    /// The bodies as the soft step reads them, the null body last, and which bodies a pin
    /// joins: every body, or where the caller said which changed (`bodies_changed_only`)
    /// those and the fixed bodies with a velocity.
    pub(super) fn load(&mut self, bodies: &[SolverBody], joints: &[JointConstraint]) {
        let only_some =
            std::mem::take(&mut self.only_those_changed) && self.bodies.len() == bodies.len() + 1;
        self.in_motion.clear();
        self.moving.clear();
        let mut fixed_in_motion = std::mem::take(&mut self.fixed_in_motion);
        if only_some {
            let changed = std::mem::take(&mut self.changed_only);
            let mut was_in_motion = std::mem::take(&mut self.spare_slots);
            was_in_motion.clone_from(&fixed_in_motion);
            fixed_in_motion.clear();
            for i in merged_increasing(&changed, &was_in_motion) {
                self.bodies[i as usize] = SoftBody::at_step_start(&bodies[i as usize]);
                self.note_motion(i, &mut fixed_in_motion);
            }
            self.changed_only = changed;
            self.spare_slots = was_in_motion;
            // The null body, last: where a batch's unused lanes point (`batch::PAD`).
            *self.bodies.last_mut().expect("the null body") = SoftBody::null();
        } else {
            fixed_in_motion.clear();
            self.bodies.clear();
            self.bodies
                .extend(bodies.iter().map(SoftBody::at_step_start));
            for i in 0..bodies.len() as u32 {
                self.note_motion(i, &mut fixed_in_motion);
            }
            // The null body, last: where a batch's unused lanes point (`batch::PAD`). Fixed
            // and at rest, and past the bodies `store` writes back.
            self.bodies.push(SoftBody::null());
        }
        self.a_fixed_body_moves = !fixed_in_motion.is_empty();
        self.fixed_in_motion = fixed_in_motion;
        self.pinned.clear();
        if !joints.is_empty() {
            self.pinned.resize(bodies.len(), false);
            for j in joints {
                self.pinned[j.body_a as usize] = true;
                self.pinned[j.body_b as usize] = true;
            }
        }
    }

    /// Lists body `i`, just loaded, among those that move, those in motion and the fixed
    /// ones in motion, as it is.
    fn note_motion(&mut self, i: u32, fixed_in_motion: &mut Vec<u32>) {
        let body = &self.bodies[i as usize];
        let has_velocity = body.v != Vec2::zeros() || body.w != 0.0;
        if body.moves() {
            self.moving.push(i);
        } else if has_velocity {
            fixed_in_motion.push(i);
        }
        if body.moves() || has_velocity {
            self.in_motion.push(i);
        }
    }
}
