//! Hard cases (issue 9): fast small bodies against thin walls, random worlds thrown
//! together, extreme but legal input. Nothing may tunnel, turn NaN or gain energy.

use pe::{BodyDef, ContactSolver, ConvexPolygon, JointDef, Vec2, World};
use proptest::prelude::*;

#[path = "support/found_piles.rs"]
mod found_piles;
#[path = "support/random_throws.rs"]
mod random_throws;

use found_piles::{FOUND_DEEP, FOUND_DEEP_2};

const H: f64 = 1.0 / 60.0;
const SOLVERS: [ContactSolver; 4] = [
    ContactSolver::Auto,
    ContactSolver::Exact,
    ContactSolver::Thesis,
    ContactSolver::Soft,
];

fn finite(world: &World) -> bool {
    world
        .bodies()
        .all(|(_, b)| b.state().iter().all(|v| v.is_finite()))
}

#[test]
fn a_small_fast_body_never_passes_through_a_thin_wall() {
    fast_bodies_against_a_thin_wall(&SOLVERS, true);
}

#[test]
fn without_continuous_collision_the_soft_step_lets_a_spinning_body_through() {
    // The check above is not vacuous: the soft step alone (contacts found once, at the
    // step's start) lets one of these through.
    let through = std::panic::catch_unwind(|| {
        fast_bodies_against_a_thin_wall(&[ContactSolver::Soft], false);
    });
    assert!(
        through.is_err(),
        "expected a tunnelling body without time of impact"
    );
}

/// The step keeps what it made from a body that has not moved (its outline, its bounds,
/// continuous collision's obstacles). A static body moved by hand between steps must be
/// met where it is now: a box resting on a floor that is pulled away falls, and a fast
/// box meets a wall moved into its path after it was first outlined far away.
#[test]
fn a_static_body_moved_by_hand_is_met_where_it_now_is() {
    for solver in SOLVERS {
        let mut w = World::new(Vec2::new(0.0, 10.0));
        w.settings.contact_solver = solver;
        let floor = ConvexPolygon::rectangle(4.0, 1.0).unwrap();
        let floor = w
            .add_body(BodyDef::new(floor, 0.0).at(Vec2::new(0.0, 0.5), 0.0))
            .unwrap();
        let crate_ = ConvexPolygon::rectangle(1.0, 1.0).unwrap();
        let crate_ = w
            .add_body(BodyDef::new(crate_, 1.0).at(Vec2::new(0.0, -0.5), 0.0))
            .unwrap();
        for _ in 0..60 {
            w.step(H);
        }
        let rest = w.body(crate_).unwrap().position.y;
        assert!((rest + 0.5).abs() < 0.01, "{solver:?}: rests at {rest}");
        w.body_mut(floor).unwrap().position.x += 100.0;
        for _ in 0..30 {
            w.step(H);
        }
        // Half a second of free fall from rest: 1.25 m.
        let fallen = w.body(crate_).unwrap().position.y - rest;
        assert!(
            fallen > 1.2,
            "{solver:?}: fell {fallen} m with the floor gone"
        );
    }
    for solver in SOLVERS {
        let mut w = World::new(Vec2::new(0.0, 0.0));
        w.settings.contact_solver = solver;
        w.settings.length_scale = 0.1;
        let wall = ConvexPolygon::rectangle(0.02, 50.0).unwrap();
        let wall = w
            .add_body(BodyDef::new(wall, 0.0).at(Vec2::new(500.0, 0.0), 0.0))
            .unwrap();
        let bullet = ConvexPolygon::rectangle(0.1, 0.1).unwrap();
        let bullet = w
            .add_body(
                BodyDef::new(bullet, 1.0)
                    .at(Vec2::new(-30.0, 0.0), 0.1)
                    .velocity(Vec2::new(1000.0, 0.0), -300.0),
            )
            .unwrap();
        w.step(H);
        let x = w.body(bullet).unwrap().position.x;
        w.body_mut(wall).unwrap().position.x = x + 5.0;
        for step in 0..30 {
            w.step(H);
            let b = w.body(bullet).unwrap();
            assert!(
                b.position.x < x + 5.0,
                "{solver:?}: through the moved wall at step {step} (x = {})",
                b.position.x
            );
        }
    }
}

fn fast_bodies_against_a_thin_wall(solvers: &[ContactSolver], continuous: bool) {
    // A 0.1 box against a wall 0.02 thick, at up to 1000 m/s: 170 of its widths per step.
    // Speculative contacts see the wall as soon as it is within this step's reach. The
    // wall is tall enough that nothing can fly round its end in the 2 s.
    for &solver in solvers {
        for speed in [10.0, 50.0, 200.0, 1000.0] {
            for (angle, spin) in [(0.0, 0.0), (0.3, 0.0), (0.7, 40.0), (0.1, -300.0f64)] {
                for heading in [0.0f64, 0.5, -0.9] {
                    let mut w = World::new(Vec2::new(0.0, 0.0));
                    w.settings.contact_solver = solver;
                    w.settings.length_scale = 0.1;
                    w.settings.continuous = continuous;
                    let wall = ConvexPolygon::rectangle(0.02, 5000.0).unwrap();
                    w.add_body(BodyDef::new(wall, 0.0).at(Vec2::zeros(), 0.0))
                        .unwrap();
                    let bullet = ConvexPolygon::rectangle(0.1, 0.1).unwrap();
                    let v = Vec2::new(heading.cos(), heading.sin()) * speed;
                    let body = w
                        .add_body(
                            BodyDef::new(bullet, 1.0)
                                .restitution(0.5)
                                .at(Vec2::new(-3.0, 0.0), angle)
                                .velocity(v, spin),
                        )
                        .unwrap();
                    for step in 0..120 {
                        w.step(H);
                        let b = w.body(body).unwrap();
                        assert!(
                            b.position.x < 0.0,
                            "{solver:?} {speed} m/s, angle {angle}, spin {spin}, heading \
                             {heading}: through the wall at step {step} (x = {})",
                            b.position.x
                        );
                    }
                    assert!(finite(&w));
                }
            }
        }
    }
}

/// A rod 1 × 0.05 spinning at 10 rad/s about a pin at its end, in no gravity, over a
/// static plate it never collides with (a robot's links pass over its mount). Its tip
/// moves 0.17 per step, far more than half its width, so continuous collision looks at
/// it every step. Returns the rod's angle after each step and the widest gap of the pin.
fn spin_rod(solver: ContactSolver, plate: bool) -> (Vec<f64>, f64) {
    let mut w = World::new(Vec2::zeros());
    w.settings.contact_solver = solver;
    w.settings.length_scale = 0.05;
    let rod = ConvexPolygon::rectangle(1.0, 0.05).unwrap();
    let rod = w
        .add_body(
            BodyDef::new(rod, 1.0)
                .at(Vec2::new(0.5, 0.0), 0.0)
                .velocity(Vec2::new(0.0, 5.0), 10.0),
        )
        .unwrap();
    w.add_joint(JointDef::new(rod, None, Vec2::zeros()))
        .unwrap();
    if plate {
        let square = ConvexPolygon::rectangle(0.3, 0.3).unwrap();
        let plate = w
            .add_body(BodyDef::new(square, 0.0).at(Vec2::new(0.0, -0.6), 0.0))
            .unwrap();
        w.ignore_collisions(rod, plate);
    }
    let mut angles = Vec::new();
    let mut widest: f64 = 0.0;
    for _ in 0..120 {
        w.step(H);
        angles.push(w.body(rod).unwrap().angle);
        widest = widest.max(w.max_joint_gap());
    }
    (angles, widest)
}

#[test]
fn continuous_collision_lets_a_body_pass_over_a_static_body_it_never_collides_with() {
    for solver in SOLVERS {
        let (over_plate, widest) = spin_rod(solver, true);
        let (alone, _) = spin_rod(solver, false);
        // Before the fix, the rod was sent back to its "impact" with the plate once per
        // turn, which opened the pin by a step's motion (0.17).
        assert_eq!(
            over_plate, alone,
            "{solver:?}: the plate changed the motion"
        );
        // Soft pins are springs: the centripetal load (50 m/s² at the centre) stretches
        // them, measured 1.7e-3.
        let tolerance = if solver == ContactSolver::Soft {
            5e-3
        } else {
            1e-6
        };
        assert!(widest < tolerance, "{solver:?}: the pin opened {widest}");
    }
}

/// Two 0.1 boxes pinned together (centres 0.2 apart), thrown at 200 m/s at a wall 0.02
/// thick, 33 lengths of the pair per step, with and without spin.
#[test]
fn a_fast_jointed_body_stopped_at_a_wall_takes_its_mechanism_with_it() {
    for solver in SOLVERS {
        for spin in [0.0, 30.0] {
            let mut w = World::new(Vec2::zeros());
            w.settings.contact_solver = solver;
            w.settings.length_scale = 0.1;
            let wall = ConvexPolygon::rectangle(0.02, 5000.0).unwrap();
            w.add_body(BodyDef::new(wall, 0.0).at(Vec2::zeros(), 0.0))
                .unwrap();
            let square = ConvexPolygon::rectangle(0.1, 0.1).unwrap();
            let pair_centre = Vec2::new(-3.0, 0.0);
            let boxes = [-0.1, 0.1].map(|dx| {
                let at = pair_centre + Vec2::new(dx, 0.0);
                let v = Vec2::new(200.0, spin * dx);
                let def = BodyDef::new(square.clone(), 1.0).at(at, 0.0);
                w.add_body(def.velocity(v, spin)).unwrap()
            });
            w.add_joint(JointDef::new(boxes[0], Some(boxes[1]), pair_centre))
                .unwrap();
            let mut widest: f64 = 0.0;
            for step in 0..60 {
                w.step(H);
                for b in boxes {
                    let x = w.body(b).unwrap().position.x;
                    // Under `thesis` the joint pass after the contacts dragged the stopped
                    // box on through the wall until continuous collision caught a body
                    // that starts in contact and ends deep.
                    assert!(x < 0.0, "{solver:?} spin {spin}: through at step {step}");
                }
                widest = widest.max(w.max_joint_gap());
            }
            // Under `exact` the pins stay shut to second order in the pair's turn within
            // the step (it spins at 470 rad/s after the impact): measured 8.7e-4, and
            // 1.2e-2 when the stopped box went back alone. Soft and thesis pins yield to
            // the impact itself (up to 0.27), and close again; the soft pin of the pair
            // still spinning at 28 rad/s stays stretched by the centripetal load
            // (78 m/s²; measured 4.0e-3, like the rod above).
            if solver == ContactSolver::Exact {
                assert!(widest < 2e-3, "spin {spin}: the pin opened {widest}");
            }
            let end = w.max_joint_gap();
            let tolerance = if solver == ContactSolver::Soft {
                1e-2
            } else {
                1e-6
            };
            assert!(
                end < tolerance,
                "{solver:?} spin {spin}: the pin ends {end} open"
            );
        }
    }
}

#[test]
fn extreme_but_legal_input_simulates_sanely() {
    extreme_input(&[ContactSolver::Exact, ContactSolver::Thesis]);
}

#[test]
fn the_soft_step_handles_extreme_but_legal_input() {
    // The 1e6:1 pair crushed the light box by a third of its size under soft contacts,
    // until islands of very different masses were solved as one LCP per pass.
    extreme_input(&[ContactSolver::Soft]);
}

fn extreme_input(solvers: &[ContactSolver]) {
    // Far from the origin, tiny and huge bodies, a density ratio of 1e6, steps from
    // 1e-4 to 0.1 s: a box dropped on a floor comes to rest on it, without NaN.
    let cases: [(&str, Vec2, f64, f64, f64); 5] = [
        ("at 1e6", Vec2::new(1e6, -1e6), 1.0, 1.0, H),
        ("size 1e-3", Vec2::zeros(), 1e-3, 1.0, H),
        ("size 1e4", Vec2::zeros(), 1e4, 1.0, H),
        ("density 1e6 on 1", Vec2::zeros(), 1.0, 1e6, H),
        ("h = 1e-4", Vec2::zeros(), 1.0, 1.0, 1e-4),
    ];
    for (name, origin, size, density, dt) in cases {
        for &solver in solvers {
            // Gravity scales with the size, so that every case settles on the same clock.
            let mut w = World::new(Vec2::new(0.0, 10.0 * size));
            w.settings.contact_solver = solver;
            w.settings.length_scale = size;
            w.friction = 0.5;
            let floor = ConvexPolygon::rectangle(20.0 * size, size).unwrap();
            w.add_body(BodyDef::new(floor, 0.0).at(origin + Vec2::new(0.0, 0.5 * size), 0.0))
                .unwrap();
            // A light box under the heavy one, so the ratio meets in a contact.
            let shape = ConvexPolygon::rectangle(size, size).unwrap();
            let light = w
                .add_body(
                    BodyDef::new(shape.clone(), 1.0).at(origin + Vec2::new(0.0, -0.6 * size), 0.0),
                )
                .unwrap();
            let heavy = w
                .add_body(
                    BodyDef::new(shape, density).at(origin + Vec2::new(0.0, -1.8 * size), 0.0),
                )
                .unwrap();
            let seconds = if dt < 1e-3 { 0.5 } else { 3.0 };
            for _ in 0..(seconds / dt) as usize {
                w.step(dt);
            }
            assert!(finite(&w), "{name} {solver:?}: not finite");
            for (which, h, rest_y) in [("light", light, -0.5), ("heavy", heavy, -1.5)] {
                let b = w.body(h).unwrap();
                let expected = origin + Vec2::new(0.0, rest_y * size);
                let off = (b.position - expected).norm() / size;
                assert!(
                    off < 0.05,
                    "{name} {solver:?}: the {which} box is {off} sizes from rest"
                );
            }
        }
    }
}

#[test]
fn a_huge_torque_spins_a_body_without_breaking_the_world() {
    // A body motor at 1e12 on a small box beside others, at nearly the fastest speed a
    // motor may ask (3 rad a step): it spins absurdly fast, but every state stays finite
    // and its neighbours do not explode.
    for solver in SOLVERS {
        let mut w = World::new(Vec2::new(0.0, 10.0));
        w.settings.contact_solver = solver;
        let floor = ConvexPolygon::rectangle(20.0, 1.0).unwrap();
        w.add_body(BodyDef::new(floor, 0.0).at(Vec2::new(0.0, 0.5), 0.0))
            .unwrap();
        let square = ConvexPolygon::rectangle(1.0, 1.0).unwrap();
        let spinner = w
            .add_body(BodyDef::new(square.clone(), 1.0).at(Vec2::new(0.0, -0.5), 0.0))
            .unwrap();
        for x in [-3.0, 3.0] {
            w.add_body(BodyDef::new(square.clone(), 1.0).at(Vec2::new(x, -0.5), 0.0))
                .unwrap();
        }
        w.add_body_motor(spinner, pe::BodyMotor::new(0, 600, 3.0, 1e12, 1e12, 0.0))
            .unwrap();
        for _ in 0..600 {
            w.step(H);
        }
        assert!(finite(&w), "{solver:?}: not finite");
    }
}

/// A random convex body: a regular polygon of 3–8 sides, radius 0.2–1.5, anywhere in a
/// 16 × 10 box above the floor, with a random velocity and spin.
fn random_body() -> impl Strategy<Value = RandomBody> {
    (
        3usize..=8,
        0.2..1.5f64,
        -8.0..8.0f64,
        -12.0..-1.0f64,
        0.0..6.3f64,
        -5.0..5.0f64,
        -5.0..5.0f64,
        -3.0..3.0f64,
        prop_oneof![Just(0.0), Just(0.3), Just(0.8)],
    )
}

type RandomBody = (usize, f64, f64, f64, f64, f64, f64, f64, f64);

/// What a random world did in 1,000 steps.
struct Thrown {
    /// The first step with a non-finite state, if any.
    non_finite_at: Option<usize>,
    /// The largest rise of total energy above its start, over Σ m g × box height.
    energy_rise: f64,
    /// The deepest penetration after the first 2 s, over the smallest body's radius.
    depth: f64,
}

/// Random convex bodies thrown together in a walled 20 × 20 box for 1,000 steps.
fn throw_together(bodies: &[RandomBody], solver: ContactSolver) -> Thrown {
    let g = 10.0;
    let mut w = random_throws::walled_box(solver);
    let mut smallest = f64::INFINITY;
    let mut weight = 0.0;
    for (i, &(sides, radius, x, y, angle, vx, vy, spin, e)) in bodies.iter().enumerate() {
        let shape = ConvexPolygon::regular(sides, radius).unwrap();
        let def = BodyDef::new(shape, 1.0)
            .restitution(e)
            .at(Vec2::new(x, y - 0.01 * i as f64), angle)
            .velocity(Vec2::new(vx, vy), spin);
        let handle = w.add_body(def).unwrap();
        weight += w.body(handle).unwrap().mass() * g;
        smallest = smallest.min(radius);
    }
    w.settings.length_scale = smallest;
    let energy = |w: &World| w.kinetic_energy() + w.potential_energy();
    let e0 = energy(&w);
    let mut thrown = Thrown {
        non_finite_at: None,
        energy_rise: 0.0,
        depth: 0.0,
    };
    for step in 0..1000 {
        w.step(H);
        if !finite(&w) {
            thrown.non_finite_at = Some(step);
            break;
        }
        thrown.energy_rise = thrown.energy_rise.max((energy(&w) - e0) / (weight * 20.0));
        // Random starts may overlap; judge depth once the world had time to separate.
        if step >= 120 {
            let deepest = w.contacts().iter().map(|c| c.depth).fold(0.0, f64::max);
            thrown.depth = thrown.depth.max(deepest / smallest);
        }
    }
    thrown
}

#[test]
fn a_pile_found_by_the_property_test_stays_shallow() {
    // An impact from a neighbour sent a pentagon resting on the floor down at 4 m/s in a
    // step whose contacts were found while it rose: the floor was not among them, and it
    // sank 0.27 of a radius in. Continuous collision now stops it at the floor.
    let thrown = throw_together(&FOUND_DEEP, ContactSolver::Exact);
    assert_eq!(thrown.non_finite_at, None);
    assert!(
        thrown.depth < 0.2,
        "penetration {} of the smallest radius",
        thrown.depth
    );
}

#[test]
fn a_second_pile_found_by_the_property_test_stays_shallow() {
    let thrown = throw_together(&FOUND_DEEP_2, ContactSolver::Exact);
    assert_eq!(thrown.non_finite_at, None);
    assert!(
        thrown.depth < 0.2,
        "penetration {} of the smallest radius",
        thrown.depth
    );
}

proptest! {
    // A fixed seed: the same twelve worlds on every run, so that CI is deterministic;
    // shrinking is capped because each case steps a world 1,000 times.
    #![proptest_config(ProptestConfig {
        cases: 12,
        rng_seed: proptest::test_runner::RngSeed::Fixed(2026),
        max_shrink_iters: 16,
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    /// No NaN; the total energy never rises above its start by 1% of Σ m g × box height
    /// (no motors); under `exact`, no contact deeper than a fifth of the smallest body.
    /// At this test's length scale, the smallest radius, `thesis` and `soft` let about one
    /// throw in ten sink past that; at the median radius (the app's) one in fifty or
    /// sixty (the next test).
    #[test]
    fn random_worlds_stay_finite_bounded_and_shallow(
        bodies in prop::collection::vec(random_body(), 2..24),
        solver in prop_oneof![Just(ContactSolver::Exact), Just(ContactSolver::Thesis), Just(ContactSolver::Soft)],
    ) {
        let thrown = throw_together(&bodies, solver);
        prop_assert_eq!(thrown.non_finite_at, None);
        prop_assert!(thrown.energy_rise < 0.01, "{:?}: energy rose by {}", solver, thrown.energy_rise);
        if solver == ContactSolver::Exact {
            prop_assert!(thrown.depth < 0.2, "{:?}: penetration {} of the smallest radius", solver, thrown.depth);
        }
    }
}

/// How often `soft` and `thesis` let a random throw sink past a fifth of the smallest
/// radius (`support/random_throws.rs`; `exact` never did in 100 throws, nor in the
/// property above), and that no throw gains energy. Measured with `throw_survey` over
/// 2,000 throws (seeds 1–5): `soft` 1.6%; over 400 (seed 2) `thesis` 2.0%. Here seed 1:
/// 400 throws under `soft` (5 sink) and 100 under `thesis` (none), allowed 14 and 7:
/// three binomial deviations above their long-run rates, so that what fails is a solver
/// that sinks more often, not the draw. Energy: at most 1% of Σ m g × the box's height
/// above its start, as in the property above; 9 of these 400 `soft` throws rose by 6–125%
/// when a bounce could return speed that other contacts gave in the same step (a small
/// body wedged between a wall and a heavy one), and with it 13 sank. (With the length
/// scale at the smallest radius instead of the median, both solvers sank one throw in
/// ten, `soft` mostly from its push speed, 3 length scales a second; the peers,
/// rapier2d and Box2D v3, sink about half of these throws, mostly on impact:
/// `bench/src/throws.rs`.)
#[test]
fn random_throws_rarely_sink_and_never_gain_energy_under_soft_and_thesis() {
    for (solver, throws, allowed) in [
        (ContactSolver::Soft, 400, 14),
        (ContactSolver::Thesis, 100, 7),
    ] {
        let mut numbers = random_throws::Numbers(1);
        let outcomes: Vec<_> = (0..throws)
            .map(|_| random_throws::throw(&mut numbers, solver, None))
            .collect();
        let sunk: Vec<_> = outcomes
            .iter()
            .filter(|t| t.sank())
            .map(|t| (t.bodies, t.depth, t.class))
            .collect();
        assert!(
            sunk.len() <= allowed,
            "{solver:?}: {} of {throws} throws sank past the bound (bodies, depth, class): {sunk:?}",
            sunk.len()
        );
        let gained: Vec<_> = (outcomes.iter().enumerate())
            .filter(|(_, t)| t.gained_energy())
            .map(|(k, t)| (k, t.energy_rise))
            .collect();
        assert!(
            gained.is_empty(),
            "{solver:?}: throws that gained energy (throw, rise): {gained:?}"
        );
    }
}

#[test]
fn numbers_that_would_poison_the_state_are_refused() {
    use pe::{BodyMotor, JointDef, JointError, JointMotor, MotorError, StepError};
    let mut w = World::new(Vec2::new(0.0, 10.0));
    let square = ConvexPolygon::rectangle(1.0, 1.0).unwrap();
    let a = w.add_body(BodyDef::new(square.clone(), 1.0)).unwrap();
    let b = w
        .add_body(BodyDef::new(square, 1.0).at(Vec2::new(1.0, 0.0), 0.0))
        .unwrap();
    // Bodies: non-finite placement, bad material (checked when added).
    let bad = BodyDef::new(ConvexPolygon::rectangle(1.0, 1.0).unwrap(), 1.0)
        .at(Vec2::new(f64::NAN, 0.0), 0.0);
    assert!(w.add_body(bad).is_err());
    // Motors.
    let motor = |angular, max| BodyMotor::new(0, 10, angular, 1.0, max, 0.0);
    assert!(matches!(
        w.add_body_motor(a, motor(f64::NAN, 1.0)),
        Err(MotorError::NonFinite("angular", _))
    ));
    assert!(matches!(
        w.add_body_motor(a, motor(0.1, f64::INFINITY)),
        Err(MotorError::NonFinite("max torque", _))
    ));
    assert!(matches!(
        w.add_body_motor(a, motor(0.1, -1.0)),
        Err(MotorError::Negative("max torque", _))
    ));
    let mut pin = JointDef::new(a, Some(b), Vec2::new(0.5, 0.0));
    pin.motor = Some(JointMotor::new(f64::NAN, 1.0));
    assert!(matches!(w.add_joint(pin), Err(JointError::BadMotor(_))));
    // Finite but absurd magnitudes (`pe::limits`): the fuzzer found that a gravity of
    // 1e308 or a motor torque of 1e300 overflowed the first step.
    let unit = || ConvexPolygon::rectangle(1.0, 1.0).unwrap();
    let beyond = |def: BodyDef| match World::new(Vec2::zeros()).add_body(def) {
        Err(pe::BodyError::Beyond(what, ..)) => what,
        other => panic!("accepted or refused for another reason: {other:?}"),
    };
    assert_eq!(beyond(BodyDef::new(unit(), 1e200)), "density");
    assert_eq!(
        beyond(BodyDef::new(unit(), 1.0).at(Vec2::new(1e300, 0.0), 0.0)),
        "x"
    );
    assert_eq!(
        beyond(BodyDef::new(unit(), 1.0).at(Vec2::zeros(), 1e300)),
        "angle"
    );
    let fast = BodyDef::new(unit(), 1.0).velocity(Vec2::new(0.0, 1e300), 0.0);
    assert_eq!(beyond(fast), "speed");
    let huge = ConvexPolygon::rectangle(4e9, 4e9).unwrap();
    assert_eq!(beyond(BodyDef::new(huge, 1.0)), "vertex coordinate");
    let strong = BodyMotor::new(0, 10, 0.1, 1e300, 1e300, 0.0);
    assert!(matches!(
        w.add_body_motor(a, strong),
        Err(MotorError::Beyond("start torque", ..))
    ));
    let mut pin = JointDef::new(a, Some(b), Vec2::new(0.5, 0.0));
    pin.motor = Some(JointMotor::new(1.0, 1e300));
    assert!(matches!(
        w.add_joint(pin),
        Err(JointError::BadMotor(MotorError::Beyond("max torque", ..)))
    ));
    let far = JointDef::new(a, Some(b), Vec2::new(0.5, 1e300));
    assert!(matches!(
        w.add_joint(far),
        Err(JointError::AnchorBeyond(..))
    ));
    assert!(w.body_motors().is_empty() && w.joints().next().is_none());
    // Steps: the reason is given and nothing moves.
    let before: Vec<_> = w.bodies().map(|(_, b)| (b.position, b.velocity)).collect();
    for dt in [0.0, -0.01, f64::NAN, f64::INFINITY] {
        assert!(matches!(w.try_step(dt), Err(StepError::BadTimeStep(_))));
        w.step(dt);
    }
    for g in [f64::NAN, 1e308] {
        w.gravity = Vec2::new(0.0, g);
        assert!(matches!(w.try_step(H), Err(StepError::BadGravity(..))));
    }
    w.gravity = Vec2::new(0.0, 10.0);
    for mu in [-1.0, 1e300, f64::NAN] {
        w.friction = mu;
        assert!(matches!(w.try_step(H), Err(StepError::BadFriction(_))));
        let def = BodyDef::new(ConvexPolygon::rectangle(1.0, 1.0).unwrap(), 1.0).friction(mu);
        assert!(w.add_body(def).is_err(), "a body with friction {mu}");
    }
    let after: Vec<_> = w.bodies().map(|(_, b)| (b.position, b.velocity)).collect();
    assert_eq!(before, after);
    assert_eq!(w.step_count(), 0);
}

/// Bodies dropped onto one spot: 600 unit boxes placed at one point overlap every other,
/// 180,000 pairs. Each collides with at most 32 moving bodies at a time (the rest pass
/// through it until they part), so contacts grow with the bodies, not their pairs: at
/// most 32 × 600 / 2 moving pairs and the 600 on the floor. The pile spreads out without
/// a non-finite number, under every solver.
#[test]
fn a_pile_up_at_one_point_keeps_a_bounded_number_of_pairs() {
    for solver in SOLVERS {
        let mut w = World::new(Vec2::new(0.0, 10.0));
        w.settings.contact_solver = solver;
        let floor = ConvexPolygon::rectangle(200.0, 1.0).unwrap();
        w.add_body(BodyDef::new(floor, 0.0).at(Vec2::new(0.0, 0.5), 0.0))
            .unwrap();
        let unit = ConvexPolygon::rectangle(1.0, 1.0).unwrap();
        for _ in 0..600 {
            w.add_body(BodyDef::new(unit.clone(), 1.0).at(Vec2::new(0.0, -0.5), 0.0))
                .unwrap();
        }
        for step in 0..3 {
            w.step(H);
            let pairs = w.manifolds().len();
            assert!(
                pairs <= 32 * 600 / 2 + 600,
                "{solver:?}, step {step}: {pairs} pairs"
            );
            assert!(pairs > 600, "{solver:?}, step {step}: only {pairs} pairs");
        }
        assert!(finite(&w), "{solver:?}");
    }
}

/// A 20 × 20 box on a floor twice as thick, under gravity up to `limits::GRAVITY` and at
/// the largest step the fall limit allows for it (`FALL_PER_STEP` length scales a step,
/// the box's bounding radius the length scale): no solver lets it through the floor. (The
/// soft step's springs let a box through at g = 1e5 and h = 1 until a touching point was
/// held at a tenth of a length scale deep a substep; the sequential solver, from 37 length
/// scales a step.)
#[test]
fn every_solver_holds_a_box_on_the_floor_at_the_limits() {
    for solver in ContactSolver::ALL {
        for g in [1e3, 1e5, 1e7, pe::limits::GRAVITY] {
            let length_scale = 200f64.sqrt();
            let h = (pe::FALL_PER_STEP * length_scale / g).sqrt();
            let mut w = World::new(Vec2::new(0.0, g));
            w.settings.contact_solver = solver;
            w.settings.length_scale = length_scale;
            let floor = ConvexPolygon::rectangle(400.0, 40.0).unwrap();
            w.add_body(BodyDef::new(floor, 0.0).at(Vec2::new(0.0, 20.0), 0.0))
                .unwrap();
            let square = ConvexPolygon::rectangle(20.0, 20.0).unwrap();
            let b = w
                .add_body(BodyDef::new(square, 1.0).at(Vec2::new(0.0, -10.0), 0.0))
                .unwrap();
            for step in 0..100 {
                w.try_step(h).unwrap();
                let y = w.body(b).unwrap().position.y;
                // Resting on the floor's top at y = 0, within a tenth of its size.
                assert!(
                    (-12.0..=-8.0).contains(&y),
                    "{solver:?} g {g:e} h {h:e}: y {y} at step {step}"
                );
            }
        }
        // One step more than the limit is refused, before anything moves.
        let mut w = World::new(Vec2::new(0.0, 1e7));
        w.settings.contact_solver = solver;
        assert!(matches!(
            w.try_step(1.0),
            Err(pe::StepError::FallsTooFar { .. })
        ));
    }
}

/// A box of density 1e-30 (a feather in any units) resting on the floor moves exactly as
/// one of density 1 does: nothing in a solve depends on the scale of the masses (the exact
/// solver's checks once had absolute tolerances, and at 1e-20 the box slid at 0.6 px/s,
/// at 1e-30 it fell through the floor). Under every solver but the naive sequential one
/// (which rocks a box on its corners, thesis §2.4.5) it lies still. A density whose mass
/// underflows is refused.
#[test]
fn a_very_light_body_moves_as_a_heavy_one() {
    let rest = |solver: ContactSolver, density: f64| {
        let mut w = World::new(Vec2::new(0.0, 9.1));
        w.settings.contact_solver = solver;
        w.settings.length_scale = 14.0;
        w.friction = 0.7;
        let floor = ConvexPolygon::rectangle(400.0, 40.0).unwrap();
        w.add_body(BodyDef::new(floor, 0.0).at(Vec2::new(0.0, 20.0), 0.0))
            .unwrap();
        let square = ConvexPolygon::rectangle(20.0, 20.0).unwrap();
        let b = w
            .add_body(BodyDef::new(square, density).at(Vec2::new(0.0, -10.0), 0.0))
            .unwrap();
        for _ in 0..200 {
            w.try_step(0.05).unwrap();
        }
        let body = w.body(b).unwrap();
        (body.position, body.velocity)
    };
    for solver in ContactSolver::ALL {
        let (p1, v1) = rest(solver, 1.0);
        for density in [1e-30, 1e-100, 1e-300] {
            let (p, v) = rest(solver, density);
            // The same solve in other units: equal but for rounding, which 200 steps carry
            // to a few billionths of a pixel (a millionth bounds it).
            assert!(
                (p - p1).norm() < 1e-6 && (v - v1).norm() < 1e-6,
                "{solver:?} {density:e}: at {p:?} moving {v:?}, against {p1:?} {v1:?}"
            );
        }
        if solver != ContactSolver::Sequential {
            // The soft step rests 0.001 px deep in the floor (its springs), the others on it.
            let moved = (p1 - Vec2::new(0.0, -10.0)).norm();
            assert!(
                moved < 0.01 && v1.norm() < 1e-6,
                "{solver:?}: {p1:?} {v1:?}"
            );
        }
    }
    let square = ConvexPolygon::rectangle(20.0, 20.0).unwrap();
    assert!(matches!(
        pe::Body::new(BodyDef::new(square, 1e-320)),
        Err(pe::BodyError::TooLight(..))
    ));
}

/// A large body among many small ones keeps every pair it needs: an 8 m box at 40 m/s into
/// a block of 0.5 m boxes (the benchmark's smash, smaller) meets far more than 32 moving
/// bodies at once, and must plough through them, not pass over them. The deepest any small
/// box gets inside it stays under a quarter of a small box (the soft step's contacts
/// yield 0.108 m at this 40 m/s impact, the exact solver's 0.004 m; a dropped pair lets
/// a box in by 0.6 m).
#[test]
fn a_large_body_collides_with_every_small_one_it_meets() {
    const SMALL: f64 = 0.5;
    const HEAVY: f64 = 8.0;
    for solver in [
        ContactSolver::Auto,
        ContactSolver::Soft,
        ContactSolver::Exact,
    ] {
        let mut w = World::new(Vec2::zeros());
        w.settings.contact_solver = solver;
        let small = ConvexPolygon::rectangle(SMALL, SMALL).unwrap();
        let mut boxes = vec![];
        for row in 0..16 {
            for column in 0..24 {
                let centre = Vec2::new(column as f64 + 0.5, row as f64 + 0.5) * SMALL;
                boxes.push(
                    w.add_body(BodyDef::new(small.clone(), 1.0).at(centre, 0.0))
                        .unwrap(),
                );
            }
        }
        let heavy = ConvexPolygon::rectangle(HEAVY, HEAVY).unwrap();
        let heavy = w
            .add_body(
                BodyDef::new(heavy, 10.0)
                    .at(Vec2::new(-1.0 - 0.5 * HEAVY, 4.0), 0.0)
                    .velocity(Vec2::new(40.0, 0.0), 0.0),
            )
            .unwrap();
        let mut deepest: f64 = 0.0;
        for _ in 0..30 {
            w.step(H);
            let heavy = w.body(heavy).unwrap();
            for &b in &boxes {
                let local = heavy.to_local(w.body(b).unwrap().centroid());
                let inside = 0.5 * HEAVY - local.x.abs().max(local.y.abs());
                deepest = deepest.max(0.5 * SMALL + inside);
            }
        }
        assert!(finite(&w), "{solver:?}");
        assert!(deepest < 0.25 * SMALL, "{solver:?}: {deepest:.3} m deep");
    }
}
