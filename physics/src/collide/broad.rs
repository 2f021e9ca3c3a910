//! Broad phase: a uniform grid of cells about twice the size of a typical body.
//!
//! Each body is listed in the cells its bounds cover, the list is grouped by cell (a
//! counting sort on a hash of the cell), and only bodies sharing a cell are compared:
//! linear in the number of bodies for piles, grids and blocks alike (a sweep along one
//! axis compares every body with every other in the same column). A body covering more than `MAX_CELLS`
//! cells (a floor, a wall) is compared with every body instead of being listed: cheap
//! while such bodies are few, as they are in a scene of bodies on terrain. A scene of a
//! few bodies (a robot) skips the grid and compares every pair. Deterministic: the pairs
//! come out sorted, whatever the order they were found in.

use super::Aabb;

/// A body covering more cells than this is compared with every body directly.
const MAX_CELLS: i64 = 16;

/// Up to this many pairs are sorted by comparison, more by a radix sort.
const SMALL_SORT: usize = 64;

/// Up to this many bodies are compared pair by pair, without the grid: for a robot's
/// dozen bodies the grid's bookkeeping cost four times the comparisons.
const ALL_PAIRS_LIMIT: usize = 24;

#[derive(Debug, Clone, Default)]
pub(crate) struct BroadPhase {
    /// ((cell x, cell y), body) for every cell each listed body covers, in body order.
    entries: Vec<((i64, i64), u32)>,
    /// The entries grouped by the hash of their cell, each group in body order, with
    /// the hash: `(hash, cell, body)`.
    sorted: Vec<(u32, (i64, i64), u32)>,
    bucket_starts: Vec<u32>,
    spare_pairs: Vec<(u32, u32)>,
    present: Vec<u32>,
    large: Vec<u32>,
    is_large: Vec<bool>,
    /// Each listed body's lower corner cell: the cell of two bodies' overlap's lower
    /// corner is the larger of theirs, x and y apart (the floor is monotonic), found
    /// without converting a coordinate per pair.
    lower_cells: Vec<(i64, i64)>,
    extents: Vec<f64>,
}

/// The cell holding coordinate `v` in a grid of `per_cell` cells per unit: floor(v ·
/// per_cell) without a call to `floor` (the same for every finite value; NaN maps to 0
/// and the infinities to the ends of i64).
pub(super) fn cell_of(v: f64, per_cell: f64) -> i64 {
    let t = v * per_cell;
    let truncated = t as i64;
    truncated - i64::from(t < truncated as f64)
}

/// A grid cell: its column and row.
pub(super) type Cell = (i64, i64);

/// The cells a box covers: from `lower` to `upper` (corners, inclusive), and whether
/// that is no more than `MAX_CELLS` (else the box is compared with every body instead of
/// being listed).
pub(super) struct CellRange {
    pub(super) lower: Cell,
    pub(super) upper: Cell,
    pub(super) small: bool,
}

pub(super) fn cells_of(b: &Aabb, per_cell: f64) -> CellRange {
    let (x0, x1) = (cell_of(b.min.x, per_cell), cell_of(b.max.x, per_cell));
    let (y0, y1) = (cell_of(b.min.y, per_cell), cell_of(b.max.y, per_cell));
    let span = |lo: i64, hi: i64| hi.saturating_sub(lo).saturating_add(1);
    let covered = span(x0, x1).saturating_mul(span(y0, y1));
    CellRange {
        lower: (x0, y0),
        upper: (x1, y1),
        small: (1..=MAX_CELLS).contains(&covered),
    }
}

/// The bits of a cell hash for `entries` entries: about two buckets per entry.
pub(super) fn hash_bits(entries: usize) -> u32 {
    (2 * entries).next_power_of_two().trailing_zeros().max(1)
}

/// A cell's bucket among `1 << bits`.
pub(super) fn cell_hash((x, y): Cell, bits: u32) -> u32 {
    let mixed = (x as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)
        ^ (y as u64).wrapping_mul(0xC2B2_AE3D_27D4_EB4F);
    (mixed >> (64 - bits)) as u32
}

/// Twice the median extent of the boxes of `slots` (1 when that is not a positive number:
/// all of them points); `extents` is scratch.
pub(super) fn cell_size(boxes: &[Option<Aabb>], slots: &[u32], extents: &mut Vec<f64>) -> f64 {
    extents.clear();
    extents.extend(slots.iter().filter_map(|&i| {
        let b = boxes[i as usize]?;
        Some((b.max.x - b.min.x).max(b.max.y - b.min.y))
    }));
    if extents.is_empty() {
        return 1.0;
    }
    let middle = extents.len() / 2;
    let (_, median, _) = extents.select_nth_unstable_by(middle, f64::total_cmp);
    let cell = 2.0 * *median;
    if cell.is_finite() && cell > 0.0 {
        cell
    } else {
        1.0
    }
}

impl BroadPhase {
    /// Candidate pairs `(i, j)`, `i < j`, whose boxes overlap, sorted, skipping pairs that
    /// `wanted` rejects. `boxes[i]` is `None` for bodies that take no part.
    pub(crate) fn pairs(
        &mut self,
        boxes: &[Option<Aabb>],
        wanted: impl FnMut(usize, usize) -> bool,
        out: &mut Vec<(u32, u32)>,
    ) {
        let mut present = std::mem::take(&mut self.present);
        present.clear();
        present.extend((0..boxes.len() as u32).filter(|&i| boxes[i as usize].is_some()));
        self.pairs_among(boxes, &present, wanted, out);
        self.present = present;
    }

    /// `pairs` among the bodies of `slots` (increasing, each with a box) only.
    pub(crate) fn pairs_among(
        &mut self,
        boxes: &[Option<Aabb>],
        slots: &[u32],
        mut wanted: impl FnMut(usize, usize) -> bool,
        out: &mut Vec<(u32, u32)>,
    ) {
        out.clear();
        self.entries.clear();
        self.sorted.clear();
        self.large.clear();
        self.is_large.clear();
        self.is_large.resize(boxes.len(), false);
        if slots.len() <= ALL_PAIRS_LIMIT {
            // A robot's few bodies: every pair, found in sorted order.
            for (k, &i) in slots.iter().enumerate() {
                let bi = boxes[i as usize].expect("present");
                for &j in &slots[k + 1..] {
                    let bj = boxes[j as usize].expect("present");
                    if bi.overlaps(&bj) && wanted(i as usize, j as usize) {
                        out.push((i, j));
                    }
                }
            }
            return;
        }
        let per_cell = 1.0 / cell_size(boxes, slots, &mut self.extents);
        self.lower_cells.clear();
        self.lower_cells.resize(boxes.len(), (0, 0));
        for &i in slots {
            let b = boxes[i as usize].expect("present");
            let CellRange {
                lower: (x0, y0),
                upper: (x1, y1),
                small,
            } = cells_of(&b, per_cell);
            if !small {
                self.large.push(i);
                self.is_large[i as usize] = true;
                continue;
            }
            self.lower_cells[i as usize] = (x0, y0);
            for x in x0..=x1 {
                self.entries.extend((y0..=y1).map(|y| ((x, y), i)));
            }
        }
        self.group_by_cell();
        let mut start = 0;
        while start < self.sorted.len() {
            let bucket = self.sorted[start].0;
            let len = self.sorted[start..]
                .iter()
                .take_while(|e| e.0 == bucket)
                .count();
            let in_bucket = &self.sorted[start..start + len];
            for (k, &(_, cell, i)) in in_bucket.iter().enumerate() {
                let bi = boxes[i as usize].expect("listed bodies have bounds");
                let (xi, yi) = self.lower_cells[i as usize];
                for &(_, other_cell, j) in &in_bucket[k + 1..] {
                    let bj = boxes[j as usize].expect("listed bodies have bounds");
                    let (xj, yj) = self.lower_cells[j as usize];
                    // Not another cell with the same hash; and of two bodies sharing several
                    // cells, paired in one only: the cell of their overlap's lower corner,
                    // which both cover. Within a bucket the entries are in body order: i < j.
                    // The tests are combined without branching, and the pair written and
                    // kept or dropped: each goes either way from pair to pair, so branches
                    // on them are mispredicted often and cost more.
                    let found = (other_cell == cell)
                        & ((xi.max(xj), yi.max(yj)) == cell)
                        & bi.overlaps(&bj);
                    out.push((i, j));
                    out.truncate(out.len() - usize::from(!found));
                }
            }
            start += len;
        }
        // `wanted` only for the overlapping pairs, which it mostly keeps: asked of every
        // pair compared, it cost the joint grid (a search among each body's pins) more
        // than the branches saved.
        out.retain(|&(i, j)| wanted(i as usize, j as usize));
        for &l in &self.large {
            let bl = boxes[l as usize].expect("large bodies have bounds");
            for &j in slots {
                // Two large bodies are paired once, from the lower index.
                let j = j as usize;
                if j == l as usize || self.is_large[j] && j < l as usize {
                    continue;
                }
                let bj = boxes[j].expect("present");
                let (lo, hi) = (j.min(l as usize), j.max(l as usize));
                if bl.overlaps(&bj) && wanted(lo, hi) {
                    out.push((lo as u32, hi as u32));
                }
            }
        }
        self.sort_pairs(out, boxes.len());
    }

    /// Sorts `out` by a radix sort on its two body indices (`< bodies`): linear, where a
    /// comparison sort was a quarter of the broad phase's time on a pile.
    pub(crate) fn sort_pairs(&mut self, out: &mut Vec<(u32, u32)>, bodies: usize) {
        if out.len() <= SMALL_SORT {
            out.sort_unstable(); // a robot's few pairs: cheaper than two counting passes
            return;
        }
        for key in [|p: &(u32, u32)| p.1, |p: &(u32, u32)| p.0] {
            let starts = &mut self.bucket_starts;
            starts.clear();
            starts.resize(bodies + 1, 0);
            for p in out.iter() {
                starts[key(p) as usize + 1] += 1;
            }
            for k in 1..starts.len() {
                starts[k] += starts[k - 1];
            }
            self.spare_pairs.clear();
            self.spare_pairs.resize(out.len(), (0, 0));
            for p in out.iter() {
                let at = &mut starts[key(p) as usize];
                self.spare_pairs[*at as usize] = *p;
                *at += 1;
            }
            std::mem::swap(out, &mut self.spare_pairs);
        }
    }

    /// Groups `entries` into `sorted` by a hash of their cell, in linear time (a counting
    /// sort; a comparison sort of the entries cost more than all of the pairing). Each
    /// group keeps the entries' body order.
    fn group_by_cell(&mut self) {
        let bits = hash_bits(self.entries.len());
        let hash = |cell| cell_hash(cell, bits);
        let starts = &mut self.bucket_starts;
        starts.clear();
        starts.resize((1 << bits) + 1, 0);
        for &(cell, _) in &self.entries {
            starts[hash(cell) as usize + 1] += 1;
        }
        for k in 1..starts.len() {
            starts[k] += starts[k - 1];
        }
        self.sorted.resize(self.entries.len(), (0, (0, 0), 0));
        for &(cell, body) in &self.entries {
            let h = hash(cell);
            let at = &mut starts[h as usize];
            self.sorted[*at as usize] = (h, cell, body);
            *at += 1;
        }
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::math::Vec2;

    fn aabb(x0: f64, y0: f64, x1: f64, y1: f64) -> Option<Aabb> {
        Some(Aabb {
            min: Vec2::new(x0, y0),
            max: Vec2::new(x1, y1),
        })
    }

    /// A deterministic stream of numbers in [0, 1) (xorshift).
    pub(in crate::collide) fn uniform(mut seed: u64) -> impl FnMut() -> f64 {
        move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    fn brute(boxes: &[Option<Aabb>]) -> Vec<(u32, u32)> {
        let mut v = vec![];
        for i in 0..boxes.len() {
            for j in i + 1..boxes.len() {
                if let (Some(a), Some(b)) = (boxes[i], boxes[j])
                    && a.overlaps(&b)
                {
                    v.push((i as u32, j as u32));
                }
            }
        }
        v
    }

    #[test]
    fn finds_exactly_the_overlapping_pairs_as_boxes_move() {
        let mut broad = BroadPhase::default();
        let mut out = vec![];
        // A deterministic cloud of boxes, moved a little each round.
        let mut rnd = uniform(12345);
        let mut centres: Vec<(f64, f64)> = (0..200).map(|_| (rnd() * 50.0, rnd() * 50.0)).collect();
        for round in 0..20 {
            let boxes: Vec<Option<Aabb>> = centres
                .iter()
                .enumerate()
                .map(|(i, &(x, y))| {
                    if (i + round) % 17 == 0 {
                        None
                    } else {
                        aabb(x, y, x + 2.0, y + 1.5)
                    }
                })
                .collect();
            broad.pairs(&boxes, |_, _| true, &mut out);
            assert_eq!(out, brute(&boxes), "round {round}");
            for c in &mut centres {
                c.0 += rnd() - 0.5;
                c.1 += rnd() - 0.5;
            }
        }
    }

    /// Sizes from points to floors, negative and far coordinates: the cells, the large
    /// bodies and the pairs shared by several cells all agree with comparing every pair.
    #[test]
    fn finds_exactly_the_overlapping_pairs_of_mixed_sizes() {
        let mut broad = BroadPhase::default();
        let mut out = vec![];
        let mut rnd = uniform(987654321);
        for (round, offset) in [0.0, -37.3, 1e9].into_iter().enumerate() {
            let boxes: Vec<Option<Aabb>> = (0..300)
                .map(|i| {
                    let (x, y) = (offset + rnd() * 40.0, offset + rnd() * 40.0);
                    let (w, h) = match i % 10 {
                        0 => (0.0, 0.0),
                        1 => (30.0 * rnd(), 0.5),
                        2 => (0.5, 25.0 * rnd()),
                        _ => (2.0 * rnd(), 2.0 * rnd()),
                    };
                    aabb(x, y, x + w, y + h)
                })
                .collect();
            broad.pairs(&boxes, |_, _| true, &mut out);
            let expected = brute(&boxes);
            assert!(expected.len() > 250, "round {round}: a crowded scene");
            assert_eq!(out, expected, "round {round}");
        }
        for count in [3, 30] {
            // Both ways of pairing (all pairs; the grid, whose cell size falls back to 1).
            let points = vec![aabb(1.0, 1.0, 1.0, 1.0); count];
            broad.pairs(&points, |_, _| true, &mut out);
            assert_eq!(out.len(), count * (count - 1) / 2, "{count} points alone");
            assert_eq!(out, brute(&points));
        }
        broad.pairs(&[], |_, _| true, &mut out);
        assert!(out.is_empty());
    }

    #[test]
    fn filter_drops_pairs() {
        let mut broad = BroadPhase::default();
        let mut out = vec![];
        let boxes = [
            aabb(0., 0., 1., 1.),
            aabb(0.5, 0.5, 2., 2.),
            aabb(0.9, 0.9, 3., 3.),
        ];
        broad.pairs(&boxes, |i, j| (i, j) != (0, 1), &mut out);
        assert_eq!(out, vec![(0, 2), (1, 2)]);
    }

    /// The same through the grid (more bodies than `ALL_PAIRS_LIMIT`), large bodies among
    /// them: exactly the overlapping pairs `wanted` keeps, in order.
    #[test]
    fn filter_drops_pairs_found_by_the_grid() {
        let mut broad = BroadPhase::default();
        let mut out = vec![];
        let mut rnd = uniform(2468);
        let boxes: Vec<Option<Aabb>> = (0..200)
            .map(|i| {
                let (x, y) = (rnd() * 30.0, rnd() * 30.0);
                let w = if i % 50 == 0 { 25.0 } else { 1.5 };
                aabb(x, y, x + w, y + 1.5)
            })
            .collect();
        let wanted = |i: usize, j: usize| !(i + j).is_multiple_of(3);
        broad.pairs(&boxes, wanted, &mut out);
        let expected: Vec<(u32, u32)> = brute(&boxes)
            .into_iter()
            .filter(|&(i, j)| wanted(i as usize, j as usize))
            .collect();
        assert!(expected.len() > 100 && expected.len() < brute(&boxes).len());
        assert_eq!(out, expected);
    }
}
