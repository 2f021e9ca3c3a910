//! The profiling examples' worlds, built in one place so that the golden test
//! (`physics/tests/golden.rs`) holds the same worlds' bits as the examples time.
#![allow(dead_code)] // each example builds one of them
use pe::{BodyDef, BodyHandle, ContactSolver, ConvexPolygon, JointDef, JointHandle, Vec2, World};

/// A pyramid of `rows` rows of unit boxes on a 100 × 1 floor, gravity 10, μ = 0.6: the
/// world, the top box and where it starts.
pub fn pyramid(solver: ContactSolver, rows: usize) -> (World, BodyHandle, Vec2) {
    let mut w = World::new(Vec2::new(0.0, 10.0));
    w.settings.contact_solver = solver;
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
            let body = w.add_body(BodyDef::new(unit.clone(), 1.0).at(at, 0.0));
            top = Some((body.unwrap(), at));
        }
    }
    let (top, top_start) = top.expect("at least one row");
    (w, top, top_start)
}

/// The benchmark's heavy chain: `links` light 1 × 0.1 links (density 2) from a pin to the
/// static world, holding a 1 m box of density 100 (500 times a link's mass), released
/// level under gravity 10: the world and its pins.
pub fn heavy_chain(solver: ContactSolver, links: usize) -> (World, Vec<JointHandle>) {
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
    (w, pins)
}

/// A row of `tiles` static unit tiles under ten unit boxes dropped from 3 m apart,
/// gravity 10: what the step spends on bodies that never move.
pub fn terrain(solver: ContactSolver, tiles: usize) -> World {
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
    w
}
