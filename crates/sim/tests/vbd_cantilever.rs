//! VBD: the 10 × 2 × 2 cm bowel cantilever (E = 180 kPa, ν = 0.45, ρ = 1040 kg/m³, 40 × 8 × 8
//! hexes = 15,360 tets, root face clamped, gravity −z) sags within 5 % of XPBD at 200
//! substeps per 72 Hz frame (same energy and mesh; 1.881 cm measured, Euler–Bernoulli
//! `ρgAL⁴/(8EI)` = 2.126 cm) at 15 substeps per 72 Hz frame, where XPBD explodes at ≤ 12
//! substeps. **It does not pass yet**: at 15 substeps × 20 iterations with Chebyshev
//! (ρ = 0.9), 300 sweeps a frame and far from real time, VBD sags 1.760 cm (−6.4 %; at
//! 15 × 10: −8.5 %, without Chebyshev −22 %; docs/physics-notes.md, "Vertex Block Descent
//! (measured)"). Kept as the open requirement, `#[ignore]`d because it fails and costs
//! ~7 min of CPU. Sag averaged over t = 1.0–1.33 s at damping 2ω₁, as in the table.

mod vbd_support;

use vbd_support::*;

/// Substeps per 72 Hz frame.
const SUBSTEPS: u32 = 15;
/// VBD iterations per substep.
const ITERATIONS: u32 = 20;
/// Chebyshev spectral-radius estimate (15 × 10 without it: −22 %, with it: −8.5 %).
const RHO: f32 = 0.9;

#[test]
#[ignore = "fails today: VBD at 15 × 20 + Chebyshev 0.9 sags 1.760 cm, −6.4 % from XPBD-200 (1.881 cm); 7 min of CPU"]
fn cantilever_sags_within_5_percent_of_xpbd_200() {
    let hz = 72.0;
    let mut p = vbd_params(hz, SUBSTEPS, ITERATIONS, true, BEAM_DAMPING);
    p.chebyshev_rho = Some(RHO);
    let (mut s, tip) = vbd_cantilever(p);
    let rest = s.mesh().rest_positions.clone();
    let settle = (BEAM_SETTLE_S * hz).round() as u32;
    let avg = (BEAM_AVERAGE_S * hz).round() as u32;
    let mut sum = 0.0;
    for f in 0..settle + avg {
        s.step_frame().expect("VBD stays finite");
        if f >= settle {
            sum += tip_sag(&rest, s.positions(), &tip);
        }
    }
    let sag = sum / avg as f32;
    // The reference: XPBD, same energy and mesh, 200 substeps per 72 Hz frame.
    let (mut x, tip_x) = xpbd_cantilever(hz, 200);
    let mut sum_x = 0.0;
    for f in 0..settle + avg {
        x.step_frame().expect("XPBD reference runs");
        if f >= settle {
            sum_x += tip_sag(&rest, x.positions(), &tip_x);
        }
    }
    let reference = sum_x / avg as f32;
    let err = sag / reference - 1.0;
    println!(
        "VBD sag {:.3} cm, XPBD-200 {:.3} cm ({:+.1} %), E-B {:.3} cm",
        sag * 100.0,
        reference * 100.0,
        err * 100.0,
        euler_bernoulli_sag() * 100.0
    );
    assert!(
        err.abs() < 0.05,
        "sag {sag} m vs XPBD-200 {reference} m ({:+.1} %)",
        err * 100.0
    );
}
