//! The golden test: the profiling examples' worlds under every solver, each run hashed
//! from the bits of every body's state at every step and compared with the committed
//! table (`snapshots/golden__*.snap`). A change that means to keep the bits must keep
//! this table; one that means to move them regenerates it
//! (`INSTA_UPDATE=always cargo test --workspace --test golden`) and says why in its
//! commit. The default database's scenes are held the same way by `tests/golden.rs`.

#[path = "../examples/support/state_hash.rs"]
mod state_hash;
#[path = "../examples/support/worlds.rs"]
mod worlds;

use pe::{ContactSolver, World};
use std::fmt::Write;
use std::hash::Hasher;

const H: f64 = 1.0 / 60.0;

/// `world` stepped `steps` times, each step's state folded into one hash; a refused step
/// ends the run and is part of the line.
fn run(world: &mut World, steps: usize) -> String {
    let mut hasher = fnv::FnvHasher::default();
    for step in 0..steps {
        if let Err(e) = world.try_step(H) {
            return format!("{:016x} (refused at step {step}: {e})", hasher.finish());
        }
        state_hash::fold_state(&mut hasher, world);
    }
    format!("{:016x}", hasher.finish())
}

fn table(solver: ContactSolver) -> String {
    let mut out = String::new();
    let (mut pyramid, _, _) = worlds::pyramid(solver, 20);
    writeln!(
        out,
        "pyramid 20 rows, 300 steps: {}",
        run(&mut pyramid, 300)
    )
    .unwrap();
    let (mut chain, _) = worlds::heavy_chain(solver, 10);
    writeln!(
        out,
        "heavy chain 10 links, 600 steps: {}",
        run(&mut chain, 600)
    )
    .unwrap();
    let mut terrain = worlds::terrain(solver, 2000);
    writeln!(
        out,
        "terrain 2000 tiles, 300 steps: {}",
        run(&mut terrain, 300)
    )
    .unwrap();
    let mut asleep = worlds::terrain(solver, 2000);
    asleep.settings.sleeping = true;
    writeln!(
        out,
        "terrain 2000 tiles asleep, 300 steps: {}",
        run(&mut asleep, 300)
    )
    .unwrap();
    out
}

#[test]
fn auto() {
    insta::assert_snapshot!(table(ContactSolver::Auto));
}

#[test]
fn exact() {
    insta::assert_snapshot!(table(ContactSolver::Exact));
}

#[test]
fn soft() {
    insta::assert_snapshot!(table(ContactSolver::Soft));
}

#[test]
fn thesis() {
    insta::assert_snapshot!(table(ContactSolver::Thesis));
}

#[test]
fn sequential() {
    insta::assert_snapshot!(table(ContactSolver::Sequential));
}
