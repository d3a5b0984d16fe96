//! Reading a measurement file (README, "Performance"): 100,000 rows of a 6-joint robot with
//! `id` and `set` columns, as `calibrate` reads them (row by row into calibration, validation
//! and plane sets), from memory so that the disk is not measured.

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use robocal_core::identification::read_split;
use robocal_core::io::{MeasurementReader, Positions};
use robocal_core::model::JointSpace;
use std::fmt::Write;
use std::path::Path;

/// `rows` rows as `simulate` writes them: 9 decimals for joints, 6 for positions.
fn file(rows: usize) -> String {
    let mut s = String::from("q1,q2,q3,q4,q5,q6,x,y,z,id,set\n");
    for i in 0..rows {
        let f = i as f64;
        for j in 0..6 {
            write!(s, "{:.9},", ((f * 0.37 + j as f64 * 1.3).sin()) * 170.0).unwrap();
        }
        let set = if i % 10 == 0 {
            "validation"
        } else {
            "calibration"
        };
        writeln!(
            s,
            "{:.6},{:.6},{:.6},P{},{}",
            2000.0 + (f * 0.11).cos() * 900.0,
            (f * 0.07).sin() * 1500.0,
            900.0 + (f * 0.05).sin() * 400.0,
            i + 1,
            set
        )
        .unwrap();
    }
    s
}

fn measurements(c: &mut Criterion) {
    let text = file(100_000);
    let joints = JointSpace::revolute(6);
    let mut g = c.benchmark_group("read_measurements");
    g.sample_size(10);
    g.bench_function("split_100k_rows", |b| {
        b.iter(|| {
            let reader = MeasurementReader::new(
                black_box(text.as_bytes()),
                Path::new("bench.csv"),
                &joints,
                Positions::Required,
            )
            .unwrap();
            let (split, _) = read_split(reader, |_| {}).unwrap();
            assert_eq!(split.calibration.len(), 90_000);
        })
    });
    g.finish();
}

criterion_group!(benches, measurements);
criterion_main!(benches);
