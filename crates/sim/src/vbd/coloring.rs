//! Vertex colouring for the per-vertex Gauss–Seidel sweep of VBD (Chen et al. 2024, §3.4
//! "parallelization": vertices of one colour share no element, so their local solves are
//! independent and may run at once).

/// Greedy colouring of the nodes of `tets` such that no two nodes of one colour share a
/// tet. Returns the colour of each node (nodes in no tet get colour 0) and the colour count.
pub fn greedy_vertex_colors(node_count: usize, tets: &[[u32; 4]]) -> (Vec<u32>, usize) {
    // Node → incident tets (CSR), then greedy smallest-free colour in node order.
    let mut offsets = vec![0u32; node_count + 1];
    for t in tets {
        for &n in t {
            offsets[n as usize + 1] += 1;
        }
    }
    for i in 0..node_count {
        offsets[i + 1] += offsets[i];
    }
    let mut fill = offsets.clone();
    let mut list = vec![0u32; offsets[node_count] as usize];
    for (ti, t) in tets.iter().enumerate() {
        for &n in t {
            list[fill[n as usize] as usize] = ti as u32;
            fill[n as usize] += 1;
        }
    }
    const NONE: u32 = u32::MAX;
    let mut color = vec![NONE; node_count];
    let mut used: Vec<u32> = Vec::new(); // used[c] == node + 1 when c is taken for `node`
    let mut ncolors = 0usize;
    for node in 0..node_count {
        let stamp = node as u32 + 1;
        for &t in &list[offsets[node] as usize..offsets[node + 1] as usize] {
            for &other in &tets[t as usize] {
                let c = color[other as usize];
                if other as usize != node && c != NONE {
                    if used.len() <= c as usize {
                        used.resize(c as usize + 1, 0);
                    }
                    used[c as usize] = stamp;
                }
            }
        }
        let c = (0..)
            .find(|&c| used.get(c).is_none_or(|&s| s != stamp))
            .unwrap_or(0);
        color[node] = c as u32;
        ncolors = ncolors.max(c + 1);
    }
    for c in &mut color {
        if *c == NONE {
            *c = 0;
        }
    }
    (color, ncolors.max(1))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_tet_holds_two_nodes_of_one_colour() {
        let tets = [[0, 1, 2, 3], [1, 2, 3, 4], [2, 3, 4, 5], [0, 5, 6, 7]];
        let (c, n) = greedy_vertex_colors(8, &tets);
        assert!(n >= 4);
        for t in tets {
            for a in 0..4 {
                for b in a + 1..4 {
                    assert_ne!(c[t[a] as usize], c[t[b] as usize], "tet {t:?}");
                }
            }
        }
    }
}
