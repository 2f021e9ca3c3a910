//! The impact pass (`StepSettings::propagate_impacts`): where two moving bodies meet at
//! speed, the impact passes on body pair by body pair, as a shock travels through bodies
//! at rest in contact (a Newton's cradle sends out one ball), instead of in one LCP with
//! the island's every contact (the thesis's model, which shares an impulse through every
//! contact at once: a cradle moves off as a block). `exact` runs it on each island before
//! the island's LCP (`on_island`); the soft step on every island before its substeps
//! (`on_every_island`). Each pair's bounce adds no energy (`solver::bounce`).

use super::bounce::{BounceGuard, gains_energy};
use super::contact::Contact;
use super::exact::system::{DenseRowsLcp, Row, RowKind, VelocityTargets, velocity_rows};
use super::island::{IslandGrouping, island_ranges};
use super::joint::JointConstraint;
use super::lcp::REGULARISATION;
use super::{BodiesAndMoving, SolverBody};

/// Whether the bodies' velocities already hold the step's forces (`exact`: a contact's
/// `normal_velocity` is the velocity now, its `approach_velocity` the one before the
/// forces) or not yet (the soft step, whose forces act in its substeps: the approach is
/// the velocity now, and `normal_velocity` adds the forces' share).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Kick {
    Applied,
    Pending,
}

/// The most times the impact pass solves a body pair, on average over the island's pairs,
/// before it leaves what still bounces to the simultaneous solve: a row of n touching
/// bodies passes one impact on in n solves, a column bouncing on the floor in about 2n.
const IMPACT_SOLVES_PER_PAIR: usize = 8;

/// The impact pass's buffers, reused from step to step.
#[derive(Debug, Clone, Default)]
pub(crate) struct ImpactPass {
    /// `StepSettings::dense_row_limit`, copied in before each pass: an island with more
    /// pins than that makes rows is left to its solver.
    pub dense_row_limit: usize,
    /// The (normal, tangent) impulses the last `on_island` gave each of its contacts.
    pub impulses: Vec<(f64, f64)>,
    /// Which of the island's body pairs the last `on_island` bounced.
    pub bounced: Vec<bool>,
    /// The island's body pairs: each one's span of its contacts (a manifold's points come
    /// one after another).
    pub pair_spans: Vec<(usize, usize)>,
    /// The pins of the island without their motors.
    impact_joints: Vec<JointConstraint>,
    /// One pair's contacts as the pass solves them.
    impact_contacts: Vec<(u32, Contact)>,
    /// Every island's contacts and joints, for `on_every_island`.
    grouping: IslandGrouping,
    ranges: Vec<(usize, usize)>,
    island_contacts: Vec<(u32, Contact)>,
    island_joints: Vec<JointConstraint>,
    /// One pair's rows and their LCP.
    rows: Vec<Row>,
    dense: DenseRowsLcp,
    x: Vec<f64>,
    /// A bouncing pair's bodies' velocities before it, after it, and after the same solve
    /// without a bounce (`solver::bounce`).
    bounce: BounceGuard,
}

impl ImpactPass {
    /// The island's impacts, body pair by body pair (`StepSettings::propagate_impacts`),
    /// instead of in the island's one LCP with everything else (the thesis's model, which
    /// shares an impulse through every contact at once: a Newton's cradle moves off as a
    /// block). An impact travels through bodies at rest in contact as a shock does: each pair
    /// with a point that meets fast enough to bounce is solved alone with the island's pins
    /// (normals, friction and pins in one small LCP), in order, sweep after sweep, until
    /// no pair bounces; then the pairs that bounced are marked as not bouncing, so that the
    /// simultaneous solve only holds them apart. A pair reflects its approach as it is when
    /// its turn comes, less this step's gravity kick (`Contact::approach_velocity`).
    pub(crate) fn on_island(
        &mut self,
        contacts: &mut [(u32, Contact)],
        joints: &[JointConstraint],
        bodies: &mut [SolverBody],
        targets: &VelocityTargets,
        kick: Kick,
    ) {
        let (dt, bounce_below) = (targets.dt, targets.bounce_below);
        self.pair_spans.clear();
        self.bounced.clear();
        self.impulses.clear();
        // Only where two moving bodies meet at speed; a body bouncing off a fixed one alone
        // passes nothing on, and is left to the simultaneous solve as before (a robot's feet
        // landing together, whose solve the pair-by-pair pass would change).
        if !contacts.iter().any(|(_, c)| passes_on(c, bodies, targets)) {
            return;
        }
        self.find_pair_spans(contacts);
        self.bounced.resize(self.pair_spans.len(), false);
        self.impact_joints.clear();
        self.impact_joints
            .extend(joints.iter().map(|j| JointConstraint { motor: None, ..*j }));
        if 2 * self.impact_joints.len() + 3 > self.dense_row_limit {
            return;
        }
        self.impulses.resize(contacts.len(), (0.0, 0.0));
        let mut budget = IMPACT_SOLVES_PER_PAIR * self.pair_spans.len();
        'sweeps: loop {
            let mut any = false;
            for p in 0..self.pair_spans.len() {
                self.read_impact_pair(contacts, p, bodies, kick);
                if !self
                    .impact_contacts
                    .iter()
                    .any(|(_, c)| c.bounces(dt, bounce_below))
                {
                    continue;
                }
                if budget == 0 {
                    break 'sweeps;
                }
                budget -= 1;
                if !self.solve_impact_pair(contacts, p, bodies, targets) {
                    break 'sweeps;
                }
                any = true;
                self.bounced[p] = true;
            }
            if !any {
                break;
            }
        }
        // The pairs that bounced only keep apart in the island's solve; the others meet it
        // as the impacts passed on left them.
        for (p, &(start, end)) in self.pair_spans.iter().enumerate() {
            for (_, c) in &mut contacts[start..end] {
                if self.bounced[p] {
                    c.approach_velocity = 0.0;
                } else {
                    let now = c.relative_velocity(bodies).dot(&c.normal);
                    let forces = c.normal_velocity - c.approach_velocity;
                    (c.approach_velocity, c.normal_velocity) = match kick {
                        Kick::Applied => (now - forces, now),
                        Kick::Pending => (now, now + forces),
                    };
                }
            }
        }
    }

    /// The impact pass on every island, for a solver that bounces contacts its own way
    /// (the soft step): the pairs it bounced get no restitution from that solver this
    /// step.
    pub(crate) fn on_every_island(
        &mut self,
        contacts: &mut [Contact],
        joints: &[JointConstraint],
        (bodies, moving): BodiesAndMoving<'_>,
        targets: &VelocityTargets,
    ) {
        // As in `propagate_impacts`: and the soft step's own bounce off a fixed body places
        // it better (at the surface, not where the pair was at the step's start).
        if !contacts.iter().any(|c| passes_on(c, bodies, targets)) {
            return;
        }
        let nc = contacts.len();
        let ends = |i: usize| {
            if i < nc {
                (contacts[i].body_a.0, contacts[i].body_b.0)
            } else {
                (joints[i - nc].body_a, joints[i - nc].body_b)
            }
        };
        let grouped = self
            .grouping
            .group(nc + joints.len(), bodies.len(), ends, moving);
        island_ranges(grouped, &mut self.ranges);
        let mut island_contacts = std::mem::take(&mut self.island_contacts);
        let mut island_joints = std::mem::take(&mut self.island_joints);
        for island in 0..self.ranges.len() {
            let (start, end) = self.ranges[island];
            island_contacts.clear();
            island_joints.clear();
            for &(_, item) in &self.grouping.grouped()[start..end] {
                let item = item as usize;
                if item < nc {
                    island_contacts.push((item as u32, contacts[item]));
                } else {
                    island_joints.push(joints[item - nc]);
                }
            }
            if !island_contacts
                .iter()
                .any(|(_, c)| passes_on(c, bodies, targets))
            {
                continue;
            }
            self.on_island(
                &mut island_contacts,
                &island_joints,
                bodies,
                targets,
                Kick::Pending,
            );
            if !self.bounced.contains(&true) {
                continue;
            }
            // The island's velocities changed: its contacts' approaches are read again.
            for &(i, c) in island_contacts.iter() {
                let now = c.relative_velocity(bodies).dot(&c.normal);
                let contact = &mut contacts[i as usize];
                let kick = contact.normal_velocity - contact.approach_velocity;
                contact.approach_velocity = now;
                contact.normal_velocity = now + kick;
            }
            for (p, &(start, end)) in self.pair_spans.iter().enumerate() {
                if self.bounced[p] {
                    for &(i, _) in &island_contacts[start..end] {
                        contacts[i as usize].restitution = 0.0;
                    }
                }
            }
        }
        self.island_contacts = island_contacts;
        self.island_joints = island_joints;
    }

    /// Each body pair's span of `island_contacts` (a pair's points come one after another).
    fn find_pair_spans(&mut self, contacts: &[(u32, Contact)]) {
        let pair = |c: &Contact| (c.body_a, c.body_b);
        let mut k = 0;
        while k < contacts.len() {
            let first = pair(&contacts[k].1);
            let n = contacts[k..]
                .iter()
                .take_while(|(_, c)| pair(c) == first)
                .count();
            self.pair_spans.push((k, k + n));
            k += n;
        }
    }

    /// Pair `p`'s contacts into `impact_contacts` with their normal velocities as they are
    /// now, after the impacts already passed on.
    fn read_impact_pair(
        &mut self,
        contacts: &[(u32, Contact)],
        p: usize,
        bodies: &[SolverBody],
        kick: Kick,
    ) {
        let (start, end) = self.pair_spans[p];
        self.impact_contacts.clear();
        for &(index, c) in &contacts[start..end] {
            let now = c.relative_velocity(bodies).dot(&c.normal);
            // What the step's forces add along the normal: reflected never, but counted in
            // whether the pair meets this step.
            let forces = c.normal_velocity - c.approach_velocity;
            let (approach_velocity, normal_velocity) = match kick {
                Kick::Applied => (now - forces, now),
                Kick::Pending => (now, now + forces),
            };
            let contact = Contact {
                approach_velocity,
                normal_velocity,
                ..c
            };
            self.impact_contacts.push((index, contact));
        }
    }

    /// Pair `p`'s impact: its normals and friction with the island's pins, which hold their
    /// velocities as they are (the pass moves nothing but the impact through them), as one
    /// LCP; the impulses go on the bodies and into `impact_impulses`.
    fn solve_impact_pair(
        &mut self,
        contacts: &[(u32, Contact)],
        p: usize,
        bodies: &mut [SolverBody],
        targets: &VelocityTargets,
    ) -> bool {
        let (start, end) = self.pair_spans[p];
        self.solve_impact_rows(bodies, targets);
        let ends = self.rows.iter().flat_map(|r| r.ends.iter().map(|e| e.body));
        let brought = self.bounce.before(bodies, ends);
        for (row, &x) in self.rows.iter().zip(&self.x) {
            row.apply(bodies, x);
        }
        let bounced = self.bounce.bounced(bodies);
        if !bounced.is_finite() {
            self.bounce.restore_before(bodies);
            return false;
        }
        if gains_energy(brought, bounced) {
            // A face's two points, each reflecting its own approach, or a pair whose rows
            // contradict its pins (two pinned bodies that overlap and may collide): the
            // bounce is held to what the pair brought (`solver::bounce`).
            self.bounce.undo_bounce(bodies, &self.x);
            self.solve_impact_rows(bodies, &targets.without_bounce());
            for (row, &x) in self.rows.iter().zip(&self.x) {
                row.apply(bodies, x);
            }
            self.bounce.hold(bodies, brought, bounced, &mut self.x);
        }
        for (row, &x) in self.rows.iter().zip(&self.x) {
            let local = |i: u32| {
                contacts[start..end]
                    .iter()
                    .position(|&(index, _)| index == i)
                    .map(|k| start + k)
            };
            match row.kind {
                RowKind::ContactNormal(i) => {
                    if let Some(k) = local(i) {
                        self.impulses[k].0 += x;
                    }
                }
                RowKind::ContactTangent(i) | RowKind::SharedTangent(i, _) => {
                    if let Some(k) = local(i) {
                        self.impulses[k].1 += x;
                    }
                }
                _ => {}
            }
        }
        true
    }

    /// The impact pass's rows for the pair in `impact_contacts`, solved into `x` (not
    /// applied): its normals and friction with the island's pins, which keep their
    /// velocities as they are.
    fn solve_impact_rows(&mut self, bodies: &[SolverBody], targets: &VelocityTargets) {
        velocity_rows(
            &self.impact_contacts,
            &self.impact_joints,
            bodies,
            targets,
            &mut self.rows,
        );
        for row in self.rows.iter_mut() {
            if matches!(row.kind, RowKind::JointX(_) | RowKind::JointY(_)) {
                row.b = 0.0;
            }
        }
        (self.dense).solve(&self.rows, bodies, REGULARISATION, &[], &mut self.x);
    }
}

/// Whether contact `c` bounces this step between two moving bodies: an impact that may
/// pass on through the bodies at rest in contact with them.
pub(crate) fn passes_on(c: &Contact, bodies: &[SolverBody], targets: &VelocityTargets) -> bool {
    let moves = |i: u32| bodies[i as usize].moves();
    c.bounces(targets.dt, targets.bounce_below) && moves(c.body_a.0) && moves(c.body_b.0)
}
