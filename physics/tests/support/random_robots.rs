//! Random robots and the invariants every solver must keep on them: the physics-invariant
//! fuzzer's worlds and its judge, shared by the property test (`physics/tests/invariants.rs`,
//! seeded, in `cargo test`) and the cargo-fuzz target (`fuzz/fuzz_targets/robot_invariants.rs`).
//!
//! A robot is links (bars, or a polygon for a hub or a wheel) pinned into a chain, a tree,
//! a closed loop or a hub with spokes, with mass ratios up to 1e4, each link at a random
//! angle (so links not pinned to each other may overlap, or not), free or pinned to the
//! static world, in free space, on a floor or partly inside it, at rest or thrown, with
//! or without gravity and motors. Every number comes from `draw`, a source of random
//! words: a seeded generator in the test, the fuzzer's bytes in the fuzz target.
//!
//! The invariants, checked at every step (`judge`):
//! - every step is taken (no `StepError`) and every number stays finite;
//! - with no gravity and no motor, the kinetic energy never rises above its start by more
//!   than the push-out allowance: bodies placed overlapping may be pushed apart at the
//!   solvers' push-out speed (3 length scales a second), none placed apart gains any;
//! - with no gravity, no static body and no body motor (joint motors act inside the
//!   robot), the linear momentum keeps its start;
//! - a body whose state says it moves does move: no pose kept to the bit while the body
//!   reports a velocity;
//! - with nothing to move it (no gravity, no motor, no overlap, no throw), nothing moves;
//! - at the end every pin is closed within the solver's tolerance.

// Each user takes what it needs of this file.
#![allow(dead_code)]

use pe::{
    BodyDef, BodyHandle, BodyMotor, ContactSolver, ConvexPolygon, JointDef, JointHandle,
    JointMotor, Vec2, World,
};

pub const H: f64 = 1.0 / 60.0;
pub const STEPS: usize = 120;
const GRAVITY: f64 = 10.0;
/// The solvers' fastest push-out, in length scales a second (`StepSettings`' split
/// impulse and the soft contacts' `max_push_speed`).
const PUSH_OUT: f64 = 3.0;

/// The shapes a robot's pins make.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Topology {
    Chain,
    Tree,
    Loop,
    Hub,
}

/// Where the robot starts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Placing {
    FreeSpace,
    OnFloor,
    PartlyInFloor,
}

/// A random robot in its world, and what the judge needs to know about how it was made.
pub struct Trial {
    pub world: World,
    pub bodies: Vec<BodyHandle>,
    pub joints: Vec<JointHandle>,
    pub topology: Topology,
    pub placing: Placing,
    pub gravity: bool,
    pub joint_motors: usize,
    pub body_motors: usize,
    /// Pinned to the static world, or standing on or in a floor.
    pub static_bodies: bool,
    pub thrown: bool,
    /// The largest mass over the smallest among the links.
    pub mass_ratio: f64,
}

/// Draws numbers from a source of random words.
pub struct Draw<'a>(pub &'a mut dyn FnMut() -> u64);

impl Draw<'_> {
    pub fn unit(&mut self) -> f64 {
        ((self.0)() >> 11) as f64 / (1u64 << 53) as f64
    }
    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }
    pub fn log_uniform(&mut self, lo: f64, hi: f64) -> f64 {
        (lo.ln() + (hi.ln() - lo.ln()) * self.unit()).exp()
    }
    pub fn below(&mut self, n: usize) -> usize {
        ((self.0)() % n as u64) as usize
    }
    pub fn chance(&mut self, p: f64) -> bool {
        self.unit() < p
    }
}

/// SplitMix64, the property test's source of words.
pub struct SplitMix(pub u64);

impl SplitMix {
    pub fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
}

/// A link: a bar between two pins `length` apart (or a regular polygon of `sides`), its
/// pins inside it at either end.
struct Link {
    shape: ConvexPolygon,
    /// From the centre to each pin, in the link's frame.
    half_span: f64,
}

fn link(draw: &mut Draw, polygon: bool) -> Link {
    if polygon {
        let radius = draw.uniform(0.3, 0.8);
        let sides = 5 + draw.below(6);
        let shape = ConvexPolygon::regular(sides, radius).expect("a regular polygon");
        return Link {
            shape,
            half_span: 0.5 * radius,
        };
    }
    let length = draw.uniform(0.6, 2.0);
    let width = draw.uniform(0.1, 0.4);
    let shape = ConvexPolygon::rectangle(length, width).expect("a bar");
    Link {
        shape,
        half_span: 0.5 * (length - width),
    }
}

/// A random robot in a world under `solver` (see the module's description).
pub fn random_robot(draw: &mut Draw, solver: ContactSolver) -> Trial {
    let topology = [
        Topology::Chain,
        Topology::Tree,
        Topology::Loop,
        Topology::Hub,
    ][draw.below(4)];
    let placing = [Placing::FreeSpace, Placing::OnFloor, Placing::PartlyInFloor][draw.below(3)];
    let gravity = draw.chance(0.5);
    let mut world = World::new(Vec2::new(0.0, if gravity { GRAVITY } else { 0.0 }));
    world.settings.contact_solver = solver;
    world.friction = [0.0, 0.5, 1.0][draw.below(3)];
    let count = 2 + draw.below(6);
    // Each link's centre, angle and pins (two world points) as placed.
    let mut placed: Vec<(Link, Vec2, f64)> = Vec::new();
    let mut pins: Vec<(usize, Option<usize>, Vec2)> = Vec::new();
    let end = |(l, c, a): &(Link, Vec2, f64), side: f64| {
        c + Vec2::new(a.cos(), a.sin()) * (side * l.half_span)
    };
    match topology {
        Topology::Loop => {
            // Bars along a closed polygon, pinned at its corners: the loop closes as placed.
            let sides = count.max(3);
            let radius = draw.uniform(0.8, 2.0);
            let turn = draw.uniform(0.0, 6.3);
            let corner = |k: usize| {
                let t = turn + std::f64::consts::TAU * k as f64 / sides as f64;
                Vec2::new(t.cos(), t.sin()) * radius
            };
            for k in 0..sides {
                let (p, q) = (corner(k), corner(k + 1));
                let width = draw.uniform(0.1, 0.3);
                let span = (q - p).norm();
                let shape = ConvexPolygon::rectangle(span + width, width).expect("a bar");
                let angle = (q.y - p.y).atan2(q.x - p.x);
                let l = Link {
                    shape,
                    half_span: 0.5 * span,
                };
                placed.push((l, (p + q) * 0.5, angle));
                pins.push((k, Some((k + 1) % sides), q));
            }
        }
        Topology::Hub => {
            let hub = link(draw, true);
            let hub_radius = hub.half_span * 2.0;
            placed.push((hub, Vec2::zeros(), 0.0));
            let at_centre = draw.chance(0.5);
            for k in 1..count.max(3) {
                let spoke = link(draw, false);
                let t = draw.uniform(0.0, 6.3);
                let dir = Vec2::new(t.cos(), t.sin());
                // Pinned at the hub's centre (every spoke about one pivot) or at a point
                // of its rim.
                let pivot = if at_centre {
                    Vec2::zeros()
                } else {
                    dir * (0.6 * hub_radius)
                };
                let centre = pivot + dir * spoke.half_span;
                placed.push((spoke, centre, t));
                pins.push((0, Some(k), pivot));
            }
        }
        Topology::Chain | Topology::Tree => {
            let polygon = draw.chance(0.2);
            let first = link(draw, polygon);
            placed.push((first, Vec2::zeros(), draw.uniform(0.0, 6.3)));
            for k in 1..count {
                let parent = if topology == Topology::Chain {
                    k - 1
                } else {
                    draw.below(k)
                };
                let side = if topology == Topology::Chain || draw.chance(0.5) {
                    1.0
                } else {
                    draw.uniform(-1.0, 1.0)
                };
                let pivot = end(&placed[parent], side);
                let polygon = draw.chance(0.15);
                let l = link(draw, polygon);
                let angle = draw.uniform(0.0, 6.3);
                let centre = pivot + Vec2::new(angle.cos(), angle.sin()) * l.half_span;
                placed.push((l, centre, angle));
                pins.push((parent, Some(k), pivot));
            }
        }
    }
    // Densities log-uniform over four decades: mass ratios up to 1e4 and more.
    let mut bodies = Vec::new();
    let mut masses = Vec::new();
    let thrown = draw.chance(0.4);
    for (l, centre, angle) in &placed {
        let density = draw.log_uniform(1.0, 1e4);
        masses.push(density * l.shape.mass_properties().area);
        let restitution = [0.0, 0.0, 0.5, 1.0][draw.below(4)];
        let mut def = BodyDef::new(l.shape.clone(), density)
            .restitution(restitution)
            .at(*centre, *angle);
        if thrown {
            def = def.velocity(
                Vec2::new(draw.uniform(-2.0, 2.0), draw.uniform(-2.0, 2.0)),
                draw.uniform(-2.0, 2.0),
            );
        }
        bodies.push(world.add_body(def).expect("a legal body"));
    }
    let mounted = draw.chance(0.4);
    if mounted {
        pins.push((0, None, end(&placed[0], -1.0)));
    }
    // Joint motors on one or two pins, at most 0.3 rad a step, with a torque from a
    // hundredth to a hundred times the robot's weight (in length scales).
    let mut motors = vec![None; pins.len()];
    let mut joint_motors = 0;
    if draw.chance(0.4) {
        let weight: f64 = masses.iter().sum::<f64>() * GRAVITY;
        for _ in 0..1 + draw.below(2) {
            let speed = draw.uniform(-0.3, 0.3) / H;
            let torque = draw.log_uniform(1e-2, 1e2) * weight;
            let k = draw.below(pins.len());
            if motors[k].is_none() {
                joint_motors += 1;
            }
            motors[k] = Some(JointMotor::new(speed, torque));
        }
    }
    let mut joints = Vec::new();
    for (&(a, b, at), motor) in pins.iter().zip(motors) {
        let mut def = JointDef::new(bodies[a], b.map(|b| bodies[b]), at);
        def.motor = motor;
        joints.push(world.add_joint(def).expect("a legal pin"));
    }
    let mut body_motors = 0;
    if draw.chance(0.2) {
        let k = draw.below(bodies.len());
        let torque = draw.log_uniform(1e-1, 1e2) * masses[k] * GRAVITY;
        let motor = BodyMotor::new(0, 60, draw.uniform(-0.2, 0.2), torque, 2.0 * torque, 0.05);
        world
            .add_body_motor(bodies[k], motor)
            .expect("a legal motor");
        body_motors += 1;
    }
    let floor_placed = placing != Placing::FreeSpace;
    if floor_placed {
        // A floor under the robot's lowest point, or a fraction of its height above it.
        let ys: Vec<f64> = bodies
            .iter()
            .flat_map(|&h| world.body(h).expect("a body").world_vertices())
            .map(|v| v.y)
            .collect();
        let lowest = ys.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let highest = ys.iter().copied().fold(f64::INFINITY, f64::min);
        let sunk = if placing == Placing::PartlyInFloor {
            draw.uniform(0.1, 0.6) * (lowest - highest)
        } else {
            0.0
        };
        let floor = ConvexPolygon::rectangle(40.0, 2.0).expect("a floor");
        world
            .add_body(BodyDef::new(floor, 0.0).at(Vec2::new(0.0, lowest - sunk + 1.0), 0.0))
            .expect("a legal floor");
    }
    world.settings.length_scale = world.median_body_radius().unwrap_or(1.0);
    let light = masses.iter().copied().fold(f64::INFINITY, f64::min);
    let heavy = masses.iter().copied().fold(0.0, f64::max);
    Trial {
        world,
        bodies,
        joints,
        topology,
        placing,
        gravity,
        joint_motors,
        body_motors,
        static_bodies: mounted || floor_placed,
        thrown,
        mass_ratio: heavy / light,
    }
}

/// Where a solver gains no kinetic energy without gravity or motors.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum EnergyPromise {
    /// Anywhere, beyond the push-out allowance where bodies start overlapping.
    Everywhere,
    /// Where no bodies start overlapping: the soft step's pins pull bodies that contacts
    /// push apart back faster than contacts push.
    UnlessOverlapping,
    /// Where nothing holds the robot (no floor, no mount) and nothing starts overlapping:
    /// pins solved apart from the contacts, each pass closing what the other opened, can
    /// gain energy against a contact that holds a pinned body.
    FreeAndApart,
}

/// What each solver is held to (docs/physics.md, "What the solvers guarantee").
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Promises {
    /// The widest pin gap at the end, in length scales (infinite: not promised).
    pub pins: f64,
    /// Where no kinetic energy is gained (with no gravity and no motor).
    pub energy: EnergyPromise,
    /// Whether a pin torn by a load or an overlap the method cannot hold ends the run
    /// with `StepError::PinTorn` rather than breaking a promise.
    pub may_refuse_torn_pins: bool,
    /// Whether a body whose state says it moves always moves. Where pins are solved
    /// apart from the contacts, a body held by a contact can be dragged into it by the
    /// pins' pass and repaired back out at the next step's start: it moves within each
    /// step, and ends each where it was.
    pub moving_moves: bool,
}

/// The default path (`auto`, and `exact` that it sends robots to) keeps every invariant.
/// The soft step's pins are springs: they stretch under loads and contacts (half a link
/// and more), and pull apart bodies placed overlapping back faster than contacts push.
/// The thesis's and the sequential method's pins are solved apart from the contacts,
/// which may hold them open.
pub fn promises(solver: ContactSolver) -> Promises {
    match solver {
        ContactSolver::Auto | ContactSolver::Exact => Promises {
            pins: 1e-2,
            energy: EnergyPromise::Everywhere,
            may_refuse_torn_pins: false,
            moving_moves: true,
        },
        ContactSolver::Soft => Promises {
            pins: f64::INFINITY,
            energy: EnergyPromise::UnlessOverlapping,
            may_refuse_torn_pins: true,
            moving_moves: true,
        },
        ContactSolver::Thesis | ContactSolver::Sequential => Promises {
            pins: f64::INFINITY,
            energy: EnergyPromise::FreeAndApart,
            may_refuse_torn_pins: true,
            moving_moves: false,
        },
    }
}

/// Steps `trial` and checks the invariants at every step; `Err` names the first broken.
pub fn judge(trial: &mut Trial) -> Result<(), String> {
    let w = &mut trial.world;
    let scale = w.settings.length_scale;
    let solver = w.settings.contact_solver;
    let total_mass: f64 = trial
        .bodies
        .iter()
        .map(|&h| w.body(h).expect("a body").mass())
        .sum();
    let kinetic = |w: &World| -> f64 {
        trial
            .bodies
            .iter()
            .map(|&h| {
                let b = w.body(h).expect("a body");
                0.5 * (b.mass() * b.velocity.norm_squared()
                    + b.inertia() * b.angular_velocity * b.angular_velocity)
            })
            .sum()
    };
    let momentum = |w: &World| -> Vec2 {
        trial
            .bodies
            .iter()
            .map(|&h| {
                let b = w.body(h).expect("a body");
                b.velocity * b.mass()
            })
            .sum()
    };
    let overlapping = starts_overlapping(w);
    let promised = promises(solver);
    let passive = !trial.gravity && trial.joint_motors == 0 && trial.body_motors == 0;
    let unit_energy = 0.5 * total_mass * scale * scale;
    let start_energy = kinetic(w);
    let start_momentum = momentum(w);
    for step in 0..STEPS {
        let before: Vec<[u64; 3]> = trial
            .bodies
            .iter()
            .map(|&h| {
                let b = w.body(h).expect("a body");
                [b.position.x, b.position.y, b.angle].map(f64::to_bits)
            })
            .collect();
        match w.try_step(H) {
            Ok(()) => {}
            Err(pe::StepError::PinTorn { .. }) if promised.may_refuse_torn_pins => return Ok(()),
            Err(e) => return Err(format!("step {step}: {e}")),
        }
        for (k, &h) in trial.bodies.iter().enumerate() {
            let b = w.body(h).expect("a body");
            if !b.state().iter().all(|v| v.is_finite()) {
                return Err(format!("step {step}: body {k} is not finite"));
            }
            let now = [b.position.x, b.position.y, b.angle].map(f64::to_bits);
            let moving =
                b.velocity.norm() * H > 1e-9 * scale || b.angular_velocity.abs() * H > 1e-9;
            if now == before[k] && moving && promised.moving_moves {
                return Err(format!(
                    "step {step}: body {k} did not move but reports velocity {:?}, spin {}",
                    b.velocity, b.angular_velocity
                ));
            }
        }
        let energy_promised = match promised.energy {
            EnergyPromise::Everywhere => true,
            EnergyPromise::UnlessOverlapping => !overlapping,
            EnergyPromise::FreeAndApart => !overlapping && !trial.static_bodies,
        };
        if passive && energy_promised {
            let energy = kinetic(w);
            let push_allowance = if overlapping {
                PUSH_OUT * PUSH_OUT * unit_energy
            } else {
                0.0
            };
            let allowed = start_energy * (1.0 + 1e-6) + 1e-9 * unit_energy + push_allowance;
            if energy > allowed {
                return Err(format!(
                    "step {step}: kinetic energy {energy:e} rose above {start_energy:e} (allowed {allowed:e})"
                ));
            }
        }
        if !trial.gravity && !trial.static_bodies && trial.body_motors == 0 {
            let drift = (momentum(w) - start_momentum).norm();
            let size = start_momentum.norm() + total_mass * scale;
            if drift > 1e-9 * size {
                return Err(format!(
                    "step {step}: linear momentum moved by {drift:e} (of {size:e})"
                ));
            }
        }
        if passive && !overlapping && !trial.thrown {
            let fastest = trial
                .bodies
                .iter()
                .map(|&h| w.body(h).expect("a body").velocity.norm())
                .fold(0.0, f64::max);
            if fastest > 1e-9 * scale {
                return Err(format!("step {step}: a robot at rest moves at {fastest:e}"));
            }
        }
    }
    let widest = trial
        .joints
        .iter()
        .filter_map(|&j| w.joint_gap(j))
        .fold(0.0, f64::max);
    let tolerance = promised.pins * scale;
    if widest > tolerance {
        return Err(format!(
            "a pin is {widest:e} open at the end (tolerance {tolerance:e})"
        ));
    }
    Ok(())
}

/// Whether two bodies that may collide (not pinned to each other, not both static)
/// overlap deeper than the world's slop as placed: the solvers may push them apart.
fn starts_overlapping(w: &World) -> bool {
    let slop = w.settings.slop();
    let polygons: Vec<(BodyHandle, bool, pe::WorldPolygon)> = w
        .bodies()
        .map(|(h, b)| {
            let mut p = pe::WorldPolygon::default();
            p.set_vertices(b.world_vertices());
            (h, b.is_static(), p)
        })
        .collect();
    let pinned = |a: BodyHandle, b: BodyHandle| {
        w.joints().any(|(_, j)| {
            (j.body_a == a && j.body_b == Some(b)) || (j.body_a == b && j.body_b == Some(a))
        })
    };
    polygons.iter().enumerate().any(|(i, (a, a_static, pa))| {
        polygons[i + 1..].iter().any(|(b, b_static, pb)| {
            !(pinned(*a, *b) || *a_static && *b_static)
                && pe::collide_polygons((*a, pa), (*b, pb), 0.0, 0.0)
                    .is_some_and(|m| m.points().iter().any(|p| p.depth > slop))
        })
    })
}
