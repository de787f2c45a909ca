//! Union–find over `0..n` (path halving; the smaller representative stays, so a set is
//! named by its smallest member): what the mesh's connected components, a Nakao star's
//! parts and the coarse level's pieces are grouped with.

/// Disjoint sets over `0..n`.
pub(crate) struct DisjointSets {
    parent: Vec<u32>,
}

impl DisjointSets {
    /// Every element its own set.
    pub(crate) fn new(n: usize) -> Self {
        DisjointSets {
            parent: (0..n as u32).collect(),
        }
    }

    /// The representative of `x`'s set: its smallest member.
    pub(crate) fn find(&mut self, mut x: usize) -> usize {
        while self.parent[x] as usize != x {
            let grand = self.parent[self.parent[x] as usize];
            self.parent[x] = grand;
            x = grand as usize;
        }
        x
    }

    /// Merge the sets of `a` and `b`.
    pub(crate) fn join(&mut self, a: usize, b: usize) {
        let (ra, rb) = (self.find(a), self.find(b));
        let (low, high) = (ra.min(rb), ra.max(rb));
        self.parent[high] = low as u32;
    }

    /// Per element, the smallest member of its set.
    pub(crate) fn first_members(mut self) -> Vec<u32> {
        (0..self.parent.len())
            .map(|x| self.find(x) as u32)
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_smallest_member_names_each_set() {
        let mut s = DisjointSets::new(6);
        s.join(4, 2);
        s.join(5, 4);
        s.join(1, 3);
        assert_eq!(s.first_members(), vec![0, 1, 2, 1, 2, 2]);
    }
}
