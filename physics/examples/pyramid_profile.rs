//! A 20-row pyramid (210 unit boxes) under a chosen solver for profiling:
//! `cargo run --release -p pe --example pyramid_profile -- soft 600 [rows] [fresh]`;
//! `fresh` runs the separating-axis test on every pair every step (no manifold reuse).
use std::time::Instant;

#[path = "support/profile_args.rs"]
mod profile_args;
#[path = "support/state_hash.rs"]
mod state_hash;
#[path = "support/worlds.rs"]
mod worlds;

fn main() {
    let mut args = std::env::args().skip(1);
    let solver = profile_args::solver(&mut args, "soft");
    let steps = profile_args::count(&mut args, 600);
    let rows = profile_args::count(&mut args, 20);
    let fresh = args.next().as_deref() == Some("fresh");
    let (mut w, top, top_start) = worlds::pyramid(solver, rows);
    w.settings.reuse_manifolds = !fresh;
    let started = Instant::now();
    for _ in 0..steps {
        w.step(1.0 / 60.0);
    }
    let per_step = started.elapsed().as_secs_f64() / steps as f64;
    // How far the top box moved: sideways (drift) and down (sag), in box widths.
    let moved = w.body(top).unwrap().position - top_start;
    println!(
        "{solver:?}: {rows} rows, {:.1} µs/step (mean of {steps}){}; top box drift {:.4}, sag {:.4}; state {:016x}",
        per_step * 1e6,
        if fresh { ", no manifold reuse" } else { "" },
        moved.x,
        moved.y,
        state_hash::state_hash(&w)
    );
}
