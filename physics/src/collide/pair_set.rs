//! A fixed set of body pairs, asked about once per overlapping pair in the broad phase.

/// Body pairs `(i, j)`, `i < j` (the pairs a joint or `World::ignore_collisions` keeps
/// apart), indexed by their first body: a query reads only that body's few pairs, where a
/// binary search over all of them would dominate the broad phase of a net of pins.
#[derive(Debug, Clone, Default)]
pub(crate) struct PairSet {
    /// Sorted, without repeats.
    pairs: Vec<(u32, u32)>,
    /// `pairs[starts[i]..starts[i + 1]]` are the pairs whose first body is `i`.
    starts: Vec<u32>,
}

impl PairSet {
    /// Replaces the set with `pairs` (each `(i, j)` with `i < j`, in any order, repeats
    /// allowed).
    pub(crate) fn rebuild(&mut self, pairs: impl IntoIterator<Item = (u32, u32)>) {
        self.pairs.clear();
        self.pairs.extend(pairs);
        self.pairs.sort_unstable();
        self.pairs.dedup();
        let bodies = self.pairs.last().map_or(0, |&(i, _)| i as usize + 1);
        self.starts.clear();
        let mut next = 0;
        for i in 0..=bodies as u32 {
            while self.pairs.get(next).is_some_and(|&(a, _)| a < i) {
                next += 1;
            }
            self.starts.push(next as u32);
        }
    }

    /// Whether `(i, j)`, `i < j`, is in the set.
    pub(crate) fn contains(&self, (i, j): (u32, u32)) -> bool {
        let i = i as usize;
        if i + 1 >= self.starts.len() {
            return false; // no pair begins with a body past the last pair's
        }
        let (start, end) = (self.starts[i] as usize, self.starts[i + 1] as usize);
        self.pairs[start..end]
            .binary_search_by_key(&j, |&(_, b)| b)
            .is_ok()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn holds_exactly_the_pairs_it_was_given() {
        let given = [(3, 7), (0, 1), (3, 4), (0, 1), (5, 9), (3, 9)];
        let mut set = PairSet::default();
        set.rebuild(given);
        for i in 0..12 {
            for j in i + 1..12 {
                assert_eq!(set.contains((i, j)), given.contains(&(i, j)), "({i}, {j})");
            }
        }
        set.rebuild([]);
        assert!(!set.contains((0, 1)));
    }
}
