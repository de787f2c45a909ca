//! Property tests of the Nakao cutter (PHYSICS.md §2.3–2.4): random blade strokes across
//! random small meshes keep every topology invariant, and an adaptive advance never creates
//! a tet whose smallest dihedral angle is below the worst of the non-adaptive split of the
//! same advance.

use glam::{DVec3, UVec3, Vec3};
use incise_sim::generate::block;
use incise_sim::mass_spring::{AxisMask, MassSpringModel, MassSpringParams, Tension};
use incise_sim::mesh::TetMesh;
use incise_sim::nakao_cut::invariants::check;
use incise_sim::nakao_cut::{BladePose, CutParams, Cutter, Subdivision};
use proptest::prelude::*;

/// A jittered block of Kuhn-split hexes, 1 cm cells.
fn mesh(cells: (u32, u32, u32), jitter: &[f32]) -> Option<TetMesh> {
    let c = UVec3::new(cells.0, cells.1, cells.2);
    let mut raw = block(Vec3::ZERO, c.as_vec3() * 0.01, c);
    for (i, p) in raw.positions.iter_mut().enumerate() {
        let j = |k: usize| jitter[(3 * i + k) % jitter.len()] * 0.002;
        *p += Vec3::new(j(0), j(1), j(2));
    }
    let (mesh, _) = TetMesh::from_raw(raw).ok()?;
    let min_dihedral = incise_sim::mesh::quality::assess(&incise_sim::RawMesh {
        positions: mesh.rest_positions.clone(),
        tets: mesh.tets.clone(),
        ..Default::default()
    })
    .dihedral_min_deg;
    (min_dihedral > 5.0).then_some(mesh)
}

#[derive(Debug, Clone)]
struct Stroke {
    centre: DVec3,
    travel: DVec3,
    blade: DVec3,
    half_length: f64,
    steps: usize,
    step: f64,
}

fn stroke() -> impl Strategy<Value = Stroke> {
    (
        prop::array::uniform3(0.0f64..0.03),
        prop::array::uniform3(-1.0f64..1.0),
        prop::array::uniform3(-1.0f64..1.0),
        prop_oneof![Just(0.1), 0.002f64..0.02],
        1usize..6,
        0.001f64..0.012,
    )
        .prop_filter_map("blade parallel to its travel", |(c, t, b, h, n, s)| {
            let travel = DVec3::from(t).try_normalize()?;
            let blade = DVec3::from(b)
                .reject_from_normalized(travel)
                .try_normalize()?;
            Some(Stroke {
                centre: DVec3::from(c),
                travel,
                blade,
                half_length: h,
                steps: n,
                step: s,
            })
        })
}

fn model(mesh: &TetMesh, tension: f64) -> MassSpringModel {
    let params = MassSpringParams {
        tension: Tension::Uniform(tension),
        ..MassSpringParams::default()
    };
    let mut m = MassSpringModel::new(mesh, params).unwrap();
    let floor: Vec<u32> = (0..m.node_count() as u32)
        .filter(|&i| m.positions()[i as usize].z < 1e-3)
        .collect();
    m.fix(&floor, AxisMask::ALL).unwrap();
    m
}

fn pose(s: &Stroke, k: usize) -> BladePose {
    let c = s.centre - s.travel * (0.5 * s.steps as f64 * s.step) + s.travel * (k as f64 * s.step);
    BladePose {
        heel: c - s.blade * s.half_length,
        tip: c + s.blade * s.half_length,
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 40, ..ProptestConfig::default() })]

    #[test]
    fn random_strokes_keep_topology_valid_and_adaptive_never_worse(
        cells in (1u32..4, 1u32..4, 1u32..3),
        jitter in prop::collection::vec(-1.0f32..1.0, 7..31),
        strokes in prop::collection::vec(stroke(), 1..3),
        tension in prop_oneof![Just(0.0), 0.01f64..0.08],
        moving in any::<bool>(),
    ) {
        let Some(mesh) = mesh(cells, &jitter) else { return Ok(()); };
        for sub in [Subdivision::Adaptive, Subdivision::NonAdaptive, Subdivision::Bielser] {
            let mut m = model(&mesh, tension);
            let params = CutParams { subdivision: sub, ..CutParams::default() };
            let mut cutter = Cutter::new(params.clone());
            for s in &strokes {
                cutter.begin(&m, pose(s, 0));
                for k in 1..=s.steps {
                    if sub == Subdivision::Adaptive {
                        // The same advance, non-adaptive, from the same state.
                        let (mut m2, mut c2) = (m.clone(), cutter.clone());
                        c2.set_params(CutParams { subdivision: Subdivision::NonAdaptive, ..params.clone() });
                        let base = c2.advance(&mut m2, pose(s, k));
                        let r = cutter.advance(&mut m, pose(s, k));
                        prop_assert!(
                            r.worst_dihedral_deg >= base.worst_dihedral_deg - 1e-9,
                            "adaptive worst {} < non-adaptive worst {}", r.worst_dihedral_deg, base.worst_dihedral_deg
                        );
                    } else {
                        cutter.advance(&mut m, pose(s, k));
                    }
                    if let Err(e) = check(&m) {
                        prop_assert!(false, "{sub:?}, advance {k} of {s:?}: {e}");
                    }
                    if moving {
                        m.advance(0.002);
                    }
                }
                cutter.end();
            }
        }
    }
}

#[test]
fn a_cut_through_a_block_separates_it_in_two() {
    let mesh = mesh((3, 2, 1), &[0.0]).unwrap();
    let mut m = model(&mesh, 0.0);
    let mut cutter = Cutter::new(CutParams::default());
    let blade = |x: f64| BladePose {
        heel: DVec3::new(x, 0.0123, -0.01),
        tip: DVec3::new(x, 0.0123, 0.03),
    };
    cutter.begin(&m, blade(-0.01));
    let r = cutter.advance(&mut m, blade(0.05));
    check(&m).unwrap();
    assert!(r.opened_faces > 0 && r.duplicated_nodes > 0, "{r:?}");
    // Two face-connected parts now: count components over shared faces.
    let tets = m.tets().to_vec();
    let mut parent: Vec<usize> = (0..tets.len()).collect();
    fn find(p: &mut [usize], mut i: usize) -> usize {
        while p[i] != i {
            p[i] = p[p[i]];
            i = p[i];
        }
        i
    }
    let mut faces = std::collections::HashMap::new();
    for (t, tet) in tets.iter().enumerate() {
        for f in incise_sim::mesh::TET_FACES {
            let mut k = f.map(|l| tet[l]);
            k.sort_unstable();
            if let Some(&o) = faces.get(&k) {
                let (a, b) = (find(&mut parent, t), find(&mut parent, o));
                parent[a] = b;
            } else {
                faces.insert(k, t);
            }
        }
    }
    let roots: std::collections::HashSet<usize> =
        (0..tets.len()).map(|t| find(&mut parent, t)).collect();
    assert_eq!(roots.len(), 2);
    // The opened surface is the block's cross-section, counted on both sides.
    let area = incise_sim::nakao_cut::measure::cut_surface_area(&m);
    assert!((area - 2.0 * 0.03 * 0.01).abs() < 1e-9, "{area}");
}
