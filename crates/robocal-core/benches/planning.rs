//! Pose planning: 75 poses from 10,000 candidates (the target: under 1 s), with the
//! default criterion (workspace error, I-optimal) and D-optimality, with and without the
//! tracker's distance-dependent noise.

use criterion::{criterion_group, criterion_main, Criterion};
use robocal_core::planning::{plan, Criterion as Index, PlanSettings};
use robocal_core::preset;
use robocal_core::simulation::{SimulationConfig, DEFAULT_TRACKER_FRAME};
use robocal_core::TrackerFrame;
use std::hint::black_box;

fn benches(c: &mut Criterion) {
    let robot = preset("kuka-kr480-r3330").unwrap();
    let base = PlanSettings {
        poses: 75,
        candidates: 10_000,
        sampler: SimulationConfig::default().sampler(&robot),
        ..PlanSettings::default()
    };
    let mut g = c.benchmark_group("plan 75 of 10000");
    g.sample_size(10);
    g.bench_function("workspace (I-optimal)", |b| {
        b.iter(|| plan(&robot, black_box(&base)).unwrap())
    });
    let d = PlanSettings {
        criterion: Index::DOptimal,
        ..base.clone()
    };
    g.bench_function("D-optimal", |b| {
        b.iter(|| plan(&robot, black_box(&d)).unwrap())
    });
    let t = PlanSettings {
        tracker_origin: Some(TrackerFrame::from_vector_deg(&DEFAULT_TRACKER_FRAME).origin()),
        ..base.clone()
    };
    g.bench_function("workspace, tracker noise", |b| {
        b.iter(|| plan(&robot, black_box(&t)).unwrap())
    });
    g.finish();
}

criterion_group!(planning, benches);
criterion_main!(planning);
