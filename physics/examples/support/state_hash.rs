//! A hash of every body's state, bit for bit (FNV-1a over the bits of each body's
//! position, angle and velocities, in slot order): two worlds hash alike only if every
//! body's state is the same to the bit. The examples print it; the golden tests fold it
//! over every step of a run.
use pe::World;
use std::hash::Hasher;

/// Folds `world`'s bodies' state into `hasher`.
pub fn fold_state(hasher: &mut fnv::FnvHasher, world: &World) {
    for (handle, body) in world.bodies() {
        hasher.write_u32(handle.0);
        for v in body.state() {
            hasher.write_u64(v.to_bits());
        }
    }
}

/// The hash of `world`'s bodies' state alone.
#[allow(dead_code)] // the golden tests fold every step instead
pub fn state_hash(world: &World) -> u64 {
    let mut hasher = fnv::FnvHasher::default();
    fold_state(&mut hasher, world);
    hasher.finish()
}
