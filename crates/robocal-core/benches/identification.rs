//! Whole identification (registration, identifiability, sum-of-norms solve, covariance, error
//! tables) on simulated KR 480 data: truth = the paper's Table III, tracker noise
//! 0.010 mm + 0.005 mm/m. Targets (issue 4): 75 poses under 10 ms, 20,000 poses under 1 s.
//! And the elasto-geometric calibration (joint compliance under gravity, `auto` joints, the
//! payload known) of 1000 simulated UR5 poses sagging under gravity: target (issue 13) under
//! 50 ms. And several reflectors (issue 12): 1000 KR 480 poses each measured through three
//! reflectors (3000 points), target under 50 ms. And the model choice by cross-validation
//! (issue 25): 75 poses under 10 ms (the geometric model alone under 5 ms), 1000 UR5 poses under
//! 150 ms.

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

/// Times the whole calibration of `obs` with `model` (default settings) as benchmark `name`.
fn bench_calibrate(
    g: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    name: &str,
    model: &Robot,
    obs: &Observations,
) {
    bench_with(g, name, model, obs, CalibrationSettings::default());
}

/// Times the whole calibration of `obs` with `model` and `settings` as benchmark `name`.
fn bench_with(
    g: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    name: &str,
    model: &Robot,
    obs: &Observations,
    settings: CalibrationSettings,
) {
    g.bench_function(name, |b| {
        b.iter(|| {
            let cal = calibrate(
                model,
                CalibrationData {
                    calibration: black_box(obs),
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
}

/// The model chosen by cross-validation (`--model auto`: six candidates, 5 folds each) against
/// the geometric model alone: 75 KR 480 poses (targets 10 ms and 5 ms, issue 25) and 1000 UR5
/// poses sagging under gravity (target 150 ms).
fn selection(c: &mut Criterion) {
    use robocal_core::identification::{AutoFamilies, ModelChoice};
    let auto = CalibrationSettings {
        model: ModelChoice::Auto(AutoFamilies::default()),
        ..Default::default()
    };
    let truth = preset("kuka-kr480-r3330-table3").unwrap();
    let nominal = preset("kuka-kr480-r3330").unwrap();
    let obs = data(&truth, 75, 7);
    let (ur5, ur5_obs) = ur5_sagging();
    let mut g = c.benchmark_group("selection");
    g.sample_size(10);
    bench_with(
        &mut g,
        "kr480 geometric 75 poses",
        &nominal,
        &obs,
        Default::default(),
    );
    bench_with(&mut g, "kr480 auto 75 poses", &nominal, &obs, auto.clone());
    bench_with(&mut g, "ur5 auto 1000 poses", &ur5, &ur5_obs, auto);
    g.finish();
}

/// 1000 poses of the UR5 example sagging under gravity (about the UR5's masses, harmonic-drive
/// compliances), and the nominal UR5.
fn ur5_sagging() -> (Robot, Observations) {
    use robocal_core::simulation::GravityModel;
    let file = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/ur5.toml");
    let nominal = robocal_core::load_robot_file(std::path::Path::new(file)).unwrap();
    let g = GravityModel::new(
        vec![0.0, 2e-6, 3e-6, 5e-6, 5e-6, 5e-6],
        vec![3.7, 8.4, 2.3, 1.2, 1.2, 0.25],
        2.0,
    );
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
    let sampler = PoseSampler {
        floor_z_mm: -2000.0,
        footprint_radius_mm: 150.0,
        max_tries_per_pose: 10_000,
    };
    let qs = random_poses(&nominal, 1000, &sampler, &mut rng).unwrap();
    let tracker = Tracker::new(TrackerFrame::identity(), 0.010, 0.005).unwrap();
    let mut obs = Observations::new(nominal.dof());
    for (i, q) in qs.iter().enumerate() {
        let p = nominal.tool_position(&g.deflected(&nominal, q));
        obs.push(q, tracker.measure(&p, &mut rng), i + 2).unwrap();
    }
    (nominal, obs)
}

/// The UR5 data of [`ur5_sagging`] with the nominal model and with compliance on its `auto`
/// joints at the 2 kg payload.
fn ur5_elasto(c: &mut Criterion) {
    use robocal_core::model::family::compliance;
    let (nominal, obs) = ur5_sagging();
    let mut model = nominal.clone();
    let joints = compliance::auto_joints(&model);
    compliance::enable(&mut model, &joints, Some(2.0)).unwrap();
    let mut grp = c.benchmark_group("identification");
    grp.sample_size(20);
    for (name, model) in [("elasto-geometric", &model), ("geometric", &nominal)] {
        bench_calibrate(&mut grp, &format!("ur5 {name} 1000 poses"), model, &obs);
    }
    grp.finish();
}

fn bench(c: &mut Criterion) {
    let truth = preset("kuka-kr480-r3330-table3").unwrap();
    let nominal = preset("kuka-kr480-r3330").unwrap();
    for (n, samples) in [(75usize, 100usize), (20_000, 10)] {
        let obs = data(&truth, n, 7);
        let mut g = c.benchmark_group("identification");
        g.sample_size(samples);
        bench_calibrate(&mut g, &format!("kr480 {n} poses"), &nominal, &obs);
        g.finish();
    }
}

/// 1000 poses of the KR 480 (truth: Table III) each measured through three reflectors.
fn reflectors(c: &mut Criterion) {
    use robocal_core::observations::RowExtras;
    let mut truth = preset("kuka-kr480-r3330-table3").unwrap();
    let mut nominal = preset("kuka-kr480-r3330").unwrap();
    let t0 = *nominal.tool0();
    let mut t2 = t0;
    t2[0] += 180.0;
    let mut t3 = t0;
    t3[1] += 160.0;
    nominal.set_target_tools(&[t0, t2, t3]).unwrap();
    truth.set_target_tools(&[t0, t2, t3]).unwrap();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
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
    let qs = random_poses(&truth, 1000, &sampler, &mut rng).unwrap();
    let mut obs = Observations::new(truth.dof());
    for (i, q) in qs.iter().enumerate() {
        for t in 0..3 {
            let m = tracker.measure(&truth.target_position(q, t), &mut rng);
            let extras = RowExtras {
                target: t,
                ..Default::default()
            };
            obs.push_with(q, m, extras, 3 * i + t + 2).unwrap();
        }
    }
    let mut g = c.benchmark_group("identification");
    g.sample_size(20);
    bench_calibrate(&mut g, "kr480 1000 poses x 3 reflectors", &nominal, &obs);
    g.finish();
}

criterion_group!(benches, bench, ur5_elasto, reflectors, selection);
criterion_main!(benches);
