//! The physics-invariant fuzzer, seeded, in `cargo test`: random robots (chains, trees,
//! closed loops, hubs; mass ratios up to 1e4; motors or not; pinned bodies overlapping or
//! not; in free space, on a floor or partly in it) under every solver, judged by the
//! invariants of `support/random_robots.rs`. The same worlds and judge run unseeded under
//! cargo-fuzz (`fuzz/fuzz_targets/robot_invariants.rs`). A counterexample either finds
//! becomes a case of `found_counterexamples_stay_fixed`.

#[path = "support/random_robots.rs"]
mod random_robots;

use pe::ContactSolver;
use proptest::prelude::*;
use random_robots::{Draw, SplitMix, judge, random_robot};

/// The robot drawn from `seed` under `solver`, judged.
fn check(seed: u64, solver: ContactSolver) -> Result<(), String> {
    let mut numbers = SplitMix(seed);
    let mut next = || numbers.next();
    let mut trial = random_robot(&mut Draw(&mut next), solver);
    let what = format!(
        "seed {seed}, {solver:?}: {:?} {:?}, gravity {}, {} joint motors, {} body motors, mass ratio {:.0}",
        trial.topology,
        trial.placing,
        trial.gravity,
        trial.joint_motors,
        trial.body_motors,
        trial.mass_ratio
    );
    judge(&mut trial).map_err(|e| format!("{what}: {e}"))
}

/// The same robots under one solver.
fn every_robot_keeps_the_invariants(solver: ContactSolver) {
    let config = ProptestConfig {
        // A fixed seed: the same robots on every run, so that CI is deterministic.
        cases: 40,
        rng_seed: proptest::test_runner::RngSeed::Fixed(61),
        max_shrink_iters: 0,
        failure_persistence: None,
        ..ProptestConfig::default()
    };
    proptest::test_runner::TestRunner::new(config)
        .run(&any::<u64>(), |seed| {
            check(seed, solver).map_err(proptest::test_runner::TestCaseError::fail)
        })
        .unwrap();
}

#[test]
fn auto_keeps_the_invariants_on_random_robots() {
    every_robot_keeps_the_invariants(ContactSolver::Auto);
}

#[test]
fn exact_keeps_the_invariants_on_random_robots() {
    every_robot_keeps_the_invariants(ContactSolver::Exact);
}

#[test]
fn soft_keeps_the_invariants_on_random_robots() {
    every_robot_keeps_the_invariants(ContactSolver::Soft);
}

#[test]
fn thesis_keeps_the_invariants_on_random_robots() {
    every_robot_keeps_the_invariants(ContactSolver::Thesis);
}

#[test]
fn sequential_keeps_the_invariants_on_random_robots() {
    every_robot_keeps_the_invariants(ContactSolver::Sequential);
}

/// Robots the fuzzer once broke, by seed: each stays fixed.
#[test]
fn found_counterexamples_stay_fixed() {
    const FOUND: &[u64] = &[];
    for &seed in FOUND {
        for solver in ContactSolver::ALL {
            check(seed, solver).unwrap();
        }
    }
}
