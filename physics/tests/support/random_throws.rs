//! Random throws: convex bodies thrown together in a walled box (the worlds of the
//! hard-case property test), each stepped 1,000 times, and the deepest contact after the
//! first 2 s over the smallest body's radius. A throw sinks past `BOUND` (the property
//! test's bound), and is put in one of three classes by its deepest contact:
//!
//! - *overlapping from the start*: the pair already overlapped by more than the bound in
//!   the first steps (random starts may overlap; some solvers take longer to part them);
//! - *in one step*: the pair was within the bound (or apart) one step before: an impact;
//! - *gradually*: the pair sank past the bound over several steps.
//!
//! Shared by `physics/examples/throw_survey.rs` (the survey) and
//! `physics/tests/hard_cases.rs` (its test).

use pe::{BodyDef, BodyHandle, ContactSolver, ConvexPolygon, Vec2, World};
use std::collections::{HashMap, HashSet};

const H: f64 = 1.0 / 60.0;
const STEPS: usize = 1000;
/// Deepest contacts are judged from this step on (2 s), as in the property test.
const JUDGED_FROM: usize = 120;
pub const BOUND: f64 = 0.2;

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

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Class {
    OverlappingFromStart,
    InOneStep,
    Gradually,
}

pub struct Outcome {
    pub bodies: usize,
    /// Deepest contact after `JUDGED_FROM`, over the smallest radius, its step, its class
    /// and the two bodies' masses.
    pub depth: f64,
    pub step: usize,
    pub class: Class,
    pub masses: (f64, f64),
}

/// The walled 20 × 20 box the throws land in: floor and walls 1 thick around
/// [-10, 10] × [-20, 0], restitution 1; friction 0.5, g = 10.
pub fn walled_box(solver: ContactSolver) -> World {
    let mut w = World::new(Vec2::new(0.0, 10.0));
    w.settings.contact_solver = solver;
    w.friction = 0.5;
    for (size, at) in [
        (Vec2::new(22.0, 1.0), Vec2::new(0.0, 0.5)),
        (Vec2::new(1.0, 22.0), Vec2::new(-10.5, -10.0)),
        (Vec2::new(1.0, 22.0), Vec2::new(10.5, -10.0)),
    ] {
        let shape = ConvexPolygon::rectangle(size.x, size.y).expect("a wall");
        w.add_body(BodyDef::new(shape, 0.0).restitution(1.0).at(at, 0.0))
            .expect("a wall");
    }
    w
}

/// Random convex bodies in the walled box: 2–23 regular polygons of 3–8 sides, radius
/// 0.2–1.5, random poses, velocities, spins, and restitution 0, 0.3 or 0.8. The world,
/// the smallest radius and the number of bodies.
fn random_world(
    numbers: &mut Numbers,
    solver: ContactSolver,
    substeps: Option<usize>,
) -> (World, f64, usize) {
    let mut w = walled_box(solver);
    if let Some(substeps) = substeps {
        w.settings.soft_substeps = substeps;
    }
    let count = 2 + numbers.below(22) as usize;
    let mut smallest = f64::INFINITY;
    for i in 0..count {
        let sides = 3 + numbers.below(6) as usize;
        let radius = numbers.uniform(0.2, 1.5);
        let at = Vec2::new(
            numbers.uniform(-8.0, 8.0),
            numbers.uniform(-12.0, -1.0) - 0.01 * i as f64,
        );
        let angle = numbers.uniform(0.0, 6.3);
        let velocity = Vec2::new(numbers.uniform(-5.0, 5.0), numbers.uniform(-5.0, 5.0));
        let spin = numbers.uniform(-3.0, 3.0);
        let restitution = [0.0, 0.3, 0.8][numbers.below(3) as usize];
        let shape = ConvexPolygon::regular(sides, radius).expect("a regular polygon");
        let def = BodyDef::new(shape, 1.0)
            .restitution(restitution)
            .at(at, angle)
            .velocity(velocity, spin);
        w.add_body(def).expect("a random body");
        smallest = smallest.min(radius);
    }
    w.settings.length_scale = smallest;
    (w, smallest, count)
}

/// Throws the next random world (`random_world`), steps it `STEPS` times, and judges its
/// deepest contact.
pub fn throw(numbers: &mut Numbers, solver: ContactSolver, substeps: Option<usize>) -> Outcome {
    let (mut w, smallest, bodies) = random_world(numbers, solver, substeps);
    let mut overlapping_at_start = HashSet::new();
    let mut outcome = Outcome {
        bodies,
        depth: 0.0,
        step: 0,
        class: Class::Gradually,
        masses: (0.0, 0.0),
    };
    // Each pair's deepest contact at the step before, over the smallest radius.
    let (mut before, mut now) = (HashMap::new(), HashMap::new());
    for step in 0..STEPS {
        w.step(H);
        std::mem::swap(&mut before, &mut now);
        now.clear();
        for c in w.contacts() {
            let deepest = now.entry((c.body_a, c.body_b)).or_insert(f64::NEG_INFINITY);
            *deepest = f64::max(*deepest, c.depth / smallest);
        }
        for c in w.contacts() {
            let depth = c.depth / smallest;
            if step < 3 && depth > BOUND {
                overlapping_at_start.insert((c.body_a, c.body_b));
            }
            if step >= JUDGED_FROM && depth > outcome.depth {
                let mass = |i: u32| w.body(BodyHandle(i)).map_or(0.0, |b| b.mass());
                outcome.depth = depth;
                outcome.step = step;
                outcome.masses = (mass(c.body_a), mass(c.body_b));
                outcome.class = if overlapping_at_start.contains(&(c.body_a, c.body_b)) {
                    Class::OverlappingFromStart
                } else if before
                    .get(&(c.body_a, c.body_b))
                    .is_none_or(|&d| d <= BOUND)
                {
                    Class::InOneStep
                } else {
                    Class::Gradually
                };
            }
        }
    }
    outcome
}
