//! The step's results written back: the bodies' velocities and motion, each contact's
//! and pin's impulses (kept for the next step's warm start), and the island reports.

use super::SoftStepSolver;
use super::batch::PassItem;
use super::constraints::DIRECT_JOINT_LIMIT;
use super::constraints::PointConstraint;
use crate::solver::SolverBody;
use crate::solver::contact::Contact;
use crate::solver::joint::JointConstraint;
use crate::solver::report::{IslandMethod, IslandReport};

impl SoftStepSolver {
    /// Records how each island of contacts and of pins was solved.
    pub(super) fn report(&mut self) {
        self.reports.clear();
        for &(start, end) in &self.pins.joint_islands {
            let pins = end - start;
            self.reports.push(IslandReport {
                contacts: 0,
                joints: pins,
                rows: 2 * pins,
                method: if (2..=DIRECT_JOINT_LIMIT).contains(&pins) {
                    IslandMethod::SoftPinBlock
                } else {
                    IslandMethod::SoftPinByPin
                },
                pivots: 0,
                over_budget: false,
                residual: f64::NAN,
            });
        }
        for &(start, end, lcp) in &self.contact_lcp.all_islands {
            let points = end - start;
            self.reports.push(IslandReport {
                contacts: points,
                joints: 0,
                rows: 2 * points,
                method: if lcp {
                    IslandMethod::SoftLcp
                } else {
                    IslandMethod::SoftPointByPoint
                },
                pivots: 0,
                over_budget: false,
                residual: f64::NAN,
            });
        }
    }
    pub(super) fn store(
        &mut self,
        bodies: &mut [SolverBody],
        contacts: &mut [Contact],
        joints: &mut [JointConstraint],
        substeps: usize,
    ) {
        for &i in &self.loaded.moving {
            let (b, s) = (&mut bodies[i as usize], &self.loaded.bodies[i as usize]);
            b.velocity = s.v;
            b.angular_velocity = s.w;
            b.position += s.dp;
            b.angle += s.dangle;
        }
        // Gathered by contact first, then written into the contacts in their order: the
        // lanes come in colour order, and writing each straight into its contact touched
        // the contacts' lines (3 MB on large_pyramid) at random.
        let mut impulses = std::mem::take(&mut self.impulses);
        impulses.clear();
        // Every contact belongs to a batch, an LCP island or a manifold solved alone, so
        // every entry is written below.
        impulses.resize(contacts.len(), (0.0, 0.0));
        let store_points = |points: &[PointConstraint], impulses: &mut [(f64, f64)]| {
            for p in points {
                impulses[p.contact as usize] = (p.normal_impulse, p.tangent_impulse);
            }
        };
        if self.may_bounce {
            store_points(&self.points, &mut impulses);
        } else {
            // The batched points' impulses are still in their lanes: from there, and
            // the rest (LCP islands, manifolds solved alone) from the points.
            self.plan.store_impulses(&mut impulses);
            for &(start, end, lcp) in &self.contact_lcp.all_islands {
                if lcp {
                    store_points(&self.points[start..end], &mut impulses);
                }
            }
            for item in &self.plan.items {
                if let PassItem::Manifold(first, count) = *item {
                    let (first, count) = (first as usize, count as usize);
                    store_points(&self.points[first..first + count], &mut impulses);
                }
            }
        }
        self.memory.store_from(contacts, &impulses);
        self.impulses = impulses;
        // The pins' pull asks for substeps only where an island of pins is solved as one
        // system (`DIRECT_JOINT_LIMIT`): there the step holds the pins exactly but for the
        // pull's own stiffness; a big net, solved pin by pin, stretches whatever the
        // substeps, and only pays for more. Each substep starts from the impulse the last
        // one ended with: the step's is about that many times one substep's.
        for &(start, end) in &self.pins.joint_islands {
            if end - start <= DIRECT_JOINT_LIMIT {
                for j in &self.pins.joints[start..end] {
                    joints[j.input as usize].impulse += j.impulse * substeps as f64;
                }
            }
        }
        for j in &self.pins.joints {
            self.pins
                .joint_memory
                .keep(j.input, (j.slot, j.impulse, j.motor_impulse));
            if let Some(m) = joints[j.input as usize].motor.as_mut() {
                m.last_impulse = j.motor_impulse;
                m.step_impulse = j.motor_step_total;
            }
        }
        self.pins.joint_memory.finish();
    }
}
