//! Criterion benchmarks of the Nakao mass-spring cutter (PHYSICS.md §2): one explicit step
//! of the whole chest-scale slab (18.5k nodes, 72k tets), localised loops at levels 4 and
//! 6, and one blade advance (subdivision + remodelling) on the slab and on the plate.

use criterion::{BatchSize, Criterion, criterion_group, criterion_main};
use glam::DVec3;
use incise_sim::mass_spring::{LocalLoop, LocalLoopParams, SystemClock};
use incise_sim::nakao_cut::{
    BladePose, CutParams, Cutter, chest_slab_model, plate_model, slab_blade,
};

fn loops(c: &mut Criterion) {
    let mut g = c.benchmark_group("mass_spring");
    g.sample_size(20);
    let mut m = chest_slab_model().expect("slab builds");
    let dt = m.stable_dt();
    g.bench_function("chest_full_step", |b| b.iter(|| m.step(dt)));
    for level in [4, 6] {
        let mut m = chest_slab_model().expect("slab builds");
        let params = LocalLoopParams {
            max_level: level,
            ..LocalLoopParams::default()
        };
        let mut local = LocalLoop::new(params, SystemClock::default());
        let tip = DVec3::new(0.01, 0.003, 0.005);
        g.bench_function(format!("chest_local_level{level}"), |b| {
            b.iter(|| local.step(&mut m, tip, dt))
        });
    }
    g.finish();
}

/// A blade pose along a cut line at abscissa `x`.
type BladeAt = Box<dyn Fn(f64) -> BladePose>;

fn cuts(c: &mut Criterion) {
    let mut g = c.benchmark_group("nakao_cut");
    g.sample_size(20);
    let slab = chest_slab_model().expect("slab builds");
    let plate = plate_model(0.04).expect("plate builds");
    let plate_blade = |x: f64| BladePose {
        heel: DVec3::new(x, 0.0011, -0.002),
        tip: DVec3::new(x, 0.0011, 0.006),
    };
    let cases: [(&str, _, BladeAt); 2] = [
        (
            "chest_advance_2mm",
            slab,
            Box::new(|x| slab_blade(x, 0.0013)),
        ),
        ("plate_advance_2mm", plate, Box::new(plate_blade)),
    ];
    for (name, model, blade) in cases {
        let mut cutter = Cutter::new(CutParams::default());
        let mut m = model.clone();
        cutter.begin(&m, blade(-0.02));
        // A cut in progress: the blade has travelled 2 cm.
        for k in 1..=10 {
            cutter.advance(&mut m, blade(-0.02 + 0.002 * k as f64));
        }
        g.bench_function(name, |b| {
            b.iter_batched(
                || (m.clone(), cutter.clone()),
                |(mut m, mut c)| c.advance(&mut m, blade(0.002)),
                BatchSize::LargeInput,
            )
        });
    }
    g.finish();
}

criterion_group!(benches, loops, cuts);
criterion_main!(benches);
