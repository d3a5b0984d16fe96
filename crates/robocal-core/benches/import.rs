//! `robocal import` throughput (README, "Performance"): 1,000,000 Leica rows paired by order
//! with a 1,000,000-row joint CSV, and a 10-hour 500 Hz RTDE log (18,000,000 rows, a dwell every
//! 10 s) paired by time with 3,600 time-stamped points, the clock offset found. Files are
//! written once to a temporary directory and read as the CLI reads them.

use criterion::{criterion_group, criterion_main, Criterion};
use robocal_core::io::import::{import_files, ImportConfig, MatchBy};
use std::io::Write;
use std::path::Path;

fn write(path: &Path, mut fill: impl FnMut(&mut std::io::BufWriter<std::fs::File>)) {
    let mut w = std::io::BufWriter::with_capacity(1 << 20, std::fs::File::create(path).unwrap());
    fill(&mut w);
    w.flush().unwrap();
}

const LEICA: &str = "X  [mm],Y  [mm],Z  [mm],U(95)  [mm],U(95) X/Y/Z [mm],Tilt [deg],Q0,Q1,Q2,\
                     Q3,Image RMS [um],Target,Temperature [C],Pressure [mBar],Humidity [%],\
                     Time Stamp,OTG Applied,Delete\n";

/// Seconds after midnight as a Leica time stamp.
fn stamp(s: f64) -> String {
    let ms = (s * 1000.0).round() as i64;
    format!(
        "'11.10.2022 {:02}:{:02}:{:02}.{:03}",
        ms / 3_600_000,
        ms / 60_000 % 60,
        ms / 1000 % 60,
        ms % 1000
    )
}

fn leica_row(w: &mut impl Write, k: usize, t: f64) {
    let a = k as f64 * 1e-3;
    writeln!(
        w,
        "{:.4},{:.4},{:.4},0.021,0.012/0.011/0.015,0.0,{:.9},{:.9},0,0,14,T-Mac,20.1,1013.2,45,{},No,",
        1500.0 + 800.0 * a.sin(),
        -300.0 + 600.0 * (1.3 * a).cos(),
        900.0 + 200.0 * (0.7 * a).sin(),
        (0.5 * a).cos(),
        (0.5 * a).sin(),
        stamp(t)
    )
    .unwrap();
}

fn benches(c: &mut Criterion) {
    let dir = tempfile_dir();
    let points = dir.join("points.csv");
    let joints = dir.join("joints.csv");
    let n = 1_000_000;
    write(&points, |w| {
        w.write_all(LEICA.as_bytes()).unwrap();
        for k in 0..n {
            leica_row(w, k, k as f64 * 0.05);
        }
    });
    write(&joints, |w| {
        writeln!(w, "q1,q2,q3,q4,q5,q6").unwrap();
        for k in 0..n {
            let a = k as f64 * 1e-3;
            writeln!(
                w,
                "{:.9},{:.9},{:.9},{:.9},{:.9},{:.9}",
                a.sin() * 90.0,
                a.cos() * 45.0 - 30.0,
                (2.0 * a).sin() * 60.0,
                a * 0.01,
                (3.0 * a).cos() * 80.0,
                a.sin() * 170.0
            )
            .unwrap();
        }
    });
    // 10 h at 500 Hz: every 10 s a 7 s motion then a 3 s dwell; the tracker measures each dwell's
    // middle on a clock 3 h ahead.
    let log = dir.join("rtde.txt");
    let timed = dir.join("timed.csv");
    let (hz, period, moving) = (500usize, 10.0, 7.0);
    let rows = 10 * 3600 * hz;
    write(&log, |w| {
        writeln!(
            w,
            "timestamp actual_q_0 actual_q_1 actual_q_2 actual_q_3 actual_q_4 actual_q_5"
        )
        .unwrap();
        for r in 0..rows {
            let t = r as f64 / hz as f64;
            let (cycle, phase) = ((t / period).floor(), t % period);
            let u = (phase / moving).min(1.0);
            let q = (cycle + 0.5 * (1.0 - (std::f64::consts::PI * u).cos())) * 0.05;
            writeln!(
                w,
                "{t:.3} {:.9} {:.9} {:.9} {:.9} {:.9} {:.9}",
                q.sin(),
                q.cos() - 1.5,
                0.5 * q.sin(),
                q * 0.1,
                0.3 * q.cos(),
                -q.sin()
            )
            .unwrap();
        }
    });
    write(&timed, |w| {
        w.write_all(LEICA.as_bytes()).unwrap();
        for k in 0..3600 {
            leica_row(w, k, 3.0 * 3600.0 + k as f64 * period + moving + 1.5);
        }
    });
    let mut g = c.benchmark_group("import");
    g.sample_size(10);
    let order = ImportConfig::new(MatchBy::Order);
    g.bench_function("1M leica rows + 1M joint rows, by order", |b| {
        b.iter(|| {
            let i = import_files(&points, &joints, &order).unwrap();
            assert_eq!(i.report.matched, n);
        })
    });
    let time = ImportConfig::new(MatchBy::Time);
    g.bench_function("3600 points + 10 h 500 Hz RTDE (18M rows), by time", |b| {
        b.iter(|| {
            let i = import_files(&timed, &log, &time).unwrap();
            assert_eq!(i.report.matched, 3600);
        })
    });
    g.finish();
    let _ = std::fs::remove_dir_all(&dir);
}

fn tempfile_dir() -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("robocal-import-bench-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

criterion_group!(import, benches);
criterion_main!(import);
