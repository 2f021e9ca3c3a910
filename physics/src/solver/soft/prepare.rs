//! The step's preparation: the bodies loaded, the contacts grouped by island, their
//! points built and the passes planned, and the pins loaded and grouped.

use super::joints::JointMemory;
use super::points::ContactsRegrouped;
use super::{SoftBody, SoftJoint, SoftStepSolver};
use crate::math::{Rot, Vec2};
use crate::solver::SolverBody;
use crate::solver::contact::Contact;
use crate::solver::island::{IslandGrouping, island_ranges, merged_increasing};
use crate::solver::joint::JointConstraint;
use crate::stage_clock::{self, Stage};

impl SoftStepSolver {
    /// The step's preparation, in order: the bodies loaded, the contacts grouped by
    /// island, their points built and the passes planned, then the pins.
    pub(super) fn prepare(
        &mut self,
        bodies: &[SolverBody],
        accelerations: &[(Vec2, f64)],
        contacts: &[Contact],
        joints: &[JointConstraint],
        dt: f64,
    ) {
        let started = stage_clock::mark();
        self.load_bodies(bodies, joints);
        let (grouping, reused) = self.take_contact_grouping(contacts, bodies.len());
        self.profile.record(Stage::PreparingIslands, started);
        self.prepare_points(bodies, accelerations, contacts, dt, (grouping, reused));
        self.prepare_pins(bodies, joints);
    }

    /// The bodies as the soft step reads them, the null body last, and which bodies a pin
    /// joins: every body, or where the caller said which changed (`bodies_changed_only`)
    /// those and the fixed bodies with a velocity.
    fn load_bodies(&mut self, bodies: &[SolverBody], joints: &[JointConstraint]) {
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

    /// The contacts' islands: last step's grouping, taken unchecked where
    /// `IslandGrouping::bodies_kept` allows (the points check it as they are built), else
    /// grouped afresh. Returns it and whether it was kept; `prepare_points` puts it back.
    fn take_contact_grouping(
        &mut self,
        contacts: &[Contact],
        body_count: usize,
    ) -> (IslandGrouping, bool) {
        // The points are built island by island (each island's in the contacts' order):
        // grouping the contacts is cheaper than reordering the larger points afterwards.
        // A pile at rest has the same contacts between the same bodies step after step:
        // its last grouping is taken unchecked, and the points, which read every contact,
        // check each one's bodies against it as they are built.
        let mut grouping = std::mem::take(&mut self.contact_grouping);
        let reused = grouping.bodies_kept(contacts.len(), body_count, &self.moving);
        if !reused {
            self.group_contacts(&mut grouping, contacts);
        }
        (grouping, reused)
    }

    /// The contacts' points built and the passes planned: the plan made first where it
    /// changed last step, the manifolds placed in the kept plan's lanes, the small
    /// islands' LCPs prepared, and the points built again where the plan changed after
    /// all or something may bounce.
    fn prepare_points(
        &mut self,
        bodies: &[SolverBody],
        accelerations: &[(Vec2, f64)],
        contacts: &[Contact],
        dt: f64,
        (mut grouping, reused): (IslandGrouping, bool),
    ) {
        // After a step whose plan changed (debris in flight: every step of the smash), the
        // plan is made from the contacts before the points are built, so that each
        // manifold goes straight into its lane, rather than into the points and from
        // there, read in colour order, into its lane (docs/bench/profile.md, "The plan
        // made before the points").
        let started = stage_clock::mark();
        let may_plan_first = !reused && !self.plan.kept_last_step();
        #[cfg(test)]
        let may_plan_first = may_plan_first && !self.write_every_point;
        let planned_first =
            may_plan_first && self.plan_from_contacts(bodies, contacts, grouping.grouped());
        if planned_first {
            self.profile.record(Stage::PreparingPlan, started);
        }
        let started = stage_clock::mark();
        // Each manifold goes into the kept plan's lanes as soon as it is complete, and
        // then its points are not written: on a big pile at rest, writing them was a
        // tenth of the step (docs/bench/profile.md, "Points not written").
        if !planned_first {
            self.plan.begin_filling();
        }
        let unchecked = reused.then(|| grouping.ends());
        let built = self.build_points(
            bodies,
            accelerations,
            contacts,
            (grouping.grouped(), unchecked),
            dt,
        );
        let skipped = match built {
            Ok(skipped) => skipped,
            Err(ContactsRegrouped) => {
                // A contact joins other bodies than last step's: grouped afresh, and
                // every point built again.
                self.group_contacts(&mut grouping, contacts);
                let grouped = (grouping.grouped(), None);
                self.build_points(bodies, accelerations, contacts, grouped, dt)
                    .expect("the contacts' own grouping")
            }
        };
        self.profile.record(Stage::PreparingPoints, started);
        let started = stage_clock::mark();
        self.contact_lcp
            .prepare(&self.bodies, &self.points, &self.contact_islands);
        // The plan was made from the manifolds the points make (the same pairing, from
        // the same levers), and nothing bounces: it stands, its lanes filled.
        debug_assert!(
            !planned_first || (self.plan_inputs == self.planned_inputs && !self.may_bounce)
        );
        let kept = planned_first
            || self.plan.read(
                &self.contact_lcp.all_islands,
                &self.plan_inputs,
                &self.pinned,
            );
        self.profile.record(Stage::PreparingPlan, started);
        let rebuild = skipped && (!kept || self.may_bounce);
        self.stats.soft_steps_skipping_points += u64::from(skipped);
        self.stats.soft_steps_rebuilding_points += u64::from(rebuild);
        self.stats.soft_steps_planned_first += u64::from(planned_first);
        if rebuild {
            // The plan changed after all, or something bounces (restitution reads every
            // point): every point is built again, and written. The LCP islands' points
            // were written already, and the plan's entries come out the same, so the LCP
            // and the plan's reading stand.
            let rebuilt = stage_clock::mark();
            self.plan.stop_filling();
            let grouped = (grouping.grouped(), None);
            self.build_points(bodies, accelerations, contacts, grouped, dt)
                .expect("the contacts' own grouping");
            self.profile.record(Stage::PreparingPoints, rebuilt);
        }
        self.contact_grouping = grouping;
        if !planned_first {
            let started = stage_clock::mark();
            self.plan.plan(&self.points, &self.bodies);
            self.profile.record(Stage::PreparingPlan, started);
        }
    }

    /// The pins that can act this step, their last impulses recalled, grouped by island,
    /// and the big islands' batches planned.
    fn prepare_pins(&mut self, bodies: &[SolverBody], joints: &[JointConstraint]) {
        // Each pinned body's rotation once: a body of a net carries four pins.
        self.rotations.clear();
        if !joints.is_empty() {
            self.rotations.resize(bodies.len(), None);
        }
        self.joints.clear();
        self.joint_memory.begin(joints.len());
        let mut cursor = 0;
        for (input, j) in joints.iter().enumerate() {
            let (a, b) = (&bodies[j.body_a as usize], &bodies[j.body_b as usize]);
            // A pin between two fixed bodies (asleep, or held for the other solver's pass
            // under `auto`) can do nothing: it is left out, so neither its island nor its
            // motor's reading (the other pass's) is touched.
            let fixed = |b: &SolverBody| b.inv_mass == 0.0 && b.inv_inertia == 0.0;
            let remembered = self.joint_memory.recall(j.joint, &mut cursor);
            if fixed(a) && fixed(b) {
                // Kept, so that the pin warm-starts again when its bodies move.
                if let Some(entry) = remembered {
                    self.joint_memory.keep(input as u32, entry);
                }
                continue;
            }
            let mut turned = |i: u32| {
                *self.rotations[i as usize]
                    .get_or_insert_with(|| Rot::new(bodies[i as usize].angle))
            };
            let (r_a, r_b) = j.arms_turned((turned(j.body_a), turned(j.body_b)));
            let (_, impulse, motor_impulse) = remembered.unwrap_or(JointMemory::NONE);
            let motor = j
                .motor
                .filter(|m| m.enabled)
                .map(|m| (m.target_speed, m.max_torque));
            self.joints.push(SoftJoint {
                a: j.body_a,
                b: j.body_b,
                r_a,
                r_b,
                // The soft step always pulls towards a closed pin (a broken joint too),
                // no faster than `max_push_speed`; the target the other solvers use to
                // repair broken joints over several steps does not apply here.
                base_gap: (a.position + r_a) - (b.position + r_b),
                impulse,
                // Warm starting applies the remembered motor impulse in every substep: a
                // motor switched off or removed must not keep driving its joint with it.
                motor_impulse: if motor.is_some() { motor_impulse } else { 0.0 },
                motor_step_total: 0.0,
                motor,
                slot: j.joint,
                input: input as u32,
            });
        }
        self.group_joints();
        self.block.begin_step(self.joint_islands.len());
        self.motor_joints.clear();
        let motors = self
            .joints
            .iter()
            .enumerate()
            .filter(|(_, j)| j.motor.is_some());
        self.motor_joints.extend(motors.map(|(k, _)| k as u32));
        let unchanged = self.joint_grouping.kept();
        self.pin_plan
            .plan(&self.joints, &self.joint_islands, &self.bodies, unchanged);
    }

    /// Orders `joints` island by island (pins linked through moving bodies; each island
    /// keeps the joints' order) and records each island's range.
    fn group_joints(&mut self) {
        let joints = &self.joints;
        let grouped = self.joint_grouping.group(
            joints.len(),
            self.bodies.len(),
            |i| (joints[i].a, joints[i].b),
            &self.moving,
        );
        // A net's pins are one island, in the joints' own order: nothing to move, and
        // copying every joint is skipped.
        if grouped
            .iter()
            .enumerate()
            .any(|(k, &(_, i))| i as usize != k)
        {
            self.spare_joints.clear();
            self.spare_joints
                .extend(grouped.iter().map(|&(_, i)| joints[i as usize]));
            std::mem::swap(&mut self.joints, &mut self.spare_joints);
        }
        island_ranges(grouped, &mut self.joint_islands);
    }
}
