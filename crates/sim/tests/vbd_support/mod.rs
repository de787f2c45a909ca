//! Scenes shared by the VBD tests and the VBD measurement table (examples/vbd_measure.rs).
#![allow(dead_code)]

use glam::{UVec3, Vec3};
use incise_sim::generate::block;
use incise_sim::grab::Grab;
use incise_sim::implicit::{NewtonParams, Scheme};
use incise_sim::vbd::{VbdParams, VbdSolver};
use incise_sim::{Material, Solver, SolverParams, TetMesh};

/// Small bowel (issue 17): E = 180 kPa, ν = 0.45, ρ = 1040 kg/m³.
pub const BOWEL: Material = Material {
    youngs_modulus: 1.8e5,
    poisson_ratio: 0.45,
    density: 1040.0,
};

/// Cantilever: 10 × 2 × 2 cm along +x, root face x = 0 clamped, gravity −z.
pub const BEAM_LEN: f32 = 0.10;
/// Side of the beam's square section, m.
pub const BEAM_SIDE: f32 = 0.02;
/// Hexes of the cantilever (2.5 mm cells, 15,360 tets).
pub const BEAM_CELLS: UVec3 = UVec3::new(40, 8, 8);
/// Velocity damping of the cantilever runs, 1/s: ≈ 2ω₁ (ω₁ = 26.7 rad/s, E-B first mode).
pub const BEAM_DAMPING: f32 = 50.0;
/// Simulated time before the sag is averaged, then the averaging window, s.
pub const BEAM_SETTLE_S: f32 = 1.0;
/// Averaging window of the sag, s.
pub const BEAM_AVERAGE_S: f32 = 1.0 / 3.0;

/// Bar of the pull: 10 × 2 × 2 cm, 20 × 4 × 4 hexes (5 mm cells, 1,920 tets).
pub const BAR_CELLS: UVec3 = UVec3::new(20, 4, 4);
/// Pull: +10 cm (100 % strain) at 0.1 m/s, i.e. 1 s.
pub const PULL: f32 = 0.10;
/// Speed of the pull, m/s.
pub const PULL_SPEED: f32 = 0.1;

/// Euler–Bernoulli tip sag `ρ g A L⁴ / (8 E I)` of the cantilever, m.
pub fn euler_bernoulli_sag() -> f32 {
    let a = BEAM_SIDE * BEAM_SIDE;
    let i = BEAM_SIDE.powi(4) / 12.0;
    BOWEL.density * 9.81 * a * BEAM_LEN.powi(4) / (8.0 * BOWEL.youngs_modulus * i)
}

/// A 10 × 2 × 2 cm box from x = 0, centred on the x axis, of `cells` hexes.
pub fn bar_mesh(cells: UVec3) -> TetMesh {
    let raw = block(
        Vec3::new(0.0, -0.5 * BEAM_SIDE, -0.5 * BEAM_SIDE),
        Vec3::new(BEAM_LEN, BEAM_SIDE, BEAM_SIDE),
        cells,
    );
    TetMesh::from_raw(raw).expect("generated block is valid").0
}

/// Nodes with `x ≤ at + 1e-6` (`side < 0`) or `x ≥ at − 1e-6` (`side > 0`).
pub fn end_nodes(mesh: &TetMesh, at: f32, side: f32) -> Vec<u32> {
    (0..mesh.node_count() as u32)
        .filter(|&i| {
            let x = mesh.rest_positions[i as usize].x;
            if side < 0.0 {
                x <= at + 1e-6
            } else {
                x >= at - 1e-6
            }
        })
        .collect()
}

/// Tip sag: −(mean z displacement) of the nodes of the free end face, m.
pub fn tip_sag(rest: &[Vec3], x: &[Vec3], tip: &[u32]) -> f32 {
    let s: f32 = tip
        .iter()
        .map(|&i| rest[i as usize].z - x[i as usize].z)
        .sum();
    s / tip.len() as f32
}

/// The pull's grab: the right end moved +`PULL` in x at `PULL_SPEED`.
pub fn pull_grab(mesh: &TetMesh) -> Grab {
    Grab {
        nodes: end_nodes(mesh, BEAM_LEN, 1.0),
        waypoints: vec![Vec3::new(PULL, 0.0, 0.0)],
        speed: PULL_SPEED,
        start_time: 0.0,
    }
}

/// VBD settings for a scene.
pub fn vbd_params(
    hz: f32,
    substeps: u32,
    iterations: u32,
    gravity: bool,
    damping: f32,
) -> VbdParams {
    VbdParams {
        frame_dt: 1.0 / hz,
        substeps,
        iterations,
        gravity: if gravity {
            Vec3::new(0.0, 0.0, -9.81)
        } else {
            Vec3::ZERO
        },
        damping,
        ..VbdParams::default()
    }
}

/// The cantilever on VBD.
pub fn vbd_cantilever(params: VbdParams) -> (VbdSolver, Vec<u32>) {
    let mesh = bar_mesh(BEAM_CELLS);
    let root = end_nodes(&mesh, 0.0, -1.0);
    let tip = end_nodes(&mesh, BEAM_LEN, 1.0);
    let mut s = VbdSolver::new(mesh, BOWEL, params).expect("valid VBD settings");
    s.pin(&root);
    (s, tip)
}

/// The cantilever on XPBD (rest-free pair, the solver's defaults otherwise).
pub fn xpbd_cantilever(hz: f32, substeps: u32) -> (Solver, Vec<u32>) {
    scheme_cantilever(hz, substeps, Scheme::Xpbd)
}

/// The cantilever on the implicit scheme (`NewtonParams::default()`: one implicit Euler
/// step a frame, the scenes' default scheme), the same damping as the XPBD runs.
pub fn implicit_cantilever(hz: f32, newton: NewtonParams) -> (Solver, Vec<u32>) {
    scheme_cantilever(hz, 1, Scheme::Newton(newton))
}

fn scheme_cantilever(hz: f32, substeps: u32, scheme: Scheme) -> (Solver, Vec<u32>) {
    let mesh = bar_mesh(BEAM_CELLS);
    let root = end_nodes(&mesh, 0.0, -1.0);
    let tip = end_nodes(&mesh, BEAM_LEN, 1.0);
    let params = SolverParams {
        scheme,
        frame_dt: 1.0 / hz,
        substeps,
        gravity: Vec3::new(0.0, 0.0, -9.81),
        damping: BEAM_DAMPING,
        release_threshold: None,
        ..SolverParams::default()
    };
    let mut s = Solver::new(mesh, BOWEL, params).expect("valid XPBD settings");
    s.pin(&root);
    (s, tip)
}

/// The 100 % pull on VBD.
pub fn vbd_pull(params: VbdParams) -> VbdSolver {
    let mesh = bar_mesh(BAR_CELLS);
    let root = end_nodes(&mesh, 0.0, -1.0);
    let grab = pull_grab(&mesh);
    let mut s = VbdSolver::new(mesh, BOWEL, params).expect("valid VBD settings");
    s.pin(&root);
    s.add_grab(grab);
    s
}

/// The 100 % pull on XPBD.
pub fn xpbd_pull(hz: f32, substeps: u32) -> Solver {
    let mesh = bar_mesh(BAR_CELLS);
    let root = end_nodes(&mesh, 0.0, -1.0);
    let grab = pull_grab(&mesh);
    let params = SolverParams {
        frame_dt: 1.0 / hz,
        substeps,
        gravity: Vec3::ZERO,
        damping: 1.0,
        release_threshold: None,
        ..SolverParams::default()
    };
    let mut s = Solver::new(mesh, BOWEL, params).expect("valid XPBD settings");
    s.pin(&root);
    s.add_grab(grab);
    s
}

/// Mean of a slice.
pub fn mean(v: &[f32]) -> f32 {
    v.iter().map(|&x| x as f64).sum::<f64>() as f32 / v.len() as f32
}
