//! A body alone under gravity follows the integrator's closed form exactly and the analytic
//! parabola to O(h), under the solvers whose step is one integrator step (the soft step
//! takes substeps of its own).

use pe::{BodyDef, ContactSolver, ConvexPolygon, Integrator, Vec2, World};

const G: f64 = 9.81;
const H: f64 = 1.0 / 60.0;
const STEPS: u32 = 240;

fn fall(integrator: Integrator) -> (Vec2, Vec2) {
    let mut world = World::new(Vec2::new(0.0, G));
    world.settings.contact_solver = ContactSolver::Exact;
    world.settings.integrator = integrator;
    let shape = ConvexPolygon::rectangle(1.0, 0.5).unwrap();
    let v0 = Vec2::new(3.0, -4.0);
    let body = world
        .add_body(
            BodyDef::new(shape, 2.0)
                .at(Vec2::new(1.0, 2.0), 0.0)
                .velocity(v0, 0.0),
        )
        .unwrap();
    for _ in 0..STEPS {
        world.step(H);
    }
    let b = world.body(body).unwrap();
    (b.position, b.velocity)
}

/// n steps of v += g h: v_n = v0 + n g h. Positions sum the velocities used:
/// semi-implicit uses v_1..v_n (n(n+1)/2 g h²), explicit v_0..v_{n−1} (n(n−1)/2 g h²).
fn closed_form(integrator: Integrator) -> (Vec2, Vec2) {
    let n = STEPS as f64;
    let (p0, v0, g) = (Vec2::new(1.0, 2.0), Vec2::new(3.0, -4.0), Vec2::new(0.0, G));
    let sum = match integrator {
        Integrator::SemiImplicitEuler => n * (n + 1.0) / 2.0,
        Integrator::ExplicitEuler => n * (n - 1.0) / 2.0,
    };
    (p0 + v0 * (n * H) + g * (sum * H * H), v0 + g * (n * H))
}

#[test]
fn each_integrator_matches_its_discrete_closed_form() {
    for integrator in [Integrator::SemiImplicitEuler, Integrator::ExplicitEuler] {
        let (p, v) = fall(integrator);
        let (p_exact, v_exact) = closed_form(integrator);
        // 240 additions of numbers ~10: rounding stays below 1e-12 relative.
        assert!(
            (p - p_exact).norm() <= 1e-12 * p_exact.norm(),
            "{integrator:?}: {p:?} vs {p_exact:?}"
        );
        assert!(
            (v - v_exact).norm() <= 1e-12 * v_exact.norm(),
            "{integrator:?}"
        );
    }
}

#[test]
fn both_integrators_approach_the_parabola_to_first_order() {
    let t = STEPS as f64 * H;
    let analytic =
        Vec2::new(1.0, 2.0) + Vec2::new(3.0, -4.0) * t + Vec2::new(0.0, G) * (0.5 * t * t);
    for (integrator, sign) in [
        (Integrator::SemiImplicitEuler, 1.0),
        (Integrator::ExplicitEuler, -1.0),
    ] {
        let (p, _) = fall(integrator);
        // The error is exactly ±g h t / 2: first order in h.
        let expected_error = sign * G * H * t / 2.0;
        assert!(
            ((p.y - analytic.y) - expected_error).abs() < 1e-9,
            "{integrator:?}"
        );
        assert!((p.x - analytic.x).abs() < 1e-12);
    }
}
