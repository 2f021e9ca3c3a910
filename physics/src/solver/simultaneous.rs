//! Simultaneous impulses (thesis §2.4.6, §3.2), island by island: the thesis's two-stage
//! friction, and the coupled model that solves normals, friction, pins and joint motors in
//! one boxed LCP whose friction bounds follow the normal impulses.

use super::bounce::{KeptVelocities, bounce_share, gains_energy, mix_velocities};
use super::contact::{Contact, ContactMemory};
use super::island::{IslandGrouping, island_ranges};
use super::joint::JointConstraint;
use super::lcp::{FrictionBound, LcpMethod, LcpProblem, LcpSolver, LcpStats, REGULARISATION};
use super::system::{Row, RowKind, VelocityTargets, assemble, velocity_rows};
use super::{BodiesAndMoving, SolverBody};
use crate::math::clamp;

/// Islands with more rows than this are solved by projected Gauss–Seidel instead of the
/// dense pivoting method, whose cost grows as n³. Measured by `examples/dense_threshold.rs`
/// (README, Physics): where the pivoting solve starts costing more than the whole rest of
/// a step.
pub(crate) const DENSE_ROW_LIMIT: usize = 96;

/// The position pass's regularisation (`lcp::LcpProblem`): it moves bodies apart, where
/// a compliance of 1e-9 changes nothing visible, and stacked boxes pressed into each other
/// give it redundant rows on which pivoting at 1e-12 cycled to its cap (the overlapping
/// pyramid: 20 solves over budget in 300 steps, against 1).
const POSITION_REGULARISATION: f64 = 1e-9;

/// How an island's constraints were solved.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum IslandMethod {
    /// `exact`/`thesis`: the dense LCP by pivoting (up to `StepSettings::dense_row_limit`
    /// rows).
    Pivoting,
    /// `exact`/`thesis` above the row limit: projected Gauss–Seidel row by row.
    GaussSeidel,
    /// `soft`: a small contact island of different masses, one LCP per pass (its normals;
    /// its friction too where the masses differ 100-fold).
    SoftLcp,
    /// `soft`: contacts point by point (two-point manifolds as a 2 × 2 block).
    SoftPointByPoint,
    /// `soft`: an island of pins, solved as one linear system per pass.
    SoftPinBlock,
    /// `soft`: pins one by one (a lone pin, or an island above the block limit, whose
    /// pins go colour by colour, eight at a time, each lane as if alone: `soft::pins`).
    SoftPinByPin,
}

/// What happened in one island during the last step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IslandReport {
    pub contacts: usize,
    pub joints: usize,
    pub rows: usize,
    pub method: IslandMethod,
    /// Pivots made, or Gauss–Seidel sweeps (0 for the soft step's islands).
    pub pivots: usize,
    /// Whether the exact solve stopped at its pivot budget (`lcp::LcpStats::over_budget`):
    /// its last round stands, and under `auto` the island goes to the soft step for a
    /// while.
    pub over_budget: bool,
    /// The LCP's complementarity residual (NaN for Gauss–Seidel row by row, which never
    /// forms the matrix the residual is measured against).
    pub residual: f64,
}

/// The two-stage thesis pipeline or the coupled one.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum FrictionModel {
    /// thesis §3.2.4 steps 1–6: normals without friction, then friction bounded by them.
    TwoStage,
    /// Normals, friction (bounds ±μ·normal, updated with it), pins and motors together.
    Coupled,
}

/// Buffers reused across steps.
#[derive(Debug, Clone, Default)]
pub(crate) struct SimultaneousSolver {
    /// The contacts' and joints' islands, kept while the items and the moving bodies are
    /// the same (the passes of one substep find them once).
    grouping: IslandGrouping,
    /// Each island's span of `grouped`.
    ranges: Vec<(usize, usize)>,
    contact_count: usize,
    scratch_contacts: Vec<Contact>,
    scratch_joints: Vec<JointConstraint>,
    pseudo: Vec<SolverBody>,
    /// Velocities of an island's bodies during the row-by-row Gauss–Seidel.
    sparse_bodies: Vec<SolverBody>,
    /// Last solve's contact impulses: the row-by-row Gauss–Seidel starts from them (warm
    /// start) instead of from zero.
    memory: ContactMemory,
    /// Each of this solve's contacts' last (normal, tangent) impulses, by its index.
    recalled: Vec<(f64, f64)>,
    /// The starting impulses of the rows being solved (empty: start from zero).
    guess: Vec<f64>,
    /// Each row's `A_ii`, for the row-by-row Gauss–Seidel.
    diagonals: Vec<f64>,
    stage_one: Vec<f64>,
    normal_ordinal: Vec<usize>,
    island_contacts: Vec<(u32, Contact)>,
    island_joints: Vec<JointConstraint>,
    joint_slots: Vec<u32>,
    rows: Vec<Row>,
    a: Vec<f64>,
    b: Vec<f64>,
    lo: Vec<f64>,
    hi: Vec<f64>,
    friction_index: Vec<Option<FrictionBound>>,
    x: Vec<f64>,
    lcp: LcpSolver,
    pub reports: Vec<IslandReport>,
    /// The bodies of the islands that went over the pivot budget in the last solve.
    pub over_budget_bodies: Vec<u32>,
    /// The LCP's regularisation for the rows being solved (`lcp::LcpProblem`).
    regularisation: f64,
    /// `StepSettings::dense_row_limit`, copied in before each solve.
    pub dense_row_limit: usize,
    /// `StepSettings::propagate_impacts`, copied in before each solve.
    pub propagate_impacts: bool,
    /// The island's body pairs: each one's span of `island_contacts` (a manifold's points
    /// come one after another).
    pair_spans: Vec<(usize, usize)>,
    /// Which pairs the impact pass bounced.
    bounced: Vec<bool>,
    /// The pins of the island without their motors, for the impact pass.
    impact_joints: Vec<JointConstraint>,
    /// One pair's contacts as the impact pass solves them.
    impact_contacts: Vec<(u32, Contact)>,
    /// The (normal, tangent) impulses the impact pass gave each of the island's contacts.
    impact_impulses: Vec<(f64, f64)>,
    /// A bouncing solve's bodies' velocities before it, after it, and after the same
    /// solve without a bounce, with the bouncing answer's impulses (`bounce`).
    before_bounce: KeptVelocities,
    full_bounce: KeptVelocities,
    inelastic: KeptVelocities,
    x_full: Vec<f64>,
}

/// Whether the bodies' velocities already hold the step's forces (`exact`: a contact's
/// `normal_velocity` is the velocity now, its `approach_velocity` the one before the
/// forces) or not yet (the soft step, whose forces act in its substeps: the approach is
/// the velocity now, and `normal_velocity` adds the forces' share).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kick {
    Applied,
    Pending,
}

/// The most times the impact pass solves a body pair, on average over the island's pairs,
/// before it leaves what still bounces to the simultaneous solve: a row of n touching
/// bodies passes one impact on in n solves, a column bouncing on the floor in about 2n.
const IMPACT_SOLVES_PER_PAIR: usize = 8;

impl SimultaneousSolver {
    /// Solves every island and applies the impulses to `bodies`; contacts get their normal
    /// and tangent impulses, joints with motors their motor impulse. With `TwoStage`,
    /// joints are left to the joint passes, as in the thesis. `moving`: the slots of the
    /// bodies that move, increasing (every other body of `bodies` is fixed).
    pub(crate) fn solve(
        &mut self,
        model: FrictionModel,
        contacts: &mut [Contact],
        joints: &mut [JointConstraint],
        (bodies, moving): BodiesAndMoving<'_>,
        targets: &VelocityTargets,
    ) {
        self.reports.clear();
        self.over_budget_bodies.clear();
        self.regularisation = REGULARISATION;
        self.memory.recall(contacts, &mut self.recalled);
        self.group(
            contacts,
            joints,
            model == FrictionModel::Coupled,
            bodies,
            moving,
        );
        for island in 0..self.ranges.len() {
            self.load_island(island, contacts, joints);
            self.impact_impulses.clear();
            match model {
                FrictionModel::TwoStage => {
                    self.solve_holding_bounce(bodies, targets, Self::solve_two_stage)
                }
                FrictionModel::Coupled => {
                    if self.propagate_impacts {
                        self.propagate_impacts(bodies, targets, Kick::Applied);
                    }
                    self.solve_holding_bounce(bodies, targets, Self::solve_coupled);
                }
            }
            self.write_back(contacts, joints);
        }
        self.memory.store(contacts);
    }

    /// The impact pass (`propagate_impacts`) on every island, for a solver that bounces
    /// contacts its own way (the soft step): the pairs it bounced get no restitution
    /// from that solver this step.
    pub(crate) fn propagate_all_impacts(
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
        self.group(contacts, joints, true, bodies, moving);
        for island in 0..self.ranges.len() {
            self.load_island(island, contacts, joints);
            if !self
                .island_contacts
                .iter()
                .any(|(_, c)| passes_on(c, bodies, targets))
            {
                continue;
            }
            self.impact_impulses.clear();
            self.propagate_impacts(bodies, targets, Kick::Pending);
            if !self.bounced.contains(&true) {
                continue;
            }
            // The island's velocities changed: its contacts' approaches are read again.
            for &(i, c) in &self.island_contacts {
                let now = c.relative_velocity(bodies).dot(&c.normal);
                let contact = &mut contacts[i as usize];
                let kick = contact.normal_velocity - contact.approach_velocity;
                contact.approach_velocity = now;
                contact.normal_velocity = now + kick;
            }
            for (p, &(start, end)) in self.pair_spans.iter().enumerate() {
                if self.bounced[p] {
                    for &(i, _) in &self.island_contacts[start..end] {
                        contacts[i as usize].restitution = 0.0;
                    }
                }
            }
        }
    }

    /// Runs `solve` on the island (it solves the rows and applies their impulses), holding
    /// its bounce to the energy the bodies brought (`solver::bounce`): if the answer has
    /// more, the island is solved again without a bounce and the two answers are mixed.
    fn solve_holding_bounce(
        &mut self,
        bodies: &mut [SolverBody],
        targets: &VelocityTargets,
        solve: fn(&mut Self, &mut [SolverBody], &VelocityTargets),
    ) {
        let (dt, below) = (targets.dt, targets.bounce_below);
        if !self
            .island_contacts
            .iter()
            .any(|(_, c)| c.bounces(dt, below))
        {
            solve(self, bodies, targets);
            return;
        }
        let contact_ends = self
            .island_contacts
            .iter()
            .map(|(_, c)| (c.body_a.0, c.body_b.0));
        let joint_ends = self.island_joints.iter().map(|j| (j.body_a, j.body_b));
        let ends = contact_ends.chain(joint_ends).flat_map(|(a, b)| [a, b]);
        self.before_bounce.keep(bodies, ends);
        let brought = self.before_bounce.kinetic_energy(bodies);
        solve(self, bodies, targets);
        self.full_bounce.keep_like(&self.before_bounce, bodies);
        let bounced = self.full_bounce.kinetic_energy(bodies);
        if !gains_energy(brought, bounced) {
            return;
        }
        self.x_full.clear();
        self.x_full.extend_from_slice(&self.x);
        self.before_bounce.restore(bodies);
        let inelastic = VelocityTargets {
            bounce_below: f64::INFINITY,
            ..*targets
        };
        solve(self, bodies, &inelastic);
        self.reports.pop(); // the island's report is the first solve's
        self.inelastic.keep_like(&self.before_bounce, bodies);
        // Where motors work, the solve without a bounce may leave more than was brought.
        let allowed = brought.max(self.inelastic.kinetic_energy(bodies));
        if !gains_energy(allowed, bounced) {
            self.full_bounce.restore(bodies);
            self.x.copy_from_slice(&self.x_full);
            return;
        }
        let s = bounce_share(&self.inelastic, &self.full_bounce, bodies, allowed);
        mix_velocities(&self.inelastic, &self.full_bounce, s, bodies);
        for (x, &full) in self.x.iter_mut().zip(&self.x_full) {
            *x += (full - *x) * s;
        }
    }

    /// Starting impulses for the rows from the last solve's, for contacts that persist.
    fn remember(&mut self) {
        self.guess.clear();
        for row in &self.rows {
            self.guess.push(match row.kind {
                RowKind::ContactNormal(i) => self.recalled[i as usize].0,
                RowKind::ContactTangent(i) => self.recalled[i as usize].1,
                RowKind::SharedTangent(i, j) => {
                    self.recalled[i as usize].1 + self.recalled[j as usize].1
                }
                _ => 0.0,
            });
        }
    }

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

    /// Groups contacts (and, if `with_joints`, joints) into islands: `ranges` of `grouped`.
    fn group(
        &mut self,
        contacts: &[Contact],
        joints: &[JointConstraint],
        with_joints: bool,
        bodies: &[SolverBody],
        moving: &[u32],
    ) {
        let nc = contacts.len();
        let joint_count = if with_joints { joints.len() } else { 0 };
        let ends = |i: usize| {
            if i < nc {
                (contacts[i].body_a.0, contacts[i].body_b.0)
            } else {
                (joints[i - nc].body_a, joints[i - nc].body_b)
            }
        };
        let grouped = self
            .grouping
            .group(nc + joint_count, bodies.len(), ends, moving);
        self.contact_count = nc;
        island_ranges(grouped, &mut self.ranges);
    }

    /// Copies island `island`'s contacts and joints into the island buffers.
    fn load_island(&mut self, island: usize, contacts: &[Contact], joints: &[JointConstraint]) {
        let (start, end) = self.ranges[island];
        let nc = self.contact_count;
        self.island_contacts.clear();
        self.island_joints.clear();
        self.joint_slots.clear();
        for &(_, item) in &self.grouping.grouped()[start..end] {
            let item = item as usize;
            if item < nc {
                self.island_contacts.push((item as u32, contacts[item]));
            } else {
                self.island_joints.push(joints[item - nc]);
                self.joint_slots.push((item - nc) as u32);
            }
        }
    }

    /// thesis §3.2.4: stage one finds frictionless normals, stage two solves normals and
    /// friction with friction bounded by ±μ·(stage-one normal).
    fn solve_two_stage(&mut self, bodies: &mut [SolverBody], targets: &VelocityTargets) {
        let frictionless = VelocityTargets {
            friction: false,
            ..*targets
        };
        velocity_rows(
            &self.island_contacts,
            &[],
            bodies,
            &frictionless,
            &mut self.rows,
        );
        self.solve_rows(bodies, false);
        std::mem::swap(&mut self.stage_one, &mut self.x);
        velocity_rows(&self.island_contacts, &[], bodies, targets, &mut self.rows);
        // Stage one's rows are stage two's normal rows, in order: each row's normal's
        // place among them.
        self.normal_ordinal.clear();
        let mut normals = 0;
        for row in &self.rows {
            self.normal_ordinal.push(normals);
            normals += usize::from(matches!(row.kind, RowKind::ContactNormal(_)));
        }
        for row in self.rows.iter_mut() {
            if let Some(f) = row.friction_of.take() {
                let bound = f.bound(|k| self.stage_one[self.normal_ordinal[k]]);
                (row.lo, row.hi) = (-bound, bound);
            }
        }
        self.solve_rows(bodies, true);
    }

    /// The island's impacts, body pair by body pair (`StepSettings::propagate_impacts`),
    /// instead of in the island's one LCP with everything else (the thesis's model, which
    /// shares an impulse through every contact at once: a Newton's cradle moves off as a
    /// block). An impact travels through bodies at rest in contact as a shock does: each pair
    /// with a point that meets fast enough to bounce is solved alone with the island's pins
    /// (normals, friction and pins in one small LCP), in order, sweep after sweep, until
    /// no pair bounces; then the pairs that bounced are marked as not bouncing, so that the
    /// simultaneous solve only holds them apart. A pair reflects its approach as it is when
    /// its turn comes, less this step's gravity kick (`Contact::approach_velocity`).
    fn propagate_impacts(
        &mut self,
        bodies: &mut [SolverBody],
        targets: &VelocityTargets,
        kick: Kick,
    ) {
        let (dt, bounce_below) = (targets.dt, targets.bounce_below);
        self.pair_spans.clear();
        self.bounced.clear();
        // Only where two moving bodies meet at speed; a body bouncing off a fixed one alone
        // passes nothing on, and is left to the simultaneous solve as before (a robot's feet
        // landing together, whose solve the pair-by-pair pass would change).
        if !self
            .island_contacts
            .iter()
            .any(|(_, c)| passes_on(c, bodies, targets))
        {
            return;
        }
        self.find_pair_spans();
        self.bounced.resize(self.pair_spans.len(), false);
        self.impact_joints.clear();
        self.impact_joints.extend(
            self.island_joints
                .iter()
                .map(|j| JointConstraint { motor: None, ..*j }),
        );
        if 2 * self.impact_joints.len() + 3 > self.dense_row_limit {
            return;
        }
        self.impact_impulses
            .resize(self.island_contacts.len(), (0.0, 0.0));
        let mut budget = IMPACT_SOLVES_PER_PAIR * self.pair_spans.len();
        'sweeps: loop {
            let mut any = false;
            for p in 0..self.pair_spans.len() {
                self.read_impact_pair(p, bodies, kick);
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
                if !self.solve_impact_pair(p, bodies, targets) {
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
            for (_, c) in &mut self.island_contacts[start..end] {
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

    /// Each body pair's span of `island_contacts` (a pair's points come one after another).
    fn find_pair_spans(&mut self) {
        let pair = |c: &Contact| (c.body_a, c.body_b);
        let mut k = 0;
        while k < self.island_contacts.len() {
            let first = pair(&self.island_contacts[k].1);
            let n = self.island_contacts[k..]
                .iter()
                .take_while(|(_, c)| pair(c) == first)
                .count();
            self.pair_spans.push((k, k + n));
            k += n;
        }
    }

    /// Pair `p`'s contacts into `impact_contacts` with their normal velocities as they are
    /// now, after the impacts already passed on.
    fn read_impact_pair(&mut self, p: usize, bodies: &[SolverBody], kick: Kick) {
        let (start, end) = self.pair_spans[p];
        self.impact_contacts.clear();
        for &(index, c) in &self.island_contacts[start..end] {
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
        p: usize,
        bodies: &mut [SolverBody],
        targets: &VelocityTargets,
    ) -> bool {
        let (start, end) = self.pair_spans[p];
        self.solve_impact_rows(bodies, targets);
        let ends = self.rows.iter().flat_map(|r| r.ends.iter().map(|e| e.body));
        self.before_bounce.keep(bodies, ends);
        let brought = self.before_bounce.kinetic_energy(bodies);
        for (row, &x) in self.rows.iter().zip(&self.x) {
            row.apply(bodies, x);
        }
        self.full_bounce.keep_like(&self.before_bounce, bodies);
        let bounced = self.full_bounce.kinetic_energy(bodies);
        if !bounced.is_finite() {
            self.before_bounce.restore(bodies);
            return false;
        }
        if gains_energy(brought, bounced) {
            // A face's two points, each reflecting its own approach, or a pair whose rows
            // contradict its pins (two pinned bodies that overlap and may collide): the
            // bounce is held to what the pair brought (`solver::bounce`).
            self.x_full.clear();
            self.x_full.extend_from_slice(&self.x);
            self.before_bounce.restore(bodies);
            let inelastic = VelocityTargets {
                bounce_below: f64::INFINITY,
                ..*targets
            };
            self.solve_impact_rows(bodies, &inelastic);
            for (row, &x) in self.rows.iter().zip(&self.x) {
                row.apply(bodies, x);
            }
            self.inelastic.keep_like(&self.before_bounce, bodies);
            let allowed = brought.max(self.inelastic.kinetic_energy(bodies));
            let s = bounce_share(&self.inelastic, &self.full_bounce, bodies, allowed);
            mix_velocities(&self.inelastic, &self.full_bounce, s, bodies);
            for (x, &full) in self.x.iter_mut().zip(&self.x_full) {
                *x += (full - *x) * s;
            }
        }
        for (row, &x) in self.rows.iter().zip(&self.x) {
            let local = |i: u32| {
                self.island_contacts[start..end]
                    .iter()
                    .position(|&(index, _)| index == i)
                    .map(|k| start + k)
            };
            match row.kind {
                RowKind::ContactNormal(i) => {
                    if let Some(k) = local(i) {
                        self.impact_impulses[k].0 += x;
                    }
                }
                RowKind::ContactTangent(i) | RowKind::SharedTangent(i, _) => {
                    if let Some(k) = local(i) {
                        self.impact_impulses[k].1 += x;
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
        self.guess.clear();
        self.solve_rows_dense(bodies);
    }

    fn solve_coupled(&mut self, bodies: &mut [SolverBody], targets: &VelocityTargets) {
        velocity_rows(
            &self.island_contacts,
            &self.island_joints,
            bodies,
            targets,
            &mut self.rows,
        );
        self.remember();
        self.solve_rows(bodies, true);
        self.guess.clear();
    }

    /// Solves the current rows and, if `apply`, applies their impulses. Islands up to
    /// `dense_row_limit` rows are solved by pivoting on the dense matrix, bigger ones by
    /// Gauss–Seidel row by row.
    fn solve_rows(&mut self, bodies: &mut [SolverBody], apply: bool) {
        let n = self.rows.len();
        let pivoting = n <= self.dense_row_limit;
        let (pivots, residual, over_budget, fell_back) = if pivoting {
            let stats = self.solve_rows_dense(bodies);
            let fell_back = stats.method == LcpMethod::ProjectedGaussSeidel;
            (stats.pivots, stats.residual, stats.over_budget, fell_back)
        } else {
            (self.solve_rows_sparse(bodies), f64::NAN, false, false)
        };
        if over_budget {
            let ends = self.rows.iter().flat_map(|r| r.ends.iter().map(|e| e.body));
            self.over_budget_bodies.extend(ends);
        }
        if apply {
            for (row, &x) in self.rows.iter().zip(&self.x) {
                row.apply(bodies, x);
            }
            self.reports.push(IslandReport {
                contacts: self.island_contacts.len(),
                joints: self.island_joints.len(),
                rows: n,
                method: if pivoting && !fell_back {
                    IslandMethod::Pivoting
                } else {
                    IslandMethod::GaussSeidel
                },
                pivots,
                over_budget,
                residual,
            });
        }
    }

    /// The boxed LCP of the rows, assembled densely and solved by pivoting, into `x`.
    fn solve_rows_dense(&mut self, bodies: &[SolverBody]) -> LcpStats {
        assemble(&self.rows, bodies, &mut self.a);
        self.b.clear();
        self.lo.clear();
        self.hi.clear();
        self.friction_index.clear();
        for r in &self.rows {
            self.b.push(r.b);
            self.lo.push(r.lo);
            self.hi.push(r.hi);
            self.friction_index.push(r.friction_of);
        }
        let problem = LcpProblem {
            n: self.rows.len(),
            a: &self.a,
            b: &self.b,
            lo: &self.lo,
            hi: &self.hi,
            friction_index: Some(&self.friction_index),
            regularisation: self.regularisation,
        };
        self.lcp.solve_guessing(&problem, &self.guess, &mut self.x)
    }

    /// Projected Gauss–Seidel on the rows themselves, for islands too big for a dense
    /// matrix: each row's velocity is read from the bodies as the impulses accumulate, so
    /// a sweep costs O(rows), not O(rows²). Leaves the impulses in `x` (the bodies are not
    /// changed) and returns the sweeps made.
    fn solve_rows_sparse(&mut self, bodies: &[SolverBody]) -> usize {
        const SWEEPS: usize = 200;
        let n = self.rows.len();
        self.x.clear();
        self.x.resize(n, 0.0);
        // Scratch velocities of the island's bodies only.
        let scratch = &mut self.sparse_bodies;
        scratch.resize(bodies.len(), SolverBody::default());
        for row in &self.rows {
            for e in &row.ends {
                scratch[e.body as usize] = bodies[e.body as usize];
            }
        }
        if self.guess.len() == n {
            for (k, row) in self.rows.iter().enumerate() {
                if self.guess[k] != 0.0 {
                    row.apply(scratch, self.guess[k]);
                    self.x[k] = self.guess[k];
                }
            }
        }
        // w_i = (row velocity now) + offset_i, where offset_i = b_i − (velocity at start).
        self.b.clear();
        self.diagonals.clear();
        for row in &self.rows {
            self.b.push(row.b - row.velocity(bodies));
            self.diagonals.push(row.diagonal(bodies));
        }
        let mut sweeps = 0;
        while sweeps < SWEEPS {
            sweeps += 1;
            let mut change: f64 = 0.0;
            let mut size: f64 = 0.0;
            for i in 0..n {
                let row = &self.rows[i];
                let diagonal = self.diagonals[i];
                if diagonal <= 0.0 {
                    continue;
                }
                let (lo, hi) = match row.friction_of {
                    Some(f) => {
                        let bound = f.bound(|k| self.x[k]);
                        (-bound, bound)
                    }
                    None => (row.lo, row.hi),
                };
                let w = row.velocity(scratch) + self.b[i];
                let new = clamp(self.x[i] - w / diagonal, lo, hi);
                let delta = new - self.x[i];
                if delta != 0.0 {
                    row.apply(scratch, delta);
                    self.x[i] = new;
                }
                change = change.max((delta * diagonal.sqrt()).abs());
                size = size.max((new * diagonal.sqrt()).abs());
            }
            if change <= 1e-10 * size.max(1e-300) {
                break;
            }
        }
        sweeps
    }

    /// Records the impulses in the contacts and joints they belong to.
    fn write_back(&mut self, contacts: &mut [Contact], joints: &mut [JointConstraint]) {
        for (row, &x) in self.rows.iter().zip(&self.x) {
            match row.kind {
                RowKind::ContactNormal(i) => contacts[i as usize].normal_impulse = x,
                RowKind::ContactTangent(i) => contacts[i as usize].tangent_impulse = x,
                RowKind::SharedTangent(i, j) => {
                    // Shared as the normals are (halves when neither pushes).
                    let (i, j) = (i as usize, j as usize);
                    let (n_i, n_j) = (contacts[i].normal_impulse, contacts[j].normal_impulse);
                    let share = if n_i + n_j > 0.0 {
                        n_i / (n_i + n_j)
                    } else {
                        0.5
                    };
                    contacts[i].tangent_impulse = x * share;
                    contacts[j].tangent_impulse = x - x * share;
                }
                RowKind::JointMotor(k) => {
                    let slot = self.joint_slots[k as usize] as usize;
                    if let Some(m) = joints[slot].motor.as_mut() {
                        m.last_impulse = x;
                    }
                }
                RowKind::JointX(k) => {
                    joints[self.joint_slots[k as usize] as usize].impulse.x += x;
                }
                RowKind::JointY(k) => {
                    joints[self.joint_slots[k as usize] as usize].impulse.y += x;
                }
            }
        }
        // What the impact pass gave a contact is part of its impulse this step.
        for (&(i, _), &(normal, tangent)) in self.island_contacts.iter().zip(&self.impact_impulses)
        {
            contacts[i as usize].normal_impulse += normal;
            contacts[i as usize].tangent_impulse += tangent;
        }
    }
}

/// Whether contact `c` bounces this step between two moving bodies: an impact that may
/// pass on through the bodies at rest in contact with them.
fn passes_on(c: &Contact, bodies: &[SolverBody], targets: &VelocityTargets) -> bool {
    let moves = |i: u32| bodies[i as usize].moves();
    c.bounces(targets.dt, targets.bounce_below) && moves(c.body_a.0) && moves(c.body_b.0)
}
