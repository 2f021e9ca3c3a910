//! Each body's outline, pose, reach and bounds for a step, kept by slot: the awake
//! bodies' made again at every step, the static and sleeping bodies' only when the sets
//! change (or the step length or the contact margin does).

use super::body_sets::{BodySets, EpochSeen, Slots};
use crate::body::Body;
use crate::collide::reuse::Pose;
use crate::collide::{Aabb, WorldPolygon};
use crate::math::Vec2;

#[derive(Debug, Clone, Default)]
pub(super) struct BodyBounds {
    /// Each body's outline in the world.
    pub(super) polygons: Vec<WorldPolygon>,
    /// The place (`Body::place`) and pose each outline was made at, and its bounds: a
    /// body where it was keeps them without being turned again.
    outlined_at: Vec<Option<([u64; 3], Pose, Aabb)>>,
    pub(super) poses: Vec<Pose>,
    /// The outlines' bounds grown by half the contact margin and the body's reach.
    pub(super) boxes: Vec<Option<Aabb>>,
    /// How far each body can move in the step, and the two parts of it: its centroid's
    /// displacement at its current velocity, and how far its spin can carry its farthest
    /// point.
    pub(super) reach: Vec<f64>,
    pub(super) motion: Vec<(Vec2, f64)>,
    /// When the static and sleeping bodies' were made, and for which step length and
    /// contact margin (bits).
    made: EpochSeen,
    made_at: Option<(u64, u64)>,
}

impl BodyBounds {
    /// Makes the bounds of the bodies for a step of `dt`: the awake ones', or everyone's
    /// if the sets, `dt` or `margin` changed since the last time. Returns the slots made.
    pub(super) fn make<'s>(
        &mut self,
        bodies: &[Option<Body>],
        sets: &'s BodySets,
        dt: f64,
        margin: f64,
    ) -> Slots<'s> {
        let n = bodies.len();
        let made_at = Some((dt.to_bits(), margin.to_bits()));
        let whole = self.made_at == made_at && self.boxes.len() == n;
        let made = sets.to_remake(&mut self.made, whole, n);
        if made.every() {
            self.made_at = made_at;
            self.polygons.resize_with(n, WorldPolygon::default);
            self.outlined_at.resize(n, None);
            self.boxes.resize(n, None);
            self.reach.resize(n, 0.0);
            self.motion.resize(n, (Vec2::zeros(), 0.0));
            self.poses.resize(n, Pose::default());
        }
        for i in made.clone() {
            let body = bodies[i as usize].as_ref();
            let velocity = body.map_or((Vec2::zeros(), 0.0), |b| sets.velocity_in_pass(i, b));
            self.make_one(i as usize, body, velocity, dt, margin);
        }
        made
    }

    /// `velocity`: the body's velocity and spin as the pass sees them.
    fn make_one(
        &mut self,
        i: usize,
        body: Option<&Body>,
        (velocity, angular_velocity): (Vec2, f64),
        dt: f64,
        margin: f64,
    ) {
        // The speed of its farthest point from the spin alone.
        let spin = body.map_or(0.0, |b| angular_velocity.abs() * b.bounding_radius());
        let reach = (velocity.norm() + spin) * dt;
        self.reach[i] = reach;
        self.motion[i] = (velocity * dt, spin * dt);
        let (polygon, outlined_at) = (&mut self.polygons[i], &mut self.outlined_at[i]);
        let outline = body.map(|b| {
            // A body where it was when its outline was last made (a static one, one
            // asleep, one at rest to the last bit) keeps that outline, its normals, its
            // pose and its bounds: the same numbers, without turning it again.
            let place = b.place();
            if outlined_at.is_none_or(|(at, ..)| at != place) {
                let pose = Pose::of(b);
                polygon.set_outline(b.local_vertices().iter().map(|&v| pose.to_world(v)));
                *outlined_at = Some((place, pose, polygon.aabb()));
            }
            outlined_at.expect("set above")
        });
        self.poses[i] = outline.map_or(Pose::default(), |(_, pose, _)| pose);
        self.boxes[i] = outline.map(|(.., aabb)| aabb.grown(0.5 * margin + reach));
    }

    /// What the static and sleeping bodies' bounds were last made for: the sets' epoch,
    /// the step length and the contact margin (bits).
    pub(super) fn made_for(&self) -> Option<(u64, u64, u64)> {
        let (dt, margin) = self.made_at?;
        Some((self.made.epoch()?, dt, margin))
    }
}
