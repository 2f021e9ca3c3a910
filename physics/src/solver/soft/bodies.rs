//! The bodies as the soft step reads them (`SoftBody`, the null body last), loaded at the
//! step's start, and which of them move, are in motion or are pinned.

use crate::math::{Rot, Vec2};
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

/// A body during the soft step: velocity, inverse mass, and how far it moved this step.
///
/// Laid out for the batches' SIMD paths (`avx2::Avx2Lanes::gather`, `avx512`), which read
/// each body's `v, w, inv_mass` as one 32-byte row and `dp, dq` as another, and
/// transpose them into lanes: the two rows start at 0 and 32 bytes. A body is 64-byte
/// aligned, so that both rows lie in one cache line: at 96 bytes a body every other one
/// straddles two, which a big pile whose bodies leave the level-2 cache pays for in
/// every pass (docs/bench/profile.md, "The Zen 1: the big scenes wait on memory").
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[repr(C, align(64))]
pub(super) struct SoftBody {
    pub(super) v: Vec2,
    pub(super) w: f64,
    pub(super) inv_mass: f64,
    /// Displacement and rotation since the start of the step.
    pub(super) dp: Vec2,
    pub(super) dq: Rot,
    pub(super) inv_inertia: f64,
    pub(super) dangle: f64,
}

/// Which four numbers of a body a batch reads together (`SoftBody::row`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum BodyRow {
    /// `v.x, v.y, w, inv_mass`.
    Velocity,
    /// `dp.x, dp.y, dq.cos, dq.sin`.
    Motion,
}

// The rows `SoftBody::row_offset` names.
const _: () = {
    use std::mem::{offset_of, size_of};
    assert!(size_of::<Vec2>() == 16 && size_of::<Rot>() == 16);
    assert!(offset_of!(SoftBody, v) == 0 && offset_of!(SoftBody, w) == 16);
    assert!(offset_of!(SoftBody, inv_mass) == 24);
    assert!(offset_of!(SoftBody, dp) == 32 && offset_of!(SoftBody, dq) == 48);
    assert!(offset_of!(Rot, cos) == 0 && offset_of!(Rot, sin) == 8);
    assert!(std::mem::align_of::<SoftBody>() == 64 && size_of::<SoftBody>() == 128);
};

impl SoftBody {
    /// The four numbers of `row`, in its order.
    pub(super) fn row(&self, row: BodyRow) -> [f64; 4] {
        match row {
            BodyRow::Velocity => [self.v.x, self.v.y, self.w, self.inv_mass],
            BodyRow::Motion => [self.dp.x, self.dp.y, self.dq.cos, self.dq.sin],
        }
    }

    /// Where `row` starts, in f64s from the start of the body (the layout asserted below
    /// the struct).
    #[cfg(target_arch = "x86_64")]
    pub(super) const fn row_offset(row: BodyRow) -> usize {
        match row {
            BodyRow::Velocity => 0,
            BodyRow::Motion => 4,
        }
    }

    /// The body a batch's unused lanes point at: fixed and at rest.
    pub(super) fn null() -> Self {
        Self {
            dq: Rot { cos: 1.0, sin: 0.0 },
            ..Self::default()
        }
    }

    /// A body as the step starts it: its velocity and inverse mass, not yet moved.
    pub(super) fn at_step_start(b: &SolverBody) -> Self {
        Self {
            v: b.velocity,
            w: b.angular_velocity,
            inv_mass: b.inv_mass,
            inv_inertia: b.inv_inertia,
            ..Self::null()
        }
    }

    /// Whether impulses move it (a fixed body, static, asleep or held, has no inverse mass).
    pub(super) fn moves(&self) -> bool {
        self.inv_mass > 0.0 || self.inv_inertia > 0.0
    }
}
