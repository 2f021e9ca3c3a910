//! `auto`: each island goes to `exact` or to the soft step, each solver's pass moving
//! its part of the awake set and holding the other's bodies still (`BodySets`).

use super::World;
use crate::collide::Manifold;
use crate::solver::ImpulseMethod;
use crate::solver::contact::Contact;
use crate::solver::island::UnionFind;
use crate::solver::report::IslandReport;

/// Seconds an island that went over the exact solver's pivot budget stays on the soft
/// step under `auto`.
const SOFT_AFTER_OVER_BUDGET: f64 = 1.0;

/// What `auto` keeps from step to step.
#[derive(Debug, Clone, Default)]
pub(super) struct AutoMemory {
    /// Per body: the step until which its island stays on the soft step
    /// (`keep_over_budget_on_soft`).
    soft_until: Vec<u64>,
    /// The last split of the islands, reused while what it is made from stands.
    last_marking: LastMarking,
    /// How the last step's islands were solved, by both passes (`World::island_reports`).
    pub(super) reports: Vec<IslandReport>,
}

/// What `auto`'s last marking of soft islands was made from, and what it found: a pile
/// at rest gives the same step after step (`World::mark_soft_islands`).
#[derive(Debug, Clone, Default)]
pub(super) struct LastMarking {
    links: Vec<(u32, u32, usize)>,
    candidates: Vec<(u32, u32)>,
    fixed: Vec<bool>,
    row_limit: usize,
    prefer_soft: Vec<bool>,
    /// Per slot: whether the body is a moving one in an island of the soft step's.
    in_soft_island: Vec<bool>,
    /// `(exact, soft)`: whether some moving body is in an exact island, some in a soft
    /// one.
    found: Option<(bool, bool)>,
}

/// `auto`'s buffers, reused from step to step: the islands' links, union-find, row
/// counts and needs, the bodies kept on the soft step this step, and the exact pass's
/// contacts and manifolds while the soft pass runs.
#[derive(Debug, Clone, Default)]
pub(super) struct AutoScratch {
    links: Vec<(u32, u32, usize)>,
    island_union: UnionFind,
    island_rows: Vec<usize>,
    island_needs: Vec<IslandNeeds>,
    /// Per body: whether it is kept on the soft step this step (`AutoMemory::soft_until`).
    prefer_soft: Vec<bool>,
    exact_contacts: Vec<Contact>,
    exact_manifolds: Vec<Manifold>,
}

/// What an island holds that decides whether `auto` solves it exactly.
#[derive(Debug, Clone, Copy)]
struct IslandNeeds {
    /// A pin or a motor.
    jointed: bool,
    /// The heaviest and the lightest moving body's inverse mass (the smallest and the
    /// largest).
    inverse_masses: (f64, f64),
    /// A body that went over the exact solver's pivot budget lately.
    prefers_soft: bool,
}

impl Default for IslandNeeds {
    fn default() -> Self {
        Self {
            jointed: false,
            inverse_masses: (f64::INFINITY, 0.0),
            prefers_soft: false,
        }
    }
}

/// Moving bodies whose masses differ this much make an island `auto` solves exactly: the
/// soft step's Gauss–Seidel passes carry a heavy body's weight down a light one slowly.
const EXACT_MASS_RATIO: f64 = 10.0;

impl IslandNeeds {
    /// A robot stays exact whatever its pivots cost: the budget bounds each step's, and
    /// the soft step would let its pins give.
    fn kept_on_soft(&self) -> bool {
        self.prefers_soft && !self.jointed
    }

    fn exact_needed(&self) -> bool {
        let (heaviest, lightest) = self.inverse_masses;
        self.jointed || (heaviest > 0.0 && lightest >= EXACT_MASS_RATIO * heaviest)
    }
}

/// The most moving bodies of its own size a moving body collides with at once, the
/// nearest first; a smaller one counts as the fraction of one that its bounding radius is
/// of the body's, so a large body meets as many small ones as fit along it. Bodies
/// dropped onto one spot (2,000 boxes placed at one point: two million pairs, 2.5 GB of
/// contacts) collide with their nearest so many and pass through the rest until they
/// have parted. No scene of bodies that merely touch comes near it (a box in a pyramid
/// has eight neighbours); where bodies move fast among many, as the benchmark's smash's
/// block of 0.5 m boxes struck at 40 m/s, the pairs dropped are those farthest off, which
impl World {
    /// `auto`: each island goes to `exact` or to the soft step (`mark_soft_islands`).
    /// Each solver's pass holds the other's bodies still. Islands are joined by the broad
    /// phase's candidate pairs of this step, not only by last step's contacts, so bodies
    /// that can touch during the step are in one pass: a box falling onto a pile joins
    /// the pile's pass before it lands: solved in two passes, each would meet the other as
    /// a fixed body, and the landing would not conserve momentum. Contacts and island
    /// reports of both passes are kept.
    pub(super) fn step_auto(&mut self, dt: f64) {
        let (exact, soft) = self.mark_soft_islands(dt);
        if !soft {
            self.step_impulses(ImpulseMethod::Exact, dt);
            self.keep_over_budget_on_soft(dt);
            self.auto.reports.clone_from(&self.solvers.exact.reports);
            return;
        }
        if !exact {
            // No body is held and none has moved: the soft step's broad phase would find
            // the candidate pairs just found.
            self.scratch.candidates_current = true;
            self.step_soft(dt);
            self.auto.reports.clone_from(&self.solvers.soft.reports);
            return;
        }
        self.hold_where(true);
        self.step_impulses(ImpulseMethod::Exact, dt);
        self.release_held();
        self.keep_over_budget_on_soft(dt);
        let s = &mut self.scratch.auto;
        std::mem::swap(&mut s.exact_contacts, &mut self.contacts);
        std::mem::swap(&mut s.exact_manifolds, &mut self.manifolds);
        self.hold_where(false);
        self.step_soft(dt);
        self.release_held();
        let s = &mut self.scratch.auto;
        self.auto.reports.clone_from(&self.solvers.exact.reports);
        self.auto
            .reports
            .extend_from_slice(&self.solvers.soft.reports);
        // A pair across the two passes (bodies that moved beyond their reach, as gravity
        // adds to the speed the reach was measured with) was found by both: keep the exact
        // pass's.
        let exact_pairs = &s.exact_manifolds;
        let seen = |a: u32, b: u32| {
            exact_pairs
                .binary_search_by(|m| (m.body_a.0, m.body_b.0).cmp(&(a, b)))
                .is_ok()
        };
        self.contacts.retain(|c| !seen(c.body_a.0, c.body_b.0));
        self.manifolds.retain(|m| !seen(m.body_a.0, m.body_b.0));
        self.contacts.splice(0..0, s.exact_contacts.drain(..));
        self.manifolds.splice(0..0, s.exact_manifolds.drain(..));
    }

    /// Marks each moving body whose island the soft step takes (`auto`). An island goes to
    /// `exact` where exact pivoting is both needed and fast: it holds a pin or a motor, or
    /// moving bodies whose masses differ tenfold (a robot, a heavy box on light ones),
    /// it has at most `dense_row_limit` LCP rows, and (unless it is a robot) none of its
    /// bodies went over the pivot budget within the last second. A pile of like bodies
    /// goes to the soft step, as accurate there at a fraction of the cost.
    ///
    /// Islands are joined by the last step's contacts, the joints and this step's candidate
    /// pairs. Rows: two per pin, one per motor, and the larger of two per contact point of
    /// the last step and two per candidate pair (one point each), so that a pile is big
    /// from its first step, before any contact is known. Returns whether some moving body
    /// is in an exact island and whether some is in a soft one.
    fn mark_soft_islands(&mut self, dt: f64) -> (bool, bool) {
        self.find_candidate_pairs(dt);
        let n = self.bodies.len();
        let bodies = &self.bodies;
        let moving = |i: u32| bodies[i as usize].as_ref().is_some_and(|b| !b.is_fixed());
        let (pairs, s) = (&self.scratch.pairs, &mut self.scratch.auto);
        let mut links: Vec<(u32, u32, usize)> = std::mem::take(&mut s.links);
        links.clear();
        links.extend(self.contacts.iter().map(|c| (c.body_a.0, c.body_b.0, 2)));
        let contact_links = links.len();
        for j in self.joints.iter().flatten() {
            let rows = 2 + usize::from(j.motor.is_some_and(|m| m.enabled));
            let b = j.body_b.map_or(j.body_a.0, |h| h.0);
            links.push((j.body_a.0, b, rows));
        }
        // A body motor is a link of the body to itself: no rows, but its island is a
        // robot's.
        links.extend(self.body_motors.iter().map(|(h, _)| (h.0, h.0, 0)));
        let soft_until = &self.auto.soft_until;
        let step = self.step_count;
        s.prefer_soft.clear();
        s.prefer_soft
            .extend((0..n).map(|i| soft_until.get(i).is_some_and(|&until| until > step)));
        // The marking is a function of its links, candidates, fixed bodies, limit and the
        // bodies kept on the soft step alone (the fixed ones are `KeptPairs::fixed`: no
        // body is held between passes): the same inputs, the same marks, without the
        // union-find.
        let limit = self.settings.dense_row_limit;
        let last = &self.auto.last_marking;
        if let Some(marked) = last.found
            && (&last.links, &last.candidates, &last.fixed, last.row_limit)
                == (&links, pairs, &self.kept_pairs.fixed, limit)
            && last.prefer_soft == s.prefer_soft
        {
            s.links = links;
            self.stats.auto_splits_kept += 1;
            return marked;
        }
        s.island_union.reset(n);
        let candidates = pairs.iter().map(|&(a, b)| (a, b, 0));
        for (a, b, _) in links.iter().copied().chain(candidates) {
            if moving(a) && moving(b) {
                s.island_union.union(a, b);
            }
        }
        // Per root, two counts: pins, motors and last step's contacts; pins, motors and
        // candidate pairs. (`links` lists the contacts first, then the joints and motors.)
        s.island_rows.clear();
        s.island_rows.resize(2 * n, 0);
        let counted = links.iter().enumerate().map(|(k, &(a, b, rows))| {
            let columns = if k < contact_links { 0..1 } else { 0..2 };
            (a, b, rows, columns)
        });
        let candidates = pairs.iter().map(|&(a, b)| (a, b, 2, 1..2));
        for (a, b, rows, columns) in counted.chain(candidates) {
            let end = if moving(a) { a } else { b };
            if moving(end) {
                let root = s.island_union.find(end) as usize;
                for column in columns {
                    s.island_rows[column * n + root] += rows;
                }
            }
        }
        // Per root: whether a pin or motor is in it, and its moving bodies' lightest and
        // heaviest inverse masses.
        s.island_needs.clear();
        s.island_needs.resize(n, IslandNeeds::default());
        for &(a, b, _) in &links[contact_links..] {
            let end = if moving(a) { a } else { b };
            if moving(end) {
                let root = s.island_union.find(end) as usize;
                s.island_needs[root].jointed = true;
            }
        }
        for i in 0..n as u32 {
            if let Some(body) = bodies[i as usize].as_ref().filter(|b| !b.is_fixed()) {
                let root = s.island_union.find(i) as usize;
                let needs = &mut s.island_needs[root];
                needs.inverse_masses.0 = needs.inverse_masses.0.min(body.inv_mass);
                needs.inverse_masses.1 = needs.inverse_masses.1.max(body.inv_mass);
                needs.prefers_soft |= s.prefer_soft[i as usize];
            }
        }
        s.links = links;
        let last = &mut self.auto.last_marking;
        last.in_soft_island.clear();
        let (mut exact, mut soft) = (false, false);
        for i in 0..n as u32 {
            let root = s.island_union.find(i) as usize;
            let rows = s.island_rows[root].max(s.island_rows[n + root]);
            let needs = &s.island_needs[root];
            let goes_exact = needs.exact_needed() && rows <= limit && !needs.kept_on_soft();
            let in_soft = moving(i) && !goes_exact;
            last.in_soft_island.push(in_soft);
            soft |= in_soft;
            exact |= moving(i) && goes_exact;
        }
        // The last links go back to be the buffer for the next marking's.
        std::mem::swap(&mut last.links, &mut s.links);
        last.candidates.clone_from(pairs);
        last.fixed.clone_from(&self.kept_pairs.fixed);
        last.row_limit = limit;
        last.prefer_soft.clone_from(&s.prefer_soft);
        last.found = Some((exact, soft));
        (exact, soft)
    }

    /// The bodies of islands whose exact solve went over its pivot budget this step stay
    /// on the soft step for the next second (`mark_soft_islands`): no island costs more
    /// than the budget for longer than a step.
    fn keep_over_budget_on_soft(&mut self, dt: f64) {
        let over = &self.solvers.exact.over_budget_bodies;
        if over.is_empty() {
            return;
        }
        // This step's count is `step_count` until it ends: the next second of steps.
        let until = self.step_count + 1 + (SOFT_AFTER_OVER_BUDGET / dt).ceil() as u64;
        self.auto.soft_until.resize(self.bodies.len(), 0);
        // The static world's slot comes after the bodies'.
        for &i in over.iter().filter(|&&i| (i as usize) < self.bodies.len()) {
            self.auto.soft_until[i as usize] = until;
        }
    }

    /// Starts a pass that holds every awake body whose island is (`soft`) or is not
    /// (`!soft`) the soft step's.
    fn hold_where(&mut self, soft: bool) {
        let in_soft_island = &self.auto.last_marking.in_soft_island;
        let held = |i: u32| in_soft_island[i as usize] == soft;
        self.sets.hold_for_pass(self.bodies.len(), held);
    }

    fn release_held(&mut self) {
        self.sets.end_pass();
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::{overlapping_pairs, pyramid_under_auto};
    use crate::body::{Body, BodyDef};
    use crate::math::Vec2;
    use crate::shape::ConvexPolygon;
    use crate::solver::ImpulseMethod;
    use crate::solver::joint::JointMotor;
    use crate::world::World;
    use crate::world::{JointDef, StepSettings};

    /// `auto` holds the soft islands' bodies for its exact pass and the exact ones' for
    /// its soft pass: the broad phase keeps its pairs across the holds, and each pass's
    /// candidates are exactly the overlapping pairs of which a body moves in that pass.
    #[test]
    fn candidates_leave_out_the_pairs_held_still_in_each_pass_of_auto() {
        let (mut world, dt) = pyramid_beside_heavy_stacks();
        assert_eq!(world.mark_soft_islands(dt), (true, true));
        let unheld = world.scratch.pairs.clone();
        assert_eq!(unheld, overlapping_pairs(&world));
        let mut moving_in_pass = vec![];
        for soft in [true, false] {
            let kept_bounds = world.kept_pairs.bounds.clone();
            world.hold_where(soft);
            world.find_candidate_pairs(dt);
            assert_eq!(world.kept_pairs.bounds, kept_bounds, "pairs kept");
            assert_eq!(world.scratch.pairs, overlapping_pairs(&world));
            assert!(world.scratch.pairs.len() < unheld.len());
            moving_in_pass.push(world.scratch.pairs.len());
            world.release_held();
        }
        // Each pass has pairs of its own: the pyramid's, and the stacks' and floor's.
        assert!(moving_in_pass.iter().all(|&n| n > 2), "{moving_in_pass:?}");
    }

    /// The pyramid of `pyramid_under_auto` (a soft island) and, apart from it, two stacks
    /// of two, each topped by a box twenty times as heavy (exact ones), five steps on.
    fn pyramid_beside_heavy_stacks() -> (World, f64) {
        let mut world = pyramid_under_auto();
        let unit = ConvexPolygon::rectangle(1.0, 1.0).unwrap();
        for x in [20.0, 25.0] {
            for (y, density) in [(-0.5, 1.0), (-1.5, 20.0)] {
                let def = BodyDef::new(unit.clone(), density).at(Vec2::new(x, y), 0.1);
                world.add_body(def).unwrap();
            }
        }
        let dt = 1.0 / 60.0;
        for _ in 0..5 {
            world.step(dt);
        }
        (world, dt)
    }

    /// Each pass of `auto` moves the bodies of its islands and leaves the other pass's
    /// bodies as they are, to the bit, while it runs (their velocities and masses among
    /// it): a pass holds bodies in the sets, not by changing them.
    #[test]
    fn each_pass_of_auto_moves_its_part_and_leaves_the_held_bodies_as_they_are() {
        let (mut world, dt) = pyramid_beside_heavy_stacks();
        assert_eq!(world.mark_soft_islands(dt), (true, true));
        let state = |b: &Body| {
            let (v, w) = (b.velocity, b.angular_velocity);
            [
                b.position.x,
                b.position.y,
                b.angle,
                v.x,
                v.y,
                w,
                b.inv_mass,
                b.inv_inertia,
            ]
            .map(f64::to_bits)
        };
        for soft_held in [true, false] {
            let before: Vec<_> = world.bodies.iter().flatten().map(state).collect();
            world.hold_where(soft_held);
            let held: Vec<bool> = (0..before.len() as u32)
                .map(|i| world.sets.is_held(i))
                .collect();
            if soft_held {
                world.step_impulses(ImpulseMethod::Exact, dt);
            } else {
                world.step_soft(dt);
            }
            let moving = world.sets.moving().to_vec();
            let after: Vec<_> = world.bodies.iter().flatten().map(state).collect();
            world.release_held();
            let held_count = held.iter().filter(|&&h| h).count();
            // The pyramid's 55 boxes, or the stacks' 4.
            assert_eq!(held_count, if soft_held { 55 } else { 4 });
            for (i, (was, is)) in before.iter().zip(&after).enumerate() {
                if held[i] {
                    assert_eq!(was, is, "held body {i} changed");
                }
            }
            assert_eq!(moving.len(), 59 - held_count);
            for &i in &moving {
                let (was, is) = (&before[i as usize], &after[i as usize]);
                assert_ne!(was[..6], is[..6], "body {i} did not move in its pass");
            }
        }
    }

    /// `auto` marks the soft islands again only when what the marks are made from changes:
    /// at every step, the kept marks are the ones a fresh marking gives, through row
    /// limits that the arm's island passes as its motor is switched off and on, and the
    /// pyramid falling asleep.
    #[test]
    fn soft_islands_are_marked_again_whenever_what_they_are_made_from_changes() {
        let mut world = pyramid_under_auto();
        world.settings.sleeping = true;
        // A bar on a motor, which never falls asleep.
        let bar = ConvexPolygon::rectangle(2.0, 0.2).unwrap();
        let arm = world
            .add_body(BodyDef::new(bar, 1.0).at(Vec2::new(40.0, -5.0), 0.0))
            .unwrap();
        let mut pin = JointDef::new(arm, None, Vec2::new(40.0, -5.0));
        pin.motor = Some(JointMotor::new(1.0, 10.0));
        let shoulder = world.add_joint(pin).unwrap();
        let dt = 1.0 / 60.0;
        for step in 0..120 {
            let default_limit = StepSettings::default().dense_row_limit;
            match step {
                10 => world.settings.dense_row_limit = 100_000,
                15 | 26 => world.settings.dense_row_limit = default_limit,
                // The arm's island: two rows for its pin, a third for its motor.
                20 => world.settings.dense_row_limit = 2,
                22 | 24 => {
                    let motor = world.joint_motor_mut(shoulder).unwrap();
                    motor.enabled = step == 24;
                }
                _ => {}
            }
            let kept = world.mark_soft_islands(dt);
            let kept_marks = world.auto.last_marking.in_soft_island.clone();
            world.auto.last_marking.found = None;
            let fresh = world.mark_soft_islands(dt);
            assert_eq!(kept, fresh, "step {step}");
            assert_eq!(
                kept_marks, world.auto.last_marking.in_soft_island,
                "step {step}"
            );
            world.step(dt);
        }
        let asleep = world.bodies().filter(|(_, b)| b.is_asleep()).count();
        assert_eq!(asleep, 55, "the pyramid fell asleep");
        // Each step marks three times: the check's, the fresh one, the step's own. The
        // first and the last are kept unless something changed: at most 240 times.
        let kept = world.stats().auto_splits_kept;
        assert!((220..=240).contains(&kept), "marks kept {kept} times");
    }
}
