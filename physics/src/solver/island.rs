//! Islands: groups of dynamic bodies connected through constraints. Static bodies do not
//! connect islands, so separate piles on one floor are solved separately.

/// Union–find over body slots with path halving; deterministic.
#[derive(Debug, Clone, Default)]
pub(crate) struct UnionFind {
    parent: Vec<u32>,
    /// `group_by_island`'s counting sort by root (`counting_sort`'s scratch).
    starts: Vec<u32>,
    /// `group_by_island`'s items in their first order, before the sort.
    unsorted: Vec<(u32, u32)>,
}

impl UnionFind {
    pub(crate) fn reset(&mut self, n: usize) {
        self.parent.clear();
        self.parent.extend(0..n as u32);
    }

    pub(crate) fn find(&mut self, mut i: u32) -> u32 {
        while self.parent[i as usize] != i {
            let grand = self.parent[self.parent[i as usize] as usize];
            self.parent[i as usize] = grand;
            i = grand;
        }
        i
    }

    /// Joins the sets of `a` and `b`; the smaller root wins, so results do not depend on
    /// the order of unions.
    pub(crate) fn union(&mut self, a: u32, b: u32) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            let (lo, hi) = (ra.min(rb), ra.max(rb));
            self.parent[hi as usize] = lo;
        }
    }
}

/// Groups items (constraints) into islands. `ends(i)` gives the two body slots of item `i`
/// and `dynamic(slot)` says whether a body connects. Returns `(island key, item)` pairs
/// sorted by island and then item, so each island's items keep their original order.
pub(crate) fn group_by_island(
    count: usize,
    bodies: usize,
    ends: impl Fn(usize) -> (u32, u32),
    dynamic: impl Fn(u32) -> bool,
    uf: &mut UnionFind,
    out: &mut Vec<(u32, u32)>,
) {
    uf.reset(bodies);
    // Items of one body pair come one after another (a manifold's points): each pair is
    // joined, and its root found, once.
    let mut last_pair = None;
    for i in 0..count {
        let (a, b) = ends(i);
        if last_pair != Some((a, b)) && dynamic(a) && dynamic(b) {
            uf.union(a, b);
        }
        last_pair = Some((a, b));
    }
    out.clear();
    let mut sorted = true;
    let mut last = None;
    for i in 0..count {
        let (a, b) = ends(i);
        let root = match last {
            Some((pair, root)) if pair == (a, b) => root,
            _ if dynamic(a) => uf.find(a),
            _ => uf.find(b),
        };
        last = Some(((a, b), root));
        sorted &= out.last().is_none_or(|&(last, _)| last <= root);
        out.push((root, i as u32));
    }
    if sorted {
        return; // one island, or islands one after another (the items are in order)
    }
    // Stable, so each island's items keep their order: the result of sorting the
    // (root, item) pairs, in O(items + bodies) instead of a comparison sort's
    // O(items log items) (many piles: 30,000 contact points a step).
    std::mem::swap(out, &mut uf.unsorted);
    let by_root = |&(root, _): &(u32, u32)| root as usize;
    counting_sort(&uf.unsorted, bodies, by_root, &mut uf.starts, out);
}

/// `group_by_island` with its last result kept: a pile at rest has the same contacts,
/// between the same bodies, step after step, and then the islands are those it found.
/// The bodies that connect are given as a list of their slots, increasing: a terrain of
/// 2,000 static tiles under a few boxes compares the few, not 2,000 flags.
#[derive(Debug, Clone, Default)]
pub(crate) struct IslandGrouping {
    uf: UnionFind,
    /// The last call's item ends, body count and connecting bodies.
    ends: Vec<(u32, u32)>,
    bodies: usize,
    dynamic_slots: Vec<u32>,
    /// `dynamic_slots` by slot, made when the grouping is found again.
    dynamic: Vec<bool>,
    grouped: Vec<(u32, u32)>,
    /// Whether the last call kept the grouping before it.
    kept: bool,
}

impl IslandGrouping {
    /// Whether the last `group` found the same items and bodies as the call before it, and
    /// so returned the grouping it had: what a caller planned from that grouping stands.
    pub(crate) fn kept(&self) -> bool {
        self.kept
    }

    /// `group_by_island`'s result for these items, with the bodies `dynamic_slots`
    /// (increasing) connecting, found again only if an item's ends or the connecting
    /// bodies differ from the last call's.
    pub(crate) fn group(
        &mut self,
        count: usize,
        bodies: usize,
        ends: impl Fn(usize) -> (u32, u32),
        dynamic_slots: &[u32],
    ) -> &[(u32, u32)] {
        // Items first: a step that changes anything usually changes them early.
        let same = self.ends.len() == count
            && (0..count).all(|i| self.ends[i] == ends(i))
            && self.dynamic_unchanged(bodies, dynamic_slots);
        self.kept = same;
        if !same {
            self.bodies = bodies;
            self.dynamic_slots.clear();
            self.dynamic_slots.extend_from_slice(dynamic_slots);
            self.dynamic.clear();
            self.dynamic.resize(bodies, false);
            for &slot in dynamic_slots {
                self.dynamic[slot as usize] = true;
            }
            self.ends.clear();
            self.ends.extend((0..count).map(&ends));
            // From the copies just taken, not the callers' (larger) items again.
            let (kept_ends, kept_dynamic) = (&self.ends, &self.dynamic);
            group_by_island(
                count,
                bodies,
                |i| kept_ends[i],
                |s| kept_dynamic[s as usize],
                &mut self.uf,
                &mut self.grouped,
            );
        }
        &self.grouped
    }

    /// Whether there are `count` items again and the same bodies connect: then the last
    /// call's grouping (`grouped`) stands if every item's ends are as they were (`ends`),
    /// which this leaves unchecked. A caller that takes it must compare every item's ends
    /// with those before it relies on the grouping, and call `group` if any differs;
    /// `kept` says true until then. (Checking them here would read every item once more:
    /// the big piles' contacts are 3 MB, and their points read each one anyway.)
    pub(crate) fn bodies_kept(
        &mut self,
        count: usize,
        bodies: usize,
        dynamic_slots: &[u32],
    ) -> bool {
        let same = self.ends.len() == count && self.dynamic_unchanged(bodies, dynamic_slots);
        self.kept = same;
        same
    }

    /// Whether there are `bodies` bodies again, the same ones connecting.
    fn dynamic_unchanged(&self, bodies: usize, dynamic_slots: &[u32]) -> bool {
        self.bodies == bodies && self.dynamic_slots == dynamic_slots
    }

    /// The last call's result: `(island key, item)` pairs, as `group` returned them.
    pub(crate) fn grouped(&self) -> &[(u32, u32)] {
        &self.grouped
    }

    /// The last call's items' ends, by item.
    pub(crate) fn ends(&self) -> &[(u32, u32)] {
        &self.ends
    }
}

/// The index range of each island in `grouped` (`group_by_island`'s result, sorted by
/// island).
pub(crate) fn island_ranges(grouped: &[(u32, u32)], ranges: &mut Vec<(usize, usize)>) {
    ranges.clear();
    let mut start = 0;
    while start < grouped.len() {
        let root = grouped[start].0;
        let len = grouped[start..].iter().take_while(|g| g.0 == root).count();
        ranges.push((start, start + len));
        start += len;
    }
}

/// The slots of two increasing lists, increasing, each once.
pub(crate) fn merged_increasing<'a>(a: &'a [u32], b: &'a [u32]) -> impl Iterator<Item = u32> + 'a {
    let (mut a, mut b) = (a.iter().copied().peekable(), b.iter().copied().peekable());
    std::iter::from_fn(move || match (a.peek(), b.peek()) {
        (Some(&x), Some(&y)) => {
            if x <= y {
                a.next();
            }
            if y <= x {
                b.next();
            }
            Some(x.min(y))
        }
        (Some(_), None) => a.next(),
        (None, _) => b.next(),
    })
}

/// `items` sorted stably by `key` (below `keys`) into `out`, in O(items + keys); `starts`
/// is scratch, kept by the caller so that a step allocates nothing.
pub(crate) fn counting_sort<T: Copy>(
    items: &[T],
    keys: usize,
    key: impl Fn(&T) -> usize,
    starts: &mut Vec<u32>,
    out: &mut Vec<T>,
) {
    starts.clear();
    starts.resize(keys + 1, 0);
    for item in items {
        starts[key(item) + 1] += 1;
    }
    for k in 1..starts.len() {
        starts[k] += starts[k - 1];
    }
    out.clear();
    out.extend_from_slice(items); // every slot is overwritten below
    for &item in items {
        let at = &mut starts[key(&item)];
        out[*at as usize] = item;
        *at += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn static_bodies_do_not_join_islands() {
        // Bodies 0..4; 4 is static. Items: (0,1), (1,4), (2,4), (2,3).
        let items = [(0, 1), (1, 4), (2, 4), (2, 3)];
        let mut uf = UnionFind::default();
        let mut out = vec![];
        group_by_island(items.len(), 5, |i| items[i], |s| s != 4, &mut uf, &mut out);
        assert_eq!(out, vec![(0, 0), (0, 1), (2, 2), (2, 3)]);
    }

    /// The kept grouping is found again whenever an item's ends or a body's flag change,
    /// and equals a fresh `group_by_island` every time.
    #[test]
    fn a_kept_grouping_follows_every_change() {
        let mut kept = IslandGrouping::default();
        // Items, the fixed body, whether the grouping is the last call's, and whether
        // `bodies_kept` (which leaves the items' ends unchecked) says it may be.
        type Case<'a> = (&'a [(u32, u32)], u32, bool, bool);
        let cases: [Case; 6] = [
            (&[(0, 1), (1, 4), (2, 4), (2, 3)], 4, false, false),
            (&[(0, 1), (1, 4), (2, 4), (2, 3)], 4, true, true),
            (&[(0, 1), (1, 4), (2, 4), (2, 3)], 1, false, false), // body 1 now fixed
            (&[(0, 1), (1, 4), (2, 4), (3, 2)], 1, false, true),  // only an item's ends
            (&[(0, 1), (1, 4), (2, 4)], 1, false, false),
            (&[(0, 1), (1, 4), (2, 4), (2, 3), (3, 0)], 4, false, false),
        ];
        for (items, fixed, same, bodies_same) in cases {
            let mut uf = UnionFind::default();
            let mut fresh = vec![];
            group_by_island(
                items.len(),
                5,
                |i| items[i],
                |s| s != fixed,
                &mut uf,
                &mut fresh,
            );
            let dynamic: Vec<u32> = (0..5).filter(|&s| s != fixed).collect();
            let bodies_kept = kept.bodies_kept(items.len(), 5, &dynamic);
            assert_eq!(bodies_kept, bodies_same, "{items:?}, body {fixed} fixed");
            if bodies_kept {
                let ends_kept = (0..items.len()).all(|i| kept.ends()[i] == items[i]);
                assert_eq!(ends_kept, same, "{items:?}, body {fixed} fixed");
            }
            let got = kept.group(items.len(), 5, |i| items[i], &dynamic);
            assert_eq!(got, &fresh[..], "{items:?}, body {fixed} fixed");
            assert_eq!(kept.kept(), same, "{items:?}, body {fixed} fixed");
        }
    }

    /// Items whose islands interleave come out as a sort of the (island, item) pairs
    /// would leave them, whichever way they are grouped (a buffer reused between calls).
    #[test]
    fn interleaved_islands_come_out_sorted() {
        let mut uf = UnionFind::default();
        let mut out = vec![];
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut interleaved = 0;
        for round in 0..50 {
            let bodies = 2 + round % 40;
            // Some pairs twice in a row, as a manifold's two points come.
            let items: Vec<(u32, u32)> = (0..3 * bodies)
                .flat_map(|_| {
                    seed ^= seed << 13;
                    seed ^= seed >> 7;
                    seed ^= seed << 17;
                    let a = (seed % bodies as u64) as u32;
                    let b = ((seed >> 20) % bodies as u64) as u32;
                    let twice = (seed >> 40) & 1 == 0;
                    std::iter::repeat_n((a, b), 1 + usize::from(twice))
                })
                .collect();
            let fixed = |s: u32| s % 7 == 3;
            group_by_island(
                items.len(),
                bodies,
                |i| items[i],
                |s| !fixed(s),
                &mut uf,
                &mut out,
            );
            // The islands found another way: each moving body labelled with the smallest
            // body it is linked to (the union's rule), by relaxing the links to a fixpoint.
            let mut label: Vec<u32> = (0..bodies as u32).collect();
            loop {
                let mut changed = false;
                for &(a, b) in &items {
                    if !fixed(a) && !fixed(b) {
                        let low = label[a as usize].min(label[b as usize]);
                        for s in [a, b] {
                            changed |= label[s as usize] != low;
                            label[s as usize] = low;
                        }
                    }
                }
                if !changed {
                    break;
                }
            }
            let mut expected: Vec<(u32, u32)> = (0..items.len())
                .map(|i| {
                    let (a, b) = items[i];
                    let end = if fixed(a) { b } else { a };
                    (label[end as usize], i as u32)
                })
                .collect();
            expected.sort_unstable();
            assert_eq!(out, expected, "round {round}");
            let mut by_item: Vec<(u32, u32)> = out.iter().map(|&(r, i)| (i, r)).collect();
            by_item.sort_unstable();
            assert!(by_item.iter().enumerate().all(|(k, &(i, _))| i == k as u32));
            // Whether the counting sort had work to do here.
            interleaved += usize::from(by_item.windows(2).any(|w| w[1].1 < w[0].1));
        }
        assert!(
            interleaved > 20,
            "only {interleaved} of 50 rounds were out of order"
        );
    }
}
