//! The exact solver's depth pass (split impulse): the depth beyond the slop removed by
//! moving positions only, with the pins as equality rows so that the push cannot open
//! them, and no kinetic energy added.

use super::SimultaneousSolver;
use super::system::{RowKind, VelocityTargets, velocity_rows};
use crate::solver::contact::Contact;
use crate::solver::joint::JointConstraint;
use crate::solver::{BodiesAndMoving, SolverBody};

/// The position pass's regularisation (`lcp::LcpProblem`): it moves bodies apart, where
/// a compliance of 1e-9 changes nothing visible, and stacked boxes pressed into each other
/// give it redundant rows on which pivoting at 1e-12 cycled to its cap (the overlapping
/// pyramid: 20 solves over budget in 300 steps, against 1).
const POSITION_REGULARISATION: f64 = 1e-9;

impl SimultaneousSolver {
    /// Removes penetration deeper than `slop` without adding energy (split impulse): the
    /// normal rows, with the pins as equality rows so the push cannot open them, are solved
    /// for pseudo-velocities that move `bodies`' positions and angles only. Each step
    /// removes the fraction `rate` of the excess depth, moving no contact point faster
    /// than `max_push` (length per second).
    pub(crate) fn separate(
        &mut self,
        contacts: &[Contact],
        joints: &[JointConstraint],
        (bodies, moving): BodiesAndMoving<'_>,
        dt: f64,
        slop: f64,
        (rate, max_push): (f64, f64),
    ) {
        let mut contacts_copy = std::mem::take(&mut self.scratch_contacts);
        contacts_copy.clear();
        contacts_copy.extend_from_slice(contacts);
        let mut joints_copy = std::mem::take(&mut self.scratch_joints);
        joints_copy.clear();
        joints_copy.extend_from_slice(joints);
        self.group(&contacts_copy, &joints_copy, true, bodies, moving);
        let mut pseudo = std::mem::take(&mut self.pseudo);
        let at_rest = |b: &SolverBody| SolverBody {
            velocity: crate::math::Vec2::zeros(),
            angular_velocity: 0.0,
            ..*b
        };
        let ends = 2 * (contacts_copy.len() + joints_copy.len()) + moving.len();
        if pseudo.len() == bodies.len() && ends < bodies.len() {
            // Only the bodies the rows read (the contacts' and joints') and the moving ones,
            // which the pass moves: a terrain's 2,000 tiles are not copied at every step.
            // (The same numbers as copying them all, which a robot's few bodies take.)
            let contact_ends = contacts_copy.iter().map(|c| (c.body_a.0, c.body_b.0));
            let joint_ends = joints_copy.iter().map(|j| (j.body_a, j.body_b));
            for (a, b) in contact_ends.chain(joint_ends) {
                pseudo[a as usize] = at_rest(&bodies[a as usize]);
                pseudo[b as usize] = at_rest(&bodies[b as usize]);
            }
            for &i in moving {
                pseudo[i as usize] = at_rest(&bodies[i as usize]);
            }
        } else {
            pseudo.clear();
            pseudo.extend(bodies.iter().map(at_rest));
        }
        let targets = VelocityTargets {
            dt,
            bounce_below: f64::INFINITY,
            friction: false,
        };
        self.regularisation = POSITION_REGULARISATION;
        for island in 0..self.ranges.len() {
            self.load_island(island, &contacts_copy, &joints_copy);
            if self.island_contacts.iter().all(|(_, c)| c.depth <= slop) {
                continue;
            }
            self.island_joints.iter_mut().for_each(|j| j.motor = None);
            velocity_rows(
                &self.island_contacts,
                &self.island_joints,
                &pseudo,
                &targets,
                &mut self.rows,
            );
            let mut contact = self.island_contacts.iter();
            for row in self.rows.iter_mut() {
                if let RowKind::ContactNormal(_) = row.kind {
                    let depth = contact.next().map_or(0.0, |(_, c)| c.depth);
                    row.b = -rate * (depth - slop).max(0.0) / dt;
                }
            }
            self.solve_rows(&mut pseudo, true);
            self.limit_separation(&mut pseudo, dt, slop, max_push);
        }
        // Only the moving bodies have a pseudo-velocity.
        for &i in moving {
            let (body, p) = (&mut bodies[i as usize], &pseudo[i as usize]);
            body.position += p.velocity * dt;
            body.angle += p.angular_velocity * dt;
        }
        self.pseudo = pseudo;
        self.scratch_contacts = contacts_copy;
        self.scratch_joints = joints_copy;
    }

    /// Scales the island's pseudo-velocities down so that no contact point moves more
    /// than twice the deepest excess penetration, nor faster than `max_push`: a push the
    /// pins forbid (two pinned bodies that overlap and may collide) has no solution, and
    /// the solve's answer to it would throw such a pair far away; and bodies placed deep
    /// in each other part gently, turning little enough in a step that their pins, held to
    /// first order by the pass, stay closed to second.
    fn limit_separation(&self, pseudo: &mut [SolverBody], dt: f64, slop: f64, max_push: f64) {
        let deepest = self
            .island_contacts
            .iter()
            .map(|(_, c)| c.depth - slop)
            .fold(0.0, f64::max);
        let allowed = (2.0 * deepest).min(max_push * dt);
        let moved = self
            .island_contacts
            .iter()
            .flat_map(|(_, c)| [c.body_a, c.body_b].map(|b| (b, c.point)))
            .map(|(b, point)| pseudo[b.index()].velocity_at(point).norm() * dt)
            .fold(0.0, f64::max);
        if moved <= allowed {
            return;
        }
        let scale = allowed / moved;
        for end in self.rows.iter().flat_map(|r| r.ends.iter()) {
            let body = &mut pseudo[end.body as usize];
            body.velocity *= scale;
            body.angular_velocity *= scale;
        }
    }
}
