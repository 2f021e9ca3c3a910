//! Random *databases*, not only random worlds: bodies, robots with joints and both kinds of
//! motor, and scenes, whose numbers come from a palette of the hostile (NaN, infinities,
//! 1e-320, 1e300, the limits and just past them, negative sizes) and from sensible ranges.
//! Each database is checked, written to its three files and loaded back, and every scene
//! is built and stepped under every solver. Nothing may panic: what the checks refuse is
//! refused with a message, what they accept builds or is refused by the simulation with
//! a message, and what builds steps until it ends or a step reports an error.

#![no_main]

use arbitrary::Arbitrary;
use libfuzzer_sys::fuzz_target;
use pe::ContactSolver;
use robosim::db::{Database, Overwrite};
use robosim::model::{
    BodyDef, BodyMotorDef, JointDef, JointMotorDef, Model, Placement, Robot, RobotBody, Scene,
    SceneRobot,
};
use robosim::sim::Simulation;

const STEPS: usize = 30;

/// A number: hostile from the palette, or in a range that makes sense for its use.
#[derive(Debug, Clone, Copy, Arbitrary)]
enum Number {
    Palette(u8),
    Sensible(u16),
}

const PALETTE: [f64; 16] = [
    0.0,
    -0.0,
    1.0,
    -1.0,
    f64::NAN,
    f64::INFINITY,
    f64::NEG_INFINITY,
    1e-320,
    1e-30,
    1e300,
    -1e300,
    1e9,
    1e9 + 1.0,
    1e12,
    1e15,
    1e16,
];

impl Number {
    /// The number, `Sensible` ones uniform in [lo, hi].
    fn get(self, lo: f64, hi: f64) -> f64 {
        match self {
            Number::Palette(k) => PALETTE[k as usize % PALETTE.len()],
            Number::Sensible(u) => lo + (hi - lo) * f64::from(u) / f64::from(u16::MAX),
        }
    }
}

#[derive(Debug, Arbitrary)]
struct Body {
    density: Number,
    cor: Number,
    friction: Option<Number>,
    vertices: Vec<(Number, Number)>,
}

#[derive(Debug, Arbitrary)]
struct Motor {
    time0: u8,
    time1: u8,
    angular: Number,
    start_torque: Number,
    max_torque: Number,
    increase: Number,
}

#[derive(Debug, Arbitrary)]
struct Placed {
    source: u8,
    x: Number,
    y: Number,
    orientation: Number,
    motor: Option<Motor>,
}

#[derive(Debug, Arbitrary)]
struct Joint {
    a: u8,
    b: u8,
    anchor: (Number, Number),
    collide: bool,
    motor: Option<Motor>,
}

#[derive(Debug, Arbitrary)]
struct RobotInput {
    bodies: Vec<Placed>,
    joints: Vec<Joint>,
}

#[derive(Debug, Arbitrary)]
struct SceneInput {
    gravitation: Number,
    friction: Number,
    timestep: Option<Number>,
    robots: Vec<Placed>,
    bodies: Vec<Placed>,
}

#[derive(Debug, Arbitrary)]
struct Input {
    bodies: Vec<Body>,
    robots: Vec<RobotInput>,
    scenes: Vec<SceneInput>,
}

fn body_motor(m: &Motor) -> BodyMotorDef {
    BodyMotorDef {
        time0: u64::from(m.time0),
        time1: u64::from(m.time1),
        angular: m.angular.get(-1.0, 1.0),
        start_torque: m.start_torque.get(0.0, 1e7),
        max_torque: m.max_torque.get(0.0, 1e7),
        increase: m.increase.get(0.0, 0.1),
        ..BodyMotorDef::default()
    }
}

fn joint_motor(m: &Motor) -> JointMotorDef {
    JointMotorDef {
        time0: u64::from(m.time0),
        time1: u64::from(m.time1),
        angular: m.angular.get(-1.0, 1.0),
        max_torque: m.max_torque.get(0.0, 1e7),
        ..JointMotorDef::default()
    }
}

/// Names from small indices, so that references meet (and sometimes dangle).
fn placement(p: &Placed, prefix: &str, k: usize, sources: usize) -> Placement {
    Placement {
        alias: format!("{prefix}{k}"),
        source: format!("{prefix}{}", usize::from(p.source) % (sources + 1)),
        x: p.x.get(-500.0, 500.0),
        y: p.y.get(-500.0, 500.0),
        orientation: p.orientation.get(-3.2, 3.2),
        ..Placement::default()
    }
}

fn model(input: &Input) -> Model {
    let mut model = Model::default();
    for (k, b) in input.bodies.iter().take(8).enumerate() {
        model.bodies.push(BodyDef {
            name: format!("b{k}"),
            density: b.density.get(0.0, 10.0),
            cor: b.cor.get(0.0, 1.0),
            friction: b.friction.map(|f| f.get(0.0, 2.0)),
            vertices: b
                .vertices
                .iter()
                .take(10)
                .map(|&(x, y)| [x.get(-60.0, 60.0), y.get(-60.0, 60.0)])
                .collect(),
            ..BodyDef::default()
        });
    }
    let bodies = model.bodies.len();
    for (k, r) in input.robots.iter().take(4).enumerate() {
        let mut robot = Robot {
            name: format!("r{k}"),
            ..Robot::default()
        };
        for (i, p) in r.bodies.iter().take(6).enumerate() {
            let mut placement = placement(p, "b", i, bodies);
            placement.alias = format!("a{i}");
            robot.bodies.push(RobotBody {
                placement,
                motors: p.motor.iter().map(body_motor).collect(),
            });
        }
        let aliases = robot.bodies.len().max(1);
        for j in r.joints.iter().take(6) {
            robot.joints.push(JointDef {
                body_a: format!("a{}", usize::from(j.a) % aliases),
                body_b: format!("a{}", usize::from(j.b) % aliases),
                anchor_ax: j.anchor.0.get(-60.0, 60.0),
                anchor_ay: j.anchor.1.get(-60.0, 60.0),
                collide: j.collide,
                motor: j.motor.as_ref().map(joint_motor),
                ..JointDef::default()
            });
        }
        model.robots.push(robot);
    }
    let robots = model.robots.len();
    for (k, s) in input.scenes.iter().take(3).enumerate() {
        model.scenes.push(Scene {
            name: format!("s{k}"),
            gravitation: s.gravitation.get(-500.0, 500.0),
            friction: s.friction.get(0.0, 2.0),
            timestep: s.timestep.map(|h| h.get(1e-4, 0.1)),
            robots: s
                .robots
                .iter()
                .take(3)
                .enumerate()
                .map(|(i, p)| {
                    let placed = placement(p, "r", i, robots);
                    SceneRobot {
                        source: placed.source,
                        x: placed.x,
                        y: placed.y,
                        orientation: placed.orientation,
                        ..SceneRobot::default()
                    }
                })
                .collect(),
            bodies: s
                .bodies
                .iter()
                .take(8)
                .enumerate()
                .map(|(i, p)| placement(p, "b", i, bodies))
                .collect(),
            ..Scene::default()
        });
    }
    model
}

fuzz_target!(|input: Input| {
    let model = model(&input);
    let db = Database::new(model.clone());
    let _problems = db.check();
    // Written and read back: the files are what a user's database would be.
    let dir = tempfile::tempdir().expect("a scratch folder");
    let mut saved = Database::new(model.clone());
    if saved.save_to(dir.path(), Overwrite::Confirmed).is_ok() {
        let _loaded = Database::load(dir.path());
    }
    for scene in &model.scenes {
        for solver in ContactSolver::ALL {
            let Ok(mut sim) = Simulation::new(&model, &scene.name, None, Some(solver)) else {
                continue;
            };
            for _ in 0..STEPS {
                if sim.try_step().is_err() {
                    break;
                }
            }
        }
    }
});
