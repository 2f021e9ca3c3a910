//! The benchmark's heavy chain (light 1 × 0.1 links holding a 1 m box 500 times heavier
//! than each, released level) under a chosen solver, for profiling:
//! `cargo run --release -p pe --example chain_profile -- exact 600 [links]`.
//! Prints the time per step, the widest any pin opened, and a hash of the final state
//! (to check that a change leaves the trajectory bit for bit).
use pe::{BodyDef, ConvexPolygon, JointDef, Vec2, World};
use std::time::Instant;

#[path = "support/profile_args.rs"]
mod profile_args;

fn main() {
    let mut args = std::env::args().skip(1);
    let solver = profile_args::solver(&mut args, "exact");
    let steps = profile_args::count(&mut args, 600);
    let links = profile_args::count(&mut args, 10);
    let mut w = World::new(Vec2::new(0.0, 10.0));
    w.settings.contact_solver = solver;
    let link = ConvexPolygon::rectangle(1.0, 0.1).unwrap();
    let end = ConvexPolygon::rectangle(1.0, 1.0).unwrap();
    let mut previous = None;
    let mut pins = Vec::new();
    for i in 0..=links {
        let def = if i < links {
            BodyDef::new(link.clone(), 2.0).at(Vec2::new(i as f64 + 0.5, 0.0), 0.0)
        } else {
            BodyDef::new(end.clone(), 100.0).at(Vec2::new(links as f64 + 0.5, 0.0), 0.0)
        };
        let body = w.add_body(def).unwrap();
        let pin = JointDef::new(body, previous, Vec2::new(i as f64, 0.0));
        pins.push(w.add_joint(pin).unwrap());
        previous = Some(body);
    }
    let started = Instant::now();
    let mut widest: f64 = 0.0;
    for _ in 0..steps {
        w.step(1.0 / 60.0);
        for &pin in &pins {
            widest = widest.max(w.joint_gap(pin).unwrap());
        }
    }
    let per_step = started.elapsed().as_secs_f64() / steps as f64;
    let hash = profile_args::state_hash(&w);
    println!(
        "{solver:?}: {links} links, {:.1} µs/step (mean of {steps}); widest pin gap {widest:.2e}; state {hash:016x}",
        per_step * 1e6
    );
}
