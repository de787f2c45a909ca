//! Mesh topology after cuts (PHYSICS.md §1.4), checked against brute-force recomputation.
//!
//! On small generated blocks and a small intestine segment, random subsets of tets are
//! released in several random batches through [`Solver::release`] (and, alongside, on a
//! standalone [`CutState`]). After every batch the incremental cut state must agree with a
//! recomputation from scratch that uses only the tet list and the rest positions:
//!
//! - the visible faces are exactly the faces of live tets whose neighbour (found by
//!   matching node triples, not from `face_neighbors`) is absent or released, each once,
//!   with every index in range and no face touching a retired node;
//! - a node is retired exactly when no live tet contains it, the counts match, and the
//!   [`ReleaseEvent`] lists exactly the newly released tets and newly retired nodes;
//! - release is irreversible and idempotent;
//! - node masses are untouched and sum to ρ·(total rest volume), and every tet keeps a
//!   positive rest volume;
//! - `connected_components` of the live tets equals a breadth-first count over shared nodes.

mod common;

use std::collections::{BTreeSet, HashMap, VecDeque};

use glam::{UVec3, Vec3};
use incise_sim::cutting::{CutState, ReleaseEvent};
use incise_sim::generate::{IntestineParams, block, intestine};
use incise_sim::mesh::topology::connected_components;
use incise_sim::mesh::{TET_FACES, shape_matrix};
use incise_sim::xpbd::NodeKind;
use incise_sim::{Material, Solver, SolverParams, TetMesh};
use proptest::collection::vec;
use proptest::prelude::*;
use proptest::sample::Index;

const DENSITY: f32 = 1000.0;

fn material() -> Material {
    common::soft(20e3, 0.45)
}

/// A solver that is never stepped: substeps only need to satisfy the stability check.
fn solver_for(mesh: TetMesh) -> Solver {
    let params = SolverParams {
        threads: 1,
        ..SolverParams::default()
    };
    common::solver(mesh, material(), params)
}

fn block_mesh(cells: UVec3) -> TetMesh {
    TetMesh::from_raw(block(Vec3::ZERO, Vec3::new(0.03, 0.02, 0.02), cells))
        .expect("generated block is valid")
        .0
}

/// 8 around × 1 through the wall × 5 along = 240 tets: every tet touches the outer or the
/// lumen surface, and the tube closes on itself around the circumference.
fn small_intestine() -> TetMesh {
    let p = IntestineParams {
        segments_around: 8,
        layers_through_wall: 1,
        segments_along: 5,
        skin_refine: 1,
        ..IntestineParams::default()
    };
    assert!(p.problems().is_empty(), "{:?}", p.problems());
    let (raw, _skin) = intestine(&p);
    TetMesh::from_raw(raw)
        .expect("generated intestine is valid")
        .0
}

/// Face-adjacency recomputed from node triples: for each tet and local face, the other tet
/// with the same three nodes, if any.
fn brute_neighbors(mesh: &TetMesh) -> Vec<[Option<u32>; 4]> {
    let key = |t: usize, f: usize| {
        let mut k = TET_FACES[f].map(|l| mesh.tets[t][l]);
        k.sort_unstable();
        k
    };
    let mut owners: HashMap<[u32; 3], Vec<u32>> = HashMap::new();
    for t in 0..mesh.tet_count() {
        for f in 0..4 {
            owners.entry(key(t, f)).or_default().push(t as u32);
        }
    }
    assert!(
        owners.values().all(|o| o.len() <= 2),
        "a face is shared by more than two tets"
    );
    (0..mesh.tet_count())
        .map(|t| {
            std::array::from_fn(|f| {
                owners[&key(t, f)]
                    .iter()
                    .copied()
                    .find(|&o| o as usize != t)
            })
        })
        .collect()
}

/// Connected components of the live tets (sharing a node), by breadth-first search over a
/// node → tets table built here from the tet list.
fn brute_components(mesh: &TetMesh, live: &[bool]) -> usize {
    let mut tets_of = vec![Vec::new(); mesh.node_count()];
    for (t, tet) in mesh.tets.iter().enumerate() {
        for &v in tet {
            tets_of[v as usize].push(t);
        }
    }
    let mut seen = vec![false; mesh.tet_count()];
    let mut count = 0;
    for start in 0..mesh.tet_count() {
        if !live[start] || seen[start] {
            continue;
        }
        count += 1;
        seen[start] = true;
        let mut queue = VecDeque::from([start]);
        while let Some(t) = queue.pop_front() {
            for &v in &mesh.tets[t] {
                for &u in &tets_of[v as usize] {
                    if live[u] && !seen[u] {
                        seen[u] = true;
                        queue.push_back(u);
                    }
                }
            }
        }
    }
    count
}

/// Nodes contained in no live tet.
fn brute_retired(mesh: &TetMesh, live: &[bool]) -> Vec<bool> {
    let mut has_live = vec![false; mesh.node_count()];
    for (t, tet) in mesh.tets.iter().enumerate() {
        if live[t] {
            for &v in tet {
                has_live[v as usize] = true;
            }
        }
    }
    has_live.iter().map(|&h| !h).collect()
}

/// Everything observable about a cut state, for before/after comparisons.
fn snapshot(cut: &CutState, n_nodes: usize) -> (Vec<bool>, BTreeSet<(u32, u8)>, Vec<bool>) {
    (
        cut.live().to_vec(),
        cut.visible_faces().iter().copied().collect(),
        (0..n_nodes).map(|i| cut.is_retired(i)).collect(),
    )
}

/// Check `cut` against the brute-force recomputation for the live set `live`.
fn check_state(
    mesh: &TetMesh,
    nbr: &[[Option<u32>; 4]],
    cut: &CutState,
    live: &[bool],
) -> Result<(), TestCaseError> {
    let (nt, nn) = (mesh.tet_count(), mesh.node_count());
    prop_assert_eq!(cut.live(), live);
    for (t, &l) in live.iter().enumerate() {
        prop_assert_eq!(cut.is_live(t), l);
    }
    prop_assert_eq!(cut.released_count(), live.iter().filter(|&&l| !l).count());

    // Visible faces: in range, each once, exactly the brute-force set.
    let visible = cut.visible_faces();
    for &(t, f) in visible {
        prop_assert!(
            (t as usize) < nt && f < 4,
            "face ({t}, {f}) is out of range"
        );
        for v in mesh.face_nodes(t as usize, f as usize) {
            prop_assert!((v as usize) < nn, "face ({t}, {f}) names node {v}");
            prop_assert!(
                !cut.is_retired(v as usize),
                "face ({t}, {f}) uses retired node {v}"
            );
        }
    }
    let got: BTreeSet<(u32, u8)> = visible.iter().copied().collect();
    prop_assert_eq!(got.len(), visible.len(), "a visible face is listed twice");
    let mut want = BTreeSet::new();
    let mut want_cut = 0;
    for t in (0..nt).filter(|&t| live[t]) {
        for (f, &n) in nbr[t].iter().enumerate() {
            match n {
                None => {
                    want.insert((t as u32, f as u8));
                }
                Some(n) if !live[n as usize] => {
                    want.insert((t as u32, f as u8));
                    want_cut += 1;
                }
                Some(_) => {}
            }
        }
    }
    prop_assert_eq!(&got, &want);
    prop_assert_eq!(cut.cut_face_count(mesh), want_cut);

    // Retired nodes.
    let retired = brute_retired(mesh, live);
    for (i, &r) in retired.iter().enumerate() {
        prop_assert_eq!(cut.is_retired(i), r, "node {}", i);
    }
    prop_assert_eq!(cut.retired_count(), retired.iter().filter(|&&r| r).count());

    // Components.
    prop_assert_eq!(
        connected_components(mesh, |t| cut.is_live(t)),
        brute_components(mesh, live)
    );
    Ok(())
}

/// Release `batches` one after another through a solver and a standalone cut state,
/// checking everything after each batch; `release_all` ends with every tet released.
fn run_batches(
    mesh: TetMesh,
    batches: &[Vec<Index>],
    release_all: bool,
) -> Result<(), TestCaseError> {
    let nt = mesh.tet_count();
    let nn = mesh.node_count();
    let nbr = brute_neighbors(&mesh);

    // Rest volumes: positive and equal to det(Dm)/6 from the rest positions.
    for (t, tet) in mesh.tets.iter().enumerate() {
        let x = tet.map(|i| mesh.rest_positions[i as usize]);
        let v = shape_matrix(x[0], x[1], x[2], x[3]).determinant() / 6.0;
        prop_assert!(
            v > 0.0 && mesh.rest_volume[t] > 0.0,
            "tet {t} has volume {v}"
        );
        prop_assert!(
            (v - mesh.rest_volume[t]).abs() <= 1e-4 * v,
            "tet {t}: {v} vs rest"
        );
    }

    let mut solver = solver_for(mesh.clone());
    let mut cut = CutState::new(&mesh);
    let masses = solver.masses().to_vec();
    let total: f64 = masses.iter().map(|&m| m as f64).sum();
    let expected = DENSITY as f64 * mesh.total_rest_volume();
    prop_assert!(
        (total - expected).abs() <= 1e-5 * expected,
        "node masses sum to {total} kg, ρV = {expected} kg"
    );

    let mut live = vec![true; nt];
    check_state(&mesh, &nbr, solver.cut(), &live)?;

    let mut plan: Vec<Vec<u32>> = batches
        .iter()
        .map(|b| b.iter().map(|i| i.index(nt) as u32).collect())
        .collect();
    if release_all {
        plan.push((0..nt as u32).collect());
    }
    for batch in &plan {
        let retired_before = brute_retired(&mesh, &live);
        let mut new_tets: Vec<u32> = batch
            .iter()
            .copied()
            .filter(|&t| live[t as usize])
            .collect();
        new_tets.sort_unstable();
        new_tets.dedup();
        for &t in batch {
            live[t as usize] = false;
        }
        let retired_after = brute_retired(&mesh, &live);
        let new_nodes: Vec<u32> = (0..nn)
            .filter(|&i| retired_after[i] && !retired_before[i])
            .map(|i| i as u32)
            .collect();
        let want = ReleaseEvent {
            tets: new_tets,
            retired_nodes: new_nodes,
        };

        let ev = solver.release(batch);
        prop_assert_eq!(&ev, &want);
        prop_assert_eq!(&cut.release(&mesh, batch), &want);
        check_state(&mesh, &nbr, solver.cut(), &live)?;
        check_state(&mesh, &nbr, &cut, &live)?;

        // The solver freezes exactly the retired nodes and leaves the masses alone.
        for (i, kind) in solver.node_kinds().iter().enumerate() {
            prop_assert_eq!(*kind == NodeKind::Retired, retired_after[i], "node {}", i);
        }
        prop_assert_eq!(solver.masses(), &masses[..]);
        prop_assert_eq!(&solver.mesh().tets, &mesh.tets);
        prop_assert_eq!(&solver.mesh().rest_volume, &mesh.rest_volume);
        for t in (0..nt).filter(|&t| live[t]) {
            prop_assert!(
                solver.mesh().rest_volume[t] > 0.0,
                "live tet {} lost its volume",
                t
            );
        }

        // Idempotent: the same batch again, or everything released so far, changes nothing.
        let before = snapshot(solver.cut(), nn);
        let again: Vec<u32> = (0..nt as u32).filter(|&t| !live[t as usize]).collect();
        prop_assert_eq!(solver.release(batch), ReleaseEvent::default());
        prop_assert_eq!(solver.release(&again), ReleaseEvent::default());
        prop_assert_eq!(cut.release(&mesh, &again), ReleaseEvent::default());
        prop_assert_eq!(snapshot(solver.cut(), nn), before.clone());
        prop_assert_eq!(snapshot(&cut, nn), before);
    }
    if release_all {
        prop_assert!(solver.cut().visible_faces().is_empty());
        prop_assert_eq!(solver.cut().retired_count(), nn);
    }
    Ok(())
}

fn batches(max_len: usize) -> impl Strategy<Value = Vec<Vec<Index>>> {
    vec(vec(any::<Index>(), 0..max_len), 1..6)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn block_topology_after_random_releases(
        cells in (1u32..=3, 1u32..=3, 1u32..=3),
        batches in batches(40),
        release_all in prop::bool::weighted(0.2),
    ) {
        run_batches(block_mesh(UVec3::new(cells.0, cells.1, cells.2)), &batches, release_all)?;
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn intestine_topology_after_random_releases(
        batches in batches(80),
        release_all in prop::bool::weighted(0.2),
    ) {
        run_batches(small_intestine(), &batches, release_all)?;
    }
}
