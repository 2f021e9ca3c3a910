//! The profiling examples' arguments.
use pe::ContactSolver;

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
