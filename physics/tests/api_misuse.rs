//! The library's API given what it must refuse (issue 63): handles that name nothing,
//! numbers set by hand through `body_mut`, `settings` and `joint_motor_mut`. Each is
//! refused with an error naming it, before the step, the world untouched; never a panic.

use pe::{
    BodyDef, BodyHandle, BodyMotor, ContactSolver, ConvexPolygon, JointDef, JointError,
    JointHandle, JointMotor, MotorError, StepError, Vec2, World,
};

const H: f64 = 1.0 / 60.0;

/// A floor, a box resting on it and a second box pinned to the first, under `solver`.
fn world(solver: ContactSolver) -> (World, BodyHandle, BodyHandle, JointHandle) {
    let mut world = World::new(Vec2::new(0.0, 9.81));
    world.settings.contact_solver = solver;
    let floor = ConvexPolygon::rectangle(20.0, 1.0).unwrap();
    let floor = world
        .add_body(BodyDef::new(floor, 0.0).at(Vec2::new(0.0, 0.5), 0.0))
        .unwrap();
    let square = ConvexPolygon::rectangle(1.0, 1.0).unwrap();
    let a = world
        .add_body(BodyDef::new(square.clone(), 1.0).at(Vec2::new(0.0, -0.5), 0.0))
        .unwrap();
    let b = world
        .add_body(BodyDef::new(square, 1.0).at(Vec2::new(1.0, -0.5), 0.0))
        .unwrap();
    let pin = world
        .add_joint(JointDef::new(a, Some(b), Vec2::new(0.5, -0.5)))
        .unwrap();
    (world, floor, a, pin)
}

/// Every body's state bits, to show that a refused step left them alone.
fn state(world: &World) -> Vec<[u64; 6]> {
    world
        .bodies()
        .map(|(_, b)| {
            [
                b.position.x,
                b.position.y,
                b.angle,
                b.velocity.x,
                b.velocity.y,
                b.angular_velocity,
            ]
            .map(f64::to_bits)
        })
        .collect()
}

#[test]
fn a_motor_on_a_body_that_does_not_exist_is_refused() {
    for solver in ContactSolver::ALL {
        let (mut world, ..) = world(solver);
        let motor = BodyMotor::new(0, 100, 0.1, 1.0, 10.0, 0.1);
        let nowhere = BodyHandle(1000);
        assert_eq!(
            world.add_body_motor(nowhere, motor),
            Err(MotorError::MissingBody)
        );
        for _ in 0..10 {
            world.try_step(H).unwrap();
        }
    }
}

#[test]
fn a_removed_body_takes_its_joints_and_leaves_its_motors_idle() {
    for solver in ContactSolver::ALL {
        let (mut world, _, a, pin) = world(solver);
        let motor = BodyMotor::new(0, 100, 0.1, 1.0, 10.0, 0.1);
        world.add_body_motor(a, motor).unwrap();
        world.remove_body(a).unwrap();
        assert!(
            world.joint(pin).is_none(),
            "{solver:?}: the pin outlived its body"
        );
        for _ in 0..30 {
            world.try_step(H).unwrap();
        }
        assert!(world.max_joint_gap() == 0.0);
    }
}

#[test]
fn joints_change_only_through_methods_that_check() {
    let (mut world, _, _, pin) = world(ContactSolver::Auto);
    assert_eq!(world.set_collide_connected(JointHandle(7), true), None);
    assert_eq!(world.set_collide_connected(pin, true), Some(()));
    let bad = JointMotor::new(1.0, f64::NAN);
    assert!(matches!(
        world.set_joint_motor(pin, Some(bad)),
        Err(JointError::BadMotor(_))
    ));
    assert_eq!(
        world.set_joint_motor(JointHandle(7), None),
        Err(JointError::MissingJoint)
    );
    world
        .set_joint_motor(pin, Some(JointMotor::new(1.0, 10.0)))
        .unwrap();
    world.joint_motor_mut(pin).unwrap().max_torque = f64::NAN;
    let before = state(&world);
    let refused = world.try_step(H);
    assert!(
        matches!(refused, Err(StepError::BadJointMotor { joint: 0, .. })),
        "{refused:?}"
    );
    assert_eq!(state(&world), before);
}

#[test]
fn numbers_set_by_hand_are_refused_before_the_step_and_the_world_is_untouched() {
    type Change = fn(&mut World, BodyHandle, BodyHandle);
    let changes: [(&str, Change); 7] = [
        ("x", |w, floor, _| {
            w.body_mut(floor).unwrap().position.x = f64::NAN
        }),
        ("angle", |w, _, a| w.body_mut(a).unwrap().angle = 1e300),
        ("torque", |w, _, a| w.body_mut(a).unwrap().torque = 1e308),
        ("force", |w, _, a| {
            w.body_mut(a).unwrap().force = Vec2::new(f64::INFINITY, 0.0)
        }),
        ("speed", |w, _, a| {
            w.body_mut(a).unwrap().velocity = Vec2::new(0.0, f64::NAN)
        }),
        ("restitution", |w, _, a| {
            w.body_mut(a).unwrap().restitution = 2.0
        }),
        ("friction", |w, floor, _| {
            w.body_mut(floor).unwrap().friction = Some(-1.0)
        }),
    ];
    for solver in ContactSolver::ALL {
        for (what, change) in changes {
            let (mut world, floor, a, _) = world(solver);
            world.step(H);
            change(&mut world, floor, a);
            let (before, steps) = (state(&world), world.step_count());
            let refused = world.try_step(H);
            match refused {
                Err(StepError::BadBody { what: named, .. }) => assert_eq!(named, what),
                other => panic!("{solver:?}, {what}: {other:?}"),
            }
            assert_eq!(world.step_count(), steps, "{solver:?}, {what}");
            // Bits compared: a NaN put there by hand is still the same NaN.
            assert_eq!(state(&world), before, "{solver:?}, {what}: the step moved");
        }
    }
}

#[test]
fn settings_out_of_range_are_refused_by_name() {
    type Change = fn(&mut World);
    let changes: [(&str, Change); 4] = [
        ("length_scale", |w| w.settings.length_scale = f64::NAN),
        ("length_scale", |w| w.settings.length_scale = 0.0),
        ("length_scale", |w| w.settings.length_scale = -1.0),
        ("soft_substeps", |w| w.settings.soft_substeps = 0),
    ];
    for (what, change) in changes {
        let (mut world, ..) = world(ContactSolver::Soft);
        change(&mut world);
        let refused = world.try_step(H);
        match refused {
            Err(e @ StepError::BadSetting { .. }) => {
                assert!(e.to_string().contains(what), "{e}")
            }
            other => panic!("{what}: {other:?}"),
        }
    }
}

/// What a mouse spring puts on the heaviest legal body is taken, not refused: the limit
/// on a hand-applied force is far above it (a density of 1e12 pulled hard: 1e20).
#[test]
fn a_heavy_body_pulled_hard_by_hand_steps() {
    for solver in ContactSolver::ALL {
        let mut world = World::new(Vec2::new(0.0, 9.81));
        world.settings.contact_solver = solver;
        let square = ConvexPolygon::rectangle(100.0, 100.0).unwrap();
        let heavy = world.add_body(BodyDef::new(square, 1e12)).unwrap();
        let body = world.body_mut(heavy).unwrap();
        body.apply_force_at(Vec2::new(1e20, 0.0), Vec2::new(0.0, 40.0));
        world.try_step(H).unwrap();
        assert!(world.body(heavy).unwrap().velocity.x > 0.0, "{solver:?}");
    }
}
