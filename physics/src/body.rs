//! Rigid bodies: a convex polygon with density, restitution and state (thesis §2.2).

use crate::limits;
use crate::math::{Rot, Vec2, cross, cross_scalar};
use crate::shape::ConvexPolygon;
use thiserror::Error;

/// A body in a [`crate::World`]. Handles are never reused, so a stale one finds nothing.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct BodyHandle(pub u32);

impl BodyHandle {
    pub(crate) fn index(self) -> usize {
        self.0 as usize
    }
}

/// Why a body cannot be built.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum BodyError {
    #[error("density must be a finite number ≥ 0, got {0}")]
    BadDensity(f64),
    #[error("restitution (cor) must lie in [0, 1], got {0}")]
    BadRestitution(f64),
    #[error("friction must be a number in [0, 1e6], got {0}")]
    BadFriction(f64),
    #[error("position and angle must be finite")]
    NonFinitePlacement,
    /// A number beyond its limit in `crate::limits`: what, value, limit.
    #[error("{0} {1:e} is beyond ±{2:e}")]
    Beyond(&'static str, f64, f64),
    /// A positive density too small for its mass or moment of inertia to have an inverse
    /// (below the smallest normal float, whose inverse overflows).
    #[error("density {0:e} gives a mass of {1:e}, too small to simulate (its inverse overflows)")]
    TooLight(f64, f64),
}

/// Everything needed to make a body: shape, material and where it starts, given to
/// [`World::add_body`](crate::World::add_body), which checks it. [`BodyDef::new`] takes
/// the shape and density (0: a static body) and the rest starts at rest at the origin,
/// with no restitution and the world's friction; each setter returns the changed
/// definition.
///
/// A hexagon thrown in empty space moves and turns at the speeds it was given:
///
/// ```
/// use pe::{BodyDef, ConvexPolygon, Vec2, World};
///
/// let mut world = World::new(Vec2::zeros());
/// let hexagon = ConvexPolygon::regular(6, 0.5).unwrap();
/// let area = hexagon.mass_properties().area;
/// let def = BodyDef::new(hexagon, 2.0)
///     .restitution(0.5)
///     .friction(0.3)
///     .at(Vec2::new(0.0, -3.0), 0.0)
///     .velocity(Vec2::new(1.0, 0.0), 0.5);
/// let thrown = world.add_body(def).unwrap();
/// for _ in 0..60 {
///     world.step(1.0 / 60.0);
/// }
/// let body = world.body(thrown).unwrap();
/// assert!((body.position - Vec2::new(1.0, -3.0)).norm() < 1e-9);
/// assert!((body.angle - 0.5).abs() < 1e-9);
/// assert_eq!(body.mass(), 2.0 * area);
/// ```
#[derive(Debug, Clone)]
pub struct BodyDef {
    pub polygon: ConvexPolygon,
    /// Mass per unit area; 0 makes the body static (terrain).
    pub density: f64,
    /// Coefficient of restitution e ∈ [0, 1] (the XML `cor`).
    pub restitution: f64,
    /// Per-body friction coefficient; `None` uses the world's.
    pub friction: Option<f64>,
    /// World position of the vertex frame's origin (the point the XML files place).
    pub origin: Vec2,
    pub angle: f64,
    pub velocity: Vec2,
    pub angular_velocity: f64,
}

impl BodyDef {
    /// `polygon` in its own vertex frame, of `density` (mass per unit area).
    pub fn new(polygon: ConvexPolygon, density: f64) -> Self {
        Self {
            polygon,
            density,
            restitution: 0.0,
            friction: None,
            origin: Vec2::zeros(),
            angle: 0.0,
            velocity: Vec2::zeros(),
            angular_velocity: 0.0,
        }
    }

    pub fn restitution(mut self, e: f64) -> Self {
        self.restitution = e;
        self
    }

    pub fn friction(mut self, mu: f64) -> Self {
        self.friction = Some(mu);
        self
    }

    /// Places the vertex frame's origin at `origin`, turned by `angle` (radians).
    pub fn at(mut self, origin: Vec2, angle: f64) -> Self {
        self.origin = origin;
        self.angle = angle;
        self
    }

    pub fn velocity(mut self, v: Vec2, omega: f64) -> Self {
        self.velocity = v;
        self.angular_velocity = omega;
        self
    }
}

/// A rigid convex body. Its position is its centroid; `local_vertices` are relative to it.
#[derive(Debug, Clone)]
pub struct Body {
    local_vertices: Vec<Vec2>,
    /// The vertex frame's origin in body space (−centroid in the vertex frame).
    local_origin: Vec2,
    radius: f64,
    /// Distance from the centroid to the nearest edge line (the polygon is convex).
    inner_radius: f64,
    mass: f64,
    inertia: f64,
    pub(crate) inv_mass: f64,
    pub(crate) inv_inertia: f64,
    pub restitution: f64,
    pub friction: Option<f64>,
    /// World position of the centroid.
    pub position: Vec2,
    pub angle: f64,
    pub velocity: Vec2,
    pub angular_velocity: f64,
    /// Force and torque accumulated since the last step, cleared by it: add to them (or
    /// call `apply_force_at`) to push the body through the next step.
    pub force: Vec2,
    pub torque: f64,
    /// Asleep: at rest with its island, skipped by the step until something wakes it
    /// (the world's body sets keep it apart from the bodies a step moves).
    pub(crate) asleep: bool,
    /// How long the body has been slower than the sleep tolerance (s).
    pub(crate) still_time: f64,
}

impl Body {
    pub fn new(def: BodyDef) -> Result<Self, BodyError> {
        if !def.density.is_finite() || def.density < 0.0 {
            return Err(BodyError::BadDensity(def.density));
        }
        if !(0.0..=1.0).contains(&def.restitution) {
            return Err(BodyError::BadRestitution(def.restitution));
        }
        if let Some(mu) = def.friction
            && !(0.0..=limits::FRICTION).contains(&mu)
        {
            return Err(BodyError::BadFriction(mu));
        }
        let finite = |v: Vec2| v.x.is_finite() && v.y.is_finite();
        if !finite(def.origin)
            || !def.angle.is_finite()
            || !finite(def.velocity)
            || !def.angular_velocity.is_finite()
        {
            return Err(BodyError::NonFinitePlacement);
        }
        let vertices = def.polygon.vertices().iter().flat_map(|v| [v.x, v.y]);
        let numbers = [
            ("density", def.density, limits::DENSITY),
            ("x", def.origin.x, limits::COORDINATE),
            ("y", def.origin.y, limits::COORDINATE),
            ("angle", def.angle, limits::ANGLE),
            ("speed", def.velocity.norm(), limits::SPEED),
            ("spin", def.angular_velocity, limits::SPIN),
        ]
        .into_iter()
        .chain(vertices.map(|v| ("vertex coordinate", v, limits::COORDINATE)));
        if let Some((what, value, limit)) = limits::first_beyond(numbers) {
            return Err(BodyError::Beyond(what, value, limit));
        }
        let mp = def.polygon.mass_properties();
        let local_vertices: Vec<Vec2> = def
            .polygon
            .vertices()
            .iter()
            .map(|v| v - mp.centroid)
            .collect();
        let radius = local_vertices.iter().map(|v| v.norm()).fold(0.0, f64::max);
        let n = local_vertices.len();
        let inner_radius = (0..n)
            .map(|i| {
                let (a, b) = (local_vertices[i], local_vertices[(i + 1) % n]);
                crate::math::cross(b - a, -a).abs() / (b - a).norm()
            })
            .fold(f64::INFINITY, f64::min);
        let (mass, inertia) = (def.density * mp.area, def.density * mp.second_moment);
        if def.density > 0.0 && !(mass.is_normal() && inertia.is_normal()) {
            return Err(BodyError::TooLight(def.density, mass.min(inertia)));
        }
        let inverse = |x: f64| if x > 0.0 { 1.0 / x } else { 0.0 };
        Ok(Self {
            local_vertices,
            local_origin: -mp.centroid,
            radius,
            inner_radius,
            mass,
            inertia,
            inv_mass: inverse(mass),
            inv_inertia: inverse(inertia),
            restitution: def.restitution,
            friction: def.friction,
            position: def.origin + Rot::new(def.angle).apply(mp.centroid),
            angle: def.angle,
            velocity: def.velocity,
            angular_velocity: def.angular_velocity,
            force: Vec2::zeros(),
            torque: 0.0,
            asleep: false,
            still_time: 0.0,
        })
    }

    /// Density 0: never moves.
    pub fn is_static(&self) -> bool {
        self.mass == 0.0
    }
    /// Static, or asleep: the step does not move it.
    pub(crate) fn is_fixed(&self) -> bool {
        self.is_static() || self.asleep
    }
    pub fn is_asleep(&self) -> bool {
        self.asleep
    }
    /// Asleep: still where it is until woken.
    pub(crate) fn fall_asleep(&mut self) {
        self.asleep = true;
        (self.velocity, self.angular_velocity) = (Vec2::zeros(), 0.0);
    }
    pub(crate) fn wake(&mut self) {
        self.asleep = false;
        self.still_time = 0.0;
    }
    /// Mass; 0 for a static body (whose mass is really infinite).
    pub fn mass(&self) -> f64 {
        self.mass
    }
    /// Moment of inertia about the centroid; 0 for a static body.
    pub fn inertia(&self) -> f64 {
        self.inertia
    }
    /// The body's motion as numbers: centroid x and y, angle, velocity x and y, angular
    /// velocity (what a trace compares bit for bit, and what must stay finite).
    pub fn state(&self) -> [f64; 6] {
        [
            self.position.x,
            self.position.y,
            self.angle,
            self.velocity.x,
            self.velocity.y,
            self.angular_velocity,
        ]
    }

    /// The radius of the largest circle about the centroid inside the body: a body moving
    /// less than half this per step cannot pass through anything.
    pub(crate) fn inner_radius(&self) -> f64 {
        self.inner_radius
    }

    /// Distance from the centroid to the farthest vertex.
    pub fn bounding_radius(&self) -> f64 {
        self.radius
    }
    /// Vertices relative to the centroid, in body axes.
    pub(crate) fn local_vertices(&self) -> &[Vec2] {
        &self.local_vertices
    }

    /// Its position and angle bit for bit: equal to an earlier one exactly when the body
    /// is where it was then, so that what was computed from its pose still holds.
    pub(crate) fn place(&self) -> [u64; 3] {
        [self.position.x, self.position.y, self.angle].map(f64::to_bits)
    }

    pub(crate) fn rotation(&self) -> Rot {
        Rot::new(self.angle)
    }

    /// World position of a body-space point.
    pub fn to_world(&self, local: Vec2) -> Vec2 {
        self.position + self.rotation().apply(local)
    }

    /// Body-space position of a world point.
    pub fn to_local(&self, world: Vec2) -> Vec2 {
        self.rotation().apply_inverse(world - self.position)
    }

    pub fn world_vertices(&self) -> impl Iterator<Item = Vec2> + '_ {
        let rot = self.rotation();
        self.local_vertices
            .iter()
            .map(move |v| self.position + rot.apply(*v))
    }

    /// World position of the centre of mass.
    pub fn centroid(&self) -> Vec2 {
        self.position
    }

    /// World position of the vertex frame's origin: the point the XML files place.
    pub fn origin(&self) -> Vec2 {
        self.to_world(self.local_origin)
    }

    /// Velocity of the material point at `world_point` (thesis eq. 1).
    pub fn velocity_at(&self, world_point: Vec2) -> Vec2 {
        self.velocity + cross_scalar(self.angular_velocity, world_point - self.position)
    }

    /// A force at a world point: also a torque `r ⊗ F` (thesis §2.2).
    pub fn apply_force_at(&mut self, force: Vec2, world_point: Vec2) {
        self.force += force;
        self.torque += cross(world_point - self.position, force);
    }

    /// An impulse at a world point changes the velocities at once (thesis eq. 5–6). A
    /// static or sleeping body takes none: wake it first (`World::wake_body`).
    pub fn apply_impulse_at(&mut self, impulse: Vec2, world_point: Vec2) {
        if self.is_fixed() {
            return;
        }
        self.velocity += impulse * self.inv_mass;
        self.angular_velocity += cross(world_point - self.position, impulse) * self.inv_inertia;
    }

    pub(crate) fn kinetic_energy(&self) -> f64 {
        0.5 * (self.mass * self.velocity.norm_squared()
            + self.inertia * self.angular_velocity * self.angular_velocity)
    }

    /// Angular momentum about the world origin: spin plus `p × m v`.
    pub(crate) fn angular_momentum(&self) -> f64 {
        self.inertia * self.angular_velocity + self.mass * cross(self.position, self.velocity)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rect(w: f64, h: f64) -> ConvexPolygon {
        ConvexPolygon::rectangle(w, h).unwrap()
    }

    #[test]
    fn density_scales_mass_and_inertia() {
        for rho in [0.5, 1.0, 7.0] {
            let b = Body::new(BodyDef::new(rect(3.0, 1.0), rho)).unwrap();
            assert!((b.mass() - rho * 3.0).abs() < 1e-12);
            assert!((b.inertia() - rho * 3.0 * (9.0 + 1.0) / 12.0).abs() < 1e-12);
            assert_eq!(b.inv_mass, 1.0 / b.mass());
        }
    }

    #[test]
    fn zero_density_is_static() {
        let b = Body::new(BodyDef::new(rect(3.0, 1.0), 0.0)).unwrap();
        assert!(b.is_static());
        assert_eq!((b.inv_mass, b.inv_inertia), (0.0, 0.0));
    }

    #[test]
    fn bad_material_is_refused() {
        assert_eq!(
            Body::new(BodyDef::new(rect(1., 1.), -1.0)).err(),
            Some(BodyError::BadDensity(-1.0))
        );
        assert!(matches!(
            Body::new(BodyDef::new(rect(1., 1.), f64::NAN)),
            Err(BodyError::BadDensity(_))
        ));
        assert_eq!(
            Body::new(BodyDef::new(rect(1., 1.), 1.0).restitution(1.5)).err(),
            Some(BodyError::BadRestitution(1.5))
        );
    }

    #[test]
    fn origin_and_centroid_are_both_tracked() {
        // A triangle whose centroid (1, 1) is off its vertex-frame origin.
        let tri =
            ConvexPolygon::new(&[Vec2::new(0., 0.), Vec2::new(3., 0.), Vec2::new(0., 3.)]).unwrap();
        let angle = std::f64::consts::FRAC_PI_2;
        let b = Body::new(BodyDef::new(tri, 1.0).at(Vec2::new(10., 20.), angle)).unwrap();
        assert!((b.origin() - Vec2::new(10., 20.)).norm() < 1e-12);
        // R(90°)·(1, 1) = (−1, 1).
        assert!((b.centroid() - Vec2::new(9., 21.)).norm() < 1e-12);
    }

    #[test]
    fn impulse_off_centre_spins() {
        let mut b = Body::new(BodyDef::new(rect(2.0, 2.0), 1.0)).unwrap();
        b.apply_impulse_at(Vec2::new(0.0, 1.0), Vec2::new(1.0, 0.0));
        assert!((b.velocity.y - 0.25).abs() < 1e-15);
        // I = 4·8/12; τ-impulse = 1 ⊗ ... = 1.
        assert!((b.angular_velocity - 1.0 / (32.0 / 12.0)).abs() < 1e-15);
    }
}
