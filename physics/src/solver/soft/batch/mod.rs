//! The passes' order over a step's manifolds, and eight manifolds solved side by side,
//! one per SIMD lane, as Box2D v3 does (in f32; here in f64).
//!
//! Manifolds of a big island are grouped by colours of the constraint graph (no two in a
//! colour share a moving body), as Box2D v3 assigns them: manifolds between two moving
//! bodies from the first colour up, those against a fixed body from the last colour down,
//! so that contacts with the ground have the last word in every pass: a pile's weight
//! reaches the ground in the pass it is pushed down, and tall piles stand. Within a
//! colour, eight
//! coupled two-point manifolds at a time are one `ManifoldBatch<2>`, and eight one-point
//! ones a `ManifoldBatch<1>`, solved with the same arithmetic as `solve_pair` and
//! `solve_point`, lane by lane, so a batch gives the same bits as its eight manifolds
//! solved one after another, whichever lanes the processor has. Small islands keep the
//! points' order, one manifold at a time.
//!
//! The colours are given in a scattered order (`PassPlan::colour_in_scattered_order`), so
//! that no one pattern repeats across a pile and sways it; with the sweeps alternating
//! (`SweepOrder`) a tall pyramid's top stays put (docs/bench/profile.md).
//!
//! This module holds the plan (`PassPlan`) and the batches' layout (`ManifoldBatch`); the
//! colouring, the chunks, the batches asked for ahead, the batch pools, the filling, the
//! SIMD dispatch and the lanes' arithmetic are each in the module named for it.

#[cfg(target_arch = "x86_64")]
use super::avx2::BothHalves;
#[cfg(target_arch = "x86_64")]
use super::avx512::F64x8Avx512;
use super::bodies::SoftBody;
use super::constraints::PointConstraint;
use super::lanes::{F64x8, LANES};
use crate::math::Vec2;
use crate::solver::island::counting_sort;

mod ahead;
mod chunks;
mod colour;
mod dispatch;
mod fill;
mod pool;
mod solve;

pub(super) use ahead::AskedFor;
use ahead::{PREFETCH_AHEAD, prefetch};
use colour::{COLOURS, ColouredManifold, MIN_COLOURED_ISLAND};
pub(super) use dispatch::{BatchLanes, LaneBatch, LanePath};
use pool::BatchPool;
pub(super) use solve::{LaneVelocity, PassSettings};

/// One step of the passes' work, in order: a batch of eight two-point manifolds, a batch
/// of eight one-point ones, or one manifold (`(first point, point count)`) solved alone.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum PassItem {
    Batch(u32),
    PointBatch(u32),
    Manifold(u32, u32),
}

/// The passes' work for one step, and the buffers that plan it, kept between steps.
#[derive(Debug, Clone, Default)]
pub(super) struct PassPlan {
    pub items: Vec<PassItem>,
    /// Where the coloured islands' items start in `items` (the small islands' come
    /// first, in the points' order).
    pub coloured_from: usize,
    /// Where the chunks' items start in `items`, each chunk's after the last's (the items
    /// before the first are the rest's), and where the last chunk's end (`assign_chunks`):
    /// one entry, `items.len()`, if there are no chunks.
    chunk_starts: Vec<usize>,
    /// The moving bodies of each chunk, chunk after chunk, and where each chunk's start
    /// (with the end of the last).
    chunk_bodies: Vec<u32>,
    chunk_body_starts: Vec<usize>,
    /// By body, whether a chunk moves it (and so the rest's passes do not).
    in_chunk: Vec<bool>,
    /// The coloured islands (their ranges of `inputs`, and whether any of their bodies
    /// carries a pin, which keeps the island out of the chunks), this step's and those
    /// the last plan was made for.
    coloured_islands: Vec<(u32, u32, bool)>,
    last_coloured_islands: Vec<(u32, u32, bool)>,
    /// Each input's chunk, counted from 1 (0: solved with the rest).
    chunk_of_input: Vec<u32>,
    /// Each coloured island's bytes of batches, 0 if it goes into no chunk.
    island_bytes: Vec<usize>,
    /// A crate-private check, off in use: other bounds than `CHUNK_FROM_BYTES` and
    /// `CHUNK_BYTES`, so that a test can show chunking gives the same bits.
    pub chunk_limits: Option<(usize, usize)>,
    /// Batches of two-point and of one-point manifolds.
    pairs: BatchPool<2>,
    singles: BatchPool<1>,
    /// Per body, a bit for each colour it already has a manifold in.
    colours_of: Vec<u32>,
    /// The coloured manifolds, by `ColouredManifold::key`.
    coloured: Vec<ColouredManifold>,
    /// The counting sort of `coloured` by colour: its output, and where each colour
    /// starts in it.
    by_colour: Vec<ColouredManifold>,
    colour_starts: Vec<u32>,
    /// The coloured manifolds (indices into `inputs`) in the order they are coloured
    /// (`colour_in_scattered_order`), its counting sort's scratch and buckets, and each
    /// manifold's colour by its index in `inputs`.
    colouring: Vec<u32>,
    colouring_scratch: Vec<u32>,
    colouring_starts: Vec<u32>,
    colour_by_input: Vec<u32>,
    /// What the last plan was made from, one entry a manifold (`PlanInput`): while it
    /// is unchanged, so is the plan, and only the batches' numbers are read again.
    inputs: Vec<PlanInput>,
    last_inputs: Vec<PlanInput>,
    /// Where the plan put each manifold, by its first point (`Slot`; `NO_SLOT` for the
    /// manifolds solved alone): while the plan is kept, a manifold's lanes are written
    /// as its points are built (`fill_manifold`), with the points still in the cache.
    slot_of: Vec<u32>,
    /// Whether this step's manifolds were written into the kept plan's lanes as they
    /// were built (`begin_filling`), so that `plan` need not fill the batches again.
    filled_while_built: bool,
    /// Whether the last step kept the plan before it (from `read` on, whether this step
    /// keeps it). One that changed will most likely change again (debris in flight: every
    /// step of the smash), and its lanes are then filled once the new plan is made rather
    /// than also while the points are built.
    kept_last_step: bool,
}

/// No batch lane: the manifold is solved alone, or in an LCP island.
const NO_SLOT: u32 = u32::MAX;

/// A manifold's place in the plan: its pool (two-point or one-point batches), batch and
/// lane, packed in a `u32` as `pool << 31 | batch << 3 | lane`.
struct Slot;

impl Slot {
    fn pack(two_points: bool, batch: usize, lane: usize) -> u32 {
        (u32::from(two_points) << 31) | ((batch as u32) << 3) | lane as u32
    }

    /// (two-point pool, batch, lane).
    fn unpack(slot: u32) -> (bool, usize, usize) {
        (
            slot >> 31 == 1,
            ((slot & !(1 << 31)) >> 3) as usize,
            (slot & 7) as usize,
        )
    }
}

const _: () = assert!(LANES == 8, "`Slot` packs the lane in three bits");

/// What planning reads of one manifold: its bodies, first point, and `PlanInput::flags`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct PlanInput {
    a: u32,
    b: u32,
    first: u32,
    flags: u32,
}

impl PlanInput {
    const TWO_POINTS: u32 = 1;
    const COLOURED: u32 = 2;
    const A_MOVES: u32 = 4;
    const B_MOVES: u32 = 8;
    /// The normal lies nearer the x axis than the y axis (batched apart, see `plan`).
    const SIDEWAYS: u32 = 16;

    /// A one-point manifold (so far) between `a` and `b`, whose point is `first`.
    pub(crate) fn new(
        (a, b): (u32, u32),
        first: usize,
        (a_moves, b_moves): (bool, bool),
        normal: Vec2,
    ) -> Self {
        let flag = |on: bool, flag: u32| if on { flag } else { 0 };
        Self {
            a,
            b,
            first: first as u32,
            flags: flag(a_moves, Self::A_MOVES)
                | flag(b_moves, Self::B_MOVES)
                | flag(normal.x.abs() > normal.y.abs(), Self::SIDEWAYS),
        }
    }

    /// The manifold's next point is coupled with its first: a two-point manifold.
    pub(crate) fn add_second_point(&mut self) {
        self.flags |= Self::TWO_POINTS;
    }

    /// Tests only: the manifold's first point and its count of points.
    #[cfg(test)]
    pub(crate) fn first_and_count(self) -> (u32, u32) {
        (self.first, self.count())
    }

    fn count(self) -> u32 {
        if self.flags & Self::TWO_POINTS != 0 {
            2
        } else {
            1
        }
    }
}

impl PassPlan {
    /// Reads this step's manifolds, `manifolds` in the points' order, grouped by `islands`
    /// (index ranges of the points, and whether the island is solved as one LCP: those
    /// are left out). Whether they are the last plan's: then `plan` keeps it.
    /// `pinned` says, by body, whether a pin joins it (bodies past its end carry none).
    pub(crate) fn read(
        &mut self,
        islands: &[(usize, usize, bool)],
        manifolds: &[PlanInput],
        pinned: &[bool],
    ) -> bool {
        self.read_inputs(islands, manifolds, pinned);
        self.kept_last_step =
            self.inputs == self.last_inputs && self.coloured_islands == self.last_coloured_islands;
        self.kept_last_step
    }

    /// Plans the passes over `points`, for the manifolds last `read`.
    pub(crate) fn plan(&mut self, points: &[PointConstraint], bodies: &[SoftBody]) {
        let filled_while_built = std::mem::take(&mut self.filled_while_built);
        if self.kept_last_step {
            // A pile at rest: the same manifolds between the same bodies.
            if !filled_while_built {
                for batch in self.pairs.filled_mut() {
                    batch.fill(batch.first_point, Some(points), bodies);
                }
                for batch in self.singles.filled_mut() {
                    batch.fill(batch.first_point, Some(points), bodies);
                }
            }
            return;
        }
        self.make(Some(points), points.len(), bodies);
    }

    /// Plans the passes for the manifolds last `read` before their points are built, from
    /// their entries alone: each manifold then goes into its lane, in the kept plan or in
    /// a new one, as its points are built (`fill_manifold`). The entries read must be
    /// those the points will make (`SoftStepSolver::plan_from_contacts` finds them).
    pub(crate) fn plan_before_points(&mut self, point_count: usize, bodies: &[SoftBody]) {
        if !self.kept_last_step {
            self.make(None, point_count, bodies);
        }
        self.filled_while_built = true;
    }

    /// Whether the last step kept the plan before it (until this step's `read`).
    pub(crate) fn kept_last_step(&self) -> bool {
        self.kept_last_step
    }

    /// A new plan for the manifolds last `read` (of `point_count` points): their colours,
    /// batches and `items`, and their lanes filled from `points` (or, without, left to
    /// `fill_manifold`).
    fn make(
        &mut self,
        points: Option<&[PointConstraint]>,
        point_count: usize,
        bodies: &[SoftBody],
    ) {
        self.items.clear();
        self.pairs.clear();
        self.singles.clear();
        self.coloured.clear();
        self.colours_of.clear();
        self.colours_of.resize(bodies.len(), 0);
        self.colour_in_scattered_order();
        let chunks = self.assign_chunks(bodies.len());
        for k in 0..self.inputs.len() {
            let input = self.inputs[k];
            if input.flags & PlanInput::COLOURED != 0 {
                // The sort key below: the chunk, the colour, then sideways after upright.
                let sideways = u32::from(input.flags & PlanInput::SIDEWAYS != 0);
                let class = self.chunk_of_input[k] * COLOURS + self.colour_by_input[k];
                let key = 2 * class + sideways;
                self.coloured.push(ColouredManifold {
                    key,
                    first: input.first,
                    count: input.count(),
                    bodies: (input.a, input.b),
                });
            } else {
                self.items
                    .push(PassItem::Manifold(input.first, input.count()));
            }
        }
        self.coloured_from = self.items.len();
        // Grouped by colour (a counting sort: the colours are few, a big pile's manifolds
        // many), and in each colour the manifolds whose normal lies nearer the y axis
        // before those nearer the x axis (`PlanInput::SIDEWAYS`), each in the points'
        // order. The order within a colour changes no result; grouping by orientation
        // keeps a pile's supports and its side contacts in batches of their own, so that
        // fewer batches hold a manifold whose two points part (one touching, one not),
        // which takes the slower path (`solve_normals_together`) (docs/bench/profile.md).
        let key = |m: &ColouredManifold| m.key as usize;
        // Colours 0..COLOURS (`colour_of`), two ways, in each of the rest and the chunks.
        let keys = 2 * COLOURS as usize * (chunks as usize + 1);
        counting_sort(
            &self.coloured,
            keys,
            key,
            &mut self.colour_starts,
            &mut self.by_colour,
        );
        std::mem::swap(&mut self.coloured, &mut self.by_colour);
        // Two-point and one-point manifolds fill their own batches, colour by colour.
        let pad_from = LanePath::best().fewest_padded();
        let mut i = 0;
        // The chunk and the colour.
        let class_at = |coloured: &[ColouredManifold], i: usize| coloured[i].key / 2;
        self.chunk_starts.clear();
        while i < self.coloured.len() {
            let class = class_at(&self.coloured, i);
            let (chunk, colour) = (class / COLOURS, class % COLOURS);
            while self.chunk_starts.len() < chunk as usize {
                self.chunk_starts.push(self.items.len());
            }
            while i < self.coloured.len() && class_at(&self.coloured, i) == class {
                let ColouredManifold { first, count, .. } = self.coloured[i];
                // Filling reads the points in colour order, scattered over the step's
                // points (megabytes of them in a big scene): they are asked for ahead.
                let ahead = self.coloured.get(i + PREFETCH_AHEAD);
                if let (Some(ahead), Some(points)) = (ahead, points) {
                    prefetch(&points[ahead.first as usize..][..ahead.count as usize]);
                    prefetch(std::slice::from_ref(&bodies[ahead.bodies.0 as usize]));
                    prefetch(std::slice::from_ref(&bodies[ahead.bodies.1 as usize]));
                }
                i += 1;
                let items = &mut self.items;
                match (colour, count) {
                    (0, _) => items.push(PassItem::Manifold(first, count)),
                    (_, 2) => self.pairs.take(first, (points, bodies), items),
                    _ => self.singles.take(first, (points, bodies), items),
                }
            }
            self.pairs
                .end_colour((points, bodies), &mut self.items, pad_from);
            self.singles
                .end_colour((points, bodies), &mut self.items, pad_from);
        }
        while self.chunk_starts.len() <= chunks as usize {
            self.chunk_starts.push(self.items.len());
        }
        std::mem::swap(&mut self.inputs, &mut self.last_inputs);
        std::mem::swap(&mut self.coloured_islands, &mut self.last_coloured_islands);
        self.slot_of.clear();
        self.slot_of.resize(point_count, NO_SLOT);
        let pairs = self.pairs.filled().iter().map(|b| (true, &b.first_point));
        let singles = self
            .singles
            .filled()
            .iter()
            .map(|b| (false, &b.first_point));
        let mut batch_index = [0, 0];
        for (two_points, firsts) in pairs.chain(singles) {
            let batch = &mut batch_index[usize::from(two_points)];
            for (lane, &first) in firsts.iter().enumerate().filter(|f| *f.1 != PAD) {
                self.slot_of[first as usize] = Slot::pack(two_points, *batch, lane);
            }
            *batch += 1;
        }
    }

    /// Starts a step whose manifolds are then written into the kept plan's lanes as they
    /// are built (`fill_manifold`), if the last step kept its plan. If the plan turns out
    /// to change, `plan` makes and fills the new one as usual; if it is kept after a
    /// change, `plan` fills it from the points.
    pub(crate) fn begin_filling(&mut self) {
        self.filled_while_built = self.kept_last_step;
    }

    /// Fills no more lanes while the points are built: `plan` fills them (the points
    /// are being built again, all written, for a plan that changed after all).
    pub(crate) fn stop_filling(&mut self) {
        self.filled_while_built = false;
    }

    /// The manifold of points `manifold` whose first point is `first`, just built, into
    /// the lane the kept plan has for it, if any and of its size: whether it went into one.
    #[inline(always)]
    pub(crate) fn fill_manifold<const N: usize>(
        &mut self,
        first: usize,
        manifold: &[PointConstraint; N],
        bodies: &[SoftBody],
    ) -> bool {
        if !self.filled_while_built {
            return false;
        }
        let Some(&slot) = self.slot_of.get(first).filter(|&&s| s != NO_SLOT) else {
            return false;
        };
        let (two_points, batch, lane) = Slot::unpack(slot);
        match (two_points, N) {
            (true, 2) => self.pairs.batches[batch].fill_lane(lane, first as u32, manifold, bodies),
            (false, 1) => {
                self.singles.batches[batch].fill_lane(lane, first as u32, manifold, bodies)
            }
            _ => return false, // the plan changes this step
        }
        true
    }

    /// The manifolds outside the LCP islands, each marked if its island is coloured,
    /// into `inputs`.
    fn read_inputs(
        &mut self,
        islands: &[(usize, usize, bool)],
        manifolds: &[PlanInput],
        pinned: &[bool],
    ) {
        self.inputs.clear();
        self.coloured_islands.clear();
        let no_pins = pinned.is_empty();
        let pinned = |body: u32| pinned.get(body as usize).copied().unwrap_or(false);
        let small_points: usize = islands
            .iter()
            .filter(|&&(start, end, lcp)| !lcp && end - start < MIN_COLOURED_ISLAND)
            .map(|&(start, end, _)| end - start)
            .sum();
        let small_ones_coloured = small_points >= MIN_COLOURED_ISLAND;
        let mut next = 0;
        for &(start, end, lcp) in islands {
            // The islands cover the points in order, so their manifolds follow each other.
            let from = next;
            while manifolds
                .get(next)
                .is_some_and(|m| (m.first as usize) < end)
            {
                next += 1;
            }
            if lcp {
                continue;
            }
            let coloured = if small_ones_coloured || end - start >= MIN_COLOURED_ISLAND {
                let island = &manifolds[from..next];
                let has_pin = !no_pins && island.iter().any(|m| pinned(m.a) || pinned(m.b));
                let at = self.inputs.len() as u32;
                let range = (at, at + island.len() as u32, has_pin);
                self.coloured_islands.push(range);
                PlanInput::COLOURED
            } else {
                0
            };
            self.inputs
                .extend(manifolds[from..next].iter().map(|m| PlanInput {
                    flags: m.flags | coloured,
                    ..*m
                }));
        }
    }

    /// Writes what the passes changed in the batches back to their points.
    pub(crate) fn scatter(&self, points: &mut [PointConstraint]) {
        for batch in self.batches() {
            batch.scatter(points);
        }
        for batch in self.point_batches() {
            batch.scatter(points);
        }
    }

    /// The batches' accumulated impulses, into `impulses` (normal and tangent, by
    /// contact).
    pub(crate) fn store_impulses(&self, impulses: &mut [(f64, f64)]) {
        for batch in self.batches() {
            batch.store_impulses(impulses);
        }
        for batch in self.point_batches() {
            batch.store_impulses(impulses);
        }
    }

    /// The step's batches of two-point manifolds.
    pub(crate) fn batches(&self) -> &[ManifoldBatch<2>] {
        self.pairs.filled()
    }

    /// The step's batches of one-point manifolds.
    pub(crate) fn point_batches(&self) -> &[ManifoldBatch<1>] {
        self.singles.filled()
    }

    /// The step's work and its batches, to solve them.
    pub(crate) fn work(
        &mut self,
    ) -> (
        &[PassItem],
        &mut [ManifoldBatch<2>],
        &mut [ManifoldBatch<1>],
    ) {
        (
            &self.items,
            self.pairs.filled_mut(),
            self.singles.filled_mut(),
        )
    }
}

/// One point of each lane's manifold.
#[derive(Debug, Clone, Copy, Default)]
#[repr(C)]
struct LanePoints<L = F64x8> {
    normal_lever_a: L,
    normal_lever_b: L,
    reach_a: L,
    reach_b: L,
    base_separation: L,
    normal_mass: L,
    tangent_mass: L,
    tangent_impulse: L,
}

/// What a point needs only if it may bounce (restitution ≠ 0), kept apart from
/// `LanePoints` so that a batch of points that cannot bounce (a pile) never touches it.
#[derive(Debug, Clone, Copy, Default)]
#[repr(C)]
struct LaneBounce<L = F64x8> {
    restitution: L,
    relative_velocity: L,
    max_normal_impulse: L,
    closing_acceleration: L,
    fastest_impact: L,
}

/// Eight manifolds of `N` points (one or two) with no moving body in common, their data
/// lane by lane; each manifold's points stay in `points` too, which this batch updates at
/// the end of the substeps. Stored with `F64x8` lanes; `repr(C)`, so that the AVX2 and
/// AVX-512 paths read the same bytes as `ManifoldBatch<N, Avx2Lanes<FIRST, END>>` and
/// `ManifoldBatch<N, F64x8Avx512>`.
#[derive(Debug, Clone, Copy)]
#[repr(C)]
pub(super) struct ManifoldBatch<const N: usize, L = F64x8> {
    /// The first of each lane's points in `points`.
    first_point: [u32; LANES],
    a: [u32; LANES],
    b: [u32; LANES],
    /// The lanes whose manifold may bounce, a bit each: only their `bounce` lanes are
    /// written when filled and read back (`scatter`), and only a batch with one reads or
    /// writes any during the passes (`may_bounce`). The others' hold what an earlier
    /// manifold left there, which the passes carry only into those same bounce lanes:
    /// a pile's batches never touch them.
    bouncing_lanes: u8,
    inv_inertia_a: L,
    inv_inertia_b: L,
    normal_x: L,
    normal_y: L,
    friction: L,
    /// 1 in lanes whose manifold has a fixed body (whose contacts are stiffer:
    /// `PassSettings::static_soft`), else 0.
    fixed: L,
    k11: L,
    k12: L,
    k22: L,
    /// The inverse of the 2 × 2 block, `[i11, i12, i22]` (two-point manifolds only).
    inverse: [L; 3],
    points: [LanePoints<L>; N],
    /// Each lane's points' contacts (`PAD` in unused lanes), where a step with nothing
    /// that bounces writes their impulses straight from the lanes (`store_impulses`).
    contacts: [[u32; LANES]; N],
    /// Each point's accumulated normal impulse, apart from `points` so that a lane
    /// solved both ways (`solve_normals_together`) copies only these.
    normal_impulses: [L; N],
    bounce: [LaneBounce<L>; N],
}

#[cfg(target_arch = "x86_64")]
const _: () = {
    use std::mem::{align_of, size_of};
    assert!(size_of::<ManifoldBatch<2>>() == size_of::<ManifoldBatch<2, BothHalves>>());
    assert!(size_of::<ManifoldBatch<1>>() == size_of::<ManifoldBatch<1, BothHalves>>());
    assert!(align_of::<ManifoldBatch<2>>() == align_of::<ManifoldBatch<2, BothHalves>>());
    assert!(align_of::<ManifoldBatch<1>>() == align_of::<ManifoldBatch<1, BothHalves>>());
    assert!(size_of::<ManifoldBatch<2>>() == size_of::<ManifoldBatch<2, F64x8Avx512>>());
    assert!(size_of::<ManifoldBatch<1>>() == size_of::<ManifoldBatch<1, F64x8Avx512>>());
    assert!(align_of::<ManifoldBatch<2>>() == align_of::<ManifoldBatch<2, F64x8Avx512>>());
    assert!(align_of::<ManifoldBatch<1>>() == align_of::<ManifoldBatch<1, F64x8Avx512>>());
};

impl<const N: usize> Default for ManifoldBatch<N> {
    fn default() -> Self {
        let zero = F64x8::default();
        Self {
            first_point: [0; LANES],
            a: [0; LANES],
            b: [0; LANES],
            inv_inertia_a: zero,
            inv_inertia_b: zero,
            normal_x: zero,
            normal_y: zero,
            friction: zero,
            fixed: zero,
            k11: zero,
            k12: zero,
            k22: zero,
            inverse: [zero; 3],
            bouncing_lanes: 0,
            points: [LanePoints::default(); N],
            contacts: [[PAD; LANES]; N],
            normal_impulses: [zero; N],
            bounce: [LaneBounce::default(); N],
        }
    }
}

/// The first point of an unused lane: the lane is all zeros, its bodies the null body
/// (the last of the solver's bodies: fixed, at rest, never stored), so that it changes
/// nothing; `scatter` passes it by.
pub(super) const PAD: u32 = u32::MAX;

#[cfg(test)]
pub(super) mod tests {
    use super::super::constraints::{NormalBlock, PointLevers};
    use super::super::contacts::{solve_pair, solve_point, warm_start_point};
    use super::super::settings::Softness;
    use super::*;
    use crate::math::{Rot, Vec2, cross};

    /// A small deterministic generator (xorshift), uniform in [lo, hi).
    pub(in crate::solver::soft) struct Numbers(pub u64);

    impl Numbers {
        pub(in crate::solver::soft) fn next(&mut self, lo: f64, hi: f64) -> f64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            lo + (hi - lo) * (self.0 >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// A body moving (or fixed), turned and moved a little since the step's start.
    pub(in crate::solver::soft) fn body(n: &mut Numbers, moving: bool) -> SoftBody {
        let (inv_mass, inv_inertia) = if moving {
            (n.next(0.1, 2.0), n.next(0.1, 6.0))
        } else {
            (0.0, 0.0)
        };
        let turn = n.next(-0.05, 0.05);
        SoftBody {
            v: Vec2::new(n.next(-1.0, 1.0), n.next(-1.0, 1.0)),
            w: n.next(-1.0, 1.0),
            inv_mass,
            inv_inertia,
            dp: Vec2::new(n.next(-0.01, 0.01), n.next(-0.01, 0.01)),
            dq: Rot::new(turn),
            dangle: turn,
        }
    }

    /// A point of a manifold between `a` and `b` along `normal`: some touching, some
    /// speculative (positive separation), some that may bounce.
    fn point(
        n: &mut Numbers,
        bodies: &[SoftBody],
        (a, b): (u32, u32),
        normal: Vec2,
    ) -> PointConstraint {
        let (ba, bb) = (&bodies[a as usize], &bodies[b as usize]);
        let r_a = Vec2::new(n.next(-0.5, 0.5), n.next(-0.5, 0.5));
        let r_b = Vec2::new(n.next(-0.5, 0.5), n.next(-0.5, 0.5));
        let levers = PointLevers {
            normal: (cross(r_a, normal), cross(r_b, normal)),
            reach: (r_a.dot(&normal), r_b.dot(&normal)),
        };
        let mass = |(la, lb): (f64, f64)| {
            1.0 / (ba.inv_mass + bb.inv_mass + ba.inv_inertia * la * la + bb.inv_inertia * lb * lb)
        };
        let bounces = n.next(0.0, 1.0) < 0.5;
        PointConstraint {
            contact: 0,
            a,
            b,
            normal,
            levers,
            base_separation: n.next(-0.02, 0.01),
            normal_mass: mass(levers.normal),
            tangent_mass: mass(levers.tangent()),
            friction: 0.6,
            restitution: if bounces { 0.5 } else { 0.0 },
            relative_velocity: n.next(-2.0, 0.0),
            normal_impulse: n.next(0.0, 0.3),
            tangent_impulse: n.next(-0.1, 0.1),
            max_normal_impulse: if bounces { 0.0 } else { 0.1 },
            closing_acceleration: n.next(0.0, 10.0),
            // Binds in the lanes whose impact is faster, not in the others.
            fastest_impact: -1.0,
            pair_coupling: None,
        }
    }

    /// A coupled two-point manifold between `a` and `b` (drawn again until its block is
    /// well conditioned).
    fn manifold(
        n: &mut Numbers,
        bodies: &[SoftBody],
        (a, b): (u32, u32),
        normal: Vec2,
    ) -> [PointConstraint; 2] {
        loop {
            let p = point(n, bodies, (a, b), normal);
            let q = point(n, bodies, (a, b), normal);
            if let Some(block) =
                NormalBlock::of((&bodies[a as usize], &bodies[b as usize]), (&p, &q))
            {
                let p = PointConstraint {
                    pair_coupling: Some(block),
                    ..p
                };
                return [p, q];
            }
        }
    }

    /// Eight two-point manifolds: lanes 0–5 between moving bodies, lanes 6 and 7 each
    /// against the same fixed body (which lanes may share).
    fn eight_manifolds(seed: u64) -> (Vec<SoftBody>, Vec<PointConstraint>) {
        let mut n = Numbers(seed);
        let mut bodies: Vec<SoftBody> = (0..14).map(|_| body(&mut n, true)).collect();
        bodies.push(body(&mut n, false));
        // The fixed body 14 in lanes 3 and 4: in both halves of the AVX2 path.
        let pairs = [
            (0, 1),
            (2, 3),
            (4, 5),
            (6, 14),
            (14, 7),
            (8, 9),
            (10, 11),
            (12, 13),
        ];
        let mut points = Vec::new();
        for (a, b) in pairs {
            let angle = n.next(0.0, std::f64::consts::TAU);
            let normal = Vec2::new(angle.cos(), angle.sin());
            points.extend(manifold(&mut n, &bodies, (a, b), normal));
        }
        (bodies, points)
    }

    fn pass(use_bias: bool) -> PassSettings {
        PassSettings {
            inv_h: 240.0,
            soft: Softness::new(30.0, 10.0, 1.0 / 240.0),
            static_soft: Softness::new(60.0, 10.0, 1.0 / 240.0),
            max_push: 3.0,
            max_depth: 0.1,
            use_bias,
        }
    }

    const FIRSTS: [u32; LANES] = [0, 2, 4, 6, 8, 10, 12, 14];

    /// Velocities and impulses: what a pass changes (and the inverse masses, which the
    /// SIMD paths write back beside the velocities).
    /// As bits, so that even the sign of a zero counts.
    fn state(bodies: &[SoftBody], points: &[PointConstraint]) -> Vec<u64> {
        let v = bodies.iter().flat_map(|b| [b.v.x, b.v.y, b.w, b.inv_mass]);
        let p = points.iter().flat_map(|p| {
            [
                p.normal_impulse,
                p.tangent_impulse,
                p.max_normal_impulse,
                p.relative_velocity,
            ]
        });
        v.chain(p).map(f64::to_bits).collect()
    }

    /// Solves the manifolds starting at `firsts` as one batch, with every lane path this
    /// processor runs (AVX-512, AVX2, portable), and checks that each leaves exactly the
    /// `expected` state: each lane runs the scalar arithmetic in the scalar order.
    fn assert_batch_gives<const N: usize>(
        (bodies, points): (&[SoftBody], &[PointConstraint]),
        firsts: [u32; LANES],
        pass: &PassSettings,
        expected: &[u64],
        label: &str,
    ) {
        for path in LanePath::available() {
            let mut batch = ManifoldBatch::<N>::default();
            batch.fill(firsts, Some(points), bodies);
            let (mut lanes, mut lane_points) = (bodies.to_vec(), points.to_vec());
            batch.solve_on(path, &mut lanes, pass);
            batch.scatter(&mut lane_points);
            assert_eq!(state(&lanes, &lane_points), expected, "{label}, {path:?}");
        }
    }

    /// `eight_manifolds(k)` for `seed` 2k − 1 and 2k, the odd one with every point made
    /// unable to bounce (a pile's): the batch then leaves its bounce lanes alone, as the
    /// scalar code leaves such points' approach and largest push.
    fn eight_manifolds_both_ways(seed: u64) -> (Vec<SoftBody>, Vec<PointConstraint>) {
        let (bodies, mut points) = eight_manifolds(seed.div_ceil(2));
        if seed % 2 == 1 {
            for p in &mut points {
                p.restitution = 0.0;
            }
        }
        (bodies, points)
    }

    #[test]
    fn a_batch_solves_as_its_manifolds_one_after_another() {
        for seed in 1..=398u64 {
            let (bodies, points) = eight_manifolds_both_ways(seed);
            for use_bias in [true, false] {
                let pass = pass(use_bias);
                let (mut one_by_one, mut their_points) = (bodies.clone(), points.clone());
                for &f in &FIRSTS {
                    let (first, second) = their_points.split_at_mut(f as usize + 1);
                    solve_pair(
                        &mut one_by_one,
                        (&mut first[f as usize], &mut second[0]),
                        &pass,
                    );
                }
                let expected = state(&one_by_one, &their_points);
                let label = format!("seed {seed}, bias {use_bias}");
                assert_batch_gives::<2>((&bodies, &points), FIRSTS, &pass, &expected, &label);
            }
        }
    }

    /// A batch filled again solves as a fresh one, whatever its lanes held before: its
    /// bounce lanes, which filling leaves in lanes that cannot bounce, included.
    #[test]
    fn a_batch_filled_again_solves_as_a_fresh_one() {
        for seed in 1..=100u64 {
            let (bodies, bouncing) = eight_manifolds(seed);
            let mut resting = bouncing.clone();
            for p in &mut resting {
                p.restitution = 0.0;
            }
            // Half the lanes' manifolds may bounce, half not.
            let mut mixed = bouncing.clone();
            for p in &mut mixed[8..] {
                p.restitution = 0.0;
            }
            let fills = [&bouncing, &resting, &mixed, &bouncing, &mixed, &resting];
            let pass = pass(true);
            let solved = |batch: &mut ManifoldBatch<2>, points: &[PointConstraint]| {
                let (mut lanes, mut lane_points) = (bodies.clone(), points.to_vec());
                batch.solve_on(LanePath::best(), &mut lanes, &pass);
                batch.scatter(&mut lane_points);
                state(&lanes, &lane_points)
            };
            let mut reused = ManifoldBatch::<2>::default();
            for (k, points) in fills.into_iter().enumerate() {
                let mut fresh = ManifoldBatch::<2>::default();
                fresh.fill(FIRSTS, Some(points), &bodies);
                reused.fill(FIRSTS, Some(points), &bodies);
                let expected = solved(&mut fresh, points);
                assert_eq!(
                    solved(&mut reused, points),
                    expected,
                    "seed {seed}, fill {k}"
                );
            }
        }
    }

    #[test]
    fn a_batch_of_one_point_manifolds_solves_as_they_do_one_after_another() {
        for seed in 1..=398u64 {
            // The first point of each of eight manifolds, each alone.
            let (bodies, pairs) = eight_manifolds_both_ways(seed);
            let points: Vec<PointConstraint> = pairs
                .iter()
                .step_by(2)
                .map(|p| PointConstraint {
                    pair_coupling: None,
                    ..*p
                })
                .collect();
            let firsts = [0, 1, 2, 3, 4, 5, 6, 7];
            for use_bias in [true, false] {
                let pass = pass(use_bias);
                let (mut one_by_one, mut their_points) = (bodies.clone(), points.clone());
                for p in &mut their_points {
                    solve_point(&mut one_by_one, p, &pass);
                }
                let expected = state(&one_by_one, &their_points);
                let label = format!("seed {seed}, bias {use_bias}");
                assert_batch_gives::<1>((&bodies, &points), firsts, &pass, &expected, &label);
            }
        }
    }

    #[test]
    fn a_batch_warm_starts_as_its_points_one_after_another() {
        for seed in 1..50 {
            let (bodies, points) = eight_manifolds(seed);
            let mut one_by_one = bodies.clone();
            for p in &points {
                warm_start_point(&mut one_by_one, p);
            }
            let mut batch = ManifoldBatch::<2>::default();
            batch.fill(FIRSTS, Some(&points), &bodies);
            for path in LanePath::available() {
                let mut lanes = bodies.clone();
                batch.warm_start_on(path, &mut lanes);
                let expected = state(&one_by_one, &[]);
                assert_eq!(state(&lanes, &[]), expected, "seed {seed}, {path:?}");
            }
        }
    }

    /// The plan's inputs as `SoftStepSolver::prepare` notes them: each coupled pair of
    /// points one manifold, every other point one.
    fn inputs_of(points: &[PointConstraint], bodies: &[SoftBody]) -> Vec<PlanInput> {
        let mut inputs = Vec::new();
        let mut first = 0;
        while first < points.len() {
            let p = &points[first];
            let moves = |i: u32| bodies[i as usize].moves();
            let mut input = PlanInput::new((p.a, p.b), first, (moves(p.a), moves(p.b)), p.normal);
            if p.pair_coupling.is_some() {
                input.add_second_point();
            }
            inputs.push(input);
            first += input.count() as usize;
        }
        inputs
    }

    /// `plan` over `points` as one island, from their entries (`inputs_of`).
    fn plan_one_island(plan: &mut PassPlan, points: &[PointConstraint], bodies: &[SoftBody]) {
        let inputs = inputs_of(points, bodies);
        plan.read(&[(0, points.len(), false)], &inputs, &[]);
        plan.plan(points, bodies);
    }

    /// A row of `n` boxes on a fixed floor (body 0), each touching the next: every
    /// manifold coupled, each box on the floor and against its neighbours.
    fn row_on_floor(n: u32) -> (Vec<SoftBody>, Vec<PointConstraint>) {
        let mut numbers = Numbers(7);
        let mut bodies = vec![body(&mut numbers, false)];
        bodies.extend((0..n).map(|_| body(&mut numbers, true)));
        let mut pairs: Vec<(u32, u32)> = (1..=n).map(|i| (0, i)).collect();
        pairs.extend((1..n).map(|i| (i, i + 1)));
        let mut points = Vec::new();
        for (a, b) in pairs {
            points.extend(manifold(&mut numbers, &bodies, (a, b), Vec2::new(0.0, 1.0)));
        }
        bodies.push(SoftBody::null());
        (bodies, points)
    }

    #[test]
    fn a_batch_writes_the_impulses_into_its_contacts_as_its_points_would() {
        let (mut bodies, mut points) = eight_manifolds(3);
        bodies.push(SoftBody::null());
        // Contacts numbered against the points' order, so that a mix-up shows.
        for (k, p) in points.iter_mut().enumerate() {
            p.contact = 15 - k as u32;
        }
        let firsts = [0, 2, 4, 6, 8, PAD, PAD, PAD];
        let mut batch = ManifoldBatch::<2>::default();
        batch.fill(firsts, Some(&points), &bodies);
        batch.solve_on(LanePath::best(), &mut bodies, &pass(true));
        // Every contact's entry marked, so that an entry written by mistake shows.
        let unwritten = (-1.0, -1.0);
        let (mut from_lanes, mut from_points) = (vec![unwritten; 16], vec![unwritten; 16]);
        batch.store_impulses(&mut from_lanes);
        batch.scatter(&mut points);
        for p in &points[..10] {
            from_points[p.contact as usize] = (p.normal_impulse, p.tangent_impulse);
        }
        assert_eq!(from_lanes, from_points);
        // The unused lanes' points (10 to 15) are left alone.
        assert!(
            points[10..]
                .iter()
                .all(|p| from_lanes[p.contact as usize] == unwritten)
        );
    }

    #[test]
    fn a_batch_with_unused_lanes_solves_its_manifolds_and_leaves_the_null_body() {
        for seed in 1..=100u64 {
            let (mut bodies, points) = eight_manifolds_both_ways(seed);
            bodies.push(SoftBody::null());
            // Three manifolds of the eight, then five unused lanes.
            let firsts = [0, 2, 4, PAD, PAD, PAD, PAD, PAD];
            for use_bias in [true, false] {
                let pass = pass(use_bias);
                let (mut one_by_one, mut their_points) = (bodies.clone(), points.clone());
                for f in [0usize, 2, 4] {
                    let (first, second) = their_points.split_at_mut(f + 1);
                    solve_pair(&mut one_by_one, (&mut first[f], &mut second[0]), &pass);
                }
                let expected = state(&one_by_one, &their_points);
                let label = format!("seed {seed}, bias {use_bias}");
                assert_batch_gives::<2>((&bodies, &points), firsts, &pass, &expected, &label);
            }
        }
    }

    /// On the AVX2 path, a pass on a batch whose upper half is unused writes only the
    /// lower half's lanes (`Lanes::set`): what it computes for the half it skips is
    /// garbage. (The other paths solve the unused lanes as manifolds of the null body.)
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn a_pass_leaves_the_lanes_of_an_unused_half_as_they_were() {
        if !LanePath::available().contains(&LanePath::Avx2) {
            return;
        }
        const MARK: f64 = 7.0;
        let written = |batch: &ManifoldBatch<2>| -> Vec<[f64; LANES]> {
            let impulses = batch.normal_impulses.iter().map(|lanes| lanes.0);
            let tangents = batch.points.iter().map(|p| p.tangent_impulse.0);
            let bounces = batch.bounce.iter();
            let bounces = bounces.flat_map(|b| [b.relative_velocity.0, b.max_normal_impulse.0]);
            impulses.chain(tangents).chain(bounces).collect()
        };
        let mark = |lanes: &mut F64x8| lanes.0[LANES / 2..].fill(MARK);
        for seed in 1..=20u64 {
            let (mut bodies, points) = eight_manifolds_both_ways(seed);
            bodies.push(SoftBody::null());
            let mut batch = ManifoldBatch::<2>::default();
            batch.fill([0, 2, 4, PAD, PAD, PAD, PAD, PAD], Some(&points), &bodies);
            batch.normal_impulses.iter_mut().for_each(mark);
            for p in &mut batch.points {
                mark(&mut p.tangent_impulse);
            }
            for b in &mut batch.bounce {
                mark(&mut b.relative_velocity);
                mark(&mut b.max_normal_impulse);
            }
            batch.solve_on(LanePath::Avx2, &mut bodies, &pass(true));
            for lanes in written(&batch) {
                assert_eq!(lanes[LANES / 2..], [MARK; 4], "seed {seed}");
            }
        }
    }

    #[test]
    fn the_plan_takes_every_manifold_once_batches_none_sharing_a_body_and_grounds_last() {
        let (bodies, mut points) = row_on_floor(40);
        // Every third manifold uncoupled: its points are two one-point manifolds.
        for m in (0..points.len() / 2).step_by(3) {
            points[2 * m].pair_coupling = None;
        }
        let mut plan = PassPlan::default();
        plan_one_island(&mut plan, &points, &bodies);
        let mut seen = vec![0; points.len()];
        let mut order = Vec::new();
        for item in &plan.items {
            let lanes_share_no_moving_body = |a: &[u32; LANES], b: &[u32; LANES]| {
                let moves = |i: &u32| bodies[*i as usize].moves();
                let mut moving: Vec<u32> = a.iter().chain(b).copied().filter(moves).collect();
                let len = moving.len();
                moving.sort_unstable();
                moving.dedup();
                moving.len() == len
            };
            let firsts: Vec<u32> = match *item {
                PassItem::Batch(k) => {
                    let batch = &plan.batches()[k as usize];
                    assert!(lanes_share_no_moving_body(&batch.a, &batch.b));
                    batch.first_point.to_vec()
                }
                PassItem::PointBatch(k) => {
                    let batch = &plan.point_batches()[k as usize];
                    assert!(lanes_share_no_moving_body(&batch.a, &batch.b));
                    batch.first_point.to_vec()
                }
                PassItem::Manifold(first, _) => vec![first],
            };
            for f in firsts.into_iter().filter(|&f| f != PAD) {
                seen[f as usize] += 1;
                order.push(f);
            }
        }
        // Each coupled manifold once by its first point, each point of the others once.
        let mut expected = vec![0; points.len()];
        for m in 0..points.len() / 2 {
            expected[2 * m] = 1;
            if points[2 * m].pair_coupling.is_none() {
                expected[2 * m + 1] = 1;
            }
        }
        assert_eq!(seen, expected);
        let (batches, point_batches) = (plan.batches().len(), plan.point_batches().len());
        assert!(batches >= 5, "{batches} batches of 52 two-point manifolds");
        assert!(
            point_batches >= 3,
            "{point_batches} batches of 54 one-point ones"
        );
        // Every contact with the floor after every contact between boxes.
        let on_floor = |f: &u32| points[*f as usize].a == 0;
        let first_on_floor = order.iter().position(on_floor).unwrap();
        assert!(order[first_on_floor..].iter().all(on_floor), "{order:?}");
        // Planned again from the same manifolds, the plan is kept and its batches read
        // the points' current numbers; from changed ones, it is the fresh plan.
        let kept = plan.items.clone();
        let batched = plan.batches()[0].first_point[3] as usize;
        points[batched].normal_impulse = 0.125;
        plan_one_island(&mut plan, &points, &bodies);
        assert_eq!(plan.items, kept);
        assert_eq!(plan.batches()[0].normal_impulses[0].0[3], 0.125);
        // The same, with the manifolds written into their lanes as they are built (as
        // `SoftStepSolver::prepare` does): every batch as a fresh fill leaves it.
        for p in &mut points {
            p.tangent_impulse += 0.5;
        }
        plan.begin_filling();
        for input in inputs_of(&points, &bodies) {
            let (first, count) = (input.first as usize, input.count() as usize);
            match count {
                2 => plan.fill_manifold(first, &[points[first], points[first + 1]], &bodies),
                _ => plan.fill_manifold(first, &[points[first]], &bodies),
            };
        }
        plan_one_island(&mut plan, &points, &bodies);
        assert_eq!(plan.items, kept);
        for batch in plan.batches() {
            let mut fresh = *batch;
            fresh.fill(batch.first_point, Some(&points), &bodies);
            let bits = |b: &ManifoldBatch<2>| {
                let lanes = b.points.iter().flat_map(|p| p.tangent_impulse.0);
                let impulses = b.normal_impulses.iter().flat_map(|l| l.0);
                lanes.chain(impulses).map(f64::to_bits).collect::<Vec<_>>()
            };
            assert_eq!(bits(batch), bits(&fresh));
            assert_eq!(batch.bouncing_lanes, fresh.bouncing_lanes);
        }
        points[batched].pair_coupling = None;
        plan_one_island(&mut plan, &points, &bodies);
        let mut fresh = PassPlan::default();
        plan_one_island(&mut fresh, &points, &bodies);
        assert_ne!(plan.items, kept);
        assert_eq!(plan.items, fresh.items);
        // A small island keeps the points' order and is not batched.
        let (bodies, points) = row_on_floor(2);
        plan.read(&[(0, 6, false)], &inputs_of(&points, &bodies), &[]);
        plan.plan(&points, &bodies);
        let in_order: Vec<PassItem> = (0..3).map(|m| PassItem::Manifold(2 * m, 2)).collect();
        assert_eq!(plan.items, in_order);
    }

    #[test]
    fn small_islands_are_coloured_together_once_they_have_enough_points() {
        // 27 two-point manifolds, taken as nine islands of 6 points (3 manifolds) each.
        let (bodies, points) = row_on_floor(14);
        let inputs = inputs_of(&points, &bodies);
        let islands: Vec<_> = (0..9).map(|k| (6 * k, 6 * k + 6, false)).collect();
        let mut plan = PassPlan::default();
        plan.read(&islands, &inputs, &[]);
        plan.plan(&points, &bodies);
        assert_eq!(plan.coloured_from, 0, "every manifold coloured");
        let lanes = |b: &ManifoldBatch<2>| b.first_point.iter().filter(|&&f| f != PAD).count();
        let batched: usize = plan.batches().iter().map(lanes).sum();
        let alone = plan
            .items
            .iter()
            .filter(|i| matches!(i, PassItem::Manifold(..)));
        assert_eq!(batched + alone.count(), 27);
        assert!(batched >= 16, "{batched} of 27 manifolds in batches");
        // Two of them and an LCP island: 12 points, coloured. With the second an LCP
        // island too, the first's 6 points are solved in their order.
        let two = [(0, 6, false), (6, 12, false), (12, 18, true)];
        plan.read(&two, &inputs[..9], &[]);
        plan.plan(&points[..18], &bodies);
        assert_eq!(plan.coloured_from, 0, "every manifold coloured");
        let one = [(0, 6, false), (6, 12, true), (12, 18, true)];
        plan.read(&one, &inputs[..9], &[]);
        plan.plan(&points[..18], &bodies);
        let in_order: Vec<PassItem> = (0..3).map(|m| PassItem::Manifold(2 * m, 2)).collect();
        assert_eq!(plan.items, in_order);
    }
}
