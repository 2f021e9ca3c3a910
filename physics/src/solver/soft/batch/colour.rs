//! Graph colouring of a big island's manifolds (no two in a colour share a moving body),
//! and the colours given in a scattered order.

use super::{PassPlan, PlanInput};
use crate::solver::island::counting_sort;

/// Colours of the constraint graph, as many as a body's `u32` of colour bits holds (a
/// manifold that finds no free colour is solved before the colours, one at a time).
/// More than Box2D v3's 24: fast debris, whose speculative contacts reach many
/// neighbours, needs more than 24 to leave few manifolds uncoloured; piles need fewer
/// than 20 and give the same bits either way.
pub(super) const COLOURS: u32 = 32;

/// Colours 0–27 are open to manifolds between two moving bodies; those against a fixed
/// body take 30 down to 1 (Box2D v3's split, four colours from the top), so 28–30 are
/// theirs alone.
const DYNAMIC_COLOURS: u32 = COLOURS - 4;

/// Islands of fewer contact points than this are solved in the points' order, one
/// manifold at a time: below it, the lanes would stay nearly empty. Unless the small
/// islands together have this many points, since the colours are shared by every island
/// and many small ones fill the lanes together (the smash's debris). From 8 points on,
/// colouring costs no more than the points' order and soon much less, in time
/// (docs/bench/profile.md, "Small islands coloured").
pub(super) const MIN_COLOURED_ISLAND: usize = 8;

/// A manifold of a coloured island, as `plan` sorts them.
#[derive(Debug, Clone, Copy)]
pub(super) struct ColouredManifold {
    /// 2 × colour, + 1 if sideways (`PlanInput::SIDEWAYS`): the sort's key.
    pub(super) key: u32,
    pub(super) first: u32,
    pub(super) count: u32,
    pub(super) bodies: (u32, u32),
}

impl PassPlan {
    /// Colours the coloured manifolds (`colour_of`) in an order scattered over the pile,
    /// into `colour_by_input`.
    ///
    /// Greedy colouring in the points' order (a pile row by row, left to right: each
    /// manifold takes the lowest colour its bodies leave free) colours a pile in one
    /// pattern repeated across it, so the one-sidedness of a Gauss–Seidel sweep over the
    /// colours adds up over the pile instead of averaging out, and the pile sways. Coloured
    /// in the order of a hash of their bodies (one counting sort on 8 bits of it: buckets
    /// scattered over the pile, each in the points' order), the colours fall anywhere, the
    /// one-sidedness averages out, and the pile sways less than Box2D v3's, with about as
    /// many colours, and so batches (docs/bench/profile.md, "Colouring in a scattered
    /// order").
    pub(super) fn colour_in_scattered_order(&mut self) {
        const HASH_BITS: u32 = 8;
        let inputs = &self.inputs;
        self.colouring.clear();
        self.colouring.extend(
            (0..inputs.len() as u32)
                .filter(|&k| inputs[k as usize].flags & PlanInput::COLOURED != 0),
        );
        // Multiplicative hashing of the body pair (the golden ratio's and xxHash's odd
        // constants); its top bits pick the bucket.
        let bucket = |&k: &u32| {
            let m = inputs[k as usize];
            let h = (m.a.wrapping_mul(0x9E37_79B1) ^ m.b.wrapping_mul(0x85EB_CA77))
                .wrapping_mul(0xC2B2_AE3D);
            (h >> (32 - HASH_BITS)) as usize
        };
        counting_sort(
            &self.colouring,
            1 << HASH_BITS,
            bucket,
            &mut self.colouring_starts,
            &mut self.colouring_scratch,
        );
        std::mem::swap(&mut self.colouring, &mut self.colouring_scratch);
        self.colour_by_input.clear();
        self.colour_by_input.resize(self.inputs.len(), 0);
        for i in 0..self.colouring.len() {
            let k = self.colouring[i] as usize;
            self.colour_by_input[k] = self.colour_of(self.inputs[k]);
        }
    }

    /// A manifold's colour, counted from 1 (0: none free, solved first), marking it taken
    /// for its moving bodies.
    fn colour_of(&mut self, input: PlanInput) -> u32 {
        let (a, b) = (input.a as usize, input.b as usize);
        let (a_moves, b_moves) = (
            input.flags & PlanInput::A_MOVES != 0,
            input.flags & PlanInput::B_MOVES != 0,
        );
        let free = match (a_moves, b_moves) {
            (true, true) => {
                let c = (self.colours_of[a] | self.colours_of[b]).trailing_ones();
                (c < DYNAMIC_COLOURS).then_some(c)
            }
            (true, false) => Self::last_free(self.colours_of[a]),
            (false, true) => Self::last_free(self.colours_of[b]),
            (false, false) => None,
        };
        let Some(c) = free else { return 0 };
        for (body, is_moving) in [(a, a_moves), (b, b_moves)] {
            if is_moving {
                self.colours_of[body] |= 1 << c;
            }
        }
        c + 1
    }

    /// The last free colour for a manifold against a fixed body (colour 0 excepted, as
    /// in Box2D v3).
    fn last_free(used: u32) -> Option<u32> {
        (1..COLOURS - 1).rev().find(|&c| used & (1 << c) == 0)
    }
}
