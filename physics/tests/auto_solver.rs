//! `ContactSolver::Auto`: exact for robots and islands of unlike masses that are small
//! enough to pivot, the soft step for the rest, in one world. Metre-sized bodies,
//! g = 10 m/s², h = 1/60 s.

use pe::{
    BodyDef, BodyHandle, ContactSolver, ConvexPolygon, IslandMethod, JointDef, JointHandle,
    JointMotor, Vec2, World,
};

const H: f64 = 1.0 / 60.0;

fn floor(w: &mut World) {
    let floor = ConvexPolygon::rectangle(200.0, 1.0).unwrap();
    w.add_body(BodyDef::new(floor, 0.0).at(Vec2::new(0.0, 0.5), 0.0))
        .unwrap();
}

/// A 10-row pyramid of unit boxes at x = 0 (55 boxes, some 200 LCP rows: a big island).
fn pyramid(w: &mut World) -> Vec<(BodyHandle, Vec2)> {
    let unit = ConvexPolygon::rectangle(1.0, 1.0).unwrap();
    let mut boxes = Vec::new();
    for row in 0..10 {
        for i in 0..10 - row {
            let centre = Vec2::new(i as f64 - 0.5 * (9 - row) as f64, -0.5 - row as f64);
            let b = w
                .add_body(BodyDef::new(unit.clone(), 1.0).at(centre, 0.0))
                .unwrap();
            boxes.push((b, centre));
        }
    }
    boxes
}

/// A robot away from the pile: a three-link arm pinned to the world at (40, −6) with a
/// motor at its shoulder, and a box resting on the floor under it (small islands).
/// Returns the bodies and the shoulder.
fn robot(w: &mut World) -> (Vec<BodyHandle>, JointHandle) {
    let link = ConvexPolygon::rectangle(1.0, 0.2).unwrap();
    let mut bodies = Vec::new();
    let mut previous = None;
    let mut shoulder = None;
    for i in 0..3 {
        let x = 40.0 + i as f64;
        let b = w
            .add_body(BodyDef::new(link.clone(), 2.0).at(Vec2::new(x + 0.5, -6.0), 0.0))
            .unwrap();
        let mut pin = JointDef::new(b, previous, Vec2::new(x, -6.0));
        if i == 0 {
            pin.motor = Some(JointMotor::new(1.5, 50.0));
        }
        let joint = w.add_joint(pin).unwrap();
        shoulder = shoulder.or(Some(joint));
        bodies.push(b);
        previous = Some(b);
    }
    let crate_box = ConvexPolygon::rectangle(1.0, 1.0).unwrap();
    bodies.push(
        w.add_body(BodyDef::new(crate_box, 1.0).at(Vec2::new(38.0, -0.5), 0.0))
            .unwrap(),
    );
    (bodies, shoulder.unwrap())
}

fn world(solver: ContactSolver) -> World {
    let mut w = World::new(Vec2::new(0.0, 10.0));
    w.settings.contact_solver = solver;
    w.friction = 0.6;
    w
}

/// Under `auto` the pile's island goes to the soft step and the robot's to `exact`: the
/// reports name both, the robot's arm moves bit for bit as it does alone under `exact`,
/// and the pile bit for bit as it does alone under `soft` (from the first step: its
/// candidate pairs make it big before any contact is known). The box on the floor, an
/// island of one body, goes to the soft step too.
#[test]
fn auto_solves_the_robot_exactly_and_the_pile_by_the_soft_step() {
    let mut mixed = world(ContactSolver::Auto);
    floor(&mut mixed);
    let boxes = pyramid(&mut mixed);
    let (robot_in_mixed, shoulder_in_mixed) = robot(&mut mixed);
    let mut alone = world(ContactSolver::Exact);
    floor(&mut alone);
    let (robot_alone, shoulder_alone) = robot(&mut alone);
    let mut soft = world(ContactSolver::Soft);
    floor(&mut soft);
    let soft_boxes = pyramid(&mut soft);

    for step in 0..300 {
        mixed.step(H);
        alone.step(H);
        soft.step(H);
        for (&a, &b) in robot_in_mixed[..3].iter().zip(&robot_alone) {
            let (a, b) = (mixed.body(a).unwrap(), alone.body(b).unwrap());
            assert_eq!(a.state(), b.state(), "robot differs at step {step}");
        }
        // The motor's reading too: the soft pass leaves the exact pass's alone.
        let torque = |w: &World, j| w.joint(j).unwrap().motor.unwrap().step_impulse;
        assert_eq!(
            torque(&mixed, shoulder_in_mixed),
            torque(&alone, shoulder_alone),
            "motor differs at step {step}"
        );
        for (&(a, _), &(b, _)) in boxes.iter().zip(&soft_boxes) {
            let (a, b) = (mixed.body(a).unwrap(), soft.body(b).unwrap());
            assert_eq!(a.state(), b.state(), "pile differs at step {step}");
        }
    }
    // The motor turned the arm: the robot did something worth comparing.
    let shoulder = mixed.body(robot_in_mixed[0]).unwrap();
    assert!(shoulder.angle.abs() > 1.0, "arm turned {}", shoulder.angle);

    let reports = mixed.island_reports();
    let robot_arm = reports
        .iter()
        .find(|r| r.joints == 3)
        .expect("the arm's island");
    assert_eq!(robot_arm.method, IslandMethod::Pivoting);
    let crate_island = reports
        .iter()
        .find(|r| r.joints == 0 && r.contacts == 2)
        .expect("the box on the floor");
    assert_eq!(crate_island.method, IslandMethod::SoftPointByPoint);
    let pile = reports
        .iter()
        .find(|r| r.contacts > 48)
        .expect("the pile's island");
    assert!(
        matches!(
            pile.method,
            IslandMethod::SoftPointByPoint | IslandMethod::SoftLcp
        ),
        "{:?}",
        pile.method
    );
    // Both passes' contacts are reported: the box's two and the pile's.
    let touching = |w: &World, b: BodyHandle| {
        w.contacts()
            .iter()
            .filter(|c| c.body_a == b || c.body_b == b)
            .count()
    };
    assert_eq!(touching(&mixed, robot_in_mixed[3]), 2);
    assert!(mixed.contacts().len() > 100);

    // And the pile stands: its top box within 1% of a width of where it started.
    let (top, start) = *boxes.last().unwrap();
    let top = mixed.body(top).unwrap().position;
    assert!((top.x - start.x).abs() < 0.01, "{top:?}");
}

/// A light box carrying a small one twenty times as heavy, falling onto the pile, is an
/// island of unlike masses (exact) until it lands, then part of the pile's island (soft):
/// the hand-over neither loses them nor lets them sink in.
#[test]
fn a_pair_landing_on_the_pile_joins_the_soft_island() {
    let mut w = world(ContactSolver::Auto);
    floor(&mut w);
    let boxes = pyramid(&mut w);
    let top = boxes.last().unwrap().1;
    let unit = ConvexPolygon::rectangle(1.0, 1.0).unwrap();
    let light = w
        .add_body(BodyDef::new(unit, 1.0).at(top - Vec2::new(0.0, 3.0), 0.0))
        .unwrap();
    let small = ConvexPolygon::rectangle(0.5, 0.5).unwrap();
    let heavy = w
        .add_body(BodyDef::new(small, 80.0).at(top - Vec2::new(0.0, 3.75), 0.0))
        .unwrap();
    let pivoted = |w: &World| {
        w.island_reports()
            .iter()
            .any(|r| r.method == IslandMethod::Pivoting)
    };
    w.step(H);
    assert!(pivoted(&w), "the falling pair is solved exactly");
    for _ in 0..180 {
        w.step(H);
    }
    let rest = w.body(light).unwrap().position;
    // Resting on the top box: one box above it, within the soft step's overlap.
    let below = w.body(boxes.last().unwrap().0).unwrap().position;
    assert!(
        (below.y - rest.y - 1.0).abs() < 0.02,
        "{rest:?} on {below:?}"
    );
    assert!((rest.x - below.x).abs() < 0.05, "{rest:?} on {below:?}");
    let on_top = w.body(heavy).unwrap().position;
    assert!(
        (rest.y - on_top.y - 0.75).abs() < 0.02,
        "{on_top:?} on {rest:?}"
    );
    assert!(w.body(light).unwrap().velocity.norm() < 0.05);
    // Only the pile and the pair move, all of them in the soft step's island now.
    assert!(!w.island_reports().is_empty());
    assert!(!pivoted(&w), "{:?}", w.island_reports());
}

/// A heavy box with a small one pinned behind it, thrown into a block of small ones, no
/// gravity: total momentum is conserved (to round-off, as under `exact` and `soft` alone),
/// also in the step where the pair, an exact island until then (a pin), hits the block's
/// soft one.
#[test]
fn auto_conserves_momentum_when_a_small_island_hits_a_big_one() {
    let mut w = World::new(Vec2::zeros());
    w.settings.contact_solver = ContactSolver::Auto;
    w.friction = 0.5;
    let small = ConvexPolygon::rectangle(0.5, 0.5).unwrap();
    for i in 0..20 {
        for j in 0..20 {
            let centre = Vec2::new(0.25 + 0.5 * i as f64, -0.25 - 0.5 * j as f64);
            w.add_body(BodyDef::new(small.clone(), 1.0).at(centre, 0.0))
                .unwrap();
        }
    }
    let heavy = ConvexPolygon::rectangle(2.0, 2.0).unwrap();
    let thrown = w
        .add_body(
            BodyDef::new(heavy, 10.0)
                .at(Vec2::new(-3.0, -5.0), 0.0)
                .velocity(Vec2::new(40.0, 0.0), 0.0),
        )
        .unwrap();
    let tail = w
        .add_body(
            BodyDef::new(small.clone(), 1.0)
                .at(Vec2::new(-4.25, -5.0), 0.0)
                .velocity(Vec2::new(40.0, 0.0), 0.0),
        )
        .unwrap();
    w.add_joint(JointDef::new(thrown, Some(tail), Vec2::new(-4.0, -5.0)))
        .unwrap();
    let p0 = w.linear_momentum();
    let (mut hit, mut block_solved_soft, mut pair_pivoted) = (false, false, false);
    for step in 0..60 {
        w.step(H);
        let drift = (w.linear_momentum() - p0).norm() / p0.norm();
        assert!(drift < 1e-12, "momentum drift {drift:e} at step {step}");
        hit |= w.body(thrown).unwrap().velocity.x < 39.0;
        let reports = w.island_reports();
        block_solved_soft |= reports.iter().any(|r| r.contacts > 48);
        pair_pivoted |= !hit && reports.iter().any(|r| r.method == IslandMethod::Pivoting);
    }
    assert!(hit, "the box reached the block");
    assert!(pair_pivoted, "the pinned pair flew as an exact island");
    // Both solvers ran: the block was solved by the soft step while the box flew alone
    // (by the end the debris has scattered into small islands).
    assert!(block_solved_soft);
}
