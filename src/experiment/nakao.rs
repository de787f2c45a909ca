//! `incise experiment nakao-plate`: the plate experiment of Nakao et al. 2003 (PHYSICS.md
//! §2.6) — the same straight cut at tension 0, 2, 4 and 6 %, adaptive, non-adaptive and
//! Bielser-style —
//! as a table (counts before/after, cut-surface area, wound opening, loop times), line
//! charts and top-down images of the opened wounds.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use incise_sim::mass_spring::MassSpringModel;
use incise_sim::nakao_cut::{PlateCutResult, PlateCutSetup, Subdivision, run_plate_cut};
use rayon::prelude::*;

use crate::report::plot::{
    LineChart, SegmentLayer, SegmentPanel, Series, write_line_chart, write_segment_panels,
};

/// The paper's counts before and after its cut (nodes, edges, triangles, tets).
const PAPER_BEFORE: [usize; 4] = [1_274, 6_160, 2_500, 3_647];
/// The paper's counts after the cut.
const PAPER_AFTER: [usize; 4] = [1_505, 7_376, 3_039, 4_301];

/// Tensions of the runs (0 checks that nothing opens without tension).
const TENSIONS: [f64; 4] = [0.0, 0.02, 0.04, 0.06];

/// Tensions of the quick version.
const QUICK_TENSIONS: [f64; 2] = [0.0, 0.04];

/// Length of the quick version's cut line, m (the reference line shortened about its
/// middle, 14 cm → 4 cm).
pub const QUICK_CUT: f64 = 0.04;

/// Options of the experiment.
#[derive(Debug, Clone)]
pub struct NakaoOptions {
    /// Output folder (created).
    pub out: PathBuf,
    /// The quick version: a 4 cm cut at 0 and 4 %, 0.2 s to open, no added-counts
    /// variants (seconds, not minutes; docs/experiments/nakao/ has the full version).
    pub quick: bool,
}

/// The subdivisions compared: the paper's adaptive one and the two baselines.
const SUBDIVISIONS: [Subdivision; 3] = [
    Subdivision::Adaptive,
    Subdivision::NonAdaptive,
    Subdivision::Bielser,
];

/// The runs' setups: every tension of the full experiment, each subdivision (the baselines
/// not at 0 %), or the quick version's.
fn setups(quick: bool) -> Vec<PlateCutSetup> {
    let tensions: &[f64] = if quick { &QUICK_TENSIONS } else { &TENSIONS };
    let mut setups = Vec::new();
    for sub in SUBDIVISIONS {
        for &s in tensions {
            if s == 0.0 && sub != Subdivision::Adaptive {
                continue;
            }
            let mut setup = PlateCutSetup::reference(s, sub);
            if quick {
                shorten(&mut setup, QUICK_CUT);
                setup.settle_after = 0.2;
            }
            if s == 0.0 {
                // Without tension no force acts in the plane; a short settle shows it.
                setup.settle_after = 0.05;
            }
            setups.push(setup);
        }
    }
    setups
}

/// Shorten the cut line to `length` about its middle, keeping its direction.
fn shorten(setup: &mut PlateCutSetup, length: f64) {
    let (a, b) = (setup.start, setup.end);
    let mid = [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])];
    let d = [b[0] - a[0], b[1] - a[1]];
    let half = 0.5 * length / d[0].hypot(d[1]);
    setup.start = [mid[0] - half * d[0], mid[1] - half * d[1]];
    setup.end = [mid[0] + half * d[0], mid[1] + half * d[1]];
}

/// One finished run and its final model.
struct Run {
    result: PlateCutResult,
    model: MassSpringModel,
}

/// Run every case, write `table.md`, `table.csv`, `results.json`, the PNG figures and the
/// added-counts comparison into `opts.out`; returns the markdown tables.
pub fn run(opts: &NakaoOptions) -> Result<String> {
    std::fs::create_dir_all(&opts.out)
        .with_context(|| format!("cannot create {}", opts.out.display()))?;
    let runs: Vec<Run> = setups(opts.quick)
        .par_iter()
        .map(|s| {
            run_plate_cut(s)
                .map(|(result, model)| Run { result, model })
                .with_context(|| format!("plate cut at tension {}", s.tension))
        })
        .collect::<Result<_>>()?;
    let prov = crate::provenance::provenance();
    let version = if opts.quick {
        "Quick version (`--quick`: 4 cm cut, 0.2 s to open). "
    } else {
        ""
    };
    let table = format!(
        "{version}Measured on {}, {}, load average {}.\n\n{}",
        prov.machine,
        prov.date_utc,
        prov.load_average,
        markdown(&runs)
    );
    write(&opts.out.join("table.md"), &table)?;
    write(&opts.out.join("table.csv"), &csv(&runs)?)?;
    let results: Vec<&PlateCutResult> = runs.iter().map(|r| &r.result).collect();
    write(
        &opts.out.join("results.json"),
        &serde_json::to_string_pretty(&results)?,
    )?;
    charts(&opts.out, &runs)?;
    wounds(&opts.out, &runs)?;
    if opts.quick {
        return Ok(table);
    }
    let counts = super::nakao_counts::run(&opts.out)?;
    Ok(format!("{table}\n{counts}"))
}

fn write(path: &Path, text: &str) -> Result<()> {
    std::fs::write(path, text).with_context(|| format!("cannot write {}", path.display()))
}

fn label(sub: Subdivision) -> &'static str {
    match sub {
        Subdivision::Adaptive => "adaptive",
        Subdivision::NonAdaptive => "non-adaptive",
        Subdivision::Bielser => "bielser",
    }
}

fn markdown(runs: &[Run]) -> String {
    let mut t = String::new();
    let _ = writeln!(
        t,
        "| subdivision | tension | nodes | edges | triangles | tets | cut area (cm²) | opening at middle (mm) | max loop (ms) | max cut (ms) | worst dihedral (°) | worst radius ratio of new tets |"
    );
    let _ = writeln!(t, "|---|---|---|---|---|---|---|---|---|---|---|---|");
    let [n0, e0, f0, t0] = PAPER_BEFORE;
    let [n1, e1, f1, t1] = PAPER_AFTER;
    let _ = writeln!(
        t,
        "| paper (Nakao 2003) | 2–6 % | {n0} → {n1} | {e0} → {e1} | {f0} → {f1} | {t0} → {t1} | (Fig. 12) | (Fig. 11) | – | – | – | – |"
    );
    for r in runs {
        let (b, a, x) = (&r.result.before, &r.result.after, &r.result);
        let _ = writeln!(
            t,
            "| {} | {:.0} % | {} → {} | {} → {} | {} → {} | {} → {} | {:.3} | {:.3} | {:.2} | {:.2} | {:.1} | {:.3} |",
            label(x.setup.cut.subdivision),
            x.setup.tension * 100.0,
            b.nodes,
            a.nodes,
            b.edges,
            a.edges,
            b.triangles,
            a.triangles,
            b.tets,
            a.tets,
            x.cut_area * 1e4,
            x.opening_width * 1e3,
            x.max_loop_ms,
            x.max_cut_ms,
            x.worst_dihedral_deg,
            x.worst_new_radius_ratio,
        );
    }
    let _ = writeln!(
        t,
        "\nMax loop = the slowest 10 ms visual loop while cutting (one blade advance + 10 ms of \
         simulation of the whole plate); max cut = the slowest blade advance alone; radius ratio = \
         3 r_in / R_circ (1 for a regular tet). Loop times \
         depend on the machine and on other load; the counts, areas and openings do not. The \
         paper gives no loop times for the plate (its 2.0–13.7 ms are the chest's: \
         `incise experiment nakao-chest`)."
    );
    t
}

fn csv(runs: &[Run]) -> Result<String> {
    let mut c = String::from(
        "subdivision,tension,nodes_before,nodes_after,edges_before,edges_after,triangles_before,triangles_after,tets_before,tets_after,cut_area_m2,opening_width_m,max_loop_ms,max_cut_ms,worst_dihedral_deg,final_kinetic_energy_j\n",
    );
    for r in runs {
        let (b, a, x) = (&r.result.before, &r.result.after, &r.result);
        writeln!(
            c,
            "{},{},{},{},{},{},{},{},{},{},{:.6e},{:.6e},{:.3},{:.3},{:.3},{:.3e}",
            label(x.setup.cut.subdivision),
            x.setup.tension,
            b.nodes,
            a.nodes,
            b.edges,
            a.edges,
            b.triangles,
            a.triangles,
            b.tets,
            a.tets,
            x.cut_area,
            x.opening_width,
            x.max_loop_ms,
            x.max_cut_ms,
            x.worst_dihedral_deg,
            x.final_kinetic_energy,
        )?;
    }
    Ok(c)
}

fn series(runs: &[Run], sub: Subdivision, value: impl Fn(&PlateCutResult) -> f64) -> Series {
    Series {
        name: label(sub).into(),
        points: runs
            .iter()
            .filter(|r| r.result.setup.cut.subdivision == sub)
            .map(|r| (r.result.setup.tension * 100.0, value(&r.result)))
            .collect(),
    }
}

fn charts(out: &Path, runs: &[Run]) -> Result<()> {
    let all = |value: &dyn Fn(&PlateCutResult) -> f64| {
        SUBDIVISIONS
            .iter()
            .map(|&sub| series(runs, sub, value))
            .collect()
    };
    write_line_chart(
        &out.join("opening_vs_tension.png"),
        &LineChart {
            title: "Wound opening at the middle of the cut (Nakao 2003 Fig. 11)".into(),
            x_label: "tension s (%)".into(),
            y_label: "opening width (mm)".into(),
            series: all(&|r| r.opening_width * 1e3),
        },
        800,
        500,
    )?;
    write_line_chart(
        &out.join("cut_area.png"),
        &LineChart {
            title: "Total cut-surface area, adaptive vs the baselines (Fig. 12)".into(),
            x_label: "tension s (%)".into(),
            y_label: "cut area (cm²)".into(),
            series: all(&|r| r.cut_area * 1e4),
        },
        800,
        500,
    )?;
    Ok(())
}

/// Top-down view of the top surface's springs in the middle of the plate, per run.
fn wounds(out: &Path, runs: &[Run]) -> Result<()> {
    for sub in SUBDIVISIONS {
        let panels: Vec<SegmentPanel> = runs
            .iter()
            .filter(|r| r.result.setup.cut.subdivision == sub && r.result.setup.tension > 0.0)
            .map(|r| SegmentPanel {
                title: format!(
                    "{} cut, tension {:.0} %",
                    label(sub),
                    r.result.setup.tension * 100.0
                ),
                layers: vec![
                    SegmentLayer {
                        name: "springs (top surface)".into(),
                        segments: top_springs(&r.model, 0.03),
                        colour: 7,
                        faint: true,
                    },
                    SegmentLayer {
                        name: "cut surface (top edge)".into(),
                        segments: cut_edges(&r.model, 0.03),
                        colour: 1,
                        faint: false,
                    },
                ],
            })
            .collect();
        if panels.is_empty() {
            continue;
        }
        let name = format!("wound_{}.png", label(sub).replace('-', "_"));
        write_segment_panels(&out.join(name), &panels, 3, 520, 520, ("x (cm)", "y (cm)"))?;
    }
    Ok(())
}

/// Springs between top-surface nodes within `half` of the plate centre, in cm.
fn top_springs(m: &MassSpringModel, half: f64) -> Vec<[(f64, f64); 2]> {
    let x = m.positions();
    let top = |i: usize| m.reference_positions()[i].z > 0.004 - 1e-6;
    let near = |i: usize| x[i].x.abs() <= half && x[i].y.abs() <= half;
    let mut segs = Vec::new();
    for i in 0..m.node_count() {
        for s in m.springs_of(i) {
            let j = s.node as usize;
            if j > i && top(i) && top(j) && near(i) && near(j) {
                segs.push([
                    (x[i].x * 100.0, x[i].y * 100.0),
                    (x[j].x * 100.0, x[j].y * 100.0),
                ]);
            }
        }
    }
    segs
}

/// Top edges of the cut-surface triangles within `half` of the centre, in cm.
fn cut_edges(m: &MassSpringModel, half: f64) -> Vec<[(f64, f64); 2]> {
    let x = m.positions();
    let top = |i: u32| m.reference_positions()[i as usize].z > 0.004 - 1e-6;
    let near = |i: u32| x[i as usize].x.abs() <= half && x[i as usize].y.abs() <= half;
    incise_sim::nakao_cut::measure::cut_triangles(m)
        .iter()
        .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
        .filter(|&(a, b)| top(a) && top(b) && near(a) && near(b))
        .map(|(a, b)| {
            let (p, q) = (x[a as usize], x[b as usize]);
            [(p.x * 100.0, p.y * 100.0), (q.x * 100.0, q.y * 100.0)]
        })
        .collect()
}
