//! The batches asked for ahead of the passes (prefetched), where the step's batches
//! outgrow the caches.

use super::super::lanes::F64x8;
use super::{LanePoints, ManifoldBatch, PassItem, PassPlan};

/// How many manifolds ahead of the one batched now `plan` asks the cache for the points
/// and bodies of.
pub(super) const PREFETCH_AHEAD: usize = 16;

/// From how many bytes of batches the passes ask for each next batch while solving one
/// (`PassPlan::batches_ahead`). Megabytes of batches come from beyond the caches in every
/// pass, and the first reads of each batch wait unless it was asked for ahead; batches
/// that stay in the caches gain nothing and pay for the asking, so smaller steps do not
/// ask (docs/bench/profile.md, "Asking ahead from 2 MB of batches"). The warm start asks
/// for what it reads too.
const ASK_AHEAD_FROM_BYTES: usize = 2 * 1024 * 1024;

/// Where the step's batches lie (`PassPlan::batches_ahead`), kept apart from their
/// borrow so that a pass holding them mutably can still ask for the next one. The
/// pointers are only ever prefetched from, never read through.
#[derive(Debug, Clone, Copy)]
pub(in crate::solver::soft) struct BatchesAhead {
    pairs: *const ManifoldBatch<2>,
    singles: *const ManifoldBatch<1>,
    on: bool,
}

/// What a batch is asked for ahead of: a pass reads most of it, the warm start less.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(in crate::solver::soft) enum AskedFor {
    Pass,
    WarmStart,
}

impl BatchesAhead {
    /// The same, asking only if `ask` too.
    pub(crate) fn only_if(mut self, ask: bool) -> Self {
        self.on &= ask;
        self
    }

    /// `items` in their order, asking for what `reader` will read of each next one's
    /// batch as the one before is handed out. An iterator rather than a callback, so that
    /// the pass's own loop is compiled with the features of the function it is in.
    #[inline(always)]
    pub(crate) fn asking<'a, I: Iterator<Item = &'a PassItem>>(
        self,
        items: I,
        reader: AskedFor,
    ) -> Asking<'a, I> {
        Asking {
            ahead: self,
            items: items.peekable(),
            reader,
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

/// Asks the cache for the lines holding `values`, ahead of reading them.
#[inline(always)]
pub(super) fn prefetch<T>(values: &[T]) {
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

impl PassPlan {
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
}

impl<const N: usize> ManifoldBatch<N> {
    /// Asks the cache for what a pass reads of the batch at `batch` (all but its bounce
    /// lanes), ahead of solving it. `batch` need not point at a batch (`prefetch_bytes`).
    #[inline(always)]
    fn prefetch(batch: *const Self) {
        prefetch_bytes(batch.cast(), std::mem::offset_of!(Self, bounce));
    }

    /// Asks the cache for what the warm start reads of the batch at `batch` (18 of the 31
    /// lines a pass reads of a two-point batch), as `prefetch`: asking for the whole batch
    /// saves the warm start nothing, asking for these saves it the waits.
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
}

/// `BatchesAhead::asking`'s items.
pub(in crate::solver::soft) struct Asking<'a, I: Iterator<Item = &'a PassItem>> {
    ahead: BatchesAhead,
    items: std::iter::Peekable<I>,
    reader: AskedFor,
}

impl<'a, I: Iterator<Item = &'a PassItem>> Iterator for Asking<'a, I> {
    type Item = &'a PassItem;

    #[inline(always)]
    fn next(&mut self) -> Option<&'a PassItem> {
        let item = self.items.next()?;
        self.ahead.ask_for(self.items.peek().copied(), self.reader);
        Some(item)
    }
}
