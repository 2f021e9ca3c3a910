//! How often each contact solver lets bodies sink into each other in random throws
//! (`physics/tests/support/random_throws.rs` says what a throw is and how it is judged):
//! the throws past the bound, each with its class, the count by class, and the throws
//! whose energy rose.
//!
//! `cargo run --release -p pe --example throw_survey -- [solver] [worlds] [seed] [substeps]`
//! (defaults: soft, 100, 1, and the soft step's default substeps; solvers by
//! `ContactSolver::name`).

#[path = "../tests/support/random_throws.rs"]
mod random_throws;

use pe::ContactSolver;
use random_throws::{BOUND, Class, Numbers, Throw, run_in_pe};
use std::time::Duration;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let solver = args.first().map_or(Some(ContactSolver::Soft), |name| {
        ContactSolver::from_name(name)
    });
    let Some(solver) = solver else {
        eprintln!("unknown solver {:?}", args[0]);
        std::process::exit(2);
    };
    let worlds: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(100);
    let seed: u64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(1);
    let substeps: Option<usize> = args.get(3).and_then(|s| s.parse().ok());
    let mut numbers = Numbers(seed);
    let mut stepping = Duration::ZERO;
    let mut failed = Vec::new();
    let mut gained = 0;
    for world in 0..worlds {
        let outcome = run_in_pe(
            &Throw::random(&mut numbers),
            solver,
            substeps,
            &mut stepping,
        );
        if outcome.sank() {
            let (a, b) = outcome.masses;
            // A fixed body (a wall, the floor) has no mass here.
            let ratio = if a.min(b) > 0.0 {
                format!("ratio {:.0}", a.max(b) / a.min(b))
            } else {
                "one fixed".to_owned()
            };
            println!(
                "world {world}: {} bodies, {:.2} radii deep at step {}, {:?}, masses {a:.3} and {b:.3} ({ratio})",
                outcome.bodies, outcome.depth, outcome.step, outcome.class,
            );
            failed.push(outcome.class);
        }
        if outcome.gained_energy() {
            println!(
                "world {world}: {} bodies, energy rose {:.3} of Σ m g × the box's height",
                outcome.bodies, outcome.energy_rise
            );
            gained += 1;
        }
    }
    let count = |class| failed.iter().filter(|&&c| c == class).count();
    let substeps = substeps.map_or(String::new(), |n| format!(" ({n} substeps)"));
    println!(
        "{}{substeps}: {} of {worlds} worlds deeper than {BOUND} radii (overlapping from the start {}, in one step {}, gradually {}), {gained} gained energy; {:.1} s stepping",
        solver.name(),
        failed.len(),
        count(Class::OverlappingFromStart),
        count(Class::InOneStep),
        count(Class::Gradually),
        stepping.as_secs_f64(),
    );
}
