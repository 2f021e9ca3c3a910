//! The step's candidate pairs: the collision filter (joints and ignored pairs), the
//! broad phase over bounds grown by each body's reach, and the cap on a crowded body's
//! neighbours.

use super::World;
use crate::body::Body;
use crate::collide::{Aabb, BroadPhase, FixedCells};
use crate::solver::island::merged_increasing;

/// While the broad phase pairs the bodies again every time, every this many pairings use
/// grown bounds, to see whether they hold again (`find_candidate_pairs`).
const RETRY_GROWN_BOUNDS: u32 = 8;

/// nearer ones stand between.
const MAX_NEIGHBOURS: f64 = 32.0;

/// From this many static and sleeping bodies on, they are kept in cells of their own
/// (`FixedCells`) and only the moving bodies are gridded at each pairing.
const FIXED_CELLS_FROM: usize = 64;

/// Whether a convex outline (vertices in positive order) covers `point`, its boundary
/// included.
fn covers_point(vertices: &[crate::math::Vec2], point: crate::math::Vec2) -> bool {
    let n = vertices.len();
    let size = vertices.iter().map(|v| v.norm()).fold(0.0, f64::max);
    (0..n).all(|i| {
        let (a, b) = (vertices[i], vertices[(i + 1) % n]);
        crate::math::cross(b - a, point - a) >= -1e-9 * size * size
    })
}

/// How much of body `i`'s room for neighbours body `j` takes: 1 for a body at least its
/// size, by bounding radius, and less for a smaller one.
fn neighbour_share(radii: &[f64], i: usize, j: usize) -> f64 {
    if radii[j] >= radii[i] {
        1.0
    } else {
        radii[j] / radii[i]
    }
}

/// Whether some moving body has more than `MAX_NEIGHBOURS` moving neighbours among
/// `pairs`, counted by `neighbour_share` into `room_taken`.
fn crowded(pairs: &[(u32, u32)], fixed: &[bool], radii: &[f64], room_taken: &mut Vec<f64>) -> bool {
    room_taken.clear();
    room_taken.resize(fixed.len(), 0.0);
    let mut crowded = false;
    for &(i, j) in pairs {
        let (i, j) = (i as usize, j as usize);
        if !fixed[i] && !fixed[j] {
            for (k, other) in [(i, j), (j, i)] {
                room_taken[k] += neighbour_share(radii, k, other);
                crowded |= room_taken[k] > MAX_NEIGHBOURS;
            }
        }
    }
    crowded
}

/// The broad phase's buffers, reused from step to step: its own, each body's bounding
/// radius, and what keeping a crowded body's nearest neighbours takes
/// (`KeptPairs::crowded`).
#[derive(Debug, Clone, Default)]
pub(super) struct CandidateScratch {
    broad_phase: BroadPhase,
    radii: Vec<f64>,
    grown_by: Vec<f64>,
    neighbours: NeighbourScratch,
}

/// Scratch for `keep_nearest_neighbours`.
#[derive(Debug, Clone, Default)]
struct NeighbourScratch {
    room_taken: Vec<f64>,
    dropped: Vec<bool>,
    /// (gap, pair) for the pairs found only by how far their bodies can move.
    within_reach: Vec<(f64, u32)>,
}

/// Keeps each pair with a fixed body, and pairs of moving bodies while both have room
/// (`MAX_NEIGHBOURS`): first those whose own bounds overlap, in the pairs' order (in a
/// pile-up they are all alike and all there is), then those found only by how far the
/// bodies can move in the step, nearest first. `boxes` are the bounds grown by `grown_by`
/// each.
fn keep_nearest_neighbours(
    pairs: &mut Vec<(u32, u32)>,
    fixed: &[bool],
    (boxes, grown_by, radii): (&[Option<Aabb>], &[f64], &[f64]),
    scratch: &mut NeighbourScratch,
) {
    let NeighbourScratch {
        room_taken,
        dropped,
        within_reach,
    } = scratch;
    room_taken.clear();
    room_taken.resize(fixed.len(), 0.0);
    dropped.clear();
    dropped.resize(pairs.len(), false);
    within_reach.clear();
    let mut keep_if_room = |p: usize, (i, j): (usize, usize), dropped: &mut [bool]| {
        let (share_i, share_j) = (neighbour_share(radii, i, j), neighbour_share(radii, j, i));
        if room_taken[i] + share_i <= MAX_NEIGHBOURS && room_taken[j] + share_j <= MAX_NEIGHBOURS {
            room_taken[i] += share_i;
            room_taken[j] += share_j;
        } else {
            dropped[p] = true;
        }
    };
    for (p, &(i, j)) in pairs.iter().enumerate() {
        let (i, j) = (i as usize, j as usize);
        if fixed[i] || fixed[j] {
            continue;
        }
        let (Some(a), Some(b)) = (&boxes[i], &boxes[j]) else {
            continue;
        };
        let apart = (b.min - a.max).sup(&(a.min - b.max));
        // The gap between their own bounds, without the growth.
        let gap = apart.x.max(apart.y) + grown_by[i] + grown_by[j];
        if gap < 0.0 {
            keep_if_room(p, (i, j), dropped);
        } else {
            within_reach.push((gap, p as u32));
        }
    }
    within_reach.sort_unstable_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
    for &(_, p) in within_reach.iter() {
        let (i, j) = pairs[p as usize];
        keep_if_room(p as usize, (i as usize, j as usize), dropped);
    }
    let mut p = 0;
    pairs.retain(|_| {
        p += 1;
        !dropped[p - 1]
    });
}

/// How far two bodies can close on each other in a step, from each one's `motion`: their
/// centroids' relative displacement and how far each one's spin carries its farthest point.
/// The broad phase's pairs, kept from step to step while they still hold: found from the
/// bounds grown by `broad_phase_margin` (or bare, while grown ones do not hold), and which
/// bodies were static or asleep then (see `find_candidate_pairs`).
#[derive(Debug, Clone, Default)]
pub(super) struct KeptPairs {
    pub(super) bounds: Vec<Option<Aabb>>,
    pairs: Vec<(u32, u32)>,
    pub(super) fixed: Vec<bool>,
    /// How many times in a row the broad phase has paired the bodies again (0: it kept its
    /// pairs the last time).
    paired_in_a_row: u32,
    /// Whether some moving body has more than `MAX_NEIGHBOURS` moving neighbours among
    /// the pairs.
    crowded: bool,
    /// The static and sleeping bodies in cells of their own, and the bounds they were
    /// listed with (`BodyBounds::made_for` and the growth, in bits); the fixed bodies, as
    /// scratch.
    fixed_cells: FixedCells,
    fixed_cells_for: Option<((u64, u64, u64), u64)>,
    fixed_slots: Vec<u32>,
}

impl KeptPairs {
    /// Found again at the next step: the joints or ignored pairs changed.
    fn forget(&mut self) {
        self.bounds.clear();
        self.fixed.clear();
        self.pairs.clear();
        self.fixed_cells_for = None;
    }
}

impl World {
    pub(super) fn refresh_collision_filter(&mut self) {
        if !std::mem::take(&mut self.collision_filter_stale) {
            return;
        }
        self.kept_pairs.forget();
        self.jointed.clear();
        self.jointed.extend(
            self.joints
                .iter()
                .flatten()
                .flat_map(|j| [Some(j.body_a.0), j.body_b.map(|b| b.0)])
                .flatten(),
        );
        self.jointed.sort_unstable();
        self.jointed.dedup();
        self.motor_joints.clear();
        self.motor_joints.extend(
            (0..self.joints.len() as u32)
                .filter(|&k| self.joints[k as usize].is_some_and(|j| j.motor.is_some())),
        );
        self.spring_joints.clear();
        self.spring_joints
            .extend((0..self.joints.len() as u32).filter(|&k| {
                self.joints[k as usize]
                    .as_ref()
                    .is_some_and(|j| j.spring.is_some())
            }));
        let pivot_sharers = self.pairs_sharing_a_pivot();
        self.non_colliding.rebuild(
            self.joints
                .iter()
                .flatten()
                .filter(|j| !j.collide_connected)
                .filter_map(|j| {
                    let (a, b) = (j.body_a.0, j.body_b?.0);
                    Some((a.min(b), a.max(b)))
                })
                .chain(self.ignored_pairs.iter().copied())
                .chain(pivot_sharers),
        );
    }

    /// The body pairs that turn about one pivot, each covering it: two bodies pinned to a
    /// third (or to the static world, or to static bodies: the world) at the same point of
    /// it, each containing that point.
    /// However they turn they overlap there, so no contact between them can ever be
    /// resolved, and a solver that tried would push them against their pins for ever.
    /// Like two pinned bodies, they pass through each other: scissors' blades, a walker's
    /// legs on one hip, a wheel's spokes. A joint that asks its bodies to collide
    /// (`collide_connected`) keeps its bodies out of this.
    fn pairs_sharing_a_pivot(&self) -> Vec<(u32, u32)> {
        const WORLD: u32 = u32::MAX;
        let covers = |body: u32, local: crate::math::Vec2| {
            self.bodies[body as usize]
                .as_ref()
                .is_some_and(|b| covers_point(b.local_vertices(), local))
        };
        // A pivot's holder and the pivot in its frame; a static body's pivots are the
        // world's, at their world points.
        let holder = |body: Option<u32>, local: crate::math::Vec2| match body
            .and_then(|i| Some((i, self.bodies[i as usize].as_ref()?)))
        {
            Some((_, b)) if b.is_static() => (
                WORLD,
                b.position + crate::math::Rot::new(b.angle).apply(local),
            ),
            Some((i, _)) => (i, local),
            None => (WORLD, local),
        };
        // (pivot's holder, the pivot in its holder's frame, the body turning about it)
        let mut pivots: Vec<(u32, crate::math::Vec2, u32)> = Vec::new();
        for j in self
            .joints
            .iter()
            .flatten()
            .filter(|j| !j.collide_connected)
        {
            let (a, b) = (j.body_a.0, j.body_b.map(|h| h.0));
            if covers(a, j.local_anchor_a) {
                let (held_by, at) = holder(b, j.local_anchor_b);
                pivots.push((held_by, at, a));
            }
            if let Some(b) = b.filter(|&b| covers(b, j.local_anchor_b)) {
                let (held_by, at) = holder(Some(a), j.local_anchor_a);
                pivots.push((held_by, at, b));
            }
        }
        pivots.sort_unstable_by(|p, q| p.0.cmp(&q.0).then(p.1.x.total_cmp(&q.1.x)));
        let mut pairs = Vec::new();
        for (k, &(holder, at, body)) in pivots.iter().enumerate() {
            // The same point to a millionth of the holder's size: anchors made from one
            // point of a file agree far closer.
            let size = match self.bodies.get(holder as usize).and_then(Option::as_ref) {
                Some(b) => b.bounding_radius(),
                None => at.norm().max(1.0),
            };
            let tolerance = 1e-6 * size;
            for &(other_holder, other_at, other) in &pivots[k + 1..] {
                if other_holder != holder || other_at.x - at.x > tolerance {
                    break;
                }
                if other != body && (other_at - at).norm() <= tolerance {
                    pairs.push((body.min(other), body.max(other)));
                }
            }
        }
        pairs
    }

    /// World outlines, each body's reach this step and poses, and the broad phase's
    /// candidate pairs: bodies whose bounds, grown by the margin and by how far each can
    /// move in `dt`, overlap (pairs of fixed bodies and pairs kept apart left out).
    pub(super) fn find_candidate_pairs(&mut self, dt: f64) {
        self.sets.refresh(&self.bodies);
        let (candidates, s) = (&mut self.scratch.pairs, &mut self.scratch.candidates);
        let kept = &mut self.kept_pairs;
        let n = self.bodies.len();
        let margin = self.settings.contact_margin();
        let is_fixed = |body: &Option<Body>| body.as_ref().is_none_or(Body::is_fixed);
        let mut made = self.bounds.make(&self.bodies, &self.sets, dt, margin);
        // The grown bounds' pairs still hold every pair whose bounds overlap now if every
        // body's bounds lie inside its grown ones, and the same bodies are fixed. Bodies
        // whose bounds were not made again are as they were when last checked.
        let bounds = &self.bounds;
        let still_inside = kept.bounds.len() == n
            && made.clone().all(
                |i| match (&bounds.boxes[i as usize], &kept.bounds[i as usize]) {
                    (Some(now), Some(fat)) => fat.contains(now),
                    (None, None) => true,
                    _ => false,
                },
            );
        let same_fixed = kept.fixed.len() == n
            && made.all(|i| kept.fixed[i as usize] == is_fixed(&self.bodies[i as usize]));
        let made_for = bounds.made_for().expect("made above");
        let bodies = &self.bodies;
        // Pairs of static or sleeping bodies are never tested: a pile at rest costs nothing.
        // The broad phase leaves out such pairs only, not those of bodies held for one pass
        // of `auto` (whose two passes hold different bodies); those are dropped from its
        // pairs below, so that its pairs serve both passes.
        if still_inside && same_fixed {
            kept.paired_in_a_row = 0;
        } else {
            kept.paired_in_a_row = kept.paired_in_a_row.wrapping_add(1);
            // Grown bounds pay while their pairs hold for a few steps. Where every step pairs
            // again anyway (the smash's flying debris) they only add pairs to compare and
            // sort: pair the bounds as they are, and try grown ones again now and then in
            // case the scene has settled. The candidates are the same either way.
            let grow_pays =
                kept.paired_in_a_row < 2 || kept.paired_in_a_row.is_multiple_of(RETRY_GROWN_BOUNDS);
            let grow = if grow_pays {
                self.settings.broad_phase_margin()
            } else {
                0.0
            };
            kept.bounds.clear();
            kept.bounds
                .extend(bounds.boxes.iter().map(|b| b.map(|b| b.grown(grow))));
            kept.fixed.clear();
            kept.fixed.extend(bodies.iter().map(is_fixed));
            let (non_colliding, fixed) = (&self.non_colliding, &kept.fixed);
            let wanted = |i: usize, j: usize| {
                let both_fixed = fixed[i] & fixed[j];
                !both_fixed && !non_colliding.contains((i as u32, j as u32))
            };
            let fixed_slots = &mut kept.fixed_slots;
            fixed_slots.clear();
            fixed_slots.extend(merged_increasing(self.sets.statics(), self.sets.sleeping()));
            if fixed_slots.len() < FIXED_CELLS_FROM {
                s.broad_phase.pairs(&kept.bounds, wanted, &mut kept.pairs);
            } else {
                let listed_with = (made_for, grow.to_bits());
                if kept.fixed_cells_for != Some(listed_with) {
                    kept.fixed_cells.build(&kept.bounds, fixed_slots);
                    kept.fixed_cells_for = Some(listed_with);
                }
                let moving = self.sets.awake();
                s.broad_phase
                    .pairs_among(&kept.bounds, moving, wanted, &mut kept.pairs);
                kept.fixed_cells
                    .pairs_with(&kept.bounds, moving, wanted, &mut kept.pairs);
                s.broad_phase.sort_pairs(&mut kept.pairs, n);
            }
            s.radii.clear();
            s.radii.extend(
                bodies
                    .iter()
                    .map(|b| b.as_ref().map_or(0.0, Body::bounding_radius)),
            );
            let room_taken = &mut s.neighbours.room_taken;
            kept.crowded = crowded(&kept.pairs, fixed, &s.radii, room_taken);
        }
        // The candidates: the pairs whose bounds overlap now, in the broad phase's order.
        let boxes = &bounds.boxes;
        let overlap = |&(i, j): &(u32, u32)| match (&boxes[i as usize], &boxes[j as usize]) {
            (Some(a), Some(b)) => a.overlaps(b),
            _ => false,
        };
        candidates.clear();
        if self.sets.in_pass() {
            // `auto`'s pass: a pair is wanted where one of its bodies moves in the pass.
            let (fixed, sets) = (&kept.fixed, &self.sets);
            let fixed_in_pass = |i: u32| fixed[i as usize] || sets.is_held(i);
            let one_moves = |&(i, j): &(u32, u32)| !(fixed_in_pass(i) && fixed_in_pass(j));
            candidates.extend(
                kept.pairs
                    .iter()
                    .copied()
                    .filter(|p| one_moves(p) && overlap(p)),
            );
        } else {
            candidates.extend(kept.pairs.iter().copied().filter(overlap));
        }
        if kept.crowded {
            s.grown_by.clear();
            s.grown_by
                .extend(bounds.reach.iter().map(|reach| 0.5 * margin + reach));
            let sizes = (&bounds.boxes[..], &s.grown_by[..], &s.radii[..]);
            keep_nearest_neighbours(candidates, &kept.fixed, sizes, &mut s.neighbours);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::{overlapping_pairs, pairs_overlapping};
    use super::*;
    use crate::body::BodyDef;
    use crate::math::Vec2;
    use crate::shape::ConvexPolygon;
    use crate::solver::ContactSolver;

    /// The broad phase keeps its pairs while bodies stay inside their grown bounds; the
    /// candidates must still be exactly the pairs whose bounds overlap now.
    #[test]
    fn candidates_are_the_overlapping_pairs_while_the_broad_phase_keeps_its_pairs() {
        let mut world = World::new(Vec2::zeros());
        world.settings.contact_solver = ContactSolver::Soft;
        let square = ConvexPolygon::rectangle(1.0, 1.0).unwrap();
        // A grid of boxes drifting slowly, each its own way: a few hundredths of a box
        // per step, so that the grown bounds hold for some steps and not for others.
        for i in 0..8 {
            for j in 0..8 {
                let (x, y) = (1.3 * i as f64, 1.3 * j as f64);
                let v = Vec2::new(
                    ((3 * i + j) % 5) as f64 - 2.0,
                    ((i + 2 * j) % 5) as f64 - 2.0,
                );
                let def = BodyDef::new(square.clone(), 1.0).at(Vec2::new(x, y), 0.0);
                world.add_body(def.velocity(v * 0.9, 0.3)).unwrap();
            }
        }
        world
            .add_body(
                BodyDef::new(ConvexPolygon::rectangle(30.0, 1.0).unwrap(), 0.0)
                    .at(Vec2::new(4.5, 11.0), 0.0),
            )
            .unwrap();
        let dt = 1.0 / 60.0;
        let (mut kept, mut found) = (0, 0);
        for _ in 0..300 {
            world.step(dt);
            let before = world.kept_pairs.bounds.clone();
            world.find_candidate_pairs(dt);
            if world.kept_pairs.bounds == before {
                kept += 1;
            } else {
                found += 1;
            }
            assert_eq!(world.scratch.pairs, overlapping_pairs(&world));
        }
        assert!(
            kept > 20 && found > 20,
            "pairs kept {kept} times, found {found} times"
        );
    }

    /// Debris flying apart leaves its grown bounds every step, so the broad phase pairs
    /// the bare bounds, trying grown ones every `RETRY_GROWN_BOUNDS` pairings; then the
    /// debris is stopped, the grown bounds hold again and their pairs are kept. The
    /// candidates are exactly the overlapping pairs throughout.
    #[test]
    fn candidates_are_the_overlapping_pairs_while_debris_outruns_its_grown_bounds() {
        let mut world = World::new(Vec2::zeros());
        world.settings.contact_solver = ContactSolver::Soft;
        let square = ConvexPolygon::rectangle(0.5, 0.5).unwrap();
        let mut handles = vec![];
        for i in 0..10 {
            for j in 0..10 {
                let at = Vec2::new(0.6 * i as f64, 0.6 * j as f64);
                // Outwards from the middle at up to 23 m/s: 0.4 m a step, four margins.
                let velocity = (at - Vec2::new(2.7, 2.7)) * 6.0;
                let def = BodyDef::new(square.clone(), 1.0).at(at, 0.2);
                handles.push(world.add_body(def.velocity(velocity, 2.0)).unwrap());
            }
        }
        let dt = 1.0 / 60.0;
        let (mut bare, mut grown, mut kept) = (0, 0, 0);
        for step in 0..60 {
            if step == 40 {
                for &h in &handles {
                    let body = world.body_mut(h).unwrap();
                    body.velocity = Vec2::zeros();
                    body.angular_velocity = 0.0;
                }
            }
            // The step's own broad phase, at the poses the step began with.
            let before = world.kept_pairs.bounds.clone();
            world.step(dt);
            let s = &world.scratch;
            if world.kept_pairs.bounds == before {
                kept += 1;
            } else if world.kept_pairs.bounds == world.bounds.boxes {
                bare += 1;
            } else {
                grown += 1;
            }
            assert_eq!(s.pairs, overlapping_pairs(&world), "step {step}");
        }
        assert!(
            bare > 30 && grown >= 5 && kept > 15,
            "bare bounds paired {bare} times, grown {grown}, pairs kept {kept} times"
        );
    }

    /// The candidates from bounds made afresh from every body where it is now, whatever
    /// the step kept: pairs of bodies whose outlines' bounds, each grown by half the
    /// contact margin and its reach in `dt`, overlap (pairs of two fixed bodies aside).
    fn pairs_from_fresh_bounds(world: &World, dt: f64) -> Vec<(u32, u32)> {
        let margin = world.settings.contact_margin();
        let bounds: Vec<Option<Aabb>> = world
            .bodies
            .iter()
            .map(|b| {
                let b = b.as_ref()?;
                let spin = b.angular_velocity.abs() * b.bounding_radius();
                let reach = (b.velocity.norm() + spin) * dt;
                let mut corners = b.world_vertices();
                let first = corners.next()?;
                let mut aabb = Aabb {
                    min: first,
                    max: first,
                };
                for v in corners {
                    aabb.min = aabb.min.inf(&v);
                    aabb.max = aabb.max.sup(&v);
                }
                Some(aabb.grown(0.5 * margin + reach))
            })
            .collect();
        pairs_overlapping(world, &bounds)
    }

    /// The step looks again only at the awake bodies; the others' bounds are kept until
    /// the sets change. Boxes fall on a row of static tiles, fall asleep and are woken.
    /// Beside one of them, a static slab is given a velocity by hand (a conveyor: it
    /// stays, and its reach grows its bounds to the box) and stopped again; then a tile
    /// is pulled from under the box by hand. At every step the candidates are the pairs
    /// of bounds made afresh from every body.
    #[test]
    fn candidates_follow_bodies_that_only_sometimes_move() {
        for solver in [
            ContactSolver::Soft,
            ContactSolver::Auto,
            ContactSolver::Exact,
        ] {
            let mut world = World::new(Vec2::new(0.0, 10.0));
            world.settings.contact_solver = solver;
            world.settings.sleeping = true;
            let tile = ConvexPolygon::rectangle(1.0, 1.0).unwrap();
            let tiles: Vec<_> = (0..40)
                .map(|i| {
                    let def = BodyDef::new(tile.clone(), 0.0).at(Vec2::new(i as f64, 0.0), 0.0);
                    world.add_body(def).unwrap()
                })
                .collect();
            for i in 0..6 {
                let at = Vec2::new(2.0 + 3.0 * i as f64, -1.5);
                world
                    .add_body(BodyDef::new(tile.clone(), 1.0).at(at, 0.1))
                    .unwrap();
            }
            // At rest on tiles 31 and 32, 0.1 right of the conveyor's end.
            let at = Vec2::new(31.6, -1.0);
            let by_conveyor = world.add_body(BodyDef::new(tile.clone(), 1.0).at(at, 0.0));
            let by_conveyor = by_conveyor.unwrap();
            let slab = ConvexPolygon::rectangle(2.0, 0.2).unwrap();
            let conveyor = BodyDef::new(slab, 0.0).at(Vec2::new(30.0, -1.0), 0.0);
            let conveyor = world.add_body(conveyor).unwrap();
            let dt = 1.0 / 60.0;
            let mut asleep_seen = false;
            let pair_with_conveyor = |world: &World| {
                let pair = (by_conveyor.0.min(conveyor.0), by_conveyor.0.max(conveyor.0));
                world.scratch.pairs.contains(&pair)
            };
            for step in 0..180 {
                match step {
                    100 => world.wake_body(by_conveyor),
                    // 30 m/s away from the box: half a box in a step, over the 0.1 gap.
                    110 => world.body_mut(conveyor).unwrap().velocity = Vec2::new(-30.0, 0.0),
                    115 => world.body_mut(conveyor).unwrap().velocity = Vec2::zeros(),
                    120 => world.body_mut(tiles[32]).unwrap().position.y += 2.0,
                    _ => {}
                }
                world.step(dt);
                asleep_seen |= world.body(by_conveyor).unwrap().is_asleep();
                world.find_candidate_pairs(dt);
                let fresh = pairs_from_fresh_bounds(&world, dt);
                assert_eq!(world.scratch.pairs, fresh, "{solver:?}, step {step}");
                if step < 120 {
                    let conveyor_on = (110..115).contains(&step);
                    assert_eq!(
                        pair_with_conveyor(&world),
                        conveyor_on,
                        "{solver:?}, {step}"
                    );
                }
            }
            assert!(asleep_seen, "{solver:?}: the boxes fell asleep");
        }
    }
}
