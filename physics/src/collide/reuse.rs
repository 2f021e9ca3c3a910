//! Manifold reuse: a pair whose relative pose has barely changed since its manifold was
//! found keeps that manifold's features, with depths and positions recomputed at the
//! current poses, instead of running the separating-axis test again.
//!
//! A manifold point is an incident vertex (or a clipped point on an incident edge) against
//! the reference edge's line. Both are stored in their own body's frame, so a reused point
//! is the same material point SAT would clip, and its depth is SAT's formula at the current
//! poses. What reuse can miss is a change of features: a clipped point sliding along its
//! edge, or another edge becoming the reference. Both need the relative pose to move by
//! more than the tolerance, which is kept far below the contact slop.

use super::{ContactPoint, FeatureId, Manifold};
use crate::body::{Body, BodyHandle};
use crate::math::{Rot, Vec2};

/// Where a body is for the narrow phase: centroid, rotation, and the radius of the circle
/// about the centroid that holds it.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct Pose {
    pub position: Vec2,
    pub rotation: Rot,
    pub angle: f64,
    pub radius: f64,
}

impl Pose {
    pub(crate) fn of(body: &Body) -> Self {
        Self {
            position: body.position,
            rotation: body.rotation(),
            angle: body.angle,
            radius: body.bounding_radius(),
        }
    }

    /// A point given in the body's frame (about its centroid), in world coordinates.
    pub(crate) fn to_world(self, local: Vec2) -> Vec2 {
        self.position + self.rotation.apply(local)
    }

    fn to_local(self, world: Vec2) -> Vec2 {
        self.rotation.apply_inverse(world - self.position)
    }
}

/// B's centroid in A's frame and B's angle less A's.
fn relative_pose(a: &Pose, b: &Pose) -> (Vec2, f64) {
    (a.to_local(b.position), b.angle - a.angle)
}

#[derive(Debug, Clone, Copy, PartialEq)]
struct CachedPoint {
    /// On the incident body, in its frame.
    incident: Vec2,
    /// On the reference edge's line, in the reference body's frame.
    reference: Vec2,
    id: FeatureId,
}

#[derive(Debug, Clone, Copy, PartialEq)]
struct CachedManifold {
    pair: (u32, u32),
    relative: (Vec2, f64),
    margin: f64,
    reference_is_b: bool,
    /// The reference edge's outward normal in the reference body's frame.
    normal: Vec2,
    points: [CachedPoint; 2],
    len: u8,
}

/// Last step's manifolds, sorted by pair, and this step's as they are found.
///
/// A pile at rest reuses every manifold of the last step, in order: this step's are then
/// the first `kept_in_place` of `last`, and they are copied into `next` only once the
/// step parts from them (a new pair's manifold stored, or one of `last`'s left out); a
/// pair found afresh replaces its own manifold there.
#[derive(Debug, Clone, Default)]
pub(crate) struct ManifoldCache {
    last: Vec<CachedManifold>,
    next: Vec<CachedManifold>,
    cursor: usize,
    /// `Some(n)`: this step's manifolds so far are `last[..n]`, and `next` is unused.
    kept_in_place: Option<usize>,
}

impl ManifoldCache {
    /// Starts a step: the manifolds kept in the last one become the ones to reuse. Pairs
    /// must then be visited in increasing order.
    pub(crate) fn begin_step(&mut self) {
        match self.kept_in_place {
            Some(kept) => self.last.truncate(kept),
            None => std::mem::swap(&mut self.last, &mut self.next),
        }
        self.next.clear();
        self.cursor = 0;
        self.kept_in_place = Some(0);
    }

    /// Forgets every manifold.
    pub(crate) fn clear(&mut self) {
        self.last.clear();
        self.next.clear();
        self.cursor = 0;
        self.kept_in_place = None;
    }

    /// This step's manifolds so far into `next`, if they were still kept in place.
    fn part_from_last(&mut self) {
        if let Some(kept) = self.kept_in_place.take() {
            self.next.extend_from_slice(&self.last[..kept]);
        }
    }

    /// The last step's manifold at `cursor`, reused: kept in place if it follows the ones
    /// kept so far, else copied into `next`.
    fn keep(&mut self) {
        match &mut self.kept_in_place {
            Some(kept) if *kept == self.cursor => *kept += 1,
            _ => {
                self.part_from_last();
                self.next.push(self.last[self.cursor]);
            }
        }
    }

    /// Pushes onto `manifolds` the pair's last manifold at the current poses, if the pair
    /// has moved relative to itself by less than `tolerance` (at any point of either body)
    /// since it was found, `margin` is no wider than it was then, and a point is still
    /// within `margin`. `false` asks for a fresh test, whose result goes to `store`.
    ///
    /// The manifold is written into the list once, from its points as values. Made in
    /// memory point by point and then copied there whole, the copy's wide loads waited on
    /// the narrower stores just made (a store cannot be forwarded to a load wider than
    /// it): over a third of large_pyramid's narrow phase.
    pub(crate) fn reuse_into(
        &mut self,
        (a, pose_a): (BodyHandle, &Pose),
        (b, pose_b): (BodyHandle, &Pose),
        (margin, tolerance): (f64, f64),
        manifolds: &mut Vec<Manifold>,
    ) -> bool {
        let pair = (a.0, b.0);
        while self.last.get(self.cursor).is_some_and(|c| c.pair < pair) {
            self.cursor += 1;
        }
        let Some(cached) = self.last.get(self.cursor).filter(|c| c.pair == pair) else {
            return false;
        };
        let (offset, turn) = relative_pose(pose_a, pose_b);
        // The shift within what the turn leaves of the tolerance, compared squared: the
        // square root's latency held up every pair.
        let left = tolerance - (turn - cached.relative.1).abs() * pose_a.radius.max(pose_b.radius);
        let shift = offset - cached.relative.0;
        if left < 0.0 || shift.norm_squared() > left * left || margin > cached.margin {
            return false;
        }
        let (reference, incident) = if cached.reference_is_b {
            (pose_b, pose_a)
        } else {
            (pose_a, pose_b)
        };
        let u = reference.rotation.apply(cached.normal);
        // Points as values (see above); a kept manifold has one or two.
        let point_at = |p: &CachedPoint| {
            let point = incident.to_world(p.incident);
            let separation = u.dot(&(point - reference.to_world(p.reference)));
            (separation <= margin).then(|| ContactPoint {
                position: point - u * (0.5 * separation),
                depth: -separation,
                id: p.id,
            })
        };
        let first = point_at(&cached.points[0]);
        let second = (cached.len == 2)
            .then(|| point_at(&cached.points[1]))
            .flatten();
        let points = match (first, second) {
            (Some(p), Some(q)) => ([p, q], 2),
            (Some(p), None) | (None, Some(p)) => ([p, ContactPoint::default()], 1),
            (None, None) => return false,
        };
        let normal = if cached.reference_is_b { u } else { -u };
        manifolds.push(Manifold::with_points(
            (a, b),
            normal,
            points,
            cached.reference_is_b,
        ));
        self.keep();
        true
    }

    /// Keeps a freshly found manifold for the next steps.
    pub(crate) fn store(
        &mut self,
        manifold: &Manifold,
        (pose_a, pose_b): (&Pose, &Pose),
        margin: f64,
    ) {
        if manifold.points().is_empty() {
            return;
        }
        // The normal is the reference normal, or its opposite when the reference is A's.
        let reference_is_b = manifold.reference_is_b;
        let (reference, incident, u) = if reference_is_b {
            (pose_b, pose_a, manifold.normal)
        } else {
            (pose_a, pose_b, -manifold.normal)
        };
        let mut points = [CachedPoint {
            incident: Vec2::zeros(),
            reference: Vec2::zeros(),
            id: FeatureId(0),
        }; 2];
        for (slot, p) in points.iter_mut().zip(manifold.points()) {
            // position = incident point − u·separation/2, with separation = −depth.
            let point = p.position - u * (0.5 * p.depth);
            *slot = CachedPoint {
                incident: incident.to_local(point),
                reference: reference.to_local(point + u * p.depth),
                id: p.id,
            };
        }
        let stored = CachedManifold {
            pair: (manifold.body_a.0, manifold.body_b.0),
            relative: relative_pose(pose_a, pose_b),
            margin,
            reference_is_b,
            normal: reference.rotation.apply_inverse(u),
            points,
            len: manifold.points().len() as u8,
        };
        // A pair found afresh where its last manifold lies next among those kept in place
        // replaces it there: a pile whose one base box creeps has that pair tested afresh
        // every step, and parting there copied every manifold after it (large_pyramid:
        // its first pair, then 15,000 manifolds of 144 bytes a step).
        match &mut self.kept_in_place {
            Some(kept)
                if *kept == self.cursor
                    && self.last.get(*kept).is_some_and(|c| c.pair == stored.pair) =>
            {
                self.last[*kept] = stored;
                *kept += 1;
            }
            _ => {
                self.part_from_last();
                self.next.push(stored);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::collide::WorldPolygon;
    use crate::collide::sat::collide_polygons;

    impl ManifoldCache {
        /// `reuse_into` a list of its own: the manifold reused, if any.
        fn reuse(
            &mut self,
            a: (BodyHandle, &Pose),
            b: (BodyHandle, &Pose),
            margin: f64,
            tolerance: f64,
        ) -> Option<Manifold> {
            let mut manifolds = Vec::new();
            self.reuse_into(a, b, (margin, tolerance), &mut manifolds)
                .then(|| manifolds[0])
        }
    }

    fn unit_square() -> Vec<Vec2> {
        vec![
            Vec2::new(-0.5, -0.5),
            Vec2::new(0.5, -0.5),
            Vec2::new(0.5, 0.5),
            Vec2::new(-0.5, 0.5),
        ]
    }

    fn placed(local: &[Vec2], position: Vec2, angle: f64) -> (WorldPolygon, Pose) {
        let pose = Pose {
            position,
            rotation: Rot::new(angle),
            angle,
            radius: local.iter().map(|v| v.norm()).fold(0.0, f64::max),
        };
        let mut polygon = WorldPolygon::default();
        polygon.set_vertices(local.iter().map(|&v| pose.to_world(v)));
        (polygon, pose)
    }

    /// A box resting on a wider slab, one of them turned a little, then nudged by up to
    /// the tolerance in every direction and turn: the reused manifold has SAT's features
    /// and normal, and depths and positions within what that motion can change (a clipped
    /// point slides with the other body; depths move by slide × tilt).
    #[test]
    fn reused_manifold_matches_a_fresh_test_after_small_motion() {
        let slab: Vec<Vec2> = [(-3.0, -0.5), (3.0, -0.5), (3.0, 0.5), (-3.0, 0.5)]
            .iter()
            .map(|&(x, y)| Vec2::new(x, y))
            .collect();
        let (margin, tie, tolerance) = (0.02, 0.001, 5e-4);
        let (handle_a, handle_b) = (BodyHandle(0), BodyHandle(1));
        let mut references_seen = [false; 2];
        for slab_first in [false, true] {
            for (box_tilt, slab_tilt) in [(0.0, 0.0), (0.002, 0.0), (0.0, 0.002)] {
                let box_at = Vec2::new(0.3, 0.999);
                let (a, b) = if slab_first {
                    (
                        (slab.clone(), Vec2::zeros(), slab_tilt),
                        (unit_square(), box_at, box_tilt),
                    )
                } else {
                    (
                        (unit_square(), -box_at, box_tilt),
                        (slab.clone(), Vec2::zeros(), slab_tilt),
                    )
                };
                let (poly_a, pose_a) = placed(&a.0, a.1, a.2);
                let (poly_b, pose_b) = placed(&b.0, b.1, b.2);
                let first = collide_polygons((handle_a, &poly_a), (handle_b, &poly_b), margin, tie)
                    .expect("in contact");
                references_seen[first.reference_is_b as usize] = true;
                let mut cache = ManifoldCache::default();
                cache.store(&first, (&pose_a, &pose_b), margin);
                for k in 0..16 {
                    let heading = k as f64 * std::f64::consts::TAU / 16.0;
                    let shift = Vec2::new(heading.cos(), heading.sin()) * (0.4 * tolerance);
                    let turn = 0.4 * tolerance / pose_a.radius.max(pose_b.radius) * heading.sin();
                    // The box moves; the slab stays.
                    let ((poly_a2, pose_a2), (poly_b2, pose_b2)) = if slab_first {
                        (
                            (poly_a.clone(), pose_a),
                            placed(&b.0, b.1 + shift, b.2 + turn),
                        )
                    } else {
                        (
                            placed(&a.0, a.1 + shift, a.2 + turn),
                            (poly_b.clone(), pose_b),
                        )
                    };
                    cache.begin_step();
                    let reused = cache
                        .reuse(
                            (handle_a, &pose_a2),
                            (handle_b, &pose_b2),
                            margin,
                            tolerance,
                        )
                        .expect("within the tolerance");
                    let fresh =
                        collide_polygons((handle_a, &poly_a2), (handle_b, &poly_b2), margin, tie)
                            .expect("in contact");
                    assert!((reused.normal - fresh.normal).norm() < 1e-12);
                    assert_eq!(reused.points().len(), fresh.points().len());
                    for (r, f) in reused.points().iter().zip(fresh.points()) {
                        assert_eq!(r.id, f.id);
                        assert!((r.depth - f.depth).abs() < 1e-6, "{} {}", r.depth, f.depth);
                        assert!((r.position - f.position).norm() <= tolerance);
                    }
                }
                // Measured against the manifold's first pose, not the last step's: beyond
                // the tolerance from there, a fresh test is asked for.
                let far = |pose: &Pose| Pose {
                    position: pose.position + Vec2::new(1.1 * tolerance, 0.0),
                    ..*pose
                };
                cache.begin_step();
                let (pa, pb) = if slab_first {
                    (pose_a, far(&pose_b))
                } else {
                    (far(&pose_a), pose_b)
                };
                assert!(
                    cache
                        .reuse((handle_a, &pa), (handle_b, &pb), margin, tolerance)
                        .is_none()
                );
            }
        }
        assert_eq!(
            references_seen,
            [true, true],
            "both bodies served as reference"
        );
    }

    /// What a step keeps for the next: the manifolds it reused or stored, in pair order,
    /// whether all of the last step's were reused in place, one was left out, or one was
    /// stored afresh between two reused ones.
    #[test]
    fn a_step_keeps_what_it_reused_and_stored() {
        let (poly_a, pose_a) = placed(&unit_square(), Vec2::zeros(), 0.0);
        let (poly_b, pose_b) = placed(&unit_square(), Vec2::new(0.0, 0.999), 0.0);
        let (margin, tie, tolerance) = (0.02, 0.001, 5e-4);
        let manifold = |(i, j): (u32, u32)| {
            collide_polygons(
                (BodyHandle(i), &poly_a),
                (BodyHandle(j), &poly_b),
                margin,
                tie,
            )
            .expect("in contact")
        };
        let pairs = [(0, 1), (0, 2), (1, 2)];
        let reuse = |cache: &mut ManifoldCache, (i, j): (u32, u32)| {
            let found = (BodyHandle(i), &pose_a);
            cache.reuse(found, (BodyHandle(j), &pose_b), margin, tolerance)
        };
        let mut cache = ManifoldCache::default();
        for pair in pairs {
            cache.store(&manifold(pair), (&pose_a, &pose_b), margin);
        }
        // Every one reused, twice over (kept in place).
        for _ in 0..2 {
            cache.begin_step();
            for pair in pairs {
                assert!(reuse(&mut cache, pair).is_some());
            }
        }
        // (0, 2) left out: gone at the next step.
        cache.begin_step();
        assert!(reuse(&mut cache, (0, 1)).is_some());
        assert!(reuse(&mut cache, (1, 2)).is_some());
        cache.begin_step();
        assert!(reuse(&mut cache, (0, 1)).is_some());
        assert!(reuse(&mut cache, (0, 2)).is_none());
        // Stored afresh between the two reused ones: all three are there next.
        cache.store(&manifold((0, 2)), (&pose_a, &pose_b), margin);
        assert!(reuse(&mut cache, (1, 2)).is_some());
        cache.begin_step();
        for pair in pairs {
            assert!(reuse(&mut cache, pair).is_some(), "{pair:?}");
        }
        // A step that visits nothing keeps nothing.
        cache.begin_step();
        cache.begin_step();
        assert!(reuse(&mut cache, (0, 1)).is_none());
    }

    /// A pair tested afresh whose last manifold is the next one kept in place replaces it
    /// there: the step keeps its manifolds in place, and the next reuses the new one and
    /// the rest.
    #[test]
    fn a_pair_found_afresh_replaces_its_last_manifold_in_place() {
        let (poly_a, pose_a) = placed(&unit_square(), Vec2::zeros(), 0.0);
        let (poly_b, pose_b) = placed(&unit_square(), Vec2::new(0.0, 0.999), 0.0);
        let (margin, tie, tolerance) = (0.02, 0.001, 5e-4);
        let wider = 2.0 * margin;
        let manifold = |(i, j): (u32, u32), margin: f64| {
            let (a, b) = ((BodyHandle(i), &poly_a), (BodyHandle(j), &poly_b));
            collide_polygons(a, b, margin, tie).expect("in contact")
        };
        let reuse = |cache: &mut ManifoldCache, (i, j): (u32, u32), margin: f64| {
            let found = (BodyHandle(i), &pose_a);
            cache.reuse(found, (BodyHandle(j), &pose_b), margin, tolerance)
        };
        let pairs = [(0, 1), (0, 2), (1, 2)];
        let mut cache = ManifoldCache::default();
        for pair in pairs {
            cache.store(&manifold(pair, margin), (&pose_a, &pose_b), margin);
        }
        cache.begin_step();
        // The first pair's margin widens: refused, found afresh, stored where it was.
        assert!(reuse(&mut cache, (0, 1), wider).is_none());
        cache.store(&manifold((0, 1), wider), (&pose_a, &pose_b), wider);
        assert_eq!(cache.kept_in_place, Some(1));
        for pair in &pairs[1..] {
            assert!(reuse(&mut cache, *pair, margin).is_some(), "{pair:?}");
        }
        assert_eq!(cache.kept_in_place, Some(3));
        cache.begin_step();
        let kept: Vec<_> = cache.last.iter().map(|c| (c.pair, c.margin)).collect();
        assert_eq!(kept, [((0, 1), wider), ((0, 2), margin), ((1, 2), margin)]);
        assert!(reuse(&mut cache, (0, 1), wider).is_some());
        for pair in &pairs[1..] {
            assert!(reuse(&mut cache, *pair, margin).is_some(), "{pair:?}");
        }
    }

    /// The two other refusals: a margin wider than the cached manifold's (it may have left
    /// points out), and cached points beyond a narrower margin, which are dropped as a
    /// fresh test would leave them out.
    #[test]
    fn a_wider_margin_asks_afresh_and_a_narrower_one_drops_far_points() {
        let slab: Vec<Vec2> = [(-3.0, -0.5), (3.0, -0.5), (3.0, 0.5), (-3.0, 0.5)]
            .iter()
            .map(|&(x, y)| Vec2::new(x, y))
            .collect();
        let (tie, tolerance) = (0.001, 5e-4);
        let (handle_a, handle_b) = (BodyHandle(0), BodyHandle(1));
        // The box tilted so that one bottom corner is 0.003 into the slab and the other
        // 0.007 above it.
        let (poly_a, pose_a) = placed(&slab, Vec2::zeros(), 0.0);
        let (poly_b, pose_b) = placed(&unit_square(), Vec2::new(0.0, 1.002), 0.01);
        let wide = 0.02;
        let first = collide_polygons((handle_a, &poly_a), (handle_b, &poly_b), wide, tie)
            .expect("in contact");
        assert_eq!(first.points().len(), 2);
        // A refused pair leaves the cache until its fresh manifold is stored: each case
        // starts from a cache holding the manifold found above.
        let cache_of_first = || {
            let mut cache = ManifoldCache::default();
            cache.store(&first, (&pose_a, &pose_b), wide);
            cache.begin_step();
            cache
        };
        let wider =
            cache_of_first().reuse((handle_a, &pose_a), (handle_b, &pose_b), 0.03, tolerance);
        assert!(wider.is_none(), "a wider margin needs a fresh test");
        let narrow = 0.005;
        let reused = cache_of_first()
            .reuse((handle_a, &pose_a), (handle_b, &pose_b), narrow, tolerance)
            .expect("one point is still within the margin");
        let fresh = collide_polygons((handle_a, &poly_a), (handle_b, &poly_b), narrow, tie)
            .expect("in contact");
        assert_eq!(reused.points().len(), 1);
        assert_eq!(fresh.points().len(), 1);
        assert_eq!(reused.points()[0].id, fresh.points()[0].id);
        assert!((reused.points()[0].depth - fresh.points()[0].depth).abs() < 1e-12);
    }
}
