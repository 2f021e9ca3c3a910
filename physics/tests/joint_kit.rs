//! The robot builder's kit on a pin (issue 65), against known answers: a rotational
//! spring's period, energy and damping; a servo's reach, overshoot and hold under load;
//! a stop that holds a pendulum, a weld that holds a cantilever.

use pe::{
    BodyDef, ContactSolver, ConvexPolygon, JointDef, JointHandle, JointLimits, JointMotor,
    JointSpring, Vec2, World,
};

const H: f64 = 1.0 / 60.0;
/// The bar: 1 × 0.1, density 1, pinned to the world at its left end.
const LENGTH: f64 = 1.0;
const WIDTH: f64 = 0.1;

/// Its moment of inertia about the pin: I_c + m·(L/2)².
fn inertia_about_pin() -> f64 {
    let m = LENGTH * WIDTH;
    m * (LENGTH * LENGTH + WIDTH * WIDTH) / 12.0 + m * (LENGTH / 2.0).powi(2)
}

/// A bar pinned to the world at the origin, lying along +x, in zero gravity unless asked.
fn pinned_bar(
    solver: ContactSolver,
    gravity: f64,
    pin: impl FnOnce(&mut JointDef),
) -> (World, JointHandle) {
    let mut w = World::new(Vec2::new(0.0, gravity));
    w.settings.contact_solver = solver;
    let bar = ConvexPolygon::rectangle(LENGTH, WIDTH).unwrap();
    let body = w
        .add_body(BodyDef::new(bar, 1.0).at(Vec2::new(LENGTH / 2.0, 0.0), 0.0))
        .unwrap();
    let mut def = JointDef::new(body, None, Vec2::zeros());
    pin(&mut def);
    let joint = w.add_joint(def).unwrap();
    (w, joint)
}

/// θ − rest over `steps` steps.
fn swing(w: &mut World, joint: JointHandle, rest: f64, steps: usize) -> Vec<f64> {
    (0..steps)
        .map(|_| {
            w.try_step(H).unwrap();
            w.joint_angle(joint).unwrap() - rest
        })
        .collect()
}

/// The times (s) at which `xs` crosses zero going up, interpolated.
fn upward_crossings(xs: &[f64]) -> Vec<f64> {
    xs.windows(2)
        .enumerate()
        .filter(|(_, w)| w[0] < 0.0 && w[1] >= 0.0)
        .map(|(i, w)| (i as f64 + 1.0 + w[0] / (w[0] - w[1])) * H)
        .collect()
}

/// The peaks of |x| between crossings.
fn peaks(xs: &[f64]) -> Vec<f64> {
    xs.windows(3)
        .filter(|w| w[1] > w[0] && w[1] >= w[2] && w[1] > 0.0)
        .map(|w| w[1])
        .collect()
}

#[test]
fn an_undamped_spring_swings_at_its_period_and_keeps_its_swing() {
    // One period a second: 60 steps a period.
    let stiffness = inertia_about_pin() * (2.0 * std::f64::consts::PI).powi(2);
    for solver in [
        ContactSolver::Auto,
        ContactSolver::Exact,
        ContactSolver::Soft,
    ] {
        let rest = 0.3;
        let (mut w, joint) = pinned_bar(solver, 0.0, |d| {
            d.spring = Some(JointSpring::new(stiffness, 0.0, rest));
        });
        let xs = swing(&mut w, joint, rest, 60 * 10 + 30);
        let ups = upward_crossings(&xs);
        let period = (ups[ups.len() - 1] - ups[0]) / (ups.len() - 1) as f64;
        assert!(
            (period - 1.0).abs() < 0.005,
            "{solver:?}: period {period} s, 2π√(I/k) = 1 s"
        );
        let swings = peaks(&xs);
        let (first, worst) = (0.3, swings.iter().fold(0.3f64, |m, &p| m.min(p)));
        let highest = swings.iter().fold(0.0f64, |m, &p| m.max(p));
        assert!(
            worst > 0.95 * first && highest < 1.05 * first,
            "{solver:?}: over 10 periods the swing stayed {worst}..{highest} of {first}"
        );
    }
}

#[test]
fn a_damped_spring_decays_by_its_damping_ratio() {
    let stiffness = inertia_about_pin() * (2.0 * std::f64::consts::PI).powi(2);
    let zeta: f64 = 0.05;
    // c = 2ζ√(k I).
    let damping = 2.0 * zeta * (stiffness * inertia_about_pin()).sqrt();
    let rest = 0.3;
    let expected = (-2.0 * std::f64::consts::PI * zeta / (1.0 - zeta * zeta).sqrt()).exp();
    for solver in [
        ContactSolver::Auto,
        ContactSolver::Exact,
        ContactSolver::Soft,
    ] {
        let (mut w, joint) = pinned_bar(solver, 0.0, |d| {
            d.spring = Some(JointSpring::new(stiffness, damping, rest));
        });
        let xs: Vec<f64> = swing(&mut w, joint, rest, 600).iter().map(|x| -x).collect();
        let p = peaks(&xs);
        assert!(p.len() >= 6, "{solver:?}: {p:?}");
        for pair in p.windows(2).take(5) {
            let ratio = pair[1] / pair[0];
            assert!(
                (ratio / expected - 1.0).abs() < 0.02,
                "{solver:?}: successive peaks {ratio}, exp(−2πζ/√(1−ζ²)) = {expected}"
            );
        }
    }
}

#[test]
fn a_stiff_spring_stays_stable_at_the_step() {
    // 1,000 times stiffer than the step resolves: (ω h)² ≈ 1,100.
    let stiffness = inertia_about_pin() * (2.0 * std::f64::consts::PI * 500.0).powi(2);
    let (mut w, joint) = pinned_bar(ContactSolver::Auto, 0.0, |d| {
        d.spring = Some(JointSpring::new(stiffness, 0.0, 0.3));
    });
    let xs = swing(&mut w, joint, 0.3, 600);
    let worst = xs.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    assert!(worst <= 0.3 + 1e-9, "never beyond its release: {worst}");
    assert!(xs[599].abs() < 0.3, "settles towards rest: {}", xs[599]);
}

#[test]
fn a_servo_reaches_its_angle_without_overshoot_and_holds_it_under_load() {
    let speed = 2.0; // rad/s: 1 rad takes 0.5 s.
    for solver in [
        ContactSolver::Auto,
        ContactSolver::Exact,
        ContactSolver::Soft,
    ] {
        // Gravity pulls the bar down (a load of m·g·L/2 = 0.49 N·m); the servo lifts it
        // to 1 rad (θ grows clockwise on screen: y down, the bar swings under the pin's
        // line) with at most 2 N·m.
        let (mut w, joint) = pinned_bar(solver, -9.8, |d| {
            d.motor = Some(JointMotor::servo(1.0, speed, 2.0));
        });
        let mut highest: f64 = f64::NEG_INFINITY;
        let mut reached_at = None;
        for step in 1..=180 {
            w.try_step(H).unwrap();
            let theta = w.joint_angle(joint).unwrap();
            highest = highest.max(theta);
            if reached_at.is_none() && (theta - 1.0).abs() < 0.01 {
                reached_at = Some(step);
            }
        }
        let reached_at = reached_at.unwrap_or_else(|| panic!("{solver:?}: never reached"));
        // 1 rad at 2 rad/s: 30 steps, and a few to get there against the load.
        assert!(reached_at <= 36, "{solver:?}: reached at step {reached_at}");
        assert!(highest < 1.02, "{solver:?}: overshot to {highest}");
        let held = w.joint_angle(joint).unwrap();
        assert!((held - 1.0).abs() < 0.01, "{solver:?}: held at {held}");
    }
}

const SOLVERS: [ContactSolver; 3] = [
    ContactSolver::Auto,
    ContactSolver::Exact,
    ContactSolver::Soft,
];

#[test]
fn a_pendulum_released_level_stops_at_its_limit_and_rests_on_it() {
    for solver in SOLVERS {
        // Gravity swings the bar down: θ (= −its angle, pinned to the world) falls
        // towards the lower stop at −0.5.
        let (mut w, joint) = pinned_bar(solver, 9.8, |d| {
            d.limits = Some(JointLimits::new(-0.5, 0.5));
        });
        let mut lowest = f64::INFINITY;
        for _ in 0..600 {
            w.try_step(H).unwrap();
            lowest = lowest.min(w.joint_angle(joint).unwrap());
        }
        assert!(
            lowest > -0.51,
            "{solver:?}: beyond the stop by {}",
            -0.5 - lowest
        );
        let theta = w.joint_angle(joint).unwrap();
        let body = w.bodies().next().unwrap().1;
        assert!(
            (theta + 0.5).abs() < 0.01 && body.angular_velocity.abs() < 1e-3,
            "{solver:?}: at rest on the stop: θ {theta}, spin {}",
            body.angular_velocity
        );
    }
}

#[test]
fn a_welded_beam_cantilevered_from_its_mount_does_not_sag() {
    for solver in SOLVERS {
        let (mut w, joint) = pinned_bar(solver, 9.8, |d| {
            d.limits = Some(JointLimits::new(0.0, 0.0));
        });
        let mut worst: f64 = 0.0;
        for _ in 0..600 {
            w.try_step(H).unwrap();
            worst = worst.max(w.joint_angle(joint).unwrap().abs());
        }
        assert!(worst < 1e-3, "{solver:?}: sagged {worst} rad");
    }
}
