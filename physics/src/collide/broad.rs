//! Sweep-and-prune broad phase on the x axis.
//!
//! The order of bodies by their lower x bound barely changes between steps, so it is kept
//! and repaired by insertion sort: close to linear per step, and deterministic.

use super::Aabb;

#[derive(Debug, Clone, Default)]
pub struct SweepAndPrune {
    /// Present bodies sorted by lower x bound (ties by index).
    order: Vec<u32>,
    listed: Vec<bool>,
}

impl SweepAndPrune {
    /// Candidate pairs `(i, j)`, `i < j`, whose boxes overlap, sorted, skipping pairs that
    /// `wanted` rejects. `boxes[i]` is `None` for bodies that take no part.
    pub fn pairs(
        &mut self,
        boxes: &[Option<Aabb>],
        mut wanted: impl FnMut(usize, usize) -> bool,
        out: &mut Vec<(u32, u32)>,
    ) {
        out.clear();
        let present = |i: u32| boxes.get(i as usize).is_some_and(Option::is_some);
        self.order.retain(|&i| present(i));
        self.listed.clear();
        self.listed.resize(boxes.len(), false);
        for &i in &self.order {
            self.listed[i as usize] = true;
        }
        for (i, b) in boxes.iter().enumerate() {
            if b.is_some() && !self.listed[i] {
                self.order.push(i as u32);
            }
        }
        let min_x = |i: u32| boxes[i as usize].map_or(f64::INFINITY, |b| b.min.x);
        let before = |a: u32, b: u32| min_x(a).total_cmp(&min_x(b)).then(a.cmp(&b)).is_lt();
        for k in 1..self.order.len() {
            let mut j = k;
            while j > 0 && before(self.order[j], self.order[j - 1]) {
                self.order.swap(j - 1, j);
                j -= 1;
            }
        }
        for (k, &i) in self.order.iter().enumerate() {
            let Some(bi) = boxes[i as usize] else {
                continue;
            };
            for &j in &self.order[k + 1..] {
                let Some(bj) = boxes[j as usize] else {
                    continue;
                };
                if bj.min.x > bi.max.x {
                    break;
                }
                let (lo, hi) = if i < j { (i, j) } else { (j, i) };
                if bi.overlaps(&bj) && wanted(lo as usize, hi as usize) {
                    out.push((lo, hi));
                }
            }
        }
        out.sort_unstable();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Vec2;

    fn aabb(x0: f64, y0: f64, x1: f64, y1: f64) -> Option<Aabb> {
        Some(Aabb {
            min: Vec2::new(x0, y0),
            max: Vec2::new(x1, y1),
        })
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
        let mut sap = SweepAndPrune::default();
        let mut out = vec![];
        // A deterministic cloud of boxes, moved a little each round.
        let mut seed = 12345u64;
        let mut rnd = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
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
            sap.pairs(&boxes, |_, _| true, &mut out);
            assert_eq!(out, brute(&boxes), "round {round}");
            for c in &mut centres {
                c.0 += rnd() - 0.5;
                c.1 += rnd() - 0.5;
            }
        }
    }

    #[test]
    fn filter_drops_pairs() {
        let mut sap = SweepAndPrune::default();
        let mut out = vec![];
        let boxes = [
            aabb(0., 0., 1., 1.),
            aabb(0.5, 0.5, 2., 2.),
            aabb(0.9, 0.9, 3., 3.),
        ];
        sap.pairs(&boxes, |i, j| (i, j) != (0, 1), &mut out);
        assert_eq!(out, vec![(0, 2), (1, 2)]);
    }
}
