//! Greedy graph colouring of tets: no two tets of one colour share a node, so each colour
//! can be projected in parallel (PHYSICS.md §1.2, parallel form).

/// Colour of each tet (0-based) and the number of colours.
///
/// Tets are visited in index order and given the smallest colour not yet used by any tet
/// sharing one of their nodes. Deterministic.
pub fn greedy_tet_colors(node_count: usize, tets: &[[u32; 4]]) -> (Vec<u32>, usize) {
    // Per node, a growable bitset of colours already used by its tets.
    let mut used: Vec<Vec<u64>> = vec![Vec::new(); node_count];
    let mut colors = Vec::with_capacity(tets.len());
    let mut count = 0usize;
    for tet in tets {
        let words = tet
            .iter()
            .map(|&v| used[v as usize].len())
            .max()
            .unwrap_or(0);
        let mut color = None;
        for w in 0..=words {
            let taken = tet
                .iter()
                .map(|&v| used[v as usize].get(w).copied().unwrap_or(0))
                .fold(0u64, |a, b| a | b);
            if taken != u64::MAX {
                color = Some(w * 64 + (!taken).trailing_zeros() as usize);
                break;
            }
        }
        let c = color.unwrap_or(words * 64);
        for &v in tet {
            let bits = &mut used[v as usize];
            if bits.len() <= c / 64 {
                bits.resize(c / 64 + 1, 0);
            }
            bits[c / 64] |= 1 << (c % 64);
        }
        count = count.max(c + 1);
        colors.push(c as u32);
    }
    (colors, count)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tets_sharing_a_node_get_different_colours() {
        let tets = [[0, 1, 2, 3], [1, 2, 3, 4], [5, 6, 7, 8], [0, 5, 9, 10]];
        let (c, n) = greedy_tet_colors(11, &tets);
        assert_eq!(c, vec![0, 1, 0, 1]);
        assert_eq!(n, 2);
    }

    #[test]
    fn more_than_64_colours_are_supported() {
        // 70 tets all sharing node 0 need 70 colours.
        let tets: Vec<[u32; 4]> = (0..70u32)
            .map(|i| [0, 1 + 3 * i, 2 + 3 * i, 3 + 3 * i])
            .collect();
        let (c, n) = greedy_tet_colors(1 + 3 * 70, &tets);
        assert_eq!(n, 70);
        assert_eq!(c[69], 69);
    }
}
