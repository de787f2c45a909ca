//! Which tets are live, which faces are visible, which nodes are retired — updated
//! incrementally as tets are released (PHYSICS.md §1.4).

use crate::mesh::{NO_NEIGHBOR, TetMesh};

const NONE: u32 = u32::MAX;

/// The cut state of a mesh: live tets, visible (boundary + cut) faces, retired nodes.
#[derive(Debug, Clone)]
pub struct CutState {
    live: Vec<bool>,
    live_tets_of_node: Vec<u32>,
    /// Visible faces as (tet, local face): faces of live tets with no live neighbour.
    visible: Vec<(u32, u8)>,
    /// Position of (tet, face) in `visible`, or NONE.
    slot: Vec<[u32; 4]>,
    released_count: usize,
    retired_count: usize,
}

/// What one call to [`CutState::release`] changed.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ReleaseEvent {
    /// Tets released now (ascending, previously live).
    pub tets: Vec<u32>,
    /// Nodes that lost their last live tet now.
    pub retired_nodes: Vec<u32>,
}

impl CutState {
    /// All tets live; the visible faces are the mesh boundary.
    pub fn new(mesh: &TetMesh) -> Self {
        let mut slot = vec![[NONE; 4]; mesh.tet_count()];
        for (i, &(t, f)) in mesh.boundary.iter().enumerate() {
            slot[t as usize][f as usize] = i as u32;
        }
        let live_tets_of_node = (0..mesh.node_count())
            .map(|i| mesh.tets_of_node(i).len() as u32)
            .collect();
        CutState {
            live: vec![true; mesh.tet_count()],
            live_tets_of_node,
            visible: mesh.boundary.clone(),
            slot,
            released_count: 0,
            retired_count: 0,
        }
    }

    /// Whether tet `t` still carries its constraints.
    pub fn is_live(&self, t: usize) -> bool {
        self.live[t]
    }

    /// Per-tet live flags.
    pub fn live(&self) -> &[bool] {
        &self.live
    }

    /// Whether node `i` has no live tet left (retired from simulation and rendering).
    pub fn is_retired(&self, i: usize) -> bool {
        self.live_tets_of_node[i] == 0
    }

    /// Visible faces (boundary of the live tets) as (tet, local face).
    pub fn visible_faces(&self) -> &[(u32, u8)] {
        &self.visible
    }

    /// Number of visible faces that are cut surface (their neighbour was released).
    pub fn cut_face_count(&self, mesh: &TetMesh) -> usize {
        self.visible
            .iter()
            .filter(|&&(t, f)| mesh.face_neighbors[t as usize][f as usize] != NO_NEIGHBOR)
            .count()
    }

    /// Tets released so far.
    pub fn released_count(&self) -> usize {
        self.released_count
    }

    /// Nodes retired so far.
    pub fn retired_count(&self) -> usize {
        self.retired_count
    }

    /// Release `tets` (already released ones are ignored): their faces leave the visible
    /// set, faces of live neighbours become visible cut surface, and nodes left without a
    /// live tet retire. Irreversible. Cost is proportional to the released tets only.
    pub fn release(&mut self, mesh: &TetMesh, tets: &[u32]) -> ReleaseEvent {
        let mut ev = ReleaseEvent::default();
        for &t in tets {
            let ti = t as usize;
            if !self.live[ti] {
                continue;
            }
            self.live[ti] = false;
            self.released_count += 1;
            ev.tets.push(t);
            for f in 0..4 {
                self.hide(t, f as u8);
                let n = mesh.face_neighbors[ti][f];
                if n != NO_NEIGHBOR && self.live[n as usize] {
                    let g = mesh.face_neighbors[n as usize]
                        .iter()
                        .position(|&m| m == t)
                        .expect("face adjacency is symmetric");
                    self.show(n, g as u8);
                }
            }
            for &v in &mesh.tets[ti] {
                let c = &mut self.live_tets_of_node[v as usize];
                *c -= 1;
                if *c == 0 {
                    self.retired_count += 1;
                    ev.retired_nodes.push(v);
                }
            }
        }
        ev.tets.sort_unstable();
        ev.retired_nodes.sort_unstable();
        ev
    }

    fn show(&mut self, t: u32, f: u8) {
        if self.slot[t as usize][f as usize] == NONE {
            self.slot[t as usize][f as usize] = self.visible.len() as u32;
            self.visible.push((t, f));
        }
    }

    fn hide(&mut self, t: u32, f: u8) {
        let s = self.slot[t as usize][f as usize];
        if s == NONE {
            return;
        }
        self.slot[t as usize][f as usize] = NONE;
        self.visible.swap_remove(s as usize);
        if let Some(&(mt, mf)) = self.visible.get(s as usize) {
            self.slot[mt as usize][mf as usize] = s;
        }
    }
}
