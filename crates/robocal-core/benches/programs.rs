//! Robot-program compensation (`compensate --program`): a KRL program of 5,000 inline joint
//! targets (`PTP {A1 .., A6 ..}`) read, its motions counted, compensated full-pose on the
//! calibrated model, verified after the controller's rounding and written back. Target (issue
//! 26): 5,000 targets in under 1 s (the CLI's whole command on a cell program is printed by the
//! test `cli_programs::five_thousand_targets_are_compensated`).

use criterion::{criterion_group, criterion_main, Criterion};
use rand::SeedableRng;
use robocal_core::programs::{compensate_program, Format, ProgramSettings, Source};
use robocal_core::simulation::{random_poses, PoseSampler};
use robocal_core::{preset, Compensator, DampedLeastSquares};
use std::hint::black_box;
use std::path::PathBuf;

/// A KRL program of `n` joint targets at random poses of the KR 480.
fn program(n: usize) -> String {
    let nom = preset("kuka-kr480-r3330").unwrap();
    let js = nom.joint_space();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
    let poses = random_poses(&nom, n, &PoseSampler::default(), &mut rng).unwrap();
    let mut s = String::from("DEF bench()\n");
    for q in &poses {
        let a = js.axes_from_joints(q);
        s += &format!(
            "PTP {{A1 {:.4},A2 {:.4},A3 {:.4},A4 {:.4},A5 {:.4},A6 {:.4}}}\n",
            a[0], a[1], a[2], a[3], a[4], a[5]
        );
    }
    s + "END\n"
}

fn bench(c: &mut Criterion) {
    let nom = preset("kuka-kr480-r3330").unwrap();
    let cal = preset("kuka-kr480-r3330-table3").unwrap();
    let comp = Compensator::new(&nom, &cal, DampedLeastSquares::default()).unwrap();
    let src = [Source {
        path: PathBuf::from("bench.src"),
        text: program(5000),
    }];
    let settings = ProgramSettings::default();
    let mut g = c.benchmark_group("programs");
    g.sample_size(10);
    g.bench_function("krl_5000_joint_targets", |b| {
        b.iter(|| {
            let out =
                compensate_program(black_box(&src), Format::Krl, None, &comp, &settings).unwrap();
            assert_eq!(out.changes.len(), 5000);
            out.changes.iter().filter(|c| c.applied).count()
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
