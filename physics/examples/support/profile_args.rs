//! What the profiling examples share: their arguments and a hash of the final state.
use pe::{ContactSolver, World};

/// The next argument as a contact solver (`default` if there is none); an unknown name
/// ends the program with the list of known ones.
pub fn solver(args: &mut impl Iterator<Item = String>, default: &str) -> ContactSolver {
    let name = args.next().unwrap_or_else(|| default.into());
    ContactSolver::from_name(&name).unwrap_or_else(|| {
        let names: Vec<_> = ContactSolver::ALL.iter().map(|s| s.name()).collect();
        eprintln!("unknown solver {name:?}: one of {}", names.join(", "));
        std::process::exit(2);
    })
}

/// The next argument as a count (`default` if there is none or it is not a number).
pub fn count(args: &mut impl Iterator<Item = String>, default: usize) -> usize {
    args.next().and_then(|s| s.parse().ok()).unwrap_or(default)
}

/// Every body's state folded bit for bit: two runs print the same hash only if they
/// ended in the same state.
#[allow(dead_code)] // not every example prints it
pub fn state_hash(world: &World) -> u64 {
    let mut hash: u64 = 0;
    for (_, b) in world.bodies() {
        for v in b.state() {
            hash = hash.rotate_left(5) ^ v.to_bits();
        }
    }
    hash
}
