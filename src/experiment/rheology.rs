//! `incise experiment rheology`: the three-element model's checks as figures and tables
//! (PHYSICS.md §3, seed 002) — one element against its closed form, the seed's
//! press-and-release of a block with every preset, the hold-time dependence of the
//! rheological residual, and the force-dependent damper under gravity.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result};
use glam::DVec3;
use incise_sim::rheology::{
    CreepTest, Damper, ElementParams, PressOutcome, PressProtocol, RheologyPresets, Specimen,
    creep_recovery, press_and_release, sag_under_gravity,
};
use rayon::prelude::*;

use crate::report::plot::{
    LineChart, SegmentLayer, SegmentPanel, Series, write_line_chart, write_segment_panels,
};

/// Presets drawn first and in this order; any others in the file follow by name.
const PRESET_ORDER: [&str; 5] = [
    "elastic",
    "viscoelastic",
    "plastic",
    "rheological",
    "rheological_fdd",
];

/// Hold time of the preset comparison, s.
const HOLD: f64 = 0.5;

/// How large the runs are: the full experiment (docs/experiments/rheology/) or its quick
/// version (`--quick`: the same parts on the coarse 10 cm block, two hold times, 2 s of
/// sag), which shows the same behaviour in seconds instead of minutes.
#[derive(Debug, Clone, Copy)]
struct Scale {
    /// The pressed block.
    specimen: Specimen,
    /// Hold times of the rheological hold-time sweep, s.
    holds: &'static [f64],
    /// Simulated seconds of the gravity sag.
    sag_seconds: f64,
}

impl Scale {
    /// The full experiment or the quick one.
    fn of(quick: bool) -> Self {
        if quick {
            Scale {
                specimen: Specimen::coarse(),
                holds: &[0.1, 1.0],
                sag_seconds: 2.0,
            }
        } else {
            Scale {
                specimen: Specimen::standard(),
                holds: &[0.1, 0.25, 0.5, 1.0],
                sag_seconds: 5.0,
            }
        }
    }
}

/// What to run and where to write it.
#[derive(Debug, Clone)]
pub struct RheologyOptions {
    /// Output folder (created).
    pub out: PathBuf,
    /// The preset file, `config/rheology.ron`.
    pub presets: PathBuf,
    /// The quick version: the coarse block, two hold times, 2 s of sag (seconds, not
    /// minutes; the figures of docs/experiments/rheology/ are the full version's).
    pub quick: bool,
}

/// Run every part, write CSV and PNG files into `opts.out`, and return a text summary.
pub fn run(opts: &RheologyOptions) -> Result<String> {
    std::fs::create_dir_all(&opts.out)
        .with_context(|| format!("cannot create {}", opts.out.display()))?;
    let presets = RheologyPresets::load(&opts.presets)?;
    let scale = Scale::of(opts.quick);
    let mut summary = String::new();
    creep(&opts.out, &mut summary)?;
    press(&opts.out, &presets, scale, &mut summary)?;
    hold_sweep(&opts.out, &presets, scale, &mut summary)?;
    gravity(&opts.out, &presets, scale, &mut summary)?;
    std::fs::write(opts.out.join("summary.txt"), &summary)
        .with_context(|| format!("cannot write {}", opts.out.join("summary.txt").display()))?;
    Ok(summary)
}

fn write(path: PathBuf, text: &str) -> Result<()> {
    std::fs::write(&path, text).with_context(|| format!("cannot write {}", path.display()))
}

/// (a) One element under 0.5 N for 1 s, then released, against `u(t)` of PHYSICS.md §3.
fn creep(out: &Path, summary: &mut String) -> Result<()> {
    let (k, c1, c2, force, release) = (100.0, 5.0, 50.0, 0.5, 1.0);
    let test = CreepTest {
        element: ElementParams {
            stiffness: k,
            voigt_damping: c1,
            damper: Damper::Linear(c2),
            ratio_min: 0.0,
            ratio_max: 1.0,
        },
        rest_length: 0.1,
        rest_ratio: 0.5,
        node_mass: 1e-4,
        force,
        release,
    };
    let step = 0.5 * test.max_step();
    let samples = test.run(step, 3.0, (0.005 / step).round() as usize)?;
    let mut csv = String::from("time_s,simulated_m,closed_form_m,ratio_a\n");
    let mut worst = 0.0f64;
    for s in &samples {
        let exact = creep_recovery(k, c1, c2, force, release, s.time);
        worst = worst.max((s.elongation - exact).abs());
        writeln!(
            csv,
            "{:.6},{:.9e},{:.9e},{:.9}",
            s.time, s.elongation, exact, s.ratio
        )?;
    }
    write(out.join("creep.csv"), &csv)?;
    let mm = |f: &dyn Fn(&incise_sim::rheology::CreepSample) -> f64| -> Vec<(f64, f64)> {
        samples.iter().map(|s| (s.time, 1e3 * f(s))).collect()
    };
    write_line_chart(
        &out.join("creep.png"),
        &LineChart {
            title: "One element: creep under 0.5 N, released at 1 s".into(),
            x_label: "time (s)".into(),
            y_label: "elongation (mm)".into(),
            series: vec![
                Series {
                    name: "RK4 (node 0.1 g)".into(),
                    points: mm(&|s| s.elongation),
                },
                Series {
                    name: "closed form".into(),
                    points: mm(&|s| creep_recovery(k, c1, c2, force, release, s.time)),
                },
            ],
        },
        900,
        500,
    )?;
    let peak = creep_recovery(k, c1, c2, force, release, release);
    writeln!(
        summary,
        "creep: k {k} N/m, c1 {c1} N·s/m, c2 {c2} N·s/m, F {force} N for {release} s; RK4 step \
         {step:.2e} s; worst error {:.3e} m = {:.4} % of the peak {:.4} m",
        worst,
        100.0 * worst / peak,
        peak
    )?;
    Ok(())
}

/// Preset names in drawing order.
fn ordered(presets: &RheologyPresets) -> Vec<String> {
    let mut names: Vec<String> = PRESET_ORDER
        .iter()
        .filter(|n| presets.materials.contains_key(**n))
        .map(|n| n.to_string())
        .collect();
    names.extend(
        presets
            .materials
            .keys()
            .filter(|n| !PRESET_ORDER.contains(&n.as_str()))
            .cloned(),
    );
    names
}

/// (b) The seed's press-and-release with every preset: depth curves and side views.
fn press(out: &Path, presets: &RheologyPresets, scale: Scale, summary: &mut String) -> Result<()> {
    let names = ordered(presets);
    let protocol = PressProtocol::standard(scale.specimen, HOLD);
    let runs: Vec<(String, PressOutcome, f64)> = names
        .par_iter()
        .map(|name| -> Result<_> {
            let started = Instant::now();
            let run = press_and_release(&presets.get(name)?, &protocol)
                .with_context(|| format!("press-and-release of preset {name}"))?;
            Ok((name.clone(), run, started.elapsed().as_secs_f64()))
        })
        .collect::<Result<_>>()?;
    let mut csv = String::from("time_s,indenter_mm");
    for (name, _, _) in &runs {
        write!(csv, ",{name}_mm")?;
    }
    csv.push('\n');
    let first = &runs[0].1;
    for (i, t) in first.times.iter().enumerate() {
        write!(csv, "{t:.4},{:.5}", 1e3 * first.indenter_depth[i])?;
        for (_, run, _) in &runs {
            write!(csv, ",{:.5}", 1e3 * run.depth[i])?;
        }
        csv.push('\n');
    }
    write(out.join("press_depth.csv"), &csv)?;
    let mut series = vec![Series {
        name: "indenter".into(),
        points: first
            .times
            .iter()
            .zip(&first.indenter_depth)
            .map(|(&t, &d)| (t, 1e3 * d))
            .collect(),
    }];
    series.extend(runs.iter().map(|(name, run, _)| {
        Series {
            name: name.clone(),
            points: run
                .times
                .iter()
                .zip(&run.depth)
                .map(|(&t, &d)| (t, 1e3 * d))
                .collect(),
        }
    }));
    let size = protocol.specimen.size;
    write_line_chart(
        &out.join("press_depth.png"),
        &LineChart {
            title: format!(
                "Press-and-release of a {:.0} x {:.0} x {:.0} cm block: depth of the top centre",
                100.0 * size.x,
                100.0 * size.y,
                100.0 * size.z
            ),
            x_label: "time (s)".into(),
            y_label: "indentation depth (mm)".into(),
            series,
        },
        1000,
        560,
    )?;
    let full_press = protocol.schedule.press + protocol.schedule.hold;
    let depth = protocol.schedule.depth;
    side_views(
        out.join("press_side_full.png"),
        &runs,
        |r| &r.at_full_press,
        Some(depth),
        &format!("at full press (t = {full_press} s)"),
    )?;
    side_views(
        out.join("press_side_recovered.png"),
        &runs,
        |r| &r.after_recovery,
        None,
        &format!("after recovery (t = {:.1} s)", protocol.duration()),
    )?;
    side_profiles(out, &runs)?;
    let mut table = String::from(
        "preset,max_depth_mm,residual_mm,residual_fraction,side_bulge_full_mm,side_bulge_recovered_mm,rk4_steps,substep_s,wall_s\n",
    );
    writeln!(
        summary,
        "press-and-release (hold {HOLD} s, depth {:.0} mm):",
        1e3 * depth
    )?;
    for (name, run, wall) in &runs {
        let bulge_full = side_bulge(run, &run.at_full_press);
        let bulge_rec = side_bulge(run, &run.after_recovery);
        writeln!(
            table,
            "{name},{:.4},{:.4},{:.5},{:.4},{:.4},{},{:.3e},{:.2}",
            1e3 * run.max_depth(),
            1e3 * run.residual_depth(),
            run.residual_fraction(),
            1e3 * bulge_full,
            1e3 * bulge_rec,
            run.steps,
            run.substep,
            wall
        )?;
        writeln!(
            summary,
            "  {name:16} max {:6.2} mm  residual {:6.2} mm ({:6.2} %)  side bulge {:5.2} -> {:5.2} mm  \
             {} steps of {:.2e} s, {:.1} s",
            1e3 * run.max_depth(),
            1e3 * run.residual_depth(),
            100.0 * run.residual_fraction(),
            1e3 * bulge_full,
            1e3 * bulge_rec,
            run.steps,
            run.substep,
            wall
        )?;
    }
    write(out.join("press_summary.csv"), &table)
}

/// Largest outward displacement of a side-face node (|x| or |y| at the side), m.
fn side_bulge(run: &PressOutcome, positions: &[DVec3]) -> f64 {
    let rest = &run.specimen.mesh.rest_positions;
    let (lo, hi) = run.specimen.mesh.rest_bounds();
    let tol = 1e-6;
    (0..rest.len())
        .map(|i| {
            let (r, p) = (rest[i], positions[i]);
            let mut out = 0.0f64;
            if (r.x - lo.x).abs() < tol {
                out = out.max(r.x as f64 - p.x);
            }
            if (r.x - hi.x).abs() < tol {
                out = out.max(p.x - r.x as f64);
            }
            if (r.y - lo.y).abs() < tol {
                out = out.max(r.y as f64 - p.y);
            }
            if (r.y - hi.y).abs() < tol {
                out = out.max(p.y - r.y as f64);
            }
            out
        })
        .fold(0.0, f64::max)
}

/// One panel per preset: the edges in the mid-plane y = 0 in side view (x, z), rest shape
/// faint: the dent under the indenter and the bulging sides.
fn side_views(
    path: PathBuf,
    runs: &[(String, PressOutcome, f64)],
    state: impl Fn(&PressOutcome) -> &Vec<DVec3>,
    indenter_depth: Option<f64>,
    when: &str,
) -> Result<()> {
    let panels: Vec<SegmentPanel> = runs
        .iter()
        .map(|(name, run, _)| {
            let section: std::collections::HashSet<u32> =
                run.specimen.section.iter().copied().collect();
            let edges = incise_sim::mesh::EdgeList::of_mesh(&run.specimen.mesh);
            let face: Vec<[u32; 2]> = edges
                .edges
                .iter()
                .filter(|e| section.contains(&e[0]) && section.contains(&e[1]))
                .copied()
                .collect();
            let rest = &run.specimen.mesh.rest_positions;
            let cm = |p: DVec3| (100.0 * p.x, 100.0 * p.z);
            let now = state(run);
            let mut layers = vec![
                SegmentLayer {
                    name: "rest".into(),
                    segments: face
                        .iter()
                        .map(|e| {
                            [
                                cm(rest[e[0] as usize].as_dvec3()),
                                cm(rest[e[1] as usize].as_dvec3()),
                            ]
                        })
                        .collect(),
                    colour: 7,
                    faint: true,
                },
                SegmentLayer {
                    name: "deformed".into(),
                    segments: face
                        .iter()
                        .map(|e| [cm(now[e[0] as usize]), cm(now[e[1] as usize])])
                        .collect(),
                    colour: 0,
                    faint: false,
                },
            ];
            if let Some(depth) = indenter_depth {
                let (_, hi) = run.specimen.mesh.rest_bounds();
                let half = hi.x as f64 / 3.0;
                let z = 100.0 * (hi.z as f64 - depth);
                layers.push(SegmentLayer {
                    name: "indenter face".into(),
                    segments: vec![[(-100.0 * half, z), (100.0 * half, z)]],
                    colour: 1,
                    faint: false,
                });
            }
            SegmentPanel {
                title: format!("{name}, {when}"),
                layers,
            }
        })
        .collect();
    write_segment_panels(&path, &panels, 3, 520, 330, ("x (cm)", "z (cm)"))?;
    Ok(())
}

/// Outward displacement of the +x side face (mid-plane) against height, one chart for full
/// press and one after recovery, a series per preset.
fn side_profiles(out: &Path, runs: &[(String, PressOutcome, f64)]) -> Result<()> {
    for (file, label, full) in [
        ("press_side_bulge_full.png", "at full press", true),
        ("press_side_bulge_recovered.png", "after recovery", false),
    ] {
        let series = runs
            .iter()
            .map(|(name, run, _)| {
                let positions = if full {
                    &run.at_full_press
                } else {
                    &run.after_recovery
                };
                let rest = &run.specimen.mesh.rest_positions;
                Series {
                    name: name.clone(),
                    points: run
                        .specimen
                        .side_profile
                        .iter()
                        .map(|&i| {
                            let (r, p) = (rest[i as usize].as_dvec3(), positions[i as usize]);
                            (1e3 * (p.x - r.x), 100.0 * r.z)
                        })
                        .collect(),
                }
            })
            .collect();
        write_line_chart(
            &out.join(file),
            &LineChart {
                title: format!("Side bulge {label}: the side face in the mid-plane"),
                x_label: "outward displacement (mm)".into(),
                y_label: "height of the node at rest (cm)".into(),
                series,
            },
            900,
            560,
        )?;
    }
    Ok(())
}

/// (c) The rheological preset's residual against hold time.
fn hold_sweep(
    out: &Path,
    presets: &RheologyPresets,
    scale: Scale,
    summary: &mut String,
) -> Result<()> {
    let material = presets.get("rheological")?;
    let runs: Vec<(f64, PressOutcome)> = scale
        .holds
        .par_iter()
        .map(|&hold| -> Result<_> {
            let protocol = PressProtocol::standard(scale.specimen, hold);
            Ok((hold, press_and_release(&material, &protocol)?))
        })
        .collect::<Result<_>>()?;
    let mut csv = String::from("hold_s,max_depth_mm,residual_mm,residual_fraction\n");
    write!(summary, "rheological residual vs hold time:")?;
    for (hold, run) in &runs {
        writeln!(
            csv,
            "{hold},{:.4},{:.4},{:.5}",
            1e3 * run.max_depth(),
            1e3 * run.residual_depth(),
            run.residual_fraction()
        )?;
        write!(
            summary,
            "  {hold} s: {:.1} %",
            100.0 * run.residual_fraction()
        )?;
    }
    summary.push('\n');
    write(out.join("hold_time.csv"), &csv)?;
    write_line_chart(
        &out.join("hold_time.png"),
        &LineChart {
            title: "Rheological preset: depth for different hold times".into(),
            x_label: "time (s)".into(),
            y_label: "indentation depth (mm)".into(),
            series: runs
                .iter()
                .map(|(hold, run)| Series {
                    name: format!("hold {hold} s"),
                    points: run
                        .times
                        .iter()
                        .zip(&run.depth)
                        .map(|(&t, &d)| (t, 1e3 * d))
                        .collect(),
                })
                .collect(),
        },
        1000,
        560,
    )?;
    Ok(())
}

/// (d) The force-dependent damper's block and its linear twin (c2 = c_min) under gravity.
fn gravity(
    out: &Path,
    presets: &RheologyPresets,
    scale: Scale,
    summary: &mut String,
) -> Result<()> {
    let fdd = presets.get("rheological_fdd")?;
    let Damper::ForceDependent { c_min, .. } = fdd.damper else {
        anyhow::bail!(
            "{}: preset rheological_fdd must have a ForceDependent damper",
            presets.path.display()
        );
    };
    let block = Specimen::coarse();
    let cases = [
        ("force-dependent damper", fdd),
        (
            "linear damper, c2 = c_min",
            fdd.with_damper(Damper::Linear(c_min)),
        ),
    ];
    let curves: Vec<Vec<(f64, f64)>> = cases
        .par_iter()
        .map(|(_, m)| sag_under_gravity(m, &block, 9.81, 0.5, scale.sag_seconds, 100))
        .collect::<Result<_, _>>()?;
    let mut csv = String::from("time_s,sag_fdd_mm,sag_linear_mm\n");
    for (a, b) in curves[0].iter().zip(&curves[1]) {
        writeln!(csv, "{:.3},{:.5},{:.5}", a.0, 1e3 * a.1, 1e3 * b.1)?;
    }
    write(out.join("gravity_sag.csv"), &csv)?;
    write_line_chart(
        &out.join("gravity_sag.png"),
        &LineChart {
            title: format!(
                "rheological_fdd block ({:.0} x {:.0} x {:.0} cm) under its own weight",
                100.0 * block.size.x,
                100.0 * block.size.y,
                100.0 * block.size.z
            ),
            x_label: "time (s)".into(),
            y_label: "sag of the top centre (mm)".into(),
            series: cases
                .iter()
                .zip(&curves)
                .map(|((name, _), c)| Series {
                    name: name.to_string(),
                    points: c.iter().map(|&(t, d)| (t, 1e3 * d)).collect(),
                })
                .collect(),
        },
        1000,
        560,
    )?;
    let (with, without) = (curves[0].last().unwrap().1, curves[1].last().unwrap().1);
    writeln!(
        summary,
        "gravity sag over {} s: {:.3} mm with the force-dependent damper, {:.3} mm with c2 = c_min \
         ({:.1} %)",
        scale.sag_seconds,
        1e3 * with,
        1e3 * without,
        100.0 * with / without
    )?;
    Ok(())
}
