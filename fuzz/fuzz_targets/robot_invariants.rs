//! The physics-invariant fuzzer: a random robot (`physics/tests/support/random_robots.rs`)
//! drawn from the input's bytes, under every solver, judged by the invariants every solver
//! promises there (energy, momentum, a body reported moving moves, rest stays rest, pins
//! closed under the default path). A broken invariant panics with what broke; its input,
//! as a seed for the property test, goes into `physics/tests/invariants.rs`.

#![no_main]

#[path = "../../physics/tests/support/random_robots.rs"]
mod random_robots;

use libfuzzer_sys::fuzz_target;
use pe::ContactSolver;
use random_robots::{Draw, judge, random_robot};

fuzz_target!(|data: &[u8]| {
    for solver in ContactSolver::ALL {
        // Eight bytes a word, zeros once the input runs out.
        let mut words = data.chunks(8).map(|c| {
            let mut word = [0u8; 8];
            word[..c.len()].copy_from_slice(c);
            u64::from_le_bytes(word)
        });
        let mut next = || words.next().unwrap_or(0);
        let mut trial = random_robot(&mut Draw(&mut next), solver);
        if let Err(e) = judge(&mut trial) {
            panic!(
                "{solver:?}: {:?} {:?}, gravity {}, mass ratio {:.0}: {e}",
                trial.topology, trial.placing, trial.gravity, trial.mass_ratio
            );
        }
    }
});
