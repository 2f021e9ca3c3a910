//! The scenes built in Box2D v3 (through the `boxdd` crate, which compiles Box2D's C
//! sources). Box2D's y axis points up, as the scene's does; it works in f32, and results
//! are widened to f64 for the shared trackers. Defaults throughout (4 substeps, contact
//! hertz 30, joint softness from it, one worker, contact recycling on), except sleeping,
//! which is off on every body so that every body is simulated on every step, as in pe and
//! rapier2d here.
//!
//! boxdd's safe API reads a body through a capability borrowed from the world
//! (`World::body`), which takes the world mutably even to read: the trackers get the world
//! as `&mut` for that reason only.

use crate::Outcome;
use crate::harness::{ProfileLog, measure};
use crate::scene::{
    BOB, BOX, BoxPose, FLOOR, FRICTION, G, H, Metric, PeerBody, Pendulum, PeriodTracker, Pyramid,
    PyramidTracker, ReboundTracker, SmashTracker, bounce, chain, joint_grid,
    momentum_and_kinetic_energy, smash, worst,
};
use boxdd::{
    Body, BodyBuilder, BodyId, BodyType, CompletedStep, Foundation, Position, Profile, ShapeDef,
    SurfaceMaterial, Vec2, World, WorldBuilder,
};

/// Box2D's default substep count for `b2World_Step`.
pub const SUBSTEPS: i32 = 4;

/// boxdd's process-wide root, with Box2D's default length unit (1 m). Every thread may ask
/// for it: the first call sets it up, the others get the same one.
pub fn foundation() -> &'static Foundation {
    Foundation::initialize_default().expect("Box2D's default foundation")
}

/// A world with gravity `g` along y, sleeping off, and Box2D's defaults for the rest.
pub fn world_with_gravity(g: f64) -> World {
    let f = foundation();
    let def = WorldBuilder::from(f.world_def())
        .gravity(Vec2::new(0.0, g as f32))
        .enable_sleep(false)
        .build()
        .expect("a valid world definition");
    f.create_world(def).expect("a new world")
}

fn world() -> World {
    world_with_gravity(-G)
}

/// A body definition with Box2D's defaults but sleeping off.
pub fn body_builder(body_type: BodyType) -> BodyBuilder {
    BodyBuilder::from(foundation().body_def())
        .body_type(body_type)
        .enable_sleep(false)
}

pub fn point((x, y): (f64, f64)) -> Position {
    Position::new(x as f32, y as f32)
}

/// One step, its profile kept if asked (`PROFILES`).
pub fn step(w: &mut World, h: f64, substeps: i32) {
    // The completed step holds the step's events, which no scene reads.
    let completed = w
        .step(h as f32, substeps)
        .and_then(CompletedStep::into_result)
        .expect("a valid step");
    drop(completed);
    if PROFILES.keeping() {
        PROFILES.push(w.profile().expect("the last step's profile"));
    }
}

/// Box2D v3's own timing of each step (`b2World_GetProfile`), for `stages`.
pub static PROFILES: ProfileLog<Profile> = ProfileLog::new();

/// Reads one body's state.
pub fn read<T>(
    world: &mut World,
    body: BodyId,
    f: impl FnOnce(&Body<'_>) -> boxdd::Result<T>,
) -> T {
    let body = world.body(body).expect("bodies are never destroyed");
    f(&body).expect("a live body's state")
}

/// A box of full size `w` × `h` on a new body; Box2D mixes friction by the geometric mean
/// and restitution by the maximum.
fn boxed(
    world: &mut World,
    body: BodyBuilder,
    size: (f64, f64),
    density: f64,
    restitution: f64,
) -> BodyId {
    let id = world
        .create_body(body.build().expect("a valid body"))
        .expect("a new body");
    let material = SurfaceMaterial::default()
        .with_friction(FRICTION as f32)
        .and_then(|m| m.with_restitution(restitution as f32))
        .expect("a valid material");
    let shape = ShapeDef::builder()
        .material(material)
        .density(density as f32)
        .build()
        .expect("a valid shape");
    let polygon =
        boxdd::shapes::box_polygon(0.5 * size.0 as f32, 0.5 * size.1 as f32).expect("a valid box");
    world
        .body(id)
        .and_then(|mut b| b.create_polygon(&shape, &polygon))
        .expect("a new shape");
    id
}

fn body_at(body_type: BodyType, centre: (f64, f64)) -> BodyBuilder {
    body_builder(body_type).position(point(centre))
}

fn centre(world: &mut World, body: BodyId) -> (f64, f64) {
    let p = read(world, body, |b| b.position());
    (f64::from(p.x), f64::from(p.y))
}

/// The static floor, its top face at height `top`, restitution 0 (the pair takes the
/// larger).
fn floor(w: &mut World, top: f64) {
    floor_piece(w, (0.0, top - 0.5 * FLOOR.1), FLOOR);
}

/// A static box of the floor.
fn floor_piece(w: &mut World, centre: (f64, f64), size: (f64, f64)) {
    boxed(w, body_at(BodyType::Static, centre), size, 0.0, 0.0);
}

/// A pyramid (or stack) stepped at `h` for `spec.steps`.
pub fn pyramid(spec: &Pyramid, h: f64, substeps: i32) -> Outcome {
    let mut w = world();
    for (centre, size) in spec.floor_pieces() {
        floor_piece(&mut w, centre, size);
    }
    let centres = spec.centres();
    let boxes: Vec<BodyId> = centres
        .iter()
        .map(|&c| boxed(&mut w, body_at(BodyType::Dynamic, c), (BOX, BOX), 1.0, 0.0))
        .collect();
    let mut tracker = PyramidTracker::new(centres);
    let timing = measure(
        &mut w,
        spec.steps,
        |w| step(w, h, substeps),
        |w, _| tracker.update(boxes.iter().map(|&b| centre(w, b))),
    );
    Outcome::new(timing, tracker.finish())
}

/// One body's motion, from its mass properties.
fn motion(world: &mut World, body: BodyId) -> PeerBody {
    read(world, body, |b| {
        let v = b.linear_velocity()?;
        Ok(PeerBody {
            mass: f64::from(b.mass()?),
            inertia: f64::from(b.rotational_inertia()?),
            velocity: (f64::from(v.x), f64::from(v.y)),
            omega: f64::from(b.angular_velocity()?),
            height: f64::from(b.world_center_of_mass()?.y),
        })
    })
}

fn energy(world: &mut World, body: BodyId) -> f64 {
    motion(world, body).energy()
}

/// A pin between two bodies, remembered by its anchor in each body's frame so that its gap
/// can be measured from the bodies' poses.
struct Pin {
    a: BodyId,
    b: BodyId,
    local_a: (f64, f64),
    local_b: (f64, f64),
}

impl Pin {
    fn new(world: &mut World, a: BodyId, b: BodyId, at: (f64, f64)) -> Self {
        world
            .create_revolute_joint_world(a, b, point(at))
            .expect("a new pin");
        let mut local = |body: BodyId| {
            let (cx, cy) = centre(world, body);
            (at.0 - cx, at.1 - cy) // bodies start unrotated
        };
        Self {
            a,
            b,
            local_a: local(a),
            local_b: local(b),
        }
    }

    fn gap(&self, world: &mut World) -> f64 {
        let mut anchor = |body: BodyId, (lx, ly): (f64, f64)| {
            let (cx, cy) = centre(world, body);
            let r = read(world, body, |b| b.rotation());
            let (c, s) = (f64::from(r.cosine()), f64::from(r.sine()));
            (cx + c * lx - s * ly, cy + s * lx + c * ly)
        };
        let (pa, pb) = (anchor(self.a, self.local_a), anchor(self.b, self.local_b));
        (pa.0 - pb.0).hypot(pa.1 - pb.1)
    }
}

/// A static body without shapes at the origin, to pin to.
fn ground(world: &mut World) -> BodyId {
    let def = body_builder(BodyType::Static)
        .build()
        .expect("a valid body");
    world.create_body(def).expect("a new body")
}

pub fn pendulum(spec: &Pendulum, substeps: i32) -> Outcome {
    let mut w = world();
    let pivot = ground(&mut w);
    let body = body_at(BodyType::Dynamic, Pendulum::bob_start());
    let bob = boxed(&mut w, body, (BOB, BOB), 1.0, 0.0);
    let pin = Pin::new(&mut w, pivot, bob, (0.0, 0.0));
    let (x0, e0) = (centre(&mut w, bob).0, energy(&mut w, bob));
    let mut tracker = PeriodTracker::new(spec.h, x0, e0);
    let h = spec.h;
    let timing = measure(
        &mut w,
        spec.steps(),
        |w| step(w, h, substeps),
        |w, n| {
            let (x, e) = (centre(w, bob).0, energy(w, bob));
            tracker.update(n, x, e, pin.gap(w));
        },
    );
    Outcome::new(timing, tracker.finish())
}

pub fn heavy_chain(h: f64, substeps: i32) -> Outcome {
    let mut w = world();
    let mut previous = ground(&mut w);
    let mut pins = Vec::with_capacity(chain::LINKS + 1);
    for i in 0..=chain::LINKS {
        let body = if i < chain::LINKS {
            let body = body_at(BodyType::Dynamic, chain::link_centre(i));
            boxed(&mut w, body, chain::LINK, chain::LINK_DENSITY, 0.0)
        } else {
            let size = (chain::END_SIZE, chain::END_SIZE);
            let body = body_at(BodyType::Dynamic, chain::end_centre());
            boxed(&mut w, body, size, chain::END_DENSITY, 0.0)
        };
        // Box2D's joints leave their bodies' collision off by default, as pe does.
        pins.push(Pin::new(&mut w, previous, body, chain::pin(i)));
        previous = body;
    }
    let mut worst_gap: f64 = 0.0;
    let timing = measure(
        &mut w,
        chain::steps(h),
        |w| step(w, h, substeps),
        |w, _| {
            for pin in &pins {
                worst_gap = worst(worst_gap, pin.gap(w));
            }
        },
    );
    Outcome::new(timing, Metric::Chain { worst_gap })
}

pub fn bounce(h: f64, substeps: i32) -> Outcome {
    let mut w = world();
    floor(&mut w, 0.0);
    let half = 0.5 * bounce::SIZE;
    let start = body_at(BodyType::Dynamic, (0.0, bounce::DROP + half));
    let size = (bounce::SIZE, bounce::SIZE);
    let body = boxed(&mut w, start, size, 1.0, bounce::RESTITUTION);
    let mut tracker = ReboundTracker::default();
    let timing = measure(
        &mut w,
        bounce::steps(h),
        |w| step(w, h, substeps),
        |w, _| {
            let v_up = f64::from(read(w, body, |b| b.linear_velocity()).y);
            tracker.update(centre(w, body).1 - half, v_up);
        },
    );
    Outcome::new(timing, tracker.finish())
}

/// The smash's boxes' poses, in the scene's order.
fn smash_poses(world: &mut World, bodies: &[BodyId]) -> Vec<BoxPose> {
    let pose = |(i, &b): (usize, &BodyId)| {
        let r = read(world, b, |b| b.rotation());
        let angle = f64::from(r.sine()).atan2(f64::from(r.cosine()));
        smash::box_pose(i, centre(world, b), angle)
    };
    bodies.iter().enumerate().map(pose).collect()
}

pub fn smash() -> Outcome {
    let mut w = world_with_gravity(0.0);
    let mut bodies = Vec::with_capacity(smash::ROWS * smash::COLUMNS + 1);
    for c in smash::small_centres() {
        let size = (smash::SMALL, smash::SMALL);
        let body = body_at(BodyType::Dynamic, c);
        bodies.push(boxed(&mut w, body, size, 1.0, 0.0));
    }
    let size = (smash::HEAVY, smash::HEAVY);
    let heavy = body_at(BodyType::Dynamic, smash::heavy_centre())
        .linear_velocity(Vec2::new(smash::SPEED as f32, 0.0));
    bodies.push(boxed(&mut w, heavy, size, smash::HEAVY_DENSITY, 0.0));
    let totals = |w: &mut World| {
        let motions: Vec<PeerBody> = bodies.iter().map(|&b| motion(w, b)).collect();
        momentum_and_kinetic_energy(motions.into_iter())
    };
    let (p0, e0) = totals(&mut w);
    let mut tracker = SmashTracker::new(p0, e0);
    let timing = measure(
        &mut w,
        smash::STEPS,
        |w| step(w, H, SUBSTEPS),
        |w, _| {
            let (p, e) = totals(w);
            tracker.update(p, e, smash_poses(w, &bodies).into_iter());
        },
    );
    Outcome::new(timing, tracker.finish())
}

pub fn joint_grid() -> Outcome {
    let mut w = world();
    let mut bodies = Vec::with_capacity(joint_grid::N * joint_grid::N);
    for r in 0..joint_grid::N {
        for c in 0..joint_grid::N {
            let kind = if joint_grid::is_static(r, c) {
                BodyType::Static
            } else {
                BodyType::Dynamic
            };
            let size = (joint_grid::SIZE, joint_grid::SIZE);
            let body = body_at(kind, joint_grid::centre(r, c));
            bodies.push(boxed(&mut w, body, size, 1.0, 0.0));
        }
    }
    let pins: Vec<Pin> = joint_grid::pins()
        .into_iter()
        .map(|(a, b, p)| Pin::new(&mut w, bodies[a], bodies[b], p))
        .collect();
    let mut worst_gap: f64 = 0.0;
    let timing = measure(
        &mut w,
        joint_grid::STEPS,
        |w| step(w, H, SUBSTEPS),
        |w, _| {
            for pin in &pins {
                worst_gap = worst(worst_gap, pin.gap(w));
            }
        },
    );
    Outcome::new(timing, Metric::Chain { worst_gap })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::PENDULUMS;

    /// The small scenes through the port to boxdd's capability API: each near Box2D v3's
    /// known behaviour (a soft pin that holds to a millimetre, a bounce that loses a quarter
    /// of its height to the soft contact, a heavy chain that stretches).
    #[test]
    fn the_small_scenes_run_as_box2d_runs_them() {
        match pendulum(&PENDULUMS[0], SUBSTEPS).metric {
            Metric::Pendulum {
                period_error,
                energy_drift,
                worst_gap,
            } => {
                assert!(period_error.abs() < 0.005, "{period_error}");
                assert!(energy_drift < 0.05, "{energy_drift}");
                assert!(worst_gap < 2e-3, "{worst_gap}");
            }
            m => panic!("{m}"),
        }
        match bounce(H, SUBSTEPS).metric {
            Metric::Bounce { error, .. } => assert!((-0.4..0.1).contains(&error), "{error}"),
            m => panic!("{m}"),
        }
        match heavy_chain(H, SUBSTEPS).metric {
            Metric::Chain { worst_gap } => {
                assert!(worst_gap.is_finite() && worst_gap < 2.0, "{worst_gap}")
            }
            m => panic!("{m}"),
        }
    }
}
