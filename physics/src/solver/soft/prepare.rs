//! The step's preparation: the bodies loaded, the contacts grouped by island, their
//! points built and the passes planned, and the pins loaded and grouped.

use super::SoftStepSolver;
use super::points::ContactsRegrouped;
use crate::math::Vec2;
use crate::solver::SolverBody;
use crate::solver::contact::Contact;
use crate::solver::island::IslandGrouping;
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
        self.loaded.load(bodies, joints);
        let (grouping, reused) = self.take_contact_grouping(contacts, bodies.len());
        self.profile.record(Stage::PreparingIslands, started);
        self.prepare_points(bodies, accelerations, contacts, dt, (grouping, reused));
        self.pins.prepare(bodies, joints, &self.loaded);
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
        let reused = grouping.bodies_kept(contacts.len(), body_count, &self.loaded.moving);
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
            .prepare(&self.loaded.bodies, &self.points, &self.contact_islands);
        // The plan was made from the manifolds the points make (the same pairing, from
        // the same levers), and nothing bounces: it stands, its lanes filled.
        debug_assert!(
            !planned_first || (self.plan_inputs == self.planned_inputs && !self.may_bounce)
        );
        let kept = planned_first
            || self.plan.read(
                &self.contact_lcp.all_islands,
                &self.plan_inputs,
                &self.loaded.pinned,
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
            self.plan.plan(&self.points, &self.loaded.bodies);
            self.profile.record(Stage::PreparingPlan, started);
        }
    }
}
