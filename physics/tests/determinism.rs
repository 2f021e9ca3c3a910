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

/// A world remakes what it keeps for static and sleeping bodies (bounds, outlines, the
/// solvers' copies, the fixed bodies' cells, the obstacles) only when a body is added,
/// removed, falls asleep, wakes or is handed out by `body_mut` while static or asleep.
/// A twin given a static body far away at every step remakes all of it at every step:
/// both must step to the same bits. The scene has all of it: a terrain of 120 static
/// tiles, a pile that falls asleep, a box woken and thrown by hand, the pile woken and
/// the tile under it made a conveyor by hand, the tile beside it raised by hand, a box
/// removed, and a pendulum pinned to a tile. (Made blind to `body_mut` on a static body,
/// the world parts from its twin at the conveyor's step under every solver.)
#[test]
fn a_world_that_keeps_what_it_made_steps_as_one_that_remakes_it_every_step() {
    let tile = ConvexPolygon::rectangle(1.0, 1.0).unwrap();
    let speck = ConvexPolygon::rectangle(0.1, 0.1).unwrap();
    let build = |solver: ContactSolver| {
        let mut world = World::new(Vec2::new(0.0, 9.81));
        world.friction = 0.5;
        world.settings.contact_solver = solver;
        world.settings.sleeping = true;
        // Tile i at x = i - 60, its top face at y = 4.5.
        let tiles: Vec<_> = (0..120)
            .map(|i| {
                let at = Vec2::new(i as f64 - 60.0, 5.0);
                world
                    .add_body(BodyDef::new(tile.clone(), 0.0).at(at, 0.0))
                    .unwrap()
            })
            .collect();
        let boxes: Vec<_> = (0..12)
            .map(|i| {
                let at = Vec2::new(-3.0 + 1.05 * (i % 4) as f64, 3.9 - 1.02 * (i / 4) as f64);
                world
                    .add_body(BodyDef::new(tile.clone(), 1.0).at(at, 0.0))
                    .unwrap()
            })
            .collect();
        let bar = ConvexPolygon::rectangle(2.0, 0.2).unwrap();
        let arm = BodyDef::new(bar, 1.0).at(Vec2::new(21.0, 1.0), 0.0);
        let arm = world.add_body(arm).unwrap();
        world
            .add_joint(pe::JointDef::new(
                arm,
                Some(tiles[80]),
                Vec2::new(20.0, 1.0),
            ))
            .unwrap();
        let thrown = BodyDef::new(tile.clone(), 2.0).at(Vec2::new(-12.0, 4.0), 0.0);
        let thrown = world.add_body(thrown).unwrap();
        (world, tiles, boxes, thrown)
    };
    for solver in ContactSolver::ALL {
        let (mut kept, tiles, boxes, thrown) = build(solver);
        let (mut remade, ..) = build(solver);
        let mut slept = false;
        for step in 0..420 {
            for world in [&mut kept, &mut remade] {
                match step {
                    200 => {
                        world.wake_body(thrown);
                        world.body_mut(thrown).unwrap().velocity = Vec2::new(15.0, -6.0);
                    }
                    240 => world.wake_body(boxes[0]),
                    250 => world.body_mut(tiles[58]).unwrap().velocity = Vec2::new(1.5, 0.0),
                    300 => world.body_mut(tiles[57]).unwrap().position.y -= 0.3,
                    340 => drop(world.remove_body(boxes[11])),
                    _ => {}
                }
            }
            // A body added makes the twin remake everything it keeps; this one, a speck far
            // off, touches nothing.
            let far = Vec2::new(1e4 + step as f64, 0.0);
            remade
                .add_body(BodyDef::new(speck.clone(), 0.0).at(far, 0.0))
                .unwrap();
            kept.step(1.0 / 60.0);
            remade.step(1.0 / 60.0);
            slept |= boxes
                .iter()
                .any(|&b| kept.body(b).is_some_and(|b| b.is_asleep()));
            let bits = state_bits(&kept);
            let twin_bits = state_bits(&remade);
            assert_eq!(bits, twin_bits[..bits.len()], "{solver:?}, step {step}");
        }
        // (`sequential` never holds a pile still enough to sleep.)
        if solver != ContactSolver::Sequential {
            assert!(slept, "{solver:?}: the pile fell asleep");
        }
    }
}
