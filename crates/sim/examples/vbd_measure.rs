//! VBD measurement table (docs/physics-notes.md, "Vertex Block Descent (measured)"): a
//! measurement, not a test, so a command:
//! `VBD_GRID="1x5,4x10" cargo run --release -p incise-sim --example vbd_measure`.
//! Prints, per (substeps, iterations): stable?, the cantilever's tip sag and the pull's
//! mean von Mises stress against the 200-substep XPBD answer, and ms per frame.
//! The open cantilever requirement (issue 31: VBD within 5 % of XPBD-200) is measured by
//! `VBD_GRID=15x20 VBD_RHO=0.9 VBD_SCENES=beam cargo run --release -p incise-sim --example
//! vbd_measure` (docs/physics-notes.md, "Open item"); `VBD_SCENES=implicit,implicit-tight
//! VBD_GRID=` measures the scenes' default scheme (implicit Euler by Newton) on the same
//! cantilever, at its default settings and solved tight.

#[path = "../tests/vbd_support/mod.rs"]
mod vbd_support;

use incise_sim::vbd::VbdSolver;
use vbd_support::*;

/// `VBD_GRID` = comma-separated `SUBSTEPSxITERATIONS`, default a small grid.
fn grid() -> Vec<(u32, u32)> {
    let text =
        std::env::var("VBD_GRID").unwrap_or_else(|_| "1x5,1x10,1x20,2x10,4x5,4x10,8x5,15x5".into());
    text.split(',')
        .filter_map(|p| {
            let (a, b) = p.trim().split_once('x')?;
            Some((a.parse().ok()?, b.parse().ok()?))
        })
        .collect()
}

fn hz() -> f32 {
    std::env::var("VBD_HZ")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(72.0)
}

/// `VBD_GUESS` = previous | inertia | gravity | adaptive (default), `VBD_RHO` = Chebyshev ρ,
/// `VBD_KD` = Rayleigh k_d (s), applied to every VBD run.
fn tune(p: &mut incise_sim::vbd::VbdParams) {
    use incise_sim::vbd::InitialGuess;
    p.threads = threads();
    p.initial_guess = match std::env::var("VBD_GUESS").as_deref() {
        Ok("previous") => InitialGuess::Previous,
        Ok("inertia") => InitialGuess::Inertia,
        Ok("gravity") => InitialGuess::InertiaAndGravity,
        _ => InitialGuess::Adaptive,
    };
    p.chebyshev_rho = std::env::var("VBD_RHO").ok().and_then(|s| s.parse().ok());
    p.stiffness_damping = std::env::var("VBD_KD")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(0.0);
}

fn threads() -> usize {
    std::env::var("VBD_THREADS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(2)
}

/// Frames of the cantilever run: settle, then average.
fn beam_frames(hz: f32) -> (u32, u32) {
    (
        (BEAM_SETTLE_S * hz).round() as u32,
        (BEAM_AVERAGE_S * hz).round() as u32,
    )
}

/// Frames of the pull: to the end of the 1 s pull.
fn pull_frames(hz: f32) -> u32 {
    (PULL / PULL_SPEED * hz).round() as u32
}

/// Tip sag averaged over the window, or None if the run blew up; and median ms/frame.
fn run_vbd_beam(s: &mut VbdSolver, tip: &[u32], hz: f32) -> (Option<f32>, f64) {
    let (settle, avg) = beam_frames(hz);
    let rest = s.mesh().rest_positions.clone();
    let mut ms = Vec::new();
    let mut sum = 0.0;
    for f in 0..settle + avg {
        match s.step_frame() {
            Ok(st) => ms.push(st.solve_ms),
            Err(_) => return (None, median(&mut ms)),
        }
        if f >= settle {
            sum += tip_sag(&rest, s.positions(), tip);
        }
    }
    let sag = sum / avg as f32;
    // Stable: finite and no node 1 m from rest (a sag past the beam's length is reported:
    // it is the beam falling through its under-converged support, not a blow-up).
    let ok = sag.is_finite() && s.displacements().iter().all(|u| u.length() < 1.0);
    (ok.then_some(sag), median(&mut ms))
}

/// The implicit-scheme rows `VBD_SCENES` asks for: `implicit`, the default settings, and
/// `implicit-tight`, Newton run to the static answer of each step (30 iterations, CG to
/// 10⁻⁴, no early stop) besides.
fn implicit_settings(scenes: &str) -> Vec<(&'static str, incise_sim::implicit::NewtonParams)> {
    use incise_sim::implicit::NewtonParams;
    let mut rows = Vec::new();
    if scenes.split(',').any(|s| s.trim() == "implicit") {
        rows.push(("default settings", NewtonParams::default()));
    }
    if scenes.split(',').any(|s| s.trim() == "implicit-tight") {
        let tight = NewtonParams {
            iterations: 30,
            cg_iterations: 1000,
            cg_tolerance: 1e-4,
            gradient_tolerance: 0.0,
            step_tolerance: 0.0,
            ..NewtonParams::default()
        };
        rows.push(("30 iterations, CG to 1e-4", tight));
    }
    rows
}

/// Tip sag of an XPBD or implicit-scheme run averaged over the window (None if a step
/// failed or it ended non-finite), and median ms/frame.
fn run_solver_beam(s: &mut incise_sim::Solver, tip: &[u32], hz: f32) -> (Option<f32>, f64) {
    let (settle, avg) = beam_frames(hz);
    let rest = s.mesh().rest_positions.clone();
    let mut ms = Vec::new();
    let mut sum = 0.0;
    for f in 0..settle + avg {
        let t = std::time::Instant::now();
        if s.step_frame().is_err() {
            return (None, median(&mut ms));
        }
        ms.push(t.elapsed().as_secs_f64() * 1e3);
        if f >= settle {
            sum += tip_sag(&rest, s.positions(), tip);
        }
    }
    let sag = sum / avg as f32;
    (sag.is_finite().then_some(sag), median(&mut ms))
}

/// A cantilever row: `lead` (scene, substeps and iterations columns), stable and the sag
/// against the reference `r` (m), or not stable, and ms a frame.
fn print_beam_row(lead: &str, sag: Option<f32>, r: f32, ms: f64) {
    match sag {
        Some(v) => println!(
            "| {lead} | yes | {:.3} cm | {:+.1} % | {ms:.1} |",
            v * 100.0,
            (v / r - 1.0) * 100.0
        ),
        None => println!("| {lead} | **no** | – | – | {ms:.1} |"),
    }
}

/// `‖a − b‖ / ‖b‖` of two per-tet fields.
fn field_error(a: &[f32], b: &[f32]) -> f32 {
    let d: f64 = a.iter().zip(b).map(|(x, y)| ((x - y) as f64).powi(2)).sum();
    let n: f64 = b.iter().map(|y| (*y as f64).powi(2)).sum();
    (d / n).sqrt() as f32
}

fn run_vbd_pull(s: &mut VbdSolver, hz: f32) -> (Option<f32>, f64) {
    let mut ms = Vec::new();
    for _ in 0..pull_frames(hz) {
        match s.step_frame() {
            Ok(st) => ms.push(st.solve_ms),
            Err(_) => return (None, median(&mut ms)),
        }
    }
    let vm = mean(&s.von_mises());
    // Blown up if any node left a 3× box around the bar.
    let ok = vm.is_finite() && s.positions().iter().all(|p| p.length() < 0.6);
    (ok.then_some(vm), median(&mut ms))
}

fn median(v: &mut [f64]) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(|a, b| a.total_cmp(b));
    v[v.len() / 2]
}

/// Print the table for the grid and settings the environment names.
fn main() {
    let hz = hz();
    let th = threads();
    let xpbd_sub: u32 = std::env::var("VBD_XPBD_SUBSTEPS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(200);
    let scenes = std::env::var("VBD_SCENES").unwrap_or_else(|_| "beam,pull".into());
    let given = |name: &str| std::env::var(name).ok().and_then(|s| s.parse::<f32>().ok());
    let mut pull_field: Vec<f32> = Vec::new();
    let (beam_ref, pull_ref) =
        if let (Some(b), Some(p)) = (given("VBD_BEAM_REF"), given("VBD_PULL_REF")) {
            // References measured by an earlier run of this table (VBD_BEAM_REF m, VBD_PULL_REF Pa).
            (
                Some(b).filter(|_| scenes.contains("beam")),
                Some(p).filter(|_| scenes.contains("pull")),
            )
        } else {
            let mut b = None;
            let mut p = None;
            if scenes.contains("beam") || scenes.contains("implicit") {
                let (mut s, tip) = xpbd_cantilever(hz, xpbd_sub);
                b = Some(
                    run_solver_beam(&mut s, &tip, hz)
                        .0
                        .expect("XPBD reference runs"),
                );
            }
            if scenes.contains("pull") {
                let mut s = xpbd_pull(hz, xpbd_sub);
                for _ in 0..pull_frames(hz) {
                    s.step_frame().expect("XPBD reference runs");
                }
                p = Some(mean(s.von_mises()));
                pull_field = s.von_mises().to_vec();
            }
            (b, p)
        };
    println!(
        "VBD_GUESS {:?}, VBD_RHO {:?}, VBD_KD {:?}",
        std::env::var("VBD_GUESS").ok(),
        std::env::var("VBD_RHO").ok(),
        std::env::var("VBD_KD").ok()
    );
    println!(
        "hz {hz}, threads {th}, Euler–Bernoulli sag {:.3} cm",
        euler_bernoulli_sag() * 100.0
    );
    if let Some(b) = beam_ref {
        println!(
            "XPBD {xpbd_sub} substeps: cantilever sag {:.3} cm",
            b * 100.0
        );
    }
    if let Some(p) = pull_ref {
        println!(
            "XPBD {xpbd_sub} substeps: pull mean von Mises {:.1} kPa",
            p / 1e3
        );
    }
    {
        // Stiffness number κ = h² μ V Σ w|∇|² of the stiffest tet (xpbd::stability) per
        // substep count: the per-vertex ratio of elastic to inertial stiffness that sets
        // how many Gauss–Seidel sweeps a substep needs.
        let mesh = bar_mesh(BEAM_CELLS);
        let w: Vec<f32> = mesh
            .lumped_masses(BOWEL.density)
            .iter()
            .map(|m| 1.0 / m)
            .collect();
        let ks: Vec<String> = [1u32, 2, 4, 8, 15, 200]
            .iter()
            .map(|&n| {
                format!(
                    "{n}: {:.1}",
                    incise_sim::xpbd::stiffness_number(
                        &mesh,
                        &w,
                        BOWEL.lame(),
                        1.0 / (hz * n as f32)
                    )
                    .0
                )
            })
            .collect();
        println!(
            "cantilever stiffness number κ by substeps: {}",
            ks.join(", ")
        );
    }
    println!("| scene | substeps | iterations | stable | value | vs XPBD-{xpbd_sub} | ms/frame |");
    println!("|---|---:|---:|---|---:|---:|---:|");
    for (name, newton) in implicit_settings(&scenes) {
        // The scenes' default scheme on the same beam, damping and frames.
        let r = beam_ref.expect("the implicit rows run the XPBD reference");
        let (mut s, tip) = implicit_cantilever(hz, newton);
        let (sag, ms) = run_solver_beam(&mut s, &tip, hz);
        print_beam_row(
            &format!("cantilever, implicit Euler ({name}) | – | –"),
            sag,
            r,
            ms,
        );
    }
    let scenes_beam = scenes.contains("beam");
    for (sub, it) in grid() {
        if let (Some(r), true) = (beam_ref, scenes_beam) {
            let mut p = vbd_params(hz, sub, it, true, BEAM_DAMPING);
            tune(&mut p);
            let (mut s, tip) = vbd_cantilever(p);
            let (sag, ms) = run_vbd_beam(&mut s, &tip, hz);
            print_beam_row(&format!("cantilever | {sub} | {it}"), sag, r, ms);
        }
        if let Some(r) = pull_ref {
            let mut p = vbd_params(hz, sub, it, false, 1.0);
            tune(&mut p);
            let mut s = vbd_pull(p);
            let (vm, ms) = run_vbd_pull(&mut s, hz);
            match vm {
                Some(v) => {
                    let fe = if pull_field.is_empty() {
                        f32::NAN
                    } else {
                        field_error(&s.von_mises(), &pull_field)
                    };
                    println!(
                        "| pull 100 % | {sub} | {it} | yes | {:.1} kPa | {:+.1} % (field {:.1} %) | {ms:.2} |",
                        v / 1e3,
                        (v / r - 1.0) * 100.0,
                        fe * 100.0
                    )
                }
                None => println!("| pull 100 % | {sub} | {it} | **no** | – | – | {ms:.2} |"),
            }
        }
    }
}
