//! A terrain of many static tiles under a few falling boxes, for profiling what the step
//! spends on bodies that never move:
//! `cargo run --release -p pe --example terrain_profile -- soft 600 2000`
//! (solver, steps, tiles). Prints the time per step and a hash of the final state.
use pe::{BodyDef, ConvexPolygon, Vec2, World};
use std::time::Instant;

#[path = "support/profile_args.rs"]
mod profile_args;

fn main() {
    let mut args = std::env::args().skip(1);
    let solver = profile_args::solver(&mut args, "auto");
    let steps = profile_args::count(&mut args, 600);
    let tiles = profile_args::count(&mut args, 2000);
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
    let hash = profile_args::state_hash(&w);
    println!(
        "{solver:?}: {tiles} static tiles, 10 boxes, {:.1} µs/step (mean of {steps}); state {hash:016x}",
        per_step * 1e6
    );
}
