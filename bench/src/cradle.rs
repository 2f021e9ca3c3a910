//! Newton's cradle in every engine (`cargo run --release -- cradle`): five pendulums whose
//! bobs touch, cor 1, frictionless, one or two pulled out 30° and let go — built as
//! physics/tests/impacts.rs builds it. Each pendulum's widest swing over the second after
//! the first impact, as a share of the release angle (ideal: as many leave at 100% as came
//! in, the rest stay), and the energy after 5 s. Writes docs/bench/cradle.md and the
//! angles over the first 6 s to docs/bench/cradle.svg.

use crate::box2d_scenes;
use boxdd::{BodyId, BodyType, ShapeDef, SurfaceMaterial, WorldBuilder};
use pe::{BodyDef, BodyHandle, ContactSolver, ConvexPolygon, JointDef, Vec2, World};
use plotters::prelude::*;
use rapier2d::prelude::*;
use std::fmt::Write as _;

const H: f64 = 1.0 / 240.0;
const G: f64 = 9.81;
const PENDULUMS: usize = 5;
const RELEASE_DEGREES: f64 = 30.0;
/// Simulated from the release; the plot shows all of it.
const SECONDS: f64 = 6.0;
/// When the energy is read, from the release.
const ENERGY_AT: f64 = 5.0;
/// Box2D's default substeps.
const BOX2D_SUBSTEPS: i32 = 4;

/// One pendulum in its own frame, the pin at the origin (y up): a tapered arm widening into
/// a 1 m square bob 3–4 m below the pin.
const OUTLINE: [(f64, f64); 6] = [
    (-0.05, 0.0),
    (0.05, 0.0),
    (0.5, -3.0),
    (0.5, -4.0),
    (-0.5, -4.0),
    (-0.5, -3.0),
];

/// Pendulum `i`'s pin, in the world (y up).
fn pin(i: usize) -> (f64, f64) {
    (i as f64, 0.0)
}

/// Pendulum `i`'s angle at release (radians): the first `released` turned to the left.
fn release_angle(i: usize, released: usize) -> f64 {
    if i < released {
        -RELEASE_DEGREES.to_radians()
    } else {
        0.0
    }
}

/// One engine set up one way.
#[derive(Debug, Clone, Copy)]
enum Engine {
    Pe {
        solver: ContactSolver,
        propagate: bool,
    },
    Rapier,
    /// Box2D v3; `None` keeps its default restitution threshold (1 m/s).
    Box2d {
        restitution_threshold: Option<f32>,
    },
}

fn configurations() -> Vec<(&'static str, Engine)> {
    let pe = |solver, propagate| Engine::Pe { solver, propagate };
    vec![
        ("pe exact", pe(ContactSolver::Exact, true)),
        (
            "pe exact, simultaneous (thesis)",
            pe(ContactSolver::Exact, false),
        ),
        ("pe auto", pe(ContactSolver::Auto, true)),
        ("pe auto, simultaneous", pe(ContactSolver::Auto, false)),
        ("pe soft", pe(ContactSolver::Soft, true)),
        ("rapier2d", Engine::Rapier),
        (
            "Box2D v3",
            Engine::Box2d {
                restitution_threshold: None,
            },
        ),
        (
            "Box2D v3, restitution threshold 0",
            Engine::Box2d {
                restitution_threshold: Some(0.0),
            },
        ),
    ]
}

/// The configurations plotted, by label: one panel each.
const PLOTTED: [&str; 4] = [
    "pe auto",
    "pe exact, simultaneous (thesis)",
    "rapier2d",
    "Box2D v3, restitution threshold 0",
];

/// One body's motion, read from an engine.
#[derive(Debug, Clone, Copy)]
struct State {
    mass: f64,
    /// About the centre of mass.
    inertia: f64,
    velocity: (f64, f64),
    omega: f64,
    centre: (f64, f64),
    angle: f64,
}

impl State {
    fn energy(&self) -> f64 {
        let (vx, vy) = self.velocity;
        let kinetic =
            0.5 * self.mass * (vx * vx + vy * vy) + 0.5 * self.inertia * self.omega.powi(2);
        kinetic + self.mass * G * self.centre.1
    }

    /// The energy hanging at rest below `pin`: the centre of mass straight below it.
    fn rest_energy(&self, pin: (f64, f64)) -> f64 {
        let reach = (self.centre.0 - pin.0).hypot(self.centre.1 - pin.1);
        self.mass * G * (pin.1 - reach)
    }
}

/// A cradle in one engine.
trait Cradle {
    fn step(&mut self);
    /// The pendulums' states, in order.
    fn states(&mut self) -> Vec<State>;
}

/// One run: the angles (radians) and the energy at the release and after every step, and
/// the energy the release added (above the cradle hanging at rest).
struct Trace {
    angles: Vec<[f64; PENDULUMS]>,
    energy: Vec<f64>,
    swing: f64,
}

impl Trace {
    fn record(cradle: &mut dyn Cradle) -> Self {
        let states = cradle.states();
        let rest: f64 = (0..PENDULUMS).map(|i| states[i].rest_energy(pin(i))).sum();
        let mut trace = Self {
            angles: Vec::new(),
            energy: Vec::new(),
            swing: 0.0,
        };
        trace.push(&states);
        trace.swing = trace.energy[0] - rest;
        for _ in 0..(SECONDS / H).round() as usize {
            cradle.step();
            let states = cradle.states();
            trace.push(&states);
        }
        trace
    }

    fn push(&mut self, states: &[State]) {
        self.angles.push(std::array::from_fn(|i| states[i].angle));
        self.energy.push(states.iter().map(State::energy).sum());
    }

    /// Each pendulum's widest swing over the second after the first impact, % of the
    /// release angle. The impact is when the first pendulum reaches the bottom (its angle
    /// −0.001 rad) or a pendulum at rest starts to move (its angle past ±0.001 rad),
    /// whichever comes first: in some engines the first bounces back before the bottom.
    fn swings(&self, released: usize) -> [f64; PENDULUMS] {
        let struck =
            |a: &[f64; PENDULUMS]| a[0] >= -1e-3 || a[released..].iter().any(|x| x.abs() >= 1e-3);
        let bottom = self
            .angles
            .iter()
            .position(struck)
            .unwrap_or(self.angles.len());
        let window = self.angles.iter().skip(bottom + 1).take((1.0 / H) as usize);
        let widest = window.fold([0.0_f64; PENDULUMS], |w, a| {
            std::array::from_fn(|i| w[i].max(a[i].abs()))
        });
        widest.map(|w| 100.0 * w / RELEASE_DEGREES.to_radians())
    }

    /// The energy's change at `ENERGY_AT`, % of the energy the release added.
    fn energy_change(&self) -> f64 {
        let at = ((ENERGY_AT / H).round() as usize).min(self.energy.len() - 1);
        100.0 * (self.energy[at] - self.energy[0]) / self.swing
    }
}

struct PeCradle {
    world: World,
    bodies: Vec<BodyHandle>,
}

impl PeCradle {
    fn new(solver: ContactSolver, propagate: bool, released: usize) -> Self {
        let mut world = World::new(Vec2::new(0.0, -G));
        world.settings.contact_solver = solver;
        world.settings.propagate_impacts = propagate;
        let outline: Vec<Vec2> = OUTLINE.iter().map(|&(x, y)| Vec2::new(x, y)).collect();
        let shape = ConvexPolygon::new(&outline).expect("convex");
        let bodies = (0..PENDULUMS)
            .map(|i| {
                let at = Vec2::new(pin(i).0, pin(i).1);
                let def = BodyDef::new(shape.clone(), 1.0)
                    .restitution(1.0)
                    .friction(0.0)
                    .at(at, release_angle(i, released));
                let body = world.add_body(def).expect("a valid body");
                world
                    .add_joint(JointDef::new(body, None, at))
                    .expect("a valid pin");
                body
            })
            .collect();
        Self { world, bodies }
    }
}

impl Cradle for PeCradle {
    fn step(&mut self) {
        self.world.step(H);
    }

    fn states(&mut self) -> Vec<State> {
        let read = |&b: &BodyHandle| {
            let b = self.world.body(b).expect("bodies are never removed");
            State {
                mass: b.mass(),
                inertia: b.inertia(),
                velocity: (b.velocity.x, b.velocity.y),
                omega: b.angular_velocity,
                centre: (b.position.x, b.position.y),
                angle: b.angle,
            }
        };
        self.bodies.iter().map(read).collect()
    }
}

struct RapierCradle {
    world: PhysicsWorld,
    bodies: Vec<RigidBodyHandle>,
}

impl RapierCradle {
    /// Convex polygon colliders, restitution 1 combined by the maximum, no friction;
    /// each pendulum pinned by a revolute impulse joint to one fixed body at the origin.
    fn new(released: usize) -> Self {
        let mut world = PhysicsWorld::new();
        world.gravity = Vector::new(0.0, -G as Real);
        world.integration_parameters.dt = H as Real;
        let outline: Vec<Vector> = OUTLINE
            .iter()
            .map(|&(x, y)| Vector::new(x as Real, y as Real))
            .collect();
        let fixed = world.insert_body(RigidBodyBuilder::fixed());
        let bodies: Vec<RigidBodyHandle> = (0..PENDULUMS)
            .map(|i| {
                let (x, y) = pin(i);
                let body = RigidBodyBuilder::dynamic()
                    .translation(Vector::new(x as Real, y as Real))
                    .rotation(release_angle(i, released) as Real)
                    .can_sleep(false);
                let shape = ColliderBuilder::convex_hull(&outline)
                    .expect("a convex hull")
                    .density(1.0)
                    .restitution(1.0)
                    .restitution_combine_rule(CoefficientCombineRule::Max)
                    .friction(0.0)
                    .friction_combine_rule(CoefficientCombineRule::Min);
                let (handle, _) = world.insert(body, shape);
                let joint = RevoluteJointBuilder::new()
                    .local_anchor1(Vector::new(x as Real, y as Real))
                    .local_anchor2(Vector::ZERO);
                world.insert_impulse_joint(fixed, handle, joint);
                handle
            })
            .collect();
        // Mass properties are otherwise only updated inside the first step.
        let PhysicsWorld {
            bodies: set,
            colliders,
            ..
        } = &mut world;
        for &b in &bodies {
            set[b].recompute_mass_properties_from_colliders(colliders);
        }
        Self { world, bodies }
    }
}

impl Cradle for RapierCradle {
    fn step(&mut self) {
        self.world.step();
    }

    fn states(&mut self) -> Vec<State> {
        let read = |&b: &RigidBodyHandle| {
            let b = &self.world.bodies[b];
            let (v, c) = (b.linvel(), b.center_of_mass());
            State {
                mass: f64::from(b.mass()),
                inertia: f64::from(b.mass_properties().local_mprops.principal_inertia()),
                velocity: (f64::from(v.x), f64::from(v.y)),
                omega: f64::from(b.angvel()),
                centre: (f64::from(c.x), f64::from(c.y)),
                angle: f64::from(b.rotation().angle()),
            }
        };
        self.bodies.iter().map(read).collect()
    }
}

struct Box2dCradle {
    world: boxdd::World,
    bodies: Vec<BodyId>,
}

impl Box2dCradle {
    /// Polygons from the outline's hull, restitution 1, no friction; each pendulum pinned
    /// by a revolute joint to a static body at the origin; sleeping off, defaults otherwise
    /// but the restitution threshold if given.
    fn new(released: usize, restitution_threshold: Option<f32>) -> Self {
        let f = box2d_scenes::foundation();
        let mut def = WorldBuilder::from(f.world_def())
            .gravity(boxdd::Vec2::new(0.0, -G as f32))
            .enable_sleep(false);
        if let Some(v) = restitution_threshold {
            def = def.restitution_threshold(v);
        }
        let mut world = f
            .create_world(def.build().expect("a valid world definition"))
            .expect("a new world");
        let ground_def = box2d_scenes::body_builder(BodyType::Static)
            .build()
            .expect("a valid body");
        let ground = world.create_body(ground_def).expect("a new body");
        let material = SurfaceMaterial::default()
            .with_friction(0.0)
            .and_then(|m| m.with_restitution(1.0))
            .expect("a valid material");
        let shape = ShapeDef::builder()
            .material(material)
            .density(1.0)
            .build()
            .expect("a valid shape");
        let outline = OUTLINE.map(|(x, y)| boxdd::Vec2::new(x as f32, y as f32));
        let polygon = boxdd::shapes::polygon_from_points(outline, 0.0).expect("a convex hull");
        let bodies = (0..PENDULUMS)
            .map(|i| {
                let at = box2d_scenes::point(pin(i));
                let def = box2d_scenes::body_builder(BodyType::Dynamic)
                    .position(at)
                    .angle(release_angle(i, released) as f32)
                    .build()
                    .expect("a valid body");
                let id = world.create_body(def).expect("a new body");
                world
                    .body(id)
                    .and_then(|mut b| b.create_polygon(&shape, &polygon))
                    .expect("a new shape");
                world
                    .create_revolute_joint_world(ground, id, at)
                    .expect("a new pin");
                id
            })
            .collect();
        Self { world, bodies }
    }
}

impl Cradle for Box2dCradle {
    fn step(&mut self) {
        box2d_scenes::step(&mut self.world, H, BOX2D_SUBSTEPS);
    }

    fn states(&mut self) -> Vec<State> {
        let mut states = Vec::with_capacity(self.bodies.len());
        for &id in &self.bodies {
            states.push(box2d_scenes::read(&mut self.world, id, |b| {
                let (v, c, r) = (
                    b.linear_velocity()?,
                    b.world_center_of_mass()?,
                    b.rotation()?,
                );
                Ok(State {
                    mass: f64::from(b.mass()?),
                    inertia: f64::from(b.rotational_inertia()?),
                    velocity: (f64::from(v.x), f64::from(v.y)),
                    omega: f64::from(b.angular_velocity()?),
                    centre: (f64::from(c.x), f64::from(c.y)),
                    angle: f64::from(r.sine()).atan2(f64::from(r.cosine())),
                })
            }));
        }
        states
    }
}

fn trace(engine: Engine, released: usize) -> Trace {
    let mut cradle: Box<dyn Cradle> = match engine {
        Engine::Pe { solver, propagate } => Box::new(PeCradle::new(solver, propagate, released)),
        Engine::Rapier => Box::new(RapierCradle::new(released)),
        Engine::Box2d {
            restitution_threshold,
        } => Box::new(Box2dCradle::new(released, restitution_threshold)),
    };
    Trace::record(cradle.as_mut())
}

/// Every configuration, one and two released: returns the Markdown of
/// docs/bench/cradle.md (without its machine line), and draws the plot to
/// `out_dir`/cradle.svg.
pub fn run(out_dir: &str) -> String {
    let mut md = String::new();
    let _ = writeln!(md, "# Newton's cradle\n");
    let _ = writeln!(
        md,
        "Written by `cd bench && cargo run --release -- cradle` (bench/src/cradle.rs). Five \
         pendulums, each one convex body (a tapered arm from its pin to a 1 m square bob \
         3–4 m below), density 1, pinned to the world 1 m apart so that the bobs touch; \
         cor 1, friction 0, g = {G} m/s², h = 1/240 s; the first one (or two) turned \
         {RELEASE_DEGREES}° to the left and let go. Each cell lists the pendulums' widest \
         swings over the second after the first impact (from when the first pendulum \
         reaches the bottom or one at rest starts to move, whichever is first), in % of \
         the release angle, first to last: ideally 0 · 0 · 0 · 0 · 100 with one released \
         and 0 · 0 · 0 · 100 · 100 with two. ΔE: the energy (kinetic + gravitational) \
         {ENERGY_AT} s after the release less the energy at release, in % of the energy \
         the release added (above the cradle at rest); ideally 0.\n"
    );
    let _ = writeln!(
        md,
        "pe: `propagate_impacts` on (the default) unless marked simultaneous, where every \
         contact of the island bounces in one LCP as in the thesis. rapier2d: convex-hull \
         colliders, restitution 1 (combine rule max), friction 0, revolute impulse joints \
         to a fixed body, default integration parameters but dt. Box2D v3 (boxdd): \
         polygons from the hull, restitution 1, friction 0, revolute joints to a static \
         body, {BOX2D_SUBSTEPS} substeps; by default it bounces only contacts approaching \
         faster than 1 m/s (`restitutionThreshold`), set to 0 in the last row.\n"
    );
    let _ = writeln!(
        md,
        "| engine | one released: swings (%) | ΔE (%) | two released: swings (%) | ΔE (%) |"
    );
    let _ = writeln!(md, "|---|---|---:|---|---:|");
    let mut plotted = Vec::new();
    for (label, engine) in configurations() {
        eprint!("{label}…");
        let (one, two) = (trace(engine, 1), trace(engine, 2));
        let cell = |t: &Trace, released| t.swings(released).map(|s| format!("{s:.0}")).join(" · ");
        let _ = writeln!(
            md,
            "| {label} | {} | {:+.1} | {} | {:+.1} |",
            cell(&one, 1),
            one.energy_change(),
            cell(&two, 2),
            two.energy_change()
        );
        if PLOTTED.contains(&label) {
            plotted.push((label, one));
        }
    }
    eprintln!();
    plotted.sort_by_key(|(label, _)| PLOTTED.iter().position(|p| p == label));
    match plot(&format!("{out_dir}/cradle.svg"), &plotted) {
        Ok(()) => {
            let _ = writeln!(
                md,
                "\n![Each pendulum's angle over the first {SECONDS} s, one released]\
                 (cradle.svg)\n"
            );
        }
        Err(e) => {
            let _ = writeln!(md, "\n(plot failed: {e})\n");
        }
    }
    md
}

/// One panel per configuration, one line per pendulum: its angle (degrees) against time.
fn plot(path: &str, traces: &[(&str, Trace)]) -> Result<(), Box<dyn std::error::Error>> {
    let root = SVGBackend::new(path, (1200, 800)).into_drawing_area();
    root.fill(&WHITE)?;
    let root = root.titled(
        &format!(
            "Newton's cradle, one pendulum released at {RELEASE_DEGREES}°: \
             each pendulum's angle (°)"
        ),
        ("sans-serif", 22),
    )?;
    let limit = RELEASE_DEGREES * 1.2;
    for (area, (label, trace)) in root.split_evenly((2, 2)).iter().zip(traces) {
        let mut chart = ChartBuilder::on(area)
            .caption(*label, ("sans-serif", 18))
            .margin(10)
            .x_label_area_size(35)
            .y_label_area_size(55)
            .build_cartesian_2d(0.0..SECONDS, -limit..limit)?;
        chart
            .configure_mesh()
            .light_line_style(WHITE)
            .bold_line_style(BLACK.mix(0.15))
            .x_desc("time (s)")
            .y_desc("angle (°)")
            .draw()?;
        for i in 0..PENDULUMS {
            let color = Palette99::pick(i).to_rgba();
            let points = trace
                .angles
                .iter()
                .enumerate()
                .map(|(n, a)| (n as f64 * H, a[i].to_degrees()));
            chart
                .draw_series(LineSeries::new(points, color.stroke_width(2)))?
                .label(format!("pendulum {}", i + 1))
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], color));
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .position(SeriesLabelPosition::UpperLeft)
            .draw()?;
    }
    root.present()?;
    Ok(())
}
