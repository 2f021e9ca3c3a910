//! The soft step's stage list (`ContactSolver::Soft`, and `auto`'s soft pass): forces,
//! contacts found once, the impact pass where two moving bodies may bounce, then the
//! soft solver's substeps (`solver::soft`).

use super::{GapTargets, Pipeline, World};
use crate::math::Vec2;
use crate::solver::contact::restitution_threshold;
use crate::solver::exact::system::VelocityTargets;
use crate::solver::soft::settings::SoftSettings;

/// The most substeps a soft step takes for fast turns or the pins' pull.
const MAX_SOFT_SUBSTEPS: usize = 32;

/// The soft step's substeps, held at the most asked for a second before they may fall.
/// Each substep warm-starts from the last one's impulses, the first from the last step's
/// last: a substep of another length starts from impulses made for another, and a chain
/// whipping a heavy load, whose pull asked for 4 substeps one step and 9 the next, held
/// its pins worse than at 4 throughout.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct HeldSubsteps {
    substeps: usize,
    until_step: u64,
}

impl HeldSubsteps {
    const HOLD_STEPS: u64 = 60;

    fn hold(&mut self, asked: usize, step: u64) -> usize {
        if asked >= self.substeps || step >= self.until_step {
            if asked >= self.substeps {
                self.until_step = step + Self::HOLD_STEPS;
            }
            self.substeps = asked;
        }
        self.substeps
    }
}

impl World {
    /// The soft step has its own stage list: forces, contacts found once, then substeps
    /// that integrate and solve together (see `solver::soft`).
    pub(super) fn step_soft(&mut self, dt: f64) {
        self.inputs.start_velocities.clear(); // forces act inside the substeps
        // Joint springs kick before the substeps drift: symplectic over the whole step.
        self.kick_joint_springs(dt);
        self.detect_contacts(dt, Pipeline::Soft);
        // The soft step pulls every pin closed its own way: no repair targets.
        self.gather_solver_bodies_with(GapTargets::None);
        // Zero but for the bodies the step moves (the ground's, last, among the zeros).
        let inputs = &mut self.inputs;
        let n = self.bodies.len();
        let whole = inputs.accelerations.len() == n + 1;
        let remake = self
            .sets
            .to_remake(&mut inputs.accelerations_made, whole, n);
        if remake.every() {
            inputs.accelerations.clear();
            inputs.accelerations.resize(n + 1, (Vec2::zeros(), 0.0));
        }
        for i in remake {
            inputs.accelerations[i as usize] = match &self.bodies[i as usize] {
                Some(b) if !self.sets.fixed_in_pass(i, b) => (
                    self.gravity + b.force * b.inv_mass,
                    b.torque * b.inv_inertia,
                ),
                _ => (Vec2::zeros(), 0.0),
            };
        }
        // The impact pass runs only where two moving bodies may bounce (a pile of cor 0
        // pays one look at its contacts). Two that meet within the step sooner than their
        // velocities at its start foretold (a pendulum speeding up through its pin) would
        // bounce in the soft step's own restitution, which shares the impulse: the step is
        // taken again with the impact pass bouncing those pairs too.
        let bodies = &self.inputs.bodies;
        let moves = |i: u32| bodies[i as usize].moves();
        let may_bounce = self.settings.propagate_impacts
            && self
                .contacts
                .iter()
                .any(|c| c.restitution > 0.0 && moves(c.body_a.0) && moves(c.body_b.0));
        let found = may_bounce.then(|| self.contacts.clone());
        if may_bounce {
            self.solvers.soft.keep_for_another_try();
        }
        // Fast turns, and the pins' pull as the last step found it (a heavy load on
        // light links: `World::substeps_for_tension`), ask for more substeps.
        let asked = self
            .settings
            .soft_substeps
            .max(1)
            .max(self.soft_substeps_for_spin(dt))
            .max(self.soft_tension_substeps);
        let substeps = self.soft_substeps_held.hold(asked, self.step_count);
        self.scratch.pin_impulses.fill(Vec2::zeros());
        let mut unforeseen = Vec::new();
        loop {
            if may_bounce {
                self.propagate_impacts_before_soft_step(dt, &unforeseen);
            }
            let s = &mut self.scratch;
            if !self.solvers.soft_seen.sets_changed(&self.sets) {
                self.solvers.soft.bodies_changed_only(self.sets.awake());
            }
            self.solvers.soft.step(
                &SoftSettings {
                    substeps,
                    alternating_sweeps: self.settings.soft_alternating_sweeps,
                    ..SoftSettings::for_length_scale(self.settings.length_scale)
                },
                &mut self.inputs.bodies,
                &self.inputs.accelerations,
                &mut self.contacts,
                &mut s.joint_constraints,
                dt,
                restitution_threshold(self.gravity, dt),
            );
            let Some(found) = found.as_ref().filter(|_| unforeseen.is_empty()) else {
                break;
            };
            unforeseen = self.unforeseen_impacts(dt);
            if unforeseen.is_empty() {
                break;
            }
            self.contacts.clone_from(found);
            self.solvers.soft.take_again();
            self.gather_solver_bodies_with(GapTargets::None);
        }
        self.scatter_solver_bodies();
        self.soft_tension_substeps = self.substeps_for_tension(dt).min(MAX_SOFT_SUBSTEPS);
    }

    /// The substeps the step's fastest turn asks for: a body turning faster than a
    /// quarter turn a substep would be held back to it by the soft step, silently, and a
    /// pin on a body turning that far in a substep opens. Each substep turns at most an
    /// eighth of a turn: the bodies' spins and the joint motors' speeds at the step's
    /// start, up to `MAX_SOFT_SUBSTEPS`.
    fn soft_substeps_for_spin(&self, dt: f64) -> usize {
        const MAX_TURN: f64 = 0.125 * std::f64::consts::PI;
        let bodies = self.sets.moving().iter().filter_map(|&i| {
            let b = self.bodies[i as usize].as_ref()?;
            Some(self.sets.velocity_in_pass(i, b).1.abs())
        });
        let motors = self
            .motor_joints
            .iter()
            .filter_map(|&k| self.joints[k as usize].and_then(|j| j.motor))
            .filter(|m| m.enabled)
            .map(|m| m.drive_speed().abs());
        let fastest = bodies.chain(motors).fold(0.0, f64::max);
        ((fastest * dt / MAX_TURN).ceil() as usize).clamp(1, MAX_SOFT_SUBSTEPS)
    }

    /// The body pairs that the soft step bounced between two moving bodies: pairs that
    /// met within the step, which the impact pass did not foresee.
    fn unforeseen_impacts(&self, dt: f64) -> Vec<(u32, u32)> {
        let bounce_below = restitution_threshold(self.gravity, dt);
        let bodies = &self.inputs.bodies;
        let moves = |i: u32| bodies[i as usize].moves();
        let mut pairs: Vec<(u32, u32)> = self
            .contacts
            .iter()
            .filter(|c| {
                c.restitution > 0.0
                    && c.approach_velocity <= -bounce_below
                    && c.normal_impulse > 0.0
                    && moves(c.body_a.0)
                    && moves(c.body_b.0)
            })
            .map(|c| (c.body_a.0, c.body_b.0))
            .collect();
        pairs.dedup();
        pairs
    }

    /// The impact pass (`SimultaneousSolver::propagate_all_impacts`) before the soft step,
    /// which then bounces only what the pass left.
    /// `unforeseen`: pairs to bounce as meeting this step whatever their velocities say.
    fn propagate_impacts_before_soft_step(&mut self, dt: f64, unforeseen: &[(u32, u32)]) {
        let s = &mut self.scratch;
        // The soft step's contacts carry the velocities of the step's start; whether
        // a pair meets this step also takes the step's forces (as `exact`'s do).
        for c in self.contacts.iter_mut() {
            let (a, b) = (c.body_a.index(), c.body_b.index());
            let kick = (self.inputs.accelerations[a].0 - self.inputs.accelerations[b].0)
                .dot(&c.normal)
                * dt;
            c.normal_velocity = c.approach_velocity + kick;
            if c.depth < 0.0 && unforeseen.contains(&(c.body_a.0, c.body_b.0)) {
                // Closing twice the gap within the step: the pair meets.
                c.normal_velocity = c.normal_velocity.min(2.0 * c.depth / dt);
            }
        }
        self.solvers.impacts.dense_row_limit = self.settings.dense_row_limit;
        self.solvers.impacts.on_every_island(
            &mut self.contacts,
            &s.joint_constraints,
            self.inputs.bodies_and_moving(self.sets.moving()),
            &VelocityTargets {
                dt,
                bounce_below: restitution_threshold(self.gravity, dt),
                friction: true,
            },
        );
        for c in self.contacts.iter_mut() {
            c.normal_velocity = c.approach_velocity;
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::body::BodyDef;
    use crate::math::Vec2;
    use crate::shape::ConvexPolygon;
    use crate::solver::ContactSolver;
    use crate::world::World;

    /// A manifold that goes into the kept plan's lanes is not written to the soft step's
    /// points; when the plan changes after all, or something bounces, they are built
    /// again. A pile stepped so must move exactly as one whose every point is written,
    /// through a box landing on it (the plan changes) and one bouncing on its top box
    /// (restitution is the smaller of the two bodies': only the top box has any).
    #[test]
    fn points_left_unwritten_change_no_step() {
        let (h, rows) = (1.0 / 60.0, 8);
        let pile = |write_every_point| {
            let mut world = World::new(Vec2::new(0.0, 10.0));
            world.settings.contact_solver = ContactSolver::Soft;
            world.friction = 0.6;
            let floor = ConvexPolygon::rectangle(40.0, 1.0).unwrap();
            world
                .add_body(BodyDef::new(floor, 0.0).at(Vec2::new(0.0, 0.5), 0.0))
                .unwrap();
            let unit = ConvexPolygon::rectangle(1.0, 1.0).unwrap();
            for row in 0..rows {
                for i in 0..rows - row {
                    let x = i as f64 - 0.5 * (rows - 1 - row) as f64;
                    let centre = Vec2::new(x, -0.5 - row as f64);
                    let def = BodyDef::new(unit.clone(), 1.0).at(centre, 0.0);
                    let top = row == rows - 1;
                    world
                        .add_body(if top { def.restitution(0.5) } else { def })
                        .unwrap();
                }
            }
            world.solvers.soft.write_every_point = write_every_point;
            world
        };
        let (mut skipping, mut writing) = (pile(false), pile(true));
        let unit = ConvexPolygon::rectangle(1.0, 1.0).unwrap();
        for step in 0..300 {
            let dropped = match step {
                90 => Some((BodyDef::new(unit.clone(), 1.0), -3.0)),
                180 => Some((BodyDef::new(unit.clone(), 1.0).restitution(0.5), 0.1)),
                _ => None,
            };
            if let Some((def, x)) = dropped {
                let def = def.at(Vec2::new(x, -(rows as f64) - 3.0), 0.1);
                skipping.add_body(def.clone()).unwrap();
                writing.add_body(def).unwrap();
            }
            skipping.step(h);
            writing.step(h);
            let bits = |w: &World| -> Vec<u64> {
                w.bodies()
                    .flat_map(|(_, b)| b.state())
                    .map(f64::to_bits)
                    .collect()
            };
            assert_eq!(bits(&skipping), bits(&writing), "step {step}");
        }
        let stats = skipping.stats();
        let (skipped, rebuilt) = (
            stats.soft_steps_skipping_points,
            stats.soft_steps_rebuilding_points,
        );
        assert!(skipped > 200, "{skipped} steps left points unwritten");
        // The landing's step or two, and every step from the bouncing box's first
        // contact on.
        assert!(
            (50..150).contains(&rebuilt),
            "{rebuilt} built their points again"
        );
        assert_eq!(writing.stats().soft_steps_skipping_points, 0);
        assert_eq!(writing.stats().soft_steps_rebuilding_points, 0);
    }
}
