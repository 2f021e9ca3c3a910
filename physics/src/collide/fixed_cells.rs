//! The fixed bodies' cells: static and sleeping bodies, which a step does not move,
//! listed in a grid of their own and kept while they stay. The broad phase then grids
//! only the moving bodies and looks each one up here (as Box2D keeps its static bodies in
//! a tree of their own): a terrain of 2,000 tiles is listed once, not at every pairing.

use super::Aabb;
use super::broad::{Cell, CellRange, cell_hash, cell_size, cells_of, hash_bits};

/// A fixed body listed in a cell, with the lower corner cell of those it covers.
#[derive(Debug, Clone, Copy, Default)]
struct Entry {
    cell: Cell,
    body: u32,
    lower: Cell,
}

#[derive(Debug, Clone, Default)]
pub(crate) struct FixedCells {
    per_cell: f64,
    /// An entry for every cell each small fixed body covers, grouped by the cell's hash
    /// (`bits` of it), each group in body order; group `h` is
    /// `entries[starts[h]..starts[h + 1]]`.
    entries: Vec<Entry>,
    bits: u32,
    starts: Vec<u32>,
    next: Vec<u32>,
    unsorted: Vec<Entry>,
    /// The fixed bodies covering more than `broad::MAX_CELLS` cells (a floor), compared
    /// with every moving body, and all the fixed bodies, compared one by one with a moving
    /// body that large.
    large: Vec<u32>,
    all: Vec<u32>,
    extents: Vec<f64>,
}

impl FixedCells {
    /// Lists the bodies of `fixed` (increasing, each with a box) in cells about twice
    /// their median size.
    pub(crate) fn build(&mut self, boxes: &[Option<Aabb>], fixed: &[u32]) {
        self.per_cell = 1.0 / cell_size(boxes, fixed, &mut self.extents);
        let unsorted = &mut self.unsorted;
        unsorted.clear();
        self.large.clear();
        self.all.clear();
        self.all.extend_from_slice(fixed);
        for &f in fixed {
            let b = boxes[f as usize].expect("a fixed body with bounds");
            let CellRange {
                lower: (x0, y0),
                upper: (x1, y1),
                small,
            } = cells_of(&b, self.per_cell);
            if !small {
                self.large.push(f);
                continue;
            }
            for x in x0..=x1 {
                unsorted.extend((y0..=y1).map(|y| Entry {
                    cell: (x, y),
                    body: f,
                    lower: (x0, y0),
                }));
            }
        }
        // Grouped by a counting sort on the cell's hash, which keeps the body order.
        self.bits = hash_bits(unsorted.len());
        let starts = &mut self.starts;
        starts.clear();
        starts.resize((1 << self.bits) + 1, 0);
        for e in unsorted.iter() {
            starts[cell_hash(e.cell, self.bits) as usize + 1] += 1;
        }
        for k in 1..starts.len() {
            starts[k] += starts[k - 1];
        }
        self.entries.clear();
        self.entries.resize(unsorted.len(), Entry::default());
        self.next.clone_from(starts);
        for &e in unsorted.iter() {
            let at = &mut self.next[cell_hash(e.cell, self.bits) as usize];
            self.entries[*at as usize] = e;
            *at += 1;
        }
    }

    /// Appends `(i, j)`, `i < j`, for each body of `moving` and fixed body whose boxes
    /// overlap and which `wanted` keeps, in no particular order. `boxes` must hold the
    /// fixed bodies' boxes as they were built.
    pub(crate) fn pairs_with(
        &self,
        boxes: &[Option<Aabb>],
        moving: &[u32],
        mut wanted: impl FnMut(usize, usize) -> bool,
        out: &mut Vec<(u32, u32)>,
    ) {
        let mut keep = |m: u32, f: u32, bm: &Aabb, out: &mut Vec<(u32, u32)>| {
            let (lo, hi) = (m.min(f), m.max(f));
            if bm.overlaps(&boxes[f as usize].expect("built")) && wanted(lo as usize, hi as usize) {
                out.push((lo, hi));
            }
        };
        for &m in moving {
            let bm = boxes[m as usize].expect("a moving body with bounds");
            let CellRange {
                lower: (x0, y0),
                upper: (x1, y1),
                small,
            } = cells_of(&bm, self.per_cell);
            if !small {
                for &f in &self.all {
                    keep(m, f, &bm, out);
                }
                continue;
            }
            for &f in &self.large {
                keep(m, f, &bm, out);
            }
            for x in x0..=x1 {
                for y in y0..=y1 {
                    let cell = (x, y);
                    let h = cell_hash(cell, self.bits) as usize;
                    let group = self.starts[h] as usize..self.starts[h + 1] as usize;
                    for e in self.entries[group].iter().filter(|e| e.cell == cell) {
                        // Of the cells both cover, the pair is met in one only: that of
                        // their overlap's lower corner.
                        if (x0.max(e.lower.0), y0.max(e.lower.1)) == cell {
                            keep(m, e.body, &bm, out);
                        }
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::broad::tests::uniform;
    use super::*;
    use crate::math::Vec2;

    /// Fixed bodies of every size (points, tiles, floors, walls) and moving ones (small,
    /// and one larger than a grid's worth of cells), far from the origin too: the pairs
    /// are exactly those of comparing every moving body with every fixed one.
    #[test]
    fn finds_exactly_the_overlapping_pairs_of_moving_and_fixed_bodies() {
        let mut rnd = uniform(0x9e37_79b9_7f4a_7c15);
        for offset in [0.0, -53.1, 1e7] {
            let boxes: Vec<Option<Aabb>> = (0..400)
                .map(|i| {
                    let (x, y) = (offset + rnd() * 40.0, offset + rnd() * 40.0);
                    let (w, h) = match i % 11 {
                        0 => (0.0, 0.0),
                        1 => (35.0 * rnd(), 0.5),
                        2 => (0.5, 20.0 * rnd()),
                        3 if i % 3 == 0 => (30.0, 30.0),
                        _ => (2.0 * rnd(), 2.0 * rnd()),
                    };
                    (i % 9 != 4).then(|| Aabb {
                        min: Vec2::new(x, y),
                        max: Vec2::new(x + w, y + h),
                    })
                })
                .collect();
            let present = |i: &u32| boxes[*i as usize].is_some();
            let fixed: Vec<u32> = (0..400).filter(|i| i % 3 != 0).filter(present).collect();
            let moving: Vec<u32> = (0..400).filter(|i| i % 3 == 0).filter(present).collect();
            let wanted = |i: usize, j: usize| !(i + 2 * j).is_multiple_of(13);
            let mut cells = FixedCells::default();
            cells.build(&boxes, &fixed);
            let mut found = vec![];
            cells.pairs_with(&boxes, &moving, wanted, &mut found);
            found.sort_unstable();
            let mut expected = vec![];
            for &m in &moving {
                for &f in &fixed {
                    let (a, b) = (boxes[m as usize].unwrap(), boxes[f as usize].unwrap());
                    let (lo, hi) = (m.min(f), m.max(f));
                    if a.overlaps(&b) && wanted(lo as usize, hi as usize) {
                        expected.push((lo, hi));
                    }
                }
            }
            expected.sort_unstable();
            assert!(expected.len() > 300, "{offset}: {} pairs", expected.len());
            assert_eq!(found, expected, "offset {offset}");
        }
    }
}
