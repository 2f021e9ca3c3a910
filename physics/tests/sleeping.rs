//! Sleeping (issue 9): islands at rest sleep and cost nothing; contact, motors and
//! `wake_body` wake them.

use pe::{BodyDef, BodyHandle, BodyMotor, ContactSolver, ConvexPolygon, Vec2, World};

const H: f64 = 1.0 / 60.0;

/// Three columns of four unit boxes on a floor, sleeping enabled.
fn piles(solver: ContactSolver) -> (World, Vec<BodyHandle>) {
    let mut w = World::new(Vec2::new(0.0, 10.0));
    w.settings.contact_solver = solver;
    w.settings.sleeping = true;
    w.friction = 0.6;
    let floor = ConvexPolygon::rectangle(40.0, 1.0).unwrap();
    w.add_body(BodyDef::new(floor, 0.0).at(Vec2::new(0.0, 0.5), 0.0))
        .unwrap();
    let unit = ConvexPolygon::rectangle(1.0, 1.0).unwrap();
    let mut boxes = Vec::new();
    for column in [-5.0, 0.0, 5.0] {
        for i in 0..4 {
            let at = Vec2::new(column, -0.5 - i as f64);
            boxes.push(
                w.add_body(BodyDef::new(unit.clone(), 1.0).at(at, 0.0))
                    .unwrap(),
            );
        }
    }
    (w, boxes)
}

fn poses(w: &World, bodies: &[BodyHandle]) -> Vec<u64> {
    bodies
        .iter()
        .flat_map(|&b| {
            let b = w.body(b).unwrap();
            [b.position.x, b.position.y, b.angle]
        })
        .map(f64::to_bits)
        .collect()
}

#[test]
fn a_pile_at_rest_falls_asleep_and_then_costs_nothing() {
    for solver in [
        ContactSolver::Exact,
        ContactSolver::Thesis,
        ContactSolver::Soft,
    ] {
        let (mut w, boxes) = piles(solver);
        let mut asleep_at = None;
        for step in 0..300 {
            w.step(H);
            if boxes.iter().all(|&b| w.body(b).unwrap().is_asleep()) {
                asleep_at = Some(step);
                break;
            }
        }
        // Settling takes a few steps, then 0.5 s of stillness (30 steps).
        let asleep_at = asleep_at.unwrap_or_else(|| panic!("{solver:?}: never slept"));
        assert!(
            asleep_at < 120,
            "{solver:?}: asleep only at step {asleep_at}"
        );
        let before = poses(&w, &boxes);
        for _ in 0..60 {
            w.step(H);
        }
        assert_eq!(
            poses(&w, &boxes),
            before,
            "{solver:?}: a sleeping pile moved"
        );
        // No pair of sleeping or static bodies is even tested.
        assert!(
            w.contacts().is_empty(),
            "{solver:?}: {} contacts",
            w.contacts().len()
        );
        for &b in &boxes {
            let b = w.body(b).unwrap();
            assert_eq!((b.velocity, b.angular_velocity), (Vec2::zeros(), 0.0));
            assert!(!b.is_static(), "asleep is not static");
        }
    }
}

#[test]
fn a_body_dropped_on_a_sleeping_pile_wakes_only_that_pile() {
    let (mut w, boxes) = piles(ContactSolver::Exact);
    while !boxes.iter().all(|&b| w.body(b).unwrap().is_asleep()) {
        w.step(H);
    }
    let unit = ConvexPolygon::rectangle(1.0, 1.0).unwrap();
    let dropped = w
        .add_body(BodyDef::new(unit, 1.0).at(Vec2::new(5.0, -8.0), 0.0))
        .unwrap();
    let mut woke = false;
    for _ in 0..60 {
        w.step(H);
        woke |= !w.body(boxes[8]).unwrap().is_asleep();
        // The two other piles are out of reach and sleep on.
        assert!(boxes[..8].iter().all(|&b| w.body(b).unwrap().is_asleep()));
    }
    assert!(woke, "the pile under the dropped box woke");
    // It lands on top of the third pile, which carries it and then sleeps again with it.
    for _ in 0..240 {
        w.step(H);
    }
    let top = w.body(dropped).unwrap();
    assert!(
        (top.position - Vec2::new(5.0, -4.5)).norm() < 0.05,
        "{:?}",
        top.position
    );
    assert!(top.is_asleep() && w.body(boxes[11]).unwrap().is_asleep());
}

#[test]
fn motors_and_wake_body_wake_a_sleeping_island() {
    let (mut w, boxes) = piles(ContactSolver::Exact);
    let spinner = boxes[3]; // the top of the left pile
    // A motor that switches on at step 200, long after the pile has gone to sleep.
    w.add_body_motor(spinner, BodyMotor::new(200, 400, 0.01, 50.0, 50.0, 0.0))
        .unwrap();
    for _ in 0..200 {
        w.step(H);
    }
    assert!(w.body(spinner).unwrap().is_asleep());
    let angle = w.body(spinner).unwrap().angle;
    w.step(H); // step 200: the motor's first
    let b = w.body(spinner).unwrap();
    assert!(!b.is_asleep(), "the motor switched on");
    assert!(b.angle != angle, "and turned the body in the same step");
    assert!(
        !w.body(boxes[0]).unwrap().is_asleep(),
        "its whole island woke"
    );
    assert!(
        w.body(boxes[4]).unwrap().is_asleep(),
        "another island did not"
    );

    w.wake_body(boxes[4]);
    assert!((4..8).all(|i| !w.body(boxes[i]).unwrap().is_asleep()));
}

#[test]
fn turning_sleeping_off_wakes_everything() {
    let (mut w, boxes) = piles(ContactSolver::Exact);
    for _ in 0..120 {
        w.step(H);
    }
    assert!(w.body(boxes[0]).unwrap().is_asleep());
    w.settings.sleeping = false;
    w.step(H);
    assert!(boxes.iter().all(|&b| !w.body(b).unwrap().is_asleep()));
}

/// A sleeping body takes no impulse (it is fixed until woken), and once woken keeps the
/// mass it had: an impulse J on a box of density 2 (mass 2) sets its velocity to J / 2,
/// to the bit, under every solver but the naive one (under `sequential` a box on a floor
/// never comes to rest: it hops at about 0.08 m/s).
#[test]
fn a_sleeping_body_takes_no_impulse_and_wakes_with_its_own_mass() {
    let settling = ContactSolver::ALL.into_iter();
    for solver in settling.filter(|&s| s != ContactSolver::Sequential) {
        let (mut w, boxes) = piles(solver);
        let heavy = ConvexPolygon::rectangle(1.0, 1.0).unwrap();
        let at = Vec2::new(12.0, -0.5);
        let heavy = w.add_body(BodyDef::new(heavy, 2.0).at(at, 0.0)).unwrap();
        for _ in 0..120 {
            w.step(H);
        }
        let impulse = Vec2::new(3.0, -1.0);
        let body = w.body_mut(heavy).unwrap();
        assert!(body.is_asleep(), "{solver:?}");
        let centre = body.position;
        body.apply_impulse_at(impulse, centre);
        assert_eq!(
            body.velocity,
            Vec2::zeros(),
            "{solver:?}: asleep, it took none"
        );
        w.wake_body(heavy);
        let body = w.body_mut(heavy).unwrap();
        body.apply_impulse_at(impulse, centre);
        assert_eq!(body.velocity, impulse * 0.5, "{solver:?}");
        assert_eq!(body.angular_velocity, 0.0, "{solver:?}");
        assert!(
            w.body(boxes[0]).unwrap().is_asleep(),
            "{solver:?}: the piles sleep on"
        );
    }
}
