//! The default database's robot scenes (the thesis's housenka and test scene, the
//! editor's car, walker and linkage), timed in pe under each contact solver through the
//! simulation layer the app and the CLI use. The peers have no thesis motors, so this
//! table is pe's alone; the target is the thesis pipeline on the housenka under
//! 20 µs per step.

use crate::harness::{Timing, measure};
use crate::scene::worst;
use pe::ContactSolver;
use robosim::db::Database;
use robosim::sim::Simulation;

pub const SCENES: [&str; 5] = [
    "housenka on the floor",
    "testovaci scena",
    "car on terrain",
    "walker",
    "four-bar linkage",
];

pub const SOLVERS: [ContactSolver; 4] = [
    ContactSolver::Thesis,
    ContactSolver::Exact,
    ContactSolver::Soft,
    ContactSolver::Auto,
];

/// Steps per run, at each scene's own time step (1/60 s; the test scene's default).
pub const STEPS: usize = 1000;

/// One scene under each of `SOLVERS`: the timing and the widest any joint opened (px).
pub struct RobotRow {
    pub scene: &'static str,
    pub runs: Vec<(Timing, f64)>,
}

pub fn run() -> Vec<RobotRow> {
    let (db, problems) = Database::embedded();
    assert!(problems.is_empty(), "the default database: {problems:?}");
    SCENES
        .iter()
        .map(|&scene| {
            eprint!("{scene}:");
            let runs = SOLVERS
                .iter()
                .map(|&solver| {
                    eprint!(" pe {}…", solver.name());
                    let mut sim = Simulation::new(&db.model, scene, None, Some(solver))
                        .expect("a default scene builds");
                    let mut widest: f64 = 0.0;
                    let timing = measure(&mut sim, STEPS, Simulation::step, |sim, _| {
                        widest = worst(widest, sim.metrics().max_joint_gap);
                    });
                    (timing, widest)
                })
                .collect();
            eprintln!();
            RobotRow { scene, runs }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_scene_is_in_the_default_database() {
        let (db, _) = Database::embedded();
        for scene in SCENES {
            assert!(db.model.scene(scene).is_some(), "{scene}");
        }
    }
}
