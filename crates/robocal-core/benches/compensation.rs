//! Compensation throughput (eq. 12-14): nominal forward kinematics of a desired pose + damped
//! least-squares IK on the calibrated model, per pose, on one core. Target: at least 50,000 poses
//! per second (release). Nominal = Table I, calibrated = Table III, 1,000 random poses per batch.
//! Full-pose compensation (position and orientation, with the configuration check): 10,000
//! random poses per batch, target at least 100,000 poses per second on one core.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use rand::SeedableRng;
use robocal_core::compensation::Target;
use robocal_core::simulation::{random_poses, PoseSampler};
use robocal_core::{preset, Compensator, DampedLeastSquares};
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let nom = preset("kuka-kr480-r3330").unwrap();
    let cal = preset("kuka-kr480-r3330-table3").unwrap();
    let comp = Compensator::new(&nom, &cal, DampedLeastSquares::default()).unwrap();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
    let poses = random_poses(&nom, 1_000, &PoseSampler::default(), &mut rng).unwrap();
    let mut g = c.benchmark_group("compensation");
    g.throughput(Throughput::Elements(poses.len() as u64));
    g.bench_function("compensate_1000_poses", |b| {
        let mut q = [0.0; 6];
        b.iter(|| {
            let mut converged = 0;
            for d in &poses {
                let (_, rep) = comp.compensate(black_box(d), &mut q);
                converged += rep.status.is_converged() as usize;
            }
            converged
        })
    });
    let many = random_poses(&nom, 10_000, &PoseSampler::default(), &mut rng).unwrap();
    g.throughput(Throughput::Elements(many.len() as u64));
    g.bench_function("compensate_pose_10000_poses", |b| {
        let mut q = [0.0; 6];
        b.iter(|| {
            let mut converged = 0;
            for d in &many {
                let (_, rep) = comp.compensate_pose(black_box(d), &mut q);
                converged += rep.status.is_converged() as usize;
            }
            converged
        })
    });
    g.throughput(Throughput::Elements(poses.len() as u64));
    // Cartesian targets with a seed (one solve each) and without (default seeds).
    let targets: Vec<Target> = poses
        .iter()
        .enumerate()
        .map(|(k, q)| Target {
            line: k + 2,
            p: cal.tool_position(q),
            abc: None,
            seed: None,
            extra: vec![],
        })
        .collect();
    g.bench_function("reach_1000_targets_default_seeds", |b| {
        let mut q = [0.0; 6];
        b.iter(|| {
            let mut converged = 0;
            for t in &targets {
                let rep = comp.reach(black_box(&t.p), None, &mut q);
                converged += rep.status.is_converged() as usize;
            }
            converged
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
