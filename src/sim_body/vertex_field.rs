//! A per-tet quantity carried to the vertices for the heat map: each node gets the mean
//! over the live tets that contain it (a node of no live tet gets 0).

/// The mean of `per_tet` over the tets of each of `node_count` nodes that `live` keeps.
pub fn vertex_mean(
    node_count: usize,
    tets: &[[u32; 4]],
    live: impl Fn(usize) -> bool,
    per_tet: &[f32],
) -> Vec<f32> {
    let mut sum = vec![0.0f64; node_count];
    let mut count = vec![0u32; node_count];
    for (t, tet) in tets.iter().enumerate().filter(|(t, _)| live(*t)) {
        for &n in tet {
            sum[n as usize] += per_tet[t] as f64;
            count[n as usize] += 1;
        }
    }
    sum.iter()
        .zip(&count)
        .map(|(&s, &c)| if c == 0 { 0.0 } else { (s / c as f64) as f32 })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shared_nodes_average_their_live_tets() {
        let tets = [[0, 1, 2, 3], [1, 2, 3, 4]];
        let v = vertex_mean(6, &tets, |_| true, &[2.0, 4.0]);
        assert_eq!(v, vec![2.0, 3.0, 3.0, 3.0, 4.0, 0.0]);
        let only_first = vertex_mean(6, &tets, |t| t == 0, &[2.0, 4.0]);
        assert_eq!(only_first[4], 0.0);
        assert_eq!(only_first[1], 2.0);
    }
}
