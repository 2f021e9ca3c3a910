//! The impulse stage list (`sequential`, `thesis`, `exact`, and `auto`'s exact pass) and
//! its stages: joint repair and velocity correction, push-apart, the contact and joint
//! solve, split impulses, bounces placed at impact, and the state saved to redo a step
//! finer.

use super::{Pipeline, World};
use crate::math::Vec2;
use crate::solver::contact::{restitution_threshold, solve_sequential};
use crate::solver::exact::FrictionModel;
use crate::solver::exact::joint_block::JointBlockSolver;
use crate::solver::exact::system::VelocityTargets;
use crate::solver::joint::JointMotor;
use crate::solver::joint::{JointConstraint, JointIterations};
use crate::solver::{BodiesAndMoving, ImpulseMethod};

/// At most this many substeps per step, where fast turns (`World::substeps_for`) or the
/// pins' pull (`World::substeps_for_tension`) ask for them: enough for a light chain
/// whipping a load 10,000 times heavier at h = 1/60.
const MAX_SUBSTEPS: usize = 64;

/// The most substeps a step is taken again with because a pin ended it wider than a
/// thousandth of the length scale, where the pins are solved apart from the contacts
/// (`thesis`, `sequential`): a contact pushing a pinned body holds its pin open however
/// fine the substeps, and a car pushing a pyramid would cost the most substeps every
/// step. Where they are solved together (`exact`) finer substeps close what the
/// prediction missed, up to `MAX_SUBSTEPS` (docs/bench/profile.md, "Substeps for pins").
const GAP_SUBSTEPS_APART: usize = 8;

/// Fraction of the excess penetration the split-impulse pass removes per step: all of it
/// at once overshoots in stacks, where pushes add up along the column.
const SPLIT_IMPULSE_RATE: f64 = 0.4;

/// The fastest the split-impulse pass moves a contact point apart, in length scales per
/// second: bodies placed deep in each other part over several steps, as Box2D v3's
/// contacts push apart no faster than 3 m/s for its metre-sized bodies.
const SPLIT_IMPULSE_MAX_PUSH: f64 = 3.0;

impl World {
    /// The impulse stage list: joints repaired, then substeps of joint correction,
    /// forces, contacts, push-apart, the solve and positions; the step taken again with
    /// finer substeps where a joint's prediction was not to be trusted.
    pub(super) fn step_impulses(&mut self, method: ImpulseMethod, dt: f64) {
        self.repair_broken_joints(dt);
        let mut substeps = self.substeps_for(dt).max(self.tension_substeps);
        // A joint still broken is being repaired on purpose over several steps; only
        // joints that should have closed ask for finer substeps.
        let repairing = self.max_joint_gap() > self.settings.joint_iterations(dt).broken_gap;
        loop {
            self.save_state();
            self.scratch.pin_impulses.fill(Vec2::zeros());
            let h = dt / substeps as f64;
            self.for_each_motor(|m| m.step_impulse = 0.0);
            self.stats.impulse_substeps += substeps as u64;
            for _ in 0..substeps {
                self.correct_joint_velocities(h);
                self.kick_joint_springs(h);
                self.integrate_velocities(h);
                self.detect_contacts(h, Pipeline::Impulses);
                self.push_apart(method);
                self.solve_constraints(method, h);
                self.place_bounces_at_impact(h);
                self.integrate_positions(h);
                self.for_each_motor(|m| {
                    if m.enabled {
                        m.step_impulse += m.last_impulse;
                    }
                });
            }
            // A whip can spin links up within the step; if they now turn too far per
            // substep, this step's joint prediction was not trustworthy: redo it finer.
            let tension = self.substeps_for_tension(dt);
            let mut needed = self.substeps_for(dt).max(tension);
            let pins_apart = method.pushes_apart();
            if !repairing
                && (!pins_apart || substeps < GAP_SUBSTEPS_APART)
                && self.max_joint_gap() > 1e-3 * self.settings.length_scale
            {
                needed = needed.max(2 * substeps);
            }
            if needed <= substeps || substeps >= MAX_SUBSTEPS {
                self.tension_substeps = tension;
                break;
            }
            self.restore_state();
            substeps = needed.max(2 * substeps).min(MAX_SUBSTEPS);
        }
    }

    /// How many substeps the pins' pull asks for (from this step's pin impulses). A pin
    /// pulling body b with force F at arm r (from b's centroid) turns b back towards the
    /// pull's line with a stiffness F·r per radian: the string's stiffness that holds a
    /// hanging chain straight. The solve takes each pin force's direction from the start
    /// of the substep, so for this stiffness it is explicit, and stable only while
    /// ω·h < 2, ω² = Σ F·r / I over b's pins: past it, light links holding a heavy load
    /// shake themselves apart from round-off. The
    /// estimate bounds the chain's fastest zigzag from above (by about 2 for a uniform
    /// link, whose neighbours give way), and a substep is kept at ω·h ≤ 2 by it. Only a
    /// body pulled at two pins or more has such a mode: one pulled at a single pin (a
    /// pendulum's bob) turns about it with the pendulum, slowly, and counting it would
    /// vary the substeps along every swing, which drains a swing's energy.
    ///
    /// Measured on the bodies where the step ends.
    pub(super) fn substeps_for_tension(&mut self, dt: f64) -> usize {
        const MAX_STIFF_TURN: f64 = 2.0;
        let s = &mut self.scratch;
        if s.pin_impulses.iter().all(|i| *i == Vec2::zeros()) {
            return 1;
        }
        s.pull_stiffness.clear();
        s.pull_stiffness.resize(self.bodies.len(), (0.0, 0));
        let mut any = false;
        for (j, impulse) in self.joints.iter().zip(&s.pin_impulses) {
            let Some(j) = j else { continue };
            if *impulse == Vec2::zeros() {
                continue;
            }
            let force = impulse / dt;
            let ends = [
                (Some(j.body_a), j.local_anchor_a, 1.0),
                (j.body_b, j.local_anchor_b, -1.0),
            ];
            for (handle, local, sign) in ends {
                let Some(body) = handle.and_then(|h| self.bodies[h.index()].as_ref()) else {
                    continue;
                };
                let arm = crate::math::Rot::new(body.angle).apply(local);
                let pull = (force * sign).dot(&arm);
                if pull > 0.0 {
                    let (stiffness, pins) = &mut s.pull_stiffness[handle.expect("a body").index()];
                    (*stiffness, *pins) = (*stiffness + pull, *pins + 1);
                    any = true;
                }
            }
        }
        if !any {
            return 1;
        }
        let fastest = self
            .sets
            .moving()
            .iter()
            .filter_map(|&i| Some((i, self.bodies[i as usize].as_ref()?)))
            .map(|(i, b)| match s.pull_stiffness[i as usize] {
                (stiffness, 2..) => stiffness * b.inv_inertia,
                _ => 0.0,
            })
            .fold(0.0, f64::max)
            .sqrt();
        ((fastest * dt / MAX_STIFF_TURN).ceil() as usize).clamp(1, MAX_SUBSTEPS)
    }

    pub(super) fn for_each_motor(&mut self, f: impl Fn(&mut JointMotor)) {
        self.joints
            .iter_mut()
            .flatten()
            .filter_map(|j| j.motor.as_mut())
            .for_each(f);
    }

    /// The poses and velocities of the bodies this pass moves, for `restore_state`.
    pub(super) fn save_state(&mut self) {
        let saved = &mut self.scratch.saved_state;
        saved.clear();
        saved.extend(self.sets.moving().iter().map(|&i| {
            let b = self.bodies[i as usize].as_ref().expect("an awake body");
            (b.position, b.angle, b.velocity, b.angular_velocity)
        }));
    }

    pub(super) fn restore_state(&mut self) {
        for (&i, &(p, a, v, w)) in self.sets.moving().iter().zip(&self.scratch.saved_state) {
            let b = self.bodies[i as usize].as_mut().expect("an awake body");
            (b.position, b.angle, b.velocity, b.angular_velocity) = (p, a, v, w);
        }
    }

    /// How many substeps this step needs: the joint prediction (thesis §3.3) follows each
    /// jointed body's rotation by ω·h, and past a quarter radian per step that is too far
    /// from linear for the Newton steps to be trusted (a whipping chain tip turns a radian
    /// per 1/60 s). Usually 1.
    pub(super) fn substeps_for(&self, dt: f64) -> usize {
        const MAX_TURN: f64 = 0.25;
        let fastest = self
            .joints
            .iter()
            .flatten()
            .flat_map(|j| [Some(j.body_a), j.body_b])
            .flatten()
            .filter_map(|h| Some((h.0, self.body(h)?)))
            .map(|(i, b)| self.sets.velocity_in_pass(i, b).1.abs())
            .fold(0.0, f64::max);
        ((fastest * dt / MAX_TURN).ceil() as usize).clamp(1, MAX_SUBSTEPS)
    }

    /// A speculative contact that bounces this step reverses while the bodies are still a
    /// gap g apart, where they have not yet fallen the last g: the rebound keeps
    /// (1 − e²)·g too much height. Moving the body down by that much (positions only) puts
    /// the bounce's energy where an impact at the surface would. Only against static
    /// bodies: between two free bodies the shift would change angular momentum about the
    /// origin, and exact conservation is worth more there than this O(v·h) height error.
    pub(super) fn place_bounces_at_impact(&mut self, dt: f64) {
        let bounce_below = restitution_threshold(self.gravity, dt);
        for k in 0..self.contacts.len() {
            let c = self.contacts[k];
            let first_of_pair = k == 0 || {
                let p = &self.contacts[k - 1];
                (p.body_a, p.body_b) != (c.body_a, c.body_b)
            };
            if !first_of_pair {
                continue;
            }
            let pair = self.contacts[k..]
                .iter()
                .take_while(|p| (p.body_a, p.body_b) == (c.body_a, c.body_b));
            let (mut gap, mut room) = (0.0, f64::INFINITY);
            for p in pair {
                if p.depth < 0.0 && p.normal_impulse > 0.0 && p.bounces(dt, bounce_below) {
                    gap = f64::max(gap, (1.0 - p.restitution * p.restitution) * -p.depth);
                }
                // The shift may not push any of the pair's other points in: a body
                // pivoting on one corner that bounces on the other must stay out at both.
                room = room.min(-p.depth);
            }
            let gap = gap.min(room);
            if gap <= 0.0 {
                continue;
            }
            let is_fixed = |i: u32| {
                let body = self.bodies[i as usize].as_ref();
                body.is_none_or(|b| self.sets.fixed_in_pass(i, b))
            };
            let (moving, direction) = match (is_fixed(c.body_a.0), is_fixed(c.body_b.0)) {
                (false, true) => (c.body_a, -c.normal),
                (true, false) => (c.body_b, c.normal),
                _ => continue,
            };
            // Moving one part of a jointed mechanism would open its joints.
            if self.jointed.binary_search(&moving.0).is_ok() {
                continue;
            }
            if let Some(body) = self.bodies[moving.index()].as_mut() {
                body.position += direction * gap;
            }
        }
    }

    /// Broken joints move towards closing, by positions only.
    pub(super) fn repair_broken_joints(&mut self, dt: f64) {
        self.joint_pass(dt, JointBlockSolver::repair_positions);
    }

    /// Stage 1: joints whose anchors drift apart stop drifting (thesis eq. 40).
    pub(super) fn correct_joint_velocities(&mut self, dt: f64) {
        self.joint_pass(dt, JointBlockSolver::correct_velocities);
    }

    /// A pass of the joints alone over the bodies gathered for it, if there are joints.
    fn joint_pass(
        &mut self,
        dt: f64,
        pass: fn(&mut JointBlockSolver, &mut [JointConstraint], BodiesAndMoving, &JointIterations),
    ) {
        if self.joints.is_empty() {
            return;
        }
        self.gather_solver_bodies();
        let it = self.settings.joint_iterations(dt);
        let s = &mut self.scratch;
        pass(
            &mut self.solvers.joints,
            &mut s.joint_constraints,
            self.inputs.bodies_and_moving(self.sets.moving()),
            &it,
        );
        self.scatter_solver_bodies();
    }

    /// The thesis removes overlap directly: each pair is pushed apart along its normal by
    /// its depth, shared by inverse mass (thesis §3.1). Positions only.
    pub(super) fn push_apart(&mut self, method: ImpulseMethod) {
        if !method.pushes_apart() {
            return;
        }
        for m in &self.manifolds {
            let depth = m.depth();
            if depth <= 0.0 {
                continue;
            }
            let (ia, ib) = (m.body_a.index(), m.body_b.index());
            let inv_mass = |i: usize| match self.bodies[i].as_ref() {
                Some(b) if !self.sets.fixed_in_pass(i as u32, b) => b.inv_mass,
                _ => 0.0,
            };
            let (inv_a, inv_b) = (inv_mass(ia), inv_mass(ib));
            let total = inv_a + inv_b;
            if total == 0.0 {
                continue;
            }
            if let Some(a) = self.bodies[ia].as_mut() {
                a.position += m.normal * (depth * inv_a / total);
            }
            if let Some(b) = self.bodies[ib].as_mut() {
                b.position -= m.normal * (depth * inv_b / total);
            }
        }
    }

    /// Stages 5–6: contact impulses (with pins and motors in the exact solver), then joint
    /// position prediction, then (exact solver) the split-impulse depth correction.
    pub(super) fn solve_constraints(&mut self, method: ImpulseMethod, dt: f64) {
        self.gather_solver_bodies();
        let s = &mut self.scratch;
        let targets = VelocityTargets {
            dt,
            bounce_below: restitution_threshold(self.gravity, dt),
            friction: true,
        };
        match method {
            ImpulseMethod::Sequential => {
                self.solvers.exact.reports.clear();
                solve_sequential(
                    &mut self.contacts,
                    &mut self.inputs.bodies,
                    dt,
                    targets.bounce_below,
                )
            }
            ImpulseMethod::Thesis | ImpulseMethod::Exact => {
                let model = if method == ImpulseMethod::Thesis {
                    FrictionModel::TwoStage
                } else {
                    FrictionModel::Coupled
                };
                self.solvers.exact.dense_row_limit = self.settings.dense_row_limit;
                self.solvers.exact.propagate_impacts = self.settings.propagate_impacts;
                self.solvers.exact.solve(
                    model,
                    &mut self.contacts,
                    &mut s.joint_constraints,
                    self.inputs.bodies_and_moving(self.sets.moving()),
                    &targets,
                    &mut self.solvers.impacts,
                );
            }
        }
        if !s.joint_constraints.is_empty() {
            let it = self.settings.joint_iterations(dt);
            self.solvers.joints.correct_positions(
                &mut s.joint_constraints,
                self.inputs.bodies_and_moving(self.sets.moving()),
                dt,
                &it,
                method.solves_motors_with_contacts(),
            );
        }
        if !method.pushes_apart() {
            self.solvers.exact.dense_row_limit = self.settings.dense_row_limit;
            self.solvers.exact.separate(
                &self.contacts,
                &s.joint_constraints,
                self.inputs.bodies_and_moving(self.sets.moving()),
                dt,
                self.settings.slop(),
                (
                    SPLIT_IMPULSE_RATE,
                    SPLIT_IMPULSE_MAX_PUSH * self.settings.length_scale,
                ),
            );
        }
        self.scatter_solver_bodies();
    }
}
