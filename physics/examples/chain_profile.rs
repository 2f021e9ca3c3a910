//! The benchmark's heavy chain (light 1 × 0.1 links holding a 1 m box 500 times heavier
//! than each, released level) under a chosen solver, for profiling:
//! `cargo run --release -p pe --example chain_profile -- exact 600 [links]`.
//! Prints the time per step, the widest any pin opened, and a hash of the final state
//! (to check that a change leaves the trajectory bit for bit).
use std::time::Instant;

#[path = "support/profile_args.rs"]
mod profile_args;
#[path = "support/state_hash.rs"]
mod state_hash;
#[path = "support/worlds.rs"]
mod worlds;

fn main() {
    let mut args = std::env::args().skip(1);
    let solver = profile_args::solver(&mut args, "exact");
    let steps = profile_args::count(&mut args, 600);
    let links = profile_args::count(&mut args, 10);
    let (mut w, pins) = worlds::heavy_chain(solver, links);
    let started = Instant::now();
    let mut widest: f64 = 0.0;
    for _ in 0..steps {
        w.step(1.0 / 60.0);
        for &pin in &pins {
            widest = widest.max(w.joint_gap(pin).unwrap());
        }
    }
    let per_step = started.elapsed().as_secs_f64() / steps as f64;
    let hash = state_hash::state_hash(&w);
    println!(
        "{solver:?}: {links} links, {:.1} µs/step (mean of {steps}); widest pin gap {widest:.2e}; state {hash:016x}",
        per_step * 1e6
    );
}
