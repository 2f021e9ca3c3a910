//! Random throws in every engine: the same worlds (`Throw`, from pe's hard-case tests) in
//! pe, rapier2d and Box2D v3, each judged from its bodies' poses after every step by the
//! same separating-axis test and energy meter (`Judge`): how often a throw
//! sinks past a fifth of the smallest radius, and how, and whether it gains energy.

#[path = "../../physics/tests/support/random_throws.rs"]
mod random_throws;

use crate::{box2d_scenes, rapier_scenes};
use pe::{ContactSolver, Vec2};
use random_throws::{
    BodyState, Class, DENSITY, FRICTION, GRAVITY, H, Judge, Numbers, Outcome, STEPS, Throw,
    WALL_RESTITUTION, WALLS, run_in_pe,
};
use std::time::{Duration, Instant};

/// The main run's throws and their seed.
pub const THROWS: usize = 200;
pub const SEED: u64 = 1;

/// The pe solvers thrown (`exact` and `auto` take minutes for a few hundred throws).
const PE_SOLVERS: [ContactSolver; 2] = [ContactSolver::Soft, ContactSolver::Thesis];

/// One engine's throws.
pub struct ThrowsRow {
    pub engine: String,
    pub throws: usize,
    /// The throws that sank, by class: from the start, in one step, gradually.
    pub sunk: [usize; 3],
    /// The deepest overlap of all, over the smallest radius.
    pub deepest: f64,
    /// The throws that gained energy (`Outcome::gained_energy`), and the most any rose.
    pub gained: usize,
    pub most_gained: f64,
    /// The time spent stepping (not judging), all throws together.
    pub stepping: Duration,
}

impl ThrowsRow {
    pub fn sunk_total(&self) -> usize {
        self.sunk.iter().sum()
    }
}

/// One engine's run of a throw, adding its stepping time to the second argument.
type ThrowRun = Box<dyn Fn(&Throw, &mut Duration) -> Outcome>;

/// `throws` random worlds from `seed` in each engine; with `list`, each throw that sinks
/// on stderr.
pub fn run(throws: usize, seed: u64, list: bool) -> Vec<ThrowsRow> {
    let pe_runs = PE_SOLVERS.map(|solver| {
        let engine = format!("pe {}", solver.name());
        (
            engine,
            Box::new(move |t: &Throw, stepping: &mut Duration| run_in_pe(t, solver, None, stepping))
                as ThrowRun,
        )
    });
    let peers: [(String, ThrowRun); 2] = [
        ("rapier2d".into(), Box::new(run_in_rapier)),
        ("Box2D v3".into(), Box::new(run_in_box2d)),
    ];
    pe_runs
        .into_iter()
        .chain(peers)
        .map(|(engine, run)| {
            let started = Instant::now();
            eprint!("random throws: {throws} in {engine}…");
            let mut numbers = Numbers(seed);
            let mut row = ThrowsRow {
                engine,
                throws,
                sunk: [0; 3],
                deepest: 0.0,
                gained: 0,
                most_gained: 0.0,
                stepping: Duration::ZERO,
            };
            for k in 0..throws {
                let outcome = run(&Throw::random(&mut numbers), &mut row.stepping);
                if list && outcome.sank() {
                    let (a, b) = outcome.masses;
                    eprint!(
                        "\n  world {k}: {:.2} radii deep at step {}, {:?}, masses {a:.3} and {b:.3}",
                        outcome.depth, outcome.step, outcome.class
                    );
                }
                row.deepest = row.deepest.max(outcome.depth);
                row.most_gained = row.most_gained.max(outcome.energy_rise);
                row.gained += usize::from(outcome.gained_energy());
                if outcome.sank() {
                    row.sunk[match outcome.class {
                        Class::OverlappingFromStart => 0,
                        Class::InOneStep => 1,
                        Class::Gradually => 2,
                    }] += 1;
                }
            }
            eprintln!(" {:.1} s", started.elapsed().as_secs_f64());
            row
        })
        .collect()
}

fn run_in_rapier(throw: &Throw, stepping: &mut Duration) -> Outcome {
    // The prelude's `Vec2` is rapier's: pe's is named in full here.
    use rapier2d::prelude::*;
    let v = |p: pe::Vec2| Vector::new(p.x as Real, p.y as Real);
    let mut w = PhysicsWorld::new();
    // pe's y points down: gravity along +y, as in the throw.
    w.gravity = Vector::new(0.0, GRAVITY as Real);
    w.integration_parameters.dt = H as Real;
    w.integration_parameters.num_solver_iterations = rapier_scenes::ITERATIONS;
    // pe's rule for a pair's restitution: the smaller one. Friction: every one is the same.
    let surface = |c: ColliderBuilder, restitution: f64| {
        c.friction(FRICTION as Real)
            .restitution(restitution as Real)
            .restitution_combine_rule(CoefficientCombineRule::Min)
    };
    for ((width, height), (x, y)) in WALLS {
        let body = RigidBodyBuilder::fixed().translation(v(pe::Vec2::new(x, y)));
        let shape = ColliderBuilder::cuboid(0.5 * width as Real, 0.5 * height as Real);
        w.insert(body, surface(shape, WALL_RESTITUTION));
    }
    let bodies: Vec<RigidBodyHandle> = throw
        .bodies
        .iter()
        .map(|b| {
            let body = RigidBodyBuilder::dynamic()
                .translation(v(b.at))
                .rotation(b.angle as Real)
                .linvel(v(b.velocity))
                .angvel(b.spin as Real)
                .can_sleep(false);
            let points: Vec<Vector> = b.shape.vertices().iter().map(|&p| v(p)).collect();
            let shape = ColliderBuilder::convex_hull(&points)
                .expect("a regular polygon")
                .density(DENSITY as Real);
            w.insert(body, surface(shape, b.restitution)).0
        })
        .collect();
    let mut judge = Judge::new(throw);
    let widen = |v: Vector| pe::Vec2::new(f64::from(v.x), f64::from(v.y));
    for step in 0..STEPS {
        let started = Instant::now();
        w.step();
        *stepping += started.elapsed();
        let state = |&h: &RigidBodyHandle| {
            let b = &w.bodies[h];
            BodyState {
                at: widen(b.translation()),
                angle: f64::from(b.rotation().angle()),
                velocity: widen(b.linvel()),
                spin: f64::from(b.angvel()),
            }
        };
        judge.after_step(step, bodies.iter().map(state));
    }
    judge.outcome()
}

fn run_in_box2d(throw: &Throw, stepping: &mut Duration) -> Outcome {
    use box2d_scenes::{body_builder, read, world_with_gravity};
    use boxdd::{Body, BodyType, MixerId, Position, ShapeDef, SurfaceMaterial};
    let at = |p: Vec2| Position::new(p.x as f32, p.y as f32);
    let v = |p: Vec2| boxdd::Vec2::new(p.x as f32, p.y as f32);
    // pe's y points down: gravity along +y, as in the throw.
    let mut w = world_with_gravity(GRAVITY);
    // pe's rule for a pair's restitution, the smaller one (Box2D's own takes the larger).
    // The identity names the rule for boxdd's recordings, which this run does not make.
    w.set_restitution_callback(
        MixerId::from_bytes(*b"pe: the smaller restitution wins"),
        |a, b| a.coefficient.min(b.coefficient),
    )
    .expect("a restitution rule");
    let shape_def = |restitution: f64, density: f64| {
        let material = SurfaceMaterial::default()
            .with_friction(FRICTION as f32)
            .and_then(|m| m.with_restitution(restitution as f32))
            .expect("a valid material");
        ShapeDef::builder()
            .material(material)
            .density(density as f32)
            .build()
            .expect("a valid shape")
    };
    for ((width, height), (x, y)) in WALLS {
        let def = body_builder(BodyType::Static)
            .position(at(Vec2::new(x, y)))
            .build()
            .expect("a valid body");
        let polygon = boxdd::shapes::box_polygon(0.5 * width as f32, 0.5 * height as f32)
            .expect("a valid box");
        let body = w.create_body(def).expect("a new body");
        w.body(body)
            .and_then(|mut b| b.create_polygon(&shape_def(WALL_RESTITUTION, 0.0), &polygon))
            .expect("a new shape");
    }
    let bodies: Vec<_> = throw
        .bodies
        .iter()
        .map(|b| {
            let def = body_builder(BodyType::Dynamic)
                .position(at(b.at))
                .angle(b.angle as f32)
                .linear_velocity(v(b.velocity))
                .angular_velocity(b.spin as f32)
                .build()
                .expect("a valid body");
            let body = w.create_body(def).expect("a new body");
            let points = b.shape.vertices().iter().map(|&p| v(p));
            let polygon =
                boxdd::shapes::polygon_from_points(points, 0.0).expect("a regular polygon");
            w.body(body)
                .and_then(|mut bb| bb.create_polygon(&shape_def(b.restitution, DENSITY), &polygon))
                .expect("a new shape");
            body
        })
        .collect();
    let mut judge = Judge::new(throw);
    let widen = |x: f32, y: f32| Vec2::new(f64::from(x), f64::from(y));
    for step in 0..STEPS {
        let started = Instant::now();
        box2d_scenes::step(&mut w, H, box2d_scenes::SUBSTEPS);
        *stepping += started.elapsed();
        let states: Vec<BodyState> = bodies
            .iter()
            .map(|&b| {
                read(&mut w, b, |body: &Body<'_>| {
                    let (p, v) = (body.position()?, body.linear_velocity()?);
                    Ok(BodyState {
                        at: widen(p.x, p.y),
                        angle: f64::from(body.rotation()?.angle()),
                        velocity: widen(v.x, v.y),
                        spin: f64::from(body.angular_velocity()?),
                    })
                })
            })
            .collect();
        judge.after_step(step, states.into_iter());
    }
    judge.outcome()
}
