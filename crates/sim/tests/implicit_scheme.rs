//! The implicit scheme (`solver.scheme: Newton`, `incise_sim::implicit`): a cantilever
//! settles on the static solution of its own mesh, a bar pulled until it tears tears as
//! the XPBD reference does (with the coarse level at rest stiffness and refreshed from the
//! current tangents, and with the Gauss–Seidel smoother), a refreshed coarse level and the
//! Gauss–Seidel smoother save products on a bent beam, the result does not depend on the
//! thread count, and unusable settings are refused naming the field.

mod common;

use glam::{DVec3, UVec3, Vec3};
use incise_sim::implicit::{CoarseRefresh, NewtonParams, Scheme, Smoother};
use incise_sim::xpbd::ConstraintPair;
use incise_sim::{Solver, SolverParams};

/// Newton iterations and CG products enough to converge these small bodies.
const CONVERGED: NewtonParams = NewtonParams {
    steps: 1,
    iterations: 6,
    cg_iterations: 200,
    cg_tolerance: 1e-3,
    gradient_tolerance: 0.0,
    step_tolerance: 0.0,
    coarse_cell: None,
    coarse_refresh: CoarseRefresh::Rest,
    smoother: Smoother::Jacobi,
};

/// A 20 × 2 × 2 cm cantilever (E = 3 MPa, ν = 0.45) pinned at x = 0 under gravity settles
/// within 2 % of the linear static solution of the same mesh (sag ≈ 3 % of its length,
/// where the Neo-Hookean and linear answers agree to well under that).
#[test]
fn a_cantilever_settles_on_the_static_solution_of_its_mesh() {
    let mesh = common::block_mesh(
        Vec3::new(0.0, -0.01, -0.01),
        Vec3::new(0.2, 0.02, 0.02),
        UVec3::new(20, 2, 2),
    );
    let material = common::soft(3e6, 0.45);
    let params = SolverParams {
        scheme: Scheme::Newton(CONVERGED),
        damping: 20.0,
        threads: 1,
        ..SolverParams::default()
    };
    let mut s = Solver::new(mesh.clone(), material, params).expect("no step bound for Newton");
    let root: Vec<u32> = (0..mesh.node_count() as u32)
        .filter(|&i| mesh.rest_positions[i as usize].x < 1e-4)
        .collect();
    s.pin(&root);
    for _ in 0..90 {
        s.step_frame().unwrap();
    }
    let tip: Vec<usize> = (0..mesh.node_count())
        .filter(|&i| mesh.rest_positions[i].x > 0.2 - 1e-4)
        .collect();
    let sag = |z: &dyn Fn(usize) -> f64| -tip.iter().map(|&i| z(i)).sum::<f64>() / tip.len() as f64;
    let x = s.positions();
    let got = sag(&|i| (x[i].z - mesh.rest_positions[i].z) as f64);
    let pinned: Vec<bool> = (0..mesh.node_count())
        .map(|i| root.contains(&(i as u32)))
        .collect();
    let loads: Vec<DVec3> = s
        .masses()
        .iter()
        .map(|&m| DVec3::new(0.0, 0.0, -9.81 * m as f64))
        .collect();
    let u = common::linear_fem::static_displacement(&mesh, material.lame(), &loads, &pinned);
    let want = sag(&|i| u[i].z);
    assert!(want > 0.005, "a sag worth measuring: {want} m");
    assert!(
        (got / want - 1.0).abs() < 0.02,
        "Newton sag {got:.5} m against the static {want:.5} m"
    );
    let report = s.newton_report().expect("the implicit scheme ran");
    assert!(
        report.iterations >= 1 && report.cg_products >= 1,
        "{report:?}"
    );
}

/// The step stop (`step_tolerance`): a stiff cantilever sagging to rest under gravity,
/// with the gradient stop out of reach (1e-6), needs far fewer Newton iterations when
/// Newton also stops after a step that moved no node more than 1 % of an edge, and ends
/// where the run without it ends, within that 1 % of an edge.
#[test]
fn newton_stops_once_its_steps_are_short() {
    let mesh = common::block_mesh(
        Vec3::new(0.0, -0.01, -0.01),
        Vec3::new(0.2, 0.02, 0.02),
        UVec3::new(20, 2, 2),
    );
    let edge = mesh.mean_edge_length();
    let run = |step_tolerance| {
        let params = SolverParams {
            scheme: Scheme::Newton(NewtonParams {
                iterations: 8,
                gradient_tolerance: 1e-6,
                step_tolerance,
                ..NewtonParams::default()
            }),
            damping: 20.0,
            threads: 1,
            ..SolverParams::default()
        };
        let mut s = Solver::new(mesh.clone(), common::soft(3e6, 0.45), params).unwrap();
        let root: Vec<u32> = (0..mesh.node_count() as u32)
            .filter(|&i| mesh.rest_positions[i as usize].x < 1e-4)
            .collect();
        s.pin(&root);
        let mut iterations = 0;
        for _ in 0..60 {
            s.step_frame().unwrap();
            iterations += s.newton_report().unwrap().iterations;
        }
        (s, iterations)
    };
    let (full, full_iterations) = run(0.0);
    let (short, short_iterations) = run(0.01);
    let gap = common::worst_gap(full.positions(), short.positions());
    let sag = common::max_displacement(&full);
    assert!(sag > 0.005, "the beam sags: {sag} m");
    assert!(
        (short_iterations as f64) < 0.6 * full_iterations as f64,
        "{short_iterations} Newton iterations with the step stop, {full_iterations} without"
    );
    assert!(
        gap <= 0.01 * edge,
        "the step stop ends {gap:e} m from the full solve (edge {edge:e} m)"
    );
}

/// The tearing bar under Newton, in steps of the release interval, tears as XPBD at three
/// times its stability bound does: the first release within two frames, the released tets
/// within 15 %, and the live tets fall apart into pieces.
#[test]
fn a_pulled_bar_tears_as_the_xpbd_reference_does() {
    let run = |mut s: Solver| {
        let mut first = None;
        for f in 0..60u32 {
            let st = s.step_frame().unwrap();
            if st.released_now > 0 && first.is_none() {
                first = Some(f);
            }
        }
        (first, s.cut().released_count(), s)
    };
    let bound = common::tearing_bar(1).params().substeps;
    let (ref_first, ref_released, _) = run(common::tearing_bar_with(|p| {
        p.threads = 1;
        p.substeps = 3 * bound;
    }));
    // Steps as long as the release interval (1/240 s): a step of a whole frame releases
    // a frame's overstress at once, and the bar's cascade then runs further (1,148
    // released against 670; docs/physics-notes.md, "The implicit scheme").
    let ref_first = ref_first.expect("XPBD tears");
    // The refreshed coarse level spans the cut with cubes too: it must not hold the two
    // sides together (it only preconditions; a released tet drops out of it).
    for (coarse_refresh, smoother) in [
        (CoarseRefresh::Rest, Smoother::Jacobi),
        (CoarseRefresh::Steps(1), Smoother::Jacobi),
        (CoarseRefresh::Steps(1), Smoother::GaussSeidel),
    ] {
        let (first, released, s) = run(common::tearing_bar_with(|p| {
            p.threads = 1;
            p.scheme = Scheme::Newton(NewtonParams {
                steps: 4,
                coarse_refresh,
                smoother,
                ..CONVERGED
            });
        }));
        let first = first.expect("Newton tears");
        assert!(
            first.abs_diff(ref_first) <= 2,
            "{coarse_refresh:?}, {smoother:?}: first release {first} against {ref_first}"
        );
        let off = released.abs_diff(ref_released) as f64 / ref_released as f64;
        assert!(
            off <= 0.15,
            "{coarse_refresh:?}, {smoother:?}: {released} released against {ref_released}"
        );
        // The cut is open: the live tets fall into two or more pieces.
        let comps =
            incise_sim::mesh::topology::connected_components(s.mesh(), |t| s.cut().is_live(t));
        assert!(
            comps >= 2,
            "{coarse_refresh:?}, {smoother:?}: the bar is still in one piece after tearing"
        );
    }
}

/// The implicit scheme at its defaults gives the same bits on 1, 2 and 3 threads through
/// a tear (its sums run in fixed parts, not one per thread), so pinned scores and goldens
/// do not depend on the machine.
#[test]
fn newton_gives_the_same_bits_on_any_thread_count() {
    let run = |threads: usize| {
        let mut s = common::tearing_bar_with(|p| {
            p.threads = threads;
            p.scheme = Scheme::Newton(NewtonParams::default());
        });
        for _ in 0..45 {
            s.step_frame().unwrap();
        }
        (s.positions().to_vec(), s.cut().live().to_vec())
    };
    let (x1, live1) = run(1);
    assert!(
        live1.iter().any(|l| !l),
        "the pull should release some tets"
    );
    for threads in [2, 3] {
        let (x, live) = run(threads);
        assert!(live == live1, "{threads} threads released another set");
        let same = x.iter().zip(&x1).all(|(a, b)| a.to_array() == b.to_array());
        assert!(same, "{threads} threads moved the nodes elsewhere");
    }
}

/// `Solver::prepare_frame` between frames (as the headset's simulation thread calls it
/// after showing each frame) does the coarse refactorisation after a frame's releases
/// before the next frame takes its pose — its time is the next frame's `ahead_ms` — and
/// changes no bit of the run: the frame does the same work itself otherwise.
#[test]
fn preparing_a_frame_ahead_changes_no_bit() {
    let run = |ahead: bool| {
        let mut s = common::tearing_bar_with(|p| {
            p.threads = 1;
            p.scheme = Scheme::Newton(NewtonParams::default());
        });
        let mut frames = Vec::new();
        for _ in 0..45 {
            let st = s.step_frame().unwrap();
            if ahead {
                s.prepare_frame();
            }
            frames.push((s.positions().to_vec(), st.released_now, st.ahead_ms));
        }
        frames
    };
    let (plain, prepared) = (run(false), run(true));
    assert!(
        plain.iter().any(|f| f.1 > 0),
        "the pull should release some tets"
    );
    for (f, (a, b)) in plain.iter().zip(&prepared).enumerate() {
        let same =
            a.0.iter()
                .zip(&b.0)
                .all(|(p, q)| p.to_array() == q.to_array());
        assert!(
            same && a.1 == b.1,
            "frame {f}: preparing ahead moved the nodes"
        );
        assert_eq!(
            a.2, 0.0,
            "frame {f}: nothing is done ahead without the call"
        );
    }
    // The frame after a release finds its refactorisation done (where no refresh,
    // which refactorises anyway, is due).
    let ahead = prepared.iter().filter(|f| f.2 > 0.0).count();
    assert!(ahead > 0, "no frame had its refactorisation done ahead");
}

/// Each frame's stats report its Newton work: at least one iteration a frame and no more
/// than the settings allow, a product per iteration at least, the iterations stopped at
/// negative curvature among them, and line-search halvings once the bar has torn; under
/// XPBD all of it is zero.
#[test]
fn each_frame_reports_its_newton_work() {
    let params = NewtonParams::default();
    let mut s = common::tearing_bar_with(|p| {
        p.threads = 1;
        p.scheme = Scheme::Newton(params);
    });
    let (mut halvings, mut curvature) = (0, 0);
    for f in 0..45 {
        let st = s.step_frame().unwrap();
        let most = params.steps * params.iterations;
        assert!(
            (1..=most).contains(&st.newton_iterations),
            "frame {f}: {} Newton iterations",
            st.newton_iterations
        );
        assert!(st.cg_products >= st.newton_iterations, "frame {f}: {st:?}");
        assert!(st.negative_curvature <= st.newton_iterations, "frame {f}");
        halvings += st.line_search_halvings;
        curvature += st.negative_curvature;
    }
    assert!(s.cut().released_count() > 0, "the bar should tear");
    assert!(
        halvings + curvature > 0,
        "no halving or negative curvature in a tear"
    );
    let mut xpbd = common::tearing_bar(1);
    let st = xpbd.step_frame().unwrap();
    let newton_work = [
        st.newton_iterations,
        st.cg_products,
        st.line_search_halvings,
    ];
    assert_eq!(newton_work, [0, 0, 0], "XPBD reports Newton work");
}

/// A soft cantilever bent a quarter of its length under gravity: the rest stiffness
/// misses the rotation of its tets, so the coarse level refreshed from the current
/// tangents needs fewer products a frame once bent, and both settle on the same sag; the
/// Gauss–Seidel smoother settles there on fewer products still.
#[test]
fn a_refreshed_coarse_level_and_gauss_seidel_save_products_on_a_bent_beam() {
    let mesh = common::block_mesh(
        Vec3::new(0.0, -0.01, -0.01),
        Vec3::new(0.2, 0.02, 0.02),
        UVec3::new(20, 2, 2),
    );
    let root: Vec<u32> = (0..mesh.node_count() as u32)
        .filter(|&i| mesh.rest_positions[i as usize].x < 1e-4)
        .collect();
    let tip: Vec<usize> = (0..mesh.node_count())
        .filter(|&i| mesh.rest_positions[i].x > 0.2 - 1e-4)
        .collect();
    let run = |coarse_refresh, smoother| {
        let params = SolverParams {
            scheme: Scheme::Newton(NewtonParams {
                cg_tolerance: 1e-2,
                gradient_tolerance: 1e-3,
                coarse_refresh,
                smoother,
                ..CONVERGED
            }),
            damping: 20.0,
            threads: 1,
            ..SolverParams::default()
        };
        let mut s = Solver::new(mesh.clone(), common::soft(1e5, 0.45), params).unwrap();
        s.pin(&root);
        let mut late_products = 0;
        for f in 0..60 {
            let st = s.step_frame().unwrap();
            if f >= 30 {
                late_products += st.cg_products;
            }
        }
        let x = s.positions();
        let sag = -tip
            .iter()
            .map(|&i| x[i].z - mesh.rest_positions[i].z)
            .sum::<f32>()
            / tip.len() as f32;
        (late_products, sag)
    };
    let (rest, rest_sag) = run(CoarseRefresh::Rest, Smoother::Jacobi);
    let (fresh, fresh_sag) = run(CoarseRefresh::Steps(1), Smoother::Jacobi);
    let (smoothed, smoothed_sag) = run(CoarseRefresh::Steps(1), Smoother::GaussSeidel);
    assert!(
        rest_sag > 0.05,
        "bent a quarter of its length: sag {rest_sag} m"
    );
    assert!(
        (fresh_sag / rest_sag - 1.0).abs() < 0.01,
        "sag {fresh_sag} refreshed against {rest_sag} at rest stiffness"
    );
    assert!(
        (fresh as f64) < 0.8 * rest as f64,
        "products over frames 30-59: {fresh} refreshed against {rest} at rest stiffness"
    );
    // The Gauss–Seidel smoother: the same sag for fewer products than block Jacobi.
    assert!(
        (smoothed_sag / fresh_sag - 1.0).abs() < 0.01,
        "sag {smoothed_sag} with Gauss–Seidel against {fresh_sag} with Jacobi"
    );
    assert!(
        (smoothed as f64) < 0.7 * fresh as f64,
        "products over frames 30-59: {smoothed} with Gauss–Seidel against {fresh} with Jacobi"
    );
}

/// Settings the scheme cannot use are refused with the field named.
#[test]
fn unusable_newton_settings_are_refused() {
    let mesh = common::block_mesh(Vec3::ZERO, Vec3::splat(0.01), UVec3::splat(2));
    let try_with = |p: SolverParams| {
        Solver::new(mesh.clone(), common::soft(30e3, 0.4), p)
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default()
    };
    let zero_steps = SolverParams {
        scheme: Scheme::Newton(NewtonParams {
            steps: 0,
            ..NewtonParams::default()
        }),
        ..SolverParams::default()
    };
    assert!(try_with(zero_steps).contains("solver.scheme.steps"));
    let bad_tolerance = SolverParams {
        scheme: Scheme::Newton(NewtonParams {
            cg_tolerance: f32::NAN,
            ..NewtonParams::default()
        }),
        ..SolverParams::default()
    };
    assert!(try_with(bad_tolerance).contains("solver.scheme.cg_tolerance"));
    let backwards = SolverParams {
        scheme: Scheme::Newton(NewtonParams {
            step_tolerance: -0.01,
            ..NewtonParams::default()
        }),
        ..SolverParams::default()
    };
    assert!(try_with(backwards).contains("solver.scheme.step_tolerance"));
    let never = SolverParams {
        scheme: Scheme::Newton(NewtonParams {
            coarse_refresh: CoarseRefresh::Steps(0),
            ..NewtonParams::default()
        }),
        ..SolverParams::default()
    };
    assert!(try_with(never).contains("solver.scheme.coarse_refresh"));
    let seed_pair = SolverParams {
        scheme: Scheme::Newton(NewtonParams::default()),
        constraints: ConstraintPair::GammaShifted,
        ..SolverParams::default()
    };
    assert!(try_with(seed_pair).contains("RestFree"));
}

/// Without loads a body at rest stays exactly at rest under Newton (the energy's gradient
/// is evaluated from `H`, so rest is force-free to the last bit), at ν up to 0.499.
#[test]
fn rest_stays_exactly_at_rest() {
    let policies = [
        (CoarseRefresh::Rest, Smoother::Jacobi),
        (CoarseRefresh::Steps(1), Smoother::Jacobi),
        (CoarseRefresh::Steps(1), Smoother::GaussSeidel),
    ];
    for (nu, (coarse_refresh, smoother)) in [0.0, 0.3, 0.45, 0.499]
        .into_iter()
        .flat_map(|nu| policies.map(|p| (nu, p)))
    {
        let mesh = common::block_mesh(Vec3::ZERO, Vec3::new(0.03, 0.02, 0.01), UVec3::new(6, 4, 2));
        let params = SolverParams {
            scheme: Scheme::Newton(NewtonParams {
                coarse_refresh,
                smoother,
                ..NewtonParams::default()
            }),
            gravity: Vec3::ZERO,
            threads: 1,
            ..SolverParams::default()
        };
        let mut s = Solver::new(mesh, common::soft(180e3, nu), params).unwrap();
        s.pin(&[0]);
        for _ in 0..10 {
            s.step_frame().unwrap();
        }
        let moved = common::max_displacement(&s);
        assert_eq!(
            moved, 0.0,
            "ν = {nu}, {coarse_refresh:?}, {smoother:?}: moved {moved} m"
        );
    }
}

/// `prepare` builds the implicit workspace before the first frame (a scene calls it at
/// load, so the first frame does not stall), and the frames after it match those of a
/// solver that built it lazily in its first frame; under XPBD it does nothing.
#[test]
fn prepare_builds_the_workspace_before_the_first_frame() {
    let mesh = || common::block_mesh(Vec3::ZERO, Vec3::new(0.03, 0.02, 0.01), UVec3::new(6, 4, 2));
    let params = SolverParams {
        scheme: Scheme::Newton(NewtonParams::default()),
        threads: 1,
        ..SolverParams::default()
    };
    let open = |prepare: bool| {
        let mut s = Solver::new(mesh(), common::soft(50e3, 0.45), params.clone()).unwrap();
        s.pin(&[0, 1, 2, 3]);
        if prepare {
            s.prepare().unwrap();
        }
        s
    };
    let (mut early, mut lazy) = (open(true), open(false));
    assert!(early.newton_report().is_some(), "built by prepare");
    assert!(lazy.newton_report().is_none(), "not built before a frame");
    for _ in 0..5 {
        early.step_frame().unwrap();
        lazy.step_frame().unwrap();
    }
    assert_eq!(early.positions(), lazy.positions());
    let xpbd_params = SolverParams {
        substeps: 40,
        ..SolverParams::default()
    };
    let mut xpbd = Solver::new(mesh(), common::soft(50e3, 0.45), xpbd_params).unwrap();
    xpbd.prepare().unwrap();
    assert!(xpbd.newton_report().is_none());
}

/// A blade pressed slowly into a pinned block, as a scalpel meets tissue: the implicit
/// scheme holds the nodes in the blade's path through each step's solve, so the tissue
/// answers the push within the step and the stress under the blade and the force on it are
/// XPBD's at 400 substeps (the converged reference) within 15 % (docs/physics-notes.md,
/// "The implicit scheme under a blade"). Projected only after the solve, the nodes came
/// back into the blade every step: the stress was several times the reference's and the
/// force nearly nothing.
#[test]
fn a_pressing_blade_meets_the_tissue_as_the_xpbd_reference_does() {
    use incise_sim::contact::ToolPose;
    let start = Vec3::new(
        0.011,
        0.01,
        common::PRESSED_TOP + common::PRESSED_BLADE_R + 0.0002,
    );
    let block = |scheme: Scheme, substeps: u32| {
        let params = SolverParams {
            scheme,
            substeps,
            gravity: Vec3::ZERO,
            damping: 10.0,
            ..SolverParams::default()
        };
        common::pressed_block(params, start)
    };
    let mut newton = block(Scheme::Newton(NewtonParams::default()), 1);
    let mut xpbd = block(Scheme::Xpbd, 400);
    let mut frames = Vec::new();
    for frame in 0..12 {
        let to = start - Vec3::Z * (0.00025 * (frame + 1) as f32);
        let pose = ToolPose::new(to, glam::Quat::IDENTITY);
        newton.move_tool(pose);
        xpbd.move_tool(pose);
        frames.push((newton.step_frame().unwrap(), xpbd.step_frame().unwrap()));
    }
    let near = |x: f32, reference: f32| (x - reference).abs() <= 0.1 * reference.abs();
    // From the fifth frame (the first touches are a tenth of a millimetre deep).
    for f in 4..frames.len() - 1 {
        let (a, b) = &frames[f];
        assert!(
            near(a.max_von_mises, b.max_von_mises),
            "frame {f}: von Mises under the blade {} Pa under Newton, {} Pa under XPBD",
            a.max_von_mises,
            b.max_von_mises
        );
        // XPBD's force is the mean over its substeps, about the middle of the frame's
        // push; one implicit step's is at its end, about the middle of this frame's and
        // the next one's means.
        let end = 0.5 * (b.tool_force.z + frames[f + 1].1.tool_force.z);
        assert!(
            near(a.tool_force.z, end),
            "frame {f}: force on the blade {} N under Newton, {end} N under XPBD at the \
             frame's end",
            a.tool_force.z
        );
    }
}

/// Failed tissue carries no load: the frame whose release check switches off the tets the
/// blade crushes books the blade's force without them. The same press with and without a
/// release threshold is the same solve, bit for bit, until that frame; then the force is
/// lower by the released tets' share (it was the same before `Solver::unload_released`,
/// and on the intestine a crushed tet put 123 N on a scalpel for one frame).
#[test]
fn a_tet_the_blade_crushes_and_releases_puts_no_force_on_it() {
    use incise_sim::contact::ToolPose;
    let start = Vec3::new(
        0.011,
        0.01,
        common::PRESSED_TOP + common::PRESSED_BLADE_R + 0.0002,
    );
    let block = |release_threshold: Option<f32>| {
        let params = SolverParams {
            scheme: Scheme::Newton(NewtonParams::default()),
            gravity: Vec3::ZERO,
            damping: 10.0,
            release_threshold,
            ..SolverParams::default()
        };
        common::pressed_block(params, start)
    };
    // 3 kPa: reached under the blade at its sixth frame (2.5 mm deep).
    let (mut cutting, mut whole) = (block(Some(3e3)), block(None));
    for frame in 0..10 {
        let pose = ToolPose::new(
            start - Vec3::Z * (0.0004 * (frame + 1) as f32),
            glam::Quat::IDENTITY,
        );
        cutting.move_tool(pose);
        whole.move_tool(pose);
        let (a, b) = (cutting.step_frame().unwrap(), whole.step_frame().unwrap());
        assert_eq!(cutting.positions(), whole.positions(), "frame {frame}");
        if a.released_now == 0 {
            assert_eq!(a.tool_force, b.tool_force, "frame {frame}");
            continue;
        }
        assert!(
            a.tool_force.z < 0.95 * b.tool_force.z,
            "frame {frame}: {} tets released under the blade, yet {} N on it against {} N \
             with them whole",
            a.released_now,
            a.tool_force.z,
            b.tool_force.z
        );
        return;
    }
    panic!("the blade released no tet in 10 frames");
}
