//! Chunks of islands solved apart, each through every substep while its batches stay
//! in the cache, before the rest.

use super::super::lanes::LANES;
use super::{ManifoldBatch, PassPlan, PlanInput};

/// From how many bytes of batches a step solves its coloured islands in chunks
/// (`PassPlan::assign_chunks`), and how many bytes of batches a chunk holds at most (an
/// island with more stays with the rest). A chunk is solved through every substep before
/// the next, so its batches are read from the level-2 cache in all but the first pass,
/// where the whole step's would come from the level 3 in every pass
/// (docs/bench/profile.md, "The Zen 1: the big scenes wait on memory").
const CHUNK_FROM_BYTES: usize = 1024 * 1024;
const CHUNK_BYTES: usize = 256 * 1024;

impl PassPlan {
    /// Puts the coloured islands into chunks (`chunk_of_input`, and each chunk's moving
    /// bodies: `chunk_bodies`, `in_chunk`), and returns how many chunks there are.
    ///
    /// Only islands whose batches fit in a chunk (`CHUNK_BYTES`) go into one: a bigger one
    /// would not stay in the cache through its substeps either. And only if those
    /// islands' batches are many (`CHUNK_FROM_BYTES`), or else they stay in the cache
    /// anyway, and only if they make more than one chunk. An island with a pin stays with
    /// the rest, whose pins are solved with their contacts in every substep.
    ///
    /// The islands share no moving body, and each manifold's colour depends only on those
    /// of its island coloured before it, so a chunk solved through all its substeps alone
    /// gives each of its bodies the same operations in the same order as the whole step
    /// solved substep by substep: the same bits.
    pub(super) fn assign_chunks(&mut self, body_count: usize) -> u32 {
        self.chunk_of_input.clear();
        self.chunk_of_input.resize(self.inputs.len(), 0);
        self.chunk_bodies.clear();
        self.chunk_body_starts.clear();
        self.in_chunk.clear();
        let (from_bytes, chunk_bytes) = (CHUNK_FROM_BYTES, CHUNK_BYTES);
        let (from_bytes, chunk_bytes) = self.chunk_limits.unwrap_or((from_bytes, chunk_bytes));
        let inputs = &self.inputs;
        let island_bytes = |&(from, to, _): &(u32, u32, bool)| -> usize {
            let bytes = |m: &PlanInput| match m.count() {
                2 => std::mem::size_of::<ManifoldBatch<2>>() / LANES,
                _ => std::mem::size_of::<ManifoldBatch<1>>() / LANES,
            };
            inputs[from as usize..to as usize].iter().map(bytes).sum()
        };
        self.island_bytes.clear();
        self.island_bytes
            .extend(self.coloured_islands.iter().map(|island| {
                let bytes = island_bytes(island);
                // An island that may not go into a chunk counts as none.
                if island.2 || bytes > chunk_bytes {
                    0
                } else {
                    bytes
                }
            }));
        let total: usize = self.island_bytes.iter().sum();
        if total < from_bytes.max(1) {
            return 0;
        }
        let (mut chunk, mut filled) = (0, 0);
        self.in_chunk.resize(body_count, false);
        let islands = self.coloured_islands.iter().zip(&self.island_bytes);
        for (&(from, to, _), &bytes) in islands.filter(|(_, bytes)| **bytes > 0) {
            if chunk == 0 || filled + bytes > chunk_bytes {
                chunk += 1;
                filled = 0;
                self.chunk_body_starts.push(self.chunk_bodies.len());
            }
            filled += bytes;
            let (from, to) = (from as usize, to as usize);
            self.chunk_of_input[from..to].fill(chunk);
            for m in &self.inputs[from..to] {
                let ends = [(m.a, PlanInput::A_MOVES), (m.b, PlanInput::B_MOVES)];
                for (body, moves) in ends {
                    if m.flags & moves != 0 && !self.in_chunk[body as usize] {
                        self.in_chunk[body as usize] = true;
                        self.chunk_bodies.push(body);
                    }
                }
            }
        }
        self.chunk_body_starts.push(self.chunk_bodies.len());
        if chunk == 1 {
            self.chunk_of_input.fill(0);
            self.chunk_bodies.clear();
            self.chunk_body_starts.clear();
            self.in_chunk.clear();
            return 0;
        }
        chunk
    }

    /// How many chunks the coloured islands are solved in (`assign_chunks`).
    pub(crate) fn chunk_count(&self) -> usize {
        self.chunk_starts.len().saturating_sub(1)
    }

    /// The rest's items: every item but the chunks'.
    pub(crate) fn rest_items(&self) -> std::ops::Range<usize> {
        0..self
            .chunk_starts
            .first()
            .copied()
            .unwrap_or(self.items.len())
    }

    /// The items of chunk `k` (from 0), and its moving bodies.
    pub(crate) fn chunk(&self, k: usize) -> (std::ops::Range<usize>, &[u32]) {
        let bodies = &self.chunk_bodies[self.chunk_body_starts[k]..self.chunk_body_starts[k + 1]];
        (self.chunk_starts[k]..self.chunk_starts[k + 1], bodies)
    }

    /// Whether a chunk moves `body` (then the rest's passes leave it).
    pub(crate) fn in_chunk(&self, body: usize) -> bool {
        self.in_chunk.get(body).copied().unwrap_or(false)
    }
}
