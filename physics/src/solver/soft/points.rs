//! The step's contact points, built island by island from the contacts with their last
//! impulses recalled, each manifold placed in its lane or written; and the plan made
//! from the contacts before the points, where it changed last step.

use super::SoftStepSolver;
use super::batch::PlanInput;
use super::constraints::{NormalBlock, PointConstraint, PointLevers, row_coupling};
use super::contact_lcp::LCP_POINT_LIMIT;
use crate::math::Vec2;
use crate::solver::SolverBody;
use crate::solver::contact::Contact;
use crate::solver::island::{IslandGrouping, island_ranges};

/// The contacts' islands as `build_points` takes them: `(island, contact)` pairs
/// (`IslandGrouping::grouped`), and, where they were taken unchecked, the bodies of the
/// contacts they grouped, by contact (`IslandGrouping::ends`).
type ContactGrouping<'a> = (&'a [(u32, u32)], Option<&'a [(u32, u32)]>);

/// The contact after the `k`-th of `grouped`, if it is the same manifold's second point:
/// it joins the same bodies along the same normal. (A manifold's points share their
/// bodies, so their island.)
fn second_point_of(contacts: &[Contact], grouped: &[(u32, u32)], k: usize) -> Option<u32> {
    let c = &contacts[grouped[k].1 as usize];
    grouped.get(k + 1).map(|&(_, j)| j).filter(|&j| {
        let d = &contacts[j as usize];
        (d.body_a, d.body_b, d.normal) == (c.body_a, c.body_b, c.normal)
    })
}

/// `build_points`' answer when a contact joins other bodies than the grouping it was
/// given says.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct ContactsRegrouped;

/// What `build_points` carries from point to point as it reads the contacts.
struct Reading<'a> {
    recall: Recall,
    /// The bodies of the contacts that the grouping taken unchecked grouped, by contact.
    unchecked_ends: Option<&'a [(u32, u32)]>,
    /// Whether a contact joins other bodies than those.
    regrouped: bool,
}

/// How `build_points` finds the last step's impulses: guessing each contact's entry at
/// (or beside) its own index until a guess misses, then from all of them recalled at once.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Recall {
    Guessing,
    AllRecalled,
}
impl SoftStepSolver {
    /// Plans the passes before the points are built (`PassPlan::plan_before_points`),
    /// from the manifolds' entries read off the contacts in the order of `grouped`, as
    /// `build_points` notes them: a contact and the next are one manifold if they join
    /// the same bodies along the same normal and their 2 × 2 block is well conditioned
    /// (found from their levers alone). Kept in `planned_inputs`, which the points'
    /// entries must equal. Not if a contact may bounce (restitution reads every point, so
    /// they are written anyway): then false, and nothing is planned.
    pub(super) fn plan_from_contacts(
        &mut self,
        bodies: &[SolverBody],
        contacts: &[Contact],
        grouped: &[(u32, u32)],
    ) -> bool {
        self.planned_inputs.clear();
        let mut k = 0;
        while k < grouped.len() {
            let c = &contacts[grouped[k].1 as usize];
            if c.restitution != 0.0 {
                return false;
            }
            let moves = |i: u32| self.loaded.bodies[i as usize].moves();
            let mut input = PlanInput::new(
                (c.body_a.0, c.body_b.0),
                k,
                (moves(c.body_a.0), moves(c.body_b.0)),
                c.normal,
            );
            let second = second_point_of(contacts, grouped, k);
            if second.is_some_and(|j| contacts[j as usize].restitution != 0.0) {
                return false;
            }
            let coupled = second.is_some_and(|j| {
                let pair = (
                    &self.loaded.bodies[c.body_a.index()],
                    &self.loaded.bodies[c.body_b.index()],
                );
                let (p, q) = (
                    PointLevers::of(bodies, c),
                    PointLevers::of(bodies, &contacts[j as usize]),
                );
                NormalBlock::of_levers(pair, (p.normal, q.normal)).is_some()
            });
            if coupled {
                input.add_second_point();
                k += 2;
            } else {
                k += 1;
            }
            self.planned_inputs.push(input);
        }
        let ends = |k: usize| {
            let c = &contacts[grouped[k].1 as usize];
            (c.body_a.0, c.body_b.0)
        };
        self.contact_lcp
            .classify(&self.loaded.bodies, &self.contact_islands, ends);
        self.plan.read(
            &self.contact_lcp.all_islands,
            &self.planned_inputs,
            &self.loaded.pinned,
        );
        self.plan
            .plan_before_points(contacts.len(), &self.loaded.bodies);
        true
    }

    /// Groups the contacts by island afresh (`grouping`), and notes each island's range.
    pub(super) fn group_contacts(&mut self, grouping: &mut IslandGrouping, contacts: &[Contact]) {
        let grouped = grouping.group(
            contacts.len(),
            self.loaded.bodies.len() - 1, // not the null body
            |i| (contacts[i].body_a.0, contacts[i].body_b.0),
            &self.loaded.moving,
        );
        island_ranges(grouped, &mut self.contact_islands);
    }

    with_fma_where_present! {
        /// The contacts' points, in the order of `grouped` (island by island), their
        /// manifolds' entries for the plan (`plan_inputs`), and `may_bounce`. A manifold
        /// that goes into the kept plan's lanes (`PassPlan::fill_manifold`) is not written
        /// to `points`, unless its island is small enough to be solved as an LCP (which
        /// reads its points): its entries there are left from an earlier step. Returns
        /// whether any was left so. Such entries are read only by a changed plan and where
        /// something may bounce (restitution, and the impulses stored from the points), and
        /// `prepare` then builds the points again, with the filling stopped.
        ///
        /// With `unchecked_ends` (the ends of the contacts that `grouped` grouped, by
        /// contact), each contact's bodies are checked against them as its point is built,
        /// and one that differs stops the building at its island's end: the grouping is not
        /// this step's.
        pub(super) fn build_points, build_points_with_fma => build_points_inline(
            &mut self,
            bodies: &[SolverBody],
            accelerations: &[(Vec2, f64)],
            contacts: &[Contact],
            grouping: ContactGrouping,
            dt: f64,
        ) -> Result<bool, ContactsRegrouped>;
    }

    #[inline(always)]
    fn build_points_inline(
        &mut self,
        bodies: &[SolverBody],
        accelerations: &[(Vec2, f64)],
        contacts: &[Contact],
        (grouped, unchecked_ends): ContactGrouping,
        dt: f64,
    ) -> Result<bool, ContactsRegrouped> {
        if self.points.len() < contacts.len() {
            self.points
                .resize(contacts.len(), PointConstraint::default());
        }
        self.points.truncate(contacts.len());
        self.plan_inputs.clear();
        self.may_bounce = false;
        let mut reading = Reading {
            recall: Recall::Guessing,
            unchecked_ends,
            regrouped: false,
        };
        let mut skipped = false;
        // A point built already that begins the next manifold: the second of two
        // whose block was not well conditioned.
        let mut carried: Option<PointConstraint> = None;
        // The island of the current point: where it ends, and whether it may be an LCP
        // island (`ContactLcp::prepare`), which reads its points.
        let (mut island, mut island_end, mut small_island) = (0, 0, true);
        let mut k = 0;
        while k < grouped.len() {
            if k == island_end {
                if reading.regrouped {
                    return Err(ContactsRegrouped);
                }
                let (start, end) = self.contact_islands[island];
                (island, island_end, small_island) =
                    (island + 1, end, end - start <= LCP_POINT_LIMIT);
            }
            let c = &contacts[grouped[k].1 as usize];
            let mut first = match carried.take() {
                Some(p) => p,
                None => self.build_point(
                    bodies,
                    accelerations,
                    contacts,
                    grouped[k].1,
                    dt,
                    &mut reading,
                ),
            };
            // The two are coupled if their block is well conditioned.
            let second = second_point_of(contacts, grouped, k)
                .map(|j| self.build_point(bodies, accelerations, contacts, j, dt, &mut reading));
            let block = second.as_ref().and_then(|q| {
                let pair = (
                    &self.loaded.bodies[c.body_a.index()],
                    &self.loaded.bodies[c.body_b.index()],
                );
                NormalBlock::of(pair, (&first, q))
            });
            let moves = |i: u32| self.loaded.bodies[i as usize].moves();
            let mut input = PlanInput::new(
                (c.body_a.0, c.body_b.0),
                k,
                (moves(c.body_a.0), moves(c.body_b.0)),
                c.normal,
            );
            if let (Some(block), Some(q)) = (block, second) {
                first.pair_coupling = Some(block);
                input.add_second_point();
                self.plan_inputs.push(input);
                skipped |= self.place_manifold(k, [first, q], small_island);
                k += 2;
            } else {
                self.plan_inputs.push(input);
                skipped |= self.place_manifold(k, [first], small_island);
                carried = second;
                k += 1;
            }
        }
        if reading.regrouped {
            return Err(ContactsRegrouped);
        }
        Ok(skipped)
    }

    /// The point of contact `i` (this step's contacts' index), its impulses recalled from
    /// the last step.
    #[inline(always)]
    fn build_point(
        &mut self,
        bodies: &[SolverBody],
        accelerations: &[(Vec2, f64)],
        contacts: &[Contact],
        i: u32,
        dt: f64,
        reading: &mut Reading,
    ) -> PointConstraint {
        let c = &contacts[i as usize];
        if let Some(ends) = reading.unchecked_ends {
            // Noted, not branched on: the building stops at the island's end.
            reading.regrouped |= ends[i as usize] != (c.body_a.0, c.body_b.0);
        }
        let recall = &mut reading.recall;
        let (a, b) = (&bodies[c.body_a.index()], &bodies[c.body_b.index()]);
        let levers = PointLevers::of(bodies, c);
        // A row's effective mass, 1 / (m_a⁻¹ + m_b⁻¹ + I_a⁻¹ l_a² + I_b⁻¹ l_b²).
        let mass = |levers: (f64, f64)| {
            let inertias = (a.inv_inertia, b.inv_inertia);
            let k = row_coupling(a.inv_mass + b.inv_mass, inertias, levers, levers);
            if k > 0.0 { 1.0 / k } else { 0.0 }
        };
        // A pile at rest has the same contacts in the same order, each its entry at its
        // own index or beside it (`ContactMemory::guess`); at the first that is not,
        // every contact's impulses are recalled at once, in the contacts' order, which
        // the memory's follows (the points are built in the islands').
        let guessed = match recall {
            Recall::Guessing => self.memory.guess(i as usize, c),
            Recall::AllRecalled => None,
        };
        let (normal_impulse, tangent_impulse) = guessed.unwrap_or_else(|| {
            if *recall == Recall::Guessing {
                self.memory.recall(contacts, &mut self.recalled);
                *recall = Recall::AllRecalled;
            }
            self.recalled[i as usize]
        });
        self.may_bounce |= c.restitution != 0.0;
        // Read only for points that may bounce (`approach`).
        let closing_acceleration = if c.restitution == 0.0 {
            0.0
        } else {
            -(accelerations[c.body_a.index()].0 - accelerations[c.body_b.index()].0).dot(&c.normal)
        };
        PointConstraint {
            contact: i,
            a: c.body_a.0,
            b: c.body_b.0,
            normal: c.normal,
            levers,
            base_separation: -c.depth,
            normal_mass: mass(levers.normal),
            tangent_mass: mass(levers.tangent()),
            friction: c.friction,
            restitution: c.restitution,
            relative_velocity: c.approach_velocity,
            normal_impulse,
            tangent_impulse,
            max_normal_impulse: 0.0,
            closing_acceleration,
            fastest_impact: c.approach_velocity - closing_acceleration.max(0.0) * dt,
            pair_coupling: None,
        }
    }

    /// A complete manifold whose first point is `first`: into its lane in the kept plan,
    /// or else written to the points. Returns whether it was left unwritten (see
    /// `build_points`); a small island's always is written, for the LCP.
    #[inline(always)]
    fn place_manifold<const N: usize>(
        &mut self,
        first: usize,
        manifold: [PointConstraint; N],
        small: bool,
    ) -> bool {
        let in_lane = self
            .plan
            .fill_manifold(first, &manifold, &self.loaded.bodies);
        let small = small || self.write_every_point;
        if in_lane && !small {
            return true;
        }
        for (j, p) in manifold.into_iter().enumerate() {
            self.points[first + j] = p;
        }
        false
    }
}
