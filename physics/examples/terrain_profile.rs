//! A terrain of many static tiles under a few falling boxes, for profiling what the step
//! spends on bodies that never move:
//! `cargo run --release -p pe --example terrain_profile -- soft 600 2000`
//! (solver, steps, tiles). Prints the time per step and a hash of the final state.
use std::time::Instant;

#[path = "support/profile_args.rs"]
mod profile_args;
#[path = "support/state_hash.rs"]
mod state_hash;
#[path = "support/worlds.rs"]
mod worlds;

fn main() {
    let mut args = std::env::args().skip(1);
    let solver = profile_args::solver(&mut args, "auto");
    let steps = profile_args::count(&mut args, 600);
    let tiles = profile_args::count(&mut args, 2000);
    let mut w = worlds::terrain(solver, tiles);
    let started = Instant::now();
    for _ in 0..steps {
        w.step(1.0 / 60.0);
    }
    let per_step = started.elapsed().as_secs_f64() / steps as f64;
    let hash = state_hash::state_hash(&w);
    println!(
        "{solver:?}: {tiles} static tiles, 10 boxes, {:.1} µs/step (mean of {steps}); state {hash:016x}",
        per_step * 1e6
    );
}
