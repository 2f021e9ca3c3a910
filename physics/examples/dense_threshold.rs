//! Where does the dense pivoting solve stop paying? Steps stacks and pyramids of growing
//! size with every island solved by pivoting, then by projected Gauss–Seidel, and prints
//! the LCP rows of the island, the median time per step of each, and how still each
//! leaves the pile (the fastest body after settling).
//!
//! `cargo run --release -p pe --example dense_threshold`

use pe::{BodyDef, ContactSolver, ConvexPolygon, Vec2, World};
use std::time::Instant;

const H: f64 = 1.0 / 60.0;

type Layout = dyn Fn(usize) -> Vec<Vec2>;

fn pile(columns_of: &Layout, size: usize, solver: ContactSolver, dense_row_limit: usize) -> World {
    let mut w = World::new(Vec2::new(0.0, 10.0));
    w.settings.contact_solver = solver;
    w.settings.dense_row_limit = dense_row_limit;
    w.friction = 0.6;
    let floor = ConvexPolygon::rectangle(200.0, 1.0).unwrap();
    w.add_body(BodyDef::new(floor, 0.0).at(Vec2::new(0.0, 0.5), 0.0))
        .unwrap();
    let unit = ConvexPolygon::rectangle(1.0, 1.0).unwrap();
    for centre in columns_of(size) {
        w.add_body(
            BodyDef::new(unit.clone(), 1.0)
                .restitution(0.0)
                .at(centre, 0.0),
        )
        .unwrap();
    }
    w
}

fn stack(n: usize) -> Vec<Vec2> {
    (0..n).map(|i| Vec2::new(0.0, -0.5 - i as f64)).collect()
}

fn pyramid(rows: usize) -> Vec<Vec2> {
    let mut v = Vec::new();
    for r in 0..rows {
        for c in 0..rows - r {
            let x = (c as f64 - (rows - r - 1) as f64 / 2.0) * 1.05;
            v.push(Vec2::new(x, -0.5 - r as f64));
        }
    }
    v
}

/// (largest island's rows, median µs per step, fastest body after settling).
fn measure(
    columns_of: &Layout,
    size: usize,
    solver: ContactSolver,
    limit: usize,
) -> (usize, f64, f64) {
    let mut w = pile(columns_of, size, solver, limit);
    for _ in 0..120 {
        w.step(H);
    }
    let rows = w.island_reports().iter().map(|r| r.rows).max().unwrap_or(0);

    let mut times = Vec::new();
    let mut fastest: f64 = 0.0;
    for _ in 0..120 {
        let t = Instant::now();
        w.step(H);
        times.push(t.elapsed().as_secs_f64() * 1e6);
        fastest = w
            .bodies()
            .map(|(_, b)| b.velocity.norm())
            .fold(fastest, f64::max);
    }
    times.sort_by(f64::total_cmp);
    (rows, times[times.len() / 2], fastest)
}

fn main() {
    println!(
        "| pile | rows | µs/step: pivoting | Gauss–Seidel | soft | fastest body: pivoting | Gauss–Seidel | soft |"
    );
    println!("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |");
    let cases: [(&str, &Layout, &[usize]); 2] = [
        ("stack", &stack, &[3, 6, 9, 12, 16, 20, 25, 30]),
        ("pyramid", &pyramid, &[2, 3, 4, 5, 6, 7]),
    ];
    for (name, layout, sizes) in cases {
        for &n in sizes {
            let (rows, dense, dense_still) = measure(layout, n, ContactSolver::Exact, usize::MAX);
            let (_, pgs, pgs_still) = measure(layout, n, ContactSolver::Exact, 0);
            let (_, soft, soft_still) = measure(layout, n, ContactSolver::Soft, 0);
            println!(
                "| {name} {n} | {rows} | {dense:.0} | {pgs:.0} | {soft:.0} | {dense_still:.1e} | {pgs_still:.1e} | {soft_still:.1e} |"
            );
        }
    }
}
