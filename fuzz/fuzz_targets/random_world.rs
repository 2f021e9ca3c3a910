//! Random small `pe` worlds, built through the public API and stepped 200 times.
//!
//! The input is decoded by `arbitrary` into a description whose numbers are all clamped
//! into sensible ranges (no NaN or infinity ever reaches a constructor): gravity, world
//! friction, 1–12 bodies (regular 3–8-gons or rectangles of size 1e-2..1e2, positions,
//! velocities, spin, density 0 or 1e-2..1e3, restitution, optional friction, an optional
//! body motor), up to 4 pin joints (to another body or to the world, optional motor),
//! the contact solver, h in 1e-4..0.1 and sleeping on or off. Constructors may refuse
//! what they are given; what they accept must step with every body's position, angle,
//! velocity and angular velocity finite.

#![no_main]

use arbitrary::Arbitrary;
use libfuzzer_sys::fuzz_target;
use pe::{BodyDef, BodyMotor, ContactSolver, ConvexPolygon, JointDef, JointMotor, Vec2, World};

const STEPS: usize = 200;
const MAX_BODIES: usize = 12;
const MAX_JOINTS: usize = 4;

/// A number in [0, 1].
#[derive(Debug, Clone, Copy, Arbitrary)]
struct Unit(u16);

impl Unit {
    fn get(self) -> f64 {
        f64::from(self.0) / f64::from(u16::MAX)
    }
    /// Uniform in [lo, hi].
    fn lin(self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.get()
    }
    /// Log-uniform in [lo, hi] (both > 0).
    fn log(self, lo: f64, hi: f64) -> f64 {
        (lo.ln() + (hi.ln() - lo.ln()) * self.get())
            .exp()
            .clamp(lo, hi)
    }
}

#[derive(Debug, Arbitrary)]
enum Shape {
    Regular { sides: u8, radius: Unit },
    Rectangle { width: Unit, height: Unit },
}

#[derive(Debug, Arbitrary)]
struct Motor {
    time0: u8,
    duration: u8,
    angular: Unit,
    start_torque: Unit,
    max_over_start: Unit,
    increase: Unit,
}

#[derive(Debug, Arbitrary)]
struct Body {
    shape: Shape,
    x: Unit,
    y: Unit,
    angle: Unit,
    vx: Unit,
    vy: Unit,
    omega: Unit,
    /// 0 (static) when `is_static`, else log-uniform in 1e-2..1e3.
    is_static: bool,
    density: Unit,
    restitution: Unit,
    friction: Option<Unit>,
    motor: Option<Motor>,
}

#[derive(Debug, Arbitrary)]
struct Joint {
    a: u8,
    /// `None` pins body a to the world.
    b: Option<u8>,
    /// Where the pin lies between a and b (or a and the origin), plus an offset.
    along: Unit,
    dx: Unit,
    dy: Unit,
    collide: bool,
    /// Target speed (rad/s) and torque limit.
    motor: Option<(Unit, Unit)>,
}

#[derive(Debug, Arbitrary)]
struct Spec {
    gravity: (Unit, Unit),
    friction: Unit,
    solver: u8,
    h: Unit,
    sleeping: bool,
    /// The world's length scale: the median body size as robosim sets it, or 1.
    median_scale: bool,
    first: Body,
    more: Vec<Body>,
    joints: Vec<Joint>,
}

fn polygon(shape: &Shape) -> Result<ConvexPolygon, pe::ShapeError> {
    match *shape {
        Shape::Regular { sides, radius } => {
            ConvexPolygon::regular(3 + usize::from(sides % 6), radius.log(5e-3, 50.0))
        }
        Shape::Rectangle { width, height } => {
            ConvexPolygon::rectangle(width.log(1e-2, 1e2), height.log(1e-2, 1e2))
        }
    }
}

fn body_def(b: &Body) -> Option<BodyDef> {
    let polygon = polygon(&b.shape).ok()?;
    let density = if b.is_static {
        0.0
    } else {
        b.density.log(1e-2, 1e3)
    };
    let mut def = BodyDef::new(polygon, density)
        .restitution(b.restitution.get())
        .at(
            Vec2::new(b.x.lin(-100.0, 100.0), b.y.lin(-100.0, 100.0)),
            b.angle.lin(-std::f64::consts::PI, std::f64::consts::PI),
        )
        .velocity(
            Vec2::new(b.vx.lin(-100.0, 100.0), b.vy.lin(-100.0, 100.0)),
            b.omega.lin(-50.0, 50.0),
        );
    if let Some(mu) = b.friction {
        def = def.friction(mu.lin(0.0, 2.0));
    }
    Some(def)
}

fn body_motor(m: &Motor) -> BodyMotor {
    let time0 = u64::from(m.time0);
    let start = m.start_torque.log(1e-2, 1e6);
    BodyMotor::new(
        time0,
        time0 + u64::from(m.duration),
        m.angular.lin(-0.5, 0.5),
        start,
        start * m.max_over_start.lin(1.0, 10.0),
        m.increase.get(),
    )
}

fn assert_finite(world: &World, step: usize) {
    for (handle, b) in world.bodies() {
        let state = b.state();
        assert!(
            state.iter().all(|v| v.is_finite()),
            "step {step}: body {} is not finite: position {:?}, angle {}, velocity {:?}, \
             angular velocity {}",
            handle.0,
            b.position,
            b.angle,
            b.velocity,
            b.angular_velocity
        );
    }
}

fuzz_target!(|spec: Spec| {
    let mut world = World::new(Vec2::new(
        spec.gravity.0.lin(-1000.0, 1000.0),
        spec.gravity.1.lin(-1000.0, 1000.0),
    ));
    world.friction = spec.friction.lin(0.0, 2.0);
    world.settings.contact_solver =
        ContactSolver::ALL[usize::from(spec.solver) % ContactSolver::ALL.len()];
    world.settings.sleeping = spec.sleeping;
    let h = spec.h.log(1e-4, 0.1);

    let specs: Vec<&Body> = std::iter::once(&spec.first)
        .chain(spec.more.iter().take(MAX_BODIES - 1))
        .collect();
    let mut bodies = Vec::new();
    for b in &specs {
        let Some(def) = body_def(b) else { continue };
        let Ok(handle) = world.add_body(def) else {
            continue;
        };
        if let Some(m) = &b.motor {
            // A motor with a refused number (MotorError) is left out: fine.
            let _ = world.add_body_motor(handle, body_motor(m));
        }
        bodies.push(handle);
    }
    if bodies.is_empty() {
        return;
    }

    for j in spec.joints.iter().take(MAX_JOINTS) {
        let a = bodies[usize::from(j.a) % bodies.len()];
        let b = j.b.map(|b| bodies[usize::from(b) % bodies.len()]);
        let pa = world.body(a).expect("a live body").position;
        let pb = b.map_or(Vec2::zeros(), |b| {
            world.body(b).expect("a live body").position
        });
        let anchor =
            pa + (pb - pa) * j.along.get() + Vec2::new(j.dx.lin(-1.0, 1.0), j.dy.lin(-1.0, 1.0));
        let mut def = JointDef::new(a, b, anchor);
        def.collide_connected = j.collide;
        def.motor = j
            .motor
            .map(|(speed, torque)| JointMotor::new(speed.lin(-20.0, 20.0), torque.log(1e-2, 1e6)));
        // A joint of a body with itself is refused: fine.
        let _ = world.add_joint(def);
    }

    if spec.median_scale
        && let Some(size) = world.median_body_radius()
    {
        world.settings.length_scale = size;
    }

    assert_finite(&world, 0);
    for step in 1..=STEPS {
        world.step(h);
        assert_finite(&world, step);
    }
});
