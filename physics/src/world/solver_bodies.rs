//! The bodies and joints copied into the solvers' arrays (the static world last), and
//! the solved velocities and poses copied back.

use super::World;
use super::body_sets::EpochSeen;
use crate::body::BodyHandle;
use crate::math::Vec2;
use crate::solver::joint::{JointConstraint, velocity_gap_target};
use crate::solver::{BodiesAndMoving, SolverBody};

/// Whether gathering the joints works out the gap each is to close (`gap_target`): the
/// exact and thesis solvers repair a broken joint over several steps; the soft step
/// pulls every pin closed its own way and never reads it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum GapTargets {
    ForBrokenJoints,
    None,
}

/// The bodies as the solvers take them (by slot, the static world last), their
/// accelerations for the soft step and their velocities at the step's start for
/// restitution. The awake bodies' are made again for each pass; the static and sleeping
/// bodies', which no solver moves, when the sets change (`*_made`).
#[derive(Debug, Clone, Default)]
pub(super) struct SolverInputs {
    pub(super) bodies: Vec<SolverBody>,
    pub(super) bodies_made: EpochSeen,
    pub(super) accelerations: Vec<(Vec2, f64)>,
    pub(super) accelerations_made: EpochSeen,
    /// Empty while the soft step runs (its forces act inside its substeps).
    pub(super) start_velocities: Vec<(Vec2, f64)>,
    pub(super) start_velocities_made: EpochSeen,
}

impl SolverInputs {
    /// The bodies, with the slots of those the pass moves (`BodySets::moving`).
    pub(super) fn bodies_and_moving<'a>(&'a mut self, moving: &'a [u32]) -> BodiesAndMoving<'a> {
        debug_assert!(moving.iter().all(|&i| self.bodies[i as usize].moves()));
        (&mut self.bodies, moving)
    }
}

impl World {
    /// Copies the bodies into the solver array, the static world last, and resolves the
    /// joints to slots in it, each with the gap it is to close this step.
    pub(super) fn gather_solver_bodies(&mut self) {
        self.gather_solver_bodies_with(GapTargets::ForBrokenJoints);
    }

    pub(super) fn gather_solver_bodies_with(&mut self, targets: GapTargets) {
        let s = &mut self.scratch;
        let ground = self.bodies.len() as u32;
        // Static and sleeping bodies are copied when the sets change; the solvers move
        // neither, so their copies stay as made.
        let inputs = &mut self.inputs;
        let n = self.bodies.len();
        let whole = inputs.bodies.len() == n + 1;
        let remake = self.sets.to_remake(&mut inputs.bodies_made, whole, n);
        if remake.every() {
            inputs.bodies.clear();
            inputs.bodies.resize(n + 1, SolverBody::default());
        }
        for i in remake {
            inputs.bodies[i as usize] = match self.bodies[i as usize].as_ref() {
                Some(body) if self.sets.is_held(i) => SolverBody::held_still(body),
                Some(body) => SolverBody::from_body(body),
                None => SolverBody::default(),
            };
        }
        s.joint_constraints.clear();
        for (i, j) in self.joints.iter().enumerate() {
            let Some(j) = j else { continue };
            let live = |h: BodyHandle| self.bodies.get(h.index()).is_some_and(Option::is_some);
            if !live(j.body_a) || !j.body_b.is_none_or(live) {
                continue;
            }
            let mut c = JointConstraint {
                joint: i as u32,
                body_a: j.body_a.0,
                body_b: j.body_b.map_or(ground, |h| h.0),
                local_anchor_a: j.local_anchor_a,
                local_anchor_b: j.local_anchor_b,
                motor: j.motor,
                limits: j.limits,
                reference_angle: j.reference_angle,
                limit_impulse: (0.0, 0.0),
                gap_target: Vec2::zeros(),
                impulse: Vec2::zeros(),
            };
            if targets == GapTargets::ForBrokenJoints {
                let gap_now = c.predicted_gap(&inputs.bodies, 0.0);
                let broken_gap = self.settings.joint_iterations(1.0).broken_gap;
                c.gap_target = velocity_gap_target(gap_now, broken_gap);
            }
            s.joint_constraints.push(c);
        }
    }

    /// Copies solved velocities and poses (of the bodies the pass moves) and motor
    /// impulses back.
    pub(super) fn scatter_solver_bodies(&mut self) {
        for &i in self.sets.moving() {
            let b = self.bodies[i as usize].as_mut().expect("an awake body");
            let solved = &self.inputs.bodies[i as usize];
            b.velocity = solved.velocity;
            b.angular_velocity = solved.angular_velocity;
            b.position = solved.position;
            b.angle = solved.angle;
        }
        let s = &mut self.scratch;
        s.pin_impulses.resize(self.joints.len(), Vec2::zeros());
        for c in &s.joint_constraints {
            if let Some(Some(j)) = self.joints.get_mut(c.joint as usize) {
                j.motor = c.motor;
            }
            s.pin_impulses[c.joint as usize] += c.impulse;
        }
    }
}
