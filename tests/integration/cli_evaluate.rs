//! `robocal evaluate`: validation statistics under both models, per-point errors, and the
//! verification workflow of the README (compensate, measure the commanded joints, evaluate).

use crate::util::library::*;
use crate::util::*;
use robocal_core::io::{write_measurements, Measurement, MeasurementSet};
use std::path::{Path, PathBuf};

fn json(o: &Outcome) -> serde_json::Value {
    o.assert_ok();
    serde_json::from_str(&o.stdout()).unwrap_or_else(|e| panic!("{e}: {}", o.stdout()))
}

/// A measurement file of the truth at `n` random poses, with an `id` column.
fn measured(dir: &Path, name: &str, n: usize, seed: u64, noise: bool) -> PathBuf {
    let joints = dir.join(format!("{name}.joints.csv"));
    write_joints(&joints, &poses(n, seed));
    let out = dir.join(format!("{name}.csv"));
    simulate(&joints, &out, &tracker(noise), seed + 100);
    out
}

#[test]
fn validation_statistics_and_per_point_file() {
    let dir = Dir::new();
    let d = dir.path();
    let t = tracker(false);
    let res = write_result(d, &t.frame);
    let data = measured(d, "val", 73, 1, false);
    let pp = d.join("per_point.csv");
    let o = robocal(&[
        "evaluate",
        "--robot",
        KUKA,
        "--params",
        p(&res),
        "--data",
        p(&data),
        "--per-point",
        p(&pp),
        "--json",
    ]);
    let v = json(&o);
    assert_eq!(v["reference"], "model");
    assert_eq!(v["n"], 73);
    // Exact data of the truth, the truth as calibrated model: zero error; the nominal model is
    // millimetres off.
    assert!(v["calibrated"]["max_mm"].as_f64().unwrap() < 1e-5, "{v}");
    let nominal_mean = v["nominal"]["mean_mm"].as_f64().unwrap();
    assert!(nominal_mean > 0.5, "{v}");
    for k in ["n", "mean_mm", "std_mm", "max_mm", "rms_mm", "p95_mm"] {
        assert!(v["nominal"][k].is_number(), "{k}: {v}");
    }
    let (h, rows) = read_csv(&pp);
    assert_eq!(rows.len(), 73);
    assert_eq!(h[0], "line");
    assert_eq!(rows[0][0], "2");
    assert_eq!(rows[0][col(&h, "id")], "p0");
    let mean: f64 = rows
        .iter()
        .map(|r| r[col(&h, "norm_nominal")].parse::<f64>().unwrap())
        .sum::<f64>()
        / 73.0;
    assert!((mean - nominal_mean).abs() < 1e-5);

    // The text table.
    let o = robocal(&[
        "evaluate",
        "--robot",
        KUKA,
        "--params",
        p(&res),
        "--data",
        p(&data),
    ]);
    o.assert_ok();
    let text = o.stdout();
    assert!(text.contains("Mean (mm)") && text.contains("nominal") && text.contains("reduced by"));
}

/// The README's verification workflow with truth = Table III and tracker noise on:
/// `calibrate --data CAL.csv`, `compensate --joints CAL.csv --out COMMANDED.csv`, measure the
/// commanded joints on the same virtual cell (here through the library, as `simulate --joints`
/// does), `evaluate --data VERIFY.csv`, which compares with the desired positions the commanded
/// file carries. Checks: verification at least 5x below the uncompensated error, and within 20%
/// of the calibrated model's own error on the calibration points (the paper's claim that
/// simulation predicts verification).
#[test]
fn verification_workflow_gives_table_v() {
    let dir = Dir::new();
    let d = dir.path();
    let t = tracker(true);
    let cal = measured(d, "cal", 75, 2, true);
    let res = d.join("result.json");
    let o = robocal(&[
        "calibrate",
        "--robot",
        KUKA,
        "--data",
        p(&cal),
        "--out",
        p(&res),
    ]);
    o.assert_ok();
    let before = json(&robocal(&[
        "evaluate",
        "--robot",
        KUKA,
        "--params",
        p(&res),
        "--data",
        p(&cal),
        "--json",
    ]));
    assert_eq!(before["reference"], "model");

    let commanded = d.join("commanded.csv");
    let o = robocal(&[
        "compensate",
        "--robot",
        KUKA,
        "--params",
        p(&res),
        "--joints",
        p(&cal),
        "--out",
        p(&commanded),
    ]);
    o.assert_ok();
    assert!(o.stderr().contains("x,y,z columns"), "{}", o.stderr());
    let verify = d.join("verify.csv");
    simulate(&commanded, &verify, &t, 7);
    let after = json(&robocal(&[
        "evaluate",
        "--robot",
        KUKA,
        "--params",
        p(&res),
        "--data",
        p(&verify),
        "--json",
    ]));
    assert_eq!(after["reference"], "desired");
    assert!(
        after["predicted"]["calibration"]["mean_mm"].is_number(),
        "{after}"
    );
    let uncompensated = before["nominal"]["mean_mm"].as_f64().unwrap();
    let predicted = before["calibrated"]["mean_mm"].as_f64().unwrap();
    // The same prediction as the result's Table IV (evaluate uses the result's tracker frame).
    let table4 = after["predicted"]["calibration"]["mean_mm"]
        .as_f64()
        .unwrap();
    assert!((predicted - table4).abs() < 1e-9, "{predicted} vs {table4}");
    let verified = after["desired"]["mean_mm"].as_f64().unwrap();
    eprintln!(
        "uncompensated {uncompensated:.4} mm, predicted {predicted:.4}, verified {verified:.4}"
    );
    assert!(verified * 5.0 <= uncompensated, "{before} {after}");
    assert!(
        (verified - predicted).abs() <= 0.2 * predicted,
        "{before} {after}"
    );
    // Forcing the model reference on the verification data compares with the models instead.
    let m = json(&robocal(&[
        "evaluate",
        "--robot",
        KUKA,
        "--params",
        p(&res),
        "--data",
        p(&verify),
        "--against",
        "model",
        "--json",
    ]));
    assert_eq!(m["reference"], "model");
}

#[test]
fn bad_inputs_are_clear_errors() {
    let dir = Dir::new();
    let d = dir.path();
    let t = tracker(false);
    let res = write_result(d, &t.frame);
    let data = measured(d, "val", 5, 3, false);
    let run = |args: &[&str]| {
        let mut a = vec!["evaluate", "--robot", KUKA];
        a.extend_from_slice(args);
        robocal(&a)
    };
    // Comparing with desired positions needs the columns.
    let o = run(&[
        "--params",
        p(&res),
        "--data",
        p(&data),
        "--against",
        "desired",
    ]);
    o.assert_code(3);
    assert!(
        o.stderr().contains("val.csv:1: field `x_desired`"),
        "{}",
        o.stderr()
    );
    // A joint file without positions.
    let joints = d.join("val.joints.csv");
    let o = run(&["--params", p(&res), "--data", p(&joints)]);
    o.assert_code(3);
    assert!(
        o.stderr().contains("field `x`: missing column"),
        "{}",
        o.stderr()
    );
    // A bad desired cell names line and column.
    let set = MeasurementSet {
        path: d.join("v.csv"),
        joints: robocal_core::JointSpace::revolute(6),
        extra_columns: vec!["x_desired".into(), "y_desired".into(), "z_desired".into()],
        rows: vec![Measurement {
            line: 2,
            q: vec![0.1; 6],
            p: Some(nalgebra::Vector3::new(1.0, 2.0, 3.0)),
            extra: vec!["1".into(), "oops".into(), "3".into()],
        }],
        warnings: vec![],
    };
    let v = d.join("v.csv");
    write_measurements(&v, &set).unwrap();
    let o = run(&["--params", p(&res), "--data", p(&v)]);
    o.assert_code(3);
    assert!(
        o.stderr().contains("v.csv:2: field `y_desired`"),
        "{}",
        o.stderr()
    );
    // Per-point output into a missing directory: I/O error, nothing printed as success.
    let o = run(&[
        "--params",
        p(&res),
        "--data",
        p(&data),
        "--per-point",
        p(&d.join("none/pp.csv")),
    ]);
    o.assert_code(4);
    // A result of another robot.
    let wam = robocal_core::load_robot(concat!(env!("CARGO_MANIFEST_DIR"), "/examples/wam.toml"))
        .unwrap();
    let r = d.join("wam.json");
    result_for(&wam, &wam, &t.frame).write(&r).unwrap();
    let o = run(&["--params", p(&r), "--data", p(&data)]);
    o.assert_code(3);
    assert!(o.stderr().contains("robot.dof"), "{}", o.stderr());
}
