//! Choosing the minimal subdivision (PHYSICS.md §2.4, Fig. 7).
//!
//! Every crossed edge is bisected at its crossing point, one edge at a time, each split
//! applied to all tets around the edge. A tet crossed 1–3 ends as 4 tets, one crossed
//! 2–2 as 6, and the mesh stays conforming whatever the order. The order is the only
//! freedom: it decides the diagonals of the quads the cut leaves on the tet faces (and,
//! for the 2–2 pattern, of the cut quad), so the admissible splits are exactly the orders
//! of the crossed edges. The adaptive rule picks the order whose tets have the best
//! dihedral angles — **[reconstructed]**: maximise the smallest dihedral angle, ties
//! broken by the smallest largest angle (the paper's eq. 5 is garbled) — by comparing
//! several orders and improving the best by swaps. The non-adaptive baseline uses a
//! fixed order (by node index).

use glam::DVec3;

use super::crossing::SplitEdge;
use crate::mass_spring::MassSpringModel;
use crate::mesh::quality::dihedral_angles_deg;

/// Quality of a set of tets: dihedral extremes and the sum of the per-tet minima.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SplitQuality {
    /// Smallest dihedral angle, degrees (+∞ for no tets).
    pub min_deg: f64,
    /// Largest dihedral angle, degrees (−∞ for no tets).
    pub max_deg: f64,
    /// Sum over tets of their smallest dihedral angle (a tie-breaker), degrees.
    pub sum_min_deg: f64,
}

impl SplitQuality {
    /// The quality of no tets.
    pub const EMPTY: SplitQuality = SplitQuality {
        min_deg: f64::INFINITY,
        max_deg: f64::NEG_INFINITY,
        sum_min_deg: 0.0,
    };

    /// Quality of one tet with corners `p`.
    pub fn of_tet(p: [DVec3; 4]) -> SplitQuality {
        let a = dihedral_angles_deg(p);
        let min = a.iter().copied().fold(f64::INFINITY, f64::min);
        let max = a.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let min = if min.is_nan() { 0.0 } else { min };
        SplitQuality {
            min_deg: min,
            max_deg: if max.is_nan() { 180.0 } else { max },
            sum_min_deg: min,
        }
    }

    /// The quality of the union of two sets.
    pub fn merge(self, o: SplitQuality) -> SplitQuality {
        SplitQuality {
            min_deg: self.min_deg.min(o.min_deg),
            max_deg: self.max_deg.max(o.max_deg),
            sum_min_deg: self.sum_min_deg + o.sum_min_deg,
        }
    }

    /// Whether `self` is better: larger smallest angle, then smaller largest angle, then
    /// larger sum of minima (differences below 1e-9° are ties).
    pub fn better_than(&self, o: &SplitQuality) -> bool {
        const EPS: f64 = 1e-9;
        if (self.min_deg - o.min_deg).abs() > EPS {
            return self.min_deg > o.min_deg;
        }
        if (self.max_deg - o.max_deg).abs() > EPS {
            return self.max_deg < o.max_deg;
        }
        self.sum_min_deg > o.sum_min_deg + EPS
    }
}

/// Corner positions of the tets a tet with corners `p` (node ids `ids`) becomes when
/// `splits` (edges of this tet) are bisected in the given order.
pub(crate) fn local_split(p: [DVec3; 4], ids: [u32; 4], splits: &[SplitEdge]) -> Vec<[DVec3; 4]> {
    let mut points: Vec<DVec3> = p.to_vec();
    let mut tets: Vec<[u8; 4]> = vec![[0, 1, 2, 3]];
    for e in splits {
        let la = ids.iter().position(|&v| v == e.a);
        let lb = ids.iter().position(|&v| v == e.b);
        let (Some(la), Some(lb)) = (la, lb) else {
            continue;
        };
        let q = points.len() as u8;
        points.push(p[la].lerp(p[lb], e.t));
        let (la, lb) = (la as u8, lb as u8);
        let mut next = Vec::with_capacity(tets.len() + 2);
        for t in tets {
            match (
                t.iter().position(|&v| v == la),
                t.iter().position(|&v| v == lb),
            ) {
                (Some(ia), Some(ib)) => {
                    let (mut c1, mut c2) = (t, t);
                    c1[ib] = q;
                    c2[ia] = q;
                    next.push(c1);
                    next.push(c2);
                }
                _ => next.push(t),
            }
        }
        tets = next;
    }
    tets.iter().map(|t| t.map(|v| points[v as usize])).collect()
}

/// The order in which to bisect the crossed edges, and the quality it gives.
#[derive(Debug, Clone)]
pub(crate) struct SplitPlan {
    /// Indices into the split-edge list, first to last.
    pub order: Vec<usize>,
    /// Quality of the tets the split creates.
    pub quality: SplitQuality,
}

/// The crossed tets and, per tet, which split edges it holds.
struct Affected {
    tets: Vec<u32>,
    edges_of: Vec<Vec<usize>>,
    tets_of_edge: Vec<Vec<usize>>,
}

fn affected(model: &MassSpringModel, split: &[SplitEdge]) -> Affected {
    let mut tets: Vec<u32> = Vec::new();
    let mut edges_of: Vec<Vec<usize>> = Vec::new();
    let mut tets_of_edge = vec![Vec::new(); split.len()];
    let mut index = std::collections::HashMap::new();
    for (k, e) in split.iter().enumerate() {
        for &t in model.tets_of(e.a as usize) {
            if !model.tets()[t as usize].contains(&e.b) {
                continue;
            }
            let i = *index.entry(t).or_insert_with(|| {
                tets.push(t);
                edges_of.push(Vec::new());
                tets.len() - 1
            });
            edges_of[i].push(k);
            tets_of_edge[k].push(i);
        }
    }
    Affected {
        tets,
        edges_of,
        tets_of_edge,
    }
}

/// Evaluates orders over the affected tets with per-tet caching.
struct Evaluator<'a> {
    model: &'a MassSpringModel,
    split: &'a [SplitEdge],
    aff: Affected,
    per_tet: Vec<SplitQuality>,
}

impl Evaluator<'_> {
    fn tet_quality(&self, i: usize, rank: &[usize]) -> SplitQuality {
        let t = self.aff.tets[i] as usize;
        let ids = self.model.tets()[t];
        let x = self.model.reference_positions();
        let p = ids.map(|v| x[v as usize]);
        let mut edges: Vec<usize> = self.aff.edges_of[i].clone();
        edges.sort_by_key(|&k| rank[k]);
        let splits: Vec<SplitEdge> = edges.iter().map(|&k| self.split[k]).collect();
        local_split(p, ids, &splits)
            .into_iter()
            .map(SplitQuality::of_tet)
            .fold(SplitQuality::EMPTY, SplitQuality::merge)
    }

    fn evaluate_all(&mut self, rank: &[usize]) -> SplitQuality {
        self.per_tet = (0..self.aff.tets.len())
            .map(|i| self.tet_quality(i, rank))
            .collect();
        self.total()
    }

    fn total(&self) -> SplitQuality {
        self.per_tet
            .iter()
            .copied()
            .fold(SplitQuality::EMPTY, SplitQuality::merge)
    }
}

fn ranks(order: &[usize]) -> Vec<usize> {
    let mut rank = vec![0; order.len()];
    for (r, &k) in order.iter().enumerate() {
        rank[k] = r;
    }
    rank
}

/// Plan the bisection of `split`: the fixed order (by node index, the non-adaptive
/// baseline) when `optimise` is false, else the best order found.
pub(crate) fn plan_split(
    model: &MassSpringModel,
    split: &[SplitEdge],
    optimise: bool,
) -> SplitPlan {
    let mut ev = Evaluator {
        model,
        split,
        aff: affected(model, split),
        per_tet: Vec::new(),
    };
    let n = split.len();
    let identity: Vec<usize> = (0..n).collect();
    let base_quality = ev.evaluate_all(&ranks(&identity));
    let mut best = SplitPlan {
        order: identity.clone(),
        quality: base_quality,
    };
    if !optimise || n < 2 {
        return best;
    }
    let x = model.reference_positions();
    let length = |k: usize| (x[split[k].a as usize] - x[split[k].b as usize]).length();
    let centred = |k: usize| (split[k].t - 0.5).abs();
    let mut candidates: Vec<Vec<usize>> = Vec::new();
    candidates.push(identity.iter().rev().copied().collect());
    for key in [0, 1, 2, 3] {
        let mut o = identity.clone();
        o.sort_by(|&i, &j| {
            let (a, b) = match key {
                0 => (length(i), length(j)),
                1 => (length(j), length(i)),
                2 => (centred(i), centred(j)),
                _ => (centred(j), centred(i)),
            };
            a.total_cmp(&b)
        });
        candidates.push(o);
    }
    for order in candidates {
        let q = ev.evaluate_all(&ranks(&order));
        if q.better_than(&best.quality) {
            best = SplitPlan { order, quality: q };
        }
    }
    // Improve by swapping neighbours in the order that share a tet.
    let mut order = best.order.clone();
    let mut rank = ranks(&order);
    ev.evaluate_all(&rank);
    let mut current = ev.total();
    for _pass in 0..4 {
        let mut improved = false;
        for i in 0..n - 1 {
            let (e1, e2) = (order[i], order[i + 1]);
            let shared: Vec<usize> = ev.aff.tets_of_edge[e1]
                .iter()
                .copied()
                .filter(|t| ev.aff.tets_of_edge[e2].contains(t))
                .collect();
            if shared.is_empty() {
                continue;
            }
            order.swap(i, i + 1);
            rank[e1] = i + 1;
            rank[e2] = i;
            let saved: Vec<SplitQuality> = shared.iter().map(|&t| ev.per_tet[t]).collect();
            for &t in &shared {
                ev.per_tet[t] = ev.tet_quality(t, &rank);
            }
            let q = ev.total();
            if q.better_than(&current) {
                current = q;
                improved = true;
            } else {
                order.swap(i, i + 1);
                rank[e1] = i;
                rank[e2] = i + 1;
                for (&t, s) in shared.iter().zip(saved) {
                    ev.per_tet[t] = s;
                }
            }
        }
        if !improved {
            break;
        }
    }
    SplitPlan {
        order,
        quality: current,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tet() -> [DVec3; 4] {
        [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z]
    }

    #[test]
    fn one_three_cut_gives_four_tets_and_two_two_cut_six() {
        // Vertex 0 alone on one side: edges 0-1, 0-2, 0-3 crossed.
        let s13 = [(0, 1), (0, 2), (0, 3)].map(|(a, b)| SplitEdge { a, b, t: 0.4 });
        let parts = local_split(tet(), [0, 1, 2, 3], &s13);
        assert_eq!(parts.len(), 4);
        // Vertices 0, 1 against 2, 3.
        let s22 = [(0, 2), (0, 3), (1, 2), (1, 3)].map(|(a, b)| SplitEdge { a, b, t: 0.5 });
        let parts22 = local_split(tet(), [0, 1, 2, 3], &s22);
        assert_eq!(parts22.len(), 6);
        for parts in [parts, parts22] {
            let total: f64 = parts
                .iter()
                .map(|p| (p[1] - p[0]).dot((p[2] - p[0]).cross(p[3] - p[0])) / 6.0)
                .inspect(|v| assert!(*v > 0.0))
                .sum();
            assert!((total - 1.0 / 6.0).abs() < 1e-15);
        }
    }

    #[test]
    fn quality_prefers_larger_minimum_then_smaller_maximum() {
        let a = SplitQuality {
            min_deg: 20.0,
            max_deg: 150.0,
            sum_min_deg: 20.0,
        };
        let b = SplitQuality {
            min_deg: 20.0,
            max_deg: 120.0,
            sum_min_deg: 20.0,
        };
        assert!(b.better_than(&a) && !a.better_than(&b));
        let c = SplitQuality {
            min_deg: 25.0,
            max_deg: 170.0,
            sum_min_deg: 25.0,
        };
        assert!(c.better_than(&b));
    }
}
