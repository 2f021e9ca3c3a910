//! The scenes built in `pe`. pe's y axis points down (gravity is +y), so every scene point
//! (x, y up) becomes (x, −y) here.

use crate::Outcome;
use crate::harness::{ProfileLog, measure};
use crate::scene::{
    BOB, BOX, BoxPose, FLOOR, FRICTION, G, H, Metric, Pendulum, PeriodTracker, Pyramid,
    PyramidTracker, ReboundTracker, SmashTracker, bounce, chain, joint_grid, smash, worst,
};
use pe::{
    BodyDef, BodyHandle, ContactSolver, ConvexPolygon, Integrator, JointDef, JointHandle,
    StepProfile, StepSettings, Vec2, World,
};

/// pe's own timing of each step (its stage clock), for `pe ... stages` and `stages`.
pub static PROFILES: ProfileLog<StepProfile> = ProfileLog::new();

/// One step, its profile kept if asked (`PROFILES`).
fn step(w: &mut World, h: f64) {
    w.step(h);
    if PROFILES.keeping() {
        PROFILES.push(*w.profile());
    }
}

/// How pe is set up for a run: the contact solver, the integrator, the soft step's
/// substeps and sweep order (used by `soft` only), and whether the narrow phase reuses
/// manifolds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PeConfig {
    pub solver: ContactSolver,
    pub integrator: Integrator,
    pub soft_substeps: usize,
    pub soft_alternating_sweeps: bool,
    pub reuse_manifolds: bool,
}

impl PeConfig {
    /// The solver with pe's defaults for the rest.
    pub fn new(solver: ContactSolver) -> Self {
        let defaults = StepSettings::default();
        Self {
            solver,
            integrator: defaults.integrator,
            soft_substeps: defaults.soft_substeps,
            soft_alternating_sweeps: defaults.soft_alternating_sweeps,
            reuse_manifolds: defaults.reuse_manifolds,
        }
    }
}

/// A scene point (y up) in pe's y-down world.
fn at((x, y): (f64, f64)) -> Vec2 {
    Vec2::new(x, -y)
}

/// A body's centre as a scene point (y up).
fn centre(world: &World, body: BodyHandle) -> (f64, f64) {
    let p = world.body(body).expect("bodies are never removed").position;
    (p.x, -p.y)
}

fn world(config: PeConfig) -> World {
    let mut w = World::new(Vec2::new(0.0, G));
    w.settings.contact_solver = config.solver;
    w.settings.integrator = config.integrator;
    w.settings.soft_substeps = config.soft_substeps;
    w.settings.soft_alternating_sweeps = config.soft_alternating_sweeps;
    w.settings.reuse_manifolds = config.reuse_manifolds;
    // All bodies are metre-sized: pe's tolerances (contact margin, slop, joint tolerance)
    // scale with this.
    w.settings.length_scale = 1.0;
    w.friction = FRICTION;
    w
}

fn rectangle(w: f64, h: f64) -> ConvexPolygon {
    ConvexPolygon::rectangle(w, h).expect("positive sizes")
}

/// The static floor, its top face at height `top`.
fn floor(w: &mut World, top: f64) {
    floor_piece(w, (0.0, top - 0.5 * FLOOR.1), FLOOR);
}

/// A static box of the floor. Restitution 1 because pe combines a pair's restitutions by
/// their minimum: the moving body's own value then applies.
fn floor_piece(w: &mut World, centre: (f64, f64), size: (f64, f64)) {
    let def = BodyDef::new(rectangle(size.0, size.1), 0.0)
        .restitution(1.0)
        .at(at(centre), 0.0);
    w.add_body(def).expect("valid floor");
}

/// A pyramid (or stack) stepped at `h` for `spec.steps`.
pub fn pyramid(config: PeConfig, spec: &Pyramid, h: f64) -> Outcome {
    let mut w = world(config);
    for (centre, size) in spec.floor_pieces() {
        floor_piece(&mut w, centre, size);
    }
    let unit = rectangle(BOX, BOX);
    let centres = spec.centres();
    let boxes: Vec<BodyHandle> = centres
        .iter()
        .map(|&c| {
            w.add_body(BodyDef::new(unit.clone(), 1.0).at(at(c), 0.0))
                .expect("valid box")
        })
        .collect();
    let mut tracker = PyramidTracker::new(centres);
    let timing = measure(
        &mut w,
        spec.steps,
        |w| step(w, h),
        |w, _| tracker.update(boxes.iter().map(|&b| centre(w, b))),
    );
    Outcome::new(timing, tracker.finish())
}

pub fn pendulum(config: PeConfig, spec: &Pendulum) -> Outcome {
    let mut w = world(config);
    let bob = w
        .add_body(BodyDef::new(rectangle(BOB, BOB), 1.0).at(at(Pendulum::bob_start()), 0.0))
        .expect("valid bob");
    let pin = w
        .add_joint(JointDef::new(bob, None, Vec2::zeros()))
        .expect("valid pin");
    let energy = |w: &World| w.kinetic_energy() + w.potential_energy();
    let mut tracker = PeriodTracker::new(spec.h, centre(&w, bob).0, energy(&w));
    let h = spec.h;
    let timing = measure(
        &mut w,
        spec.steps(),
        |w| step(w, h),
        |w, n| {
            let gap = w.joint_gap(pin).expect("joints are never removed");
            tracker.update(n, centre(w, bob).0, energy(w), gap);
        },
    );
    Outcome::new(timing, tracker.finish())
}

pub fn heavy_chain(config: PeConfig, h: f64) -> Outcome {
    let mut w = world(config);
    let link = rectangle(chain::LINK.0, chain::LINK.1);
    let mut joints: Vec<JointHandle> = Vec::with_capacity(chain::LINKS + 1);
    let mut previous: Option<BodyHandle> = None;
    for i in 0..=chain::LINKS {
        let def = if i < chain::LINKS {
            BodyDef::new(link.clone(), chain::LINK_DENSITY).at(at(chain::link_centre(i)), 0.0)
        } else {
            let end = rectangle(chain::END_SIZE, chain::END_SIZE);
            BodyDef::new(end, chain::END_DENSITY).at(at(chain::end_centre()), 0.0)
        };
        let body = w.add_body(def).expect("valid link");
        // The first link is pinned to the world (body_b None), the others to the one before.
        let pin = JointDef::new(body, previous, at(chain::pin(i)));
        joints.push(w.add_joint(pin).expect("valid pin"));
        previous = Some(body);
    }
    let mut worst_gap: f64 = 0.0;
    let timing = measure(
        &mut w,
        chain::steps(h),
        |w| step(w, h),
        |w, _| {
            for &j in &joints {
                worst_gap = worst(worst_gap, w.joint_gap(j).expect("joints are never removed"));
            }
        },
    );
    Outcome::new(timing, Metric::Chain { worst_gap })
}

pub fn bounce(config: PeConfig, h: f64) -> Outcome {
    let mut w = world(config);
    floor(&mut w, 0.0);
    let half = 0.5 * bounce::SIZE;
    let def = BodyDef::new(rectangle(bounce::SIZE, bounce::SIZE), 1.0)
        .restitution(bounce::RESTITUTION)
        .at(at((0.0, bounce::DROP + half)), 0.0);
    let body = w.add_body(def).expect("valid box");
    let mut tracker = ReboundTracker::default();
    let timing = measure(
        &mut w,
        bounce::steps(h),
        |w| step(w, h),
        |w, _| {
            let v_up = -w.body(body).expect("live").velocity.y;
            tracker.update(centre(w, body).1 - half, v_up);
        },
    );
    Outcome::new(timing, tracker.finish())
}

/// The smash's boxes' poses, in the scene's order. The scene's y points up, pe's down:
/// mirrored, a box turns the other way.
fn smash_poses(world: &World) -> impl Iterator<Item = BoxPose> + '_ {
    let pose = |(i, (_, b)): (usize, (BodyHandle, &pe::Body))| {
        smash::box_pose(i, (b.position.x, -b.position.y), -b.angle)
    };
    world.bodies().enumerate().map(pose)
}

pub fn smash(config: PeConfig) -> Outcome {
    let mut w = world(config);
    w.gravity = Vec2::zeros();
    let small = rectangle(smash::SMALL, smash::SMALL);
    for c in smash::small_centres() {
        w.add_body(BodyDef::new(small.clone(), 1.0).at(at(c), 0.0))
            .expect("valid box");
    }
    let heavy = BodyDef::new(rectangle(smash::HEAVY, smash::HEAVY), smash::HEAVY_DENSITY)
        .at(at(smash::heavy_centre()), 0.0)
        .velocity(Vec2::new(smash::SPEED, 0.0), 0.0);
    w.add_body(heavy).expect("valid box");
    let momentum = |w: &World| {
        let p = w.linear_momentum();
        (p.x, -p.y)
    };
    let mut tracker = SmashTracker::new(momentum(&w), w.kinetic_energy());
    let timing = measure(
        &mut w,
        smash::STEPS,
        |w| step(w, H),
        |w, _| tracker.update(momentum(w), w.kinetic_energy(), smash_poses(w)),
    );
    Outcome::new(timing, tracker.finish())
}

pub fn joint_grid(config: PeConfig) -> Outcome {
    let mut w = world(config);
    let square = rectangle(joint_grid::SIZE, joint_grid::SIZE);
    let mut bodies = Vec::with_capacity(joint_grid::N * joint_grid::N);
    for r in 0..joint_grid::N {
        for c in 0..joint_grid::N {
            let density = if joint_grid::is_static(r, c) {
                0.0
            } else {
                1.0
            };
            let def = BodyDef::new(square.clone(), density).at(at(joint_grid::centre(r, c)), 0.0);
            bodies.push(w.add_body(def).expect("valid square"));
        }
    }
    let pins: Vec<JointHandle> = joint_grid::pins()
        .into_iter()
        .map(|(a, b, p)| {
            w.add_joint(JointDef::new(bodies[a], Some(bodies[b]), at(p)))
                .expect("valid pin")
        })
        .collect();
    let mut worst_gap: f64 = 0.0;
    let timing = measure(
        &mut w,
        joint_grid::STEPS,
        |w| step(w, H),
        |w, _| {
            for &j in &pins {
                worst_gap = worst(worst_gap, w.joint_gap(j).expect("joints are never removed"));
            }
        },
    );
    Outcome::new(timing, Metric::Chain { worst_gap })
}
