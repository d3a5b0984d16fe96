//! Simulation throughput: a whole paper session (3 plane + 75 calibration + 73 validation
//! points), drawing random poses, and measuring 10,000 poses with and without gravity.

use criterion::{criterion_group, criterion_main, Criterion};
use robocal_core::preset;
use robocal_core::simulation::{simulate, GravityModel, SimulationConfig, TruthSpec, VirtualCell};
use std::hint::black_box;

fn benches(c: &mut Criterion) {
    let nominal = preset("kuka-kr480-r3330").unwrap();
    let truth = TruthSpec::Robot(preset("kuka-kr480-r3330-table3").unwrap());
    let cfg = SimulationConfig {
        poses: 75,
        validation_poses: 73,
        ..SimulationConfig::default()
    };
    c.bench_function("session 3+75+73 (plane IK included)", |b| {
        b.iter(|| simulate(&nominal, &truth, black_box(&cfg), &()).unwrap())
    });
    let cell = VirtualCell::from_config(&nominal, &truth, &cfg).unwrap();
    c.bench_function("random_poses 10000", |b| {
        b.iter_batched(
            || cell.clone(),
            |mut cell| cell.random_poses(10_000).unwrap(),
            criterion::BatchSize::LargeInput,
        )
    });
    let qs = cell.clone().random_poses(10_000).unwrap();
    c.bench_function("measure 10000", |b| {
        b.iter_batched(
            || cell.clone(),
            |mut cell| cell.measure_joints(&qs).unwrap(),
            criterion::BatchSize::LargeInput,
        )
    });
    let g = cell
        .clone()
        .with_gravity(GravityModel::new(vec![1e-7; 6], vec![100.0; 6], 300.0))
        .unwrap();
    c.bench_function("measure 10000 with gravity", |b| {
        b.iter_batched(
            || g.clone(),
            |mut cell| cell.measure_joints(&qs).unwrap(),
            criterion::BatchSize::LargeInput,
        )
    });
}

criterion_group!(simulation, benches);
criterion_main!(simulation);
