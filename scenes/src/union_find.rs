//! Disjoint sets of indices (union–find with path halving). The smaller root wins each join, so
//! the sets and their roots do not depend on the order of the joins.

/// Disjoint sets over `0..n`.
#[derive(Clone, Debug)]
pub struct UnionFind(Vec<usize>);

impl UnionFind {
    /// `n` sets of one index each.
    pub fn new(n: usize) -> UnionFind {
        UnionFind((0..n).collect())
    }

    /// The root of `i`'s set: its smallest member.
    pub fn find(&mut self, mut i: usize) -> usize {
        while self.0[i] != i {
            self.0[i] = self.0[self.0[i]];
            i = self.0[i];
        }
        i
    }

    /// Merges the sets of `a` and `b`; the merged set's root is the smaller of their roots.
    pub fn join(&mut self, a: usize, b: usize) {
        let (a, b) = (self.find(a), self.find(b));
        self.0[a.max(b)] = a.min(b);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sets_join_and_keep_their_smallest_member_as_root() {
        let mut sets = UnionFind::new(6);
        sets.join(4, 2);
        sets.join(5, 4);
        sets.join(1, 3);
        assert_eq!(sets.find(5), 2);
        assert_eq!(sets.find(3), 1);
        assert_eq!(sets.find(0), 0);
        sets.join(3, 5);
        assert_eq!((sets.find(2), sets.find(4)), (1, 1));
    }
}
