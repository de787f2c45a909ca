//! The frame loop of `incise run` for mass-spring scenes (PHYSICS.md §2.3–2.5): each frame
//! advances the blade along the stroke (cutting), then takes the frame's explicit steps on
//! the whole mesh or on the nodes the localisation frees around the blade: a fixed level
//! d, or the refresh-rate manager, which picks the level each frame from the time the last
//! one took. Every frame records the level, the free nodes and the loop-time split.

use std::time::Instant;

use anyhow::Result;
use glam::DVec3;
use incise_sim::mass_spring::{LocalLoop, LocalLoopParams, MassSpringModel, SystemClock};
use incise_sim::nakao_cut::{BladePose, Cutter};

use crate::loop_report::{LocalisationInfo, LoopSample, LoopSplit};
use crate::report::{EdgeFrameStats, FrameData, FrameRecord, Report};
use crate::run::RunOptions;
use crate::run_mass_spring::{blade_at, max_displacement, snapshot};
use crate::scene::{Localisation, MassSpringScene};

/// The localised loop of a scene's setting (`None` for `Whole`).
fn local_loop(l: Localisation) -> Option<LocalLoop> {
    let params = match l {
        Localisation::Whole => return None,
        Localisation::Level(d) => LocalLoopParams {
            max_level: d,
            ..LocalLoopParams::default()
        },
        Localisation::Budget(ms) => LocalLoopParams {
            budget_ms: Some(ms),
            max_level: u32::MAX,
            ..LocalLoopParams::default()
        },
    };
    Some(LocalLoop::new(params, SystemClock::default()))
}

/// `steps` steps of `dt` on every node, timed by phase: (force ms, integrate ms).
fn whole_frame(
    model: &mut MassSpringModel,
    dt: f64,
    steps: u32,
    forces: &mut Vec<DVec3>,
) -> (f64, f64) {
    let all: Vec<u32> = (0..model.node_count() as u32).collect();
    let (mut force_ms, mut integrate_ms) = (0.0, 0.0);
    for _ in 0..steps {
        let a = Instant::now();
        model.gather_forces(&all, forces);
        let b = Instant::now();
        model.integrate_nodes(dt, &all, forces);
        force_ms += (b - a).as_secs_f64() * 1e3;
        integrate_ms += b.elapsed().as_secs_f64() * 1e3;
    }
    (force_ms, integrate_ms)
}

/// The tool point the localisation follows: the middle of the blade's edge.
fn tool_point(pose: BladePose) -> DVec3 {
    (pose.heel + pose.tip) * 0.5
}

/// The ordinary run: cut along the stroke and step the model frame by frame, localised as
/// the scene says; fills the report's frames and localisation summary; returns the model.
#[allow(clippy::too_many_arguments)]
pub(crate) fn run_frames(
    mut model: MassSpringModel,
    ms: &MassSpringScene,
    frame_dt: f64,
    frames: u64,
    total_volume: f64,
    opts: &RunOptions,
    report: &mut Report,
    pvd: &mut Vec<(f64, String)>,
) -> Result<MassSpringModel> {
    let mut cutter = Cutter::new(ms.cut.clone());
    let mut local = local_loop(ms.localisation);
    let mut forces = Vec::new();
    let mut samples = Vec::with_capacity(frames as usize);
    let mut cutting = false;
    for f in 0..frames {
        if crate::interrupt::requested() {
            break;
        }
        let t0 = Instant::now();
        let mut cut_ms = 0.0;
        let mut tool = None;
        if let Some(stroke) = &ms.stroke {
            let (pose, progress) = blade_at(stroke, model.time());
            tool = Some(tool_point(pose));
            if progress > 0.0 && !cutting && progress < 1.0 {
                cutter.begin(&model, blade_at(stroke, stroke.start as f64).0);
                cutting = true;
            }
            if cutting {
                cut_ms = cutter.advance(&mut model, pose).ms;
                if progress >= 1.0 {
                    cutter.end();
                    cutting = false;
                }
            }
        }
        let steps = (frame_dt / model.stable_dt()).ceil().max(1.0) as u32;
        let dt = frame_dt / steps as f64;
        let sample = match (&mut local, tool) {
            (Some(l), Some(tip)) => {
                let s = l.frame(&mut model, tip, dt, steps);
                LoopSample {
                    level: Some(s.level()),
                    free_nodes: s.free_nodes,
                    split: LoopSplit {
                        localise_ms: s.localise_ms,
                        force_ms: s.force_ms,
                        integrate_ms: s.integrate_ms,
                        cut_ms,
                    },
                }
            }
            _ => {
                let (force_ms, integrate_ms) = whole_frame(&mut model, dt, steps, &mut forces);
                LoopSample {
                    level: None,
                    free_nodes: model.node_count(),
                    split: LoopSplit {
                        localise_ms: 0.0,
                        force_ms,
                        integrate_ms,
                        cut_ms,
                    },
                }
            }
        };
        let wall_ms = t0.elapsed().as_secs_f64() * 1e3;
        samples.push(sample);
        report
            .frames
            .push(record(&model, f, steps, total_volume, wall_ms, &sample));
        if opts.vtu_every > 0 && (f + 1) % opts.vtu_every == 0 {
            snapshot(&opts.out, &model, f + 1, pvd)?;
        }
    }
    let budget = match ms.localisation {
        Localisation::Budget(b) => Some(b),
        _ => None,
    };
    report.localisation = LocalisationInfo::of(ms.localisation.label(), budget, &samples);
    Ok(model)
}

/// The report record of frame `f`.
fn record(
    model: &MassSpringModel,
    f: u64,
    steps: u32,
    total_volume: f64,
    wall_ms: f64,
    sample: &LoopSample,
) -> FrameRecord {
    let volume: f64 = (0..model.tet_count())
        .map(|t| model.current_volume(t))
        .sum();
    FrameRecord {
        haptic_amplitude: None,
        stats: FrameData::Edges(EdgeFrameStats {
            frame: f,
            sim_time: model.time(),
            substeps: steps as u64,
            volume_ratio: volume / total_volume,
            max_displacement: max_displacement(model.reference_positions(), model.positions()),
            kinetic_energy: Some(model.kinetic_energy()),
            solve_ms: Some(wall_ms),
            level: sample.level,
            free_nodes: Some(sample.free_nodes),
            localise_ms: Some(sample.split.localise_ms),
            force_ms: Some(sample.split.force_ms),
            integrate_ms: Some(sample.split.integrate_ms),
            cut_ms: Some(sample.split.cut_ms),
            ..EdgeFrameStats::default()
        }),
        wall_ms,
        gpu_ms: None,
    }
}
