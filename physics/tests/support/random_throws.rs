//! Random throws: convex bodies thrown together in a walled box (the worlds of the
//! hard-case property test), each stepped 1,000 times, and the deepest overlap after the
//! first 2 s over the smallest body's radius. A throw sinks past `BOUND` (the property
//! test's bound), and is put in one of three classes by its deepest overlap:
//!
//! - *overlapping from the start*: the pair already overlapped by more than the bound in
//!   the first steps (random starts may overlap; some solvers take longer to part them);
//! - *in one step*: the pair was within the bound (or apart) one step before: an impact;
//! - *gradually*: the pair sank past the bound over several steps.
//!
//! The worlds are described apart from any engine (`Throw`), and judged from the bodies'
//! poses after each step by pe's separating-axis test (`Judge`), so that other engines'
//! runs of the same throws are judged by the same code.
//!
//! Shared by `physics/examples/throw_survey.rs` (the survey), `physics/tests/hard_cases.rs`
//! (its test) and the benchmark's `throws` (`bench/src/throws.rs`: pe, rapier2d and
//! Box2D v3 on the same throws).

// Each user takes what it needs of this file.
#![allow(dead_code)]

use pe::{
    BodyDef, BodyHandle, ContactSolver, ConvexPolygon, Vec2, World, WorldPolygon, collide_polygons,
};
use std::collections::{HashMap, HashSet};
use std::time::{Duration, Instant};

pub const H: f64 = 1.0 / 60.0;
pub const STEPS: usize = 1000;
/// Deepest overlaps are judged from this step on (2 s), as in the property test.
const JUDGED_FROM: usize = 120;
pub const BOUND: f64 = 0.2;
/// A throw gains energy if it rises above its start by more than this much of
/// Σ m g × the box's height (the property test's bound).
pub const ENERGY_BOUND: f64 = 0.01;
/// Along +y: pe's y points down.
pub const GRAVITY: f64 = 10.0;
/// Every contact's friction coefficient.
pub const FRICTION: f64 = 0.5;
/// The thrown bodies' density.
pub const DENSITY: f64 = 1.0;
/// The fixed floor and walls (size, centre) of a 20 × 20 box around [-10, 10] × [-20, 0],
/// 1 thick. Their restitution is 1, and a pair takes the smaller of its two bodies'
/// (pe's rule), so a body bounces off them with its own.
pub const WALLS: [((f64, f64), (f64, f64)); 3] = [
    ((22.0, 1.0), (0.0, 0.5)),
    ((1.0, 22.0), (-10.5, -10.0)),
    ((1.0, 22.0), (10.5, -10.0)),
];
pub const WALL_RESTITUTION: f64 = 1.0;
/// The box's inside height, for the energy's scale.
const BOX_HEIGHT: f64 = 20.0;

/// SplitMix64: enough randomness for reproducible worlds without a dependency.
pub struct Numbers(pub u64);

impl Numbers {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }

    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
}

/// One thrown body: a regular polygon centred on its position.
#[derive(Debug, Clone)]
pub struct ThrownBody {
    pub shape: ConvexPolygon,
    pub radius: f64,
    pub at: Vec2,
    pub angle: f64,
    pub velocity: Vec2,
    pub spin: f64,
    pub restitution: f64,
}

impl ThrownBody {
    pub fn mass(&self) -> f64 {
        DENSITY * self.shape.mass_properties().area
    }

    /// About its centre, which is its position: a regular polygon's centroid.
    pub fn inertia(&self) -> f64 {
        DENSITY * self.shape.mass_properties().second_moment
    }
}

/// A random world: 2–23 regular polygons of 3–8 sides, radius 0.2–1.5, random poses,
/// velocities, spins, and restitution 0, 0.3 or 0.8, above the floor of the walled box.
pub struct Throw {
    pub bodies: Vec<ThrownBody>,
    pub smallest: f64,
}

impl Throw {
    pub fn random(numbers: &mut Numbers) -> Self {
        let count = 2 + numbers.below(22) as usize;
        let bodies: Vec<ThrownBody> = (0..count)
            .map(|i| {
                let sides = 3 + numbers.below(6) as usize;
                let radius = numbers.uniform(0.2, 1.5);
                let at = Vec2::new(
                    numbers.uniform(-8.0, 8.0),
                    numbers.uniform(-12.0, -1.0) - 0.01 * i as f64,
                );
                ThrownBody {
                    shape: ConvexPolygon::regular(sides, radius).expect("a regular polygon"),
                    radius,
                    at,
                    angle: numbers.uniform(0.0, 6.3),
                    velocity: Vec2::new(numbers.uniform(-5.0, 5.0), numbers.uniform(-5.0, 5.0)),
                    spin: numbers.uniform(-3.0, 3.0),
                    restitution: [0.0, 0.3, 0.8][numbers.below(3) as usize],
                }
            })
            .collect();
        let smallest = bodies
            .iter()
            .map(|b| b.radius)
            .fold(f64::INFINITY, f64::min);
        Self { bodies, smallest }
    }

    /// The throw as a pe world; the walls are bodies 0–2, the thrown ones follow in order.
    /// Its length scale is the median radius, as the app gives a scene (`sim`): a typical
    /// body's size, as the setting means, and near the 1 m the peers' defaults assume.
    pub fn pe_world(&self, solver: ContactSolver, substeps: Option<usize>) -> World {
        let mut w = walled_box(solver);
        if let Some(substeps) = substeps {
            w.settings.soft_substeps = substeps;
        }
        for body in &self.bodies {
            let def = BodyDef::new(body.shape.clone(), DENSITY)
                .restitution(body.restitution)
                .at(body.at, body.angle)
                .velocity(body.velocity, body.spin);
            w.add_body(def).expect("a random body");
        }
        w.settings.length_scale = w.median_body_radius().expect("thrown bodies");
        w
    }
}

/// The walled box alone (`WALLS`), under `solver`.
pub fn walled_box(solver: ContactSolver) -> World {
    let mut w = World::new(Vec2::new(0.0, GRAVITY));
    w.settings.contact_solver = solver;
    w.friction = FRICTION;
    for ((width, height), (x, y)) in WALLS {
        let shape = ConvexPolygon::rectangle(width, height).expect("a wall");
        w.add_body(
            BodyDef::new(shape, 0.0)
                .restitution(WALL_RESTITUTION)
                .at(Vec2::new(x, y), 0.0),
        )
        .expect("a wall");
    }
    w
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Class {
    OverlappingFromStart,
    InOneStep,
    Gradually,
}

pub struct Outcome {
    pub bodies: usize,
    /// Deepest overlap after `JUDGED_FROM`, over the smallest radius, its step, its class
    /// and the two bodies' masses (0 for a wall).
    pub depth: f64,
    pub step: usize,
    pub class: Class,
    pub masses: (f64, f64),
    /// The most the total energy rose above its start at the end of any step, over
    /// Σ m g × the box's height (the property test's measure; `EnergyMeter`).
    pub energy_rise: f64,
}

impl Outcome {
    pub fn sank(&self) -> bool {
        self.depth > BOUND
    }

    pub fn gained_energy(&self) -> bool {
        self.energy_rise > ENERGY_BOUND
    }
}

/// A thrown body after a step, as any engine reports it: its position (its vertex
/// origin, which is its centre: a regular polygon's centroid), angle, velocity and spin.
#[derive(Debug, Clone, Copy)]
pub struct BodyState {
    pub at: Vec2,
    pub angle: f64,
    pub velocity: Vec2,
    pub spin: f64,
}

/// Judges a throw from its bodies' states after each step: every pair's deepest overlap by
/// pe's separating-axis test and clipping (the depth pe's contacts report), and the
/// energy (`EnergyMeter`).
pub struct Judge {
    smallest: f64,
    /// The walls' polygons, then the thrown bodies' at their last poses.
    polygons: Vec<WorldPolygon>,
    /// The thrown bodies' vertices in their own frames, and their masses.
    shapes: Vec<(Vec<Vec2>, f64)>,
    overlapping_at_start: HashSet<(usize, usize)>,
    /// Each overlapping pair's deepest overlap, over the smallest radius, at the step
    /// before, and at this one in the pairs' order (so that ties go the same way each run).
    before: HashMap<(usize, usize), f64>,
    now: Vec<((usize, usize), f64)>,
    energy: EnergyMeter,
    /// This step's states, read twice.
    states: Vec<BodyState>,
    outcome: Outcome,
}

impl Judge {
    pub fn new(throw: &Throw) -> Self {
        let walls = WALLS.iter().map(|&((width, height), (x, y))| {
            let mut polygon = WorldPolygon::default();
            let shape = ConvexPolygon::rectangle(width, height).expect("a wall");
            let centre = Vec2::new(x, y);
            polygon.set_vertices(shape.vertices().iter().map(|v| v + centre));
            polygon
        });
        Self {
            smallest: throw.smallest,
            polygons: walls.collect(),
            shapes: throw
                .bodies
                .iter()
                .map(|b| (b.shape.vertices().to_vec(), b.mass()))
                .collect(),
            overlapping_at_start: HashSet::new(),
            before: HashMap::new(),
            now: Vec::new(),
            energy: EnergyMeter::new(throw),
            states: Vec::new(),
            outcome: Outcome {
                bodies: throw.bodies.len(),
                depth: 0.0,
                step: 0,
                class: Class::Gradually,
                masses: (0.0, 0.0),
                energy_rise: 0.0,
            },
        }
    }

    /// After step `step` (from 0), with each thrown body's state in order.
    pub fn after_step(&mut self, step: usize, states: impl Iterator<Item = BodyState>) {
        self.states.clear();
        self.states.extend(states);
        self.energy.after_step(&self.states);
        self.polygons.truncate(WALLS.len());
        for ((vertices, _), state) in self.shapes.iter().zip(&self.states) {
            // R(θ)·v, the rotation pe places a body's vertices by.
            let (sin, cos) = state.angle.sin_cos();
            let turn = |v: Vec2| Vec2::new(cos * v.x - sin * v.y, sin * v.x + cos * v.y);
            let mut polygon = WorldPolygon::default();
            polygon.set_vertices(vertices.iter().map(|&v| state.at + turn(v)));
            self.polygons.push(polygon);
        }
        self.before.clear();
        self.before.extend(self.now.drain(..));
        let bounds: Vec<_> = self.polygons.iter().map(WorldPolygon::aabb).collect();
        let tie_tolerance = 0.001 * self.smallest;
        for j in WALLS.len()..self.polygons.len() {
            for i in 0..j {
                if !bounds[i].overlaps(&bounds[j]) {
                    continue;
                }
                let manifold = collide_polygons(
                    (BodyHandle(i as u32), &self.polygons[i]),
                    (BodyHandle(j as u32), &self.polygons[j]),
                    0.0,
                    tie_tolerance,
                );
                let deepest = manifold.map_or(0.0, |m| {
                    m.points().iter().map(|p| p.depth).fold(0.0, f64::max)
                });
                if deepest > 0.0 {
                    self.now.push(((i, j), deepest / self.smallest));
                }
            }
        }
        for &(pair, depth) in &self.now {
            if step < 3 && depth > BOUND {
                self.overlapping_at_start.insert(pair);
            }
            if step >= JUDGED_FROM && depth > self.outcome.depth {
                let mass = |k: usize| k.checked_sub(WALLS.len()).map_or(0.0, |k| self.shapes[k].1);
                self.outcome.depth = depth;
                self.outcome.step = step;
                self.outcome.masses = (mass(pair.0), mass(pair.1));
                self.outcome.class = if self.overlapping_at_start.contains(&pair) {
                    Class::OverlappingFromStart
                } else if self.before.get(&pair).is_none_or(|&d| d <= BOUND) {
                    Class::InOneStep
                } else {
                    Class::Gradually
                };
            }
        }
    }

    pub fn outcome(self) -> Outcome {
        Outcome {
            energy_rise: self.energy.rise(),
            ..self.outcome
        }
    }
}

/// The thrown bodies' energy, kinetic and in gravity, from their states after each step,
/// with each body's mass and inertia from its shape (the same for every engine).
struct EnergyMeter {
    /// Each body's mass and inertia.
    bodies: Vec<(f64, f64)>,
    start: f64,
    scale: f64,
    rise: f64,
}

impl EnergyMeter {
    fn new(throw: &Throw) -> Self {
        let bodies: Vec<(f64, f64)> = (throw.bodies.iter())
            .map(|b| (b.mass(), b.inertia()))
            .collect();
        let weight: f64 = bodies.iter().map(|&(m, _)| m * GRAVITY).sum();
        let mut meter = Self {
            bodies,
            start: 0.0,
            scale: weight * BOX_HEIGHT,
            rise: 0.0,
        };
        let starts = throw.bodies.iter().map(|b| (b.at, b.velocity, b.spin));
        meter.start = meter.energy(starts);
        meter
    }

    /// Of bodies at (position, velocity, spin).
    fn energy(&self, motions: impl Iterator<Item = (Vec2, Vec2, f64)>) -> f64 {
        // y points down, along gravity: the potential energy is −m g y.
        let each = self.bodies.iter().zip(motions);
        each.map(|(&(m, i), (at, v, w))| {
            0.5 * (m * v.norm_squared() + i * w * w) - m * GRAVITY * at.y
        })
        .sum()
    }

    fn after_step(&mut self, states: &[BodyState]) {
        let motions = states.iter().map(|s| (s.at, s.velocity, s.spin));
        let rise = (self.energy(motions) - self.start) / self.scale;
        self.rise = self.rise.max(rise);
    }

    fn rise(&self) -> f64 {
        self.rise
    }
}

/// Throws the next random world under pe's `solver` (`run_in_pe`).
pub fn throw(numbers: &mut Numbers, solver: ContactSolver, substeps: Option<usize>) -> Outcome {
    let mut stepping = Duration::ZERO;
    run_in_pe(&Throw::random(numbers), solver, substeps, &mut stepping)
}

/// Steps `throw` in pe `STEPS` times, and judges it and its energy; adds the time spent
/// stepping (not judging) to `stepping`.
pub fn run_in_pe(
    throw: &Throw,
    solver: ContactSolver,
    substeps: Option<usize>,
    stepping: &mut Duration,
) -> Outcome {
    let mut w = throw.pe_world(solver, substeps);
    let mut judge = Judge::new(throw);
    let thrown: Vec<BodyHandle> = (0..throw.bodies.len())
        .map(|k| BodyHandle((WALLS.len() + k) as u32))
        .collect();
    for step in 0..STEPS {
        let started = Instant::now();
        w.step(H);
        *stepping += started.elapsed();
        let state = |&h: &BodyHandle| {
            let b = w.body(h).expect("a thrown body");
            BodyState {
                at: b.origin(),
                angle: b.angle,
                velocity: b.velocity,
                spin: b.angular_velocity,
            }
        };
        judge.after_step(step, thrown.iter().map(state));
    }
    judge.outcome()
}
