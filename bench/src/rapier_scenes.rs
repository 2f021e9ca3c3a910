//! The scenes built in rapier2d. Rapier's y axis points up, as the scene's does, so points
//! carry over unchanged and gravity is −10 m/s² along y. Rapier works in f32 (its default
//! feature set); results are widened to f64 for the shared trackers.

use crate::Outcome;
use crate::harness::{ProfileLog, measure};
use crate::scene::{
    BOB, BOX, BoxPose, FLOOR, FRICTION, G, H, Metric, PeerBody, Pendulum, PeriodTracker, Pyramid,
    PyramidTracker, ReboundTracker, SmashTracker, bounce, chain, joint_grid,
    momentum_and_kinetic_energy, smash, worst,
};
use rapier2d::prelude::*;

/// A scene point as rapier's vector type.
fn point((x, y): (f64, f64)) -> Vector {
    Vector::new(x as Real, y as Real)
}

fn centre(world: &PhysicsWorld, body: RigidBodyHandle) -> (f64, f64) {
    let t = world.bodies[body].translation();
    (f64::from(t.x), f64::from(t.y))
}

/// rapier2d's own timing of one step's stages (its `Counters`), in microseconds, for
/// `stages` to set beside pe's stage clock. Zero unless the bench is built with the
/// feature `stages` (rapier2d's `profiler`).
#[derive(Debug, Clone, Copy, Default)]
pub struct Profile {
    pub step: f64,
    pub broad_phase: f64,
    pub narrow_phase: f64,
    pub islands: f64,
    /// Bodies and forces updated before the solve (`update_time`).
    pub update: f64,
    /// The solver's serial set-up before its passes: buffers, the chunk layout of its
    /// persistent colours, the joints' constraints (`velocity_assembly_time`).
    pub assembly: f64,
    /// The contact constraints built, the passes with their integration, and impulses and
    /// bodies written back (`velocity_resolution_time`).
    pub resolution: f64,
    pub ccd: f64,
}

/// rapier2d's own timing of each step, for `stages`.
pub static PROFILES: ProfileLog<Profile> = ProfileLog::new();

/// One step, its profile kept if asked (`PROFILES`).
fn step(w: &mut PhysicsWorld) {
    w.step();
    if PROFILES.keeping() {
        let c = &w.physics_pipeline.counters;
        let us = |t: &rapier2d::counters::Timer| 1e6 * t.time().as_secs_f64();
        let profile = Profile {
            step: us(&c.step_time),
            broad_phase: us(&c.cd.broad_phase_time) + us(&c.cd.final_broad_phase_time),
            narrow_phase: us(&c.cd.narrow_phase_time),
            islands: us(&c.stages.island_construction_time),
            update: us(&c.stages.update_time),
            assembly: us(&c.solver.velocity_assembly_time),
            resolution: us(&c.solver.velocity_resolution_time),
            ccd: us(&c.stages.ccd_time),
        };
        PROFILES.push(profile);
    }
}

/// Rapier's default solver iterations per step.
pub const ITERATIONS: usize = 4;

/// A world with the default integration parameters except the step and the solver
/// iterations.
fn world(h: f64, iterations: usize) -> PhysicsWorld {
    let mut w = PhysicsWorld::new();
    w.gravity = Vector::new(0.0, -G as Real);
    w.integration_parameters.dt = h as Real;
    w.integration_parameters.num_solver_iterations = iterations;
    if PROFILES.keeping() {
        w.physics_pipeline.counters.enable();
    }
    w
}

/// A dynamic body at `position`. Sleeping is off so that every body is simulated on every
/// step, as in pe, which has no sleeping: otherwise resting pyramids would cost nothing.
fn dynamic(position: (f64, f64)) -> RigidBodyBuilder {
    RigidBodyBuilder::dynamic()
        .translation(point(position))
        .can_sleep(false)
}

/// A box collider of full size `w` × `h` (rapier takes half-extents).
fn cuboid(w: f64, h: f64, density: f64) -> ColliderBuilder {
    ColliderBuilder::cuboid(0.5 * w as Real, 0.5 * h as Real).density(density as Real)
}

/// The static floor, its top face at height `top`, with the scenes' friction so that
/// rapier's default averaging of the pair's coefficients gives exactly `FRICTION`.
fn floor(w: &mut PhysicsWorld, top: f64, restitution: f64) {
    floor_piece(w, (0.0, top - 0.5 * FLOOR.1), FLOOR, restitution);
}

/// A static box of the floor.
fn floor_piece(w: &mut PhysicsWorld, centre: (f64, f64), size: (f64, f64), restitution: f64) {
    let body = RigidBodyBuilder::fixed()
        .translation(point(centre))
        .can_sleep(false);
    let shape = cuboid(size.0, size.1, 0.0)
        .friction(FRICTION as Real)
        .restitution(restitution as Real);
    w.insert(body, shape);
}

/// A pyramid (or stack) stepped at `h` for `spec.steps`.
pub fn pyramid(spec: &Pyramid, h: f64, iterations: usize) -> Outcome {
    let mut w = world(h, iterations);
    for (centre, size) in spec.floor_pieces() {
        floor_piece(&mut w, centre, size, 0.0);
    }
    let centres = spec.centres();
    let boxes: Vec<RigidBodyHandle> = centres
        .iter()
        .map(|&c| {
            let shape = cuboid(BOX, BOX, 1.0).friction(FRICTION as Real);
            w.insert(dynamic(c), shape).0
        })
        .collect();
    let mut tracker = PyramidTracker::new(centres);
    let timing = measure(&mut w, spec.steps, step, |w, _| {
        tracker.update(boxes.iter().map(|&b| centre(w, b)))
    });
    Outcome::new(timing, tracker.finish())
}

/// One body's motion, from its mass properties.
fn motion(world: &PhysicsWorld, body: RigidBodyHandle) -> PeerBody {
    let b = &world.bodies[body];
    let v = b.linvel();
    PeerBody {
        mass: f64::from(b.mass()),
        inertia: f64::from(b.mass_properties().local_mprops.principal_inertia()),
        velocity: (f64::from(v.x), f64::from(v.y)),
        omega: f64::from(b.angvel()),
        height: f64::from(b.center_of_mass().y),
    }
}

fn energy(world: &PhysicsWorld, body: RigidBodyHandle) -> f64 {
    motion(world, body).energy()
}

pub fn pendulum(spec: &Pendulum, iterations: usize) -> Outcome {
    let mut w = world(spec.h, iterations);
    // The pivot is a fixed body without collider at the origin.
    let pivot = w.insert_body(RigidBodyBuilder::fixed());
    let start = Pendulum::bob_start();
    let (bob, _) = w.insert(dynamic(start), cuboid(BOB, BOB, 1.0));
    // Mass properties are otherwise only updated inside the first step; E0 needs them now.
    let PhysicsWorld {
        bodies, colliders, ..
    } = &mut w;
    bodies[bob].recompute_mass_properties_from_colliders(colliders);
    // Anchors in each body's frame: the pivot's origin, and the pivot as seen from the
    // bob's centre.
    let pin = RevoluteJointBuilder::new()
        .local_anchor1(Vector::ZERO)
        .local_anchor2(-point(start));
    let pin = w.insert_impulse_joint(pivot, bob, pin);
    let mut tracker = PeriodTracker::new(spec.h, centre(&w, bob).0, energy(&w, bob));
    let timing = measure(&mut w, spec.steps(), step, |w, n| {
        tracker.update(n, centre(w, bob).0, energy(w, bob), joint_gap(w, pin))
    });
    Outcome::new(timing, tracker.finish())
}

/// Distance between a joint's two anchors in world coordinates.
fn joint_gap(world: &PhysicsWorld, joint: ImpulseJointHandle) -> f64 {
    let j = world
        .impulse_joints
        .get(joint)
        .expect("joints are never removed");
    let a = world.bodies[j.body1()]
        .position()
        .transform_point(j.data.local_anchor1());
    let b = world.bodies[j.body2()]
        .position()
        .transform_point(j.data.local_anchor2());
    f64::from(a.distance(b))
}

pub fn heavy_chain(h: f64, iterations: usize) -> Outcome {
    let mut w = world(h, iterations);
    let mut previous = (w.insert_body(RigidBodyBuilder::fixed()), (0.0, 0.0));
    let mut joints = Vec::with_capacity(chain::LINKS + 1);
    for i in 0..=chain::LINKS {
        let (c, shape) = if i < chain::LINKS {
            let shape = cuboid(chain::LINK.0, chain::LINK.1, chain::LINK_DENSITY);
            (chain::link_centre(i), shape)
        } else {
            let shape = cuboid(chain::END_SIZE, chain::END_SIZE, chain::END_DENSITY);
            (chain::end_centre(), shape)
        };
        let (body, _) = w.insert(dynamic(c), shape);
        let pin = chain::pin(i);
        // Each anchor is the pin relative to its body's centre. Pinned neighbours overlap
        // at the pin, and pe never lets jointed bodies collide: switch contacts off.
        let joint = RevoluteJointBuilder::new()
            .local_anchor1(point(pin) - point(previous.1))
            .local_anchor2(point(pin) - point(c))
            .contacts_enabled(false);
        joints.push(w.insert_impulse_joint(previous.0, body, joint));
        previous = (body, c);
    }
    let mut worst_gap: f64 = 0.0;
    let timing = measure(&mut w, chain::steps(h), step, |w, _| {
        for &j in &joints {
            worst_gap = worst(worst_gap, joint_gap(w, j));
        }
    });
    Outcome::new(timing, Metric::Chain { worst_gap })
}

pub fn bounce(h: f64, iterations: usize) -> Outcome {
    let mut w = world(h, iterations);
    // Rapier averages the pair's restitutions by default: with 0.5 on both the pair's is 0.5.
    floor(&mut w, 0.0, bounce::RESTITUTION);
    let half = 0.5 * bounce::SIZE;
    let shape = cuboid(bounce::SIZE, bounce::SIZE, 1.0)
        .friction(FRICTION as Real)
        .restitution(bounce::RESTITUTION as Real);
    let (body, _) = w.insert(dynamic((0.0, bounce::DROP + half)), shape);
    let mut tracker = ReboundTracker::default();
    let timing = measure(&mut w, bounce::steps(h), step, |w, _| {
        let v_up = f64::from(w.bodies[body].linvel().y);
        tracker.update(centre(w, body).1 - half, v_up);
    });
    Outcome::new(timing, tracker.finish())
}

/// The smash's boxes' poses, in the scene's order.
fn smash_poses<'a>(
    world: &'a PhysicsWorld,
    bodies: &'a [RigidBodyHandle],
) -> impl Iterator<Item = BoxPose> + 'a {
    bodies.iter().enumerate().map(move |(i, &b)| {
        let angle = f64::from(world.bodies[b].rotation().angle());
        smash::box_pose(i, centre(world, b), angle)
    })
}

pub fn smash() -> Outcome {
    let mut w = world(H, ITERATIONS);
    w.gravity = Vector::ZERO;
    let mut bodies = Vec::with_capacity(smash::ROWS * smash::COLUMNS + 1);
    for c in smash::small_centres() {
        let shape = cuboid(smash::SMALL, smash::SMALL, 1.0).friction(FRICTION as Real);
        bodies.push(w.insert(dynamic(c), shape).0);
    }
    let heavy = dynamic(smash::heavy_centre()).linvel(Vector::new(smash::SPEED as Real, 0.0));
    let shape = cuboid(smash::HEAVY, smash::HEAVY, smash::HEAVY_DENSITY).friction(FRICTION as Real);
    bodies.push(w.insert(heavy, shape).0);
    let PhysicsWorld {
        bodies: set,
        colliders,
        ..
    } = &mut w;
    for &b in &bodies {
        set[b].recompute_mass_properties_from_colliders(colliders);
    }
    let totals =
        |w: &PhysicsWorld| momentum_and_kinetic_energy(bodies.iter().map(|&b| motion(w, b)));
    let (p0, e0) = totals(&w);
    let mut tracker = SmashTracker::new(p0, e0);
    let timing = measure(&mut w, smash::STEPS, step, |w, _| {
        let (p, e) = totals(w);
        tracker.update(p, e, smash_poses(w, &bodies));
    });
    Outcome::new(timing, tracker.finish())
}

pub fn joint_grid() -> Outcome {
    let mut w = world(H, ITERATIONS);
    let mut bodies = Vec::with_capacity(joint_grid::N * joint_grid::N);
    for r in 0..joint_grid::N {
        for c in 0..joint_grid::N {
            let at = joint_grid::centre(r, c);
            let body = if joint_grid::is_static(r, c) {
                RigidBodyBuilder::fixed().translation(point(at))
            } else {
                dynamic(at)
            };
            let shape = cuboid(joint_grid::SIZE, joint_grid::SIZE, 1.0);
            bodies.push((w.insert(body, shape).0, at));
        }
    }
    let joints: Vec<ImpulseJointHandle> = joint_grid::pins()
        .into_iter()
        .map(|(a, b, p)| {
            let ((ha, ca), (hb, cb)) = (bodies[a], bodies[b]);
            let pin = RevoluteJointBuilder::new()
                .local_anchor1(point(p) - point(ca))
                .local_anchor2(point(p) - point(cb))
                .contacts_enabled(false);
            w.insert_impulse_joint(ha, hb, pin)
        })
        .collect();
    let mut worst_gap: f64 = 0.0;
    let timing = measure(&mut w, joint_grid::STEPS, step, |w, _| {
        for &j in &joints {
            worst_gap = worst(worst_gap, joint_gap(w, j));
        }
    });
    Outcome::new(timing, Metric::Chain { worst_gap })
}
