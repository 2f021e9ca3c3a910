//! The world and its step: a list of named stages (SPEC §3.4).

use crate::body::{Body, BodyDef, BodyError, BodyHandle};
use crate::collide::{Aabb, Manifold, SweepAndPrune, WorldPolygon, collide_polygons};
use crate::math::Vec2;
use crate::solver::contact::{Contact, restitution_threshold, solve_sequential};
use crate::solver::{ContactSolver, SolverBody};

/// How velocities and positions advance over a step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Integrator {
    /// Position from the velocity at the start of the step (SPEC §2.1).
    ExplicitEuler,
    /// Velocity first, then position with the new velocity: the thesis's order (SPEC §2.2).
    #[default]
    SemiImplicitEuler,
}

/// Tuning of a world. Lengths scale with `length_scale`, the size of a typical body, so that
/// a scene in pixels behaves like the same scene in metres.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepSettings {
    pub integrator: Integrator,
    pub contact_solver: ContactSolver,
    /// A typical body size in the world's length unit (1 for metre-sized bodies).
    pub length_scale: f64,
}

impl Default for StepSettings {
    fn default() -> Self {
        Self {
            integrator: Integrator::default(),
            contact_solver: ContactSolver::default(),
            length_scale: 1.0,
        }
    }
}

impl StepSettings {
    /// Bodies closer than this count as touching, so resting contacts persist (SPEC §3.1).
    pub fn contact_margin(&self) -> f64 {
        0.02 * self.length_scale
    }

    /// A reference face is swapped for the other body's only when better by this much.
    pub fn tie_tolerance(&self) -> f64 {
        0.001 * self.length_scale
    }
}

/// A 2D world of rigid convex bodies.
#[derive(Debug, Clone, Default)]
pub struct World {
    bodies: Vec<Option<Body>>,
    pub gravity: Vec2,
    /// Friction coefficient for contacts whose bodies set none (the scene's `friction`).
    pub friction: f64,
    pub settings: StepSettings,
    step_count: u64,
    manifolds: Vec<Manifold>,
    contacts: Vec<Contact>,
    scratch: Scratch,
}

/// Buffers reused from step to step so that stepping does not allocate.
#[derive(Debug, Clone, Default)]
struct Scratch {
    polygons: Vec<WorldPolygon>,
    boxes: Vec<Option<Aabb>>,
    broad_phase: SweepAndPrune,
    pairs: Vec<(u32, u32)>,
    solver_bodies: Vec<SolverBody>,
}

impl World {
    pub fn new(gravity: Vec2) -> Self {
        Self {
            gravity,
            ..Self::default()
        }
    }

    pub fn add_body(&mut self, def: BodyDef) -> Result<BodyHandle, BodyError> {
        let body = Body::new(def)?;
        self.bodies.push(Some(body));
        Ok(BodyHandle((self.bodies.len() - 1) as u32))
    }

    /// Removes a body; its handle then finds nothing. Returns the body if it existed.
    pub fn remove_body(&mut self, handle: BodyHandle) -> Option<Body> {
        self.bodies.get_mut(handle.index())?.take()
    }

    pub fn body(&self, handle: BodyHandle) -> Option<&Body> {
        self.bodies.get(handle.index())?.as_ref()
    }

    pub fn body_mut(&mut self, handle: BodyHandle) -> Option<&mut Body> {
        self.bodies.get_mut(handle.index())?.as_mut()
    }

    /// Live bodies in handle order.
    pub fn bodies(&self) -> impl Iterator<Item = (BodyHandle, &Body)> {
        self.bodies
            .iter()
            .enumerate()
            .filter_map(|(i, b)| Some((BodyHandle(i as u32), b.as_ref()?)))
    }

    pub fn step_count(&self) -> u64 {
        self.step_count
    }

    /// The manifolds found by the last step.
    pub fn manifolds(&self) -> &[Manifold] {
        &self.manifolds
    }

    /// The contact points of the last step with the impulses the solver gave them.
    pub fn contacts(&self) -> &[Contact] {
        &self.contacts
    }

    pub fn kinetic_energy(&self) -> f64 {
        self.bodies().map(|(_, b)| b.kinetic_energy()).sum()
    }

    /// Potential energy in the uniform gravity field, zero at the world origin.
    pub fn potential_energy(&self) -> f64 {
        self.bodies()
            .map(|(_, b)| -b.mass() * self.gravity.dot(&b.position))
            .sum()
    }

    pub fn linear_momentum(&self) -> Vec2 {
        self.bodies().map(|(_, b)| b.velocity * b.mass()).sum()
    }

    pub fn angular_momentum(&self) -> f64 {
        self.bodies().map(|(_, b)| b.angular_momentum()).sum()
    }

    /// Advances the world by `dt`: SPEC §3.4's stages, in order.
    pub fn step(&mut self, dt: f64) {
        self.integrate_velocities(dt);
        self.detect_contacts();
        self.push_apart();
        self.solve_contacts(dt);
        self.integrate_positions(dt);
        self.clear_forces();
        self.step_count += 1;
    }

    /// Gravity and accumulated forces change velocities (SPEC §3.4 steps 2–3).
    fn integrate_velocities(&mut self, dt: f64) {
        for b in self.bodies.iter_mut().flatten() {
            if b.is_static() {
                continue;
            }
            b.velocity += (self.gravity + b.force * b.inv_mass) * dt;
            b.angular_velocity += b.torque * b.inv_inertia * dt;
        }
    }

    /// Broad phase, then SAT on each candidate pair (SPEC §3.1).
    fn detect_contacts(&mut self) {
        let s = &mut self.scratch;
        s.polygons
            .resize_with(self.bodies.len(), WorldPolygon::default);
        s.boxes.clear();
        let margin = self.settings.contact_margin();
        for (body, polygon) in self.bodies.iter().zip(s.polygons.iter_mut()) {
            s.boxes.push(body.as_ref().map(|b| {
                polygon.update(b);
                polygon.aabb().grown(0.5 * margin)
            }));
        }
        let bodies = &self.bodies;
        let is_static = |i: usize| bodies[i].as_ref().is_none_or(Body::is_static);
        s.broad_phase.pairs(
            &s.boxes,
            |i, j| !(is_static(i) && is_static(j)),
            &mut s.pairs,
        );
        self.manifolds.clear();
        self.contacts.clear();
        let tie = self.settings.tie_tolerance();
        for &(i, j) in &s.pairs {
            let (a, b) = (BodyHandle(i), BodyHandle(j));
            let found = collide_polygons(
                (a, &s.polygons[i as usize]),
                (b, &s.polygons[j as usize]),
                margin,
                tie,
            );
            if let Some(m) = found {
                self.manifolds.push(m);
            }
        }
        for m in &self.manifolds {
            let body = |h: BodyHandle| self.bodies.get(h.index()).and_then(Option::as_ref);
            let (Some(a), Some(b)) = (body(m.body_a), body(m.body_b)) else {
                continue;
            };
            let friction =
                (a.friction.unwrap_or(self.friction) * b.friction.unwrap_or(self.friction)).sqrt();
            for p in m.points() {
                self.contacts.push(Contact {
                    body_a: m.body_a.0,
                    body_b: m.body_b.0,
                    point: p.position,
                    normal: m.normal,
                    depth: p.depth,
                    id: p.id,
                    restitution: a.restitution.min(b.restitution),
                    friction,
                    normal_impulse: 0.0,
                    tangent_impulse: 0.0,
                });
            }
        }
    }

    /// The thesis removes overlap directly: each pair is pushed apart along its normal by
    /// its depth, shared by inverse mass (SPEC §3.1). Positions only.
    fn push_apart(&mut self) {
        for m in &self.manifolds {
            let depth = m.depth();
            if depth <= 0.0 {
                continue;
            }
            let (ia, ib) = (m.body_a.index(), m.body_b.index());
            let inv_a = self.bodies[ia].as_ref().map_or(0.0, Body::inv_mass);
            let inv_b = self.bodies[ib].as_ref().map_or(0.0, Body::inv_mass);
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

    fn solve_contacts(&mut self, dt: f64) {
        let s = &mut self.scratch;
        s.solver_bodies.clear();
        s.solver_bodies.extend(
            self.bodies
                .iter()
                .map(|b| b.as_ref().map(SolverBody::from_body).unwrap_or_default()),
        );
        let bounce_below = restitution_threshold(self.gravity, dt);
        match self.settings.contact_solver {
            ContactSolver::Sequential | ContactSolver::Thesis => {
                solve_sequential(&mut self.contacts, &mut s.solver_bodies, bounce_below)
            }
        }
        for (body, solved) in self.bodies.iter_mut().zip(&s.solver_bodies) {
            if let Some(b) = body {
                b.velocity = solved.velocity;
                b.angular_velocity = solved.angular_velocity;
            }
        }
    }

    /// Positions follow velocities (SPEC §3.4 step 7).
    fn integrate_positions(&mut self, dt: f64) {
        let gravity = self.gravity;
        let explicit = self.settings.integrator == Integrator::ExplicitEuler;
        for b in self.bodies.iter_mut().flatten() {
            if b.is_static() {
                continue;
            }
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

    fn clear_forces(&mut self) {
        for b in self.bodies.iter_mut().flatten() {
            b.force = Vec2::zeros();
            b.torque = 0.0;
        }
    }
}
