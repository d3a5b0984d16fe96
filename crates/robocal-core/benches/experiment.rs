//! The paper's whole experiment in simulation (`robocal demo` without printing and writing):
//! 3 + 75 + 73 points measured, registration, identification, validation, compensation of the
//! 75 calibration poses, verification measurement, truth comparison. Target: the whole demo
//! under 5 s (release); the library part should take milliseconds.

use criterion::{criterion_group, criterion_main, Criterion};
use robocal_core::experiment::{run_experiment, ExperimentConfig};
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let config = ExperimentConfig::paper(1).unwrap();
    c.bench_function("paper_experiment", |b| {
        b.iter(|| {
            let e = run_experiment(black_box(config.clone()), &()).unwrap();
            e.verified().mean_mm
        })
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
