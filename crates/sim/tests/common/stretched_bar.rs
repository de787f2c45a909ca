//! A 10:1 bar pulled along x with both end faces held: in its middle third, away from the
//! clamped ends, the state is free uniaxial tension, the set-up of the closed-form stress
//! and volume tests.

use glam::{UVec3, Vec3};
use incise_sim::grab::Grab;
use incise_sim::selection::NodeSelection;
use incise_sim::{Material, Solver, SolverParams};

use super::{block_mesh, solver_at_kappa};

/// Length and side of the bar, m.
pub const LEN: f32 = 0.1;
/// Side of the square cross-section, m.
pub const SIDE: f32 = 0.01;
/// The middle third's bounding planes, as fractions of the length.
const MIDDLE: (f32, f32) = (0.35, 0.65);

/// The bar after settling at `strain`: 20 × 2 × 2 hexes, no gravity, damping 20/s, κ = 0.02
/// (XPBD's static error is a few per cent at κ = 1), left face pinned, right face grabbed
/// and moved by `strain × LEN` at 0.2 m/s, then 150 frames.
pub fn stretched_bar(m: Material, strain: f32) -> Solver {
    let mesh = block_mesh(
        Vec3::new(0.0, -SIDE / 2.0, -SIDE / 2.0),
        Vec3::new(LEN, SIDE, SIDE),
        UVec3::new(20, 2, 2),
    );
    let params = SolverParams {
        gravity: Vec3::ZERO,
        damping: 20.0,
        threads: 1,
        ..SolverParams::default()
    };
    let mut s = solver_at_kappa(mesh, m, params, 0.02);
    let rest = s.mesh().rest_positions.clone();
    s.pin(&plane_side(&rest, 1e-5, -1.0));
    s.add_grab(Grab {
        nodes: plane_side(&rest, LEN - 1e-5, 1.0),
        waypoints: vec![Vec3::X * (strain * LEN)],
        speed: 0.2,
        start_time: 0.0,
    });
    for _ in 0..150 {
        s.step_frame().unwrap();
    }
    s
}

/// Nodes on the `n` side (±1 along x) of the plane x = `x`.
pub fn plane_side(rest: &[Vec3], x: f32, n: f32) -> Vec<u32> {
    NodeSelection::PlaneSide {
        point: Vec3::new(x, 0.0, 0.0),
        normal: Vec3::X * n,
    }
    .select(rest)
    .unwrap()
}

/// Axial stretch of the middle third: the distance between the mean positions of its two
/// bounding node planes over their rest distance.
pub fn middle_stretch(s: &Solver) -> f32 {
    let (rest, x) = (&s.mesh().rest_positions, s.positions());
    let plane_x = |at: f32| {
        let nodes: Vec<usize> = (0..rest.len())
            .filter(|&i| (rest[i].x - at).abs() < 1e-5)
            .collect();
        nodes.iter().map(|&i| x[i].x).sum::<f32>() / nodes.len() as f32
    };
    let (a0, a1) = (MIDDLE.0 * LEN, MIDDLE.1 * LEN);
    (plane_x(a1) - plane_x(a0)) / (a1 - a0)
}

/// Tets whose rest centroid lies in the middle third.
pub fn middle_tets(s: &Solver) -> Vec<usize> {
    let rest = &s.mesh().rest_positions;
    (0..s.mesh().tet_count())
        .filter(|&t| {
            let c = s.mesh().tets[t]
                .iter()
                .map(|&i| rest[i as usize])
                .sum::<Vec3>()
                / 4.0;
            c.x > MIDDLE.0 * LEN && c.x < MIDDLE.1 * LEN
        })
        .collect()
}

/// Lateral stretch at mid-length: the distance between the ±y faces' nodes on the plane
/// x = LEN/2 over the side.
pub fn middle_lateral_stretch(s: &Solver) -> f32 {
    let (rest, x) = (&s.mesh().rest_positions, s.positions());
    let mid_y = |sign: f32| {
        let nodes: Vec<usize> = (0..rest.len())
            .filter(|&i| {
                (rest[i].x - 0.5 * LEN).abs() < 1e-5 && (rest[i].y - sign * SIDE / 2.0).abs() < 1e-6
            })
            .collect();
        nodes.iter().map(|&i| x[i].y).sum::<f32>() / nodes.len() as f32
    };
    (mid_y(1.0) - mid_y(-1.0)) / SIDE
}
