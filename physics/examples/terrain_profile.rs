//! A terrain of many static tiles under a few falling boxes, for profiling what the step
//! spends on bodies that never move:
//! `cargo run --release -p pe --example terrain_profile -- soft 600 2000`
//! (solver, steps, tiles). Prints the time per step and a hash of the final state.
use pe::{BodyDef, ContactSolver, ConvexPolygon, Vec2, World};
use std::time::Instant;

fn main() {
    let mut args = std::env::args().skip(1);
    let name = args.next().unwrap_or_else(|| "auto".into());
    let Some(solver) = ContactSolver::from_name(&name) else {
        let names: Vec<_> = ContactSolver::ALL.iter().map(|s| s.name()).collect();
        eprintln!("unknown solver {name:?}: one of {}", names.join(", "));
        std::process::exit(2);
    };
    let steps: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(600);
    let tiles: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(2000);
    let mut w = World::new(Vec2::new(0.0, 10.0));
    w.settings.contact_solver = solver;
    let tile = ConvexPolygon::rectangle(1.0, 1.0).unwrap();
    for i in 0..tiles {
        let def = BodyDef::new(tile.clone(), 0.0).at(Vec2::new(i as f64, 0.0), 0.0);
        w.add_body(def).unwrap();
    }
    for i in 0..10 {
        let def = BodyDef::new(tile.clone(), 1.0).at(Vec2::new(3.0 * i as f64, -3.0), 0.0);
        w.add_body(def).unwrap();
    }
    let started = Instant::now();
    for _ in 0..steps {
        w.step(1.0 / 60.0);
    }
    let per_step = started.elapsed().as_secs_f64() / steps as f64;
    let mut hash: u64 = 0;
    for (_, b) in w.bodies() {
        for v in b.state() {
            hash = hash.rotate_left(5) ^ v.to_bits();
        }
    }
    println!(
        "{solver:?}: {tiles} static tiles, 10 boxes, {:.1} µs/step (mean of {steps}); state {hash:016x}",
        per_step * 1e6
    );
}
