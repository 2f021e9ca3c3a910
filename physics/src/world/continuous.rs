//! Continuous collision: a body that ended its step through or deep in a static body
//! goes back along its path to its time of impact, its joint island with it.

use super::World;
use super::body_sets::{BodySets, EpochSeen};
use crate::body::Body;
use crate::collide::toi::{Sweep, place, separation, time_of_impact, time_of_sinking};
use crate::collide::{Aabb, WorldPolygon};
use crate::math::Vec2;
use crate::solver::ContactSolver;
use crate::solver::island::UnionFind;

/// Continuous collision's buffers, reused from step to step.
#[derive(Debug, Clone, Default)]
pub(super) struct ContinuousScratch {
    /// By slot, each awake body's centroid and angle when the step began.
    pub(super) step_start: Vec<(Vec2, f64)>,
    /// The moving body's outline where its step ends and starts, and the time-of-impact
    /// search's own.
    mover_at_end: WorldPolygon,
    mover_at_start: WorldPolygon,
    toi_scratch: WorldPolygon,
    /// The bodies stopped, their times of impact and whether they sank (`Stop`); joint
    /// islands and each island's earliest stop.
    impacts: Vec<(u32, Stop)>,
    impact_union: UnionFind,
    island_impact: Vec<Stop>,
}

/// The static bodies as obstacles, kept while the sets stay: each one's slot, outline,
/// bounds and place, and an index of them by their bounds' left edge, for finding those
/// a sweep passes over without looking at every one (a terrain of 2,000 tiles).
#[derive(Debug, Clone, Default)]
pub(super) struct Obstacles {
    list: Vec<(u32, WorldPolygon, Aabb, [u64; 3])>,
    /// The narrow obstacles' left edges and `list` indices, increasing, and the widest
    /// of them.
    by_left_edge: Vec<(f64, u32)>,
    widest: f64,
    /// The wide ones (over `WIDE` times the median width: a floor), met by every sweep.
    wide: Vec<u32>,
    widths: Vec<f64>,
    seen: EpochSeen,
}

/// Where continuous collision stops a body: the fraction of its step's sweep, and
/// whether it came from apart (an impact, which the contacts bounce next step) or sank
/// from contact, or met the obstacle where it started (the contact solver did not hold
/// it: it moves on only as far as it got).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Stop {
    t: f64,
    sank: bool,
}

impl Stop {
    const NONE: Stop = Stop {
        t: f64::INFINITY,
        sank: false,
    };

    fn earlier(self, other: Stop) -> Stop {
        if other.t < self.t { other } else { self }
    }
}

/// An obstacle this many times wider than the median one is not in the index by left
/// edge: it would widen every search.
const WIDE: f64 = 4.0;

impl Obstacles {
    /// The static bodies listed again if the sets changed since the last time.
    fn list_again_if_changed(&mut self, sets: &BodySets, bodies: &[Option<Body>]) {
        if !self.seen.sets_changed(sets) {
            return;
        }
        let mut n = 0;
        for &slot in sets.statics() {
            let obstacle = bodies[slot as usize].as_ref().expect("a static body");
            if self.list.len() == n {
                self.list.push(Default::default());
            }
            let (index, polygon, bounds, placed_at) = &mut self.list[n];
            // The same static body where it was placed last time has the same outline:
            // a terrain of many is not turned again whenever the sets change.
            let place = obstacle.place();
            if *index != slot || *placed_at != place || polygon.vertices.is_empty() {
                *index = slot;
                polygon.update(obstacle);
                *bounds = polygon.aabb();
                *placed_at = place;
            }
            n += 1;
        }
        self.list.truncate(n);
        let width = |b: &Aabb| b.max.x - b.min.x;
        self.widths.clear();
        self.widths
            .extend(self.list.iter().map(|(_, _, b, _)| width(b)));
        let median = if self.widths.is_empty() {
            0.0
        } else {
            let middle = self.widths.len() / 2;
            *self.widths.select_nth_unstable_by(middle, f64::total_cmp).1
        };
        self.by_left_edge.clear();
        self.wide.clear();
        self.widest = 0.0;
        for (k, (_, _, b, _)) in self.list.iter().enumerate() {
            // Not narrow unless finite and at most `WIDE` medians wide (NaN: wide).
            if width(b) <= WIDE * median {
                self.by_left_edge.push((b.min.x, k as u32));
                self.widest = self.widest.max(width(b));
            } else {
                self.wide.push(k as u32);
            }
        }
        self.by_left_edge
            .sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    }

    /// The obstacles whose bounds overlap `swept`: the wide ones, then the narrow ones by
    /// left edge (the order does not matter to the earliest impact).
    fn near<'a>(
        &'a self,
        swept: &'a Aabb,
    ) -> impl Iterator<Item = &'a (u32, WorldPolygon, Aabb, [u64; 3])> + 'a {
        // A narrow obstacle that reaches `swept` starts at most `widest` left of it (twice
        // that, against the rounding of the widths).
        let from = self
            .by_left_edge
            .partition_point(|&(left, _)| left < swept.min.x - 2.0 * self.widest);
        let narrow = self.by_left_edge[from..]
            .iter()
            .take_while(|&&(left, _)| left <= swept.max.x)
            .map(|&(_, k)| k);
        self.wide
            .iter()
            .copied()
            .chain(narrow)
            .map(|k| &self.list[k as usize])
            .filter(|(_, _, bounds, _)| swept.overlaps(bounds))
    }
}

impl World {
    /// Continuous collision: see `step`.
    pub(super) fn stop_at_impact(&mut self, dt: f64) {
        let slop = self.settings.slop();
        let margin = self.settings.contact_margin();
        let s = &mut self.scratch.continuous;
        // Whether the step's pins were solved apart from its contacts (`thesis`,
        // `sequential`).
        let pins_apart = matches!(
            self.settings.contact_solver,
            ContactSolver::Thesis | ContactSolver::Sequential
        );
        // The static bodies, looked at when the first body needs them (most steps, none
        // does), and listed again only if the sets changed.
        let mut obstacles = std::mem::take(&mut self.obstacles);
        let mut listed = false;
        s.impacts.clear();
        for &i in self.sets.awake() {
            let i = i as usize;
            let body = self.bodies[i].as_ref().expect("an awake body");
            let sweep = Sweep {
                start: s.step_start[i],
                end: (body.position, body.angle),
            };
            let radius = body.bounding_radius();
            let motion =
                (sweep.end.0 - sweep.start.0).norm() + (sweep.end.1 - sweep.start.1).abs() * radius;
            // Fast bodies, and bodies an impact sent further than the contact margin (their
            // contacts were found before the solve, for the motion they had then). A
            // jointed body only when fast enough to pass through something: its whole
            // mechanism goes back with it (below), and a robot's feet pressed a little deep
            // into the ground are the contacts' job: taken back too, a robot walks less far
            // and its pins open more (docs/bench/profile.md, "The measurements behind the
            // code's rules").
            let fast = 0.5 * body.inner_radius();
            // Slow enough for any body, and then for a jointed one: most bodies are
            // the first, and need no search among the jointed.
            if motion <= fast.min(margin) {
                continue;
            }
            let jointed = self.jointed.binary_search(&(i as u32)).is_ok();
            if motion <= fast && jointed {
                continue;
            }
            if !std::mem::replace(&mut listed, true) {
                obstacles.list_again_if_changed(&self.sets, &self.bodies);
            }
            let swept = Aabb {
                min: sweep.start.0.inf(&sweep.end.0),
                max: sweep.start.0.sup(&sweep.end.0),
            }
            .grown(radius + slop);
            let local = body.local_vertices();
            // The body's outlines at either end of its sweep, placed when an obstacle
            // first needs them: most fast bodies have none near, and placing both for
            // every fast body is a noticeable part of a scene of flying debris's step.
            let (mut placed_at_end, mut placed_at_start) = (false, false);
            let mut first: Option<Stop> = None;
            for (obstacle, polygon, _, _) in obstacles.near(&swept) {
                // A static body this one never collides with (a robot's pivot that its
                // own links pass over) is no obstacle.
                let pair = ((i as u32).min(*obstacle), (i as u32).max(*obstacle));
                if self.non_colliding.contains(pair) {
                    continue;
                }
                if !placed_at_end {
                    place(&mut s.mover_at_end, local, sweep.end);
                    placed_at_end = true;
                }
                // Ending in contact (within the solver's slop either way) is the contact
                // solver's business: a landing, a body sliding along a floor.
                let end_gap = separation(&s.mover_at_end, polygon);
                if (-2.0 * slop..=slop).contains(&end_gap) {
                    continue;
                }
                // Apart at both ends, and too far apart for the motion to have touched in
                // between (the gap shrinks no faster than `motion` per step).
                if end_gap > slop {
                    if !placed_at_start {
                        place(&mut s.mover_at_start, local, sweep.start);
                        placed_at_start = true;
                    }
                    let start_gap = separation(&s.mover_at_start, polygon);
                    if start_gap + end_gap > motion + 2.0 * slop {
                        continue;
                    }
                }
                // In contact at the start and far deeper at the end: the contact solver
                // did not hold it (under `thesis`, the joint pass after the contacts drags
                // a stopped link on into a wall); it goes back to where it was 2 × slop deep.
                // Where pins and contacts are solved together, a jointed body sinks only
                // where the repair of a broken pin (positions, before the contacts) moved
                // it: taken back, the repair would be undone at every step, and its pins
                // never close; the contacts push it out instead.
                let hit = time_of_impact(
                    local,
                    radius,
                    &sweep,
                    polygon,
                    slop,
                    0.25 * slop,
                    &mut s.toi_scratch,
                )
                // Stopped within the slop of where it started, it met the obstacle at
                // the step's start: the contacts had it, as one that sank.
                .map(|t| Stop {
                    t,
                    sank: t * motion <= slop,
                })
                .or_else(|| {
                    if end_gap >= -2.0 * slop || jointed && !pins_apart {
                        return None;
                    }
                    let t = time_of_sinking(
                        local,
                        radius,
                        &sweep,
                        polygon,
                        2.0 * slop,
                        0.25 * slop,
                        &mut s.toi_scratch,
                    )?;
                    Some(Stop { t, sank: true })
                });
                if let Some(hit) = hit {
                    first = Some(first.map_or(hit, |f| f.earlier(hit)));
                }
            }
            if let Some(stop) = first {
                s.impacts.push((i as u32, stop));
            }
        }
        self.obstacles = obstacles;
        self.move_back_to_impacts(dt);
    }

    /// Moves each body that continuous collision stopped back along its sweep to its time
    /// of impact. A jointed body takes its joint island with it, every moving body to the
    /// same fraction of its own sweep: moving one link alone would open its pins by the
    /// rest of the step's motion. (Turning bodies' pins then stay together to second order
    /// in the step's rotation; the joint passes close the rest next step.)
    ///
    /// A body that came from apart keeps its velocity: the contacts meet the impact next
    /// step and bounce it. One that sank from contact moves on with the velocity it
    /// actually moved with, the fraction of its sweep it kept over the step: its velocity
    /// into the obstacle is what the contact solver failed to stop, and kept, it would
    /// send the body back into the obstacle, and back to the same place, step after step,
    /// gaining speed from gravity while it does not move (a hub of 20 pinned spokes on a
    /// floor under `thesis`).
    fn move_back_to_impacts(&mut self, dt: f64) {
        let s = &mut self.scratch.continuous;
        if s.impacts.is_empty() {
            return;
        }
        let bodies = &mut self.bodies;
        let moving = |i: usize| bodies[i].as_ref().is_some_and(|b| !b.is_fixed());
        let jointed_hit = s
            .impacts
            .iter()
            .any(|(i, _)| self.jointed.binary_search(i).is_ok());
        if jointed_hit {
            s.impact_union.reset(bodies.len());
            for j in self.joints.iter().flatten() {
                if let Some(b) = j.body_b {
                    let (ia, ib) = (j.body_a.index(), b.index());
                    if moving(ia) && moving(ib) {
                        s.impact_union.union(ia as u32, ib as u32);
                    }
                }
            }
            s.island_impact.clear();
            s.island_impact.resize(bodies.len(), Stop::NONE);
            for &(i, stop) in &s.impacts {
                let root = s.impact_union.find(i) as usize;
                s.island_impact[root] = s.island_impact[root].earlier(stop);
            }
            s.impacts.clear();
            for i in 0..bodies.len() {
                if moving(i) {
                    let stop = s.island_impact[s.impact_union.find(i as u32) as usize];
                    if stop.t.is_finite() {
                        s.impacts.push((i as u32, stop));
                    }
                }
            }
        }
        for &(i, stop) in &s.impacts {
            let body = bodies[i as usize].as_mut().expect("a moving body");
            let sweep = Sweep {
                start: s.step_start[i as usize],
                end: (body.position, body.angle),
            };
            (body.position, body.angle) = sweep.at(stop.t);
            if stop.sank {
                body.velocity = (body.position - sweep.start.0) / dt;
                body.angular_velocity = (body.angle - sweep.start.1) / dt;
            }
        }
    }
}
