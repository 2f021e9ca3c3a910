//! The batches of a plan, kept from step to step and filled colour by colour.

use super::super::bodies::SoftBody;
use super::super::constraints::PointConstraint;
use super::super::lanes::LANES;
use super::{ManifoldBatch, PAD, PassItem};

/// Batches of `N`-point manifolds being filled for one step: the step's are the first
/// `filled`, the rest kept (with their allocation) to be refilled next step.
#[derive(Debug, Clone, Default)]
pub(super) struct BatchPool<const N: usize> {
    pub(super) batches: Vec<ManifoldBatch<N>>,
    filled: usize,
    /// First points of the colour's manifolds waiting for a full batch.
    waiting: [u32; LANES],
    waiting_len: usize,
}

impl<const N: usize> BatchPool<N> {
    pub(super) fn clear(&mut self) {
        self.filled = 0;
        self.waiting_len = 0;
    }

    pub(super) fn filled(&self) -> &[ManifoldBatch<N>] {
        &self.batches[..self.filled]
    }

    pub(super) fn filled_mut(&mut self) -> &mut [ManifoldBatch<N>] {
        &mut self.batches[..self.filled]
    }

    /// Takes the manifold at `first` into the colour's next batch, which goes into
    /// `items` once it holds `LANES`.
    pub(super) fn take(
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
    pub(super) fn end_colour(
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
