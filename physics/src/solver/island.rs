//! Islands: groups of dynamic bodies connected through constraints. Static bodies do not
//! connect islands, so separate piles on one floor are solved separately.

/// Union–find over body slots with path halving; deterministic.
#[derive(Debug, Clone, Default)]
pub struct UnionFind {
    parent: Vec<u32>,
}

impl UnionFind {
    pub fn reset(&mut self, n: usize) {
        self.parent.clear();
        self.parent.extend(0..n as u32);
    }

    pub fn find(&mut self, mut i: u32) -> u32 {
        while self.parent[i as usize] != i {
            let grand = self.parent[self.parent[i as usize] as usize];
            self.parent[i as usize] = grand;
            i = grand;
        }
        i
    }

    /// Joins the sets of `a` and `b`; the smaller root wins, so results do not depend on
    /// the order of unions.
    pub fn union(&mut self, a: u32, b: u32) {
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
pub fn group_by_island(
    count: usize,
    bodies: usize,
    ends: impl Fn(usize) -> (u32, u32),
    dynamic: impl Fn(u32) -> bool,
    uf: &mut UnionFind,
    out: &mut Vec<(u32, u32)>,
) {
    uf.reset(bodies);
    for i in 0..count {
        let (a, b) = ends(i);
        if dynamic(a) && dynamic(b) {
            uf.union(a, b);
        }
    }
    out.clear();
    for i in 0..count {
        let (a, b) = ends(i);
        let root = if dynamic(a) { uf.find(a) } else { uf.find(b) };
        out.push((root, i as u32));
    }
    out.sort_unstable();
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
}
