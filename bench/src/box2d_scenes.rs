//! The scenes built in Box2D v3 (through the `boxdd` crate, which compiles Box2D's C
//! sources). Box2D's y axis points up, as the scene's does; it works in f32, and results
//! are widened to f64 for the shared trackers. Defaults throughout (4 substeps, contact
//! hertz 30, joint softness from it), except sleeping, which is off on every body so
//! that every body is simulated on every step, as in pe and rapier2d here.

use crate::Outcome;
use crate::harness::{ProfileLog, measure};
use crate::scene::{
    BOB, BOX, BoxPose, FLOOR, FRICTION, G, H, Metric, PeerBody, Pendulum, PeriodTracker, Pyramid,
    PyramidTracker, ReboundTracker, SmashTracker, bounce, chain, joint_grid,
    momentum_and_kinetic_energy, smash, worst,
};
use boxdd::{
    BodyBuilder, BodyId, BodyType, Profile, ShapeDef, SurfaceMaterial, Vec2, World, WorldDef,
};

/// Box2D's default substep count for `b2World_Step`.
pub const SUBSTEPS: i32 = 4;

fn point((x, y): (f64, f64)) -> Vec2 {
    Vec2::new(x as f32, y as f32)
}

fn world() -> World {
    let def = WorldDef::builder()
        .gravity([0.0, -G as f32])
        .enable_sleep(false)
        .build();
    World::new(def).expect("a valid world definition")
}

fn step(w: &mut World, h: f64, substeps: i32) {
    w.step(h as f32, substeps);
    if PROFILES.keeping() {
        PROFILES.push(w.profile());
    }
}

/// Box2D v3's own timing of each step (`b2World_GetProfile`), for `stages`.
pub static PROFILES: ProfileLog<Profile> = ProfileLog::new();

/// A box of full size `w` × `h` on a new body; Box2D mixes friction by the geometric mean
/// and restitution by the maximum.
fn boxed(
    world: &mut World,
    body_type: BodyType,
    centre: (f64, f64),
    size: (f64, f64),
    density: f64,
    restitution: f64,
) -> BodyId {
    let def = BodyBuilder::new()
        .body_type(body_type)
        .position(point(centre))
        .enable_sleep(false)
        .build();
    let body = world.create_body_id(def);
    let material = SurfaceMaterial::default()
        .with_friction(FRICTION as f32)
        .with_restitution(restitution as f32);
    let shape = ShapeDef::builder()
        .material(material)
        .density(density as f32)
        .build();
    let polygon = boxdd::shapes::box_polygon(0.5 * size.0 as f32, 0.5 * size.1 as f32);
    world.create_polygon_shape_for(body, &shape, &polygon);
    body
}

fn centre(world: &World, body: BodyId) -> (f64, f64) {
    let p = world.body_position(body);
    (f64::from(p.x), f64::from(p.y))
}

/// The static floor, its top face at height `top`, restitution 0 (the pair takes the
/// larger).
fn floor(w: &mut World, top: f64) {
    boxed(
        w,
        BodyType::Static,
        (0.0, top - 0.5 * FLOOR.1),
        FLOOR,
        0.0,
        0.0,
    );
}

/// A pyramid (or stack) stepped at `h` for `spec.steps`.
pub fn pyramid(spec: &Pyramid, h: f64, substeps: i32) -> Outcome {
    let mut w = world();
    for top in spec.floor_tops() {
        floor(&mut w, top);
    }
    let centres = spec.centres();
    let boxes: Vec<BodyId> = centres
        .iter()
        .map(|&c| boxed(&mut w, BodyType::Dynamic, c, (BOX, BOX), 1.0, 0.0))
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
fn motion(world: &World, body: BodyId) -> PeerBody {
    let v = world.body_linear_velocity(body);
    PeerBody {
        mass: f64::from(world.body_mass(body)),
        inertia: f64::from(world.body_rotational_inertia(body)),
        velocity: (f64::from(v.x), f64::from(v.y)),
        omega: f64::from(world.body_angular_velocity(body)),
        height: f64::from(world.body_world_center_of_mass(body).y),
    }
}

fn energy(world: &World, body: BodyId) -> f64 {
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
        world.create_revolute_joint_world_id(a, b, point(at));
        let local = |body: BodyId| {
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

    fn gap(&self, world: &World) -> f64 {
        let anchor = |body: BodyId, (lx, ly): (f64, f64)| {
            let (cx, cy) = centre(world, body);
            let r = world.body_rotation(body);
            let (c, s) = (f64::from(r.cosine()), f64::from(r.sine()));
            (cx + c * lx - s * ly, cy + s * lx + c * ly)
        };
        let (pa, pb) = (anchor(self.a, self.local_a), anchor(self.b, self.local_b));
        (pa.0 - pb.0).hypot(pa.1 - pb.1)
    }
}

/// A static body without shapes at the origin, to pin to.
fn ground(world: &mut World) -> BodyId {
    world.create_body_id(BodyBuilder::new().body_type(BodyType::Static).build())
}

pub fn pendulum(spec: &Pendulum, substeps: i32) -> Outcome {
    let mut w = world();
    let pivot = ground(&mut w);
    let bob = boxed(
        &mut w,
        BodyType::Dynamic,
        Pendulum::bob_start(),
        (BOB, BOB),
        1.0,
        0.0,
    );
    let pin = Pin::new(&mut w, pivot, bob, (0.0, 0.0));
    let mut tracker = PeriodTracker::new(spec.h, centre(&w, bob).0, energy(&w, bob));
    let h = spec.h;
    let timing = measure(
        &mut w,
        spec.steps(),
        |w| step(w, h, substeps),
        |w, n| tracker.update(n, centre(w, bob).0, energy(w, bob), pin.gap(w)),
    );
    Outcome::new(timing, tracker.finish())
}

pub fn heavy_chain(h: f64, substeps: i32) -> Outcome {
    let mut w = world();
    let mut previous = ground(&mut w);
    let mut pins = Vec::with_capacity(chain::LINKS + 1);
    for i in 0..=chain::LINKS {
        let body = if i < chain::LINKS {
            let c = chain::link_centre(i);
            boxed(
                &mut w,
                BodyType::Dynamic,
                c,
                chain::LINK,
                chain::LINK_DENSITY,
                0.0,
            )
        } else {
            let size = (chain::END_SIZE, chain::END_SIZE);
            let c = chain::end_centre();
            boxed(&mut w, BodyType::Dynamic, c, size, chain::END_DENSITY, 0.0)
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
    let body = boxed(
        &mut w,
        BodyType::Dynamic,
        (0.0, bounce::DROP + half),
        (bounce::SIZE, bounce::SIZE),
        1.0,
        bounce::RESTITUTION,
    );
    let mut tracker = ReboundTracker::default();
    let timing = measure(
        &mut w,
        bounce::steps(h),
        |w| step(w, h, substeps),
        |w, _| {
            let v_up = f64::from(w.body_linear_velocity(body).y);
            tracker.update(centre(w, body).1 - half, v_up);
        },
    );
    Outcome::new(timing, tracker.finish())
}

/// The smash's boxes' poses, in the scene's order.
fn smash_poses<'a>(world: &'a World, bodies: &'a [BodyId]) -> impl Iterator<Item = BoxPose> + 'a {
    bodies.iter().enumerate().map(move |(i, &b)| {
        let r = world.body_rotation(b);
        let angle = f64::from(r.sine()).atan2(f64::from(r.cosine()));
        smash::box_pose(i, centre(world, b), angle)
    })
}

pub fn smash() -> Outcome {
    let def = WorldDef::builder()
        .gravity([0.0, 0.0])
        .enable_sleep(false)
        .build();
    let mut w = World::new(def).expect("a valid world definition");
    let mut bodies = Vec::with_capacity(smash::ROWS * smash::COLUMNS + 1);
    for c in smash::small_centres() {
        let size = (smash::SMALL, smash::SMALL);
        bodies.push(boxed(&mut w, BodyType::Dynamic, c, size, 1.0, 0.0));
    }
    let size = (smash::HEAVY, smash::HEAVY);
    let heavy = boxed(
        &mut w,
        BodyType::Dynamic,
        smash::heavy_centre(),
        size,
        smash::HEAVY_DENSITY,
        0.0,
    );
    w.set_body_linear_velocity(heavy, Vec2::new(smash::SPEED as f32, 0.0));
    bodies.push(heavy);
    let totals = |w: &World| momentum_and_kinetic_energy(bodies.iter().map(|&b| motion(w, b)));
    let (p0, e0) = totals(&w);
    let mut tracker = SmashTracker::new(p0, e0);
    let timing = measure(
        &mut w,
        smash::STEPS,
        |w| step(w, H, SUBSTEPS),
        |w, _| {
            let (p, e) = totals(w);
            tracker.update(p, e, smash_poses(w, &bodies));
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
            bodies.push(boxed(
                &mut w,
                kind,
                joint_grid::centre(r, c),
                size,
                1.0,
                0.0,
            ));
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
