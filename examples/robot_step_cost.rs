//! Median time per step of the default database's robot scenes under each contact solver
//! (issue 8's target: the thesis pipeline on housenka under 20 µs per step).
//!
//! `cargo run --release --example robot_step_cost`

use robosim::db::Database;
use robosim::pe::ContactSolver;
use robosim::sim::Simulation;
use std::time::Instant;

const STEPS: usize = 2000;

fn main() {
    let (db, problems) = Database::embedded();
    assert!(problems.is_empty(), "{problems:#?}");
    println!("| scene | thesis µs/step | exact µs/step | soft µs/step |");
    println!("| --- | ---: | ---: | ---: |");
    for scene in ["housenka on the floor", "car on terrain", "walker"] {
        let mut cells = Vec::new();
        for solver in [
            ContactSolver::Thesis,
            ContactSolver::Exact,
            ContactSolver::Soft,
        ] {
            let mut sim = Simulation::new(&db.model, scene, None, Some(solver))
                .expect("the default scenes build");
            let mut times: Vec<f64> = (0..STEPS)
                .map(|_| {
                    let t = Instant::now();
                    sim.step();
                    t.elapsed().as_secs_f64() * 1e6
                })
                .collect();
            times.sort_by(f64::total_cmp);
            cells.push(format!("{:.1}", times[STEPS / 2]));
        }
        println!("| {scene} | {} |", cells.join(" | "));
    }
}
