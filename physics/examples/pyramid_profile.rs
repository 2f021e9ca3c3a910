//! A 20-row pyramid (210 unit boxes) under a chosen solver for profiling:
//! `cargo run --release -p pe --example pyramid_profile -- soft 600 [rows] [fresh]`;
//! `fresh` runs the separating-axis test on every pair every step (no manifold reuse).
use pe::{BodyDef, ConvexPolygon, Vec2, World};
use std::time::Instant;

#[path = "support/profile_args.rs"]
mod profile_args;

fn main() {
    let mut args = std::env::args().skip(1);
    let solver = profile_args::solver(&mut args, "soft");
    let steps = profile_args::count(&mut args, 600);
    let rows = profile_args::count(&mut args, 20);
    let fresh = args.next().as_deref() == Some("fresh");
    let mut w = World::new(Vec2::new(0.0, 10.0));
    w.settings.contact_solver = solver;
    w.settings.reuse_manifolds = !fresh;
    w.friction = 0.6;
    let floor = ConvexPolygon::rectangle(100.0, 1.0).unwrap();
    w.add_body(BodyDef::new(floor, 0.0).at(Vec2::new(0.0, 0.5), 0.0))
        .unwrap();
    let unit = ConvexPolygon::rectangle(1.0, 1.0).unwrap();
    let mut top = None;
    for row in 0..rows {
        for i in 0..rows - row {
            let x = i as f64 - 0.5 * (rows - 1 - row) as f64;
            let at = Vec2::new(x, -0.5 - row as f64);
            top = Some((
                w.add_body(BodyDef::new(unit.clone(), 1.0).at(at, 0.0))
                    .unwrap(),
                at,
            ));
        }
    }
    let (top, top_start) = top.expect("at least one row");
    let started = Instant::now();
    for _ in 0..steps {
        w.step(1.0 / 60.0);
    }
    let per_step = started.elapsed().as_secs_f64() / steps as f64;
    // How far the top box moved: sideways (drift) and down (sag), in box widths.
    let moved = w.body(top).unwrap().position - top_start;
    println!(
        "{solver:?}: {rows} rows, {:.1} µs/step (mean of {steps}){}; top box drift {:.4}, sag {:.4}",
        per_step * 1e6,
        if fresh { ", no manifold reuse" } else { "" },
        moved.x,
        moved.y
    );
}
