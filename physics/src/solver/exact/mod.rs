//! The exact solver (`exact`, `thesis`, and `auto`'s exact islands): simultaneous impulses
//! (thesis §2.4.6, §3.2), island by island, as one boxed LCP: the thesis's two-stage
//! friction, or the coupled model that solves normals, friction, pins and joint motors
//! together, with friction bounds that follow the normal impulses. Its rows (`system`),
//! the depth's position pass (`separation`), and the impulse stage list's passes over the
//! pins (`joint_block`, with `pin_island`) are its parts; the impact pass before each
//! island's LCP is the world's (`solver::impacts`).

pub(crate) mod joint_block;
mod pin_island;
mod separation;
pub(crate) mod system;

use super::bounce::{BounceGuard, gains_energy};
use super::contact::{Contact, ContactMemory};
use super::impacts::{ImpactPass, Kick};
use super::island::{IslandGrouping, island_ranges};
use super::joint::JointConstraint;
use super::lcp::{LcpMethod, LcpStats, REGULARISATION};
use super::report::{IslandMethod, IslandReport};
use super::{BodiesAndMoving, SolverBody};
use crate::math::clamp;
use system::{DenseRowsLcp, Row, RowKind, VelocityTargets, velocity_rows};

/// Islands with more rows than this are solved by projected Gauss–Seidel instead of the
/// dense pivoting method, whose cost grows as n³. Measured by `examples/dense_threshold.rs`
/// (README, Physics): where the pivoting solve starts costing more than the whole rest of
/// a step.
pub(crate) const DENSE_ROW_LIMIT: usize = 96;

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
    dense: DenseRowsLcp,
    /// Each row's velocity target less its velocity, for the row-by-row Gauss–Seidel.
    b: Vec<f64>,
    x: Vec<f64>,
    pub reports: Vec<IslandReport>,
    /// The bodies of the islands that went over the pivot budget in the last solve.
    pub over_budget_bodies: Vec<u32>,
    /// The LCP's regularisation for the rows being solved (`lcp::LcpProblem`).
    regularisation: f64,
    /// `StepSettings::dense_row_limit`, copied in before each solve.
    pub dense_row_limit: usize,
    /// `StepSettings::propagate_impacts`, copied in before each solve.
    pub propagate_impacts: bool,
    /// A bouncing solve's bodies' velocities before it, after it, and after the same
    /// solve without a bounce, with the bouncing answer's impulses (`bounce`).
    bounce: BounceGuard,
}

impl SimultaneousSolver {
    /// Solves every island and applies the impulses to `bodies`; contacts get their normal
    /// and tangent impulses, joints with motors their motor impulse. Under the coupled
    /// model each island's impacts pass on first (`impacts`). With `TwoStage`,
    /// joints are left to the joint passes, as in the thesis. `moving`: the slots of the
    /// bodies that move, increasing (every other body of `bodies` is fixed).
    pub(crate) fn solve(
        &mut self,
        model: FrictionModel,
        contacts: &mut [Contact],
        joints: &mut [JointConstraint],
        (bodies, moving): BodiesAndMoving<'_>,
        targets: &VelocityTargets,
        impacts: &mut ImpactPass,
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
            impacts.impulses.clear();
            match model {
                FrictionModel::TwoStage => {
                    self.solve_holding_bounce(bodies, targets, Self::solve_two_stage)
                }
                FrictionModel::Coupled => {
                    if self.propagate_impacts {
                        impacts.dense_row_limit = self.dense_row_limit;
                        let contacts = &mut self.island_contacts;
                        impacts.on_island(
                            contacts,
                            &self.island_joints,
                            bodies,
                            targets,
                            Kick::Applied,
                        );
                    }
                    self.solve_holding_bounce(bodies, targets, Self::solve_coupled);
                }
            }
            self.write_back(contacts, joints, &impacts.impulses);
        }
        self.memory.store(contacts);
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
        let brought = self.bounce.before(bodies, ends);
        solve(self, bodies, targets);
        let bounced = self.bounce.bounced(bodies);
        if !gains_energy(brought, bounced) {
            return;
        }
        self.bounce.undo_bounce(bodies, &self.x);
        solve(self, bodies, &targets.without_bounce());
        self.reports.pop(); // the island's report is the first solve's
        self.bounce.hold(bodies, brought, bounced, &mut self.x);
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
        let regularisation = self.regularisation;
        (self.dense).solve(&self.rows, bodies, regularisation, &self.guess, &mut self.x)
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
    fn write_back(
        &mut self,
        contacts: &mut [Contact],
        joints: &mut [JointConstraint],
        impact_impulses: &[(f64, f64)],
    ) {
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
        for (&(i, _), &(normal, tangent)) in self.island_contacts.iter().zip(impact_impulses) {
            contacts[i as usize].normal_impulse += normal;
            contacts[i as usize].tangent_impulse += tangent;
        }
    }
}
