//! The golden test: every scene of the default database under every solver, awake and
//! with sleeping, each run hashed from the bits of every body's state at every step and
//! compared with the committed table (`snapshots/golden__*.snap`). A change that means to
//! keep the bits must keep this table; one that means to move them regenerates it
//! (`INSTA_UPDATE=always cargo test --workspace --test golden`) and says why in its
//! commit. The profiling examples' worlds are held the same way by
//! `physics/tests/golden.rs`.

#[path = "../physics/examples/support/state_hash.rs"]
mod state_hash;

use robosim::db::Database;
use robosim::pe::ContactSolver;
use robosim::sim::Simulation;
use std::fmt::Write;
use std::hash::Hasher;

/// As many steps as `robosim run` takes by default.
const STEPS: u64 = 1000;

/// Scene `name` under `solver`, sleeping or not, `STEPS` steps at the scene's step, each
/// step's state folded into one hash; a refused step ends the run and is part of the line.
fn run(name: &str, solver: ContactSolver, sleeping: bool) -> String {
    let (db, _) = Database::embedded();
    let mut sim = Simulation::new(&db.model, name, None, Some(solver)).unwrap();
    sim.world.settings.sleeping = sleeping;
    let mut hasher = fnv::FnvHasher::default();
    for step in 0..STEPS {
        if let Err(e) = sim.try_step() {
            return format!("{:016x} (refused at step {step}: {e})", hasher.finish());
        }
        state_hash::fold_state(&mut hasher, &sim.world);
    }
    format!("{:016x}", hasher.finish())
}

fn table(solver: ContactSolver) -> String {
    let (db, problems) = Database::embedded();
    assert!(problems.is_empty(), "{problems:#?}");
    let mut out = String::new();
    for scene in &db.model.scenes {
        for sleeping in [false, true] {
            let hash = run(&scene.name, solver, sleeping);
            let mode = if sleeping { "sleeping" } else { "awake" };
            writeln!(out, "{} ({mode}): {hash}", scene.name).unwrap();
        }
    }
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
