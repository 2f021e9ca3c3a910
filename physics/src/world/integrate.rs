//! Forces and integration: motor torques, velocities from gravity and forces, positions
//! from velocities, and forces cleared after the step.

use super::{Integrator, World};
use crate::body::Body;
use crate::math::Vec2;

impl World {
    /// Stage 2: body motors add their torque (thesis §4.4), to the bodies the step moves
    /// only: a static or sleeping body's forces are not cleared after the step.
    pub(super) fn apply_motor_torques(&mut self, dt: f64) {
        for (handle, motor) in self.body_motors.iter_mut() {
            let Some(Some(b)) = self.bodies.get_mut(handle.index()) else {
                continue;
            };
            if b.is_static() || b.is_asleep() {
                continue;
            }
            b.torque += motor.torque(self.step_count, b.angular_velocity, dt);
        }
    }

    /// Joint springs change spins at once, before a (sub)step's velocities are
    /// integrated: a kick before the drift, symplectic where the step resolves the spring
    /// (`JointSpring::impulse`); + on body B, − on body A, of the bodies this pass moves.
    pub(super) fn kick_joint_springs(&mut self, dt: f64) {
        // Only the joints with a spring: a joint net's thousands of pins are not read
        // every substep to find none.
        for i in 0..self.spring_joints.len() {
            let k = self.spring_joints[i] as usize;
            let Some((spring, body_a, body_b)) = self.joints[k]
                .as_ref()
                .and_then(|j| Some((j.spring?, j.body_a, j.body_b)))
            else {
                continue;
            };
            let moving = |h: Option<crate::body::BodyHandle>| {
                let h = h?;
                let b = self.bodies.get(h.index())?.as_ref()?;
                (!self.sets.fixed_in_pass(h.0, b)).then_some((b.angular_velocity, b.inv_inertia))
            };
            let (a, b) = (moving(Some(body_a)), moving(body_b));
            if a.is_none() && b.is_none() {
                continue;
            }
            let Some(theta) = self.joint_angle(crate::JointHandle(k as u32)) else {
                continue;
            };
            let spin = |side: Option<(f64, f64)>| side.map_or(0.0, |s| s.0);
            let inverse = |side: Option<(f64, f64)>| side.map_or(0.0, |s| s.1);
            let impulse = spring.impulse(theta, spin(b) - spin(a), inverse(a) + inverse(b), dt);
            let mut kick = |h: crate::body::BodyHandle, impulse: f64| {
                if let Some(Some(body)) = self.bodies.get_mut(h.index()) {
                    body.angular_velocity += impulse * body.inv_inertia;
                }
            };
            if a.is_some() {
                kick(body_a, -impulse);
            }
            if let (Some(_), Some(h)) = (b, body_b) {
                kick(h, impulse);
            }
        }
    }

    /// Gravity and accumulated forces change velocities (thesis §3.4 steps 2–3).
    /// (Every body's velocity is kept in `start_velocities` first, for restitution: the
    /// awake bodies' each time, the others' when the sets change.)
    pub(super) fn integrate_velocities(&mut self, dt: f64) {
        let inputs = &mut self.inputs;
        let n = self.bodies.len();
        let whole = inputs.start_velocities.len() == n;
        let remake = self
            .sets
            .to_remake(&mut inputs.start_velocities_made, whole, n);
        if remake.every() {
            inputs.start_velocities.clear();
            inputs.start_velocities.resize(n, (Vec2::zeros(), 0.0));
        }
        for i in remake {
            let body = self.bodies[i as usize].as_ref();
            let velocity = |b| self.sets.velocity_in_pass(i, b);
            inputs.start_velocities[i as usize] = body.map_or((Vec2::zeros(), 0.0), velocity);
        }
        for &i in self.sets.moving() {
            let b = self.bodies[i as usize].as_mut().expect("an awake body");
            b.velocity += (self.gravity + b.force * b.inv_mass) * dt;
            b.angular_velocity += b.torque * b.inv_inertia * dt;
        }
    }

    /// Positions follow velocities (thesis §3.4 step 7).
    pub(super) fn integrate_positions(&mut self, dt: f64) {
        let gravity = self.gravity;
        let explicit = self.settings.integrator == Integrator::ExplicitEuler;
        for &i in self.sets.moving() {
            let b = self.bodies[i as usize].as_mut().expect("an awake body");
            let (v, w) = if explicit {
                // Undo this step's force contribution: the position uses the old velocity,
                // plus whatever impulses (contacts, joints) changed since.
                let force_dv = (gravity + b.force * b.inv_mass) * dt;
                let force_dw = b.torque * b.inv_inertia * dt;
                (b.velocity - force_dv, b.angular_velocity - force_dw)
            } else {
                (b.velocity, b.angular_velocity)
            };
            b.position += v * dt;
            b.angle += w * dt;
        }
    }

    /// Every force and torque back to zero: the awake bodies', and everyone's when the
    /// sets changed (a force given by hand to a static or sleeping body goes too).
    pub(super) fn clear_forces(&mut self) {
        let clear = |b: &mut Body| {
            b.force = Vec2::zeros();
            b.torque = 0.0;
        };
        let n = self.bodies.len();
        for i in self.sets.to_remake(&mut self.forces_cleared, true, n) {
            if let Some(b) = self.bodies[i as usize].as_mut() {
                clear(b);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::body::BodyDef;
    use crate::shape::ConvexPolygon;
    use crate::solver::motor::BodyMotor;

    /// Forces and torques last one step on every body: a box asleep on a static floor,
    /// both given a force and a torque by hand, and a motor running on the floor (which
    /// does not turn it). After the next step no body holds any.
    #[test]
    fn forces_last_one_step_on_every_body() {
        let mut world = World::new(Vec2::new(0.0, 10.0));
        world.settings.sleeping = true;
        let slab = ConvexPolygon::rectangle(10.0, 1.0).unwrap();
        let floor = world.add_body(BodyDef::new(slab, 0.0)).unwrap();
        let unit = ConvexPolygon::rectangle(1.0, 1.0).unwrap();
        let at = Vec2::new(0.0, -1.0);
        let square = world.add_body(BodyDef::new(unit, 1.0).at(at, 0.0)).unwrap();
        for _ in 0..120 {
            world.step(1.0 / 60.0);
        }
        assert!(world.body(square).unwrap().is_asleep());
        let motor = BodyMotor::new(0, 1000, 1.0, 10.0, 20.0, 0.1);
        world.add_body_motor(floor, motor).unwrap();
        for handle in [floor, square] {
            let body = world.body_mut(handle).unwrap();
            body.force = Vec2::new(1.0, 2.0);
            body.torque = 3.0;
        }
        for step in 0..3 {
            world.step(1.0 / 60.0);
            for (_, b) in world.bodies() {
                assert_eq!((b.force, b.torque), (Vec2::zeros(), 0.0), "step {step}");
            }
        }
    }
}
