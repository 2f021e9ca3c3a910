//! The passes' order over a step's manifolds, and eight manifolds solved side by side,
//! one per SIMD lane, as Box2D v3 does (in f32; here in f64).
//!
//! Manifolds of a big island are grouped by colours of the constraint graph (no two in a
//! colour share a moving body), as Box2D v3 assigns them: manifolds between two moving
//! bodies from the first colour up, those against a fixed body from the last colour down,
//! so that contacts with the ground have the last word in every pass. (Against a fixed
//! body first, the 100-row pyramid fell: 2,068 of 5,050 boxes.) Within a colour, eight
//! coupled two-point manifolds at a time are one `ManifoldBatch<2>`, and eight one-point
//! ones a `ManifoldBatch<1>`, solved with the same arithmetic as `solve_pair` and
//! `solve_point`, lane by lane, so a batch gives the same bits as its eight manifolds
//! solved one after another, whichever lanes the processor has. Small islands keep the
//! points' order, one manifold at a time.
//!
//! The colours are given in a scattered order (`PassPlan::colour_in_scattered_order`):
//! given in the points' order, they repeated one pattern across a pile and it swayed. With
//! that and the sweeps alternating (`SweepOrder`), the 100-row pyramid's top stays within
//! 0.25% of a box over 500 steps (Box2D v3 0.94%): see docs/bench/profile.md.

#[cfg(target_arch = "x86_64")]
use super::avx2::{BothHalves, LowerHalf};
#[cfg(target_arch = "x86_64")]
use super::avx512::F64x8Avx512;
use super::lanes::{F64x8, LANES, LaneMask, Lanes};
use super::{BodyRow, NormalBlock, PointConstraint, PointLevers, SoftBody, Softness};
use crate::math::Vec2;
use crate::solver::island::counting_sort;

/// Colours of the constraint graph, as many as a body's `u32` of colour bits holds (a
/// manifold that finds no free colour is solved before the colours, one at a time).
/// Box2D v3 has 24; with 24 the smash's fast debris, whose speculative contacts reach
/// many neighbours, left about 6,000 of its 59,000 coloured manifolds without a colour,
/// and 32 took its steps 20–26 from 262.2M to 256.4M instructions a step. Piles need
/// fewer than 20 and give the same bits either way.
const COLOURS: u32 = 32;

/// Colours 0–27 are open to manifolds between two moving bodies; those against a fixed
/// body take 30 down to 1 (Box2D v3's split, four colours from the top), so 28–30 are
/// theirs alone.
const DYNAMIC_COLOURS: u32 = COLOURS - 4;

/// Islands of fewer contact points than this are solved in the points' order, one
/// manifold at a time: below it, the lanes would stay nearly empty. Unless the small
/// islands together have this many points, since the colours are shared by every island
/// and many small ones fill the lanes together (the smash's debris). Coloured, a lone
/// stack of 2 boxes (4 points) costs the same a step, of 5 boxes 4% less, of 10 boxes
/// 39% less; three stacks of 2 boxes 30% less (docs/bench/profile.md, "Small islands
/// coloured"; this was 48, from instructions counted rather than time).
const MIN_COLOURED_ISLAND: usize = 8;

/// How many manifolds ahead of the one batched now `plan` asks the cache for the points
/// and bodies of.
const PREFETCH_AHEAD: usize = 16;

/// From how many bytes of batches the passes ask for each next batch while solving one
/// (`PassPlan::batches_ahead`). Many megabytes of them come from farther out in every
/// pass, and the first reads of each batch waited: asked for ahead, the smash's passes
/// (6.5 MB of batches at step 120) took 30% less time on the Zen 1, large_pyramid's and
/// many_pyramids' (4.9–5.0 MB) 15–25%. Batches that stay in the caches gain nothing and
/// pay for the asking: pyramid20's (207 KB) passes 3% slower, pyramid40's (806 KB, past
/// the level-2 cache but well inside the level-3) warm start 9–12% slower and its solve
/// 1–2%. The warm start asks for what it reads too.
const ASK_AHEAD_FROM_BYTES: usize = 2 * 1024 * 1024;

/// From how many bytes of batches a step solves its coloured islands in chunks
/// (`PassPlan::assign_chunks`), and how many bytes of batches a chunk holds at most (an
/// island with more stays with the rest). A chunk is solved through every substep before
/// the next, so its batches are read from the level-2 cache (512 KB a core here) in all
/// but the first pass, where the whole step's would come from the level 3 in every pass:
/// many_pyramids' warm start a third cheaper, its solve a seventh (docs/bench/profile.md).
const CHUNK_FROM_BYTES: usize = 1024 * 1024;
const CHUNK_BYTES: usize = 256 * 1024;

/// Where the step's batches lie (`PassPlan::batches_ahead`), kept apart from their
/// borrow so that a pass holding them mutably can still ask for the next one. The
/// pointers are only ever prefetched from, never read through.
#[derive(Debug, Clone, Copy)]
pub(super) struct BatchesAhead {
    pairs: *const ManifoldBatch<2>,
    singles: *const ManifoldBatch<1>,
    on: bool,
}

/// What a batch is asked for ahead of: a pass reads most of it, the warm start less.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum AskedFor {
    Pass,
    WarmStart,
}

impl BatchesAhead {
    /// The same, asking only if `ask` too.
    pub(crate) fn only_if(mut self, ask: bool) -> Self {
        self.on &= ask;
        self
    }

    /// Hands `items` to `visit` in their order, asking for what `reader` will read of
    /// each next one's batch while the one before is visited.
    #[inline(always)]
    pub(crate) fn visit<'a>(
        self,
        items: impl Iterator<Item = &'a PassItem>,
        reader: AskedFor,
        mut visit: impl FnMut(&'a PassItem),
    ) {
        let mut items = items.peekable();
        while let Some(item) = items.next() {
            self.ask_for(items.peek().copied(), reader);
            visit(item);
        }
    }

    /// Asks the cache for what `reader` will read of `item`'s batch, if it is one.
    #[inline(always)]
    fn ask_for(self, item: Option<&PassItem>, reader: AskedFor) {
        match (item, reader) {
            _ if !self.on => {}
            (Some(&PassItem::Batch(k)), AskedFor::Pass) => {
                ManifoldBatch::prefetch(self.pairs.wrapping_add(k as usize))
            }
            (Some(&PassItem::Batch(k)), AskedFor::WarmStart) => {
                ManifoldBatch::prefetch_for_warm_start(self.pairs.wrapping_add(k as usize))
            }
            (Some(&PassItem::PointBatch(k)), AskedFor::Pass) => {
                ManifoldBatch::prefetch(self.singles.wrapping_add(k as usize))
            }
            (Some(&PassItem::PointBatch(k)), AskedFor::WarmStart) => {
                ManifoldBatch::prefetch_for_warm_start(self.singles.wrapping_add(k as usize))
            }
            _ => {}
        }
    }
}

/// A manifold of a coloured island, as `plan` sorts them.
#[derive(Debug, Clone, Copy)]
struct ColouredManifold {
    /// 2 × colour, + 1 if sideways (`PlanInput::SIDEWAYS`): the sort's key.
    key: u32,
    first: u32,
    count: u32,
    bodies: (u32, u32),
}

/// Asks the cache for the lines holding `values`, ahead of reading them.
#[inline(always)]
fn prefetch<T>(values: &[T]) {
    prefetch_bytes(values.as_ptr().cast(), std::mem::size_of_val(values));
}

/// Asks the cache for the lines holding the `len` bytes from `start`. Only a hint: it
/// reads nothing the program sees and cannot fault, so `start` may point anywhere.
#[inline(always)]
fn prefetch_bytes(start: *const u8, len: usize) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        const LINE: usize = 64;
        // From the start of the line `start` is in, up to the one the bytes end in.
        let skew = start as usize % LINE;
        for offset in (0..skew + len).step_by(LINE) {
            // The address needs no more than to be computed without overflow.
            let line = start.wrapping_sub(skew).wrapping_add(offset).cast::<i8>();
            // SAFETY: as above, a prefetch of any address is sound.
            unsafe { _mm_prefetch::<_MM_HINT_T0>(line) };
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (start, len);
}

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
    /// Tests only: other bounds than `CHUNK_FROM_BYTES` and `CHUNK_BYTES`.
    #[cfg(test)]
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
        // which takes the slower path (`solve_normals_together`): on the 40-row pyramid
        // at rest 332 of 2,400 batch passes a step, against 504 ungrouped.
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
                // points (the smash's ~12 MB): they are asked for ahead.
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
    fn assign_chunks(&mut self, body_count: usize) -> u32 {
        self.chunk_of_input.clear();
        self.chunk_of_input.resize(self.inputs.len(), 0);
        self.chunk_bodies.clear();
        self.chunk_body_starts.clear();
        self.in_chunk.clear();
        let (from_bytes, chunk_bytes) = (CHUNK_FROM_BYTES, CHUNK_BYTES);
        #[cfg(test)]
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

    /// Where the step's batches lie, for the passes to ask for each next one while
    /// solving one, if the batches are too many to stay in the cache
    /// (`ASK_AHEAD_FROM_BYTES`).
    pub(crate) fn batches_ahead(&self) -> BatchesAhead {
        let bytes =
            std::mem::size_of_val(self.batches()) + std::mem::size_of_val(self.point_batches());
        BatchesAhead {
            pairs: self.batches().as_ptr(),
            singles: self.point_batches().as_ptr(),
            on: bytes >= ASK_AHEAD_FROM_BYTES,
        }
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

    /// Colours the coloured manifolds (`colour_of`) in an order scattered over the pile,
    /// into `colour_by_input`.
    ///
    /// Greedy colouring in the points' order (a pile row by row, left to right: each
    /// manifold takes the lowest colour its bodies leave free) colours a pile in one
    /// pattern repeated across it, so the one-sidedness of a Gauss–Seidel sweep over the
    /// colours adds up over the pile instead of averaging out, and the pile sways. Coloured
    /// in the order of a hash of their bodies (one counting sort on 8 bits of it: buckets
    /// scattered over the pile, each in the points' order), the colours fall anywhere,
    /// and the 100-row pyramid's top box sways at most 0.0025 of a width in 500 steps and
    /// ends 0.0010 off (in the points' order 0.022 and 0.0063; Box2D v3 0.0094 and
    /// 0.0041): see docs/bench/profile.md. The colours needed, and so the batches, stay
    /// about as many (2,400 batch passes a step on the 40-row pyramid, against 2,376).
    fn colour_in_scattered_order(&mut self) {
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

/// Batches of `N`-point manifolds being filled for one step: the step's are the first
/// `filled`, the rest kept (with their allocation) to be refilled next step.
#[derive(Debug, Clone, Default)]
struct BatchPool<const N: usize> {
    batches: Vec<ManifoldBatch<N>>,
    filled: usize,
    /// First points of the colour's manifolds waiting for a full batch.
    waiting: [u32; LANES],
    waiting_len: usize,
}

impl<const N: usize> BatchPool<N> {
    fn clear(&mut self) {
        self.filled = 0;
        self.waiting_len = 0;
    }

    fn filled(&self) -> &[ManifoldBatch<N>] {
        &self.batches[..self.filled]
    }

    fn filled_mut(&mut self) -> &mut [ManifoldBatch<N>] {
        &mut self.batches[..self.filled]
    }

    /// Takes the manifold at `first` into the colour's next batch, which goes into
    /// `items` once it holds `LANES`.
    fn take(
        &mut self,
        first: u32,
        (points, bodies): (Option<&[PointConstraint]>, &[SoftBody]),
        items: &mut Vec<PassItem>,
    ) {
        self.waiting[self.waiting_len] = first;
        self.waiting_len += 1;
        if self.waiting_len == LANES {
            self.push_batch((points, bodies), items);
        }
    }

    /// The waiting manifolds as the next batch, into `items`.
    fn push_batch(
        &mut self,
        (points, bodies): (Option<&[PointConstraint]>, &[SoftBody]),
        items: &mut Vec<PassItem>,
    ) {
        self.waiting_len = 0;
        if self.filled == self.batches.len() {
            self.batches.push(ManifoldBatch::default());
        }
        self.batches[self.filled].fill(self.waiting, points, bodies);
        let k = self.filled as u32;
        items.push(if N == 2 {
            PassItem::Batch(k)
        } else {
            PassItem::PointBatch(k)
        });
        self.filled += 1;
    }

    /// At the end of a colour, the manifolds short of a batch: a batch with its other
    /// lanes unused (`PAD`) if they are at least `pad_from`, else one by one into `items`.
    fn end_colour(
        &mut self,
        (points, bodies): (Option<&[PointConstraint]>, &[SoftBody]),
        items: &mut Vec<PassItem>,
        pad_from: usize,
    ) {
        if self.waiting_len > 0 && self.waiting_len >= pad_from {
            self.waiting[self.waiting_len..].fill(PAD);
            return self.push_batch((points, bodies), items);
        }
        let alone = self.waiting[..self.waiting_len].iter();
        items.extend(alone.map(|&f| PassItem::Manifold(f, N as u32)));
        self.waiting_len = 0;
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

/// A body's velocity, lane by lane.
#[derive(Debug, Clone, Copy)]
pub(super) struct LaneVelocity<L> {
    pub x: L,
    pub y: L,
    pub w: L,
    /// The inverse masses read with the velocities (`BodyRow::Velocity`), which
    /// `scatter_velocities` may write back beside them.
    pub inv_mass: L,
}

impl<L: Lanes> LaneVelocity<L> {
    /// # Safety
    /// Every index must be below `bodies.len()` (`Lanes::gather`).
    #[inline(always)]
    pub(crate) unsafe fn load(bodies: &[SoftBody], index: &[u32; LANES]) -> Self {
        // SAFETY: the caller's precondition.
        let [x, y, w, inv_mass] = unsafe { L::gather(bodies, index, BodyRow::Velocity) };
        Self { x, y, w, inv_mass }
    }

    /// # Safety
    /// As `load`.
    #[inline(always)]
    pub(crate) unsafe fn store(&self, bodies: &mut [SoftBody], index: &[u32; LANES]) {
        let columns = [self.x, self.y, self.w, self.inv_mass];
        // SAFETY: the caller's precondition.
        unsafe { L::scatter_velocities(columns, bodies, index) };
    }
}

/// The two bodies' velocities and inverse masses of every lane, as `BodyPair`.
#[derive(Debug, Clone, Copy)]
struct LanePair<L> {
    a: LaneVelocity<L>,
    b: LaneVelocity<L>,
    inv_inertia: (L, L),
}

impl<L: Lanes> LanePair<L> {
    /// `if_true`'s velocities where `mask` holds, `if_false`'s elsewhere.
    #[inline(always)]
    fn select(mask: L::Mask, if_true: Self, if_false: Self) -> Self {
        let pick = |t: LaneVelocity<L>, f: LaneVelocity<L>| LaneVelocity {
            x: mask.select(t.x, f.x),
            y: mask.select(t.y, f.y),
            w: mask.select(t.w, f.w),
            inv_mass: f.inv_mass,
        };
        Self {
            a: pick(if_true.a, if_false.a),
            b: pick(if_true.b, if_false.b),
            ..if_false
        }
    }

    /// `BodyPair::velocity_along`, lane by lane.
    #[inline(always)]
    fn velocity_along(&self, (dx, dy): (L, L), lever_a: L, lever_b: L) -> L {
        let (rx, ry) = (self.a.x - self.b.x, self.a.y - self.b.y);
        let linear = ry.mul_add(dy, rx * dx);
        let angular = self.b.w.neg_mul_add(lever_b, self.a.w * lever_a);
        linear + angular
    }

    /// `BodyPair::apply_along`, lane by lane.
    #[inline(always)]
    fn apply_along(&mut self, (dx, dy): (L, L), lever_a: L, lever_b: L, impulse: L) {
        let (sa, sb) = (impulse * self.a.inv_mass, impulse * self.b.inv_mass);
        self.a.x = dx.mul_add(sa, self.a.x);
        self.a.y = dy.mul_add(sa, self.a.y);
        self.a.w = (self.inv_inertia.0 * lever_a).mul_add(impulse, self.a.w);
        self.b.x = dx.neg_mul_add(sb, self.b.x);
        self.b.y = dy.neg_mul_add(sb, self.b.y);
        self.b.w = (self.inv_inertia.1 * lever_b).neg_mul_add(impulse, self.b.w);
    }
}

/// What one pass needs to find each point's target and softness (see `normal_target`).
#[derive(Debug, Clone, Copy)]
pub(super) struct PassSettings {
    pub(super) inv_h: f64,
    pub(super) soft: Softness,
    /// The softness of contacts with a fixed body.
    pub(super) static_soft: Softness,
    pub(super) max_push: f64,
    /// `SoftSettings::max_soft_depth`.
    pub(super) max_depth: f64,
    pub(super) use_bias: bool,
}

/// The lanes a batch is solved with: the widest this processor has.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum LanePath {
    /// `F64x8`: plain arrays, any processor.
    Portable,
    /// `Avx2Lanes`: four lanes to a 256-bit register, a row in two.
    #[cfg(target_arch = "x86_64")]
    Avx2,
    /// `F64x8Avx512`: one 512-bit register.
    #[cfg(target_arch = "x86_64")]
    Avx512,
}

/// The first point of an unused lane: the lane is all zeros, its bodies the null body
/// (the last of the solver's bodies: fixed, at rest, never stored), so that it changes
/// nothing; `scatter` passes it by.
pub(super) const PAD: u32 = u32::MAX;

impl LanePath {
    /// The fewest manifolds worth a batch of their own at the end of a colour, the other
    /// lanes unused: a batch's pass costs about three manifolds' alone in AVX-512 (one
    /// register a lane row) and in AVX2 (whose pass skips an unused upper half; two or
    /// three made the same instructions on the 20-row pyramid and the smash), six in the
    /// portable lanes.
    pub(super) fn fewest_padded(self) -> usize {
        match self {
            #[cfg(target_arch = "x86_64")]
            Self::Avx512 | Self::Avx2 => 3,
            Self::Portable => 6,
        }
    }

    /// The widest path this processor runs (detected once, then a cached flag).
    #[inline(always)]
    pub(super) fn best() -> Self {
        #[cfg(target_arch = "x86_64")]
        {
            if std::arch::is_x86_feature_detected!("avx512f") {
                return Self::Avx512;
            }
            if Self::has_avx2_and_fma() {
                return Self::Avx2;
            }
        }
        Self::Portable
    }

    /// The AVX2 path's fused multiply–adds (`Lanes::mul_add`) are FMA's instructions, which
    /// every AVX2 processor from Intel and AMD has.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn has_avx2_and_fma() -> bool {
        std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
    }

    /// Every path this processor runs, the portable one first.
    #[cfg(test)]
    pub(super) fn available() -> Vec<Self> {
        let mut paths = vec![Self::Portable];
        #[cfg(target_arch = "x86_64")]
        {
            if Self::has_avx2_and_fma() {
                paths.push(Self::Avx2);
            }
            if std::arch::is_x86_feature_detected!("avx512f") {
                paths.push(Self::Avx512);
            }
        }
        paths
    }
}

/// A batch of eight lanes stored with `F64x8` (`ManifoldBatch`, `pins::PinBatch`), whose
/// warm start and pass run with the lanes `LanePath` picks: one code, compiled for each
/// path, reading the batch's bytes as that path's lane type.
///
/// # Safety
/// `Self::With<L>` must be `Self` with `L` in place of `F64x8`: the same size, alignment
/// and layout (`repr(C)`, lanes of one size and alignment; any bits are valid in each), so
/// that a batch can be read as it.
pub(super) unsafe trait LaneBatch: Sized {
    /// What a pass reads besides the bodies.
    type Pass;
    /// The batch read with the lanes `L`.
    type With<L: Lanes>: BatchLanes<Self::Pass>;

    /// Whether any of lanes 4–7 is in use: the AVX2 path skips that half if not.
    fn upper_half_used(&self) -> bool;

    /// The warm start on every lane, with the lanes of `path`, which this processor must
    /// run (`LanePath::best`).
    fn warm_start_on(&self, path: LanePath, bodies: &mut [SoftBody]) {
        match path {
            // SAFETY: plain arrays run anywhere.
            LanePath::Portable => unsafe { as_lanes::<Self, F64x8>(self) }.warm_start_lanes(bodies),
            // SAFETY: `path` is one this processor runs (`LanePath::best`, `available`).
            #[cfg(target_arch = "x86_64")]
            LanePath::Avx2 => unsafe { warm_start_avx2(self, bodies) },
            #[cfg(target_arch = "x86_64")]
            LanePath::Avx512 => unsafe { warm_start_avx512(self, bodies) },
        }
    }

    /// A pass on every lane, with the lanes of `path`, as `warm_start_on`.
    fn solve_on(&mut self, path: LanePath, bodies: &mut [SoftBody], pass: &Self::Pass) {
        match path {
            // SAFETY: as in `warm_start_on`.
            LanePath::Portable => {
                unsafe { as_lanes_mut::<Self, F64x8>(self) }.solve_lanes(bodies, pass)
            }
            #[cfg(target_arch = "x86_64")]
            LanePath::Avx2 => unsafe { solve_avx2(self, bodies, pass) },
            #[cfg(target_arch = "x86_64")]
            LanePath::Avx512 => unsafe { solve_avx512(self, bodies, pass) },
        }
    }
}

/// A batch's warm start and pass, in the lanes it is read with (`LaneBatch::With`).
pub(super) trait BatchLanes<Pass> {
    fn warm_start_lanes(&self, bodies: &mut [SoftBody]);
    fn solve_lanes(&mut self, bodies: &mut [SoftBody], pass: &Pass);
}

/// `batch` read with the lane type `L`.
///
/// # Safety
/// The processor must run `L`'s instructions.
#[inline(always)]
unsafe fn as_lanes<B: LaneBatch, L: Lanes>(batch: &B) -> &B::With<L> {
    // SAFETY: the same bytes (`LaneBatch`'s contract); the borrow is `batch`'s.
    unsafe { &*(batch as *const B).cast::<B::With<L>>() }
}

/// # Safety
/// As `as_lanes`.
#[inline(always)]
unsafe fn as_lanes_mut<B: LaneBatch, L: Lanes>(batch: &mut B) -> &mut B::With<L> {
    // SAFETY: as `as_lanes`.
    unsafe { &mut *(batch as *mut B).cast::<B::With<L>>() }
}

/// The same code compiled for AVX2, whose 256-bit registers hold half the lanes: both
/// halves at once, interleaved, unless the upper one is unused; see `avx2`.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn warm_start_avx2<B: LaneBatch>(batch: &B, bodies: &mut [SoftBody]) {
    // SAFETY (both): this function runs only where the processor has AVX2 and FMA
    // (`LaneBatch::warm_start_on`).
    if batch.upper_half_used() {
        unsafe { as_lanes::<B, BothHalves>(batch) }.warm_start_lanes(bodies);
    } else {
        unsafe { as_lanes::<B, LowerHalf>(batch) }.warm_start_lanes(bodies);
    }
}

/// A pass solves both halves at once, interleaved, unless the upper one is unused.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn solve_avx2<B: LaneBatch>(batch: &mut B, bodies: &mut [SoftBody], pass: &B::Pass) {
    // SAFETY (both): this function runs only where the processor has AVX2 and FMA
    // (`LaneBatch::solve_on`).
    if batch.upper_half_used() {
        unsafe { as_lanes_mut::<B, BothHalves>(batch) }.solve_lanes(bodies, pass);
    } else {
        unsafe { as_lanes_mut::<B, LowerHalf>(batch) }.solve_lanes(bodies, pass);
    }
}

/// The same code compiled for AVX-512, whose 512-bit registers hold all eight lanes.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
fn warm_start_avx512<B: LaneBatch>(batch: &B, bodies: &mut [SoftBody]) {
    // SAFETY: this function runs only where the processor has AVX-512F.
    unsafe { as_lanes::<B, F64x8Avx512>(batch) }.warm_start_lanes(bodies)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
fn solve_avx512<B: LaneBatch>(batch: &mut B, bodies: &mut [SoftBody], pass: &B::Pass) {
    // SAFETY: this function runs only where the processor has AVX-512F.
    unsafe { as_lanes_mut::<B, F64x8Avx512>(batch) }.solve_lanes(bodies, pass)
}

// SAFETY: `ManifoldBatch<N, L>` is `repr(C)` with lanes of `F64x8`'s size and alignment
// (asserted with the struct), any bits valid in each.
unsafe impl<const N: usize> LaneBatch for ManifoldBatch<N> {
    type Pass = PassSettings;
    type With<L: Lanes> = ManifoldBatch<N, L>;

    #[inline(always)]
    fn upper_half_used(&self) -> bool {
        self.first_point[LANES / 2..].iter().any(|&f| f != PAD)
    }
}

impl<const N: usize> ManifoldBatch<N> {
    /// Asks the cache for what a pass reads of the batch at `batch` (all but its bounce
    /// lanes), ahead of solving it. `batch` need not point at a batch (`prefetch_bytes`).
    #[inline(always)]
    fn prefetch(batch: *const Self) {
        prefetch_bytes(batch.cast(), std::mem::offset_of!(Self, bounce));
    }

    /// Asks the cache for what the warm start reads of the batch at `batch` (18 of the 31
    /// lines a pass reads of a two-point batch), as `prefetch`. Asked for whole, the warm
    /// start took no less time; asked for these, large_pyramid's took 5–15% less on the
    /// Zen 1 and the smash's 10–30%.
    #[inline(always)]
    fn prefetch_for_warm_start(batch: *const Self) {
        use std::mem::{offset_of, size_of};
        let at = |offset: usize| batch.cast::<u8>().wrapping_add(offset);
        prefetch_bytes(at(0), offset_of!(Self, friction));
        for k in 0..N {
            let point = offset_of!(Self, points) + k * size_of::<LanePoints>();
            let levers = offset_of!(LanePoints, normal_lever_a);
            let levers_end = offset_of!(LanePoints, base_separation);
            prefetch_bytes(at(point + levers), levers_end - levers);
            let tangent = offset_of!(LanePoints, tangent_impulse);
            prefetch_bytes(at(point + tangent), size_of::<F64x8>());
        }
        prefetch_bytes(
            at(offset_of!(Self, normal_impulses)),
            N * size_of::<F64x8>(),
        );
    }

    /// Fills the batch with the manifolds whose first points are `first_point` (`PAD`:
    /// an unused lane, on the null body, the last of `bodies`).
    /// Without `points`, only the unused lanes are filled: the others are filled as
    /// their points are built (`PassPlan::plan_before_points`).
    fn fill(
        &mut self,
        first_point: [u32; LANES],
        points: Option<&[PointConstraint]>,
        bodies: &[SoftBody],
    ) {
        self.first_point = first_point;
        let unused = first_point
            .contains(&PAD)
            .then(|| unused_lane(bodies.len() as u32 - 1));
        for (k, &first) in first_point.iter().enumerate() {
            let lane_points = match (&unused, points) {
                (Some(unused), _) if first == PAD => &unused[..],
                (_, Some(points)) => &points[first as usize..],
                (_, None) => continue,
            };
            self.fill_lane(k, first, &lane_points[..N], bodies);
        }
    }

    /// Lane `k`: the manifold whose points are `lane_points` (its first point `first`).
    #[inline(always)]
    fn fill_lane(
        &mut self,
        k: usize,
        first: u32,
        lane_points: &[PointConstraint],
        bodies: &[SoftBody],
    ) {
        self.first_point[k] = first;
        let p = &lane_points[0];
        let (a, b) = (&bodies[p.a as usize], &bodies[p.b as usize]);
        self.a[k] = p.a;
        self.b[k] = p.b;
        self.inv_inertia_a.0[k] = a.inv_inertia;
        self.inv_inertia_b.0[k] = b.inv_inertia;
        self.normal_x.0[k] = p.normal.x;
        self.normal_y.0[k] = p.normal.y;
        self.friction.0[k] = p.friction;
        self.fixed.0[k] = if a.moves() && b.moves() { 0.0 } else { 1.0 };
        if N == 2 {
            let block = p.pair_coupling.expect("batched pairs are coupled");
            self.k11.0[k] = block.k11;
            self.k12.0[k] = block.k12;
            self.k22.0[k] = block.k22;
            self.inverse[0].0[k] = block.inverse.0;
            self.inverse[1].0[k] = block.inverse.1;
            self.inverse[2].0[k] = block.inverse.2;
        }
        let lanes = self.points.iter_mut().zip(&mut self.normal_impulses);
        for (((lane, impulse), contacts), p) in lanes.zip(&mut self.contacts).zip(lane_points) {
            contacts[k] = p.contact;
            impulse.0[k] = p.normal_impulse;
            lane.normal_lever_a.0[k] = p.levers.normal.0;
            lane.normal_lever_b.0[k] = p.levers.normal.1;
            lane.reach_a.0[k] = p.levers.reach.0;
            lane.reach_b.0[k] = p.levers.reach.1;
            lane.base_separation.0[k] = p.base_separation;
            lane.normal_mass.0[k] = p.normal_mass;
            lane.tangent_mass.0[k] = p.tangent_mass;
            lane.tangent_impulse.0[k] = p.tangent_impulse;
        }
        let bounces = lane_points[..N].iter().any(|p| p.restitution != 0.0);
        let bit = 1 << k;
        if bounces {
            for (lane, p) in self.bounce.iter_mut().zip(lane_points) {
                lane.restitution.0[k] = p.restitution;
                lane.relative_velocity.0[k] = p.relative_velocity;
                lane.max_normal_impulse.0[k] = p.max_normal_impulse;
                lane.closing_acceleration.0[k] = p.closing_acceleration;
                lane.fastest_impact.0[k] = p.fastest_impact;
            }
        }
        self.bouncing_lanes = if bounces {
            self.bouncing_lanes | bit
        } else {
            self.bouncing_lanes & !bit
        };
    }

    /// The accumulated impulses, into `impulses` at the lanes' contacts.
    pub(super) fn store_impulses(&self, impulses: &mut [(f64, f64)]) {
        let points = self.points.iter().zip(&self.normal_impulses);
        for ((lanes, normal), indices) in points.zip(&self.contacts) {
            for (k, &index) in indices.iter().enumerate().filter(|&(_, &i)| i != PAD) {
                impulses[index as usize] = (normal.0[k], lanes.tangent_impulse.0[k]);
            }
        }
    }

    /// Writes what the passes changed back to the batch's points.
    pub(super) fn scatter(&self, points: &mut [PointConstraint]) {
        for (which, (lp, lb)) in self.points.iter().zip(&self.bounce).enumerate() {
            let normal = self.normal_impulses[which].0;
            let tangent = lp.tangent_impulse.0;
            let max_normal = lb.max_normal_impulse.0;
            let relative = lb.relative_velocity.0;
            for k in (0..LANES).filter(|&k| self.first_point[k] != PAD) {
                let p = &mut points[self.first_point[k] as usize + which];
                p.normal_impulse = normal[k];
                p.tangent_impulse = tangent[k];
                // A point that cannot bounce keeps its own, as the passes leave them.
                if self.bouncing_lanes & (1 << k) != 0 {
                    p.max_normal_impulse = max_normal[k];
                    p.relative_velocity = relative[k];
                }
            }
        }
    }
}

impl<const N: usize, L: Lanes> ManifoldBatch<N, L> {
    /// Whether any lane's points may bounce: only then are `bounce`'s lanes read or
    /// written during the passes (they change nothing where restitution is 0).
    #[inline(always)]
    fn may_bounce(&self) -> bool {
        self.bouncing_lanes != 0
    }

    /// Whether every lane's bodies are in `bodies`: checked once a pass, so that the
    /// gathers need not check each index.
    #[inline(always)]
    fn indices_fit(&self, bodies: &[SoftBody]) -> bool {
        let highest = self.a.iter().chain(&self.b).fold(0, |m, &i| m.max(i));
        (highest as usize) < bodies.len()
    }

    /// # Safety
    /// `indices_fit(bodies)`.
    #[inline(always)]
    unsafe fn load(&self, bodies: &[SoftBody]) -> LanePair<L> {
        // SAFETY: the caller's precondition.
        unsafe {
            LanePair {
                a: LaneVelocity::load(bodies, &self.a),
                b: LaneVelocity::load(bodies, &self.b),
                inv_inertia: (self.inv_inertia_a, self.inv_inertia_b),
            }
        }
    }

    /// A's lanes, then B's, as `BodyPair::store` writes them.
    ///
    /// # Safety
    /// `indices_fit(bodies)`.
    #[inline(always)]
    unsafe fn store(&self, pair: &LanePair<L>, bodies: &mut [SoftBody]) {
        // SAFETY: the caller's precondition.
        unsafe {
            pair.a.store(bodies, &self.a);
            pair.b.store(bodies, &self.b);
        }
    }

    /// `separation` for each lane's point `which`.
    ///
    /// # Safety
    /// `indices_fit(bodies)`.
    #[inline(always)]
    unsafe fn separations(&self, bodies: &[SoftBody]) -> [L; N] {
        // SAFETY (both): the caller's precondition.
        let [dpx_a, dpy_a, cos_a, sin_a] = unsafe { L::gather(bodies, &self.a, BodyRow::Motion) };
        let [dpx_b, dpy_b, cos_b, sin_b] = unsafe { L::gather(bodies, &self.b, BodyRow::Motion) };
        let (dx, dy) = (dpx_a - dpx_b, dpy_a - dpy_b);
        let one = L::splat(1.0);
        let moved = dy.mul_add(self.normal_y, dx * self.normal_x);
        // Written out in the loop: a closure here was left out of line.
        let mut separations = [L::splat(0.0); N];
        for (s, p) in separations.iter_mut().zip(&self.points) {
            let turned_a = sin_a.mul_add(p.normal_lever_a, (cos_a - one) * p.reach_a);
            let turned_b = sin_b.mul_add(p.normal_lever_b, (cos_b - one) * p.reach_b);
            *s = moved + turned_a - turned_b + p.base_separation;
        }
        separations
    }

    /// A two-point manifold's normals, as `solve_pair` solves them: together where both
    /// rows are rigid (the relax pass, or both points speculative), point by point where
    /// a row is a soft spring; in a batch with lanes of both kinds, both are computed and
    /// each lane's chosen.
    #[inline(always)]
    fn solve_normals_together<const BIAS: bool, const BOUNCE: bool>(
        &mut self,
        pair: &mut LanePair<L>,
        separations: &[L],
        targets: &[Target<L>],
    ) {
        let zero = L::splat(0.0);
        let normal = (self.normal_x, self.normal_y);
        let rigid = separations[0].gt(zero) & separations[1].gt(zero);
        let soft = rigid ^ zero.eq(zero);
        if !BIAS || !soft.any() {
            self.solve_normals_as_block::<BOUNCE>(pair, separations, targets);
            return;
        }
        if !rigid.any() {
            let bounce = BOUNCE.then_some(&mut self.bounce[..]);
            let points = (&self.points[..], &mut self.normal_impulses[..], bounce);
            solve_normals_alone::<L, BIAS>(pair, points, normal, separations, targets);
            self.push_to_floors::<BOUNCE>(pair, targets);
            return;
        }
        // Copied before the block changes them: the velocities and impulses, and the
        // bounce lanes of a batch that may bounce.
        let (mut alone, mut impulses) = (*pair, self.normal_impulses);
        let mut bounce = BOUNCE.then_some(self.bounce);
        self.solve_normals_as_block::<BOUNCE>(pair, separations, targets);
        let alone_bounce = bounce.as_mut().map(|b| &mut b[..]);
        let alone_points = (&self.points[..], &mut impulses[..], alone_bounce);
        solve_normals_alone::<L, BIAS>(&mut alone, alone_points, normal, separations, targets);
        *pair = LanePair::select(rigid, *pair, alone);
        for (p, q) in self.normal_impulses.iter_mut().zip(impulses) {
            p.set(rigid.select(*p, q));
        }
        if let Some(bounce) = bounce {
            for (p, q) in self.bounce.iter_mut().zip(bounce) {
                let largest = rigid.select(p.max_normal_impulse, q.max_normal_impulse);
                p.max_normal_impulse.set(largest);
                let fastest = rigid.select(p.relative_velocity, q.relative_velocity);
                p.relative_velocity.set(fastest);
            }
        }
        self.push_to_floors::<BOUNCE>(pair, targets);
    }

    /// `push_to_floors` on every lane where a point sank below its floor (a lane that
    /// did not gets nothing: its rows' LCP is solved by no push).
    #[inline(always)]
    fn push_to_floors<const BOUNCE: bool>(
        &mut self,
        pair: &mut LanePair<L>,
        targets: &[Target<L>],
    ) {
        let zero = L::splat(0.0);
        let normal = (self.normal_x, self.normal_y);
        let points = &self.points[..];
        let v1 = pair.velocity_along(normal, points[0].normal_lever_a, points[0].normal_lever_b);
        let v2 = pair.velocity_along(normal, points[1].normal_lever_a, points[1].normal_lever_b);
        let (r1, r2) = (v1 - targets[0].3, v2 - targets[1].3);
        let (below1, below2) = (r1.lt(zero), r2.lt(zero));
        // a | b as (a ^ b) ^ (a & b): the masks have no "or".
        if !((below1 ^ below2) ^ (below1 & below2)).any() {
            return;
        }
        let [i11, i12, i22] = self.inverse;
        let k12 = self.k12;
        let both = (-(i12.mul_add(r2, i11 * r1)), -(i22.mul_add(r2, i12 * r1)));
        let first = -r1 * points[0].normal_mass;
        let second = -r2 * points[1].normal_mass;
        let take_both = both.0.ge(zero) & both.1.ge(zero);
        let take_first = first.ge(zero) & k12.mul_add(first, r2).ge(zero);
        let take_second = second.ge(zero) & k12.mul_add(second, r1).ge(zero);
        let push1 = take_both.select(both.0, take_first.select(first, zero));
        let push2 = take_both.select(
            both.1,
            take_first.select(zero, take_second.select(second, zero)),
        );
        let points = self.points.iter().zip(&mut self.normal_impulses);
        for (((p, impulse), bounce), push) in points.zip(&mut self.bounce).zip([push1, push2]) {
            let total = *impulse + push;
            apply_normal(pair, (p, impulse), BOUNCE.then_some(bounce), normal, total);
        }
    }

    /// Both points' normal velocities, their approach where they may bounce, and the
    /// 2 × 2 block (`solve_block`).
    #[inline(always)]
    fn solve_normals_as_block<const BOUNCE: bool>(
        &mut self,
        pair: &mut LanePair<L>,
        separations: &[L],
        targets: &[Target<L>],
    ) {
        let normal = (self.normal_x, self.normal_y);
        let points = &self.points[..];
        let v1 = pair.velocity_along(normal, points[0].normal_lever_a, points[0].normal_lever_b);
        let v2 = pair.velocity_along(normal, points[1].normal_lever_a, points[1].normal_lever_b);
        if BOUNCE {
            approach(&mut self.bounce[0], v1, separations[0]);
            approach(&mut self.bounce[1], v2, separations[1]);
        }
        self.solve_block::<BOUNCE>(pair, [v1, v2], [targets[0].0, targets[1].0]);
    }

    /// `solve_normal_pair` on every lane: the active set of each lane's 2 × 2 LCP chosen
    /// by masks. Rigid rows (the relax pass): targets `t1`, `t2`.
    #[inline(always)]
    fn solve_block<const BOUNCE: bool>(
        &mut self,
        pair: &mut LanePair<L>,
        [v1, v2]: [L; 2],
        [t1, t2]: [L; 2],
    ) {
        let zero = L::splat(0.0);
        let points = &self.points[..];
        let [x1, x2] = [self.normal_impulses[0], self.normal_impulses[1]];
        let (k11, k12, k22) = (self.k11, self.k12, self.k22);
        let (kx1, kx2) = (k12.mul_add(x2, k11 * x1), k22.mul_add(x2, k12 * x1));
        let (r1, r2) = ((v1 - t1) - kx1, (v2 - t2) - kx2);
        let [i11, i12, i22] = self.inverse;
        let both = (-(i12.mul_add(r2, i11 * r1)), -(i22.mul_add(r2, i12 * r1)));
        let first = -r1 * points[0].normal_mass;
        let second = -r2 * points[1].normal_mass;
        let take_both = both.0.ge(zero) & both.1.ge(zero);
        let take_first = first.ge(zero) & k12.mul_add(first, r2).ge(zero);
        let take_second = second.ge(zero) & k12.mul_add(second, r1).ge(zero);
        let total1 = take_both.select(both.0, take_first.select(first, zero));
        let total2 = take_both.select(
            both.1,
            take_first.select(zero, take_second.select(second, zero)),
        );
        let normal = (self.normal_x, self.normal_y);
        let points = self.points.iter().zip(&mut self.normal_impulses);
        for (((p, impulse), bounce), total) in points.zip(&mut self.bounce).zip([total1, total2]) {
            apply_normal(pair, (p, impulse), BOUNCE.then_some(bounce), normal, total);
        }
    }
}

impl<const N: usize, L: Lanes> BatchLanes<PassSettings> for ManifoldBatch<N, L> {
    /// `warm_start` for the batch's points.
    #[inline(always)]
    fn warm_start_lanes(&self, bodies: &mut [SoftBody]) {
        assert!(
            self.indices_fit(bodies),
            "a batch's bodies are the solver's"
        );
        // SAFETY: just checked.
        let mut pair = unsafe { self.load(bodies) };
        let normal = (self.normal_x, self.normal_y);
        let tangent = (-self.normal_y, self.normal_x);
        for (p, &impulse) in self.points.iter().zip(&self.normal_impulses) {
            pair.apply_along(normal, p.normal_lever_a, p.normal_lever_b, impulse);
            // The tangent row's levers are the reaches (`PointLevers::tangent`).
            pair.apply_along(tangent, p.reach_a, p.reach_b, p.tangent_impulse);
        }
        // SAFETY: checked above.
        unsafe { self.store(&pair, bodies) };
    }

    /// `solve_pair` on every lane.
    #[inline(always)]
    fn solve_lanes(&mut self, bodies: &mut [SoftBody], pass: &PassSettings) {
        // The relax pass (no bias) has mass scale 1 and impulse scale 0 in every lane;
        // compiled apart, it leaves out the terms they multiply. The same bits: x · 1 is
        // x, and leaving out a term of 0 · y can only turn a zero's sign, which the
        // clamp at 0 (`apply_normal`) then drops. And a batch with no lane that may
        // bounce (every batch of a pile) is compiled without the bounce lanes' code,
        // which otherwise took registers the passes spilled for.
        match (pass.use_bias, self.may_bounce()) {
            (true, false) => self.solve_pass::<true, false>(bodies, pass),
            (false, false) => self.solve_pass::<false, false>(bodies, pass),
            (true, true) => self.solve_pass::<true, true>(bodies, pass),
            (false, true) => self.solve_pass::<false, true>(bodies, pass),
        }
    }
}

impl<const N: usize, L: Lanes> ManifoldBatch<N, L> {
    /// `solve_pair` on every lane, `BIAS` being `pass.use_bias` and `BOUNCE`
    /// `self.may_bounce()`.
    #[inline(always)]
    fn solve_pass<const BIAS: bool, const BOUNCE: bool>(
        &mut self,
        bodies: &mut [SoftBody],
        pass: &PassSettings,
    ) {
        assert!(
            self.indices_fit(bodies),
            "a batch's bodies are the solver's"
        );
        // SAFETY: just checked.
        let (separations, mut pair) = unsafe { (self.separations(bodies), self.load(bodies)) };
        let normal = (self.normal_x, self.normal_y);
        let zero = L::splat(0.0);
        let one = L::splat(1.0);
        // `normal_target`: speculative points close their gap, touching ones are soft
        // with bias (or rigid in the relax pass).
        let fixed = self.fixed.gt(zero);
        let soft = |f: fn(&Softness) -> f64| {
            fixed.select(L::splat(f(&pass.static_soft)), L::splat(f(&pass.soft)))
        };
        let target = |s: L| {
            let speculative = s.gt(zero);
            let (target, mass_scale, impulse_scale) = if BIAS {
                let bias = -(soft(|t| t.bias_rate) * s).max(L::splat(-pass.max_push));
                (bias, soft(|t| t.mass_scale), soft(|t| t.impulse_scale))
            } else {
                (zero, one, zero)
            };
            let floor = if BIAS {
                (-(L::splat(pass.max_depth) + s) * L::splat(pass.inv_h)).min(zero)
            } else {
                L::splat(f64::NEG_INFINITY)
            };
            (
                speculative.select(-s * L::splat(pass.inv_h), target),
                speculative.select(one, mass_scale),
                speculative.select(zero, impulse_scale),
                floor,
            )
        };
        let mut targets = [(zero, zero, zero, zero); N];
        for (t, &s) in targets.iter_mut().zip(&separations) {
            *t = target(s);
        }
        if N == 2 {
            self.solve_normals_together::<BIAS, BOUNCE>(&mut pair, &separations, &targets);
        } else {
            let bounce = BOUNCE.then_some(&mut self.bounce[..]);
            let points = (&self.points[..], &mut self.normal_impulses[..], bounce);
            solve_normals_alone::<L, BIAS>(&mut pair, points, normal, &separations, &targets);
        }
        let tangent = (-self.normal_y, self.normal_x);
        for (p, &normal_impulse) in self.points.iter_mut().zip(&self.normal_impulses) {
            let vt = pair.velocity_along(tangent, p.reach_a, p.reach_b);
            let limit = self.friction * normal_impulse;
            let total = p
                .tangent_mass
                .neg_mul_add(vt, p.tangent_impulse)
                .clamp(-limit, limit);
            let delta = total - p.tangent_impulse;
            p.tangent_impulse.set(total);
            pair.apply_along(tangent, p.reach_a, p.reach_b, delta);
        }
        // SAFETY: checked above.
        unsafe { self.store(&pair, bodies) };
    }
}

/// The points of an unused lane (`PAD`): all zero, between the null body and itself, so
/// that every pass leaves them and the body as they are.
fn unused_lane(null_body: u32) -> [PointConstraint; 2] {
    let point = PointConstraint {
        contact: PAD,
        a: null_body,
        b: null_body,
        normal: Vec2::zeros(),
        levers: PointLevers::default(),
        base_separation: 0.0,
        normal_mass: 0.0,
        tangent_mass: 0.0,
        friction: 0.0,
        restitution: 0.0,
        relative_velocity: 0.0,
        normal_impulse: 0.0,
        tangent_impulse: 0.0,
        max_normal_impulse: 0.0,
        closing_acceleration: 0.0,
        fastest_impact: 0.0,
        pair_coupling: Some(NormalBlock {
            k11: 0.0,
            k12: 0.0,
            k22: 0.0,
            inverse: (0.0, 0.0, 0.0),
        }),
    };
    [point; 2]
}

/// A point's normal target, mass scale and impulse scale (see `normal_target`), lane by
/// lane.
/// A point's normal target, mass scale, impulse scale and, in a biased pass, the least
/// velocity it may keep (`sinking_floor`; −∞ in the relax pass).
type Target<L> = (L, L, L, L);

/// A batch's points, their normal impulses, and their bounce lanes where some lane may
/// bounce.
type PointsOf<'a, L> = (
    &'a [LanePoints<L>],
    &'a mut [L],
    Option<&'a mut [LaneBounce<L>]>,
);

/// `solve_normal` on every lane, point after point.
#[inline(always)]
fn solve_normals_alone<L: Lanes, const BIAS: bool>(
    pair: &mut LanePair<L>,
    (points, impulses, mut bounce): PointsOf<L>,
    normal: (L, L),
    separations: &[L],
    targets: &[Target<L>],
) {
    for (k, (p, impulse)) in points.iter().zip(impulses).enumerate() {
        let (target, mass_scale, impulse_scale, floor) = targets[k];
        let vn = pair.velocity_along(normal, p.normal_lever_a, p.normal_lever_b);
        let mut bounce = bounce.as_deref_mut().map(|b| &mut b[k]);
        if let Some(b) = bounce.as_deref_mut() {
            approach(b, vn, separations[k]);
        }
        let accumulated = *impulse;
        let change = if BIAS {
            let soft =
                impulse_scale.neg_mul_add(accumulated, -p.normal_mass * mass_scale * (vn - target));
            soft.max(-p.normal_mass * (vn - floor))
        } else {
            -p.normal_mass * (vn - target)
        };
        apply_normal(pair, (p, impulse), bounce, normal, accumulated + change);
    }
}

/// `apply_normal` on every lane: the accumulated normal impulse set to `total` (clamped
/// at 0), the difference applied; the largest push kept for points that may bounce.
#[inline(always)]
fn apply_normal<L: Lanes>(
    pair: &mut LanePair<L>,
    (p, impulse): (&LanePoints<L>, &mut L),
    bounce: Option<&mut LaneBounce<L>>,
    normal: (L, L),
    total: L,
) {
    let total = total.max(L::splat(0.0));
    let delta = total - *impulse;
    impulse.set(total);
    if let Some(b) = bounce {
        let elastic = b.restitution.ne(L::splat(0.0));
        let largest = elastic.select(b.max_normal_impulse.max(delta), b.max_normal_impulse);
        b.max_normal_impulse.set(largest);
    }
    pair.apply_along(normal, p.normal_lever_a, p.normal_lever_b, delta);
}

/// `approach` on every lane: the fastest approach of points that may bounce.
#[inline(always)]
fn approach<L: Lanes>(b: &mut LaneBounce<L>, vn: L, separation: L) {
    let zero = L::splat(0.0);
    let may_bounce = b.restitution.ne(zero) & b.max_normal_impulse.eq(zero) & vn.lt(zero);
    if may_bounce.any() {
        let gained = L::splat(2.0) * b.closing_acceleration * separation.max(zero);
        let impact = (-(vn * vn + gained.max(zero)).sqrt()).max(b.fastest_impact);
        let fastest = may_bounce.select(b.relative_velocity.min(impact), b.relative_velocity);
        b.relative_velocity.set(fastest);
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::super::contacts::{solve_pair, solve_point, warm_start_point};
    use super::super::{NormalBlock, PointLevers};
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
