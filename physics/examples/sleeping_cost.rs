//! What sleeping saves: 1,000 unit boxes in 100 columns of ten on a floor, stepped awake
//! (sleeping off) and asleep, median time per step of each; and asleep while another 1,000
//! boxes fall high above them (what checking the awake against the asleep for waking costs).
//!
//! `cargo run --release -p pe --example sleeping_cost`

use pe::{BodyDef, ContactSolver, ConvexPolygon, Vec2, World};
use std::time::Instant;

const H: f64 = 1.0 / 60.0;

fn columns(solver: ContactSolver) -> World {
    let mut w = World::new(Vec2::new(0.0, 10.0));
    w.settings.contact_solver = solver;
    w.friction = 0.6;
    let floor = ConvexPolygon::rectangle(400.0, 1.0).unwrap();
    w.add_body(BodyDef::new(floor, 0.0).at(Vec2::new(0.0, 0.5), 0.0))
        .unwrap();
    let unit = ConvexPolygon::rectangle(1.0, 1.0).unwrap();
    for c in 0..100 {
        for i in 0..10 {
            let at = Vec2::new(-150.0 + 3.0 * c as f64, -0.5 - i as f64);
            w.add_body(BodyDef::new(unit.clone(), 1.0).at(at, 0.0))
                .unwrap();
        }
    }
    w
}

fn median_step_micros(w: &mut World, steps: usize) -> f64 {
    let mut times: Vec<f64> = (0..steps)
        .map(|_| {
            let t = Instant::now();
            w.step(H);
            t.elapsed().as_secs_f64() * 1e6
        })
        .collect();
    times.sort_by(f64::total_cmp);
    times[steps / 2]
}

fn main() {
    println!(
        "| solver | awake µs/step | asleep µs/step | ratio | asleep, 1,000 more falling above: µs/step |"
    );
    println!("| --- | ---: | ---: | ---: | ---: |");
    for solver in [ContactSolver::Exact, ContactSolver::Soft] {
        let mut w = columns(solver);
        for _ in 0..60 {
            w.step(H);
        }
        let awake = median_step_micros(&mut w, 60);
        w.settings.sleeping = true;
        let mut steps = 0;
        while w.bodies().any(|(_, b)| !b.is_static() && !b.is_asleep()) && steps < 600 {
            w.step(H);
            steps += 1;
        }
        let asleep = median_step_micros(&mut w, 60);
        // Falling from 40 m, the newcomers reach the columns after about 2.5 s: time the
        // first 20 steps, while they are awake and touch nothing.
        let unit = ConvexPolygon::rectangle(1.0, 1.0).unwrap();
        for c in 0..100 {
            for i in 0..10 {
                let at = Vec2::new(-150.0 + 3.0 * c as f64, -40.0 - 2.0 * i as f64);
                w.add_body(BodyDef::new(unit.clone(), 1.0).at(at, 0.0))
                    .unwrap();
            }
        }
        let mixed = median_step_micros(&mut w, 20);
        println!(
            "| {} | {awake:.0} | {asleep:.1} | {:.4} | {mixed:.0} |",
            solver.name(),
            asleep / awake
        );
    }
}
