//! Whole identification (registration, identifiability, sum-of-norms solve, covariance, error
//! tables) on simulated KR 480 data: truth = the paper's Table III, tracker noise
//! 0.010 mm + 0.005 mm/m. Targets (issue 4): 75 poses under 10 ms, 20,000 poses under 1 s.

use criterion::{criterion_group, criterion_main, Criterion};
use rand::SeedableRng;
use robocal_core::frame::{pose, TrackerFrame};
use robocal_core::identification::{calibrate, CalibrationData, CalibrationSettings, Observations};
use robocal_core::simulation::{random_poses, PoseSampler, Tracker};
use robocal_core::{preset, Robot};
use std::hint::black_box;

fn data(truth: &Robot, n: usize, seed: u64) -> Observations {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let tracker = Tracker::new(
        TrackerFrame::new(pose(&[3900.0, -2200.0, -350.0, 2.65, 0.007, -0.012])),
        0.010,
        0.005,
    )
    .unwrap();
    let sampler = PoseSampler {
        floor_z_mm: 0.0,
        footprint_radius_mm: 800.0,
        max_tries_per_pose: 10_000,
    };
    let qs = random_poses(truth, n, &sampler, &mut rng).unwrap();
    let mut obs = Observations::new(truth.dof());
    for (i, q) in qs.iter().enumerate() {
        obs.push(q, tracker.measure(&truth.tool_position(q), &mut rng), i + 2)
            .unwrap();
    }
    obs
}

fn bench(c: &mut Criterion) {
    let truth = preset("kuka-kr480-r3330-table3").unwrap();
    let nominal = preset("kuka-kr480-r3330").unwrap();
    let settings = CalibrationSettings::default();
    for (n, samples) in [(75usize, 100usize), (20_000, 10)] {
        let obs = data(&truth, n, 7);
        let mut g = c.benchmark_group("identification");
        g.sample_size(samples);
        g.bench_function(format!("kr480 sum-of-norms {n} poses"), |b| {
            b.iter(|| {
                let cal = calibrate(
                    &nominal,
                    CalibrationData {
                        calibration: black_box(&obs),
                        plane: None,
                        validation: None,
                    },
                    &settings,
                    &(),
                )
                .unwrap();
                black_box(cal.calibration.after_stats())
            })
        });
        g.finish();
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
