//! The node hierarchy of PHYSICS.md §2.5 (Fig. 9): breadth-first levels over the springs
//! from the node nearest the tool. Nodes up to level d are free; deeper nodes are frozen.

use glam::DVec3;

use super::MassSpringModel;

/// Breadth-first levels from a root node, up to a level and a node budget.
#[derive(Debug, Clone, Default)]
pub struct NodeHierarchy {
    root: Option<u32>,
    /// Nodes in breadth-first order (level by level).
    order: Vec<u32>,
    /// `order[level_start[l]..level_start[l + 1]]` are the nodes of level `l`.
    level_start: Vec<usize>,
    /// Per node: the build stamp that reached it.
    stamp: Vec<u32>,
    epoch: u32,
}

impl NodeHierarchy {
    /// An empty hierarchy.
    pub fn new() -> Self {
        Self::default()
    }

    /// The node nearest `tip`, found by walking the springs downhill from the last root
    /// (a full scan the first time, or when the walk stalls far from the tool).
    pub fn nearest_node(&self, model: &MassSpringModel, tip: DVec3) -> Option<u32> {
        let x = model.positions();
        let Some(mut best) = self.root.filter(|&r| (r as usize) < model.node_count()) else {
            return model.nearest_node(tip);
        };
        loop {
            let d = (x[best as usize] - tip).length_squared();
            let next = model
                .springs_of(best as usize)
                .iter()
                .map(|s| s.node)
                .min_by(|&a, &b| {
                    (x[a as usize] - tip)
                        .length_squared()
                        .total_cmp(&(x[b as usize] - tip).length_squared())
                });
            match next {
                Some(n) if (x[n as usize] - tip).length_squared() < d => best = n,
                _ => return Some(best),
            }
        }
    }

    /// Rebuild from `root`, keeping levels `0..=max_level` but no more than `max_nodes`
    /// nodes (the last level may be partial).
    // PHYSICS.md §2.5: BFS hierarchy from the node nearest the tool.
    pub fn build(&mut self, model: &MassSpringModel, root: u32, max_level: u32, max_nodes: usize) {
        let n = model.node_count();
        if self.stamp.len() < n {
            self.stamp.resize(n, 0);
        }
        self.epoch = self.epoch.wrapping_add(1);
        if self.epoch == 0 {
            self.stamp.iter_mut().for_each(|s| *s = 0);
            self.epoch = 1;
        }
        self.root = Some(root);
        self.order.clear();
        self.level_start.clear();
        if (root as usize) >= n || max_nodes == 0 {
            self.level_start.push(0);
            return;
        }
        self.order.push(root);
        self.stamp[root as usize] = self.epoch;
        self.level_start.extend([0, 1]);
        let mut level = 0;
        while level < max_level as usize && self.order.len() < max_nodes {
            let (begin, end) = (self.level_start[level], self.level_start[level + 1]);
            'grow: for k in begin..end {
                let v = self.order[k];
                for s in model.springs_of(v as usize) {
                    if self.stamp[s.node as usize] != self.epoch {
                        self.stamp[s.node as usize] = self.epoch;
                        self.order.push(s.node);
                        if self.order.len() >= max_nodes {
                            break 'grow;
                        }
                    }
                }
            }
            if self.order.len() == end {
                break;
            }
            self.level_start.push(self.order.len());
            level += 1;
        }
    }

    /// The root of the last build.
    pub fn root(&self) -> Option<u32> {
        self.root
    }

    /// The free nodes: every node of the hierarchy, breadth-first.
    pub fn free_nodes(&self) -> &[u32] {
        &self.order
    }

    /// Number of levels built (level 0 is the root).
    pub fn levels(&self) -> usize {
        self.level_start.len().saturating_sub(1)
    }

    /// The nodes of level `l`.
    pub fn level(&self, l: usize) -> &[u32] {
        match (self.level_start.get(l), self.level_start.get(l + 1)) {
            (Some(&a), Some(&b)) => &self.order[a..b],
            _ => &[],
        }
    }

    /// Whether node `v` is free in the last build.
    pub fn is_free(&self, v: u32) -> bool {
        self.stamp.get(v as usize) == Some(&self.epoch) && self.root.is_some()
    }
}

#[cfg(test)]
mod tests {
    use glam::{UVec3, Vec3};

    use super::*;
    use crate::generate::block;
    use crate::mass_spring::MassSpringParams;
    use crate::mesh::TetMesh;

    fn model() -> MassSpringModel {
        let (mesh, _) = TetMesh::from_raw(block(
            Vec3::ZERO,
            Vec3::new(0.1, 0.1, 0.01),
            UVec3::new(10, 10, 1),
        ))
        .unwrap();
        MassSpringModel::new(&mesh, MassSpringParams::default()).unwrap()
    }

    #[test]
    fn levels_are_spring_distances_from_the_root() {
        let m = model();
        let root = m.nearest_node(DVec3::new(0.05, 0.05, 0.0)).unwrap();
        let mut h = NodeHierarchy::new();
        h.build(&m, root, 3, usize::MAX);
        assert_eq!(h.levels(), 4);
        assert_eq!(h.level(0), &[root]);
        assert_eq!(h.level(1).len(), m.springs_of(root as usize).len());
        for l in 1..4 {
            for &v in h.level(l) {
                // Some neighbour is one level up, none is two levels up.
                let up = |k: usize| {
                    h.level(k)
                        .iter()
                        .any(|&u| m.springs_of(v as usize).iter().any(|s| s.node == u))
                };
                assert!(up(l - 1));
                assert!(l < 2 || !up(l - 2));
            }
        }
        let capped = {
            let mut c = NodeHierarchy::new();
            c.build(&m, root, 10, 40);
            c.free_nodes().len()
        };
        assert_eq!(capped, 40);
    }

    #[test]
    fn nearest_node_walk_agrees_with_a_scan() {
        let m = model();
        let mut h = NodeHierarchy::new();
        h.build(&m, 0, 1, 10);
        for tip in [DVec3::new(0.03, 0.07, 0.0), DVec3::new(0.091, 0.012, 0.01)] {
            let walked = h.nearest_node(&m, tip).unwrap();
            let scanned = m.nearest_node(tip).unwrap();
            let d = |i: u32| (m.positions()[i as usize] - tip).length();
            assert!((d(walked) - d(scanned)).abs() < 1e-12);
        }
    }
}
