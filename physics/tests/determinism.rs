//! The same world stepped twice from the same start gives bit-identical states, and so does
//! a world cloned mid-run.

use pe::{BodyDef, ContactSolver, ConvexPolygon, Vec2, World};

fn pile(solver: ContactSolver) -> World {
    let mut world = World::new(Vec2::new(0.0, 9.81));
    world.friction = 0.5;
    world.settings.contact_solver = solver;
    let floor = ConvexPolygon::rectangle(40.0, 1.0).unwrap();
    world
        .add_body(BodyDef::new(floor, 0.0).at(Vec2::new(0.0, 5.0), 0.0))
        .unwrap();
    for i in 0..30 {
        let shape = ConvexPolygon::regular(3 + i % 5, 0.5).unwrap();
        let at = Vec2::new(-6.0 + 0.45 * i as f64, 3.0 - 1.1 * (i % 6) as f64);
        world
            .add_body(
                BodyDef::new(shape, 1.0)
                    .restitution(0.3)
                    .at(at, 0.1 * i as f64),
            )
            .unwrap();
    }
    world
}

fn state_bits(world: &World) -> Vec<u64> {
    world
        .bodies()
        .flat_map(|(_, b)| b.state())
        .map(f64::to_bits)
        .collect()
}

#[test]
fn stepping_twice_gives_bit_identical_states() {
    for solver in ContactSolver::ALL {
        let (mut a, mut b) = (pile(solver), pile(solver));
        for _ in 0..300 {
            a.step(1.0 / 60.0);
            b.step(1.0 / 60.0);
        }
        assert!(
            a.contacts().len() > 10,
            "{solver:?}: the pile must actually touch"
        );
        assert_eq!(state_bits(&a), state_bits(&b), "{solver:?}");
    }
}

#[test]
fn a_world_cloned_mid_run_goes_on_as_the_original() {
    // The clone carries the solvers' state between steps (warm-start memory, kept
    // manifolds and plans, the soft step's count of substeps, which sets its sweep order).
    for solver in ContactSolver::ALL {
        let mut original = pile(solver);
        for _ in 0..150 {
            original.step(1.0 / 60.0);
        }
        let mut clone = original.clone();
        for _ in 0..150 {
            original.step(1.0 / 60.0);
            clone.step(1.0 / 60.0);
        }
        assert_eq!(state_bits(&original), state_bits(&clone), "{solver:?}");
    }
}
